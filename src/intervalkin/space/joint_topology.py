"""The joint box paved directly, with what is proved of its cells' topology, as one task.

The cells of the direct joint paving (:mod:`intervalkin.space.joint_paving`) come with what the
library proves about the components of the joint box minus g(S): the cells that are whole components
(:func:`~intervalkin.space.joint_closure.closed_cells`), the cells of one signature that are different
components (:func:`~intervalkin.space.joint_separation.separated_cells`), and, when asked, how far the open
layer retracts into the cells (:func:`~intervalkin.space.joint_retraction.retract_joint_paving`, the local step
of an upper bound).  They read only the paving, so the chain computes them where it paves it: in the paper run that is the second
process, beside the regions, rather than after both.  Nothing here is written to the certificates.

Where the separations leave two cells of one signature in one group, the joint box is paved again with the
leaves between them (:attr:`~intervalkin.space.joint_separation.Separation.between`, as level-``depth`` boxes)
split :data:`ZONE_LEVELS` more times (:mod:`intervalkin.space.joint_zones`), up to :data:`ZONE_PASSES` times, the
zone growing by the leaves still between.  A finer paving is kept only when it keeps every cell (each old
cell's witness in a different new cell of its signature; it may find more) and proves more components apart;
otherwise the one before it stands.  A cell found only by the finer paving changes the count found: the pass
says so (``cells_found``), since a count that moves with the paving is not yet a result.  On the paper's
manipulator with limits [10.5, 32] one pass proves cells 3 and 7 apart (a 6-solution sliver 0.016 wide keeps
them apart along the face rho_3 = 10.5), so all 28 regions found are proved different; with the default limits
every cell is apart already and no pass runs.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Beside, Workers, default_workers
from intervalkin.space.joint_closure import Closure, closed_cells
from intervalkin.space.joint_paving import JointSpacePaving, pave_joint_space
from intervalkin.space.joint_retraction import retract_joint_paving
from intervalkin.space.joint_separation import Separation, separated_cells
from intervalkin.space.joint_zones import RefinementZone

__all__ = ["pave_joint_topology", "refine_separations", "ZONE_PASSES", "ZONE_LEVELS"]

#: Pavings made again with a finer zone between cells still joined (each costs about one paving and its separations).
ZONE_PASSES = 2
#: Levels the zone's undecided leaves are split past those the paving gave them (about 4 ** 4 children for one along a sheet).
ZONE_LEVELS = 4


def pave_joint_topology(geometry: Geometry, depth: int, join_levels: int, progress=None, retract: bool = False,
                        **levels) -> tuple[JointSpacePaving, Closure, Separation]:
    """(the paving of :func:`~intervalkin.space.joint_paving.pave_joint_space`, its closed cells, its separations),
    after the zone passes of the module docstring; with ``retract``, the paving carries its open layer's retraction
    into the cells (``retraction``; None without).

    The retraction is off by default: it proves no count on any geometry yet (no retraction closes), and on the
    paper's paving it took 131 s of wall time on two cores, beside the separations, after a paving of 215 s, so a
    run pays for it only when asked."""
    first = pave_joint_space(geometry, depth, join_levels, progress=progress, **levels)
    # the separations are serial and their working memory is large (about 1 GiB on the paper's paving): a short-lived
    # second process computes them, meanwhile this one retracts the same paving when asked; the retraction stands
    # unless a zone pass replaces the paving (then it is retracted again)
    with Beside(separated_cells, first, geometry) as side:
        retraction = _retraction(first, geometry) if retract else None
        separation = side.result()
    cells, separation = refine_separations(geometry, first, separation, depth, join_levels, progress, **levels)
    if retract:
        if cells is not first:
            retraction = _retraction(cells, geometry)
        cells = dataclasses.replace(cells, retraction=retraction)
    return cells, closed_cells(cells, geometry), separation


def _retraction(cells: JointSpacePaving, geometry: Geometry):
    with Workers(default_workers()) as workers:
        return retract_joint_paving(cells, geometry, workers)


def refine_separations(geometry: Geometry, cells: JointSpacePaving, separation: Separation, depth: int,
                       join_levels: int, progress=None, **levels) -> tuple[JointSpacePaving, Separation]:
    """The zone passes of the module docstring: (the paving kept, its separations, with ``zone_passes`` saying
    what each pass proved).  ``cells``, ``separation``: the paving made with ``depth``, ``join_levels`` and
    ``levels`` (the arguments of :func:`~intervalkin.space.joint_paving.pave_joint_space`) and its separations."""
    zone, passes = None, []
    for _ in range(ZONE_PASSES if cells.windows is not None else 0):
        if not separation.between.size:
            break
        p = cells.paving
        more = RefinementZone.of_leaves(p.level[separation.between], p.ijk[separation.between], depth, ZONE_LEVELS)
        zone = more if zone is None else zone.union(more)
        finer = pave_joint_space(geometry, depth, join_levels, progress=progress, zone=zone, **levels)
        finer_separation = separated_cells(finer, geometry)
        kept_cells = _old_cells_kept(geometry, cells, finer)
        better = finer_separation.components_at_least() > separation.components_at_least()
        passes.append({**zone.to_json(p.hi.max(axis=0) - p.lo.min(axis=0)), "cells_found": len(finer.cells),
                       "old_cells_kept": kept_cells, "components_at_least": finer_separation.components_at_least(),
                       "basic_regions_at_least": finer_separation.basic_regions_at_least(),
                       "kept": kept_cells and better})
        if not (kept_cells and better):
            break
        cells, separation = finer, finer_separation
    return cells, (dataclasses.replace(separation, zone_passes=tuple(passes)) if passes else separation)


def _old_cells_kept(geometry: Geometry, old: JointSpacePaving, new: JointSpacePaving) -> bool:
    """Every old cell's witness lies in a new cell of its signature, no two in one: no cell was lost or merged
    (a finer paving may find more, as it may prove more of them apart)."""
    if len(new.cells) < len(old.cells):
        return False
    witness = np.array([[float(v) for v in c.witness] for c in old.cells]).reshape(-1, 3)
    at = new.cell_of(witness, geometry)
    if (at < 0).any() or np.unique(at).size != at.size or (at >= len(new.cells)).any():
        return False
    return all(new.cells[int(j)].signature == c.signature for c, j in zip(old.cells, at))

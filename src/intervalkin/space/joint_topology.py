"""The joint box paved directly, with what is proved of its cells' topology, as one task.

The cells of the direct joint paving (:mod:`intervalkin.space.joint_paving`) come with what the
library proves about the components of the joint box minus g(S): the cells that are whole components
(:func:`~intervalkin.space.joint_closure.closed_cells`), the cells of one signature that are different
components (:func:`~intervalkin.space.joint_separation.separated_cells`), and how far the open layer
retracts into the cells (:func:`~intervalkin.space.joint_retraction.retract_joint_paving`, the local step
of an upper bound).  They read only the paving, so the chain computes them where it paves it: in the paper run that is the second
process, beside the regions, rather than after both.  Nothing here is written to the certificates.
"""

from __future__ import annotations

import dataclasses

from intervalkin.core.geometry import Geometry
from intervalkin.space.joint_closure import Closure, closed_cells
from intervalkin.space.joint_paving import JointSpacePaving, pave_joint_space
from intervalkin.space.joint_retraction import retract_joint_paving
from intervalkin.space.joint_separation import Separation, separated_cells

__all__ = ["pave_joint_topology"]


def pave_joint_topology(geometry: Geometry, depth: int, join_levels: int, progress=None,
                        **levels) -> tuple[JointSpacePaving, Closure, Separation]:
    """(the paving of :func:`~intervalkin.space.joint_paving.pave_joint_space` with its open layer's retraction
    into the cells, its closed cells, its separations)."""
    cells = pave_joint_space(geometry, depth, join_levels, progress=progress, **levels)
    cells = dataclasses.replace(cells, retraction=retract_joint_paving(cells, geometry))
    return cells, closed_cells(cells, geometry), separated_cells(cells, geometry)

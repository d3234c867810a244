"""The whole workspace chain for one geometry, writing one output folder.

``run_pave`` (the ``intervalkin pave`` command) paves W, the sign of det A and the
aspects, finds the aspects as connected components, and writes::

    DIR/pavings/workspace.npz    boxes and labels (format: intervalkin.app.export)
    DIR/pavings/workspace.vtu    the same as a VTK unstructured grid of hexahedra
    DIR/figures/*.png            3-D views and phi-slices
    DIR/summary.json             counts, volumes, components, timings, what is certified
"""

from __future__ import annotations

from dataclasses import dataclass

from intervalkin.app.progress import Stages
from intervalkin.core.errors import InputError
from intervalkin.paving.budget import check_depth
from intervalkin.space.basic_region import analyse_regions
from intervalkin.space.joint_space import joint_paving
from intervalkin.space.singular_surface import pave_singular_layer

__all__ = ['Analysis', 'analyse']
#: Workspace depth of the default run (about a minute on two cores).
DEFAULT_DEPTH = 8
MAX_CHAIN_DEPTH = 9


def check_chain_depth(depth) -> int:
    """A user depth for the chain: an integer in 3..MAX_CHAIN_DEPTH whose singular layer fits in memory."""
    if isinstance(depth, bool) or not isinstance(depth, int) or not 3 <= depth <= MAX_CHAIN_DEPTH:
        raise InputError(f"--depth: expected an integer in 3..{MAX_CHAIN_DEPTH}, got {depth!r}")
    check_depth(depth + 1)
    return depth


def chain_depths(depth: int) -> tuple[int, int, int]:
    """(workspace depth, singular-layer depth, joint depth) for a user depth."""
    return depth, depth + 1, min(depth - 1, 7)


@dataclass(frozen=True, eq=False)
class Analysis:
    """The definition sets of one manipulator, as certified pavings and counts."""

    geometry: object
    depth: int
    singular_depth: int
    joint_depth: int
    n_singular_boxes: int
    joint: object
    regions: object
    timings: dict
    refinement: tuple = ()


def _singular_and_joint(geometry, singular_depth: int, joint_depth: int, st: Stages):
    """The singular layer at ``singular_depth`` and the joint cells on 2**joint_depth voxels per axis."""

    st.start(f"singular layer (depth {singular_depth})")
    sing = pave_singular_layer(geometry, singular_depth, progress=st.bar())
    st.done()
    st.start(f"joint space: enclosure of g(S) and certified cells (2^{joint_depth} voxels per axis)")
    jp = joint_paving(geometry, sing, joint_depth)
    st.done()
    return sing, jp


def analyse(geometry, depth: int = DEFAULT_DEPTH, stages: Stages | None = None, refine_to: int | None = None) -> Analysis:
    """Run the chain geometry -> singular layer -> joint cells -> regions -> uniqueness domains.

    ``depth`` is the octree depth of the workspace paving; the singular layer
    is paved one level deeper and the joint grid has 2**min(depth - 1, 7) voxels
    per axis (see :func:`chain_depths`).

    ``refine_to``: while Proposition 1 is not seen in full (a sheet above a
    counted cell holds no certified box), pave the regions one level deeper, up
    to this depth.  The paver only splits undecided boxes, so a deeper level
    refines near the characteristic surfaces, the singular layer and the joint
    limits, not the whole domain.  ``Analysis.refinement`` records each try and
    why it stopped.
    """

    check_chain_depth(depth)
    st = stages or Stages(quiet=True)
    dw, ds, dj = chain_depths(depth)
    sing, jp = _singular_and_joint(geometry, ds, dj, st)
    st.start(f"workspace, aspects, characteristic surfaces, basic regions (depth {dw})")
    ra = analyse_regions(geometry, jp, dw, progress=st.bar())
    st.done()
    history = [{"depth": dw, "consistent": ra.consistent, "basic_regions": len(ra.regions)}]
    if refine_to is not None:
        if isinstance(refine_to, bool) or not isinstance(refine_to, int) or not dw <= refine_to <= MAX_CHAIN_DEPTH:
            raise InputError(f"--refine-to: expected an integer in {dw}..{MAX_CHAIN_DEPTH}, got {refine_to!r}")
        while not ra.consistent and dw < refine_to:
            dw += 1
            st.start(f"refining where Proposition 1 is not yet seen in full: regions at depth {dw}")
            ra = analyse_regions(geometry, jp, dw, progress=st.bar())
            st.done()
            history.append({"depth": dw, "consistent": ra.consistent, "basic_regions": len(ra.regions)})
    if ra.consistent:
        history[-1]["stopped"] = "consistent: every sheet above every counted cell holds certified boxes"
    elif refine_to is None:
        history[-1]["stopped"] = "not consistent at this depth; no refinement asked (--refine-to)"
    else:
        history[-1]["stopped"] = f"limit reached (depth {dw}) before consistency"
    return Analysis(geometry, dw, ds, dj, len(sing), jp, ra, dict(st.timings), tuple(history))

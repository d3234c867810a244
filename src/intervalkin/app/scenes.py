"""The 3-D scenes of the paper, as coloured surfaces: shared by the PNG figures and report.html.

A :class:`Scene` is a list of :class:`Layer` objects, each the boundary surface
(:mod:`intervalkin.app.surfaces`) of one labelled set with its colour
(:func:`intervalkin.app.palette.colour_of`) and legend text.  The workspace scenes
(Figures 3, 5, 6, 9, 10, 12 and 13 of the paper) come from the regions paving,
the joint-space scenes (Figures 2, 11 and 13) from the joint cells.  phi is drawn
in degrees.

Joint spaces are read through :func:`~intervalkin.app.boxes.joint_boxes` (a uniform
voxel grid or an adaptive paving alike).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.app.boxes import JointBoxes, cell_by_id, fine_bounds, joint_boxes, rasterise
from intervalkin.app.palette import colour_of
from intervalkin.app.surfaces import Surface, grid_geometry, label_surfaces
from intervalkin.app.units import JOINT_AXES, WORKSPACE_AXES, phi_factor
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving
from intervalkin.space.basic_region import RegionAnalysis
from intervalkin.space.singular_surface import may_be_singular

__all__ = ["Layer", "Scene", "paving_scenes", "region_scenes", "workspace_scenes", "joint_scenes", "top_cell",
           "top_cell_scenes", "SCENE_BITS"]

#: Grid resolution (2**bits cells per axis) of the surfaces: fine enough to show the thin
#: regions, light enough for a browser and for matplotlib.
SCENE_BITS = 6

#: Faces above which a surface is drawn at a coarser step (:func:`~intervalkin.app.surfaces.label_surfaces`):
#: keeps report.html and the 3-D PNGs light; the thin sets have far fewer faces and keep every cell.
MAX_FACES = 15000


@dataclass(frozen=True)
class Layer:
    """One surface of a scene: ``kind`` and ``key`` name it for :func:`~intervalkin.app.palette.colour_of`."""

    name: str
    kind: str
    key: object
    surface: Surface
    group: str = ""
    opacity: float = 1.0

    @property
    def colour(self) -> str:
        return colour_of(self.kind, self.key)


@dataclass(frozen=True)
class Scene:
    """A 3-D view: ``key`` (file and element names), ``title``, axis titles, layers, paper figure, a note."""

    key: str
    title: str
    axes: tuple[str, str, str]
    layers: tuple[Layer, ...]
    paper_figure: str
    note: str = ""


def _workspace_grid(p: Paving, mask: np.ndarray, values: np.ndarray, bits: int):
    lo, hi = fine_bounds(p.level[mask], p.ijk[mask], p.depth)
    return rasterise(lo, hi, values[mask], p.depth, min(bits, p.depth))


def _surfaces(grid, keys, origin, spacing) -> dict[int, Surface]:
    return label_surfaces(grid, keys, origin, spacing, max_faces=MAX_FACES)


def _layers(grid, keys, names, kind, origin, spacing, groups=None) -> tuple[Layer, ...]:
    surfaces = _surfaces(grid, keys, origin, spacing)
    return tuple(Layer(names[i], kind, k, surfaces[int(k)], (groups or {}).get(k, ""))
                 for i, k in enumerate(keys) if not surfaces[int(k)].is_empty())


def paving_scenes(p: Paving, bits: int = SCENE_BITS) -> list[Scene]:
    """Workspace W, the singular layer and the aspects of a workspace paving (Figs. 3, 5, 6)."""
    b = min(bits, p.depth)
    origin, spacing = grid_geometry(p.domain, b, (1.0, 1.0, phi_factor("deg")))
    lab = p.labels
    wa1, wa2 = lab["WA1"] == Label.INSIDE, lab["WA2"] == Label.INSIDE
    zero = np.zeros(len(p), dtype=np.int32)
    grid = _workspace_grid(p, lab["W"] == Label.INSIDE, zero, b)
    w = Scene("workspace", f"Workspace W: boxes certified inside (depth {p.depth})", WORKSPACE_AXES,
              (Layer("W (certified)", "state", "workspace", _surfaces(grid, [0], origin, spacing)[0]),), "Fig. 3")
    # the singular layer is a thin sheet: drawn at full resolution, whatever its number of faces
    grid = _workspace_grid(p, may_be_singular(lab), zero, b)
    sheet = label_surfaces(grid, [0], origin, spacing)[0]
    sing = Scene("singular", "Type-2 singular layer: boxes where det A = 0 is not excluded", WORKSPACE_AXES,
                 (Layer("det A = 0 may occur", "state", "singular", sheet),), "Fig. 5")
    grid = _workspace_grid(p, wa1 | wa2, np.where(wa1, 0, 1).astype(np.int32), b)
    surf = _surfaces(grid, [0, 1], origin, spacing)
    asp = Scene("aspects", "The aspects: det A > 0 (WA1) and det A < 0 (WA2), certified boxes", WORKSPACE_AXES,
                (Layer("WA1 (det A > 0)", "aspect", "WA1", surf[0]), Layer("WA2 (det A < 0)", "aspect", "WA2", surf[1])),
                "Fig. 6")
    return [w, sing, asp]


def region_scenes(regions: RegionAnalysis, bits: int = SCENE_BITS) -> list[Scene]:
    """The characteristic layer of WA1, the basic regions and the uniqueness domains (Figs. 9, 10, 12)."""
    p = regions.paving
    b = min(bits, p.depth)
    origin, spacing = grid_geometry(p.domain, b, (1.0, 1.0, phi_factor("deg")))
    lab = p.labels
    wa1 = lab["WA1"] == Label.INSIDE
    sc1 = wa1 & (lab["off_Sc"] != Label.INSIDE)
    sing = may_be_singular(lab) & (lab["W"] == Label.INSIDE)
    grid = _workspace_grid(p, sc1 | sing, np.where(sc1, 0, 1).astype(np.int32), b)
    surf = label_surfaces(grid, [0, 1], origin, spacing)
    char = Scene("characteristic", "Characteristic surface S_c1 of WA1 (enclosure) and the singular layer",
                 WORKSPACE_AXES, (Layer("S_c1 (may meet it)", "state", "characteristic", surf[0]),
                                  Layer("singular layer", "state", "singular", surf[1])), "Fig. 9")
    ids = [r.id for r in regions.regions if r.n_boxes > 0]
    grid = _workspace_grid(p, regions.region >= 0, regions.region.astype(np.int32), b)
    names = [_region_name(regions, i) for i in ids]
    reg = Scene("basic_regions", f"{len(regions.regions)} basic regions", WORKSPACE_AXES,
                _layers(grid, ids, names, "region", origin, spacing, {i: regions.regions[i].aspect for i in ids}),
                "Fig. 10")
    dids = list(range(len(regions.domains)))
    grid = _workspace_grid(p, regions.domain >= 0, regions.domain.astype(np.int32), b)
    names = [f"domain {d}: regions {', '.join(map(str, regions.domains[d]))}" for d in dids]
    dom = Scene("uniqueness_domains", f"{len(dids)} uniqueness domains", WORKSPACE_AXES,
                _layers(grid, dids, names, "domain", origin, spacing), "Fig. 12")
    return [char, reg, dom]


def workspace_scenes(regions: RegionAnalysis, bits: int = SCENE_BITS) -> list[Scene]:
    """:func:`paving_scenes` then :func:`region_scenes` of the regions paving."""
    return paving_scenes(regions.paving, bits) + region_scenes(regions, bits)


def _region_name(regions: RegionAnalysis, rid: int) -> str:
    r = regions.regions[rid]
    return f"region {rid}: {r.aspect}, cell {r.cell} ({r.cell_count} sol.)"


def _joint_grid(jb: JointBoxes, values: np.ndarray, mask: np.ndarray, bits: int):
    b = min(bits, jb.depth)
    grid = rasterise(jb.lo[mask], jb.hi[mask], values[mask], jb.depth, b)
    origin, spacing = grid_geometry(jb.domain, b)
    return grid, origin, spacing


def joint_scenes(joint, bits: int = SCENE_BITS) -> list[Scene]:
    """Joint space Q (outer enclosure; Fig. 2) and every joint cell coloured by its certified count (Fig. 11).

    Cells that cover fewer than two grid cells are not drawn (the note says how many).
    """
    jb = joint_boxes(joint)
    cols = jb.columns
    cell, count = cols["cell"], cols["count"]
    # Q's boundary inside the joint box lies on g(S), inside the undecided layer: the layer is kept, and
    # only the cells certified to have no solution are cut away (an outer enclosure of Q)
    grid, origin, spacing = _joint_grid(jb, np.zeros(len(cell), np.int32), ~((cell >= 0) & (count == 0)), bits)
    q = Layer("joint space Q (outer enclosure)", "state", "joint_space", _surfaces(grid, [0], origin, spacing)[0])
    scenes = [Scene("joint_space", "Joint space Q: the joint box minus the cells certified to have no solution",
                    JOINT_AXES, (q,), "Fig. 2")]
    grid, origin, spacing = _joint_grid(jb, cell.astype(np.int32), (cell >= 0) & (count > 0), bits)
    sizes = np.bincount(grid[grid >= 0], minlength=max(cell_by_id(joint), default=-1) + 1)
    drawn = [c for c in joint.cells if c.count > 0 and sizes[c.id] >= 2]
    drawn.sort(key=lambda c: (c.count, c.id))
    names = [f"cell {c.id}: {c.count} solutions ({c.n_wa1} WA1 + {c.n_wa2} WA2)" for c in drawn]
    surfaces = _surfaces(grid, [c.id for c in drawn], origin, spacing)
    # the cells of the fewest solutions wrap around the others: drawn see-through in the interactive view
    outer = min((c.count for c in drawn), default=0)
    layers = tuple(Layer(nm, "count", c.count, surfaces[c.id], f"{c.count} solutions",
                         0.3 if c.count == outer and len({d.count for d in drawn}) > 1 else 1.0)
                   for nm, c in zip(names, drawn) if not surfaces[c.id].is_empty())
    hidden = sum(1 for c in joint.cells if c.count > 0) - len(layers)
    scenes.append(Scene("joint_cells", "Joint cells (basic components) by certified number of solutions",
                        JOINT_AXES, layers, "Fig. 11",
                        f"{hidden} cells smaller than two grid cells are not drawn" if hidden else ""))
    return scenes


def top_cell(regions: RegionAnalysis, joint) -> int | None:
    """The joint cell with the most solutions that carries certified regions (the paper's Fig. 13 cell)."""
    realized = {r.cell for r in regions.regions if r.n_boxes > 0}
    if not realized:
        return None
    cells = cell_by_id(joint)
    return max(realized, key=lambda c: (cells[c].count, sum(r.n_boxes for r in regions.regions if r.cell == c)))


def top_cell_scenes(regions: RegionAnalysis, joint, bits: int = SCENE_BITS) -> list[Scene]:
    """The basic regions above the richest joint cell, and that cell (Fig. 13); empty without regions."""
    cid = top_cell(regions, joint)
    if cid is None:
        return []
    p = regions.paving
    b = min(bits, p.depth)
    origin, spacing = grid_geometry(p.domain, b, (1.0, 1.0, phi_factor("deg")))
    ids = [r.id for r in regions.regions if r.cell == cid and r.n_boxes > 0]
    sel = np.isin(regions.region, ids)
    grid = _workspace_grid(p, sel, regions.region.astype(np.int32), b)
    c = cell_by_id(joint)[cid]
    ws = Scene("top_cell_regions", f"The basic regions above joint cell {cid} ({c.count} solutions)",
               WORKSPACE_AXES, _layers(grid, ids, [_region_name(regions, i) for i in ids], "region", origin,
                                       spacing), "Fig. 13")
    jb = joint_boxes(joint)
    cell = jb.columns["cell"]
    grid, origin, spacing = _joint_grid(jb, np.zeros(len(cell), np.int32), cell == cid, bits)
    js = Scene("top_cell", f"Joint cell {cid}: {c.count} coincident basic components", JOINT_AXES,
               (Layer(f"cell {cid}: {c.count} solutions", "count", c.count,
                      _surfaces(grid, [0], origin, spacing)[0]),), "Fig. 13")
    return [ws, js]

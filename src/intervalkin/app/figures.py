"""The figures of an output folder, one (or a few) per octree figure of the paper.

:data:`PAPER_FIGURES` lists, for each octree figure of Wenger & Chablat (1997)
(Figures 2, 3, 5, 6, 9, 10, 11, 12, 13), what it shows in our words and the files
that redraw it from certified labels; ``report.md`` and ``report.html`` cite them
from this table.  The entry points write them:

* :func:`render_paper_figures`: all of them, from an :class:`~intervalkin.pipeline.Analysis`;
* :func:`render_all` (workspace paving only: Figs. 3, 5, 6), :func:`render_joint`
  (Figs. 2, 11) and :func:`render_regions` (Figs. 9, 10, 12, and 13 given the joint
  cells): the pieces, for commands that have only part of the chain.

matplotlib is imported when a figure is drawn (:func:`~intervalkin.app.plotting.pyplot`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from intervalkin.app.figures_joint import render_joint_figures
from intervalkin.app.figures_workspace import render_paving_figures, render_region_figures
from intervalkin.app.plotting import pyplot, save_png
from intervalkin.paving.tree import Paving

__all__ = ["PaperFigure", "PAPER_FIGURES", "render_paper_figures", "render_chain_figures", "render_all", "render_joint",
           "render_regions", "pyplot", "save_png"]


@dataclass(frozen=True)
class PaperFigure:
    """An octree figure of the paper: its number, what it shows (our words), our files (figures/)."""

    number: int
    shows: str
    files: tuple[str, ...]


PAPER_FIGURES: tuple[PaperFigure, ...] = (
    PaperFigure(2, "the joint space: the leg lengths for which the platform can be assembled at all",
                ("joint_space_3d.png",)),
    PaperFigure(3, "the workspace: the poses (x, y, phi) that respect the leg limits",
                ("workspace_3d.png", "workspace_slices.png")),
    PaperFigure(5, "the type-2 singular poses (det A = 0) inside the workspace",
                ("singular_3d.png",)),
    PaperFigure(6, "the two aspects, on either side of the singular surface",
                ("aspects_3d.png", "aspects_slices.png")),
    PaperFigure(9, "the singular surface together with the characteristic surface of the first aspect",
                ("characteristic_3d.png", "characteristic_slices.png")),
    PaperFigure(10, "the basic regions, the pieces left of the aspects once the characteristic surfaces are removed",
                ("basic_regions_3d.png", "basic_regions_slices.png", "basic_regions_atlas.png")),
    PaperFigure(11, "the basic components, images of the basic regions in joint space, which coincide in "
                "domains of 2, 4 and 6 solutions", ("joint_3d.png", "joint_slices.png")),
    PaperFigure(12, "the uniqueness domains, unions of basic regions whose images do not overlap",
                ("uniqueness_domains_3d.png", "uniqueness_domains_slices.png")),
    PaperFigure(13, "the basic regions above the joint-space domain of six solutions, and that domain",
                ("top_cell_regions_3d.png",)),
)


def render_all(paving: Paving, out_dir, base=None, max_points=None) -> list[Path]:
    """Figs. 3, 5, 6 of a workspace paving (``base``: the base points, (3, 2), drawn in the legends).

    ``max_points`` is accepted for older callers and ignored (the 3-D views are surfaces now).
    """
    return render_paving_figures(paving, out_dir, base=_floats(base))


def render_joint(joint, out_dir) -> list[Path]:
    """Figs. 2 and 11 of the joint cells."""
    return render_joint_figures(joint, out_dir)


def render_regions(analysis, out_dir, base=None, joint=None) -> list[Path]:
    """Figs. 9, 10, 12 of a :class:`~intervalkin.space.basic_region.RegionAnalysis`, and 13 when ``joint`` is given."""
    return render_region_figures(analysis, out_dir, base=_floats(base), joint=joint)


def render_paper_figures(analysis, out_dir) -> list[Path]:
    """Every file of :data:`PAPER_FIGURES` for an :class:`~intervalkin.pipeline.Analysis`, into ``out_dir``."""
    return render_chain_figures(analysis.geometry, analysis.regions, analysis.joint, out_dir)


def render_chain_figures(geometry, regions, joint, out_dir) -> list[Path]:
    """:func:`render_paper_figures` from the parts it draws: the regions and the joint enclosure, not the
    joint cells (so the paper run draws them while the joint paving still runs)."""
    base = geometry.base
    return (render_all(regions.paving, out_dir, base=base) + render_joint(joint, out_dir)
            + render_regions(regions, out_dir, base=base, joint=joint))


def _floats(base):
    """Base points as a float array (3, 2), or None."""
    if base is None:
        return None
    return np.array([[float(c) for c in a] for a in base])

"""Figures: one per octree figure of the paper, the same colour for a region or a domain everywhere,
legends beside the data, axis labels with units, every joint cell drawn, the phi seam marked.

The figures are built at depth 6 (a couple of seconds); pixels are not compared, the
figures' own artists are read (legend entries and colours, axes and labels).
"""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest

from intervalkin.app.animation import seam_crossings
from intervalkin.app.figures import PAPER_FIGURES
from intervalkin.app.figures_joint import joint_count_grid, joint_figures, thin_cells
from intervalkin.app.figures_workspace import paving_figures, region_figures
from intervalkin.app.palette import colour_of
from intervalkin.app.plotting import base_points, legend_colours, pyplot
from intervalkin.app.report_html import scene_figure
from intervalkin.app.scenes import joint_scenes, region_scenes
from intervalkin.app.units import JOINT_AXES, WORKSPACE_AXES
from intervalkin.core.geometry import default_geometry
from intervalkin.paving.predicates import pave_workspace
from intervalkin.space.joint_space import joint_paving
from intervalkin.space.singular_surface import pave_singular_layer

from .shared import chain, paper_folder


@pytest.fixture(scope="module")
def chain6():
    return chain(6)


@pytest.fixture(scope="module")
def region_figs(chain6):
    figs = region_figures(chain6.regions, base_points(chain6.geometry), chain6.joint)
    yield figs
    for f in figs.values():
        pyplot().close(f)


def _ids(fig, pattern: str) -> dict[int, str]:
    """{id: colour} of the legend entries of ``fig`` whose text matches ``pattern`` (group 1 = the id)."""
    out = {}
    for text, colour in legend_colours(fig).items():
        if m := re.match(pattern, text):
            out[int(m.group(1))] = colour
    return out


def test_a_region_has_one_colour_in_every_figure(chain6, region_figs):
    """Region k is drawn in colour_of('region', k) in the sections, the 3-D view, Fig. 13 and report.html.

    Would catch a figure that numbers its colours by position (the old 3-D view coloured the
    regions above one cell 0, 1, 2, ... whatever their ids).
    """
    slices = _ids(region_figs["basic_regions_slices.png"], r"^(\d+): W")
    view = _ids(region_figs["basic_regions_3d.png"], r"^region (\d+):")
    top = _ids(region_figs["top_cell_regions_3d.png"], r"^region (\d+):")
    html = {int(re.match(r"region (\d+)", t.name).group(1)): t.color
            for t in scene_figure(next(s for s in region_scenes(chain6.regions) if s.key == "basic_regions")).data}
    assert len(view) >= 5 and len(top) >= 2 and set(top) <= set(view) <= set(slices)
    for rid in slices:
        expected = colour_of("region", rid)
        assert slices[rid] == expected
        assert view.get(rid, expected) == expected and top.get(rid, expected) == expected
        assert html.get(rid, expected) == expected
    assert len(set(slices.values())) == len(slices)  # distinct regions, distinct colours


def test_a_domain_has_one_colour_in_every_figure(region_figs):
    slices = _ids(region_figs["uniqueness_domains_slices.png"], r"^domain (\d+):")
    view = _ids(region_figs["uniqueness_domains_3d.png"], r"^domain (\d+):")
    assert slices and set(view) <= set(slices)
    assert all(slices[d] == colour_of("domain", d) and view.get(d, slices[d]) == slices[d] for d in slices)


@pytest.mark.parametrize("name", ["basic_regions_slices.png", "basic_regions_3d.png", "top_cell_regions_3d.png",
                                  "uniqueness_domains_3d.png"])
def test_legends_stand_beside_the_axes_and_name_the_base_points(region_figs, name):
    """No legend overlaps an axes or its labels (it would cover data or a label); the workspace figures
    list the base points.  (Drawing is the slow part: the sections and the 3-D views, one of each kind.)"""
    for fig in [region_figs[name]]:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        for leg in fig.legends:
            box = leg.get_window_extent(renderer)
            for ax in fig.axes:
                assert not box.overlaps(ax.get_tightbbox(renderer)), (name, ax.get_title())
        assert any(t.startswith("base points A1, A2, A3") for t in legend_colours(fig)), name


def test_axes_are_labelled_with_units(region_figs, chain6):
    """x, y in length units and phi in degrees on the workspace figures; rho in length units in joint space."""
    fig = region_figs["basic_regions_slices.png"]
    labels = {ax.get_xlabel() for ax in fig.axes} | {ax.get_ylabel() for ax in fig.axes}
    assert {WORKSPACE_AXES[0], WORKSPACE_AXES[1]} <= labels
    ax3 = region_figs["basic_regions_3d.png"].axes[0]
    assert (ax3.get_xlabel(), ax3.get_ylabel(), ax3.get_zlabel()) == WORKSPACE_AXES
    assert np.allclose(ax3.get_zlim(), (-180.0, 180.0))
    figs = joint_figures(chain6.joint)
    try:
        j3 = figs["joint_3d.png"].axes[0]
        assert (j3.get_xlabel(), j3.get_ylabel(), j3.get_zlabel()) == JOINT_AXES
        assert JOINT_AXES[0] in {ax.get_xlabel() for ax in figs["joint_slices.png"].axes}
    finally:
        for f in figs.values():
            pyplot().close(f)


def test_the_joint_view_draws_every_cell_with_solutions(chain6):
    """Every cell with a certified count > 0 that covers two grid cells is a layer of the joint view
    (the old view drew only the 6-solution cell), coloured by its count."""
    _, cells = joint_scenes(chain6.joint)
    cell_grid, _, _, _ = joint_count_grid(chain6.joint, bits=6)
    sizes = np.bincount(cell_grid[cell_grid >= 0], minlength=max(c.id for c in chain6.joint.cells) + 1)
    expected = {c.id for c in chain6.joint.cells if c.count > 0 and sizes[c.id] >= 2}
    drawn = {int(re.match(r"cell (\d+):", ly.name).group(1)) for ly in cells.layers}
    assert drawn == expected and {2, 4, 6} <= {ly.key for ly in cells.layers}
    assert all(ly.colour == colour_of("count", ly.key) for ly in cells.layers)


def test_thin_cells_are_small_or_flat(chain6):
    cell, _, _, _ = joint_count_grid(chain6.joint)
    for cid in thin_cells(chain6.joint, cell):
        idx = np.argwhere(cell == cid)
        extent = idx.max(axis=0) - idx.min(axis=0) + 1
        assert chain6.joint.cells[cid].count > 0
        assert len(idx) < 0.005 * cell.size or extent.min() <= 4


def test_every_paper_figure_is_written_without_warnings():
    """render_paper_figures writes every file of PAPER_FIGURES (Figs. 2, 3, 5, 6, 9-13) as a PNG, silently."""
    assert sorted(f.number for f in PAPER_FIGURES) == [2, 3, 5, 6, 9, 10, 11, 12, 13]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out, summary = paper_folder(6)
    written = [out / f for f in summary["files"] if f.startswith("figures/")]
    names = {p.name for p in written}
    for f in PAPER_FIGURES:
        assert set(f.files) <= names, f.number
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in written)


def test_shallow_pavings_draw_empty_sets():
    """At depth 3 nothing is certified in some sets (no joint cell has a count): the figures say so
    instead of failing or warning."""
    g = default_geometry()
    joint = joint_paving(g, pave_singular_layer(g, 3), 3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        figs = {**paving_figures(pave_workspace(g, 3)), **joint_figures(joint)}
    for f in figs.values():
        pyplot().close(f)


def test_an_adaptive_joint_paving_is_drawn_and_exported(tmp_path, joint_paving_4):
    """The joint figures and joint.vtu read a direct (adaptive) joint paving as well as the voxel grid:
    every cell with solutions is drawn, in its count's colour.  (joint_paving_4, tests/conftest.py:
    ``pave_joint_space`` of the paper's manipulator at depth 4, shared with space/test_joint_paving.py.)"""
    from intervalkin.app.vtk_export import read_vtu, write_joint_vtu

    joint = joint_paving_4
    _, cells = joint_scenes(joint)
    assert {ly.key for ly in cells.layers} == {c.count for c in joint.cells if c.count > 0}
    figs = joint_figures(joint)
    for f in figs.values():
        pyplot().close(f)
    mesh = read_vtu(write_joint_vtu(tmp_path / "joint.vtu", joint))
    assert set(np.unique(mesh.cell_data["cell"][0])) == {c.id for c in joint.cells + joint.fragments}


def test_seam_crossings_are_found_and_placed_on_the_seam():
    """A path that turns through phi = pi is cut there; both ends of the cut are returned, at +pi and -pi."""
    phi = np.linspace(2.8, 3.6, 9)  # crosses pi between samples 4 and 5
    path = np.stack([np.linspace(0, 8, 9), np.zeros(9), phi], axis=1)
    (a, b), = seam_crossings(path)
    assert a[2] == math.pi and b[2] == -math.pi and a[0] == b[0]
    assert 3.0 < a[0] < 5.0  # interpolated between the samples around the jump
    assert seam_crossings(path[:4]) == []


def test_the_animation_moves_the_platform_over_a_fixed_background(tmp_path):
    """The GIF has one frame per requested pose; the platform moves from frame to frame, while the base
    points, the path and the axes (the background rendered once) stay where they are."""
    from types import SimpleNamespace

    from PIL import Image

    from intervalkin.app.animation import _render_animation

    t = np.linspace(0.0, 1.0, 200)
    path = np.stack([10 + 3 * np.cos(6 * t), 5 + 3 * np.sin(6 * t), 2 * t - 1], axis=1)
    traj = SimpleNamespace(samples=path, i_from=2, i_to=3, aspect="WA1", sign=1)
    (gif,) = _render_animation(traj, default_geometry(), tmp_path, 12)
    im = Image.open(gif)
    assert im.n_frames == 12
    frames = []
    for k in (0, 6, 11):
        im.seek(k)
        frames.append(np.asarray(im.convert("RGB"), dtype=np.int16))
    # the GIF palette is chosen per frame: a fixed pixel may change by a few units of colour, a moved one by far more
    diff = [np.abs(frames[0] - f).sum(axis=2) for f in frames[1:]]
    assert all((d > 48).mean() > 0.002 for d in diff)  # the platform and its legs moved
    # the frame's border (ticks, labels, outside the axes; the title is at the top) is the same in every frame
    border = np.zeros(diff[0].shape, dtype=bool)
    border[-40:, :] = border[:, :40] = True
    assert max(int(d[border].max()) for d in diff) <= 24

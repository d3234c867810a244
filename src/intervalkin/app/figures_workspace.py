"""The paper's workspace figures (3, 5, 6, 9, 10, 12, 13) from certified pavings.

Each ``figure_*`` function returns a matplotlib figure (the tests read its legend
colours); :func:`render_paving_figures` and :func:`render_region_figures` write them
as PNG files.  3-D views are the surfaces of :mod:`intervalkin.app.scenes`, x-y
sections are painted from the boxes themselves (:func:`~intervalkin.app.plotting.draw_slices`),
and thin basic regions get their own zoomed panel in the atlas (Fig. 10).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from intervalkin.app.boxes import fine_bounds, rasterise
from intervalkin.app.palette import colour_of
from intervalkin.app.plotting import (
    draw_base_points,
    draw_scene,
    draw_slices,
    legend_outside,
    new_figure,
    patch,
    pyplot,
    save_png,
    state_colour,
    workspace_bounds,
)
from intervalkin.app.scenes import Scene, paving_scenes, region_scenes, top_cell_scenes
from intervalkin.app.units import WORKSPACE_AXES
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving
from intervalkin.space.basic_region import RegionAnalysis
from intervalkin.space.singular_surface import may_be_singular

__all__ = ["figure_scene", "figure_slices", "figure_atlas", "figure_top_cell", "paving_figures", "region_figures",
           "save_figures", "render_paving_figures", "render_region_figures"]


def _floor_base(ax, base):
    """The base points on the floor of a 3-D workspace view (phi = -180 deg)."""
    return draw_base_points(ax, base, z=-180.0)


def figure_scene(scene: Scene, bounds: np.ndarray, title: str, panels=None, base=None, ncols_legend: int = 1):
    """A figure of one scene: one 3-D panel, or one per entry of ``panels``: (title, layers[, (elev, azim)]).

    Panels sit on a grid of at most three columns; the legend (every layer once, and
    the base points on the floor phi = -180 deg of workspace views) stands to the right.
    """
    panels = panels or [("", scene.layers)]
    ncols = min(3, len(panels))
    nrows = int(np.ceil(len(panels) / ncols))
    fig = new_figure(4.8 * ncols + 2.8, 4.4 * nrows + 0.6)
    handles, seen, floor = [], set(), None
    for k, panel in enumerate(panels):
        sub, layers = panel[0], panel[1]
        view = panel[2] if len(panel) > 2 else (22, -60)
        ax = fig.add_subplot(nrows, ncols, k + 1, projection="3d")
        for h in draw_scene(ax, scene, bounds, layers=layers, view=view):
            if h.get_label() not in seen:
                seen.add(h.get_label())
                handles.append(h)
        if scene.axes == WORKSPACE_AXES and base is not None:
            floor = _floor_base(ax, base)
        if sub:
            ax.set_title(sub, fontsize=9)
    fig.suptitle(title, fontsize=10)
    legend_outside(fig, handles + ([floor] if floor is not None else []), ncols=ncols_legend,
                   fontsize=7 if len(handles) > 12 else 8)
    return fig


def figure_slices(paving: Paving, codes: np.ndarray, colours, names, title: str, base=None, ncols_legend: int = 1):
    """Eight x-y sections at phi = -157.5 ... 157.5 deg; ``codes`` (per box, -1 not drawn) index ``colours``."""
    fig = new_figure(13.0, 5.9, dpi=100)
    axes = draw_slices(fig, paving, codes, colours, base=base)
    handles = [patch(c, n) for c, n in zip(colours, names)]
    hb = next((h for h in axes[0, 0].get_lines() if h.get_label().startswith("base points")), None)
    legend_outside(fig, handles + ([hb] if hb is not None else []), ncols=ncols_legend,
                   fontsize=7 if len(handles) > 12 else 8)
    fig.suptitle(title, fontsize=10)
    return fig


def _region_names(regions: RegionAnalysis) -> list[str]:
    return [f"{r.id}: {r.aspect}, cell {r.cell} ({r.cell_count} sol.)" for r in regions.regions]


def _phi_range(occupied: np.ndarray, phi0: float, step: float) -> str:
    """The phi range of a set from its occupied phi bins, read around the circle (a set may cross the seam)."""
    if occupied.all():
        return "φ: all angles"
    n = occupied.size
    # the longest run of empty bins, circularly: the set is the rest of the circle
    free = np.concatenate([~occupied, ~occupied])
    best, start, run = 0, 0, 0
    for i, f in enumerate(free):
        run = run + 1 if f else 0
        if run > best:
            best, start = run, i - run + 1
    first, last = (start + best) % n, (start - 1) % n
    lo, hi = phi0 + first * step, phi0 + (last + 1) * step
    return f"φ from {lo:.0f}° to {hi:.0f}°" + (" (across ±180°)" if first > last else "")


def figure_atlas(regions: RegionAnalysis, bits: int = 7):
    """One panel per basic region: its x-y shadow (the union over phi), zoomed in, with its phi range.

    Small and thin regions, lost among the others in the 3-D view, are as visible here
    as the big ones; a region without certified boxes at this depth says so.
    """
    p = regions.paving
    b = min(bits, p.depth)
    sel = regions.region >= 0
    lo, hi = fine_bounds(p.level[sel], p.ijk[sel], p.depth)
    grid = rasterise(lo, hi, regions.region[sel], p.depth, b)
    dom = workspace_bounds(p)
    step = (dom[:, 1] - dom[:, 0]) / (1 << b)
    n = max(len(regions.regions), 1)
    ncols = 7
    nrows = int(np.ceil(n / ncols))
    fig = new_figure(14, 2.2 * nrows + 0.6, dpi=100)
    axes = fig.subplots(nrows, ncols, squeeze=False)
    plt = pyplot()
    for ax, r in zip(axes.ravel(), regions.regions):
        mask = grid == r.id
        ax.set_title(f"region {r.id}: {r.aspect}, cell {r.cell}", fontsize=7, pad=2)
        ax.tick_params(labelsize=6)
        if not mask.any():
            ax.text(0.5, 0.5, "no certified box\nat this depth", ha="center", va="center", fontsize=7,
                    transform=ax.transAxes)
            ax.set_xticks([])
            ax.set_yticks([])
            continue
        shadow = mask.any(axis=2)
        cmap = plt.matplotlib.colors.ListedColormap(["white", colour_of("region", r.id)])
        ax.imshow(shadow.T.astype(int), origin="lower", cmap=cmap, vmin=0, vmax=1, interpolation="nearest",
                  extent=(dom[0, 0], dom[0, 1], dom[1, 0], dom[1, 1]))
        ii, jj = np.flatnonzero(shadow.any(axis=1)), np.flatnonzero(shadow.any(axis=0))
        pad = 2 * step[:2]
        ax.set_xlim(dom[0, 0] + ii[0] * step[0] - pad[0], dom[0, 0] + (ii[-1] + 1) * step[0] + pad[0])
        ax.set_ylim(dom[1, 0] + jj[0] * step[1] - pad[1], dom[1, 0] + (jj[-1] + 1) * step[1] + pad[1])
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel(_phi_range(mask.any(axis=(0, 1)), dom[2, 0], step[2]), fontsize=6, labelpad=1)
    for ax in axes.ravel()[len(regions.regions):]:
        ax.axis("off")
    fig.suptitle("Basic regions one by one: x-y shadow of each region (zoomed), with its φ range "
                 f"({WORKSPACE_AXES[0]} across, {WORKSPACE_AXES[1]} up)", fontsize=10)
    return fig


def figure_top_cell(regions: RegionAnalysis, joint, base=None):
    """Fig. 13: the basic regions above the richest joint cell (workspace) beside that cell (joint space)."""
    from intervalkin.app.figures_joint import joint_bounds

    scenes = top_cell_scenes(regions, joint)
    fig = new_figure(11.5, 4.9)
    handles = []
    if not scenes:
        ax = fig.add_subplot(1, 1, 1)
        ax.text(0.5, 0.5, "no joint cell carries certified regions at this depth", ha="center", va="center")
        ax.axis("off")
        return fig
    ws, js = scenes
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    handles += draw_scene(ax, ws, workspace_bounds(regions.paving))
    if base is not None:
        handles.append(_floor_base(ax, base))
    ax.set_title("in the workspace: one region per solution", fontsize=9)
    ax = fig.add_subplot(1, 2, 2, projection="3d")
    handles += draw_scene(ax, js, joint_bounds(joint))
    ax.set_title("in joint space: their common basic component", fontsize=9)
    fig.suptitle(ws.title, fontsize=10)
    legend_outside(fig, handles)
    return fig


def save_figures(figs: dict, out_dir) -> list[Path]:
    """Write each {file name: figure} as a PNG into ``out_dir`` and close it; returns the paths."""
    plt = pyplot()
    written = []
    for name, fig in figs.items():
        written.append(save_png(fig, Path(out_dir) / name))
        plt.close(fig)
    return written


def render_paving_figures(paving: Paving, out_dir, base=None) -> list[Path]:
    """Figs. 3, 5 and 6 (workspace, singular layer, aspects: 3-D and sections) into ``out_dir``."""
    return save_figures(paving_figures(paving, base), out_dir)


def render_region_figures(regions: RegionAnalysis, out_dir, base=None, joint=None) -> list[Path]:
    """Figs. 9, 10, 12 (and 13 when ``joint`` is given) into ``out_dir``."""
    return save_figures(region_figures(regions, base, joint), out_dir)


def paving_figures(paving: Paving, base=None) -> dict:
    """{file name: figure} of Figs. 3, 5 and 6."""
    lab = paving.labels
    bounds = workspace_bounds(paving)
    w, sing, asp = paving_scenes(paving)
    figs = {
        "workspace_3d.png": figure_scene(w, bounds, f"Workspace W, boxes certified inside (depth {paving.depth}); "
                                         "cf. the paper's Fig. 3", base=base),
        "singular_3d.png": figure_scene(sing, bounds, "Type-2 singular layer: det A = 0 not excluded; cf. Fig. 5",
                                        panels=[("seen from x > 0, y < 0", sing.layers),
                                                ("seen from x < 0, y > 0", sing.layers, (22, 120))], base=base),
        "aspects_3d.png": figure_scene(asp, bounds, "The two aspects (certified boxes); cf. Fig. 6",
                                       panels=[("WA1: det A > 0", asp.layers[:1]), ("WA2: det A < 0", asp.layers[1:])],
                                       base=base),
    }
    w_in, w_bd = lab["W"] == Label.INSIDE, lab["W"] == Label.BOUNDARY
    codes = np.where(w_in, 0, np.where(w_bd, 1, -1)).astype(np.int16)
    figs["workspace_slices.png"] = figure_slices(
        paving, codes, [state_colour("workspace"), state_colour("undecided")], ["W (certified)", "undecided"],
        f"Workspace W in x-y sections (depth {paving.depth}); cf. Fig. 3", base=base)
    codes = np.full(len(paving), -1, np.int16)
    codes[w_bd] = 3
    codes[may_be_singular(lab) & w_in] = 2
    codes[lab["WA1"] == Label.INSIDE] = 0
    codes[lab["WA2"] == Label.INSIDE] = 1
    figs["aspects_slices.png"] = figure_slices(
        paving, codes, [colour_of("aspect", "WA1"), colour_of("aspect", "WA2"), state_colour("singular"),
                        state_colour("undecided")],
        ["WA1 (det A > 0)", "WA2 (det A < 0)", "singular layer", "W undecided"],
        f"Aspects and singular layer in x-y sections (depth {paving.depth}); cf. Fig. 6", base=base)
    return figs


def region_figures(regions: RegionAnalysis, base=None, joint=None) -> dict:
    """{file name: figure} of Figs. 9, 10, 12, and 13 when ``joint`` is given."""
    p = regions.paving
    lab = p.labels
    bounds = workspace_bounds(p)
    char, reg, dom = region_scenes(regions)
    wa1 = [ly for ly in reg.layers if ly.group == "WA1"]
    wa2 = [ly for ly in reg.layers if ly.group == "WA2"]
    figs = {
        "characteristic_3d.png": figure_scene(char, bounds, "Singular layer and characteristic surface S_c1 of WA1 "
                                              "(outer enclosures); cf. Fig. 9", base=base),
        "basic_regions_3d.png": figure_scene(reg, bounds, f"{len(regions.regions)} basic regions; cf. Fig. 10",
                                             panels=[("in WA1", wa1), ("in WA2", wa2)], base=base, ncols_legend=1),
        "uniqueness_domains_3d.png": figure_scene(
            dom, bounds, f"{len(regions.domains)} uniqueness domains; cf. Fig. 12",
            panels=[(ly.name.split(":")[0], [ly]) for ly in dom.layers] or None, base=base),
        "basic_regions_atlas.png": figure_atlas(regions),
    }
    in_aspect = (lab["WA1"] == Label.INSIDE) | (lab["WA2"] == Label.INSIDE)
    sc = in_aspect & (lab["off_Sc"] != Label.INSIDE)
    codes = np.full(len(p), -1, np.int16)
    codes[(lab["WA1"] == Label.INSIDE) & ~sc] = 0
    codes[(lab["WA2"] == Label.INSIDE) & ~sc] = 1
    codes[sc] = 2
    codes[may_be_singular(lab)] = 3
    figs["characteristic_slices.png"] = figure_slices(
        p, codes, [colour_of("aspect", "WA1"), colour_of("aspect", "WA2"), state_colour("characteristic"),
                   state_colour("singular")],
        ["WA1 off S_c", "WA2 off S_c", "S_c may be met", "singular layer"],
        f"Characteristic surfaces S_c1, S_c2 (outer enclosure) in x-y sections (depth {p.depth}); cf. Fig. 9",
        base=base)
    n = len(regions.regions)
    sing = may_be_singular(lab)
    codes = np.where(regions.region >= 0, regions.region, np.where(sc, n, np.where(sing, n + 1, -1))).astype(np.int16)
    figs["basic_regions_slices.png"] = figure_slices(
        p, codes, [colour_of("region", i) for i in range(n)] + [state_colour("undecided"), state_colour("singular")],
        _region_names(regions) + ["S_c may be met, or sheet undecided", "singular layer"],
        f"{n} basic regions in x-y sections (depth {p.depth}); cf. Fig. 10", base=base, ncols_legend=2 if n > 14 else 1)
    m = len(regions.domains)
    codes = np.where(regions.domain >= 0, regions.domain,
                     np.where(in_aspect, m, np.where(sing, m + 1, -1))).astype(np.int16)
    figs["uniqueness_domains_slices.png"] = figure_slices(
        p, codes, [colour_of("domain", i) for i in range(m)] + [state_colour("undecided"), state_colour("singular")],
        [f"domain {i}: regions {', '.join(map(str, d))}" for i, d in enumerate(regions.domains)]
        + ["in an aspect, no domain", "singular layer"],
        f"{m} uniqueness domains in x-y sections (depth {p.depth}); cf. Fig. 12", base=base)
    if joint is not None:
        figs["top_cell_regions_3d.png"] = figure_top_cell(regions, joint, base=base)
    return figs

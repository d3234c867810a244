"""The paper's joint-space figures (2 and 11) from the certified joint cells.

* Fig. 2, ``joint_space_3d.png``: the joint box minus the cells certified to have no solution,
  an outer enclosure of the joint space Q (two views).
* Fig. 11, ``joint_3d.png``: every drawn cell, one 3-D panel per certified count (2, 4, 6),
  coloured by count (the same colours as everywhere), each cell marked with its id.
* Fig. 11, ``joint_slices.png``: rho3-sections of the cells by count, and a zoomed
  panel on each thin cell (small or flat cells, invisible at the scale of the box).

Each ``figure_*`` function returns the matplotlib figure; :func:`render_joint_figures`
writes them.  A joint space is read through :func:`~intervalkin.app.boxes.joint_boxes`
(uniform voxels or an adaptive paving alike).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from intervalkin.app.boxes import cell_by_id, joint_boxes, rasterise
from intervalkin.app.palette import colour_of
from intervalkin.app.plotting import draw_scene, legend_outside, new_figure, patch, pyplot, save_png, state_colour
from intervalkin.app.scenes import joint_scenes
from intervalkin.app.units import JOINT_AXES

__all__ = ["joint_bounds", "joint_count_grid", "thin_cells", "figure_joint_space", "figure_joint_cells",
           "figure_joint_slices", "joint_figures", "render_joint_figures"]

#: The counts drawn, in order, and the codes of the section images (0: may meet g(S)).
_COUNTS = (-1, 0, 2, 4, 6)


def joint_bounds(joint) -> np.ndarray:
    """The joint box (3, 2) as floats (axis limits)."""
    return joint_boxes(joint).domain


def joint_count_grid(joint, bits: int = 7):
    """(cell grid, count grid, origin, spacing) on (2**bits)^3 cells; -1 where the box may meet g(S)."""
    jb = joint_boxes(joint)
    b = min(bits, jb.depth)
    cell = rasterise(jb.lo, jb.hi, jb.columns["cell"], jb.depth, b)
    ids = cell_by_id(joint)
    table = np.full(max(ids, default=-1) + 2, -2, dtype=np.int32)  # -2 (the last entry): no cell
    for cid, c in ids.items():
        table[cid] = c.count
    count = table[cell]
    origin = jb.domain[:, 0]
    spacing = (jb.domain[:, 1] - jb.domain[:, 0]) / (1 << b)
    return cell, count, origin, spacing


def thin_cells(joint, cell_grid: np.ndarray, limit: int = 8) -> list[int]:
    """Cells with solutions that are hard to see at the scale of the joint box: a few grid cells, or flat.

    A cell is thin when it covers fewer than 0.5 % of the grid, or spans at most four grid
    cells along some axis; the largest such cells come first, at most ``limit`` of them.
    """
    sizes = np.bincount(cell_grid[cell_grid >= 0], minlength=max(cell_by_id(joint), default=-1) + 1)
    out = []
    for c in joint.cells:
        if c.count <= 0 or sizes[c.id] < 2:
            continue
        idx = np.argwhere(cell_grid == c.id)
        extent = idx.max(axis=0) - idx.min(axis=0) + 1
        if sizes[c.id] < 0.005 * cell_grid.size or extent.min() <= 4:
            out.append(c.id)
    out.sort(key=lambda cid: -sizes[cid])
    return out[:limit]


def figure_joint_space(joint):
    """Fig. 2: the joint space Q, enclosed by the joint box minus the cells certified empty (two views)."""
    (q, _) = joint_scenes(joint)
    fig = new_figure(11.5, 4.9)
    bounds = joint_bounds(joint)
    handles = []
    for k, view in enumerate(((22, -60), (22, 120))):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        handles = draw_scene(ax, q, bounds, view=view)
        ax.set_title(f"seen from azimuth {view[1]}°", fontsize=9)
    fig.suptitle("Joint space Q: the joint box minus the cells certified to have no solution "
                 "(an outer enclosure); cf. the paper's Fig. 2", fontsize=10)
    legend_outside(fig, handles + [patch("white", "cut away: certified 0 solutions")])
    return fig


def figure_joint_cells(joint):
    """Fig. 11: the cells (basic components) in one 3-D panel per certified count, ids at their centres."""
    _, cells = joint_scenes(joint)
    counts = sorted({int(ly.key) for ly in cells.layers}) or [2, 4, 6]
    fig = new_figure(4.3 * len(counts) + 2.8, 4.9)
    bounds = joint_bounds(joint)
    handles = []
    for k, n in enumerate(counts):
        ax = fig.add_subplot(1, len(counts), k + 1, projection="3d")
        layers = [ly for ly in cells.layers if ly.key == n]
        draw_scene(ax, cells, bounds, layers=layers, alpha=0.85)
        for ly in layers:
            centre = ly.surface.vertices.mean(axis=0)
            ax.text(*centre, ly.name.split(":")[0].replace("cell ", "#"), fontsize=7, zorder=10)
        ax.set_title(f"{n} solutions: {len(layers)} cell(s)", fontsize=9)
        handles.append(patch(colour_of("count", n), f"{n} solutions"))
    note = f" ({cells.note})" if cells.note else ""
    fig.suptitle(f"Joint cells by certified number of solutions{note}; cf. Fig. 11", fontsize=10)
    legend_outside(fig, handles, title="cells with")
    return fig


def figure_joint_slices(joint, bits: int = 7):
    """Fig. 11 in sections: eight rho3-slices coloured by certified count, then a zoom on each thin cell."""
    from matplotlib.colors import ListedColormap

    cell, count, origin, spacing = joint_count_grid(joint, bits)
    n = cell.shape[0]
    codes = np.zeros(count.shape, dtype=np.int16)  # 0: may meet g(S)
    for j, k in enumerate(_COUNTS):
        codes[count == k] = j + 1
    colours = [state_colour("undecided")] + [colour_of("count", k) for k in _COUNTS]
    names = ["may meet g(S)", "solve not completed", "0 solutions", "2 solutions", "4 solutions", "6 solutions"]
    cmap = ListedColormap(colours)
    thin = thin_cells(joint, cell)
    rows = 2 + (len(thin) + 3) // 4
    fig = new_figure(13.5, 2.9 * rows + 0.7, dpi=100)
    axes = fig.subplots(rows, 4, squeeze=False)
    ext = (origin[0], origin[0] + n * spacing[0], origin[1], origin[1] + n * spacing[1])
    for k, (ax, kk) in enumerate(zip(axes[:2].ravel(), np.linspace(0, n - 1, 8).round().astype(int))):
        ax.imshow(codes[:, :, kk].T, origin="lower", cmap=cmap, vmin=0, vmax=len(colours) - 1,
                  interpolation="nearest", extent=ext)
        ax.set_title(f"ρ3 = {origin[2] + (kk + 0.5) * spacing[2]:.2f}", fontsize=8, pad=2)
        ax.tick_params(labelsize=7)
        if k % 4 == 0:
            ax.set_ylabel(JOINT_AXES[1], fontsize=8)
        if k >= 4 and not thin:
            ax.set_xlabel(JOINT_AXES[0], fontsize=8)
    zooms = axes[2:].ravel()
    for ax, cid in zip(zooms, thin):
        mask = cell == cid
        kk = int(np.argmax(mask.sum(axis=(0, 1))))
        ii, jj = np.flatnonzero(mask[:, :, kk].any(axis=1)), np.flatnonzero(mask[:, :, kk].any(axis=0))
        ax.imshow(codes[:, :, kk].T, origin="lower", cmap=cmap, vmin=0, vmax=len(colours) - 1,
                  interpolation="nearest", extent=ext)
        ax.contour(mask[:, :, kk].T.astype(float), levels=[0.5], colors="k", linewidths=0.8, extent=ext)
        pad = 4
        ax.set_xlim(origin[0] + (ii[0] - pad) * spacing[0], origin[0] + (ii[-1] + 1 + pad) * spacing[0])
        ax.set_ylim(origin[1] + (jj[0] - pad) * spacing[1], origin[1] + (jj[-1] + 1 + pad) * spacing[1])
        c = cell_by_id(joint)[cid]
        ax.set_title(f"zoom: cell {cid} ({c.count} sol.) at ρ3 = {origin[2] + (kk + 0.5) * spacing[2]:.2f}",
                     fontsize=8, pad=2)
        ax.tick_params(labelsize=7)
        ax.set_xlabel(JOINT_AXES[0], fontsize=8)
    for r in range(2, rows):
        axes[r, 0].set_ylabel(JOINT_AXES[1], fontsize=8)
    for ax in zooms[len(thin):]:
        ax.axis("off")
    handles = [patch(c, t) for c, t in zip(colours, names)]
    if thin:
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], color="k", lw=0.8, label="outline of the zoomed cell"))
    legend_outside(fig, handles)
    fig.suptitle("Joint space in ρ3-sections: certified number of solutions of each cell; cf. Fig. 11"
                 + (f" (bottom row: the {len(thin)} thin cells, zoomed)" if thin else ""), fontsize=10)
    return fig


def joint_figures(joint) -> dict:
    """{file name: figure} of Figs. 2 and 11: joint_space_3d.png, joint_3d.png, joint_slices.png."""
    return {"joint_space_3d.png": figure_joint_space(joint), "joint_3d.png": figure_joint_cells(joint),
            "joint_slices.png": figure_joint_slices(joint)}


def render_joint_figures(joint, out_dir) -> list[Path]:
    """Figs. 2 and 11 into ``out_dir``."""
    plt = pyplot()
    written = []
    for name, fig in joint_figures(joint).items():  # one at a time would be lighter, but they are three
        written.append(save_png(fig, Path(out_dir) / name))
        plt.close(fig)
    return written

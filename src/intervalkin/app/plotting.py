"""The one matplotlib setup of the package and the drawing pieces every figure shares.

* :func:`pyplot` selects the Agg backend before pyplot is imported (matplotlib is
  imported on first use only), :func:`save_png` writes a figure atomically through
  :mod:`intervalkin.core.files`, :func:`new_figure` uses the constrained layout
  (tick labels never run into the titles of the row below).
* :func:`draw_scene` draws the shaded surfaces of a :class:`~intervalkin.app.scenes.Scene`
  on 3-D axes, :func:`slice_image` / :func:`draw_slices` draw x-y sections of a
  paving at several phi, with the base points A1, A2, A3.
* :func:`legend_outside` puts a legend beside the axes, never over the data.

Colours come from :func:`intervalkin.app.palette.colour_of` only; phi is shown in
degrees and lengths in the unit of the geometry (:mod:`intervalkin.app.units`).
The paper's figures are assembled in :mod:`intervalkin.app.figures_workspace` and
:mod:`intervalkin.app.figures_joint`, and listed in :mod:`intervalkin.app.figures`.  The figures are pictures
of certified labels, not certificates themselves.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from intervalkin.app.palette import colour_of
from intervalkin.app.scenes import Scene
from intervalkin.app.units import WORKSPACE_AXES, phi_factor
from intervalkin.core.files import atomic_write_bytes
from intervalkin.paving.tree import Paving

__all__ = ["pyplot", "save_png", "new_figure", "legend_outside", "patch", "draw_scene", "slice_image",
           "draw_slices", "base_points", "draw_base_points", "SLICE_PHIS", "legend_colours", "workspace_bounds",
           "state_colour"]

#: phi of the slices (radians): the centres of eight equal sectors, -157.5 deg ... 157.5 deg.
SLICE_PHIS = np.linspace(-np.pi, np.pi, 9)[:-1] + np.pi / 8

#: Direction of the light on the 3-D surfaces (axes scaled to a unit cube).
_LIGHT = np.array([-0.35, -0.55, 0.76])


def pyplot():
    """matplotlib.pyplot on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def save_png(fig, path, dpi="figure") -> Path:
    """Write ``fig`` as a PNG to ``path`` atomically (at the figure's own dpi unless given); returns the path.

    At the figure's own dpi on the Agg canvas, the canvas is drawn once and its pixels written: ``savefig`` with a
    layout engine draws the figure twice, laying it out each time, and half of a figure's time went into the
    constrained layout.  The pixels are those ``savefig`` would draw at that dpi."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    buf = io.BytesIO()
    if dpi == "figure" and type(fig.canvas) is FigureCanvasAgg:
        from matplotlib.image import imsave

        fig.canvas.draw()
        imsave(buf, np.asarray(fig.canvas.buffer_rgba()), format="png", origin="upper", dpi=fig.dpi)
    else:
        fig.savefig(buf, format="png", dpi=dpi)
    return atomic_write_bytes(path, buf.getvalue())


def new_figure(width: float, height: float, dpi: int = 110):
    """A figure with the constrained layout (titles, tick labels and outside legends never overlap)."""
    return pyplot().figure(figsize=(width, height), dpi=dpi, layout="constrained")


def patch(colour: str, label: str):
    """A legend entry: a filled square of ``colour``."""
    from matplotlib.patches import Patch

    return Patch(facecolor=colour, edgecolor="none", label=label)


def legend_outside(fig, handles, title: str | None = None, ncols: int = 1, where: str = "right", fontsize=8,
                   markerscale: float = 1.0):
    """A legend beside the axes (``where``: "right" or "bottom"), outside every axes of ``fig``.

    Figures with 3-D axes get a wider padding around their axes: the constrained layout
    under-counts the label of the vertical 3-D axis, which would otherwise run under the legend.
    """
    if any(getattr(ax, "name", "") == "3d" for ax in fig.axes):
        fig.get_layout_engine().set(w_pad=0.3)
    # "center": a legend at the top right would run into a long suptitle
    loc = "outside right center" if where == "right" else "outside lower center"
    return fig.legend(handles=handles, loc=loc, ncols=ncols, title=title, fontsize=fontsize,
                      title_fontsize=fontsize + 1, frameon=False, markerscale=markerscale)


def legend_colours(fig) -> dict[str, str]:
    """{legend text: colour as #rrggbb} of every legend of ``fig`` (what the tests compare across figures)."""
    from matplotlib.colors import to_hex

    out = {}
    for leg in fig.legends + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]:
        for h, t in zip(leg.legend_handles, leg.get_texts()):
            colour = h.get_facecolor() if hasattr(h, "get_facecolor") else h.get_color()
            if isinstance(colour, np.ndarray) and colour.ndim == 2:
                colour = colour[0]
            out[t.get_text()] = to_hex(colour)
    return out


def base_points(geometry) -> np.ndarray:
    """The base points A1, A2, A3 as floats (3, 2), for drawing."""
    return np.array([[float(c) for c in a] for a in geometry.base])


def draw_base_points(ax, base: np.ndarray | None, z: float | None = None, names: bool = True):
    """Mark A1, A2, A3 on 2-D axes (or on 3-D axes at height ``z``); returns the legend handle (None if no base)."""
    if base is None:
        return None
    if z is None:
        (h,) = ax.plot(base[:, 0], base[:, 1], "k^", ms=5, mec="white", mew=0.6, label="base points A1, A2, A3")
        if names:
            for i, (x, y) in enumerate(base, 1):
                # kept out of the layout: with an outside legend, annotations derail the constrained layout
                ax.annotate(f"A{i}", (x, y), textcoords="offset points", xytext=(3, 3), fontsize=6).set_in_layout(False)
        return h
    # drawn after the surfaces and above them (no depth sorting): a reference mark, always visible
    ax.computed_zorder = False
    (h,) = ax.plot(base[:, 0], base[:, 1], np.full(len(base), z), "k^", ms=5, ls="none", zorder=10,
                   label="base points A1, A2, A3 (on the floor)")
    return h


def _shaded(colour: str, normals: np.ndarray) -> np.ndarray:
    from matplotlib.colors import to_rgb

    n = normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    light = _LIGHT / np.linalg.norm(_LIGHT)
    shade = 0.5 + 0.5 * np.abs(n @ light)  # two-sided: the inside of a cut-open surface is lit too
    return np.clip(np.asarray(to_rgb(colour))[None, :] * shade[:, None], 0, 1)


def draw_scene(ax, scene: Scene, bounds: np.ndarray, alpha: float = 1.0, layers=None, view=(22, -60)) -> list:
    """Draw the surfaces of ``scene`` (all layers, or those given) on 3-D axes; returns legend handles.

    ``bounds`` (3, 2) are the axis limits in the scene's units.  All triangles go in one
    collection, so matplotlib sorts them by depth together (layers hide each other properly).
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    bounds = np.asarray(bounds, dtype=np.float64)
    span = bounds[:, 1] - bounds[:, 0]
    tris, colours, handles = [], [], []
    for layer in scene.layers if layers is None else layers:
        s = layer.surface
        handles.append(patch(layer.colour, layer.name))
        if s.is_empty():
            continue
        t = s.vertices[s.faces]
        unit = (t - bounds[:, 0]) / span  # normals in the drawn (cubic) proportions
        normals = np.cross(unit[:, 1] - unit[:, 0], unit[:, 2] - unit[:, 0])
        tris.append(t)
        colours.append(_shaded(layer.colour, normals))
    if tris:
        faces = np.concatenate(colours)
        # edges in the face colour: without them, anti-aliasing leaves hairline gaps between triangles
        coll = Poly3DCollection(np.concatenate(tris), facecolors=faces, edgecolors=faces, linewidths=0.25,
                                alpha=alpha, zorder=1)
        ax.add_collection3d(coll)
    ax.set_xlim(*bounds[0])
    ax.set_ylim(*bounds[1])
    ax.set_zlim(*bounds[2])
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel(scene.axes[0], fontsize=8, labelpad=2)
    ax.set_ylabel(scene.axes[1], fontsize=8, labelpad=2)
    ax.set_zlabel(scene.axes[2], fontsize=8, labelpad=2)
    ax.tick_params(labelsize=7, pad=0)
    if scene.axes == WORKSPACE_AXES:
        ax.set_zticks([-180, -90, 0, 90, 180])
    ax.view_init(elev=view[0], azim=view[1])
    if not tris:
        ax.text2D(0.5, 0.5, "no certified box at this depth", transform=ax.transAxes, ha="center", fontsize=8)
    return handles


def workspace_bounds(paving: Paving) -> np.ndarray:
    """Axis limits (3, 2) of a workspace paving in drawing units (phi in degrees)."""
    dom = np.array(paving.domain, dtype=np.float64)
    dom[2] *= phi_factor("deg")
    return dom


def slice_image(paving: Paving, phi: float, codes: np.ndarray, resolution: int = 256) -> np.ndarray:
    """Raster (resolution x resolution, rows = y) of integer ``codes`` over x-y at angle ``phi`` (radians).

    Boxes are painted from coarse to fine; a code of -1 is not painted; pixels met
    by no painted box are -1.
    """
    dom = paving.domain
    img = np.full((resolution, resolution), -1, dtype=np.int16)
    hit = (paving.lo[:, 2] <= phi) & (phi <= paving.hi[:, 2]) & (codes >= 0)
    idx = np.flatnonzero(hit)
    idx = idx[np.argsort(-(paving.hi[idx, 0] - paving.lo[idx, 0]), kind="stable")]
    sx = resolution / (dom[0, 1] - dom[0, 0])
    sy = resolution / (dom[1, 1] - dom[1, 0])
    i0 = np.floor((paving.lo[idx, 0] - dom[0, 0]) * sx + 0.5).astype(int)
    i1 = np.maximum(np.floor((paving.hi[idx, 0] - dom[0, 0]) * sx + 0.5).astype(int), i0 + 1)
    j0 = np.floor((paving.lo[idx, 1] - dom[1, 0]) * sy + 0.5).astype(int)
    j1 = np.maximum(np.floor((paving.hi[idx, 1] - dom[1, 0]) * sy + 0.5).astype(int), j0 + 1)
    for size in np.unique(i1 - i0):  # one size per octree level: few sizes
        sel = np.flatnonzero(i1 - i0 == size)
        if size > 6:  # few big boxes: one slice assignment each
            for m in sel:
                img[j0[m]:j1[m], i0[m]:i1[m]] = codes[idx[m]]
            continue
        for di in range(size):
            for dj in range(size):
                img[np.clip(j0[sel] + dj, 0, resolution - 1), np.clip(i0[sel] + di, 0, resolution - 1)] = \
                    codes[idx[sel]]
    return img


def draw_slices(fig, paving: Paving, codes: np.ndarray, colours, phis=SLICE_PHIS, base=None, ncols: int = 4,
                resolution: int = 256):
    """x-y sections of the boxes at each phi on a grid of axes; ``codes`` index ``colours``; returns the axes.

    Axis labels (with units) on the outer panels only; the base points are drawn in
    every panel (their legend entry is the caller's, through :func:`draw_base_points`).
    """
    from matplotlib.colors import ListedColormap

    nrows = int(np.ceil(len(phis) / ncols))
    axes = fig.subplots(nrows, ncols, squeeze=False, sharex=True, sharey=True)
    cmap = ListedColormap(["white"] + list(colours))
    dom = paving.domain
    for k, (ax, phi) in enumerate(zip(axes.ravel(), phis)):
        img = slice_image(paving, float(phi), codes, resolution)
        ax.imshow(img + 1, origin="lower", cmap=cmap, vmin=0, vmax=len(colours), interpolation="nearest",
                  extent=(dom[0, 0], dom[0, 1], dom[1, 0], dom[1, 1]))
        ax.set_title(f"φ = {np.degrees(phi):.1f}°", fontsize=8, pad=2)
        ax.tick_params(labelsize=7)
        ax.set_aspect("equal")
        draw_base_points(ax, base, names=k == 0)
        if k % ncols == 0:
            ax.set_ylabel(WORKSPACE_AXES[1], fontsize=8)
        if k // ncols == nrows - 1:
            ax.set_xlabel(WORKSPACE_AXES[0], fontsize=8)
    for ax in axes.ravel()[len(phis):]:
        ax.axis("off")
    return axes


def state_colour(name: str) -> str:
    """Shorthand for ``colour_of("state", name)``."""
    return colour_of("state", name)

"""Figures of certified labels (matplotlib, Agg backend), and the one matplotlib setup of the package.

* Workspace paving, like the paper's Figures 3 (W), 5 (singular layer) and 6
  (aspects): 3-D scatters of box centres (subsampled, marker size growing with
  the box) over x, y, phi, and phi-slices, x-y images of the labels at several
  phi values, which read better than 3-D views (each box meeting the slice
  paints its (x, y) rectangle).
* Joint space (Figs. 2 and 11): cells coloured by certified solution count.
* Definition sets (Figs. 9, 10, 12, 13): characteristic surfaces, basic regions,
  uniqueness domains, the regions above the richest joint cell.

Colours: certified INSIDE boxes are solid, the undecided layer is grey or orange.
The figures are pictures of certified labels, not certificates themselves.

:func:`pyplot` selects the Agg backend before pyplot is imported (matplotlib is
imported on first use only); :func:`save_png` writes a figure atomically through
:mod:`intervalkin.core.files`.  The trajectory figures
(:mod:`intervalkin.app.animation`) use both.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from intervalkin.core.files import atomic_write_bytes
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving
from intervalkin.space.singular_surface import may_be_singular

__all__ = ['pyplot', 'save_png', 'render_3d', 'slice_image', 'render_slices', 'render_all', 'render_joint',
           'render_ids_3d', 'render_ids_slices', 'render_regions']

_WA1 = "#1f77b4"
_WA2 = "#d62728"
_W = "#2ca02c"
_UND = "#ff9f1c"


def pyplot():
    """matplotlib.pyplot on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def save_png(fig, path, dpi="figure") -> Path:
    """Write ``fig`` as a PNG to ``path`` atomically (at the figure's own dpi unless given); returns the path."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return atomic_write_bytes(path, buf.getvalue())


def _subsample(idx: np.ndarray, limit: int, rng) -> np.ndarray:
    if idx.size <= limit:
        return idx
    return np.sort(rng.choice(idx, size=limit, replace=False))


def _opaque_legend(ax, markerscale: float) -> bool:
    """A legend with opaque markers when some artist of ``ax`` has a label; whether one was drawn."""
    if not ax.get_legend_handles_labels()[0]:
        return False
    leg = ax.legend(loc="upper left", fontsize=8, markerscale=markerscale)
    for h in leg.legend_handles:
        h.set_alpha(1)
    return True


def render_3d(paving: Paving, layers, path, title: str, max_points: int = 40000, seed: int = 0):
    """Scatter of box centres in (x, y, phi) for each (mask, colour, name) layer; one PNG."""
    plt = pyplot()
    rng = np.random.default_rng(seed)
    fig = plt.figure(figsize=(7.5, 6.5), dpi=110)
    ax = fig.add_subplot(projection="3d")
    c = 0.5 * (paving.lo + paving.hi)
    w = (paving.hi - paving.lo)[:, 0]
    for mask, colour, name in layers:
        idx = _subsample(np.flatnonzero(mask), max_points, rng)
        if idx.size == 0:
            continue
        s = np.clip(w[idx] * 10.0, 3.0, 80.0)
        ax.scatter(c[idx, 0], c[idx, 1], c[idx, 2], s=s, color=colour, alpha=0.55, linewidths=0,
                   label=f"{name} ({np.count_nonzero(mask)} boxes)", depthshade=True)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("phi (rad)")
    ax.set_xlim(*paving.domain[0])
    ax.set_ylim(*paving.domain[1])
    ax.set_zlim(-np.pi, np.pi)
    ax.view_init(elev=22, azim=-60)
    ax.set_title(title, fontsize=11)
    if not _opaque_legend(ax, markerscale=4):
        ax.text2D(0.05, 0.95, "no certified box at this depth", transform=ax.transAxes, fontsize=9)
    fig.tight_layout()
    written = save_png(fig, path)
    plt.close(fig)
    return written


def slice_image(paving: Paving, phi: float, codes: np.ndarray, resolution: int = 256) -> np.ndarray:
    """Raster (resolution x resolution) of integer ``codes`` over x-y at angle ``phi``.

    Boxes are painted from coarse to fine; pixels not met by any box are -1.
    """
    dom = paving.domain
    img = np.full((resolution, resolution), -1, dtype=np.int16)
    hit = (paving.lo[:, 2] <= phi) & (phi <= paving.hi[:, 2])
    idx = np.flatnonzero(hit)
    idx = idx[np.argsort(-(paving.hi[idx, 0] - paving.lo[idx, 0]), kind="stable")]
    sx = resolution / (dom[0, 1] - dom[0, 0])
    sy = resolution / (dom[1, 1] - dom[1, 0])
    i0 = np.floor((paving.lo[idx, 0] - dom[0, 0]) * sx + 0.5).astype(int)
    i1 = np.floor((paving.hi[idx, 0] - dom[0, 0]) * sx + 0.5).astype(int)
    j0 = np.floor((paving.lo[idx, 1] - dom[1, 0]) * sy + 0.5).astype(int)
    j1 = np.floor((paving.hi[idx, 1] - dom[1, 0]) * sy + 0.5).astype(int)
    i1 = np.maximum(i1, i0 + 1)
    j1 = np.maximum(j1, j0 + 1)
    # paint with a difference trick per distinct box size (few sizes: one per level)
    for size in np.unique(i1 - i0):
        sel = np.flatnonzero(i1 - i0 == size)
        if size > 6:  # few big boxes: one slice assignment each
            for m in sel:
                img[j0[m]:j1[m], i0[m]:i1[m]] = codes[idx[m]]
            continue
        for di in range(size):
            for dj in range(size):
                ii = np.clip(i0[sel] + di, 0, resolution - 1)
                jj = np.clip(j0[sel] + dj, 0, resolution - 1)
                img[jj, ii] = codes[idx[sel]]
    return img


def render_slices(paving: Paving, codes: np.ndarray, palette, names, path, title: str,
                  phis=None, resolution: int = 256, base=None):
    """A grid of x-y slices at several phi values; ``codes`` index ``palette`` (0..k-1)."""
    plt = pyplot()
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    if phis is None:
        phis = np.linspace(-np.pi, np.pi, 9)[:-1] + np.pi / 8 * 0.5
    ncol = 4
    nrow = int(np.ceil(len(phis) / ncol))
    fig, axes = plt.subplots(nrow, ncol, figsize=(3.3 * ncol, 3.5 * nrow + 0.8), dpi=100, squeeze=False)
    cmap = ListedColormap(["white"] + list(palette))
    dom = paving.domain
    for ax, phi in zip(axes.ravel(), phis):
        img = slice_image(paving, float(phi), codes, resolution)
        ax.imshow(img + 1, origin="lower", cmap=cmap, vmin=0, vmax=len(palette), interpolation="nearest",
                  extent=(dom[0, 0], dom[0, 1], dom[1, 0], dom[1, 1]))
        ax.set_title(f"phi = {np.degrees(phi):.1f} deg", fontsize=9)
        ax.set_xticks([-30, 0, 30])
        ax.set_yticks([-30, 0, 30])
        ax.tick_params(labelsize=7)
        if base is not None:  # the base points A1, A2, A3
            ax.plot([float(a[0]) for a in base], [float(a[1]) for a in base], "k^", ms=4)
    for ax in axes.ravel()[len(phis):]:
        ax.axis("off")
    handles = [Patch(color=c, label=n) for c, n in zip(palette, names)]
    ncol = min(len(names), 10)
    rows = int(np.ceil(len(names) / ncol)) if names else 1
    fig.legend(handles=handles, loc="lower center", ncol=ncol, fontsize=8 if rows > 1 else 9, frameon=False)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout(rect=(0, 0.03 + 0.03 * rows, 1, 0.96), h_pad=1.6)
    written = save_png(fig, path)
    plt.close(fig)
    return written


def render_all(paving: Paving, out_dir, max_points: int = 40000, base=None) -> list[Path]:
    """Write W, singular layer and aspects as 3-D views and phi-slices into ``out_dir``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    W = paving.labels["W"]
    wa1 = paving.labels["WA1"] == Label.INSIDE
    wa2 = paving.labels["WA2"] == Label.INSIDE
    w_in = W == Label.INSIDE
    w_bd = W == Label.BOUNDARY
    sing = may_be_singular(paving.labels)
    files = [
        render_3d(paving, [(w_in, _W, "W (certified)")], out / "workspace_3d.png",
                  f"Workspace W, certified boxes (depth {paving.depth}; cf. paper Fig. 3)", max_points),
        render_3d(paving, [(sing & w_in, "#444444", "det A = 0 may occur, in W"),
                           (sing & w_bd, _UND, "... on W's undecided boundary")],
                  out / "singular_3d.png",
                  "Type-2 singular layer (det A undecided; cf. paper Fig. 5)", max_points),
        render_3d(paving, [(wa1, _WA1, "WA1: det A > 0"), (wa2, _WA2, "WA2: det A < 0")],
                  out / "aspects_3d.png", "Aspects, certified boxes (cf. paper Fig. 6)", max_points),
    ]
    # slices: W / undecided; aspects / singular / undecided
    codes_w = np.where(w_in, 0, np.where(w_bd, 1, -1)).astype(np.int16)
    files.append(render_slices(paving, codes_w, [_W, _UND], ["W certified", "undecided"],
                               out / "workspace_slices.png", f"Workspace W, phi-slices (depth {paving.depth})", base=base))
    codes_a = np.full(len(paving), -1, np.int16)
    codes_a[w_bd] = 3
    codes_a[sing & w_in] = 2
    codes_a[wa1] = 0
    codes_a[wa2] = 1
    files.append(render_slices(paving, codes_a, [_WA1, _WA2, "#222222", "#bbbbbb"],
                               ["WA1 (det A > 0)", "WA2 (det A < 0)", "singular layer", "W undecided"],
                               out / "aspects_slices.png", f"Aspects and singular layer, phi-slices (depth {paving.depth})",
                               base=base))
    return files


# --------------------------------------------------------------------------------------
# Joint space (paper Figs. 2 and 11) and the definition sets (Figs. 9, 10, 12, 13)
# --------------------------------------------------------------------------------------
_COUNT_COLOURS = {0: "#dddddd", 2: "#8ecae6", 4: "#ffb703", 6: "#d62828"}


def _palette(k: int) -> list[str]:
    plt = pyplot()
    cmaps = [plt.get_cmap("tab20"), plt.get_cmap("tab20b"), plt.get_cmap("tab20c")]
    colours = []
    for cm in cmaps:
        colours.extend(cm(i) for i in range(20))
    # greys read as "undecided": leave them out
    colours = [c for c in colours if max(c[:3]) - min(c[:3]) > 0.08]
    return [colours[i % len(colours)] for i in range(max(k, 1))]


def render_joint(joint, out_dir, max_points: int = 60000, seed: int = 0) -> list[Path]:
    """Joint-space cells coloured by certified solution count: a 3-D view and rho3-slices."""
    plt = pyplot()
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cols = joint.columns()
    count = cols["count"]
    centre = 0.5 * (cols["lo"] + cols["hi"])
    rng = np.random.default_rng(seed)
    fig = plt.figure(figsize=(7.5, 6.5), dpi=110)
    ax = fig.add_subplot(projection="3d")
    for k in (2, 4, 6):
        idx = _subsample(np.flatnonzero(count == k), max_points // 3, rng)
        if idx.size:
            ax.scatter(*centre[idx].T, s={2: 1, 4: 2, 6: 4}[k], c=_COUNT_COLOURS[k],
                       alpha={2: 0.06, 4: 0.2, 6: 0.6}[k], linewidths=0,
                       label=f"{k} solutions ({np.count_nonzero(count == k)} voxels)")
    ax.set_xlabel("rho1")
    ax.set_ylabel("rho2")
    ax.set_zlabel("rho3")
    ax.set_title(f"Joint space: certified cells by number of solutions\n(voxels 2^-{joint.depth}; cf. paper Figs. 2, 11)",
                 fontsize=10)
    _opaque_legend(ax, markerscale=5)  # none when no cell has a certified count (shallow depths)
    fig.tight_layout()
    p3 = save_png(fig, out / "joint_3d.png")
    plt.close(fig)

    n = joint.n
    grid = count.reshape(n, n, n)
    codes = np.full(grid.shape, 0, dtype=np.int16)  # 0 undecided
    for j, k in enumerate((0, 2, 4, 6)):
        codes[grid == k] = j + 1
    palette = ["#555555", _COUNT_COLOURS[0], _COUNT_COLOURS[2], _COUNT_COLOURS[4], _COUNT_COLOURS[6]]
    names = ["may meet g(S)", "0 solutions", "2 solutions", "4 solutions", "6 solutions"]
    ks = np.linspace(0, n - 1, 8).round().astype(int)
    fig, axes = plt.subplots(2, 4, figsize=(13, 7.4), dpi=100)
    r0, h = joint.approx_grid()
    ext = (r0[0], r0[0] + n * h[0], r0[1], r0[1] + n * h[1])
    for a, kk in zip(axes.ravel(), ks):
        a.imshow(codes[:, :, kk].T, origin="lower", cmap=ListedColormap(palette), vmin=0, vmax=4,
                 interpolation="nearest", extent=ext)
        a.set_title(f"rho3 = {r0[2] + (kk + 0.5) * h[2]:.2f}", fontsize=9)
        a.set_xlabel("rho1", fontsize=8)
        a.set_ylabel("rho2", fontsize=8)
        a.tick_params(labelsize=7)
    fig.legend(handles=[Patch(color=c, label=t) for c, t in zip(palette, names)], loc="lower center", ncol=5,
               fontsize=9, frameon=False)
    fig.suptitle("Joint space, rho3-slices: certified solution count per voxel", fontsize=11)
    fig.tight_layout(rect=(0, 0.05, 1, 0.96))
    ps = save_png(fig, out / "joint_slices.png")
    plt.close(fig)
    return [p3, ps]


def render_ids_3d(paving: Paving, ids: np.ndarray, path, title: str, names=None, max_points: int = 60000,
                  seed: int = 0) -> Path:
    """3-D scatter of box centres coloured by an integer id per box (-1 not drawn)."""
    k = int(ids.max()) + 1 if ids.size and ids.max() >= 0 else 0
    k = max(k, len(names) if names else 0)
    pal = _palette(k)
    layers = [(ids == i, pal[i], names[i] if names else f"{i}") for i in range(k)]
    return render_3d(paving, layers, path, title, max_points=max_points, seed=seed)


def render_ids_slices(paving: Paving, ids: np.ndarray, path, title: str, names=None, extra=None, base=None) -> Path:
    """phi-slices coloured by an integer id per box; ``extra`` = (mask, colour, name) drawn underneath."""
    k = int(ids.max()) + 1 if ids.size and ids.max() >= 0 else 0
    k = max(k, len(names) if names else 0)
    pal = list(_palette(k))
    nm = list(names) if names else [f"{i}" for i in range(k)]
    codes = ids.astype(np.int16).copy()
    if extra is not None:
        mask, colour, name = extra
        codes = np.where((codes < 0) & mask, k, codes).astype(np.int16)
        pal.append(colour)
        nm.append(name)
    short = [n.split(":")[0] for n in nm] if len(nm) > 10 else nm
    return render_slices(paving, codes, pal, short, path, title, base=base)


def render_regions(analysis, out_dir, base=None) -> list[Path]:
    """The paper's Figures 9, 10, 12 and 13 from a :class:`~intervalkin.space.basic_region.RegionAnalysis`."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    p = analysis.paving
    files = []
    in_aspect = (p.labels["WA1"] == Label.INSIDE) | (p.labels["WA2"] == Label.INSIDE)
    sc = in_aspect & (p.labels["off_Sc"] != Label.INSIDE)
    sing = may_be_singular(p.labels)
    codes = np.full(len(p), -1, np.int16)
    codes[(p.labels["WA1"] == Label.INSIDE) & ~sc] = 0
    codes[(p.labels["WA2"] == Label.INSIDE) & ~sc] = 1
    codes[sc] = 2
    codes[sing] = 3
    files.append(render_slices(p, codes, [_WA1, _WA2, "#ffb703", "#222222"],
                               ["WA1 off S_c", "WA2 off S_c", "may meet S_c (characteristic)", "singular layer"],
                               out / "characteristic_slices.png",
                               f"Characteristic surfaces S_c1, S_c2 (outer enclosure; cf. paper Fig. 9), depth {p.depth}",
                               base=base))
    files.append(render_3d(p, [(sc & (p.labels["WA1"] == Label.INSIDE), "#ffb703", "S_c1 enclosure"),
                               (sing & (p.labels["W"] == Label.INSIDE), "#222222", "singular layer")],
                           out / "characteristic_3d.png", "Characteristic surface of WA1 and singular layer (Fig. 9)"))
    names = [f"{r.id}: {r.aspect} cell {r.cell} ({r.cell_count} sol.)" for r in analysis.regions]
    files.append(render_ids_slices(p, analysis.region, out / "basic_regions_slices.png",
                                   f"{len(analysis.regions)} basic regions (cf. paper Fig. 10)", names,
                                   extra=(sc, "#eeeeee", "undecided"), base=base))
    files.append(render_ids_3d(p, analysis.region, out / "basic_regions_3d.png",
                               "Basic regions (cf. paper Fig. 10)", names))
    dnames = [f"domain {i}" for i in range(len(analysis.domains))]
    files.append(render_ids_slices(p, analysis.domain, out / "uniqueness_domains_slices.png",
                                   f"{len(analysis.domains)} uniqueness domains (cf. paper Fig. 12)", dnames,
                                   extra=(in_aspect, "#eeeeee", "undecided"), base=base))
    files.append(render_ids_3d(p, analysis.domain, out / "uniqueness_domains_3d.png",
                               "Uniqueness domains (cf. paper Fig. 12)", dnames))
    if analysis.regions:
        top = max(analysis.regions, key=lambda r: (r.cell_count, r.n_boxes)).cell
        sel = [r.id for r in analysis.regions if r.cell == top]
        ids = np.where(np.isin(analysis.region, sel), analysis.region, -1)
        remap = {rid: i for i, rid in enumerate(sel)}
        ids = np.array([remap.get(int(v), -1) for v in ids], dtype=np.int32) if len(sel) else ids
        files.append(render_ids_3d(p, ids, out / "top_cell_regions_3d.png",
                                   f"The {len(sel)} basic regions above cell {top} (cf. paper Fig. 13)",
                                   [f"region {rid} ({analysis.regions[rid].aspect})" for rid in sel]))
    return files

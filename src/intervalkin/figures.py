"""PNG renderings of a workspace paving (matplotlib, Agg backend, imported lazily).

* 3-D views like the paper's Figures 3 (W), 5 (singular layer) and 6 (aspects):
  scatter of box centres (subsampled, marker size growing with the box), x, y, phi axes.
* phi-slices: x-y images of the labels at several phi values, which read better
  than 3-D views; each box meeting the slice paints its (x, y) rectangle.

Colours: certified INSIDE boxes are solid, the undecided layer is grey or orange.
The figures are pictures of certified labels, not certificates themselves.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .paving import Label, Paving

__all__ = ["render_all", "render_3d", "render_slices", "slice_image"]

_WA1 = "#1f77b4"
_WA2 = "#d62728"
_W = "#2ca02c"
_UND = "#ff9f1c"


def _plt():
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def _subsample(idx: np.ndarray, limit: int, rng) -> np.ndarray:
    if idx.size <= limit:
        return idx
    return np.sort(rng.choice(idx, size=limit, replace=False))


def render_3d(paving: Paving, layers, path, title: str, max_points: int = 40000, seed: int = 0):
    """Scatter of box centres in (x, y, phi) for each (mask, colour, name) layer; one PNG."""
    plt = _plt()
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
        ax.scatter(c[idx, 0], c[idx, 1], c[idx, 2], s=s, c=colour, alpha=0.55, linewidths=0,
                   label=f"{name} ({np.count_nonzero(mask)} boxes)", depthshade=True)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("phi (rad)")
    ax.set_xlim(*paving.domain[0])
    ax.set_ylim(*paving.domain[1])
    ax.set_zlim(-np.pi, np.pi)
    ax.view_init(elev=22, azim=-60)
    ax.set_title(title, fontsize=11)
    leg = ax.legend(loc="upper left", fontsize=8, markerscale=4)
    for h in leg.legend_handles:
        h.set_alpha(1)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return Path(path)


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
                  phis=None, resolution: int = 256):
    """A grid of x-y slices at several phi values; ``codes`` index ``palette`` (0..k-1)."""
    plt = _plt()
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
        ax.plot([0, 15.91, 0], [0, 0, 10], "k^", ms=4)
    for ax in axes.ravel()[len(phis):]:
        ax.axis("off")
    handles = [Patch(color=c, label=n) for c, n in zip(palette, names)]
    fig.legend(handles=handles, loc="lower center", ncol=len(names), fontsize=9, frameon=False)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout(rect=(0, 0.05, 1, 0.96), h_pad=1.6)
    fig.savefig(path)
    plt.close(fig)
    return Path(path)


def render_all(paving: Paving, out_dir, max_points: int = 40000) -> list[Path]:
    """Write W, singular layer and aspects as 3-D views and phi-slices into ``out_dir``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    W = paving.labels["W"]
    D = paving.labels["det_positive"]
    wa1 = paving.labels["WA1"] == Label.INSIDE
    wa2 = paving.labels["WA2"] == Label.INSIDE
    w_in = W == Label.INSIDE
    w_bd = W == Label.BOUNDARY
    sing = (W != Label.OUTSIDE) & (D == Label.BOUNDARY)
    files = [
        render_3d(paving, [(w_in, _W, "W (certified)")], out / "workspace_3d.png",
                  f"Workspace W, certified boxes (depth {paving.depth}; cf. paper Fig. 3)", max_points),
        render_3d(paving, [(sing & w_in, "#444444", "det A = 0 may occur, in W"),
                           (sing & w_bd, _UND, "... on W's undecided boundary")],
                  out / "singular_3d.png",
                  f"Type-2 singular layer (det A undecided; cf. paper Fig. 5)", max_points),
        render_3d(paving, [(wa1, _WA1, "WA1: det A > 0"), (wa2, _WA2, "WA2: det A < 0")],
                  out / "aspects_3d.png", f"Aspects, certified boxes (cf. paper Fig. 6)", max_points),
    ]
    # slices: W / undecided; aspects / singular / undecided
    codes_w = np.where(w_in, 0, np.where(w_bd, 1, -1)).astype(np.int16)
    files.append(render_slices(paving, codes_w, [_W, _UND], ["W certified", "undecided"],
                               out / "workspace_slices.png", f"Workspace W, phi-slices (depth {paving.depth})"))
    codes_a = np.full(len(paving), -1, np.int16)
    codes_a[w_bd] = 3
    codes_a[sing & w_in] = 2
    codes_a[wa1] = 0
    codes_a[wa2] = 1
    files.append(render_slices(paving, codes_a, [_WA1, _WA2, "#222222", "#bbbbbb"],
                               ["WA1 (det A > 0)", "WA2 (det A < 0)", "singular layer", "W undecided"],
                               out / "aspects_slices.png", f"Aspects and singular layer, phi-slices (depth {paving.depth})"))
    return files

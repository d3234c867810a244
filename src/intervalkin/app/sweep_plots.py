"""Plots of a sweep: the counts and the volumes of each analysed design against the swept parameters.

The first parameter is the x axis; each value of the second (if any) is one line; further
parameters are folded into the line labels.  Counts are drawn as found (solid, dots) with their
certified lower bound (dashed, same colour); an exact count has both on one line.  Designs that
failed or are degenerate have no point.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Sequence

from intervalkin.app.plotting import new_figure, pyplot, save_png
from intervalkin.sweeps.table import COUNT_NAMES, VOLUME_COLUMNS

__all__ = ["plot_sweep"]

_TITLES = {"aspects": "aspects", "joint_cells": "joint cells", "basic_regions": "basic regions",
           "uniqueness_domains": "uniqueness domains", "volume_W": "W (certified inside)",
           "volume_WA1": "det A > 0 (WA1)", "volume_WA2": "det A < 0 (WA2)",
           "volume_largest_uniqueness_domain": "largest uniqueness domain", "volume_undecided": "undecided in W"}


def _series(rows: Sequence[Mapping[str, Any]], parameters: Sequence[str]) -> dict[str, list[Mapping[str, Any]]]:
    """The analysed rows grouped into lines (by every parameter but the first), each sorted along x."""
    x, rest = parameters[0], parameters[1:]
    lines: dict[str, list[Mapping[str, Any]]] = {}
    for r in rows:
        if r.get("status") != "ok":
            continue
        label = ", ".join(f"{p} = {r[p]:g}" for p in rest) or "designs"
        lines.setdefault(label, []).append(r)
    return {k: sorted(v, key=lambda r: r[x]) for k, v in lines.items()}


def plot_sweep(rows: Sequence[Mapping[str, Any]], parameters: Sequence[str], folder: str | Path,
               name: str = "") -> list[Path]:
    """Write ``counts.png`` and ``volumes.png`` into ``folder``; returns their paths."""
    plt = pyplot()
    folder = Path(folder)
    lines = _series(rows, parameters)
    x = parameters[0]
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    written = []
    for fname, names, draw in (("counts.png", COUNT_NAMES, _draw_count), ("volumes.png", VOLUME_COLUMNS, _draw_volume)):
        ncols = 2 if len(names) == 4 else 3
        fig = new_figure(4.0 * ncols, 3.0 * ((len(names) + ncols - 1) // ncols) + 0.4, dpi=80)
        axes = fig.subplots((len(names) + ncols - 1) // ncols, ncols, squeeze=False).ravel()
        for ax, col in zip(axes, names):
            for i, (label, pts) in enumerate(lines.items()):
                draw(ax, [r[x] for r in pts], pts, col, colours[i % len(colours)], label)
            ax.set_title(_TITLES[col], fontsize=10)
            ax.set_xlabel(x, fontsize=9)
            ax.grid(alpha=0.3)
        for ax in axes[len(names):]:
            ax.set_visible(False)
        handles, labels = axes[0].get_legend_handles_labels()
        if handles:
            fig.legend(handles, labels, loc="outside lower center", ncols=min(len(labels), 4), fontsize=8)
        what = "counts: found (solid), certified lower bound (dashed)" if fname == "counts.png" else \
            "volumes (x, y, phi in radians): certified boxes"
        fig.suptitle(f"{name}: {what}" if name else what, fontsize=11)
        written.append(save_png(fig, folder / fname))
        plt.close(fig)
    return written


def _draw_count(ax, xs, pts, col, colour, label) -> None:
    from matplotlib.ticker import MaxNLocator

    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax.plot(xs, [r[f"{col}_found"] for r in pts], "o-", color=colour, label=label, ms=4)
    ax.plot(xs, [r[f"{col}_lower"] for r in pts], "--", color=colour, lw=1)


def _draw_volume(ax, xs, pts, col, colour, label) -> None:
    ax.plot(xs, [r[col] for r in pts], "o-", color=colour, label=label, ms=4)

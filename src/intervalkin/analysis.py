"""The whole workspace chain for one geometry, writing one output folder.

``run_pave`` (the ``intervalkin pave`` command) paves W, the sign of det A and the
aspects, finds the aspects as connected components, and writes::

    DIR/pavings/workspace.npz    boxes and labels (format: intervalkin.export)
    DIR/pavings/workspace.vtu    the same as a VTK unstructured grid of hexahedra
    DIR/figures/*.png            3-D views and phi-slices
    DIR/summary.json             counts, volumes, components, timings, what is certified
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from .errors import InputError
from .paving import Label, Paving, check_depth, shares_face

__all__ = ["run_pave", "pave_summary", "CERTIFIED_NOTE", "ProgressBar"]

CERTIFIED_NOTE = {
    "labels": "Every INSIDE / OUTSIDE box label is proved with outward-rounded interval arithmetic "
              "(W: rho_min <= rho_i <= rho_max on the whole box; det_sign: det A > 0 or < 0 on the whole box). "
              "Undecided boxes are reported as such and counted in the 'boundary' volumes.",
    "volumes": "inside volume is a certified inner bound, inside + boundary a certified outer bound "
               "of the true volume (up to float summation).",
    "connected": "Each component is a union of face-adjacent certified boxes (phi wraps): certified connected.",
    "distinct": "Components of opposite det A signs lie in different aspects (the sign is the witness). "
                "Components of the same sign are NOT proved distinct: they may join through the undecided layer; "
                "their count is an upper bound of the aspects of that sign found at this depth.",
}


class ProgressBar:
    """A plain text bar on stderr, one update per paving level."""

    def __init__(self, stream=None, width: int = 30):
        self.stream = stream if stream is not None else sys.stderr
        self.width = width
        self.t0 = time.perf_counter()

    def __call__(self, st: dict) -> None:
        done = (st["level"] + 1) / (st["depth"] + 1)
        n = int(round(done * self.width))
        self.stream.write(
            f"\rpaving [{'#' * n}{'.' * (self.width - n)}] level {st['level']}/{st['depth']}"
            f"  {st['boxes']:>9,d} boxes  {time.perf_counter() - self.t0:6.1f} s"
        )
        if st["level"] == st["depth"] or st["split"] == 0:
            self.stream.write("\n")
        self.stream.flush()


def pave_summary(paving: Paving, info: list[dict], timings: dict) -> dict:
    """The summary.json document of a workspace paving."""
    def block(name):
        return {"boxes": paving.count_by_label(name), "volume": paving.volume_by_label(name)}

    comps = {}
    for name, sign in (("WA1", 1), ("WA2", -1)):
        mine = [d for d in info if d["sign"] == sign]
        comps[name] = {
            "det_sign": sign,
            "components": len(mine),
            "volumes": [d["volume"] for d in mine],
            "boxes": [d["boxes"] for d in mine],
            "ids": [d["id"] for d in mine],
        }
    W = paving.labels["W"]
    sing = (W != Label.OUTSIDE) & (paving.labels["det_positive"] == Label.BOUNDARY)
    return {
        "depth": paving.depth,
        "domain": paving.domain.tolist(),
        "leaf_width": (np.ldexp(paving.domain[:, 1] - paving.domain[:, 0], -paving.depth)).tolist(),
        "boxes": len(paving),
        "boxes_evaluated": int(sum(s["boxes"] for s in paving.stats)),
        "W": block("W"),
        "WA1": block("WA1"),
        "WA2": block("WA2"),
        "singular_layer": {"boxes": int(np.count_nonzero(sing)), "volume": float(paving.volume()[sing].sum())},
        "components": comps,
        "undecided_volume_per_level": [
            {"level": s["level"], "W": s["undecided_volume"]["W"], "boxes": s["boxes"], "seconds": s["seconds"]}
            for s in paving.stats
        ],
        "timings_seconds": timings,
        "certified": CERTIFIED_NOTE,
    }


def _table(summary: dict) -> str:
    rows = [f"{'set':<6}{'inside':>12}{'undecided':>12}{'outside':>12}   (volume, x*y*phi)"]
    for name in ("W", "WA1", "WA2"):
        v = summary[name]["volume"]
        rows.append(f"{name:<6}{v['inside']:>12.2f}{v['boundary']:>12.2f}{v['outside']:>12.2f}")
    c = summary["components"]
    rows.append(
        f"components: WA1 (det A > 0) {c['WA1']['components']}, WA2 (det A < 0) {c['WA2']['components']}"
        f"  (largest volumes {c['WA1']['volumes'][:1]}, {c['WA2']['volumes'][:1]})"
    )
    t = summary["timings_seconds"]
    rows.append(f"depth {summary['depth']}: {summary['boxes']} boxes, paving {t['paving']:.2f} s, total {t['total']:.2f} s")
    return "\n".join(rows)


def run_pave(geometry_path, depth, out, figures: bool = True, progress: bool = True) -> int:
    """Pave W, det A sign and the aspects at ``depth`` and write everything into ``out``.

    Validates ``depth`` (integer 1..MAX_DEPTH, memory estimate against
    MemAvailable) before any work; returns the exit status 0.
    """
    from .export import paving_columns, write_json, write_npz, write_vtu
    from .geometry import geometry_from_option
    from .predicates import aspect_components, pave_workspace

    depth = check_depth(depth)
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out: {str(out)!r} exists and is not a folder")
    geometry = geometry_from_option(geometry_path)
    t0 = time.perf_counter()
    paving = pave_workspace(geometry, depth, progress=ProgressBar() if progress else None)
    t1 = time.perf_counter()
    edges = shares_face(paving.level, paving.ijk, paving.depth)
    aspect, info = aspect_components(paving, edges)
    t2 = time.perf_counter()
    write_npz(out / "pavings" / "workspace.npz", paving, aspect)
    cols = paving_columns(paving, aspect)
    write_vtu(out / "pavings" / "workspace.vtu", paving.lo, paving.hi,
              {k: cols[k] for k in ("in_workspace", "det_sign", "aspect", "depth")})
    t3 = time.perf_counter()
    fig_files = []
    if figures:
        from .figures import render_all

        fig_files = render_all(paving, out / "figures")
    t4 = time.perf_counter()
    timings = {"paving": t1 - t0, "components": t2 - t1, "export": t3 - t2, "figures": t4 - t3, "total": t4 - t0}
    summary = pave_summary(paving, info, timings)
    summary["geometry"] = geometry.name
    summary["files"] = ["pavings/workspace.npz", "pavings/workspace.vtu"] + [f"figures/{f.name}" for f in fig_files]
    write_json(out / "summary.json", summary)
    sys.stdout.write(_table(summary) + "\n")
    return 0

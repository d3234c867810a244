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
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import InputError
from .paving import Label, Paving, check_depth, shares_face

__all__ = ["run_pave", "pave_summary", "CERTIFIED_NOTE", "ProgressBar", "Analysis", "analyse", "run_analyze",
           "chain_summary", "write_chain", "DEFAULT_DEPTH"]

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
    from .export import paving_columns, write_json, write_npz, write_vtu_paving
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
    write_vtu_paving(out / "pavings" / "workspace.vtu", paving,
                     {k: cols[k] for k in ("in_workspace", "det_sign", "aspect", "depth")},
                     mask=paving.labels["W"] != Label.OUTSIDE)
    t3 = time.perf_counter()
    fig_files = []
    if figures:
        from .figures import render_all

        fig_files = render_all(paving, out / "figures", base=geometry.base)
    t4 = time.perf_counter()
    timings = {"paving": t1 - t0, "components": t2 - t1, "export": t3 - t2, "figures": t4 - t3, "total": t4 - t0}
    summary = pave_summary(paving, info, timings)
    summary["geometry"] = geometry.name
    summary["files"] = ["pavings/workspace.npz", "pavings/workspace.vtu"] + [f"figures/{f.name}" for f in fig_files]
    write_json(out / "summary.json", summary)
    sys.stdout.write(_table(summary) + "\n")
    return 0


# ======================================================================================
# The whole chain: workspace, singular surface, joint cells, regions, domains
# ======================================================================================
MARKER = ".intervalkin-output"
from . import DEFAULT_DEPTH  # noqa: E402  (about a minute on two cores)
MAX_CHAIN_DEPTH = 9


class Stages:
    """Stage names and timings on stderr (silent when quiet)."""

    def __init__(self, quiet: bool = False, stream=None):
        self.quiet = quiet
        self.stream = stream if stream is not None else sys.stderr
        self.t0 = time.perf_counter()
        self.timings: dict[str, float] = {}
        self._name = None
        self._start = 0.0

    def start(self, name: str) -> None:
        self._name, self._start = name, time.perf_counter()
        if not self.quiet:
            self.stream.write(f"[{time.perf_counter() - self.t0:6.1f} s] {name} ...\n")
            self.stream.flush()

    def done(self) -> None:
        self.timings[self._name] = time.perf_counter() - self._start

    def bar(self):
        return None if self.quiet else ProgressBar(self.stream)


def check_chain_depth(depth) -> int:
    """A user depth for the chain: an integer in 3..MAX_CHAIN_DEPTH whose singular layer fits in memory."""
    if isinstance(depth, bool) or not isinstance(depth, int) or not 3 <= depth <= MAX_CHAIN_DEPTH:
        raise InputError(f"--depth: expected an integer in 3..{MAX_CHAIN_DEPTH}, got {depth!r}")
    check_depth(depth + 1)
    return depth


def chain_depths(depth: int) -> tuple[int, int, int]:
    """(workspace depth, singular-layer depth, joint depth) for a user depth."""
    return depth, depth + 1, min(depth - 1, 7)


@dataclass(frozen=True, eq=False)
class Analysis:
    """The definition sets of one manipulator, as certified pavings and counts."""

    geometry: object
    depth: int
    singular_depth: int
    joint_depth: int
    n_singular_boxes: int
    joint: object
    regions: object
    timings: dict
    refinement: tuple = ()


def _singular_and_joint(geometry, singular_depth: int, joint_depth: int, st: Stages):
    """The singular layer at ``singular_depth`` and the joint cells on 2**joint_depth voxels per axis."""
    from .joint import joint_paving, pave_singular_layer

    st.start(f"singular layer (depth {singular_depth})")
    sing = pave_singular_layer(geometry, singular_depth, progress=st.bar())
    st.done()
    st.start(f"joint space: enclosure of g(S) and certified cells (2^{joint_depth} voxels per axis)")
    jp = joint_paving(geometry, sing, joint_depth)
    st.done()
    return sing, jp


def analyse(geometry, depth: int = DEFAULT_DEPTH, stages: Stages | None = None, refine_to: int | None = None) -> Analysis:
    """Run the chain geometry -> singular layer -> joint cells -> regions -> uniqueness domains.

    ``depth`` is the octree depth of the workspace paving; the singular layer
    is paved one level deeper and the joint grid has 2**min(depth - 1, 7) voxels
    per axis (see :func:`chain_depths`).

    ``refine_to``: while Proposition 1 is not seen in full (a sheet above a
    counted cell holds no certified box), pave the regions one level deeper, up
    to this depth.  The paver only splits undecided boxes, so a deeper level
    refines near the characteristic surfaces, the singular layer and the joint
    limits, not the whole domain.  ``Analysis.refinement`` records each try and
    why it stopped.
    """
    from .regions import analyse_regions

    check_chain_depth(depth)
    st = stages or Stages(quiet=True)
    dw, ds, dj = chain_depths(depth)
    sing, jp = _singular_and_joint(geometry, ds, dj, st)
    st.start(f"workspace, aspects, characteristic surfaces, basic regions (depth {dw})")
    ra = analyse_regions(geometry, jp, dw, progress=st.bar())
    st.done()
    history = [{"depth": dw, "consistent": ra.consistent, "basic_regions": len(ra.regions)}]
    if refine_to is not None:
        if isinstance(refine_to, bool) or not isinstance(refine_to, int) or not dw <= refine_to <= MAX_CHAIN_DEPTH:
            raise InputError(f"--refine-to: expected an integer in {dw}..{MAX_CHAIN_DEPTH}, got {refine_to!r}")
        while not ra.consistent and dw < refine_to:
            dw += 1
            st.start(f"refining where Proposition 1 is not yet seen in full: regions at depth {dw}")
            ra = analyse_regions(geometry, jp, dw, progress=st.bar())
            st.done()
            history.append({"depth": dw, "consistent": ra.consistent, "basic_regions": len(ra.regions)})
    if ra.consistent:
        history[-1]["stopped"] = "consistent: every sheet above every counted cell holds certified boxes"
    elif refine_to is None:
        history[-1]["stopped"] = "not consistent at this depth; no refinement asked (--refine-to)"
    else:
        history[-1]["stopped"] = f"limit reached (depth {dw}) before consistency"
    return Analysis(geometry, dw, ds, dj, len(sing), jp, ra, dict(st.timings), tuple(history))


def joint_summary(jp) -> dict:
    """The joint-space part of summary.json."""
    return {
        "depth": jp.depth,
        "voxels_per_axis": jp.n,
        "cells": [c.to_json() for c in jp.cells],
        "volume_by_count": jp.volume_by_count(),
        "undecided_share": float(jp.marked.mean()),
        "singular_boxes": jp.n_singular_boxes,
        "possibly_joined_cells": [list(p) for p in jp.joinable],
        "certified": {
            "counts": "each cell is a face-connected set of voxels certified off the outer enclosure of g(S); "
                      "its count and aspect split come from one certified solve and hold at every point of it",
            "distinct": "cells with different counts are different components of the joint box minus g(S); "
                        "two cells with equal counts may be one true component joined through the undecided layer: "
                        "possibly_joined_cells lists the pairs separated only by a stretch of that layer",
        },
    }


def chain_summary(a: Analysis) -> dict:
    """summary.json of the whole chain (counts with their certification status first)."""
    ra = a.regions
    p = ra.paving
    counts = ra.counts()
    out = dict(counts)
    out.update(
        {
            "geometry": a.geometry.name,
            "depth": {"workspace": a.depth, "singular_layer": a.singular_depth, "joint": a.joint_depth},
            "W": {"boxes": p.count_by_label("W"), "volume": p.volume_by_label("W")},
            "WA1": {"boxes": p.count_by_label("WA1"), "volume": p.volume_by_label("WA1")},
            "WA2": {"boxes": p.count_by_label("WA2"), "volume": p.volume_by_label("WA2")},
            "aspect_components": list(ra.aspect_info),
            "joint": joint_summary(a.joint),
            "basic_region_list": [r.to_json() for r in ra.regions],
            "uniqueness_domain_list": [list(g) for g in ra.domains],
            "consistency": list(ra.consistency),
            "cells_without_regions": list(ra.unrealized_cells),
            "witnesses": [w.to_json() for w in ra.witnesses],
            "undecided_volume": {
                name: p.volume_by_label(name)["boundary"] for name in ("W", "WA1", "WA2")
            },
            "characteristic_layer_volume": float(
                p.volume()[((p.labels["WA1"] == Label.INSIDE) | (p.labels["WA2"] == Label.INSIDE))
                           & (p.labels["off_Sc"] != Label.INSIDE)].sum()
            ),
            "timings_seconds": a.timings,
            "refinement": list(a.refinement),
            "certified": CERTIFIED_NOTE,
        }
    )
    return out


def prepare_output_dir(out, force: bool) -> Path:
    """Create ``out`` or accept it when empty / an earlier intervalkin output; refuse otherwise."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out: {str(out)!r} exists and is not a folder")
    if out.is_dir() and any(out.iterdir()) and not (out / MARKER).exists() and not force:
        raise InputError(f"--out: {str(out)!r} is not empty and not an intervalkin output (use --force to write there)")
    try:
        out.mkdir(parents=True, exist_ok=True)
        for stale in out.rglob(".*.tmp"):  # left by a run that was killed outright
            stale.unlink()
        probe = out / f".{MARKER}.probe"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise InputError(f"--out: cannot write to {str(out)!r} ({exc.strerror or exc})") from None
    from .export import atomic_write_bytes

    atomic_write_bytes(out / MARKER, b"intervalkin output folder\n")
    return out


def write_chain(a: Analysis, out: Path, figures: bool = True, stages: Stages | None = None) -> dict:
    """Write pavings (npz, VTK), figures and summary.json of an analysis; returns the summary."""
    from .export import atomic_write_bytes, paving_columns, write_json, write_npz, write_vtu_paving

    st = stages or Stages(quiet=True)
    ra = a.regions
    p = ra.paving
    st.start("writing pavings (npz, VTK)")
    extra = {"basic_region": ra.region.astype(np.int32), "uniqueness_domain": ra.domain.astype(np.int32)}
    write_npz(out / "pavings" / "workspace.npz", p, ra.aspect, extra)
    cols = paving_columns(p, ra.aspect, extra)
    write_vtu_paving(out / "pavings" / "workspace.vtu", p,
                     {k: cols[k] for k in ("in_workspace", "det_sign", "aspect", "basic_region", "uniqueness_domain",
                                           "depth")},
                     # a viewable file: the basic regions and the singular layer (the npz holds every box)
                     mask=(ra.region >= 0) | ((p.labels["W"] == Label.INSIDE) & (p.labels["det_positive"] == Label.BOUNDARY)))
    jc = a.joint.columns()
    atomic_write_bytes(out / "pavings" / "joint.npz", _npz_bytes(jc))
    st.done()
    files = ["pavings/workspace.npz", "pavings/workspace.vtu", "pavings/joint.npz"]
    if figures:
        st.start("figures")
        from .figures import render_all, render_joint, render_regions

        base = a.geometry.base
        figs = (render_all(p, out / "figures", base=base) + render_joint(a.joint, out / "figures")
                + render_regions(ra, out / "figures", base=base))
        files += [f"figures/{f.name}" for f in figs]
        st.done()
    summary = chain_summary(a)
    summary["timings_seconds"] = {**a.timings, **st.timings}
    summary["files"] = files
    write_json(out / "summary.json", summary)
    return summary


def _npz_bytes(cols: dict) -> bytes:
    import io

    buf = io.BytesIO()
    np.savez_compressed(buf, **cols)
    return buf.getvalue()


def chain_table(summary: dict) -> str:
    """A short terminal table of the counts and their status."""
    def status(block):
        if block.get("exact"):
            return "exact"
        return f"found; certified lower bound {block['lower_bound']}"

    rows = [
        f"{'set':<22}{'count':>7}   status",
        f"{'aspects':<22}{summary['aspects']['count']:>7}   {status(summary['aspects'])}",
        f"{'basic regions':<22}{summary['basic_regions']['count']:>7}   {status(summary['basic_regions'])}",
        f"{'uniqueness domains':<22}{summary['uniqueness_domains']['count']:>7}   {status(summary['uniqueness_domains'])}"
        + ("  (minimal)" if summary["uniqueness_domains"].get("minimal") else ""),
    ]
    cells = [c for c in summary["joint"]["cells"] if c["count"] > 0 and c["voxels"] > 1]
    by = {}
    for c in cells:
        by.setdefault(c["count"], []).append(c["share"])
    rows.append("joint cells (count: number, share of the joint box): "
                + ", ".join(f"{k}: {len(v)} ({100 * sum(v):.1f}%)" for k, v in sorted(by.items())))
    u = summary["undecided_volume"]
    rows.append(f"undecided volume: W {u['W']:.1f}, WA1 {u['WA1']:.1f}, WA2 {u['WA2']:.1f}; "
                f"depth {summary['depth']['workspace']} (singular {summary['depth']['singular_layer']}, "
                f"joint {summary['depth']['joint']})")
    return "\n".join(rows)


def run_analyze(geometry_path, depth: int, out, force: bool = False, quiet: bool = False, as_json: bool = False,
                figures: bool = True, certificates: bool = True, paper: bool = False,
                refine_to: int | None = None) -> int:
    """``intervalkin analyze`` (and ``paper`` when paper=True): the whole chain into one folder."""
    import json

    from .geometry import default_geometry, geometry_from_option

    geometry = default_geometry() if paper else geometry_from_option(geometry_path)
    check_chain_depth(depth)
    out = prepare_output_dir(out, force)
    st = Stages(quiet=quiet)
    a = analyse(geometry, depth, st, refine_to=refine_to)
    summary = write_chain(a, out, figures=figures, stages=st)
    trajs = []
    if paper:  # before the certificates, which re-check these paths
        st.start("certified trajectories between Table 1's solutions 2, 3, 6")
        summary["trajectories"], trajs = _paper_trajectories(a, out, summary["files"])
        st.done()
    if certificates:
        st.start("certificates")
        cert_files = _write_certificates(a, out, trajectories=trajs)
        st.done()
        summary["files"] += cert_files
    if paper:
        st.start("paper report")
        from .paper import write_report

        summary["timings_seconds"] = {**summary["timings_seconds"], **st.timings,
                                      "total": time.perf_counter() - st.t0}

        summary["files"].append(write_report(a, summary, out, st.timings))
        st.done()
    summary["timings_seconds"] = {**summary["timings_seconds"], **st.timings,
                                  "total": time.perf_counter() - st.t0}
    from .export import write_json

    write_json(out / "summary.json", summary)
    if as_json:
        sys.stdout.write(json.dumps(summary) + "\n")
    elif not quiet:
        sys.stdout.write(chain_table(summary) + f"\nwritten to {out}/ in {summary['timings_seconds']['total']:.1f} s\n")
    return 0


def _write_certificates(a: Analysis, out: Path, trajectories=()) -> list[str]:
    """Certificates of the claims (written by :mod:`intervalkin.certificates` when present).

    ``trajectories``: :class:`~intervalkin.trajectory.Trajectory` objects, written
    as ``trajectory`` claims (the paper run passes its three Table 1 paths).
    """
    try:
        from .certificates import write_certificates
    except ImportError:  # pragma: no cover - the certificates module ships with the package
        return []
    from .dkp import solve

    dkp_results = []
    if a.geometry.name == "Wenger-Chablat 1997":
        from .dkp import parse_joint_vector
        from .paper import TABLE1_RHO

        dkp_results.append(solve(a.geometry, parse_joint_vector(a.geometry, TABLE1_RHO)))
    paths = write_certificates(out / "certificates", a.geometry, dkp_results=dkp_results, joint=a.joint,
                               regions=a.regions, trajectories=trajectories)
    return [f"certificates/{Path(p).name}" for p in paths]


def joint_table(jp) -> str:
    rows = [f"{'cell':>5}{'count':>7}{'WA1':>5}{'WA2':>5}{'voxels':>10}{'volume':>11}{'share':>8}   witness rho"]
    for c in jp.cells:
        if c.n_voxels < 2 and len(jp.cells) > 40:
            continue
        w = "-" if c.witness is None else ", ".join(f"{float(v):.4f}" for v in c.witness)
        cnt = str(c.count) if c.count >= 0 else "?"
        rows.append(f"{c.id:>5}{cnt:>7}{c.n_wa1:>5}{c.n_wa2:>5}{c.n_voxels:>10}{c.volume:>11.2f}{100 * c.share:>7.2f}%   ({w})")
    vb = jp.volume_by_count()
    rows.append("volume by count: " + ", ".join(f"{k}: {v:.1f}" for k, v in vb.items())
                + f"  (joint box volume {sum(vb.values()):.1f})")
    return "\n".join(rows)


def run_joint(geometry_path, depth: int, out, force: bool = False, quiet: bool = False, figures: bool = True) -> int:
    """``intervalkin joint``: the enclosure of g(S), the certified cells and their table."""
    from .export import atomic_write_bytes, write_json
    from .geometry import geometry_from_option

    if isinstance(depth, bool) or not isinstance(depth, int) or not 2 <= depth <= 8:
        raise InputError(f"--depth: expected an integer in 2..8 (voxels per axis 2**depth), got {depth!r}")
    geometry = geometry_from_option(geometry_path)
    out = prepare_output_dir(out, force)
    st = Stages(quiet=quiet)
    ds = min(depth + 2, 10)
    check_depth(ds)
    _, jp = _singular_and_joint(geometry, ds, depth, st)
    atomic_write_bytes(out / "pavings" / "joint.npz", _npz_bytes(jp.columns()))
    files = ["pavings/joint.npz"]
    if figures:
        st.start("figures")
        from .figures import render_joint

        files += [f"figures/{f.name}" for f in render_joint(jp, out / "figures")]
        st.done()
    summary = {"geometry": geometry.name, "singular_depth": ds, "joint": joint_summary(jp),
               "timings_seconds": st.timings, "files": files}
    write_json(out / "summary.json", summary)
    if not quiet:
        sys.stdout.write(joint_table(jp) + "\n")
    return 0


def run_label(geometry_path, pose, depth: int, source=None, as_json: bool = False) -> int:
    """``intervalkin label X Y PHI``: certified aspect, basic region and uniqueness domain of a pose."""
    import json
    from fractions import Fraction

    from .geometry import geometry_from_option

    try:
        exact = [Fraction(str(v)) for v in pose]
    except (ValueError, ZeroDivisionError):
        raise InputError(f"pose: expected three numbers X Y PHI, got {' '.join(map(str, pose))}") from None
    if source is not None:
        res = _label_from_npz(Path(source), exact)
        res["pose"] = [str(v) for v in pose]
    else:
        geometry = geometry_from_option(geometry_path)
        from .regions import label_pose

        a = analyse(geometry, depth)
        res = label_pose(a.regions, [str(v) for v in pose])
    if res["aspect"] in ("WA1", "WA2") and res["basic_region"] == "undecided":
        res["note"] = ("certified inside the aspect, but the box holding the pose may meet a characteristic "
                       "surface (its image meets the enclosure of g(S)), or its sheet is not identified; "
                       "a deeper --depth may decide it")
    elif res["in_workspace"] == "undecided":
        res["note"] = "the box holding the pose is on the undecided layer of W or of det A = 0"
    if as_json:
        sys.stdout.write(json.dumps(res) + "\n")
    else:
        for k in ("in_workspace", "aspect", "basic_region", "uniqueness_domain", "note"):
            if k not in res:
                continue
            sys.stdout.write(f"{k:<18} {res[k]}\n")
    return 0


def _label_from_npz(folder: Path, exact) -> dict:
    """Look a pose up in the workspace.npz of an earlier ``analyze`` / ``paper`` output."""
    from fractions import Fraction

    path = folder / "pavings" / "workspace.npz"
    try:
        with np.load(path) as z:
            cols = {k: z[k] for k in ("lo", "hi", "in_workspace", "det_sign", "basic_region", "uniqueness_domain")}
    except (OSError, KeyError, ValueError) as exc:
        raise InputError(f"--from: cannot read {str(path)!r} ({exc})") from None
    xf = np.array([float(v) for v in exact])
    near = np.flatnonzero(np.all((cols["lo"] <= xf + 1e-9) & (xf - 1e-9 <= cols["hi"]), axis=1))
    hit = [i for i in near if all(Fraction(float(cols["lo"][i, j])) <= exact[j] <= Fraction(float(cols["hi"][i, j]))
                                  for j in range(3))]
    res = {"pose": [str(v) for v in exact], "boxes": len(hit), "in_workspace": "undecided", "aspect": "undecided",
           "basic_region": "undecided", "uniqueness_domain": "undecided"}
    for i in hit:
        w = int(cols["in_workspace"][i])
        if w != 0:
            res["in_workspace"] = "yes" if w > 0 else "no"
        if w > 0 and cols["det_sign"][i] != 0:
            res["aspect"] = "WA1" if cols["det_sign"][i] > 0 else "WA2"
        if cols["basic_region"][i] >= 0:
            res["basic_region"] = int(cols["basic_region"][i])
        if cols["uniqueness_domain"][i] >= 0:
            res["uniqueness_domain"] = int(cols["uniqueness_domain"][i])
    if res["in_workspace"] == "no":
        res["aspect"] = res["basic_region"] = res["uniqueness_domain"] = "none (outside W)"
    return res


def _paper_trajectories(a: Analysis, out: Path, files: list[str]) -> tuple[list[dict], list]:
    """Certified non-singular paths between Table 1's solutions 2, 3 and 6 (paper section 3.2, Fig. 13).

    Returns the report entries (one per pair, failures included) and the
    :class:`~intervalkin.trajectory.Trajectory` objects found (for the certificates).
    """
    from .errors import IntervalkinError
    from .paper import TABLE1_RHO
    from .trajectory import trajectory, write_trajectory

    done, found = [], []
    for i, j in ((2, 3), (2, 6), (3, 6)):
        try:
            tr = trajectory(a.geometry, TABLE1_RHO, i, j, analysis=a.regions, joint=a.joint)
        except IntervalkinError as exc:
            done.append({"from": i, "to": j, "certified": False, "reason": str(exc)})
            continue
        folder = out / "trajectories" / f"{i}-{j}"
        for path in write_trajectory(tr, a.geometry, folder, paving=a.regions.paving, joint=a.joint):
            files.append(str(Path(path).relative_to(out)))
        doc = tr.to_json()
        doc["summary"] = tr.summary()
        doc["folder"] = f"trajectories/{i}-{j}"
        done.append(doc)
        found.append(tr)
    return done, found


def run_trajectory(geometry_path, rho, i_from: int, i_to: int, depth: int = 7, out=None,
                   as_json: bool = False, quiet: bool = False) -> int:
    """``intervalkin trajectory``: the chain at ``depth``, then a certified path between two solutions.

    The request is checked first (solutions of different aspects are refused at
    once, before any paving).
    """
    import json

    from .geometry import geometry_from_option
    from .trajectory import check_request, trajectory, write_trajectory

    geometry = geometry_from_option(geometry_path)
    check_request(geometry, rho, i_from, i_to)
    check_chain_depth(depth)
    if out is not None:
        out = prepare_output_dir(out, force=True) if Path(out).is_dir() and (Path(out) / MARKER).exists() \
            else prepare_output_dir(out, force=False)
    st = Stages(quiet=quiet or as_json)
    a = analyse(geometry, depth, st)
    st.start("certified path")
    traj = trajectory(geometry, rho, i_from, i_to, analysis=a.regions, joint=a.joint)
    st.done()
    if out is not None:
        write_trajectory(traj, geometry, out, paving=a.regions.paving, joint=a.joint)
    if as_json:
        sys.stdout.write(json.dumps(traj.to_json()) + "\n")
    else:
        sys.stdout.write(traj.summary() + "\n")
    return 0

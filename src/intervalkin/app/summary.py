"""summary.json and the terminal tables: the counts with their status, volumes, cells, timings.

The documents are built from the library's typed results; the keys are the
output contract (README "Output files").  Each count block carries "count",
"exact", "lower_bound", "upper_bound" (null: none proved) and "why"
(:meth:`intervalkin.core.status.Count.to_json`), and ``certified`` spells out
what the labels, volumes and components prove.
"""

from __future__ import annotations

import numpy as np

from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving
from intervalkin.pipeline import Analysis
from intervalkin.recheck.separation_file import barrier_bound, components_apart
from intervalkin.space.joint_closure import closed_cells
from intervalkin.space.joint_separation import separated_cells
from intervalkin.space.joint_space import JointPaving

__all__ = ['CERTIFIED_NOTE', 'pave_summary', 'pave_table', 'joint_summary', 'joint_table', 'chain_summary', 'chain_table']

CERTIFIED_NOTE = {
    "labels": "Every INSIDE / OUTSIDE box label is proved with outward-rounded interval arithmetic "
              "(W: rho_min <= rho_i <= rho_max on the whole box; det_sign: det A > 0 or < 0 on the whole box). "
              "Undecided boxes are reported as such and counted in the 'boundary' volumes.",
    "volumes": "inside volume is a certified inner bound, inside + boundary a certified outer bound "
               "of the true volume (up to float summation).",
    "connected": "Each component is a union of face-adjacent certified boxes (phi wraps): certified connected.",
    "distinct": "Components of opposite det A signs lie in different aspects (the sign is the witness). "
                "Components of the same sign are NOT proved distinct: they may join through the undecided layer; "
                "their count is an upper bound of the aspects of that sign found at this depth. The aspect count "
                "itself is bounded from above by the covers under aspects.covers (each sign's part of W proved "
                "connected).",
}


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


def pave_table(summary: dict) -> str:
    """A short terminal table of a workspace paving: volumes per label, components, time."""
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


def joint_summary(jp: JointPaving) -> dict:
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


def joint_cells_summary(jp, geometry=None, closure=None, separation=None) -> dict:
    """The direct joint paving: its resolution, certified share, cells (each with its certified count) and levels;
    with ``geometry``, the cells proved closed (whole components; :mod:`intervalkin.space.joint_closure`) and the
    cells proved to be different components (:mod:`intervalkin.space.joint_separation`): ``closure`` and
    ``separation`` when given (an analysis has them), computed here otherwise."""
    stats = jp.paving.stats
    uniform = [st for st in stats if st["stage"] == "joint paving"]
    fs = jp.fold_stats
    return {
        "depth": int(uniform[-1]["depth"]) if uniform else 0,
        "deepest_level": int(jp.paving.level.max()),
        "boxes": len(jp.paving),
        "certified_share": jp.certified_share(),
        "undecided_volume": jp.undecided_volume(),
        "undecided_volume_per_level": [st["undecided_volume"]["clear"] for st in stats],
        "stages": [{"stage": st["stage"], "level": int(st["level"]), "boxes": int(st["boxes"]),
                    "seconds": float(st.get("seconds", 0.0)),
                    "undecided_volume": float(st["undecided_volume"]["clear"]),
                    "without_model_volume": float(st["undecided_volume"].get("model", st["undecided_volume"]["clear"]))}
                   for st in stats],
        "cells": [c.to_json() for c in jp.cells],
        "fragments": [c.to_json() for c in jp.fragments],
        "fold_boxes": int(fs.get("fold_boxes", 0)),
        "boxes_cleared_by_exclusion": {"boxes": int(fs.get("void_boxes", 0)), "volume": float(fs.get("void_volume", 0.0))},
        "unjoined_fold_pieces": {"groups": int(fs.get("unjoined_piece_groups", 0)),
                                 "volume": float(fs.get("unjoined_piece_volume", 0.0))},
        "inferred_piece_signatures": int(fs.get("inferred_piece_signatures", 0)),
        "empty_pieces": int(fs.get("empty_pieces", 0)),
        "window_models": dict(fs.get("windows", {})),
        "open_places": jp.open_places()["places"],
        **({} if geometry is None else {
            "closed_cells": (closed_cells(jp, geometry) if closure is None else closure).to_json(),
            "separations": (separated_cells(jp, geometry) if separation is None else separation).to_json()}),
        "certified": "every box of a cell is proved off g(S) (no singular pose has its joint vector in it: by the "
                     "torus search or by Krawczyk exclusion), or is a fold box: one sheet of g(S) crosses it as a "
                     "certified graph and each of its two pieces is joined to the cell through a point placed in "
                     "both; each cell's count and aspect split come from one complete certified solve at its "
                     "witness and hold at every point of the cell; cells are not proved to be different "
                     "components, except the closed cells (closed_cells: each is a whole component) and the cells in different "
                     "groups of one signature (separations); fragments are certified islands inside the undecided layer, made only by the "
                     "local refinement and touching no face of the joint box: each lies in some component but is "
                     "not joined to one, so they are listed, not counted; fold pieces joined to no clear box are "
                     "counted under unjoined_fold_pieces and get their count from the other piece of their box "
                     "(the side of the extra pair of solutions is proved at one sheet point) or are proved "
                     "empty (inferred_piece_signatures, empty_pieces); open_places lists the face-connected "
                     "groups of leaves not certified (no local model, or a piece of unknown count)",
    }


def chain_summary(a: Analysis) -> dict:
    """summary.json of the whole chain (counts with their certification status first)."""
    ra = a.regions
    p = ra.paving
    out = a.counts().to_json()
    out["basic_regions"]["seen_in_workspace"] = len(ra.regions)
    if a.aspect_topology is not None:
        out["aspects"]["covers"] = a.aspect_topology.to_json()["covers"]
    out.update(
        {
            "geometry": a.geometry.name,
            "depth": {"workspace": a.depth, "singular_layer": a.singular_depth, "joint": a.joint_depth},
            "W": {"boxes": p.count_by_label("W"), "volume": p.volume_by_label("W")},
            "WA1": {"boxes": p.count_by_label("WA1"), "volume": p.volume_by_label("WA1")},
            "WA2": {"boxes": p.count_by_label("WA2"), "volume": p.volume_by_label("WA2")},
            "aspect_components": list(ra.aspect_info),
            "joint": joint_summary(a.joint),
            "joint_cells": joint_cells_summary(a.cells, a.geometry, a.closure, a.separation),
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
            "refinement": [step.to_json() for step in a.refinement],
            "certified": CERTIFIED_NOTE,
        }
    )
    add_separation_bound(out)
    return out


def add_separation_bound(summary: dict) -> None:
    """Put the basic-region bound of the separations beside the certified one, when it is higher.

    Kept apart from ``lower`` (``separations_at_least``, and a sentence in ``why``): the library proves
    it, but the separations between cells with solutions are not in the certificates (only the count
    barriers are), so ``intervalkin verify`` does not re-prove it.
    """
    sep = (summary.get("joint_cells") or {}).get("separations")
    block = summary["basic_regions"]
    if not sep or sep["basic_regions_at_least"] <= block["lower"]:
        return
    n = sep["basic_regions_at_least"]
    block["separations_at_least"] = n
    block["why"] += (f"; the separations of cells of one signature (joint_cells.separations, "
                     f"proofs/lemma-separation.md) prove at least {n}, but some of those between cells with "
                     "solutions rest on window patterns only, not in the certificates (the count and pattern barriers "
                     "are: joint_cells.separations.count_barriers), so intervalkin verify does not re-prove that "
                     "bound")


def add_barrier_certificates(summary: dict, claims: list[dict]) -> None:
    """Record in ``joint_cells.separations.count_barriers`` the separations written as count or pattern barriers
    (``certificates/joint_separation.json``, re-proved by ``intervalkin verify``), and in ``basic_regions`` the
    lower bound they prove (``barriers_at_least``, when above the counts claim's): it becomes the block's
    certified ``lower_bound`` (and ``lower``), the claim's own bound kept as ``counts_claim_lower``.

    Each claim tells its cell apart from every other cell of its signature, so a signature with k claims
    has at least k + 1 components certified (the k cells and any one other are pairwise apart).  Cells of
    different signatures are different components (their witnesses' joint_cell claims), and above a
    component with n solutions lie n basic regions (Theorem 1): the basic regions number at least the sum,
    over the signatures, of components times count."""
    sep = (summary.get("joint_cells") or {}).get("separations")
    if sep is None or not claims:
        return
    by_sig: dict[tuple, list[int]] = {}
    kinds: dict[str, list[int]] = {}
    for c in claims:
        by_sig.setdefault(tuple(c["signature"]), []).append(int(c["cell"]))
        kinds.setdefault(c.get("kind", "count"), []).append(int(c["cell"]))
    # counted as verify counts them: witness points proved pairwise apart (k claims against all others: k + 1)
    apart = components_apart(claims, [True] * len(claims))
    rows = [{"signature": list(sig), "cells": sorted(set(cells)), "components_at_least": apart[sig]}
            for sig, cells in sorted(by_sig.items())]
    barred = {tuple(r["signature"]): r["components_at_least"] for r in rows}
    signatures = {tuple(b["signature"]) for b in sep.get("by_signature", [])} | set(barred)
    regions = sum(barred.get(sig, 1) * sig[0] for sig in signatures)
    sep["count_barriers"] = {
        "by_signature": rows,
        "components_at_least": sum(r["components_at_least"] for r in rows),
        "all_components_at_least": sum(barred.get(sig, 1) for sig in signatures),
        "basic_regions_at_least": regions,
        "count_barrier_cells": sorted(kinds.get("count", [])),
        "pattern_barrier_cells": sorted(kinds.get("pattern", [])),
        "file": "certificates/joint_separation.json",
        "certified": "each listed cell and every other cell of its signature lie in different components of the "
                     "joint box minus g(S): a region around its witness whose boundary carries no point of its "
                     "count (count barriers, proofs/lemma-count-barrier.md, lemma-count-range.md) or none of the "
                     "patterns of its solutions on the circle (pattern barriers, proofs/lemma-pattern-barrier.md), "
                     "re-proved by intervalkin verify",
    }
    block = summary.get("basic_regions")
    lower = None if block is None else block.get("lower_bound", block.get("lower"))
    # what verify re-proves: the counts claim's bound, plus n for each witness of n solutions in a largest set that
    # the claims prove pairwise apart, beyond the first (one cell of each signature is in the bound already)
    proved = None if lower is None else barrier_bound(lower, claims, [True] * len(claims))
    if proved is not None and proved > lower:
        # the certified lower bound is the larger one: verify re-proves both halves (the counts claim in the arb
        # checker, the barriers and this sum in the recheck's barrier_bound verdict), and the checker accepts a
        # summary lower bound above the claim's only when it is this number (checker.consistency)
        block["barriers_at_least"] = proved
        block["counts_claim_lower"] = lower
        block["lower_bound"] = proved
        if "lower" in block:
            block["lower"] = proved
        upper = block.get("upper_bound")
        block["exact"] = upper is not None and upper == proved
        block["why"] = block.get("why", "") + (
            f"; the certified lower bound is {proved}: the counts claim's {lower} plus n for each cell of n "
            "solutions that a count or pattern barrier of certificates/joint_separation.json tells apart from the "
            "others of its signature (one more component, n more basic regions), all re-proved by intervalkin verify")


def chain_table(summary: dict) -> str:
    """A short terminal table of the counts and their status."""
    def status(block):
        if block.get("exact"):
            return "exact"
        if block.get("barriers_at_least") is not None:
            return (f"found; certified lower bound {block['lower_bound']} ({block['counts_claim_lower']} by the "
                    "counts claim, the rest by barriers re-proved by verify)"
                    + ("" if block.get("separations_at_least") is None else
                       f"; at least {block['separations_at_least']} by library separations (not re-proved by verify)"))
        n = block.get("separations_at_least")
        more = "" if n is None else (f"; at least {n} by separations (not re-proved by verify)"
                                     + (", the count found: no upper bound yet" if n >= block["count"] else ""))
        return f"found; certified lower bound {block['lower_bound']}{more}"

    rows = [
        f"{'set':<22}{'count':>7}   status",
        f"{'aspects':<22}{summary['aspects']['count']:>7}   {status(summary['aspects'])}",
        f"{'basic regions':<22}{summary['basic_regions']['count']:>7}   {status(summary['basic_regions'])}",
        f"{'uniqueness domains':<22}{summary['uniqueness_domains']['count']:>7}   {status(summary['uniqueness_domains'])}"
        + ("  (minimal)" if summary["uniqueness_domains"].get("minimal") else ""),
    ]
    direct = summary.get("joint_cells")
    if direct:  # the direct joint paving: the cells the basic regions are counted over
        by = {}
        for c in direct["cells"]:
            by.setdefault(c["count"], []).append(c["volume"])
        frag = len(direct.get("fragments", []))
        rows.append(f"joint cells (count: number; {100 * direct['certified_share']:.1f}% of the joint box certified): "
                    + ", ".join(f"{k}: {len(v)}" for k, v in sorted(by.items()))
                    + (f"; {frag} fragments listed apart" if frag else ""))
    else:
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


def joint_table(jp: JointPaving) -> str:
    """A terminal table of the joint cells: count, aspect split, size, witness."""
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

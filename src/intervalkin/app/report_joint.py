"""The report's passage on the direct joint paving: the count of basic regions explained cell by cell.

Written from ``summary.json``'s ``joint_cells`` block alone (:func:`intervalkin.app.summary.joint_cells_summary`),
so what the report says is exactly what the summary states.
"""

from __future__ import annotations

from fractions import Fraction

__all__ = ["joint_cells_passage"]

_FACE = 0.5  # a witness this close to a limit is said to lie "along" that face


def _zone_text(sep: dict) -> str:
    """The pavings made again between cells still joined (space.joint_topology), when any."""
    passes = sep.get("zone_passes") or []
    if not passes:
        return ""
    kept = [z for z in passes if z["kept"]]
    last = passes[-1]
    stands = (f"the last one kept ({kept[-1]['cells_found']} cells) is the one reported" if kept
              else "none was kept: the first paving is the one reported")
    return (f"The joint box was paved again {len(passes)} time{'s' if len(passes) > 1 else ''}, finer between cells "
            f"still joined ({last['boxes']} boxes of the uniform level, volume {last['volume']:.2f}, split "
            f"{last['levels']} more times); {len(kept)} of these pavings kept every cell and proved more apart, and "
            f"{stands}. ")


def _barrier_text(sep: dict) -> str:
    """Which separations the certificates hold (count barriers) and which they do not."""
    bars = sep.get("count_barriers")
    if not bars:
        return "These separations are not yet in the certificates, and the lower bound above does not use them."
    ids = [str(c) for row in bars["by_signature"] for c in row["cells"]]
    pattern = bars.get("pattern_barrier_cells") or []
    return (f"The separations of cell{'s' if len(ids) > 1 else ''} {', '.join(ids)} from the other cells of their "
            "signature are also in certificates/joint_separation.json, re-proved by intervalkin verify: count "
            "barriers (proofs/lemma-count-barrier.md)"
            + (f" and, for cell{'s' if len(pattern) > 1 else ''} {', '.join(map(str, pattern))}, a pattern barrier "
               "(proofs/lemma-pattern-barrier.md)" if pattern else "")
            + f": at least {bars['all_components_at_least']} components of the joint box minus g(S) and "
            f"{bars['basic_regions_at_least']} basic regions are certified. The others rest on window patterns "
            "and are not yet in the certificates.")


def _where(witness: list[float], lo: list[float], hi: list[float]) -> str:
    near = [f"rho_{i + 1} = {lo[i]:g}" for i in range(3) if witness[i] - lo[i] < _FACE]
    near += [f"rho_{i + 1} = {hi[i]:g}" for i in range(3) if hi[i] - witness[i] < _FACE]
    return "along " + " and ".join(near) if near else "inside"


def joint_cells_passage(summary: dict, limits: tuple[list[float], list[float]]) -> list[str]:
    """Markdown lines: the cells of the direct joint paving, their counts, and the sum that is the count of basic regions.

    ``limits``: (rho_min, rho_max) per leg, to say which cells hug a face of the joint box.
    """
    jc = summary.get("joint_cells")
    if not jc:
        return []
    lo, hi = limits
    br = summary.get("basic_regions", {})
    out = ["## The joint box paved directly: the count of basic regions, cell by cell\n",
           f"The joint box is paved to depth {jc['depth']} (leaves down to level {jc['deepest_level']}, "
           f"{jc['boxes']} boxes). A box is certified when it is proved off g(S) (no singular pose has its joint "
           "vector in it: by the search on the circle of leg 1, or by Krawczyk exclusion: "
           f"{jc['boxes_cleared_by_exclusion']['boxes']} boxes) or when one sheet of g(S) crosses it as a proved "
           f"graph and both of its pieces are counted ({jc['fold_boxes']} fold boxes). Certified: "
           f"{100 * jc['certified_share']:.1f}% of the joint box; undecided volume {jc['undecided_volume']:.1f}.\n",
           "A cell is a connected set of certified boxes and pieces; one complete certified solve at its witness "
           "gives its count and aspect split, which hold at every point of the cell. Above a cell whose points have "
           "n_1 solutions in WA1 and n_2 in WA2 lie n_1 basic regions in WA1 and n_2 in WA2 (Theorem 1 and "
           "Proposition 1), so the count of basic regions is the sum of the cells' counts:\n",
           "| cell | solutions | WA1 | WA2 | volume | witness (rho_1, rho_2, rho_3) | where |",
           "|---|---|---|---|---|---|---|"]
    for c in jc["cells"]:
        w = [float(Fraction(v)) for v in c["witness"]]
        cnt = str(c["count"]) if c["count"] >= 0 else "?"
        out.append(f"| {c['id']} | {cnt} | {c['n_wa1']} | {c['n_wa2']} | {c['volume']:.2f} | "
                   f"({', '.join(f'{v:.3f}' for v in w)}) | {_where(w, lo, hi)} |")
    counts = [c["count"] for c in jc["cells"] if c["count"] >= 0]
    terms = " + ".join(str(n) for n in sorted(counts, reverse=True))
    lower = br.get("lower")
    out.append(f"\nSum: {terms} = {sum(counts)} basic regions found"
               + (f" (proved lower bound {lower}" if lower is not None else " (")
               + (f", upper bound {br['upper']})" if br.get("upper") is not None else "; no upper bound is proved)")
               + ". Cells with equal counts are proved to be different components of the joint box minus g(S) "
               "only where the separations below say so, and undecided boxes could still hide a small one.\n")
    closed = (jc.get("closed_cells") or {}).get("closed") or []
    if closed:
        sig = {c["id"]: c["count"] for c in jc["cells"] + (jc.get("fragments") or [])}
        out.append(f"Closed cells: {', '.join(f'{c} ({sig.get(c, -1)} solutions)' for c in closed)}. Each is proved to be "
                   "a whole component of the joint box minus g(S): every face contact of its pieces is decided and "
                   "leads back into it (proofs/lemma-closed-cell.md), so it is separated from every other cell. "
                   "These separations are not yet in the certificates, and the lower bound above does not use them.\n")
    sep = jc.get("separations") or {}
    apart = [g for g in sep.get("by_signature", []) if len(g["groups"]) > 1]
    if apart:
        out.append("Separated cells: " + "; ".join(
            f"{g['signature'][0]} solutions: " + " | ".join(", ".join(str(c) for c in grp) for grp in g["groups"])
            for g in apart)
            + f". Cells in different groups are proved to be different components (proofs/lemma-separation.md): "
            f"at least {sep['components_at_least']} components hold a cell, and at least "
            f"{sep['basic_regions_at_least']} basic regions lie above them. " + _zone_text(sep) + _barrier_text(sep)
            + "\n")
    frags = jc.get("fragments") or []
    if frags:
        out.append(f"{len(frags)} fragment{'' if len(frags) == 1 else 's'} (certified islands inside the undecided layer, made only by the local "
                   "refinement and joined to no cell; each lies in some component, perhaps one of the cells "
                   "above) are listed apart and not counted: "
                   + ", ".join(f"{f['count']} solutions at ({', '.join(f'{float(Fraction(v)):.2f}' for v in f['witness'])})"
                               for f in frags[:8]) + (" ..." if len(frags) > 8 else "") + ".\n")
    ufp = jc.get("unjoined_fold_pieces") or {}
    if ufp.get("groups"):
        out.append(f"Fold pieces joined to no cell: {ufp['groups']} groups, volume {ufp['volume']:.2f}; "
                   f"{jc.get('inferred_piece_signatures', 0)} pieces get their count from the other piece of their "
                   f"box (the side of the extra pair is proved at a sheet point) and {jc.get('empty_pieces', 0)} "
                   "are proved empty.\n")
    places = jc.get("open_places") or {}
    if places.get("count"):
        out += [f"What is left open: {places['count']} places (face-connected groups of leaves without a "
                f"certified count), {places['volume_without_model']:.2f} of volume without a local model of any "
                f"kind, {places.get('volume_window_model', 0.0):.2f} with a window model (a certified count at each "
                "point, pieces not proved connected). "
                "A cell could hide in a place, or two cells meet through one, so no upper bound is proved. "
                + _why_line(places.get("by_reason") or {})
                + _retraction_line(((summary.get("basic_regions") or {}).get("undecided") or {}).get("retraction"))
                + "The largest:\n",
                "| volume | leaves | without a model | from (rho_1, rho_2, rho_3) | to | on a face | why (leaves) |",
                "|---|---|---|---|---|---|---|"]
        for q in places["largest"][:10]:
            out.append(f"| {q['volume']:.3f} | {q['leaves']} | {q['without_model']} | "
                       f"({', '.join(f'{v:.2f}' for v in q['lo'])}) | ({', '.join(f'{v:.2f}' for v in q['hi'])}) | "
                       f"{'yes' if q['on_face'] else 'no'} | "
                       + ", ".join(f"{_WHY.get(k, k)} {v['leaves']}" for k, v in (q.get("why") or {}).items()) + " |")
        out.append("")
    return out


#: Short names of the reasons a leaf is open (space.joint_places.REASONS), for the report's tables.
_WHY = {"no_model": "no model", "cusp_window": "cusp window", "window_at_points": "window signs at points only",
        "pair_windows": "several pair windows", "slope_not_certified": "one pair window (slope not certified)",
        "fold_piece_count": "fold piece of unknown count", "other": "other"}


#: Short names of the kinds of nodes (space.joint_retraction.SOURCES).
_NODES = {"clear": "clear leaves", "fold_piece": "fold pieces", "window_piece": "window pieces",
          "pair_pattern": "pair-window patterns", "cusp_side": "cusp sides", "signature_only": "signature-only leaves",
          "no_piece_model": "leaves without pieces", "cusp_pattern": "cusp sides beside pair windows"}


def _retraction_line(block: dict | None) -> str:
    """One sentence: how far the open layer retracts into the cells (the local step of an upper bound), or that
    the run did not retract it (the retraction is asked for with ``--retraction``)."""
    if not block:
        return ("The open layer was not retracted towards the cells (`--retraction` does it: the local step of an "
                "upper bound, which closes on no geometry yet). ")
    left = [f"{_NODES.get(k, k)} {v['unresolved']}" for k, v in block["by_source"].items() if v["unresolved"]]
    head = (f"Retraction towards the cells (proofs/lemma-joint-retraction.md): {block['resolved']} of "
            f"{block['nodes'] - block['sinks']} nodes off the cells are ranked")
    if block["closed"]:
        return head + ": every point off g(S) is joined to a cell of its signature. "
    return (head + f"; {block['leaves_unresolved']} leaves (volume {block['volume_unresolved']:.2f}) still hold a node "
            "that is not, so no upper bound: " + ", ".join(left) + ". ")


def _why_line(by_reason: dict) -> str:
    """One sentence: the open leaves and volume by reason (what a model would have to handle)."""
    if not by_reason:
        return ""
    parts = [f"{_WHY.get(k, k)} {v['leaves']} leaves ({v['volume']:.2f})" for k, v in by_reason.items()]
    return "By reason: " + "; ".join(parts) + ". "

"""Claims about the workspace paving: ``aspect_distinct``, ``region_distinct``, ``box_labels``, ``counts``.

* ``aspect_distinct``: one box certified INSIDE W with det A > 0 and one with
  det A < 0, chosen among the paving's aspect boxes so that the checker can
  re-prove them: there are at least two aspects.
* ``region_distinct``: k solutions of one joint vector in one aspect, each in a
  paving box of a different piece off S_c; by Theorem 1 the pieces lie in k
  different basic regions.  The checker re-proves the solutions and the W and
  det A labels of the paving boxes, not the off-S_c label (the statement says
  so).
* ``box_labels``: a sample of paving boxes drawn by
  :func:`intervalkin.checker.sample_indices` from a seed, with their W and det A
  labels, each re-provable over the whole box.
* ``counts``: the library's counts of aspects, basic regions and uniqueness
  domains, each with the lower bound its supporting claims prove, and the
  upper bound where one is certified (the aspects, by ``aspect_connected``).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from intervalkin.certify.evidence import (
    box_json,
    certified,
    labels_of,
    rho_text,
)
from intervalkin.checker import box_label_proved, check_claim, sample_indices
from intervalkin.checker.parse import inside
from intervalkin.core.exact import exact_text
from intervalkin.core.geometry import Geometry
from intervalkin.paving.labels import Label
from intervalkin.solve.dkp import solve

__all__ = ['aspect_distinct_claims', 'region_distinct_claims', 'box_labels_claim', 'counts_claims']


def aspect_distinct_claims(geometry: Geometry, paving, precision: int = 128,
                           tries: int = 40) -> tuple[list[dict], list[dict]]:
    """One ``aspect_distinct`` claim: a box of each sign of det A inside W, re-proved by the checker."""
    chosen = {}
    vol = paving.volume()
    for aspect, sign in (("WA1", 1), ("WA2", -1)):
        lab = paving.labels.get(aspect)
        if lab is None:
            continue
        idx = np.flatnonzero(lab == Label.INSIDE)
        # medium boxes first: big ones need many sub-boxes in the checker, tiny ones say little
        order = idx[np.argsort(-vol[idx], kind="stable")]
        order = np.concatenate([order[len(order) // 4:], order[: len(order) // 4]])
        want = 2 if sign > 0 else 1
        for i in order[:tries]:
            box = paving.box(i)
            if box_label_proved(geometry, box, "W", 2, precision) and \
                    box_label_proved(geometry, box, "det_positive", want, precision):
                chosen[aspect] = {"box": box_json(box), "aspect": aspect, "paving_index": int(i)}
                break
    if len(chosen) < 2:
        return [], [{"what": "aspect_distinct", "why": "no box of each sign of det A was re-proved by the checker"}]
    claim = {
        "id": "aspects",
        "precision": precision,
        "boxes": [chosen["WA1"], chosen["WA2"]],
        "statement": "these two boxes lie in W, det A > 0 on the first and < 0 on the second: "
                     "they lie in two different aspects",
    }
    ok, why = check_claim(geometry, "aspect_distinct", claim, precision)
    return ([claim], []) if ok else ([], [{"what": "aspect_distinct", "why": why}])


def _region_claim(geometry, analysis, rho, cell, aspect, boxes, claim_id, precision):
    p = analysis.paving
    sign = 1 if aspect == "WA1" else -1
    sols = []
    for b in boxes:
        i = int(p.locate_boxes(np.asarray(b, dtype=np.float64)[None])[0])
        if i < 0 or analysis.piece[i] < 0:
            return None, "a solution box is not inside one certified box of a piece"
        sols.append({
            "box": box_json(b),
            "det_sign": sign,
            "piece": int(analysis.piece[i]),
            "region": int(analysis.region[i]),
            "paving_box": {"index": i, "box": box_json(p.box(i)),
                           "labels": labels_of(p, i, ("W", "det_positive", "off_Sc"))},
        })
    claim = {
        "id": claim_id,
        "rho": [exact_text(r) for r in rho],
        "cell": int(cell),
        "aspect": aspect,
        "solutions": sols,
        "statement": (f"q = ({rho_text(rho)}) has {len(sols)} distinct certified solutions in {aspect}, in the "
                      f"paving boxes listed; those boxes lie in pieces {[s['piece'] for s in sols]} (regions "
                      f"{[s['region'] for s in sols]}) certified off S_c by the library; by Theorem 1 g is injective "
                      "on a basic region, so these pieces lie in pairwise different basic regions"),
    }
    return certified(geometry, "region_distinct", claim, precision,
                     box_ok=lambda s: inside(s["box"], s["paving_box"]["box"]))


def region_distinct_claims(geometry: Geometry, analysis, joint=None, precision: int = 128,
                           limit: int = 12) -> tuple[list[dict], list[dict]]:
    """``region_distinct`` claims from the analysis's witnesses (or, if none, from cell witnesses)."""
    claims, omitted = [], []
    for k, w in enumerate(analysis.witnesses[:limit]):
        got, why = _region_claim(geometry, analysis, w.rho, w.cell, w.aspect, w.boxes, f"witness-{k}", precision)
        (claims.append(got) if got else omitted.append({"what": f"region_distinct witness-{k}", "why": why}))
    if claims or joint is None:
        return claims, omitted
    for cell in joint.cells:  # fallback: the cells' own witnesses
        if len(claims) >= limit:
            break
        if not cell.complete or cell.witness is None:
            continue
        res = solve(geometry, cell.witness)
        if not res.complete:
            continue
        for aspect, sign in (("WA1", 1), ("WA2", -1)):
            boxes = [s.box for s in res.solutions if s.status == "unique" and s.det_sign == sign]
            if len(boxes) < 2:
                continue
            located = analysis.paving.locate_boxes(np.asarray(boxes))
            if np.any(located < 0):
                continue
            pieces = analysis.piece[located]
            if np.any(pieces < 0) or len(set(pieces.tolist())) != len(boxes):
                continue
            got, why = _region_claim(geometry, analysis, cell.witness, cell.id, aspect, boxes,
                                     f"cell-{cell.id}-{aspect}", precision)
            if got:
                claims.append(got)
    return claims, omitted


def box_labels_claim(paving, sample: int, seed: int, precision: int = 128) -> dict:
    """A ``box_labels`` claim: the boxes drawn by :func:`~intervalkin.checker.sample_indices`, with their labels."""
    n = len(paving)
    idx = sample_indices(seed, n, sample) if n else []
    return {
        "id": "sample",
        "precision": precision,
        "seed": int(seed),
        "population": int(n),
        "sample_size": int(sample),
        "boxes": [{"index": int(i), "box": box_json(paving.box(i)),
                   "labels": labels_of(paving, int(i), ("W", "det_positive"))} for i in idx],
        "statement": f"{len(idx)} boxes drawn from the {n} of the paving (seed {seed}) carry the stated W and "
                     "det A sign labels: INSIDE holds on the whole box, OUTSIDE fails on the whole box",
    }


def counts_claims(analysis, aspect_refs: Sequence[str], solve_refs: Sequence[str], counts=None) -> list[dict]:
    """The declared counts (``counts``, else ``RegionAnalysis.counts()``) with the claims supporting their lower bounds."""
    c = (analysis.counts() if counts is None else counts).to_json()
    out = []
    for name, refs, why in (
        ("aspects", aspect_refs, "opposite certified signs of det A inside W"),
        ("basic_regions", solve_refs, "the solutions of one joint vector in one aspect lie in different basic "
                                      "regions (Theorem 1), and joint vectors with different aspect splits have "
                                      "their solutions in different basic regions"),
        ("uniqueness_domains", solve_refs, "the solutions of one joint vector in one aspect lie in different "
                                           "uniqueness domains of that aspect"),
    ):
        upper = c[name].get("upper_bound")
        out.append({
            "id": name,
            "name": name,
            "lower_bound": int(c[name]["lower_bound"]),
            "upper_bound": None if upper is None else int(upper),
            "found": int(c[name]["count"]),
            "exact": bool(c[name]["exact"]),
            "support": list(refs),
            "statement": f"at least {c[name]['lower_bound']} {name.replace('_', ' ')} ({why}); "
                         + (f"at most {upper} (each sign's part of W proved connected); exactly {upper}"
                            if c[name]["exact"] else f"{c[name]['count']} found, not proved exact"),
        })
    return out

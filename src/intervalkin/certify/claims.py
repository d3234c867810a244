"""Certificate files: each claim intervalkin makes, with the evidence a sceptic needs.

The writers here turn the library's results into JSON files; the independent
checker (:mod:`intervalkin.checker`, ``intervalkin verify DIR``) re-proves them
from the files alone with arb, without the paving, region or solver code.

Schema (format ``"intervalkin-certificate"``, version 1)
-------------------------------------------------------
A certificate folder holds ``index.json`` and one file per claim type::

    index.json   {"format": "intervalkin-certificate", "version": 1, "kind": "index",
                  "geometry_toml": "<Geometry.to_toml()>", "files": ["dkp.json", ...],
                  "tool": {"name": "intervalkin", "version": "..."},
                  "omitted": [{"what": "...", "why": "..."}]}
    <kind>.json  {"format": ..., "version": 1, "kind": "<kind>",
                  "geometry_toml": "<the same text as the index>", "precision": 128,
                  "claims": [{"id": "...", ...}, ...]}

Conventions for every file:

* ``geometry_toml``: the manipulator as the exact decimal strings that were read
  (:meth:`~intervalkin.core.geometry.Geometry.to_toml`); the checker re-reads it with
  :func:`~intervalkin.core.geometry.parse_geometry` and requires every file to carry
  the index's text.
* Joint vectors are exact: decimal strings ``"14.98"`` when the value is a finite
  decimal, else ``"p/q"`` (never JSON numbers).
* A box is ``[[xlo, xhi], [ylo, yhi], [philo, phihi]]`` of binary64 numbers written
  in shortest round-trip form (Python ``repr``), phi in radians; the box is the
  set of reals between those binary64 values.
* ``precision``: arb working precision (bits) of the checker for the claim
  (a claim's own ``precision`` overrides the file's).
* ``statement``: human text; the checker never trusts it.

Claim fields by kind (``id`` is unique within its file):

``dkp``
    ``rho`` (3 exact strings), ``complete`` (bool), ``count``, ``phi0`` (binary64
    shift of t = tan((phi - phi0)/2), used when complete), ``solutions``:
    ``[{"box", "det_sign": 1 | -1}]``.  Proves: each box holds exactly one
    solution, with that sign of det A; with ``complete``, there are no others.
``joint_cell``
    ``cell`` (id in the joint paving), ``witness`` (3 exact strings), ``count``,
    ``n_wa1``, ``n_wa2``, ``phi0``, ``solutions`` as for dkp (always complete).
    Proves the witness's count and aspect split.  That the whole cell shares
    them rests on the library's enclosure of g(S) (not re-checked).
``aspect_distinct``
    ``boxes``: ``[{"box", "aspect": "WA1" | "WA2", "paving_index"}]``.  Proves
    each box inside W with that sign of det A on the whole box: two aspects.
``region_distinct``
    ``rho``, ``cell``, ``aspect``, ``solutions``: ``[{"box", "det_sign", "piece",
    "region", "paving_box": {"index", "box", "labels": {"W", "det_positive",
    "off_Sc"}}}]``.  Proves k distinct solutions of q in the aspect, each inside
    its paving box, whose W and det labels are re-proved; the off-S_c label and
    the piece / region ids are the library's (see the claim statement).
``box_labels``
    ``seed``, ``population`` (boxes in the paving), ``sample_size``, ``boxes``:
    ``[{"index", "box", "labels": {"W": 1|2|3, "det_positive": 1|2|3}}]``; the
    indices are :func:`intervalkin.checker.sample_indices` (seed, population,
    sample_size).  Labels: 1 OUTSIDE, 2 INSIDE, 3 BOUNDARY (claims nothing).
``trajectory``
    one claim per path (id ``"I-J"``): ``rho`` (3 exact strings), ``from``,
    ``to`` (solution numbers, 1-based in increasing phi, as ``intervalkin dkp``
    lists them), ``aspect``, ``det_sign``, ``phi0`` and ``solutions`` (the
    complete solution list of rho, as for dkp: it fixes the numbering),
    ``start_box``, ``goal_box`` (enclosures of the two end solutions, phi in
    [-pi, pi]), ``phi_turns`` (the path reaches the goal at its phi plus
    2 pi phi_turns: phi is unwrapped along the path), ``waypoints`` (m rows
    [x, y, phi] as hex strings, for the reader) and ``segments``:
    ``[{"start", "end", "pieces"}]`` exactly as
    :meth:`~intervalkin.space.trajectory.Trajectory.certificate` gives them: end point
    enclosures ``[[lo, hi]] * 3`` and pieces ``[[t0, t1], ...]``, every number a
    binary64 written EXACTLY as a hex string (``float.hex``).  Proves: the
    straight segments, each from any point of its start enclosure to any point
    of its end enclosure, keep det A of the aspect's sign and every leg within
    its limits; they join end to end from the exact start solution to the
    exact goal solution.
``counts``
    one claim per count: ``name`` (``aspects``, ``basic_regions``,
    ``uniqueness_domains``), ``lower_bound``, ``found`` (the library's number,
    not certified), ``exact`` (always false), ``support`` (references
    ``"file#id"`` to the claims that prove the bound).

Writers build each solve claim, then run the checker on it before writing; a
claim the checker refuses is left out and listed under ``omitted`` in the index
with the reason (it is never written as if it held).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Iterable, Sequence

import numpy as np

from intervalkin import checker
from intervalkin.core.geometry import Geometry
from intervalkin.paving.labels import Label
from intervalkin.solve.dkp import solve

__all__ = ['FORMAT', 'VERSION', 'dkp_claim', 'joint_cell_claims', 'aspect_distinct_claims', 'region_distinct_claims', 'box_labels_claim', 'trajectory_claims', 'counts_claims']

FORMAT = checker.FORMAT
VERSION = checker.VERSION

#: Shifts phi0 tried for the reduced sextic (its leading coefficient f(phi0 + pi) must be non-zero).
_PHI0 = (0.0,) + tuple(round(j * math.pi / 6, 6) for j in range(1, 12))
#: Working precisions tried for a solve claim, after the requested one.
_PRECISIONS = (128, 256, 512)
#: Relative paddings tried around a solver box when the tight box does not pass the checker's Krawczyk test.
_PADS = (0.0, 1e-13, 1e-11)


def _exact(q: Fraction) -> str:
    """The exact decimal "14.98" when the denominator divides a power of ten, else "p/q"."""
    q = Fraction(q)
    d, twos, fives = q.denominator, 0, 0
    while d % 2 == 0:
        d, twos = d // 2, twos + 1
    while d % 5 == 0:
        d, fives = d // 5, fives + 1
    if d != 1:
        return f"{q.numerator}/{q.denominator}"
    digits = max(twos, fives)
    if digits == 0:
        return str(q.numerator)
    scaled = abs(q.numerator) * 10**digits // q.denominator
    sign = "-" if q < 0 else ""
    return f"{sign}{scaled // 10**digits}.{scaled % 10**digits:0{digits}d}"


def _box_json(box) -> list[list[float]]:
    b = np.asarray(box, dtype=np.float64).reshape(3, 2)
    return [[float(lo), float(hi)] for lo, hi in b]


def _pad(box: list[list[float]], rel: float) -> list[list[float]]:
    if rel == 0.0:
        return box
    out = []
    for lo, hi in box:
        d = rel * (1.0 + max(abs(lo), abs(hi)))
        out.append([float(np.nextafter(lo - d, -np.inf)), float(np.nextafter(hi + d, np.inf))])
    return out


def _rho_text(rho: Sequence[Fraction]) -> str:
    return ", ".join(_exact(r) for r in rho)


def _certified(geometry: Geometry, kind: str, claim: dict, precision: int, pads=_PADS,
               phi0s: Iterable[float] = _PHI0, box_ok=None) -> tuple[dict | None, str]:
    """The claim with the first (precision, padding, phi0) the checker verifies, or (None, last reason)."""
    why = "no attempt"
    precs = [precision] + [p for p in _PRECISIONS if p > precision]
    base = [dict(s) for s in claim["solutions"]]
    phi0s = tuple(phi0s) if "phi0" in claim else (None,)
    for prec in precs:
        for rel in pads:
            sols = [dict(s, box=_pad(s["box"], rel)) for s in base]
            if box_ok is not None and not all(box_ok(s) for s in sols):
                continue
            for phi0 in phi0s:
                c = dict(claim, precision=prec, solutions=sols)
                if phi0 is not None:
                    c["phi0"] = phi0
                ok, why = checker.check_claim(geometry, kind, c, prec)
                if ok:
                    return c, ""
                if "leading coefficient" not in why:
                    break  # another shift cannot help
    return None, why


# --------------------------------------------------------------------------------------
# Claim builders
# --------------------------------------------------------------------------------------
def _solution_entries(result) -> list[dict]:
    return [{"box": _box_json(s.box), "det_sign": int(s.det_sign)}
            for s in result.solutions if s.status == "unique" and s.det_sign != 0]


def dkp_claim(geometry: Geometry, result, claim_id: str, precision: int = 128) -> tuple[dict | None, str]:
    """A ``dkp`` claim from a :class:`~intervalkin.solve.dkp.DkpResult` (checked), or (None, why not)."""
    sols = _solution_entries(result)
    complete = bool(result.complete) and len(sols) == len(result.solutions)
    claim = {
        "id": claim_id,
        "rho": [_exact(r) for r in result.rho],
        "complete": complete,
        "count": len(sols),
        "phi0": 0.0,
        "solutions": sols,
        "statement": (f"q = ({_rho_text(result.rho)}) has " + ("exactly " if complete else "at least ")
                      + f"{len(sols)} direct-kinematic solutions, one in each box, det A of the stated sign"),
    }
    if not complete:
        del claim["phi0"]
    return _certified(geometry, "dkp", claim, max(precision, result.precision))


def joint_cell_claims(geometry: Geometry, joint, precision: int = 128) -> tuple[list[dict], list[dict]]:
    """One ``joint_cell`` claim per cell with a certified count (its witness re-solved); and the omitted ones."""

    claims, omitted = [], []
    for cell in joint.cells:
        if not cell.complete or cell.witness is None:
            continue
        res = solve(geometry, cell.witness)
        sols = _solution_entries(res)
        claim = {
            "id": f"cell-{cell.id}",
            "cell": int(cell.id),
            "witness": [_exact(r) for r in cell.witness],
            "count": int(cell.count),
            "n_wa1": int(cell.n_wa1),
            "n_wa2": int(cell.n_wa2),
            "phi0": 0.0,
            "solutions": sols,
            "statement": (f"the witness q = ({_rho_text(cell.witness)}) of joint cell {cell.id} has exactly "
                          f"{cell.count} solutions ({cell.n_wa1} in WA1, {cell.n_wa2} in WA2), none singular; "
                          "the library's enclosure of g(S) (not re-checked) extends this to the whole cell"),
        }
        if not res.complete or len(sols) != len(res.solutions):
            omitted.append({"what": f"joint_cell cell-{cell.id}", "why": "the re-solve of the witness is not complete"})
            continue
        got, why = _certified(geometry, "joint_cell", claim, max(precision, res.precision))
        if got is None:
            omitted.append({"what": f"joint_cell cell-{cell.id}", "why": why})
        else:
            claims.append(got)
    return claims, omitted


def _labels_of(paving, i: int, names: Sequence[str]) -> dict[str, int]:
    return {n: int(paving.labels[n][i]) for n in names if n in paving.labels}


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
            box = paving.boxes[i]
            if checker.box_label_proved(geometry, box, "W", 2, precision) and \
                    checker.box_label_proved(geometry, box, "det_positive", want, precision):
                chosen[aspect] = {"box": _box_json(box), "aspect": aspect, "paving_index": int(i)}
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
    ok, why = checker.check_claim(geometry, "aspect_distinct", claim, precision)
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
            "box": _box_json(b),
            "det_sign": sign,
            "piece": int(analysis.piece[i]),
            "region": int(analysis.region[i]),
            "paving_box": {"index": i, "box": _box_json(p.boxes[i]),
                           "labels": _labels_of(p, i, ("W", "det_positive", "off_Sc"))},
        })
    claim = {
        "id": claim_id,
        "rho": [_exact(r) for r in rho],
        "cell": int(cell),
        "aspect": aspect,
        "solutions": sols,
        "statement": (f"q = ({_rho_text(rho)}) has {len(sols)} distinct certified solutions in {aspect}, in the "
                      f"paving boxes listed; those boxes lie in pieces {[s['piece'] for s in sols]} (regions "
                      f"{[s['region'] for s in sols]}) certified off S_c by the library; by Theorem 1 g is injective "
                      "on a basic region, so these pieces lie in pairwise different basic regions"),
    }

    def inside(s):
        return all(plo <= lo and hi <= phi for (lo, hi), (plo, phi) in zip(s["box"], s["paving_box"]["box"]))

    return _certified(geometry, "region_distinct", claim, precision, box_ok=inside)


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
    """A ``box_labels`` claim: the boxes drawn by :func:`checker.sample_indices` with their W and det labels."""
    n = len(paving)
    idx = checker.sample_indices(seed, n, sample) if n else []
    return {
        "id": "sample",
        "precision": precision,
        "seed": int(seed),
        "population": int(n),
        "sample_size": int(sample),
        "boxes": [{"index": int(i), "box": _box_json(paving.boxes[i]),
                   "labels": _labels_of(paving, int(i), ("W", "det_positive"))} for i in idx],
        "statement": f"{len(idx)} boxes drawn from the {n} of the paving (seed {seed}) carry the stated W and "
                     "det A sign labels: INSIDE holds on the whole box, OUTSIDE fails on the whole box",
    }


def trajectory_claims(geometry: Geometry, trajectories: Sequence,
                      precision: int = 128) -> tuple[list[dict], list[dict]]:
    """One ``trajectory`` claim per certified :class:`~intervalkin.space.trajectory.Trajectory` (checked); and the omitted.

    The segments are copied from :meth:`Trajectory.certificate` (exact hex
    floats); the solution list of the joint vector (which numbers the
    solutions) is padded if the checker's Krawczyk test needs it, the start
    and goal boxes never are (they are the enclosures the segments start and
    end in).  An uncertified trajectory, or one the checker refuses, is omitted.
    """
    claims, omitted = [], []
    for tr in trajectories:
        cid = f"{tr.i_from}-{tr.i_to}"
        if not tr.certified:
            omitted.append({"what": f"trajectory {cid}", "why": f"the path is not certified: {tr.reason}"})
            continue
        sols = list(tr.solutions)
        if not sols or any(s.status != "unique" or s.det_sign == 0 for s in sols):
            omitted.append({"what": f"trajectory {cid}", "why": "the solutions of rho are not all certified"})
            continue
        cert = tr.certificate()
        hx = lambda v: float(v).hex()  # noqa: E731
        claim = {
            "id": cid,
            "rho": [_exact(r) for r in tr.rho],
            "from": int(tr.i_from),
            "to": int(tr.i_to),
            "aspect": tr.aspect,
            "det_sign": int(tr.sign),
            "phi0": 0.0,
            "solutions": [{"box": _box_json(s.box), "det_sign": int(s.det_sign)} for s in sols],
            "start_box": _box_json(sols[tr.i_from - 1].box),
            "goal_box": _box_json(sols[tr.i_to - 1].box),
            "phi_turns": int(tr.phi_turns),
            "waypoints": [[hx(v) for v in w] for w in tr.waypoints],
            "segments": [{k: s[k] for k in ("start", "end", "pieces")} for s in cert["segments"]],
            "statement": (f"for q = ({_rho_text(tr.rho)}), the straight segments between the waypoints move the "
                          f"platform from solution {tr.i_from} to solution {tr.i_to} with det A "
                          f"{'> 0' if tr.sign > 0 else '< 0'} and every leg within its limits all along: "
                          f"a non-singular change of assembly mode in {tr.aspect}"),
        }
        got, why = _certified(geometry, "trajectory", claim, precision)
        (claims.append(got) if got else omitted.append({"what": f"trajectory {cid}", "why": why}))
    return claims, omitted


def counts_claims(analysis, aspect_refs: Sequence[str], solve_refs: Sequence[str]) -> list[dict]:
    """The declared counts of :meth:`RegionAnalysis.counts` with the claims supporting their lower bounds."""
    c = analysis.counts()
    out = []
    for name, refs, why in (
        ("aspects", aspect_refs, "opposite certified signs of det A inside W"),
        ("basic_regions", solve_refs, "the solutions of one joint vector in one aspect lie in different basic "
                                      "regions (Theorem 1), and joint vectors with different aspect splits have "
                                      "their solutions in different basic regions"),
        ("uniqueness_domains", solve_refs, "the solutions of one joint vector in one aspect lie in different "
                                           "uniqueness domains of that aspect"),
    ):
        out.append({
            "id": name,
            "name": name,
            "lower_bound": int(c[name]["lower_bound"]),
            "found": int(c[name]["count"]),
            "exact": False,
            "support": list(refs),
            "statement": f"at least {c[name]['lower_bound']} {name.replace('_', ' ')} ({why}); "
                         f"{c[name]['count']} found, not proved exact",
        })
    return out

"""The independent checker of intervalkin certificate files (``intervalkin verify DIR``).

A certificate folder (written by :func:`intervalkin.certify.writer.write_certificates`;
schema in that module) states claims with their evidence.  This module re-proves
every claim from the files alone, in arb ball arithmetic (python-flint), and
prints one line per claim.  Its trusted base is small on purpose:

* the Python standard library and python-flint (arb, acb, arb_poly, acb_poly,
  arb_mat; ``acb_poly.roots`` for certified complex root isolation);
* :mod:`intervalkin.core.geometry` (reads the geometry TOML stored in the files as
  exact decimals; constants as exact rationals and surds) and
  :mod:`intervalkin.core.errors`;
* the few formulas written out below (rho_i^2, det A, F, F', the reduced
  sextic), re-derived here on purpose instead of imported from
  :mod:`intervalkin.kinematics` or :mod:`intervalkin.solve.dkp`.

It never imports the paving, predicate, joint, region, dkp or analysis code
(``tests/test_certificates.py::test_checker_imports_none_of_the_checked_modules``).
What each claim type proves, and what it still trusts, is in
``proofs/lemma-checker.md``.

Re-proved per claim type
------------------------
``dkp`` / ``joint_cell``
    Each solution box holds exactly one solution of the ORIGINAL system
    F_i = |B_i - A_i|^2 - rho_i^2 (Krawczyk, the checker's own preconditioner,
    strict interior inclusion); det A has the declared sign on the whole box;
    the boxes are pairwise disjoint with phi read modulo 2 pi; and, for a claim
    of completeness, the checker rebuilds the reduced sextic in t = tan((phi -
    phi0)/2) by its own real-polynomial derivation, proves its leading
    coefficient non-zero, isolates its roots (``acb_poly.roots``), counts the
    real ones, proves the 2x2 system regular at each, and requires that count
    to equal the number of boxes.  A ``joint_cell`` claim also checks that the
    witness lies in the joint limits and that its count and aspect split are
    the ones declared.
``aspect_distinct``
    Each box lies in W (rho_min_i^2 <= rho_i^2 <= rho_max_i^2 on the whole box)
    and det A has the declared sign on the whole box (box subdivided in arb
    when the natural enclosure is too wide); the two signs are opposite.
``region_distinct``
    The joint vector's listed solutions are re-proved (Krawczyk, one aspect,
    pairwise disjoint), each solution box lies in its stated paving box, and
    that paving box's W and det-sign labels are re-proved in arb.  The
    "off S_c" label and the box-to-piece map are NOT re-checked (they need the
    joint-space enclosure of g(S)); the claim text says so.
``box_labels``
    Every INSIDE / OUTSIDE label of the sampled boxes (W and det_positive) is
    re-proved in arb over the whole box, subdividing when needed; BOUNDARY
    labels claim nothing.  The sample indices are re-derived from the seed.
``trajectory``
    The joint vector's complete solution list is re-proved as for ``dkp`` (it
    fixes the solution numbers: increasing phi in [-pi, pi]); the start and
    goal enclosures each hold exactly one solution (Krawczyk), lie in the
    listed solutions ``from`` and ``to``, and carry det A of the stated sign.
    For every piece [t0, t1] of every straight segment A + t (B - A) (A, B
    the segment's end enclosures), the ball A + [t0, t1] (B - A) is formed in
    arb and det A is proved of the aspect's sign and rho_min_i^2 <= rho_i^2 <=
    rho_max_i^2 proved on it (the t range bisected while undecided, within
    :data:`PIECE_BUDGET`); the pieces tile [0, 1]; consecutive segments share
    their end enclosure; the start enclosure lies in the first segment's
    start, and the goal enclosure shifted by 2 pi phi_turns (phi unwrapped)
    in the last segment's end.
``counts``
    Each declared lower bound is recomputed from the referenced claims that
    verified (rules in :func:`_count_bound`); a declared lower bound larger than
    the recomputed one, or a count declared exact, is refused.
"""

from __future__ import annotations

from intervalkin.checker.model import (
    _SIGN,
    _det_negative,
    _det_positive,
    _holds_on_box,
    _in_w,
    _Model,
    _prove_label,
    _rho,
    _strictly_in_limits,
)
from intervalkin.checker.parse import (
    _PREC_RANGE,
    _box,
    _get,
    _int,
    _Refused,
    sample_indices,
)
from intervalkin.checker.solutions import _check_solve
from intervalkin.checker.trajectory import _check_trajectory
from intervalkin.core.geometry import Geometry

__all__ = ['check_claim', 'box_label_proved']


def _check_dkp(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    rho = _rho(claim)
    complete = _get(claim, "complete")
    if not isinstance(complete, bool):
        raise _Refused("complete: expected true or false")
    sols = _get(claim, "solutions")
    if not isinstance(sols, list):
        raise _Refused("solutions: expected a list")
    facts = _check_solve(model, rho, sols, complete, claim.get("phi0"), prec)
    declared = claim.get("count")
    if declared is not None and declared != facts["n"]:
        raise _Refused(f"declared count {declared!r} but {facts['n']} solution boxes are listed")
    facts.update(rho=rho, in_limits=_strictly_in_limits(model.geometry, rho))
    q = ", ".join(str(r) for r in rho)
    if complete:
        msg = (f"q = ({q}) has exactly {facts['n']} solutions ({facts['n_wa1']} with det A > 0, "
               f"{facts['n_wa2']} with det A < 0), one in each box")
    else:
        msg = f"q = ({q}): each of the {facts['n']} boxes holds exactly one solution (completeness not claimed)"
    return msg, facts


def _check_joint_cell(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    rho = _rho(claim, "witness")
    g = model.geometry
    if not all(g.rho_min[i] <= rho[i] <= g.rho_max[i] for i in range(3)):
        raise _Refused("witness: not within the joint limits")
    sols = _get(claim, "solutions")
    if not isinstance(sols, list):
        raise _Refused("solutions: expected a list")
    facts = _check_solve(model, rho, sols, True, _get(claim, "phi0"), prec)
    for key, val in (("count", facts["n"]), ("n_wa1", facts["n_wa1"]), ("n_wa2", facts["n_wa2"])):
        if _get(claim, key) != val:
            raise _Refused(f"declared {key} = {claim[key]!r} but the checker proves {val}")
    facts.update(rho=rho, in_limits=_strictly_in_limits(g, rho))
    q = ", ".join(str(r) for r in rho)
    return (f"witness q = ({q}) of cell {claim.get('cell')!r} has exactly {facts['n']} solutions, split "
            f"{facts['n_wa1']} (WA1) + {facts['n_wa2']} (WA2), none singular"), facts




def _check_aspect_distinct(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    items = _get(claim, "boxes")
    if not isinstance(items, list) or len(items) < 2:
        raise _Refused("boxes: expected at least two witness boxes")
    signs = set()
    for k, it in enumerate(items):
        b = _box(_get(it, "box"), f"boxes[{k}]")
        aspect = _get(it, "aspect")
        if aspect not in _SIGN:
            raise _Refused(f"boxes[{k}]: aspect must be WA1 or WA2, got {aspect!r}")
        if not _holds_on_box(b, lambda s: _in_w(model, s)):
            raise _Refused(f"boxes[{k}]: not proved inside W (joint limits on the whole box)")
        test = _det_positive if _SIGN[aspect] > 0 else _det_negative
        if not _holds_on_box(b, lambda s: test(model, s)):
            raise _Refused(f"boxes[{k}]: det A not proved {'> 0' if _SIGN[aspect] > 0 else '< 0'} on the whole box")
        signs.add(_SIGN[aspect])
    if signs != {1, -1}:
        raise _Refused("the boxes do not have opposite signs of det A")
    return "two boxes inside W with opposite certified signs of det A: they lie in different aspects", {"signs": signs}


def _check_region_distinct(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    rho = _rho(claim)
    aspect = _get(claim, "aspect")
    if aspect not in _SIGN:
        raise _Refused(f"aspect must be WA1 or WA2, got {aspect!r}")
    sols = _get(claim, "solutions")
    if not isinstance(sols, list) or len(sols) < 2:
        raise _Refused("solutions: expected at least two solutions of one aspect")
    for k, s in enumerate(sols):
        if _get(s, "det_sign") != _SIGN[aspect]:
            raise _Refused(f"solution {k}: det_sign {s.get('det_sign')!r} is not the sign of {aspect}")
    facts = _check_solve(model, rho, sols, False, None, prec)
    pieces = []
    for k, s in enumerate(sols):
        b = _box(s["box"], f"solution {k} box")
        pb = _get(s, "paving_box")
        pbox = _box(_get(pb, "box"), f"solution {k} paving box")
        if not all(plo <= lo and hi <= phi for (lo, hi), (plo, phi) in zip(b, pbox)):
            raise _Refused(f"solution {k}: the solution box is not inside the stated paving box")
        labels = _get(pb, "labels")
        want = {"W": 2, "det_positive": 2 if _SIGN[aspect] > 0 else 1}
        for name, val in want.items():
            if labels.get(name) != val:
                raise _Refused(f"solution {k}: paving box label {name} = {labels.get(name)!r}, expected {val}")
            if not _prove_label(model, pbox, name, val):
                raise _Refused(f"solution {k}: paving box label {name} = {val} not re-proved in arb")
        pieces.append(_int(_get(s, "piece"), f"solution {k} piece", 0))
    if len(set(pieces)) != len(pieces):
        raise _Refused(f"two solutions are declared in one piece {pieces}: that would contradict Theorem 1")
    q = ", ".join(str(r) for r in rho)
    return (f"q = ({q}) has {len(sols)} distinct solutions in {aspect}, each in a paving box re-proved inside "
            f"{aspect}; the library puts those boxes in pieces {pieces} off S_c (not re-checked here), which "
            "by Theorem 1 then lie in pairwise different basic regions"), facts


def _check_box_labels(model: _Model, claim: dict, prec: int) -> tuple[str, dict]:
    seed = _int(_get(claim, "seed"), "seed")
    population = _int(_get(claim, "population"), "population", 1)
    boxes = _get(claim, "boxes")
    if not isinstance(boxes, list):
        raise _Refused("boxes: expected a list")
    size = _int(_get(claim, "sample_size"), "sample_size", 0)
    if min(size, population) != len(boxes):
        raise _Refused(f"{len(boxes)} boxes listed for a sample of {min(size, population)}")
    expect = sample_indices(seed, population, size)
    got = [b.get("index") if isinstance(b, dict) else None for b in boxes]
    if got != expect:
        raise _Refused("the sampled indices are not the ones the seed gives (sample_indices)")
    proved = 0
    for k, it in enumerate(boxes):
        b = _box(_get(it, "box"), f"boxes[{k}]")
        labels = _get(it, "labels")
        if not isinstance(labels, dict):
            raise _Refused(f"boxes[{k}]: labels: expected an object")
        for name, val in sorted(labels.items()):
            ok = _prove_label(model, b, name, val)
            if ok is None:
                continue
            if not ok:
                raise _Refused(f"box index {it['index']}: label {name} = {val} not re-proved in arb")
            proved += 1
    return f"{proved} INSIDE/OUTSIDE labels of {len(boxes)} sampled boxes (seed {seed}) re-proved in arb", {}


_CHECKERS = {
    "dkp": _check_dkp,
    "joint_cell": _check_joint_cell,
    "aspect_distinct": _check_aspect_distinct,
    "region_distinct": _check_region_distinct,
    "box_labels": _check_box_labels,
    "trajectory": _check_trajectory,
}


def check_claim(geometry: Geometry, kind: str, claim: dict, precision: int = 128) -> tuple[bool, str]:
    """Re-check one claim of a kind other than ``counts`` (what :func:`verify_directory` does per claim).

    Returns (verified, message).  The certificate writers call it before
    writing, so that a file never holds a claim its own checker refuses.
    """
    from flint import ctx

    if kind not in _CHECKERS:
        raise ValueError(f"kind: expected one of {', '.join(_CHECKERS)}, got {kind!r}")
    try:
        prec = _int(claim.get("precision", precision), "precision", *_PREC_RANGE)
        with ctx.workprec(prec):
            msg, _ = _CHECKERS[kind](_Model(geometry), claim, prec)
    except _Refused as exc:
        return False, str(exc)
    except (TypeError, KeyError, AttributeError, ValueError, OverflowError, ZeroDivisionError) as exc:
        return False, f"malformed claim ({type(exc).__name__}: {exc})"
    return True, msg


def box_label_proved(geometry: Geometry, box, name: str, value: int, precision: int = 128) -> bool | None:
    """Whether the checker re-proves label ``name`` = ``value`` (W or det_positive) on ``box`` (3, 2).

    None for BOUNDARY (3), which claims nothing.
    """
    from flint import ctx

    b = _box([[float(lo), float(hi)] for lo, hi in box])
    with ctx.workprec(precision):
        return _prove_label(_Model(geometry), b, name, value)


# --------------------------------------------------------------------------------------
# Counts
# --------------------------------------------------------------------------------------
def _count_bound(name: str, support: list[dict]) -> int:
    """The lower bound the verified support proves (proofs/lemma-checker.md, section counts).

    * ``aspects``: number of distinct det A signs among verified aspect_distinct boxes.
    * ``basic_regions``: over verified complete solves of joint vectors strictly
      inside the joint limits, the sum over their distinct aspect splits
      (n_wa1, n_wa2) of n_wa1 + n_wa2 (Theorem 1 and the constant-split lemma;
      proofs/lemma-theorem1-distinctness.md).
    * ``uniqueness_domains``: over the same solves, max n_wa1 + max n_wa2
      (proofs/lemma-uniqueness-domain-bound.md).
    """
    if name == "aspects":
        signs: set = set()
        for f in support:
            signs |= f.get("signs", set())
        return len(signs)
    solves = [f for f in support if f.get("complete") and f.get("in_limits")]
    if name == "basic_regions":
        splits = {(f["n_wa1"], f["n_wa2"]) for f in solves}
        return sum(a + b for a, b in splits)
    if name == "uniqueness_domains":
        return max((f["n_wa1"] for f in solves), default=0) + max((f["n_wa2"] for f in solves), default=0)
    raise _Refused(f"unknown count {name!r} (known: aspects, basic_regions, uniqueness_domains)")


def _check_count(claim: dict, verified: dict[str, dict]) -> tuple[str, dict]:
    name = _get(claim, "name")
    declared = _int(_get(claim, "lower_bound"), "lower_bound", 0)
    if claim.get("exact") is not False:
        raise _Refused("a count declared exact (or without \"exact\": false) needs an upper bound "
                       "this checker cannot verify")
    refs = _get(claim, "support")
    if not isinstance(refs, list):
        raise _Refused("support: expected a list of claim references \"file#id\"")
    used = [verified[r] for r in refs if r in verified]
    bound = _count_bound(name, used)
    if declared > bound:
        raise _Refused(f"declared lower bound {declared} exceeds {bound}, what the {len(used)} verified "
                       f"supporting claims (of {len(refs)} referenced) prove")
    found = claim.get("found")
    extra = f"; {found} found by the library (not certified)" if found is not None else ""
    return f"{name} >= {declared} (the {len(used)} verified supporting claims prove >= {bound}){extra}", {}

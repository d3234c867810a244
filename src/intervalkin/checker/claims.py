"""One check per claim kind, and :func:`check_claim`, which runs the right one at the claim's precision.

Each check takes the checker's arb model of the geometry, the claim (a JSON
object) and the working precision, and returns ``(statement, facts)``: the
sentence printed for a verified claim and the facts a ``counts`` claim may lean
on (n, n_wa1, n_wa2, complete, in_limits, signs).  A step that cannot be
re-proved raises :class:`~intervalkin.checker.parse.Refused`.  What each kind
proves is listed in :mod:`intervalkin.checker`; ``trajectory`` lives in
:mod:`intervalkin.checker.trajectory`.

``counts`` is the one kind checked from the other claims rather than from the
geometry: each declared lower bound must not exceed what the verified
supporting claims prove (:func:`count_bound`).
"""

from __future__ import annotations

from flint import ctx

from intervalkin.checker.aspects import check_aspect_connected
from intervalkin.checker.consistency import check_found, check_summary_block
from intervalkin.checker.joint_join import check_joint_join
from intervalkin.checker.joint_models import check_joint_fold_model
from intervalkin.checker.labels import (
    det_negative,
    det_positive,
    holds_on_box,
    in_w,
    prove_label,
)
from intervalkin.checker.model import ArbModel
from intervalkin.checker.parse import (
    ASPECT_SIGN,
    PREC_RANGE,
    Refused,
    get,
    inside,
    read_aspect,
    read_box,
    read_int,
    read_rho,
    sample_indices,
)
from intervalkin.checker.solutions import check_solutions
from intervalkin.checker.trajectory import check_trajectory
from intervalkin.core.geometry import Geometry

__all__ = ['CHECKS', 'SUPPORTED_CHECKS', 'MALFORMED', 'check_claim', 'run_check', 'malformed_message', 'check_count', 'count_bound',
           'count_upper']

#: Errors that mean a field had an unexpected type or value: the claim is malformed (refused, not crashed on).
MALFORMED = (TypeError, KeyError, AttributeError, ValueError, OverflowError, ZeroDivisionError)


def _strictly_in_limits(g: Geometry, rho) -> bool:
    return all(g.rho_min[i] < rho[i] < g.rho_max[i] for i in range(3))


def _solution_list(claim: dict) -> list:
    sols = get(claim, "solutions")
    if not isinstance(sols, list):
        raise Refused("solutions: expected a list")
    return sols


def _check_dkp(model: ArbModel, claim: dict, prec: int) -> tuple[str, dict]:
    rho = read_rho(claim)
    complete = get(claim, "complete")
    if not isinstance(complete, bool):
        raise Refused("complete: expected true or false")
    facts = check_solutions(model, rho, _solution_list(claim), complete, claim.get("phi0"), prec)
    declared = claim.get("count")
    if declared is not None and declared != facts["n"]:
        raise Refused(f"declared count {declared!r} but {facts['n']} solution boxes are listed")
    facts.update(rho=rho, in_limits=_strictly_in_limits(model.geometry, rho))
    q = ", ".join(str(r) for r in rho)
    if complete:
        msg = (f"q = ({q}) has exactly {facts['n']} solutions ({facts['n_wa1']} with det A > 0, "
               f"{facts['n_wa2']} with det A < 0), one in each box")
    else:
        msg = f"q = ({q}): each of the {facts['n']} boxes holds exactly one solution (completeness not claimed)"
    return msg, facts


def _check_joint_cell(model: ArbModel, claim: dict, prec: int) -> tuple[str, dict]:
    rho = read_rho(claim, "witness")
    g = model.geometry
    if not all(g.rho_min[i] <= rho[i] <= g.rho_max[i] for i in range(3)):
        raise Refused("witness: not within the joint limits")
    facts = check_solutions(model, rho, _solution_list(claim), True, get(claim, "phi0"), prec)
    for key, val in (("count", facts["n"]), ("n_wa1", facts["n_wa1"]), ("n_wa2", facts["n_wa2"])):
        if get(claim, key) != val:
            raise Refused(f"declared {key} = {claim[key]!r} but the checker proves {val}")
    facts.update(rho=rho, in_limits=_strictly_in_limits(g, rho))
    q = ", ".join(str(r) for r in rho)
    return (f"witness q = ({q}) of cell {claim.get('cell')!r} has exactly {facts['n']} solutions, split "
            f"{facts['n_wa1']} (WA1) + {facts['n_wa2']} (WA2), none singular"), facts


def _check_aspect_distinct(model: ArbModel, claim: dict, prec: int) -> tuple[str, dict]:
    items = get(claim, "boxes")
    if not isinstance(items, list) or len(items) < 2:
        raise Refused("boxes: expected at least two witness boxes")
    signs = set()
    for k, it in enumerate(items):
        b = read_box(get(it, "box"), f"boxes[{k}]")
        aspect = get(it, "aspect")
        if aspect not in ASPECT_SIGN:
            raise Refused(f"boxes[{k}]: aspect must be WA1 or WA2, got {aspect!r}")
        if not holds_on_box(b, lambda s: in_w(model, s)):
            raise Refused(f"boxes[{k}]: not proved inside W (joint limits on the whole box)")
        test = det_positive if ASPECT_SIGN[aspect] > 0 else det_negative
        if not holds_on_box(b, lambda s: test(model, s)):
            raise Refused(f"boxes[{k}]: det A not proved {'> 0' if ASPECT_SIGN[aspect] > 0 else '< 0'} "
                          "on the whole box")
        signs.add(ASPECT_SIGN[aspect])
    if signs != {1, -1}:
        raise Refused("the boxes do not have opposite signs of det A")
    return "two boxes inside W with opposite certified signs of det A: they lie in different aspects", {"signs": signs}


def _check_region_distinct(model: ArbModel, claim: dict, prec: int) -> tuple[str, dict]:
    rho = read_rho(claim)
    aspect, sign = read_aspect(claim)
    sols = get(claim, "solutions")
    if not isinstance(sols, list) or len(sols) < 2:
        raise Refused("solutions: expected at least two solutions of one aspect")
    for k, s in enumerate(sols):
        if get(s, "det_sign") != sign:
            raise Refused(f"solution {k}: det_sign {s.get('det_sign')!r} is not the sign of {aspect}")
    facts = check_solutions(model, rho, sols, False, None, prec)
    pieces = []
    for k, s in enumerate(sols):
        b = read_box(s["box"], f"solution {k} box")
        pb = get(s, "paving_box")
        pbox = read_box(get(pb, "box"), f"solution {k} paving box")
        if not inside(b, pbox):
            raise Refused(f"solution {k}: the solution box is not inside the stated paving box")
        labels = get(pb, "labels")
        want = {"W": 2, "det_positive": 2 if sign > 0 else 1}
        for name, val in want.items():
            if labels.get(name) != val:
                raise Refused(f"solution {k}: paving box label {name} = {labels.get(name)!r}, expected {val}")
            if not prove_label(model, pbox, name, val):
                raise Refused(f"solution {k}: paving box label {name} = {val} not re-proved in arb")
        pieces.append(read_int(get(s, "piece"), f"solution {k} piece", 0))
    if len(set(pieces)) != len(pieces):
        raise Refused(f"two solutions are declared in one piece {pieces}: that would contradict Theorem 1")
    q = ", ".join(str(r) for r in rho)
    return (f"q = ({q}) has {len(sols)} distinct solutions in {aspect}, each in a paving box re-proved inside "
            f"{aspect}; the library puts those boxes in pieces {pieces} off S_c (not re-checked here), which "
            "by Theorem 1 then lie in pairwise different basic regions"), facts


def _check_box_labels(model: ArbModel, claim: dict, prec: int) -> tuple[str, dict]:
    seed = read_int(get(claim, "seed"), "seed")
    population = read_int(get(claim, "population"), "population", 1)
    boxes = get(claim, "boxes")
    if not isinstance(boxes, list):
        raise Refused("boxes: expected a list")
    size = read_int(get(claim, "sample_size"), "sample_size", 0)
    if min(size, population) != len(boxes):
        raise Refused(f"{len(boxes)} boxes listed for a sample of {min(size, population)}")
    expect = sample_indices(seed, population, size)
    got = [b.get("index") if isinstance(b, dict) else None for b in boxes]
    if got != expect:
        raise Refused("the sampled indices are not the ones the seed gives (sample_indices)")
    proved = 0
    for k, it in enumerate(boxes):
        b = read_box(get(it, "box"), f"boxes[{k}]")
        labels = get(it, "labels")
        if not isinstance(labels, dict):
            raise Refused(f"boxes[{k}]: labels: expected an object")
        for name, val in sorted(labels.items()):
            ok = prove_label(model, b, name, val)
            if ok is None:
                continue
            if not ok:
                raise Refused(f"box index {it['index']}: label {name} = {val} not re-proved in arb")
            proved += 1
    return f"{proved} INSIDE/OUTSIDE labels of {len(boxes)} sampled boxes (seed {seed}) re-proved in arb", {}


#: The check of each claim kind but ``counts``.
CHECKS = {
    "dkp": _check_dkp,
    "joint_cell": _check_joint_cell,
    "aspect_distinct": _check_aspect_distinct,
    "region_distinct": _check_region_distinct,
    "box_labels": _check_box_labels,
    "trajectory": check_trajectory,
    "aspect_connected": check_aspect_connected,
    "joint_fold_model": check_joint_fold_model,
}
#: Checks that also lean on claims verified before them ("file#id" -> facts): a join on its fold models.
SUPPORTED_CHECKS = {
    "joint_join": check_joint_join,
}


def run_check(geometry: Geometry, kind: str, claim: dict, precision: int,
              verified: dict | None = None) -> tuple[str, dict]:
    """(statement, facts) of one claim of a kind other than ``counts``, at its own precision.

    The claim's ``precision`` field, if any, overrides ``precision``.  ``verified`` ("file#id" ->
    facts of the claims verified so far) is what a kind of :data:`SUPPORTED_CHECKS` may lean on.
    Raises :class:`Refused` or one of :data:`MALFORMED`.
    """
    prec = read_int(claim.get("precision", precision), "precision", *PREC_RANGE)
    with ctx.workprec(prec):
        if kind in SUPPORTED_CHECKS:
            return SUPPORTED_CHECKS[kind](ArbModel(geometry), claim, prec, verified or {})
        return CHECKS[kind](ArbModel(geometry), claim, prec)


def malformed_message(exc: BaseException) -> str:
    """The reason given for a claim whose fields made a check fail with ``exc`` (one of :data:`MALFORMED`)."""
    return f"malformed claim ({type(exc).__name__}: {exc})"


def check_claim(geometry: Geometry, kind: str, claim: dict, precision: int = 128,
                verified: dict | None = None) -> tuple[bool, str]:
    """Re-check one claim of a kind other than ``counts`` (what :func:`verify_directory` does per claim).

    Returns (verified, message).  The certificate writers call it before
    writing, so that a file never holds a claim its own checker refuses.
    ``verified``: the facts of claims verified before, for a kind that refers to them.
    """
    if kind not in CHECKS and kind not in SUPPORTED_CHECKS:
        raise ValueError(f"kind: expected one of {', '.join(list(CHECKS) + list(SUPPORTED_CHECKS))}, got {kind!r}")
    try:
        msg, _ = run_check(geometry, kind, claim, precision, verified)
    except Refused as exc:
        return False, str(exc)
    except MALFORMED as exc:
        return False, malformed_message(exc)
    return True, msg


# --------------------------------------------------------------------------------------
# Counts
# --------------------------------------------------------------------------------------
def count_bound(name: str, support: list[dict]) -> int:
    """The lower bound the verified support proves (proofs/lemma-checker.md, section counts).

    * ``aspects``: for each sign of det A, the larger of 1 when a verified aspect_distinct box has
      it and the ``components_at_least`` of its verified aspect_connected claim (pieces of the
      non-OUT boxes holding sinks, proofs/lemma-aspect-retraction.md); summed over the signs.
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
        pieces = {f["aspect_sign"]: int(f.get("components_at_least", 0)) for f in support if "aspect_sign" in f}
        return sum(max(1 if s in signs else 0, pieces.get(s, 0)) for s in (1, -1))
    solves = [f for f in support if f.get("complete") and f.get("in_limits")]
    if name == "basic_regions":
        splits = {(f["n_wa1"], f["n_wa2"]) for f in solves}
        return sum(a + b for a, b in splits)
    if name == "uniqueness_domains":
        return max((f["n_wa1"] for f in solves), default=0) + max((f["n_wa2"] for f in solves), default=0)
    raise Refused(f"unknown count {name!r} (known: aspects, basic_regions, uniqueness_domains)")


def count_upper(name: str, support: list[dict]) -> int | None:
    """The upper bound the verified support proves, None when it proves none (proofs/lemma-aspect-retraction.md).

    * ``aspects``: when verified ``aspect_connected`` claims cover both signs of det A, the sum
      of their bounds on the components of each sign's part of W (its groups of sinks; 0 for a
      sign proved empty): every aspect is one such component.
    """
    if name != "aspects":
        return None
    by_sign = {f["aspect_sign"]: f for f in support if "aspect_sign" in f}
    if set(by_sign) != {1, -1}:
        return None
    return sum(int(f["components_at_most"]) for f in by_sign.values())


def check_count(claim: dict, verified: dict[str, dict], summary: dict | None = None) -> tuple[str, dict]:
    """Re-check one ``counts`` claim against the facts of the claims verified so far ("file#id" -> facts).

    The declared lower bound must be backed by the verified support, the
    library's ``found`` must not fall below what that support proves, and, when
    ``summary`` (the output folder's summary.json) is given, its block for this
    count must agree (:mod:`intervalkin.checker.consistency`).
    """
    name = get(claim, "name")
    declared = read_int(get(claim, "lower_bound"), "lower_bound", 0)
    refs = get(claim, "support")
    if not isinstance(refs, list):
        raise Refused("support: expected a list of claim references \"file#id\"")
    used = [verified[r] for r in refs if r in verified]
    bound = count_bound(name, used)
    upper = count_upper(name, used)
    if declared > bound:
        raise Refused(f"declared lower bound {declared} exceeds {bound}, what the {len(used)} verified "
                      f"supporting claims (of {len(refs)} referenced) prove")
    declared_upper = claim.get("upper_bound")
    if declared_upper is not None:
        declared_upper = read_int(declared_upper, "upper_bound", 0)
        if upper is None or declared_upper < upper:
            raise Refused(f"declared upper bound {declared_upper} is not backed: the verified supporting claims "
                          f"prove {'no upper bound' if upper is None else f'at most {upper}'}")
    if claim.get("exact") is not (declared_upper is not None and declared_upper == declared):
        raise Refused(f"exact is {claim.get('exact')!r} with declared bounds {declared}..{declared_upper}: a count "
                      "is exact exactly when a proved upper bound meets its lower bound")
    found = claim.get("found")
    check_found(name, found, bound, upper)
    extra = f"; {found} found by the library" if found is not None else ""
    extra += check_summary_block(name, claim, bound, summary, upper)
    if claim["exact"]:
        extra = f"; exactly {declared}" + extra
    facts = {"name": name, "lower_bound": declared, "proved": bound, "upper_bound": declared_upper, "found": found}
    upper_text = "" if upper is None else f" and <= {upper}"
    return (f"{name} >= {declared} (the {len(used)} verified supporting claims prove >= {bound}{upper_text})"
            f"{extra}"), facts

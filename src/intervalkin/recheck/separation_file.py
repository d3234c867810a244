"""Count barriers re-proved from an output folder: ``certificates/joint_separation.json`` and ``.npz``.

Each claim says that the witness of one joint cell and the witnesses of the other cells of its
signature (count, n_wa1, n_wa2) lie in different components of the joint box Q minus g(S).  Its
evidence is a *region* S (closed boxes, rows of the npz) and a *barrier* (closed boxes, usually
face rectangles).  :func:`check_separation` proves, from the files and the geometry alone:

1. every witness's solution list is complete, with the declared count and split, and all declare
   the claim's signature (the arb checker, :func:`intervalkin.checker.claims.run_check`);
2. no point of any barrier box has exactly c solutions, c the signature's count
   (:func:`~intervalkin.recheck.count_range.excludes_count`);
3. the boundary of S inside the open joint box is covered by the barrier (:mod:`~intervalkin.recheck.region_boundary`): on every plane
   x_a = v that holds a face of a box of S, with v strictly between the joint limits of axis a,
   the plane is cut into open cells by every rectangle edge met there; a cell that S reaches from
   one side only must lie in some barrier box (:func:`uncovered_boundary`);
4. the cell's witness lies in the interior of a box of S, every other witness outside S.

A path of Q minus g(S) from the first witness to another keeps c solutions
(lemma-constant-count-off-gS.md); pushed into general position inside the open joint box, it
leaves S through the open cell of some plane, which the barrier covers: a point with c solutions
on a barrier box, against 2.  The argument is ``proofs/lemma-count-barrier.md``.

Numbers read from the npz are binary64, hence exact rationals; the joint limits are compared
exactly (as Fractions), witnesses are exact rationals enclosed by floats one ulp apart.
"""

from __future__ import annotations

import json
import time
import zipfile
from fractions import Fraction
from pathlib import Path

import networkx as nx
import numpy as np

from intervalkin.checker.claims import MALFORMED, run_check
from intervalkin.checker.folder import CheckResult
from intervalkin.checker.parse import Refused, read_box
from intervalkin.core.errors import CertificateFormatError
from intervalkin.core.geometry import Geometry
from intervalkin.core.workers import Workers, default_workers
from intervalkin.recheck.arith import fraction_enclosure
from intervalkin.recheck.arc_pattern import (MAX_COUNT, box_arcs, face_relations, own_patterns,
                                             pattern_of_angles, prune_relations, unpack)
from intervalkin.recheck.count_range import excludes_count, supported
from intervalkin.recheck.reduced_equation import reduced_constants
from intervalkin.recheck.paving_file import folder_geometry
from intervalkin.recheck.region_boundary import face_pairs, require_covered, uncovered_boundary

__all__ = ["CLAIMS", "ARRAYS", "KIND", "uncovered_boundary", "face_pairs", "check_separation",
           "check_pattern_separation", "recheck_separations", "barrier_bound",
           "components_apart"]

#: Where an output folder keeps the separation claims and their boxes.
CLAIMS = Path("certificates") / "joint_separation.json"
ARRAYS = Path("certificates") / "joint_separation.npz"
#: The kind of the result lines ``verify`` prints for them.
KIND = "joint_separation"
#: Barrier boxes worth sending to a second process at once.
MIN_PART = 400
_COLUMNS = ("region_lo", "region_hi", "region_claim", "barrier_lo", "barrier_hi", "barrier_claim")
#: Columns only pattern barriers need (a file of count barriers alone may lack them).
_PATTERN_COLUMNS = ("barrier_box", "barrier_outer_lo", "barrier_outer_hi", "pattern_box", "pattern_rows")


def _witness(geometry: Geometry, obj, what: str) -> tuple[tuple[Fraction, ...], tuple[int, int, int]]:
    """The witness point and its (count, n_wa1, n_wa2), its complete solution list re-proved in arb."""
    if not isinstance(obj, dict):
        raise Refused(f"{what}: expected an object")
    try:
        _, facts = run_check(geometry, "joint_cell", dict(obj, id="witness"), 128)
    except MALFORMED as exc:
        raise Refused(f"{what}: malformed ({exc})") from None
    except Refused as exc:
        raise Refused(f"{what}: {exc}") from None
    q = tuple(Fraction(str(v)) for v in obj["witness"])
    return q, (int(facts["n"]), int(facts["n_wa1"]), int(facts["n_wa2"]))


def _enclose(q: tuple[Fraction, ...]) -> tuple[np.ndarray, np.ndarray]:
    pairs = [fraction_enclosure(v) for v in q]
    return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])


def check_separation(geometry: Geometry, claim: dict, region: tuple[np.ndarray, np.ndarray],
                     barrier: tuple[np.ndarray, np.ndarray], workers: Workers | None = None) -> tuple[str, dict]:
    """Re-prove one claim (module docstring); (statement, facts) or :class:`Refused`.  ``workers`` may share
    the count ranges of the barrier boxes between processes (the same verdict)."""
    r_lo, r_hi = region
    b_lo, b_hi = barrier
    sig, x, _, others = _common(geometry, claim, {"region": region, "barrier": barrier})
    x_lo, x_hi = _enclose(x)
    if not np.any(np.all((r_lo < x_lo) & (x_hi < r_hi), axis=1)):
        raise Refused("the witness is not inside a box of the region")
    cells = []
    for k, (y, other) in enumerate(others):
        y_lo, y_hi = _enclose(y)
        if np.any(np.all((r_lo <= y_hi) & (y_lo <= r_hi), axis=1)):
            raise Refused(f"others[{k}]: its witness may lie in the region")
        cells.append(other.get("cell"))
    free = excludes_count(geometry, b_lo, b_hi, sig[0], workers)
    if not free.all():
        i = int(np.flatnonzero(~free)[0])
        raise Refused(f"{int((~free).sum())} barrier boxes not proved free of {sig[0]} solutions, the first "
                      f"[{b_lo[i].tolist()}, {b_hi[i].tolist()}]")
    require_covered(r_lo, r_hi, b_lo, b_hi, geometry)
    facts = {"signature": sig, "cell": claim.get("cell"), "others": cells}
    return (f"cell {claim.get('cell')} and cells {', '.join(map(str, cells))} ({sig[0]} solutions) lie in different "
            f"components of the joint box minus g(S): {len(r_lo)} region boxes, their boundary covered by "
            f"{len(b_lo)} boxes with no point of {sig[0]} solutions"), facts


def _common(geometry: Geometry, claim: dict, boxes: dict[str, tuple[np.ndarray, np.ndarray]]):
    """The checks both kinds share: signature, boxes, the witnesses re-proved.  Returns (signature, witness
    point, its object, [(other point, its object)])."""
    sig = claim.get("signature")
    if not (isinstance(sig, list) and len(sig) == 3 and all(isinstance(v, int) and 0 <= v <= 6 for v in sig)):
        raise Refused(f"signature: expected [count, n_wa1, n_wa2], got {sig!r}")
    sig = tuple(sig)
    others = claim.get("others")
    if not isinstance(others, list) or not others:
        raise Refused("others: expected a non-empty list of witnesses")
    for name, (lo, hi) in boxes.items():
        if lo.size == 0 and name == "region":
            raise Refused("the region holds no box")
        if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo <= hi) and np.all(lo > 0)):
            raise Refused(f"{name}: boxes need finite bounds with 0 < lo <= hi")
    if not supported(geometry):
        raise Refused("count ranges are refused for this geometry (|p_i| = |A_i - A_1| on legs 2 and 3)")
    x, got = _witness(geometry, claim.get("witness"), "witness")
    if got != sig:
        raise Refused(f"witness: its solutions give {got}, not the claimed signature {sig}")
    if not all(Fraction(geometry.rho_min[a]) < x[a] < Fraction(geometry.rho_max[a]) for a in range(3)):
        raise Refused("the witness is not strictly inside the joint limits")
    rest = []
    for k, other in enumerate(others):
        y, got = _witness(geometry, other, f"others[{k}]")
        if got != sig:
            raise Refused(f"others[{k}]: its solutions give {got}, not the claimed signature {sig}")
        rest.append((y, other))
    return sig, x, claim["witness"], rest


def _solution_phi(witness: dict) -> tuple[np.ndarray, np.ndarray]:
    boxes = [read_box(s["box"], f"solution {k}") for k, s in enumerate(witness["solutions"])]
    return np.array([b[2][0] for b in boxes], dtype=np.float64), np.array([b[2][1] for b in boxes], dtype=np.float64)


def _unwalled(k, f_lo: np.ndarray, f_hi: np.ndarray, rels: list[set], count: int, bad) -> tuple | None:
    """The first face t with a pair (u, v) of its relation for which ``bad(t, u, v)`` holds, and that pair, after
    the faces with such pairs that split count ranges prove free of ``count`` solutions get the empty relation
    (lemma, fact 4); None when no face is left."""
    failing = np.array([t for t, rel in enumerate(rels) if any(bad(t, u, v) for u, v in rel)], dtype=np.int64)
    rels = prune_relations(k, f_lo, f_hi, rels, count, failing)
    return next(((int(t), (u, v)) for t in failing.tolist() for u, v in rels[t] if bad(t, u, v)), None)


def check_pattern_separation(geometry: Geometry, claim: dict, region: tuple[np.ndarray, np.ndarray],
                             patterns: list[set], barrier: tuple[np.ndarray, np.ndarray], barrier_box: np.ndarray,
                             outer: tuple[np.ndarray, np.ndarray]) -> tuple[str, dict]:
    """Re-prove one pattern barrier (proofs/lemma-pattern-barrier.md); (statement, facts) or :class:`Refused`.

    ``patterns[i]``: the pattern set of region box i; barrier box j lies in region box ``barrier_box[j]`` and
    in the box ``outer[.][j]``.  Proves: the witnesses' solution lists (arb); the witness inside a region box
    whose set holds its pattern, and every other witness, in every region box that may hold it, with a
    pattern outside the set; on every 2-D (or 3-D) intersection of two region boxes, the face relation links
    patterns inside the two sets only to each other; on every barrier box, no relation pair starts in its
    region box's set; the region's boundary inside the open joint box covered by barrier boxes."""
    r_lo, r_hi = region
    b_lo, b_hi = barrier
    o_lo, o_hi = outer
    sig, x, x_obj, others = _common(geometry, claim, {"region": region, "barrier": barrier,
                                                      "outer boxes": outer})
    count = sig[0]
    if not (np.all(b_lo >= r_lo[barrier_box]) and np.all(b_hi <= r_hi[barrier_box])):
        raise Refused("a barrier box does not lie in its region box")
    if not (np.all(b_lo >= o_lo) and np.all(b_hi <= o_hi)):
        raise Refused("a barrier box does not lie in its outer box")
    k = reduced_constants(geometry)
    arcs = box_arcs(k, r_lo, r_hi)
    x_lo, x_hi = _enclose(x)
    holds = np.flatnonzero(np.all((r_lo <= x_lo) & (x_hi <= r_hi), axis=1))
    phi = _solution_phi(x_obj)
    if not any(pattern_of_angles(arcs.signs[i], *phi) in patterns[i] for i in holds.tolist()):
        raise Refused("the witness lies in no region box whose pattern set holds its pattern")
    cells = []
    for n_o, (y, obj) in enumerate(others):
        y_lo, y_hi = _enclose(y)
        phi = _solution_phi(obj)
        for i in np.flatnonzero(np.all((r_lo <= y_hi) & (y_lo <= r_hi), axis=1)).tolist():
            got = pattern_of_angles(arcs.signs[i], *phi)
            if got is None or got in patterns[i]:
                raise Refused(f"others[{n_o}]: its witness may lie in region box {i} with a pattern of its set")
        cells.append(obj.get("cell"))
    own = own_patterns(arcs, count)
    pi, pj = face_pairs(r_lo, r_hi)
    n_pairs = pi.size
    # a face whose boxes' own pattern sets hold no pair the sets would tear needs no relation (fact 5)
    tears = [any((u in patterns[i]) != (v in patterns[j]) for u in own[i] for v in own[j])
             for i, j in zip(pi.tolist(), pj.tolist())]
    pi, pj = pi[tears], pj[tears]
    if pi.size:
        f_lo, f_hi = np.maximum(r_lo[pi], r_lo[pj]), np.minimum(r_hi[pi], r_hi[pj])
        rels = face_relations(k, f_lo, f_hi, arcs.take(pi), arcs.take(pj), count)
        torn = _unwalled(k, f_lo, f_hi, rels, count,
                         lambda t, u, v: (u in patterns[int(pi[t])]) != (v in patterns[int(pj[t])]))
        if torn is not None:
            t, (u, v) = torn
            raise Refused(f"region boxes {int(pi[t])} and {int(pj[t])}: on their shared face pattern {list(u)} of one "
                          f"and {list(v)} of the other may meet, and only one is in its box's set")
    # a barrier box on a region box none of whose own patterns is in its set, or beyond which the outer box allows
    # no pattern of the count, holds no pair starting in the set
    at = np.flatnonzero([bool(own[i] & patterns[i]) for i in barrier_box.tolist()])
    if at.size:
        # boxes beyond the region hold several barrier boxes each: their arcs once
        outer, which = np.unique(np.hstack([o_lo[at], o_hi[at]]), axis=0, return_inverse=True)
        which = which.ravel()
        o_arcs = box_arcs(k, outer[:, :3], outer[:, 3:])
        at_o = np.array([bool(x) for x in own_patterns(o_arcs, count)], dtype=bool)[which]
        at, o_arcs = at[at_o], o_arcs.take(which[at_o])
    if at.size:
        rel = face_relations(k, b_lo[at], b_hi[at], arcs.take(barrier_box[at]), o_arcs, count)
        open_ = _unwalled(k, b_lo[at], b_hi[at], rel, count, lambda t, u, v: u in patterns[int(barrier_box[at[t]])])
        if open_ is not None:
            t = int(at[open_[0]])
            raise Refused(f"barrier box {t} [{b_lo[t].tolist()}, {b_hi[t].tolist()}]: a pattern of its region "
                          "box's set is not excluded there")
    require_covered(r_lo, r_hi, b_lo, b_hi, geometry)
    facts = {"signature": sig, "cell": claim.get("cell"), "others": cells}
    return (f"cell {claim.get('cell')} and cells {', '.join(map(str, cells))} ({count} solutions) lie in different "
            f"components of the joint box minus g(S): {len(r_lo)} region boxes with the patterns of the cell's "
            f"solutions, {n_pairs} shared faces ({pi.size} of them ranged), the boundary covered by {len(b_lo)} boxes where none of "
            "those patterns occurs"), facts


def _read(folder: Path) -> tuple[dict, dict[str, np.ndarray]]:
    try:
        doc = json.loads((folder / CLAIMS).read_text(encoding="utf-8"))
        with np.load(folder / ARRAYS, allow_pickle=False) as z:
            arrays = {k: np.asarray(z[k]) for k in _COLUMNS}
            arrays.update({k: np.asarray(z[k]) for k in _PATTERN_COLUMNS if k in z.files})
    except FileNotFoundError as exc:
        raise CertificateFormatError(f"{folder}: {exc.filename} missing beside {CLAIMS}") from None
    except KeyError as exc:
        raise CertificateFormatError(f"{folder / ARRAYS}: column {exc} missing") from None
    except (OSError, ValueError, zipfile.BadZipFile, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise CertificateFormatError(f"{folder}: cannot read the separation certificate ({exc})") from None
    n_bar = arrays["barrier_lo"].shape[0]
    shapes = {"barrier_box": (n_bar,), "barrier_outer_lo": (n_bar, 3), "barrier_outer_hi": (n_bar, 3),
              "pattern_rows": (arrays.get("pattern_box", np.zeros(0)).shape[0], MAX_COUNT)}
    for k in _PATTERN_COLUMNS:
        if k in arrays:
            kind = "f" if k.startswith("barrier_outer") else "i"
            if arrays[k].dtype.kind != kind or (k in shapes and arrays[k].shape != shapes[k]) or (
                    k == "pattern_box" and arrays[k].ndim != 1):
                raise CertificateFormatError(f"{folder / ARRAYS}: {k} has the wrong type or shape")
    if not isinstance(doc, dict) or not isinstance(doc.get("claims"), list):
        raise CertificateFormatError(f"{folder / CLAIMS}: claims: expected a list")
    for k in ("region_lo", "region_hi", "barrier_lo", "barrier_hi"):
        if arrays[k].dtype != np.float64 or arrays[k].ndim != 2 or arrays[k].shape[1:] != (3,):
            raise CertificateFormatError(f"{folder / ARRAYS}: {k} must be float64 of shape (n, 3)")
    for k in ("region_claim", "barrier_claim"):
        if arrays[k].dtype.kind != "i" or arrays[k].shape != arrays[k.replace("claim", "lo")].shape[:1]:
            raise CertificateFormatError(f"{folder / ARRAYS}: {k} must be integers, one per box")
    return doc, arrays


def recheck_separations(folder: str | Path) -> list[CheckResult]:
    """One verdict per separation claim of the output folder (given as the folder or its ``certificates/``);
    [] when it has none, plus the ``barrier_bound`` verdict when ``summary.json`` states a bound from barriers
    (also when there are no claims: then it is refused unless it is the counts claim's own).  Raises
    :class:`CertificateFormatError` for unreadable or malformed files."""
    root = Path(folder)
    if root.name == "certificates" and not (root / CLAIMS).is_file():
        root = root.parent
    if not (root / CLAIMS).is_file():
        # a summary may still state a bound from barriers: with no claims to back it, the verdict refuses it
        bound = _summary_bound(root, [], [])
        return [] if bound is None else [bound]
    doc, arrays = _read(root)
    geometry = folder_geometry(root / "pavings" / "workspace.npz")
    out = []
    with Workers(default_workers(), min_items=MIN_PART) as workers:
        for j, claim in enumerate(doc["claims"]):
            out.append(_one(geometry, j, claim, arrays, workers))
    bound = _summary_bound(root, doc["claims"], out)
    return out + ([] if bound is None else [bound])


def barrier_bound(counts_lower: int, claims: list, verified: list[bool]) -> int:
    """The basic regions the verified barriers prove beside the counts claim's lower bound L
    (proofs/lemma-count-barrier.md, last section): L plus, for each signature with n solutions, n times (k - 1),
    where k is :func:`components_apart` of the signature.  L counts one component of each signature at most, and
    a signature L misses only makes the sum smaller than the truth."""
    return counts_lower + sum(sig[0] * (k - 1) for sig, k in components_apart(claims, verified).items())


def components_apart(claims: list, verified: list[bool]) -> dict[tuple, int]:
    """Per signature of the verified claims: the size of a largest set of its witness points proved pairwise
    apart (a claim proves its witness apart from each of its others), a lower bound of its components.
    Witnesses are compared as the exact points they are, not by the cell numbers the file gives them, so a
    claim written twice, or one per cell of a signature, proves no more than its points do."""
    apart: dict[tuple, nx.Graph] = {}
    for claim, ok in zip(claims, verified):
        if not ok:
            continue
        graph = apart.setdefault(tuple(claim["signature"]), nx.Graph())
        x = _point(claim["witness"])
        graph.add_node(x)
        graph.add_edges_from((x, y) for y in map(_point, claim["others"]) if y != x)
    # a signature has a few dozen witnesses at most: an exact largest clique is cheap
    return {sig: max(1, len(nx.max_weight_clique(g, weight=None)[0])) for sig, g in apart.items()}


def _point(witness: dict) -> tuple[Fraction, ...]:
    return tuple(Fraction(str(v)) for v in witness["witness"])


def _summary_bound(root: Path, claims: list, results: list[CheckResult]) -> CheckResult | None:
    """When ``summary.json`` states ``basic_regions.barriers_at_least``, one more verdict: that number may not
    exceed :func:`barrier_bound` over the claims verified here and the counts claim's lower bound (which
    ``verify`` re-proves apart)."""
    try:
        summary = json.loads((root / "summary.json").read_text(encoding="utf-8"))
        stated = summary["basic_regions"]["barriers_at_least"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    try:
        counts = json.loads((root / "certificates" / "counts.json").read_text(encoding="utf-8"))
        lower = next(int(c["lower_bound"]) for c in counts["claims"] if c.get("name") == "basic_regions")
    except (OSError, ValueError, KeyError, TypeError, StopIteration):
        return CheckResult("summary.json", "basic_regions", "barrier_bound", False,
                           "barriers_at_least is stated but counts.json has no basic_regions lower bound to add to")
    proved = barrier_bound(lower, claims, [r.verified for r in results])
    if not isinstance(stated, int) or stated > proved:
        return CheckResult("summary.json", "basic_regions", "barrier_bound", False,
                           f"barriers_at_least = {stated!r} but the verified barriers prove {proved}")
    return CheckResult("summary.json", "basic_regions", "barrier_bound", True,
                       f"basic regions >= {proved}: the counts claim's {lower} and the verified barriers "
                       f"(summary.json states {stated})")


def _one(geometry: Geometry, j: int, claim, arrays: dict, workers: Workers) -> CheckResult:
    """The verdict on claim ``j`` of the file (its boxes: the npz rows tagged ``j``)."""
    t0 = time.perf_counter()
    name = str(claim.get("id", f"#{j}")) if isinstance(claim, dict) else f"#{j}"
    try:
        if not isinstance(claim, dict) or claim.get("region") != j:
            raise Refused(f"claim {j}: expected an object whose region is {j}")
        rows, walls = arrays["region_claim"] == j, arrays["barrier_claim"] == j
        region = (arrays["region_lo"][rows], arrays["region_hi"][rows])
        barrier = (arrays["barrier_lo"][walls], arrays["barrier_hi"][walls])
        if claim.get("kind", "count") == "pattern":
            if any(k not in arrays for k in _PATTERN_COLUMNS):
                raise Refused("a pattern barrier needs the npz columns " + ", ".join(_PATTERN_COLUMNS))
            index = np.flatnonzero(rows)
            local = np.full(rows.size, -1, dtype=np.int64)
            local[index] = np.arange(index.size)
            box = arrays["barrier_box"][walls]
            if np.any((box < 0) | (box >= rows.size)) or np.any(local[np.clip(box, 0, rows.size - 1)] < 0):
                raise Refused("barrier_box: a barrier row points to no region box of its claim")
            mine = (arrays["pattern_box"] >= 0) & (arrays["pattern_box"] < rows.size)
            mine[mine] &= rows[arrays["pattern_box"][mine]]
            patterns: list[set] = [set() for _ in range(index.size)]
            for r, pat in zip(local[arrays["pattern_box"][mine]].tolist(), unpack(arrays["pattern_rows"][mine])):
                patterns[r].add(pat)
            msg, _ = check_pattern_separation(geometry, claim, region, patterns, barrier, local[box],
                                              (arrays["barrier_outer_lo"][walls], arrays["barrier_outer_hi"][walls]))
        elif claim.get("kind", "count") == "count":
            msg, _ = check_separation(geometry, claim, region, barrier, workers)
        else:
            raise Refused(f"kind: expected count or pattern, got {claim.get('kind')!r}")
    except Refused as exc:
        return CheckResult(CLAIMS.name, name, KIND, False, str(exc))
    return CheckResult(CLAIMS.name, name, KIND, True, f"{msg} ({time.perf_counter() - t0:.1f} s)")

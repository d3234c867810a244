"""Window patterns (space.joint_patterns, proofs/lemma-window-patterns.md) on the session's depth-5 paving with windows.

Every check is against the certified direct-kinematics solver (``solve.dkp.solve``) at sampled joint vectors:

- fixed-root arcs: at random points of modelled boxes each arc ``root_lo .. root_hi`` holds exactly one
  solution, a box has ``off[:, 0]`` arcs, and every solution lies in exactly one unit (a window or a
  fixed-root arc), arcs across phi = pi included;
- ``pattern_at``: where it decides, its digits are the solver's number of solutions in each super-window,
  the code is a row of ``window_patterns`` (a possible pattern) and the total is the solver's count;
- ``compatible``: at points of faces shared by two pattern boxes, the patterns of the two boxes at the same
  point are never refused, and each solution's units in the two boxes are said to overlap;
- mutations: moved root arcs, window counts given to the wrong window, swapped parities, a ``compatible``
  that refuses everything, unit overlaps that ignore where the arcs are or forget the part of an arc beyond
  phi = pi: each is caught by these checks.  In the separations, a ``compatible`` that accepts everything
  merges the two 2-solution cells that only the pattern test separates, and one that refuses everything
  is caught by the separations' own soundness check.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from fractions import Fraction

import numpy as np
import pytest

import intervalkin.space.joint_patterns as jpat
import intervalkin.space.joint_separation as js
from intervalkin.core.interval import PI_HI
from intervalkin.paving.adjacency import shares_face
from intervalkin.solve.dkp import solve
from intervalkin.space.joint_patterns import compatible, digits, pattern_at, unit_overlaps, window_patterns

TWO_PI = 2.0 * math.pi


# ----------------------------------------------------------------------------------------------------------
# helpers: the solver's orientations, arcs in circle order, the units of a box
# ----------------------------------------------------------------------------------------------------------
def _phis(geometry, q) -> np.ndarray | None:
    """The orientations of every solution at q, in [-pi, pi] (None when the solver is not complete)."""
    res = solve(geometry, [Fraction(float(v)) for v in q])
    if not res.complete:
        return None
    out = []
    for s in res.solutions:
        lo, hi = s.box[2]
        assert hi - lo < 1e-6
        out.append(math.remainder(0.5 * (lo + hi), TWO_PI))
    return np.array(out, dtype=np.float64)


def _in_arc(phi: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Whether each phi lies on the closed arc from lo to hi in circle order (across pi when hi <= lo)."""
    if hi > lo:
        return (lo <= phi) & (phi <= hi)
    return (phi >= lo) | (phi <= hi)


def _window_arcs(models) -> tuple[np.ndarray, np.ndarray]:
    """(w,) start and stop of each window: the start of its first piece and the end of its last."""
    w = len(models.degree)
    first = np.searchsorted(models.piece_window, np.arange(w), side="left")
    last = np.searchsorted(models.piece_window, np.arange(w), side="right") - 1
    return models.piece_lo[first], models.piece_hi[last]


class _Units:
    """The arcs of each box that may hold a root, numbered as in ``unit_overlaps``: the windows (unit: the
    rank of their super-window), then the fixed-root arcs (unit: width + position in the box)."""

    def __init__(self, models, patterns):
        self.m = models
        self.wlo, self.whi = _window_arcs(models)
        self.wunit = patterns.rank[patterns.super_of]
        self.width = patterns.width

    def windows(self, box: int) -> range:
        m = self.m
        return range(int(np.searchsorted(m.window_box, box, "left")), int(np.searchsorted(m.window_box, box, "right")))

    def roots(self, box: int) -> range:
        m = self.m
        return range(int(np.searchsorted(m.root_box, box, "left")), int(np.searchsorted(m.root_box, box, "right")))

    def of(self, box: int) -> list[tuple[int, float, float]]:
        """(unit, start, stop) of every arc of ``box`` that may hold a root."""
        m = self.m
        out = [(int(self.wunit[k]), float(self.wlo[k]), float(self.whi[k])) for k in self.windows(box)]
        return out + [(self.width + i, float(m.root_lo[k]), float(m.root_hi[k])) for i, k in enumerate(self.roots(box))]

    def holding(self, box: int, phi: float) -> list[int]:
        """The units of ``box`` whose arc holds the orientation phi."""
        return [u for u, lo, hi in self.of(box) if _in_arc(np.array([phi]), lo, hi)[0]]


def _arc_errors(models, patterns, rows: np.ndarray, phis: list) -> list:
    """Points at which the fixed-root arcs disagree with the solver: an arc without exactly one solution, a
    number of arcs other than off[:, 0], or a solution in no unit or in two (window or fixed-root arc)."""
    u = _Units(models, patterns)
    errors = []
    for row, phi in zip(rows, phis):
        if phi is None:
            continue
        arcs = u.roots(row)
        held = [int(_in_arc(phi, models.root_lo[k], models.root_hi[k]).sum()) for k in arcs]
        units = np.zeros(phi.size, dtype=np.int64)
        for _, lo, hi in u.of(row):
            units += _in_arc(phi, lo, hi)
        if any(h != 1 for h in held) or len(arcs) != models.off[row, 0] or np.any(units != 1):
            errors.append((int(row), held, int(models.off[row, 0]), units.tolist()))
    return errors


def _row_of(patterns, box: np.ndarray, code: np.ndarray) -> np.ndarray:
    """The row of (box, code) in ``patterns`` (sorted by box, then code), -1 where there is none."""
    lo = np.searchsorted(patterns.box, box, side="left")
    hi = np.searchsorted(patterns.box, box, side="right")
    out = np.full(box.size, -1, dtype=np.int64)
    for i in range(box.size):
        hit = np.flatnonzero(patterns.code[lo[i]:hi[i]] == code[i])
        if hit.size:
            out[i] = lo[i] + hit[0]
    return out


@pytest.fixture(scope="module")
def patterns(fold_paving):
    return window_patterns(fold_paving.windows.models)


@pytest.fixture(scope="module")
def arc_sample(fold_paving, paper_geometry):
    """Random points of random modelled boxes (a third of them boxes with an arc across phi = pi), and the
    solver's orientations there."""
    m = fold_paving.windows.models
    rng = np.random.default_rng(41)
    ok = np.flatnonzero(m.ok)
    across = np.unique(m.root_box[m.root_hi <= m.root_lo])
    assert across.size >= 40
    rows = np.r_[rng.choice(ok, 100, replace=False), rng.choice(across, 50, replace=False)]
    b = m.boxes[rows]
    pts = b[:, :, 0] + rng.uniform(size=(len(rows), 3)) * (b[:, :, 1] - b[:, :, 0])
    return rows, pts, [_phis(paper_geometry, q) for q in pts]


# ----------------------------------------------------------------------------------------------------------
# (a) fixed-root arcs
# ----------------------------------------------------------------------------------------------------------
def test_fixed_root_arcs_hold_one_solution_each(fold_paving, patterns, arc_sample):
    """Each fixed-root arc holds exactly one solution, a box has off[:, 0] of them, and each solution
    lies in exactly one window or fixed-root arc (some arcs run across phi = pi)."""
    m = fold_paving.windows.models
    rows, _, phis = arc_sample
    assert np.array_equal(np.bincount(m.root_box, minlength=len(m.ok))[m.ok], m.off[m.ok, 0])
    assert np.all(np.diff(m.root_box) >= 0)
    done = np.array([p is not None for p in phis])
    assert done.sum() >= 140
    assert np.bincount(m.root_box, minlength=len(m.ok))[rows[done]].sum() >= 200  # many arcs checked
    errors = _arc_errors(m, patterns, rows, phis)
    assert not errors, errors[:3]


def test_moved_root_arcs_are_caught(fold_paving, patterns, arc_sample):
    """Mutations: every arc turned by pi, and the first arc of each box cut down to a stub at its start;
    both disagree with the solver at sampled points."""
    m = fold_paving.windows.models
    rows, _, phis = arc_sample
    turn = np.vectorize(lambda x: math.remainder(x + math.pi, TWO_PI))
    turned = dataclasses.replace(m, root_lo=turn(m.root_lo), root_hi=turn(m.root_hi))
    assert len(_arc_errors(turned, patterns, rows, phis)) >= 20
    first = np.r_[True, m.root_box[1:] != m.root_box[:-1]]
    stub = dataclasses.replace(m, root_hi=np.where(first, m.root_lo + 1e-6, m.root_hi))
    assert len(_arc_errors(stub, patterns, rows, phis)) >= 20


# ----------------------------------------------------------------------------------------------------------
# (b) patterns at points
# ----------------------------------------------------------------------------------------------------------
def _pattern_sample(fold_paving, patterns):
    """Random points of random pattern boxes, half of them boxes with two super-windows or more."""
    m = fold_paving.windows.models
    rng = np.random.default_rng(42)
    boxes = np.unique(patterns.box)
    nsup = np.bincount(m.window_box, weights=m.end_signs[:, 0] != 0, minlength=len(m.ok))
    several = boxes[nsup[boxes] >= 2]
    assert several.size > 1000
    rows = np.r_[rng.choice(boxes, 80, replace=False), rng.choice(several, 80, replace=False)]
    b = m.boxes[rows]
    return rows, b[:, :, 0] + rng.uniform(size=(len(rows), 3)) * (b[:, :, 1] - b[:, :, 0])


def _pattern_errors(geometry, models, patterns, rows, points, codes) -> tuple[list, int]:
    """Points where a decided code disagrees with the solver (digits per super-window, total count) or is
    no row of its box; and the number of points checked."""
    u = _Units(models, patterns)
    found = _row_of(patterns, rows, codes)
    errors, checked = [], 0
    for row, q, code, r in zip(rows, points, codes, found):
        if code < 0:
            continue
        phi = _phis(geometry, q)
        if phi is None:
            continue
        checked += 1
        got = digits(patterns, np.array([code]))[0]
        truth = np.zeros(got.size, dtype=np.int64)
        for k in u.windows(row):
            truth[u.wunit[k]] += int(_in_arc(phi, u.wlo[k], u.whi[k]).sum())
        total = models.off[row, 0] + got.sum()
        if r < 0 or not np.array_equal(got, truth) or total != phi.size or patterns.count[r] != phi.size:
            errors.append((int(row), int(code), got.tolist(), truth.tolist(), phi.size, int(r)))
    return errors, checked


def test_pattern_at_counts_the_solutions_of_each_super_window(fold_paving, paper_geometry, patterns):
    """Super-windows are the runs of windows joined by inner cuts (an end sign 0), ranked 0, 1, ... in each
    box; where ``pattern_at`` decides, each digit is the solver's number of solutions in that super-window,
    the code is one of the box's rows and the total is the solver's count."""
    m = fold_paving.windows.models
    # the super-windows rebuilt from the end signs: a window whose first cut is certified starts one
    mine = np.cumsum(m.end_signs[:, 0] != 0) - 1
    pairs = np.unique(np.stack([mine, patterns.super_of], axis=1), axis=0)
    assert len(pairs) == np.unique(mine).size == np.unique(patterns.super_of).size
    sbox = np.zeros(int(patterns.super_of.max()) + 1, dtype=np.int64)
    sbox[patterns.super_of] = m.window_box
    assert np.all(patterns.rank < np.bincount(sbox)[sbox])
    assert np.unique(np.stack([sbox, patterns.rank], axis=1), axis=0).shape[0] == sbox.size
    rows, points = _pattern_sample(fold_paving, patterns)
    codes = pattern_at(paper_geometry, m, patterns, rows, points)
    assert np.mean(codes >= 0) > 0.9
    errors, checked = _pattern_errors(paper_geometry, m, patterns, rows, points, codes)
    assert checked >= 130
    assert not errors, errors[:3]
    d = digits(patterns, codes[codes >= 0])
    assert np.count_nonzero(d.sum(axis=1)) >= 30 and np.count_nonzero((d > 0).sum(axis=1) >= 2) >= 5


def test_misplaced_window_counts_and_swapped_parities_are_caught(fold_paving, paper_geometry, patterns,
                                                                monkeypatch):
    """Mutations: each window's count given to the next window of its box (an indexing slip in
    ``pattern_at``), and the possible counts of windows with certified ends given the wrong parity (in
    ``window_patterns``); each is caught at some sampled point."""
    m = fold_paving.windows.models
    rows, points = _pattern_sample(fold_paving, patterns)
    real_counts = jpat.window_root_counts

    def shifted(geometry, models, r, pts, *args):
        c = real_counts(geometry, models, r, pts, *args)
        nxt = np.r_[np.arange(1, c.pt.size), 0]
        same = c.pt[nxt] == c.pt
        roots = c.roots.copy()
        roots[same] = c.roots[nxt[same]]
        return dataclasses.replace(c, roots=roots)

    monkeypatch.setattr(jpat, "window_root_counts", shifted)
    codes = pattern_at(paper_geometry, m, patterns, rows, points)
    monkeypatch.undo()
    assert _pattern_errors(paper_geometry, m, patterns, rows, points, codes)[0]

    real_sets = jpat._window_sets

    def swapped(models):
        sets = real_sets(models)
        firm = (models.end_signs != 0).all(axis=1) & (models.d_sign != 0)
        every = np.left_shift(1, models.degree.astype(np.int64) + 1) - 1
        return np.where(firm, every & ~sets, sets)

    monkeypatch.setattr(jpat, "_window_sets", swapped)
    wrong = window_patterns(m)
    monkeypatch.undo()
    codes = pattern_at(paper_geometry, m, patterns, rows, points)
    assert _pattern_errors(paper_geometry, m, wrong, rows, points, codes)[0]


# ----------------------------------------------------------------------------------------------------------
# (c) patterns of two boxes at one point of their shared face
# ----------------------------------------------------------------------------------------------------------
def _cut_at_seam(models):
    """The models with every arc that runs across phi = pi stopped at pi (its part beyond pi forgotten)."""
    wlo, whi = _window_arcs(models)
    last = np.searchsorted(models.piece_window, np.arange(len(models.degree)), side="right") - 1
    piece_hi = models.piece_hi.copy()
    piece_hi[last[whi <= wlo]] = PI_HI
    return dataclasses.replace(models, piece_hi=piece_hi,
                               root_hi=np.where(models.root_hi <= models.root_lo, PI_HI, models.root_hi))


@pytest.fixture(scope="module")
def face_sample(fold_paving, paper_geometry, patterns):
    """Points of faces shared by two pattern boxes (random contacts, and five points on each of up to 40
    contacts whose overlaps need the part of an arc beyond phi = pi): the pattern rows of both boxes there,
    the unit overlaps, and each solution's units in each box."""
    jp, m = fold_paving, fold_paving.windows.models
    p = jp.paving
    u = _Units(m, patterns)
    a, b = shares_face(p.level, p.ijk, int(p.level.max()), periodic=(False, False, False))
    is_p = np.zeros(len(p.lo), dtype=bool)
    is_p[jp.windows.leaf[np.unique(patterns.box)]] = True
    both = np.flatnonzero(is_p[a] & is_p[b])
    assert both.size > 1000
    box_a, box_b = np.searchsorted(jp.windows.leaf, a[both]), np.searchsorted(jp.windows.leaf, b[both])
    # the contacts whose unit overlaps need the part of some arc beyond phi = pi
    seam = np.flatnonzero(np.any(unit_overlaps(m, patterns, box_a, box_b)
                                 != unit_overlaps(_cut_at_seam(m), patterns, box_a, box_b), axis=(1, 2)))
    assert seam.size >= 20
    rng = np.random.default_rng(43)
    pick = np.r_[rng.choice(both.size, 200, replace=False), np.repeat(seam[:40], 5)]
    la, lb = a[both[pick]], b[both[pick]]
    flo, fhi = np.maximum(p.lo[la], p.lo[lb]), np.minimum(p.hi[la], p.hi[lb])
    assert np.all((flo == fhi).sum(axis=1) == 1)  # a face: one coordinate pinned
    q = flo + rng.uniform(size=flo.shape) * (fhi - flo)
    box_a, box_b = box_a[pick], box_b[pick]
    ca = pattern_at(paper_geometry, m, patterns, box_a, q)
    cb = pattern_at(paper_geometry, m, patterns, box_b, q)
    keep = (ca >= 0) & (cb >= 0)
    box_a, box_b, q = box_a[keep], box_b[keep], q[keep]
    ra, rb = _row_of(patterns, box_a, ca[keep]), _row_of(patterns, box_b, cb[keep])
    assert np.all(ra >= 0) and np.all(rb >= 0)
    units = []
    for ba, bb, x in zip(box_a, box_b, q):
        phi = _phis(paper_geometry, x)
        units.append(None if phi is None else [(u.holding(ba, f), u.holding(bb, f)) for f in phi])
    return dict(box_a=box_a, box_b=box_b, row_a=ra, row_b=rb, overlap=unit_overlaps(m, patterns, box_a, box_b),
                units=units)


def _refused(models, patterns, sample, overlap=None, fn=compatible) -> int:
    ov = sample["overlap"] if overlap is None else overlap
    return int(np.count_nonzero(~fn(models, patterns, sample["row_a"], sample["row_b"], ov)))


def test_compatible_admits_every_pair_met_on_a_shared_face(fold_paving, patterns, face_sample):
    """At points of faces shared by two pattern boxes, the two patterns found at the same point are never
    refused, and each solution's unit in one box is said to meet its unit in the other.  Not vacuous: many
    pairs are checked, and ``compatible`` refuses many of the pairs of equal count of the same contacts."""
    m = fold_paving.windows.models
    s = face_sample
    assert s["row_a"].size >= 300
    assert _refused(m, patterns, s) == 0
    assert np.count_nonzero(patterns.code[s["row_a"]] != 0) >= 50
    solutions = 0
    for c, per in enumerate(s["units"]):
        for ua, ub in per or []:
            assert len(ua) == 1 and len(ub) == 1, (c, ua, ub)
            assert s["overlap"][c, ua[0], ub[0]], (c, ua, ub)
            solutions += 1
    assert solutions >= 600
    # every pair of rows of equal count of these contacts: compatible refuses a fair share of them
    ia, ga, gb = [], [], []
    for c, (ba, bb) in enumerate(zip(s["box_a"], s["box_b"])):
        x, y = np.meshgrid(np.flatnonzero(patterns.box == ba), np.flatnonzero(patterns.box == bb), indexing="ij")
        same = patterns.count[x] == patterns.count[y]
        ga.append(x[same]), gb.append(y[same]), ia.append(np.full(same.sum(), c))
    ia, ga, gb = np.concatenate(ia), np.concatenate(ga), np.concatenate(gb)
    ok = compatible(m, patterns, ga, gb, s["overlap"][ia])
    assert ok.size >= 1000 and 0.1 < np.mean(~ok) < 0.9, (ok.size, np.mean(~ok))


def test_a_compatible_that_refuses_true_pairs_is_caught(fold_paving, patterns, face_sample):
    """Mutations caught by the face points: ``compatible`` refusing everything; unit overlaps that let unit
    i of one box meet only unit i of the other (ignoring where the arcs are); unit overlaps of arcs cut at
    phi = pi (the part of an arc beyond pi forgotten)."""
    m = fold_paving.windows.models
    s = face_sample
    assert _refused(m, patterns, s, fn=lambda *args: np.zeros(len(args[2]), dtype=bool)) == s["row_a"].size
    eye = np.broadcast_to(np.eye(s["overlap"].shape[1], dtype=bool), s["overlap"].shape)
    assert _refused(m, patterns, s, overlap=eye) >= 5
    cut = unit_overlaps(_cut_at_seam(m), patterns, s["box_a"], s["box_b"])
    assert _refused(m, patterns, s, overlap=cut) >= 5


# ----------------------------------------------------------------------------------------------------------
# (d) what the pattern test does for the separations
# ----------------------------------------------------------------------------------------------------------
def _replace_compatible(monkeypatch, fn) -> int:
    """Put ``fn`` in place of :func:`compatible` in every loaded module of the package that holds it (the
    separations reach it through helper modules); the number of modules patched."""
    done = 0
    for name, mod in list(sys.modules.items()):
        if name.startswith("intervalkin.") and getattr(mod, "compatible", None) is compatible:
            monkeypatch.setattr(mod, "compatible", fn)
            done += 1
    return done


def _refines(fine, coarse) -> bool:
    """Every group of ``fine`` lies inside one group of ``coarse``."""
    at = {s: {c: i for i, g in enumerate(groups) for c in g} for s, groups in coarse.groups.items()}
    return all(len({at[s][c] for c in g}) == 1 for s, groups in fine.groups.items() for g in groups)


def test_the_pattern_test_separates_the_two_cells_of_two_solutions(fold_paving, paper_geometry, monkeypatch):
    """G_sigma alone (no refuting rounds): the two cells with 2 solutions (1 + 1) are separated, and with
    ``compatible`` accepting every pair they are one group: the pattern test is what separates them.  With
    the refuting rounds and ``compatible`` refusing every pair, contacts that a cell of 4 solutions runs
    through are cut and the separations' soundness check fails."""
    real = js.separated_cells(fold_paving, paper_geometry, rounds=0)
    assert len(real.groups[(2, 1, 1)]) == 2, real.groups
    assert _replace_compatible(monkeypatch, lambda m, p, ra, rb, ov: np.ones(len(ra), dtype=bool)) >= 1
    loose = js.separated_cells(fold_paving, paper_geometry, rounds=0)
    assert len(loose.groups[(2, 1, 1)]) == 1, loose.groups
    assert _refines(real, loose)
    assert loose.basic_regions_at_least() == real.basic_regions_at_least() - 2
    monkeypatch.undo()
    assert _replace_compatible(monkeypatch, lambda m, p, ra, rb, ov: np.zeros(len(ra), dtype=bool)) >= 1
    with pytest.raises(AssertionError, match="soundness bug"):
        js.separated_cells(fold_paving, paper_geometry)


def _synthetic_models(n_windows: int):
    """One modelled box with n pair windows (end signs equal, D signed: 0 or 2 roots each), no fixed root."""
    from intervalkin.solve.window_model import WindowModels

    edges = np.linspace(-3.0, 3.0, 2 * n_windows + 1)
    z = np.zeros(n_windows, dtype=np.int64)
    return WindowModels(np.array([[[20.0, 20.1]] * 3]), np.array([True]), np.zeros((1, 3), dtype=np.int64),
                        z, np.full(n_windows, 2, dtype=np.int8), np.ones((n_windows, 2), dtype=np.int8),
                        np.ones(n_windows, dtype=np.int8), np.arange(n_windows), edges[0:-1:2], edges[1::2],
                        np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0))


def test_patterns_stay_few_and_codes_exact():
    # 5 pair windows (digits 0 or 2): 2**5 combinations, of which those with at most MAX_ROOTS = 6 roots
    # (at most three pairs) are patterns, codes distinct; 11 windows: 232 left, kept; 12: 299 left, more
    # than MAX_PATTERNS, none (the box stays one node: a neighbour pair of such boxes once filled 24 GB with
    # pairs of patterns); 15: past MAX_ENUMERATED, not enumerated
    few = jpat.window_patterns(_synthetic_models(5))
    assert len(few.code) == 1 + 5 + 10 + 10 and len(set(few.code.tolist())) == 26
    d = jpat.digits(few, few.code)
    assert d.shape == (26, 5) and set(np.unique(d).tolist()) == {0, 2}
    assert np.array_equal(few.count, d.sum(axis=1)) and few.count.max() == jpat.MAX_ROOTS
    assert len(jpat.window_patterns(_synthetic_models(11)).code) == 1 + 11 + 55 + 165 <= jpat.MAX_PATTERNS
    assert 1 + 12 + 66 + 220 > jpat.MAX_PATTERNS
    for n in (12, 15):
        assert len(jpat.window_patterns(_synthetic_models(n)).code) == 0
    assert 2 ** 15 > jpat.MAX_ENUMERATED

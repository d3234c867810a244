"""Window models in the joint paving (space.joint_windows): the leaves with no fold model.

- the leaves tried are exactly the undecided leaves without a fold model, most get a model;
- ``signature_of`` at random points of window-modelled leaves equals the certified solver;
- ``open_places`` keeps those leaves open for the counts and reports their volume apart, except
  window-clear leaves and window folds (proved pieces); the npz columns are unchanged;
- window pieces joined to a cell carry its signature, and points in them get a cell whose
  signature is the certified solver's.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from intervalkin.solve.dkp import solve
from intervalkin.solve.window_fold import CLEAR, FOLD
from tests.solve.shared import split_of


def test_leaves_without_a_fold_model_get_window_models(fold_paving):
    w = fold_paving.windows
    assert w is not None
    none = fold_paving.cell < 0
    none[fold_paving.pieces.box] = False
    assert np.array_equal(w.leaf, np.flatnonzero(none))
    st = fold_paving.fold_stats["windows"]
    assert st["leaves_modelled"] == int(w.models.ok.sum()) > 0.4 * st["leaves_tried"]
    assert st["pair_windows"] > 0 and st["triple_windows"] > 0


def test_signature_of_points_in_window_leaves_is_the_solvers(fold_paving, paper_geometry):
    w = fold_paving.windows
    rng = np.random.default_rng(17)
    leaves = rng.choice(w.leaf[w.models.ok], 60, replace=False)
    lo, hi = fold_paving.paving.lo[leaves], fold_paving.paving.hi[leaves]
    points = lo + rng.uniform(0.01, 0.99, size=lo.shape) * (hi - lo)
    sig = fold_paving.signature_of(points, paper_geometry)
    decided = sig[:, 0] >= 0
    assert decided.mean() > 0.9
    truth = np.array([split_of(solve(paper_geometry, [Fraction(float(v)) for v in p])) for p in points[decided]])
    assert np.array_equal(sig[decided], truth)


def test_window_leaves_without_pieces_stay_open_for_the_counts(fold_paving):
    """Window-modelled leaves are open unless window-clear or a window fold; the volumes add up."""
    block = fold_paving.open_places()
    places = block["places"]
    v = fold_paving.paving.volume()
    w = fold_paving.windows
    pieced = np.isin(w.folds.kind, (CLEAR, FOLD))
    assert pieced.any() and not pieced[~w.models.ok].any()
    assert np.isclose(places["volume_window_model"], v[w.leaf[w.models.ok & ~pieced]].sum())
    assert np.isclose(places["volume_window_pieces"], v[w.leaf[pieced]].sum())
    assert np.isclose(places["volume_without_model"], v[w.leaf[~w.models.ok]].sum())
    # open for the counts: the undecided volume holds the window-modelled leaves without pieces, not the pieced ones
    assert block["joint_volume"] >= (places["volume_window_model"] + places["volume_without_model"]) * (1 - 1e-9)
    assert np.isclose(block["joint_volume"] + places["volume_window_pieces"] + v[fold_paving.cell >= 0].sum()
                      + v[fold_paving.counted_fold_mask()].sum(), v.sum())
    assert "window model" in places["why"]
    assert set(fold_paving.columns()) == {"lo", "hi", "level", "cell", "count", "n_wa1", "n_wa2", "fold_axis",
                                          "cell_below", "cell_above", "count_below", "count_above",
                                          "open_reason", "open_place"}


def test_window_pieces_carry_their_cells_signature(fold_paving, paper_geometry):
    """Window pieces joined to a cell have its signature (the paving checks it too: here independently), many
    join one; points of window-pieced leaves get a cell whose signature is the certified solver's."""
    w = fold_paving.windows
    wc = fold_paving.window_cell
    assert len(wc) == 2 * len(w.leaf)
    joined = np.flatnonzero(wc >= 0)
    assert joined.size > 100
    sig = {c.id: c.signature for c in fold_paving.cells + fold_paving.fragments}
    assert all(tuple(w.folds.signature[j // 2, j % 2]) == sig[int(wc[j])] for j in joined)
    rng = np.random.default_rng(23)
    rows = rng.choice(np.flatnonzero(np.isin(w.folds.kind, (CLEAR, FOLD))), 40, replace=False)
    lo, hi = fold_paving.paving.lo[w.leaf[rows]], fold_paving.paving.hi[w.leaf[rows]]
    points = lo + rng.uniform(0.01, 0.99, size=lo.shape) * (hi - lo)
    cell = fold_paving.cell_of(points, paper_geometry)
    at = np.flatnonzero(cell >= 0)
    assert at.size >= 25
    truth = [split_of(solve(paper_geometry, [Fraction(float(v)) for v in p])) for p in points[at]]
    assert [sig[int(c)] for c in cell[at]] == [tuple(t) for t in truth]


def test_certified_share_grows_with_window_pieces(fold_paving):
    """The window-pieced leaves count as certified volume: the share is the clear, counted-fold and pieced volume."""
    v = fold_paving.paving.volume()
    known = (fold_paving.cell >= 0) | fold_paving.counted_fold_mask()
    assert fold_paving.certified_share() > v[known].sum() / v.sum()
    assert np.isclose(fold_paving.certified_share(), v[known | fold_paving.pieced_mask()].sum() / v.sum())


def test_npz_columns_of_window_pieces(fold_paving, paper_geometry):
    """Window-clear leaves carry their signature; for window folds, where the counts the window model proves
    near the bottom and the top of the leaf along fold_axis differ, they are count_below and count_above (so a
    swapped orientation fails)."""
    cols = fold_paving.columns()
    w = fold_paving.windows
    clear = w.leaf[w.folds.kind == CLEAR]
    assert np.array_equal(cols["count"][clear], w.folds.signature[w.folds.kind == CLEAR, 0, 0])
    rows = np.flatnonzero(w.folds.kind == FOLD)[:300]
    leaf = w.leaf[rows]
    k = cols["fold_axis"][leaf]
    assert np.all((k >= 0) & (k <= 2))
    lo, hi = fold_paving.paving.lo[leaf], fold_paving.paving.hi[leaf]
    centre = 0.5 * (lo + hi)
    idx = np.arange(len(leaf))
    near = []
    for f in (0.001, 0.999):
        p = centre.copy()
        p[idx, k] = lo[idx, k] + f * (hi[idx, k] - lo[idx, k])
        near.append(fold_paving.signature_of(p, paper_geometry)[:, 0])
    # the line crosses the sheet at most once, from the piece below to the piece above: where its two ends
    # differ, they are (count_below, count_above); where they agree, the count is one of the two
    crossed = (near[0] >= 0) & (near[1] >= 0) & (near[0] != near[1])
    assert crossed.sum() > 30
    assert np.array_equal(near[0][crossed], cols["count_below"][leaf][crossed])
    assert np.array_equal(near[1][crossed], cols["count_above"][leaf][crossed])
    same = (near[0] >= 0) & (near[0] == near[1])
    assert np.all((near[0][same] == cols["count_below"][leaf][same]) | (near[0][same] == cols["count_above"][leaf][same]))


@pytest.fixture(scope="module")
def paving_with_failed_models(paper_geometry):
    """A depth-3 paving with window models whose gap bound at the zeros of D is switched off: since that bound
    (proofs/lemma-gap-at-d-zeros.md) no leaf of the paper's pavings fails its model, and without it the
    leaves near the spurious plane f(phi_D; r) = 0 fail as they used to (95 split here)."""
    import intervalkin.solve.window_model as wm
    from intervalkin.space.joint_paving import pave_joint_space

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(wm, "gap_positive", lambda geometry, boxes, owner, lo, hi: np.zeros(len(owner), dtype=bool))
        return pave_joint_space(paper_geometry, 3, 1, fold=True, model_levels=1, windows=True, workers=1)


def test_leaves_whose_model_fails_are_split_and_their_children_modelled(paving_with_failed_models, paper_geometry,
                                                                      monkeypatch):
    """window_refinement: a leaf whose window model fails is replaced by its eight children (up to
    WINDOW_LEVELS times), so a failed model is left only on leaves that many levels finer than the paving's
    other leaves; the leaves stay a partition of the joint box, and the children's models are their own."""
    import intervalkin.solve.window_model as wm
    from intervalkin.solve.window_model import window_models
    from intervalkin.space.joint_windows import WINDOW_LEVELS

    w, p = paving_with_failed_models.windows, paving_with_failed_models.paving
    st = paving_with_failed_models.fold_stats["windows"]
    assert st["leaves_split"] > 0
    assert np.isclose(p.volume().sum(), np.prod(np.diff(p.domain, axis=1)))
    failed = w.leaf[~w.models.ok]
    split_levels = np.unique(p.level[failed])
    assert failed.size == 0 or split_levels.min() >= int(p.level[w.leaf[w.models.ok]].min()) + 1
    rows = np.flatnonzero(w.models.ok)[-12:]  # the last rows: children of split leaves
    boxes = np.stack([p.lo[w.leaf[rows]], p.hi[w.leaf[rows]]], axis=-1)
    assert np.array_equal(w.models.boxes[rows], boxes)
    monkeypatch.setattr(wm, "gap_positive", lambda geometry, boxes, owner, lo, hi: np.zeros(len(owner), dtype=bool))
    again = window_models(paper_geometry, boxes)
    assert np.array_equal(again.degree, w.models.take(rows).degree)
    assert WINDOW_LEVELS >= 1

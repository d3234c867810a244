"""Window models in the joint paving (space.joint_windows): the leaves with no fold model.

- the leaves tried are exactly the undecided leaves without a fold model, most get a model;
- ``signature_of`` at random points of window-modelled leaves equals the certified solver;
- ``open_places`` keeps those leaves open for the counts and reports their volume apart;
  the npz columns are unchanged.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from intervalkin.solve.dkp import solve
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


def test_window_leaves_stay_open_for_the_counts(fold_paving):
    block = fold_paving.open_places()
    places = block["places"]
    v = fold_paving.paving.volume()
    w = fold_paving.windows
    assert np.isclose(places["volume_window_model"], v[w.leaf[w.models.ok]].sum())
    assert np.isclose(places["volume_without_model"], v[w.leaf[~w.models.ok]].sum())
    # open for the counts all the same: the undecided volume holds both
    assert block["joint_volume"] >= (places["volume_window_model"] + places["volume_without_model"]) * (1 - 1e-9)
    assert "window model" in places["why"]
    assert set(fold_paving.columns()) == {"lo", "hi", "level", "cell", "count", "n_wa1", "n_wa2", "fold_axis",
                                          "cell_below", "cell_above", "count_below", "count_above"}

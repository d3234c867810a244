"""Every label of a library paving is confirmed; a wrong label is refuted, not merely left open.

A depth-5 workspace paving of the paper's manipulator (``pave_workspace``, the
function ``intervalkin pave`` and the analysis use) is re-checked in full by
:func:`~intervalkin.recheck.bisect.confirm_labels`.  Would fail if the recheck
were unsound in the direction that matters (confirming a flipped label) or too
loose to re-prove the library's labels.
"""

from __future__ import annotations

import numpy as np
import pytest

from intervalkin.app.export import paving_columns
from intervalkin.paving.predicates import pave_workspace
from intervalkin.recheck.bisect import CONFIRMED, NOT_CONFIRMED, REFUTED, confirm_labels
from intervalkin.recheck.model import constants


@pytest.fixture(scope="module")
def columns(paper_geometry):
    return paving_columns(pave_workspace(paper_geometry, 5))


@pytest.mark.parametrize("name", ["in_workspace", "det_sign"])
def test_every_label_of_a_library_paving_is_confirmed(paper_geometry, columns, name):
    rows = np.flatnonzero(columns[name] != 0)
    assert len(rows) > 1000 and set(np.unique(columns[name][rows])) == {-1, 1}
    st = confirm_labels(constants(paper_geometry), columns["lo"][rows], columns["hi"][rows], name, columns[name][rows])
    assert (st == CONFIRMED).all()


@pytest.mark.parametrize("name", ["in_workspace", "det_sign"])
def test_flipped_labels_are_refuted(paper_geometry, columns, name, rng):
    """Every flipped label of 300 drawn boxes: refuted (the true label is proved on a part), never confirmed."""
    rows = rng.choice(np.flatnonzero(columns[name] != 0), 300, replace=False)
    flipped = -columns[name][rows]
    st = confirm_labels(constants(paper_geometry), columns["lo"][rows], columns["hi"][rows], name, flipped)
    assert (st == REFUTED).all()


def test_boundary_boxes_claimed_inside_are_not_confirmed(paper_geometry, columns):
    """Boxes the library left undecided for W, claimed INSIDE: none may be confirmed (most straddle the limits)."""
    rows = np.flatnonzero(columns["in_workspace"] == 0)
    st = confirm_labels(constants(paper_geometry), columns["lo"][rows], columns["hi"][rows], "in_workspace",
                        np.ones(len(rows), np.int8), rounds=6)
    assert (st != CONFIRMED).mean() > 0.95
    assert set(np.unique(st)) <= {REFUTED, NOT_CONFIRMED, CONFIRMED}
    assert (st == REFUTED).any()

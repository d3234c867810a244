"""Joint space: the enclosure of g(S) is sound and each cell's count holds everywhere in it."""

from __future__ import annotations

from decimal import Decimal
from fractions import Fraction

import numpy as np
import pytest
from flint import arb, ctx

from intervalkin.kinematics.formulas import approx_det_a, det_a_arb, inverse_kinematics_arb
from intervalkin.solve.dkp import solve
from intervalkin.solve.dkp import parse_joint_vector
from intervalkin.space.joint_space import _mark, _range_sum, _summed_area, joint_paving

from ..conftest import small_chain


def solution_count(geometry, rho, paving):
    """(count, n_wa1, n_wa2, source): from the cell of q when it is solved, else from a certified solve.

    Moved here from ``intervalkin.space.joint_space`` (only this test used it; the
    library's answer is ``Analysis.locate``).
    """
    q = parse_joint_vector(geometry, rho)
    cid = paving.cell_at(q)
    if cid >= 0 and paving.cells[cid].count >= 0:
        c = paving.cells[cid]
        return c.count, c.n_wa1, c.n_wa2, f"cell {cid}"
    res = solve(geometry, q)
    assert res.complete and all(s.status == "unique" for s in res.solutions)
    n1 = sum(1 for s in res.solutions if s.det_sign > 0)
    return len(res.solutions), n1, len(res.solutions) - n1, "solve"


@pytest.fixture(scope="module")
def joint(paper_geometry):
    return small_chain(paper_geometry, 7, 5, max_solves=200)


def _random_point_in_cell(jp, rng, cid):
    vox = np.argwhere(jp.cell == cid)
    v = vox[rng.integers(len(vox))]
    t = [Fraction(int(rng.integers(0, 1000)), 1000) for _ in range(3)]
    return tuple(jp.rho_min[i] + (int(v[i]) + t[i]) * jp.step[i] for i in range(3))


def test_counts_of_cells_hold_at_random_points(joint, paper_geometry):
    """Property: an independent certified solve anywhere in a cell gives the cell's count and split."""
    rng = np.random.default_rng(1)
    solved = [c for c in joint.cells if c.count >= 0]
    assert {c.count for c in solved} >= {0, 2, 4, 6}
    checked = 0
    for c in solved:
        for _ in range(6 if c.n_voxels > 10 else 1):
            q = _random_point_in_cell(joint, rng, c.id)
            res = solve(paper_geometry, q)
            assert res.complete
            n1 = sum(1 for s in res.solutions if s.det_sign > 0)
            assert (len(res.solutions), n1, len(res.solutions) - n1) == (c.count, c.n_wa1, c.n_wa2), (c, q)
            checked += 1
    assert checked > 50


def test_solutions_split_equally_between_aspects(joint):
    for c in joint.cells:
        if c.count >= 0:
            assert c.n_wa1 == c.n_wa2 == c.count // 2


def test_paper_joint_vector_is_in_a_six_solution_cell(joint, paper_geometry):
    """solution_count answers Table 1's q with 6 = 3 + 3, from its cell when it has one, else by a solve;
    and a cell's own witness is answered from the cell, with the cell's count.

    Would catch a lookup that answers from the wrong cell, or never from a cell at all.
    """
    q = [Fraction("14.98"), Fraction("15.38"), Fraction("12.0")]
    count, n1, n2, source = solution_count(paper_geometry, ["14.98", "15.38", "12.0"], joint)
    assert (count, n1, n2) == (6, 3, 3)
    cid = joint.cell_at(q)
    assert source == (f"cell {cid}" if cid >= 0 and joint.cells[cid].count >= 0 else "solve")
    for c in [c for c in joint.cells if c.count >= 0][:5]:
        # the witnesses have power-of-two denominators: exact as decimals
        text = [str(Decimal(v.numerator) / Decimal(v.denominator)) for v in c.witness]
        assert [Fraction(t) for t in text] == list(c.witness)
        assert solution_count(paper_geometry, text, joint) == (c.count, c.n_wa1, c.n_wa2, f"cell {c.id}")


def _certified_singular_point(g, rng):
    """(x, phi) random, y bracketing a sign change of det A, all in arb: a segment holding S."""
    while True:
        x, phi = float(rng.uniform(-32, 32)), float(rng.uniform(-np.pi, np.pi))
        ys = np.linspace(-32, 32, 257)
        d = approx_det_a(g, np.column_stack([np.full_like(ys, x), ys, np.full_like(ys, phi)]))
        idx = np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)
        if idx.size == 0:
            continue
        a, b = ys[idx[0]], ys[idx[0] + 1]
        da = det_a_arb(g, arb(x), arb(a), arb(phi))
        db = det_a_arb(g, arb(x), arb(b), arb(phi))
        if not ((da < 0 and db > 0) or (da > 0 and db < 0)):
            continue
        for _ in range(40):  # bisection, every sign decided in arb
            m = 0.5 * (a + b)
            dm = det_a_arb(g, arb(x), arb(m), arb(phi))
            if dm == 0 or not (dm < 0 or dm > 0):
                break
            if (dm < 0) == (da < 0):
                a, da = m, dm
            else:
                b = m
        return x, (a, b), phi


def test_enclosure_of_gS_covers_certified_singular_points(joint, paper_geometry):
    """A segment {x} x [a, b] x {phi} holding a singular point: its image meets only marked voxels."""
    rng = np.random.default_rng(5)
    old = ctx.prec
    ctx.prec = 128
    hits = 0
    try:
        for _ in range(400):
            x, (a, b), phi = _certified_singular_point(paper_geometry, rng)
            y = arb(a).union(arb(b))
            rho = inverse_kinematics_arb(paper_geometry, arb(x), y, arb(phi))
            lo = np.array([[float(r.lower()) for r in rho]])
            hi = np.array([[float(r.upper()) for r in rho]])
            lim = (10.0 + 1e-6, 32.0 - 1e-6)
            if not np.all((lo > lim[0]) & (hi < lim[1])):
                continue
            ilo, ihi, _ = joint.index_ranges(lo, hi)
            block = joint.marked[ilo[0, 0]:ihi[0, 0] + 1, ilo[0, 1]:ihi[0, 1] + 1, ilo[0, 2]:ihi[0, 2] + 1]
            # the singular point's image lies in one of these voxels; it must be marked
            assert block.any()
            if block.size == 1:
                assert block.all()
            hits += 1
    finally:
        ctx.prec = old
    assert hits > 30


def test_marking_and_range_sums_match_brute_force():
    rng = np.random.default_rng(2)
    n = 8
    ilo = rng.integers(0, n, (20, 3))
    ihi = np.minimum(ilo + rng.integers(0, 3, (20, 3)), n - 1)
    marked = _mark(n, ilo, ihi)
    brute = np.zeros((n, n, n), bool)
    for a, b in zip(ilo, ihi):
        brute[a[0]:b[0] + 1, a[1]:b[1] + 1, a[2]:b[2] + 1] = True
    assert np.array_equal(marked, brute)
    p = _summed_area(marked)
    qlo = rng.integers(0, n, (50, 3))
    qhi = np.minimum(qlo + rng.integers(0, 4, (50, 3)), n - 1)
    s = _range_sum(p, qlo, qhi)
    for k in range(50):
        a, b = qlo[k], qhi[k]
        assert s[k] == marked[a[0]:b[0] + 1, a[1]:b[1] + 1, a[2]:b[2] + 1].sum()


def test_bad_depth_is_refused(paper_geometry):
    from intervalkin.core.errors import InputError

    with pytest.raises(InputError, match="joint depth"):
        joint_paving(paper_geometry, np.zeros((0, 3, 2)), 12)


def test_columns_have_the_documented_layout(joint):
    cols = joint.columns()
    n = joint.n ** 3
    assert set(cols) == {"lo", "hi", "cell", "count", "n_wa1", "n_wa2"}
    assert cols["lo"].shape == (n, 3) and cols["cell"].shape == (n,)
    assert np.all(cols["lo"] < cols["hi"])
    und = cols["cell"] < 0
    assert np.all(cols["count"][und] == -1)


def test_possibly_joined_cells_have_equal_counts_and_touch_the_layer(joint):
    """Reported pairs: equal certified counts; two cells in one face-connected block would be one cell."""
    assert joint.joinable
    for a, b in joint.joinable:
        assert a != b and joint.cells[a].count == joint.cells[b].count >= 0
    # no two different cells are face-adjacent without marked voxels between them
    c = joint.cell
    for axis in range(3):
        x = np.moveaxis(c, axis, 0)
        touch = (x[:-1] >= 0) & (x[1:] >= 0)
        assert np.all(x[:-1][touch] == x[1:][touch])

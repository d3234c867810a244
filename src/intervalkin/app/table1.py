"""Table 1 of the paper beside the certified solutions of its joint vector (``intervalkin table1``).

Wenger & Chablat (1997), section 3.2, eq. (11) and Table 1: for the joint vector
rho = (14.98, 15.38, 12.0) the direct kinematic problem of the paper's 3-RPR has
six real solutions, and solutions 2, 3 and 6 lie in the same aspect (WA1, det A > 0
with the sign convention of DESIGN.md section 2).

The paper printed its rows with three decimals from inexact numerics: put back
into the inverse kinematics they miss the prescribed leg lengths by up to about
0.02 (0.01 typically).  The certified solutions of :func:`intervalkin.solve.dkp.solve`
are exact up to their enclosure width (< 1e-9); the comparison reports both the
distance from each paper row to its certified solution and the paper row's own
residual in rho, so that the two sources of difference can be told apart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from intervalkin.core.geometry import Geometry, default_geometry
from intervalkin.kinematics.formulas import approx_inverse_kinematics
from intervalkin.solve.dkp import DkpResult, solve

__all__ = ['TABLE1_RHO', 'TABLE1_ROWS', 'TABLE1_SAME_ASPECT', 'Table1Pair', 'Table1Comparison', 'table1_comparison', 'format_table1']

#: Eq. (11): the joint vector of Table 1, as the exact decimals printed.
TABLE1_RHO: tuple[str, str, str] = ("14.98", "15.38", "12.0")

#: Table 1: (x, y, phi) of solutions 1..6, as printed (phi in radians).
TABLE1_ROWS: tuple[tuple[str, str, str], ...] = (
    ("-8.715", "12.183", "-0.987"),
    ("-5.495", "-13.935", "-0.047"),
    ("-14.894", "1.596", "0.244"),
    ("-13.417", "-6.660", "0.585"),
    ("14.920", "-1.337", "1.001"),
    ("14.673", "-3.013", "2.133"),
)

#: "solutions -2-, -3-, -6- are in the same aspect (WA1)" (section 3.2, Figure 7).
TABLE1_SAME_ASPECT: frozenset[int] = frozenset({2, 3, 6})


@dataclass(frozen=True, eq=False)
class Table1Pair:
    """One paper row beside the certified solution it is paired with.

    Attributes
    ----------
    row : int, the paper's solution number (1..6).
    paper : ndarray (3,), the printed (x, y, phi).
    solution : int, the certified solution's number (1-based, increasing phi).
    certified_box : ndarray (3, 2), its enclosure.
    distance : ndarray (3,), |paper - certified midpoint| per coordinate (phi wrapped).
    distance_max : float, the largest of the three.
    paper_residual : ndarray (3,), g(paper row) - rho, in float64 (the paper's inexactness).
    det_sign, aspect : the certified sign of det A on the box and the aspect.
    """

    row: int
    paper: np.ndarray
    solution: int
    certified_box: np.ndarray
    distance: np.ndarray
    distance_max: float
    paper_residual: np.ndarray
    det_sign: int
    aspect: str | None

    def to_json(self) -> dict:
        b = self.certified_box
        return {
            "row": self.row,
            "paper": [float(v) for v in self.paper],
            "solution": self.solution,
            "certified": {"x": [float(b[0, 0]), float(b[0, 1])], "y": [float(b[1, 0]), float(b[1, 1])],
                          "phi": [float(b[2, 0]), float(b[2, 1])]},
            "distance": [float(v) for v in self.distance],
            "distance_max": self.distance_max,
            "paper_residual_rho": [float(v) for v in self.paper_residual],
            "det_sign": self.det_sign,
            "aspect": self.aspect,
        }


@dataclass(frozen=True, eq=False)
class Table1Comparison:
    """Table 1 against the certified solver.

    Attributes
    ----------
    result : DkpResult, the certified solve of eq. (11).
    pairs : tuple of Table1Pair, one per paper row (1..6), a bijection onto the
        certified solutions.
    same_aspect_rows : frozenset of paper rows whose certified aspect is WA1.
    same_aspect_claim_holds : bool, True when that set is {2, 3, 6} exactly.
    max_distance : float, largest coordinate distance paper <-> certified.
    max_paper_residual : float, largest |g(paper row) - rho|.
    """

    result: DkpResult
    pairs: tuple[Table1Pair, ...]
    same_aspect_rows: frozenset[int]
    same_aspect_claim_holds: bool
    max_distance: float
    max_paper_residual: float

    def to_json(self) -> dict:
        return {
            "rho": [float(r) for r in self.result.rho],
            "count": self.result.count,
            "complete": self.result.complete,
            "pairs": [p.to_json() for p in self.pairs],
            "wa1_rows": sorted(self.same_aspect_rows),
            "paper_claim_wa1_rows": sorted(TABLE1_SAME_ASPECT),
            "same_aspect_claim_holds": self.same_aspect_claim_holds,
            "max_distance": self.max_distance,
            "max_paper_residual_rho": self.max_paper_residual,
            "note": "the paper's rows come from inexact numerics; they miss the prescribed rho by about 0.01",
        }


def _wrapped(d: np.ndarray) -> np.ndarray:
    out = np.abs(d).astype(np.float64)
    out[..., 2] = np.abs(np.remainder(d[..., 2] + math.pi, 2 * math.pi) - math.pi)
    return out


def table1_comparison(geometry: Geometry | None = None) -> Table1Comparison:
    """Solve eq. (11) with certificates and pair every Table 1 row with one solution.

    Each paper row is paired with the certified solution nearest to it (largest
    coordinate difference, phi wrapped); the pairing must be a bijection, and the
    nearest paper row of each certified solution must be its partner (mutual
    nearest neighbours), otherwise AssertionError.
    """

    g = default_geometry() if geometry is None else geometry
    rho = tuple(Fraction(v) for v in TABLE1_RHO)
    result = solve(g, rho)
    paper = np.array([[float(v) for v in row] for row in TABLE1_ROWS])
    mids = np.array([s.midpoint for s in result.solutions]).reshape(-1, 3)
    assert len(mids) == len(paper), f"certified count {len(mids)} != {len(paper)} paper rows"
    dist = _wrapped(paper[:, None, :] - mids[None, :, :]).max(axis=-1)  # (rows, solutions)
    nearest = dist.argmin(axis=1)
    assert sorted(nearest.tolist()) == list(range(len(mids))), "Table 1 pairing is not a bijection"
    assert np.array_equal(dist.argmin(axis=0)[nearest], np.arange(len(paper))), "pairing is not mutual"
    residual = approx_inverse_kinematics(g, paper) - np.array([float(r) for r in rho])
    pairs = []
    for i, j in enumerate(nearest):
        s = result.solutions[j]
        d = _wrapped(paper[i] - s.midpoint)
        pairs.append(Table1Pair(
            row=i + 1, paper=paper[i], solution=int(j) + 1, certified_box=s.box, distance=d,
            distance_max=float(d.max()), paper_residual=residual[i], det_sign=s.det_sign, aspect=s.aspect,
        ))
    wa1 = frozenset(p.row for p in pairs if p.aspect == "WA1")
    return Table1Comparison(
        result=result,
        pairs=tuple(pairs),
        same_aspect_rows=wa1,
        same_aspect_claim_holds=wa1 == TABLE1_SAME_ASPECT,
        max_distance=max(p.distance_max for p in pairs),
        max_paper_residual=float(np.abs(residual).max()),
    )


def format_table1(comparison: Table1Comparison) -> str:
    """The paper's rows beside the certified solutions, with distances and residuals."""
    r = comparison.result
    lines = [
        "Wenger & Chablat (1997), Table 1: rho = (" + ", ".join(TABLE1_RHO) + ")",
        f"certified: {r.count} solutions, completeness {'PROVED' if r.complete else 'NOT proved'}",
        f"{'row':>3}  {'paper x':>8} {'paper y':>8} {'paper phi':>9}   {'sol':>3}  {'certified x':>12} "
        f"{'certified y':>12} {'certified phi':>13}  {'dist':>7}  {'paper |g-rho|':>13}  {'det A':>5}  aspect",
    ]
    lines.append("-" * len(lines[-1]))
    for p in comparison.pairs:
        x, y, phi = 0.5 * (p.certified_box[:, 0] + p.certified_box[:, 1])
        sign = {1: "+", -1: "-"}.get(p.det_sign, "?")
        lines.append(
            f"{p.row:>3}  {p.paper[0]:>8.3f} {p.paper[1]:>8.3f} {p.paper[2]:>9.3f}   {p.solution:>3}  {x:>12.6f} "
            f"{y:>12.6f} {phi:>13.6f}  {p.distance_max:>7.4f}  {np.abs(p.paper_residual).max():>13.4f}  "
            f"{sign:>5}  {p.aspect or '-'}"
        )
    same = ", ".join(str(v) for v in sorted(comparison.same_aspect_rows))
    verdict = "confirmed" if comparison.same_aspect_claim_holds else "NOT confirmed"
    lines.append(f"rows in aspect WA1 (det A > 0): {{{same}}}; the paper's claim {{2, 3, 6}}: {verdict}")
    lines.append(
        f"largest distance paper <-> certified: {comparison.max_distance:.4f}; the paper's rows miss rho by up to "
        f"{comparison.max_paper_residual:.4f} (printed from inexact numerics, about 0.01)"
    )
    return "\n".join(lines)

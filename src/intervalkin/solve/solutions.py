"""What the direct-kinematics solver returns: each assembly mode with its status, and the list's status.

A :class:`DkpSolution` is one assembly mode of a joint vector: an enclosure of
the pose (x, y, phi), the sign of det A on it (which names the aspect, WA1 for
det A > 0, WA2 for det A < 0) and its status, ``"unique"`` (PROVED to hold
exactly one solution) or ``"unknown"`` (where the float solver points; nothing
claimed) with the reason.  A :class:`DkpResult` is the list of them for one
exact joint vector, with the "no others" half of the claim stated apart:
``complete`` is True only when it is PROVED that the unique boxes hold all the
real solutions (see :func:`intervalkin.solve.dkp.solve`).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

__all__ = ['DkpSolution', 'DkpResult']


@dataclass(frozen=True, eq=False)
class DkpSolution:
    """One assembly mode.

    Attributes
    ----------
    box : ndarray of shape (3, 2), float64
        Rows (x, y, phi), columns (lo, hi).  For status ``"unique"`` the box is
        PROVED to contain exactly one solution of F = 0 (phi read modulo 2 pi) and
        is narrower than :data:`~intervalkin.solve.dkp.MAX_WIDTH`.  The phi
        interval meets (-pi, pi]; when it holds the seam it is written around +pi
        and exceeds pi by less than its width (the solution is then within that
        width of phi = pi).  For ``"unknown"`` the box is where the float solver
        points; nothing is claimed about it.
    det_sign : int
        1 or -1: sign of det A PROVED on the whole box; 0: not proved.
    aspect : str or None
        ``"WA1"`` (det A > 0), ``"WA2"`` (det A < 0) or None.
    status : str
        ``"unique"`` or ``"unknown"``.
    reason : str
        Why an unknown box could not be proved ("" for unique ones).
    """

    box: np.ndarray
    det_sign: int
    aspect: str | None
    status: str
    reason: str = ""

    @property
    def midpoint(self) -> np.ndarray:
        """(x, y, phi) at the box centre (float; approximate)."""
        return 0.5 * (self.box[:, 0] + self.box[:, 1])

    @property
    def width(self) -> float:
        """Largest side of the box."""
        return float(np.max(self.box[:, 1] - self.box[:, 0]))

    def to_json(self) -> dict:
        d = {
            "x": [float(self.box[0, 0]), float(self.box[0, 1])],
            "y": [float(self.box[1, 0]), float(self.box[1, 1])],
            "phi": [float(self.box[2, 0]), float(self.box[2, 1])],
            "det_sign": int(self.det_sign),
            "aspect": self.aspect,
            "status": self.status,
        }
        if self.status != "unique":
            d["reason"] = self.reason
        return d


@dataclass(frozen=True, eq=False)
class DkpResult:
    """Every assembly mode of one joint vector, with the status of the claim.

    Attributes
    ----------
    rho : three Fractions, the exact leg lengths solved for.
    solutions : tuple of DkpSolution, sorted by increasing phi midpoint.
    complete : bool
        True when it is PROVED that the unique boxes hold ALL the real solutions
        (one each, no others anywhere in R^2 x S^1).  False otherwise; then the
        listed unique boxes are still each proved, but the list may miss
        solutions or contain unknown boxes.
    completeness_reason : str
        How completeness was proved, or why it could not be.
    precision : int
        The arb working precision (bits) of the last attempt.
    """

    rho: tuple[Fraction, Fraction, Fraction]
    solutions: tuple[DkpSolution, ...]
    complete: bool
    completeness_reason: str
    precision: int

    @property
    def count(self) -> int:
        """Number of listed solutions (the certified count only when ``complete``)."""
        return len(self.solutions)

    @property
    def signature(self) -> tuple[int, int, int] | None:
        """(count, n_wa1, n_wa2) when the list is complete and every solution is proved non-singular with its
        sign of det A (the signature of the joint vector, certified); None otherwise."""
        if not self.complete or any(s.aspect not in ("WA1", "WA2") for s in self.solutions):
            return None
        n1 = sum(1 for s in self.solutions if s.aspect == "WA1")
        return self.count, n1, self.count - n1

    def to_json(self) -> dict:
        """``{"rho", "count", "complete", "solutions"}`` as plain JSON types."""
        return {
            "rho": [float(r) for r in self.rho],
            "count": self.count,
            "complete": bool(self.complete),
            "solutions": [s.to_json() for s in self.solutions],
        }

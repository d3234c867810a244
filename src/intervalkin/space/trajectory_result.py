"""A certified motion between two assembly modes of one aspect: the :class:`Trajectory` result.

:func:`intervalkin.space.trajectory.trajectory` builds it; this module holds what
it returns and how that is written out (``--json`` object, certificate,
summary).

phi convention
--------------
Waypoints carry an UNWRAPPED phi: phi is continuous along the path, it starts at
the start solution's phi (in (-pi, pi]) and may leave (-pi, pi] when the path
crosses the seam phi = +-pi.  The last waypoint is the goal solution's phi plus
``2 pi * phi_turns``.  Take phi modulo 2 pi to get the usual pose.  The
kinematics are 2 pi periodic in phi, so nothing else changes.

What is certified
-----------------
The motion is the chain of exact straight segments between consecutive
waypoints, the first starting at the EXACT start solution and the last ending
at the EXACT goal solution (known through their enclosures).  Each segment
carries a :class:`~intervalkin.space.segment.SegmentCertificate`; ``certified``
True means every segment is proved to keep det A of the aspect's sign and every
leg within its limits.  :meth:`Trajectory.certificate` gives that evidence with
every float as an exact hex string, for the independent checker.

The regions and cells crossed are reports with their own standing (see
:mod:`intervalkin.space.trajectory`): the joint cells are certified per piece,
the basic regions are sampled.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from intervalkin.space.segment import SegmentCertificate

__all__ = ['Trajectory']


@dataclass(frozen=True, eq=False)
class Trajectory:
    """A path between two assembly modes of one aspect, with its certificate.

    Attributes
    ----------
    rho : three Fractions, the joint vector.
    i_from, i_to : the solution numbers (1-based, increasing phi, as ``intervalkin dkp``).
    aspect : ``"WA1"`` or ``"WA2"``; ``sign`` its det A sign.
    waypoints : ndarray (m, 3), phi unwrapped (module docstring).  Rows 0 and m-1
        are the float midpoints of the solution enclosures; the certified motion
        starts and ends at the exact solutions (``segments[0].start`` and
        ``segments[-1].end`` are their enclosures).
    phi_turns : the goal is reached at its phi plus 2 pi phi_turns.
    segments : one :class:`SegmentCertificate` per pair of consecutive waypoints.
    certified : bool, all segments certified; ``reason`` otherwise.
    box_path : paving indices of the boxes of the shortest path (before smoothing).
    raw_waypoints : number of waypoints before smoothing.
    depth : depth of the paving used.
    samples : ndarray (s, 3), points along the path (unwrapped); ``sample_rho`` (s, 3)
        their float images g(X) (for plots only); ``sample_segment`` (s,).
    basic_regions : tuple of region ids in order (-1: the layer), or None without analysis.
    sample_region : ndarray (s,) or None.
    joint_cells : tuple of dicts {cell, count, n_wa1, n_wa2} in order (cell -1: layer),
        certified per piece (module docstring), or None without a joint paving.
    sample_count : ndarray (s,) certified count of the cell holding each sample's image, -1 unknown.
    seconds : timings.
    """

    rho: tuple[Fraction, Fraction, Fraction]
    i_from: int
    i_to: int
    aspect: str
    sign: int
    waypoints: np.ndarray
    phi_turns: int
    segments: tuple[SegmentCertificate, ...]
    certified: bool
    reason: str
    box_path: np.ndarray
    raw_waypoints: int
    depth: int
    samples: np.ndarray
    sample_rho: np.ndarray
    sample_segment: np.ndarray
    basic_regions: tuple[int, ...] | None = None
    sample_region: np.ndarray | None = None
    joint_cells: tuple[dict, ...] | None = None
    sample_count: np.ndarray | None = None
    solutions: tuple = ()
    seconds: dict = field(default_factory=dict)

    @property
    def counts_along_path(self) -> list[int] | None:
        """Certified solution counts of the cells crossed, in order (layer entries left out)."""
        if self.joint_cells is None:
            return None
        return [c["count"] for c in self.joint_cells if c["cell"] >= 0]

    @property
    def through_two_solution_cell(self) -> bool | None:
        """True when some piece of the path is PROVED to map into a cell with exactly 2 solutions.

        False only means "not shown at this depth": the image may cross a 2-solution
        cell inside the joint-space layer.  None without a joint paving.
        """
        c = self.counts_along_path
        return None if c is None else (2 in c)

    def to_json(self) -> dict:
        """The ``intervalkin trajectory --json`` object (plain JSON types)."""
        d = {
            "rho": [float(v) for v in self.rho],
            "rho_exact": [f"{v.numerator}/{v.denominator}" for v in self.rho],
            "from": self.i_from,
            "to": self.i_to,
            "aspect": self.aspect,
            "waypoints": self.waypoints.tolist(),
            "phi_convention": "unwrapped: continuous along the path from the start solution's phi; "
                              "the goal is reached at its phi + 2 pi * phi_turns",
            "phi_turns": self.phi_turns,
            "basic_regions": None if self.basic_regions is None
            else [r if r >= 0 else "layer" for r in self.basic_regions],
            "certified": bool(self.certified),
        }
        if not self.certified:
            d["reason"] = self.reason
        if self.joint_cells is not None:
            d["joint_cells"] = [dict(c, cell=c["cell"] if c["cell"] >= 0 else "layer") for c in self.joint_cells]
            d["counts_along_path"] = self.counts_along_path
            d["through_two_solution_cell"] = self.through_two_solution_cell
        d["depth"] = self.depth
        d["raw_waypoints"] = self.raw_waypoints
        d["pieces_per_segment"] = [int(s.pieces.shape[0]) for s in self.segments]
        return d

    def certificate(self) -> dict:
        """What an independent checker needs to re-prove the motion (floats as exact hex strings).

        For each segment: the enclosures of its end points and its pieces [t0, t1];
        the claim is that on every piece the segment stays where det A has the sign
        ``sign`` and the legs within [rho_min, rho_max] (module docstring).
        """
        hx = lambda v: float(v).hex()  # noqa: E731
        return {
            "claim": "non-singular motion within the joint limits",
            "rho_exact": [f"{v.numerator}/{v.denominator}" for v in self.rho],
            "from": self.i_from,
            "to": self.i_to,
            "aspect": self.aspect,
            "det_sign": self.sign,
            "segments": [
                {
                    "start": [[hx(a), hx(b)] for a, b in s.start],
                    "end": [[hx(a), hx(b)] for a, b in s.end],
                    "pieces": [[hx(a), hx(b)] for a, b in s.pieces],
                    "certified": bool(s.certified),
                }
                for s in self.segments
            ],
        }

    def summary(self) -> str:
        """A few human-readable lines."""
        lines = [
            f"trajectory from solution {self.i_from} to {self.i_to} in {self.aspect}: "
            f"{len(self.waypoints)} waypoints ({self.raw_waypoints} before smoothing), "
            f"{'CERTIFIED' if self.certified else 'NOT certified: ' + self.reason}",
        ]
        if self.basic_regions is not None:
            lines.append("basic regions: " + " -> ".join(str(r) if r >= 0 else "layer" for r in self.basic_regions))
        if self.joint_cells is not None:
            lines.append("joint cells (count): " + " -> ".join(
                f"{c['cell']} ({c['count']})" if c["cell"] >= 0 else "layer" for c in self.joint_cells))
            lines.append(f"through a 2-solution cell: {'yes' if self.through_two_solution_cell else 'no'}")
        lines.append("waypoints (x, y, phi unwrapped):")
        lines += [f"  {x: .6f} {y: .6f} {p: .6f}" for x, y, p in self.waypoints]
        return "\n".join(lines)

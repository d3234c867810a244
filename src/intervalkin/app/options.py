"""The 3-RPR manipulator as data: exact, validated, frozen.

A pose is X = (x, y, phi): (x, y) is the platform point B1 and phi the angle of
the platform side B1B2 with the fixed x axis.  In the platform frame (origin B1,
x axis along B1B2) the platform points are

    p1 = (0, 0),   p2 = (l2, 0),   p3 = (p3x, p3y),

and in the fixed frame B_i = B1 + R(phi) p_i.  Leg i joins the base point A_i to
B_i and its length is rho_i = |B_i - A_i|, limited to [rho_min_i, rho_max_i].

Every input number is read as an exact decimal (15.91 is 1591/100).  The derived
platform constants are of the form ``q * sqrt(r)`` with q, r rational (l3 sin
theta is a square root, not a rational), carried exactly as :class:`Surd` and
turned into arb balls or outward-rounded float enclosures on demand.  Nothing in
this module rounds silently.
"""

from __future__ import annotations

from pathlib import Path

from intervalkin.core.geometry import Geometry, default_geometry, load_geometry


def geometry_from_option(path: str | Path | None) -> Geometry:
    """The geometry named on the command line, or the paper's default when None."""
    return default_geometry() if path is None else load_geometry(path)

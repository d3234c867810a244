"""Axis names and units shared by the figures, the report and the exports.

Poses are (x, y, phi) with phi in radians inside the library; people read phi in
degrees, so every figure, the interactive report and (by default) the VTK files
show phi in degrees.  The lengths carry the unit of the geometry file (the
paper gives none), called "length units" here.

>>> phi_factor("deg") == 180 / math.pi, phi_factor("rad"), phi_factor(10.0)
(True, 1.0, 10.0)
"""

from __future__ import annotations

import math

from intervalkin.core.errors import InputError

__all__ = ["PHI_UNITS", "phi_factor", "phi_unit_name", "WORKSPACE_AXES", "JOINT_AXES", "LENGTH"]

#: Named scales of phi: the factor that turns radians into the unit.
PHI_UNITS = {"deg": 180.0 / math.pi, "rad": 1.0}

LENGTH = "length units"

#: Axis titles of the workspace (x, y, phi in degrees) and of the joint space.
WORKSPACE_AXES = (f"x ({LENGTH})", f"y ({LENGTH})", "φ (deg)")
JOINT_AXES = (f"ρ1 ({LENGTH})", f"ρ2 ({LENGTH})", f"ρ3 ({LENGTH})")


def phi_factor(unit: str | float) -> float:
    """The factor from radians to ``unit``: "deg", "rad" or a positive number (radians times it).

    Raises :class:`~intervalkin.core.errors.InputError` naming ``phi_unit`` otherwise.
    """
    if isinstance(unit, str):
        if unit in PHI_UNITS:
            return PHI_UNITS[unit]
        try:
            unit = float(unit)
        except ValueError:
            raise InputError(f"phi_unit: expected 'deg', 'rad' or a positive number, got {unit!r}") from None
    if isinstance(unit, bool) or not isinstance(unit, (int, float)) or not math.isfinite(unit) or unit <= 0:
        raise InputError(f"phi_unit: expected 'deg', 'rad' or a positive number, got {unit!r}")
    return float(unit)


def phi_unit_name(unit: str | float) -> str:
    """Words for the phi axis of a file: 'degrees', 'radians' or 'radians x <factor>'."""
    factor = phi_factor(unit)
    if factor == PHI_UNITS["deg"]:
        return "degrees"
    if factor == 1.0:
        return "radians"
    return f"radians x {factor:g}"

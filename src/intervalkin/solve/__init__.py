"""solve/: certified direct kinematics of the 3-RPR, joint boxes proved off g(S) or cut by one fold sheet, continuation.

The layer is callable: ``intervalkin.solve(rho, geometry=None)`` solves the
direct kinematics of one joint vector (:func:`solve_joint_vector`).  A package
cannot hold both a sub-package and a function called ``solve``: importing
``intervalkin.solve.dkp`` would replace the function by the sub-package.  So
the sub-package itself answers the call, and ``intervalkin.solve.dkp`` and the
function never get in each other's way.
"""

from __future__ import annotations

import sys
import types
from typing import Sequence

from intervalkin.core.geometry import Geometry, default_geometry
from intervalkin.solve import dkp

__all__ = ["solve_joint_vector"]


def solve_joint_vector(rho: Sequence, geometry: Geometry | None = None) -> dkp.DkpResult:
    """Every real solution of the direct kinematics of ``rho``, each proved unique in its box.

    Parameters
    ----------
    rho : three leg lengths: decimal text, ints or Fractions, read exactly (a float through its
        shortest decimal text, 14.98 as "14.98"); see :func:`intervalkin.solve.dkp.parse_joint_vector`.
    geometry : the manipulator; the paper's (Wenger & Chablat 1997) when None.

    Returns a :class:`~intervalkin.solve.solutions.DkpResult`: ``complete`` says whether
    it is also proved that there are no other solutions.

    >>> import intervalkin
    >>> r = intervalkin.solve(["14.98", "15.38", "12.0"])
    >>> r.count, r.complete
    (6, True)
    """
    geometry = default_geometry() if geometry is None else geometry
    return dkp.solve(geometry, dkp.parse_joint_vector(geometry, rho))


class _CallableLayer(types.ModuleType):
    """The ``intervalkin.solve`` package, callable as :func:`solve_joint_vector`."""

    def __call__(self, rho: Sequence, geometry: Geometry | None = None) -> dkp.DkpResult:
        return solve_joint_vector(rho, geometry)


sys.modules[__name__].__class__ = _CallableLayer

"""A float-only direct-kinematics solver, the tests' independent slow path.

Dense sampling in phi with float Newton polishing: no arb, no proof. It is kept
here, not in the package, because nothing certified may rest on it.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from intervalkin.core.geometry import Geometry
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.formulas import approx_inverse_kinematics, approx_jacobian


def approx_solve(geometry: Geometry, rho: Sequence[float], samples: int = 1 << 16) -> np.ndarray:
    """Approximate solutions (n, 3) by dense phi sampling of the reduced equation.

    Not certified.  Independent of :func:`solve`: it uses only float64 numpy
    (the kinematics constants, not the Laurent reduction), finds the sign
    changes of f(phi) = |N|^2 - rho_1^2 D^2 on a uniform grid, refines each by
    bisection and lifts it with Cramer's rule and a few Newton steps on the 3x3
    system.  Double roots (tangencies) are missed by design.
    """


    k = constants(geometry)
    r = np.asarray([float(v) for v in rho])
    a = np.stack([k.ax - k.ax[0], k.ay - k.ay[0]], axis=-1)

    def parts(phi):
        phi = np.asarray(phi, dtype=np.float64)
        ex = [k.radius[i] * np.cos(phi + k.alpha[i]) for i in range(3)]
        ey = [k.radius[i] * np.sin(phi + k.alpha[i]) for i in range(3)]
        vx = [ex[i] - a[i, 0] for i in (1, 2)]
        vy = [ey[i] - a[i, 1] for i in (1, 2)]
        kk = [r[i] ** 2 - r[0] ** 2 - (vx[j] ** 2 + vy[j] ** 2) for j, i in enumerate((1, 2))]
        m2x, m2y, m3x, m3y = 2 * vx[0], 2 * vy[0], 2 * vx[1], 2 * vy[1]
        D = m2x * m3y - m2y * m3x
        Nx = kk[0] * m3y - kk[1] * m2y
        Ny = m2x * kk[1] - m3x * kk[0]
        return D, Nx, Ny

    def f(phi):
        D, Nx, Ny = parts(phi)
        return Nx**2 + Ny**2 - r[0] ** 2 * D**2

    grid = np.linspace(-math.pi, math.pi, samples + 1)
    vals = f(grid)
    idx = np.nonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) <= 0)[0]
    out = []
    for i in idx:
        lo, hi = grid[i], grid[i + 1]
        flo = vals[i]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            fm = f(mid)
            if np.sign(fm) == np.sign(flo) and fm != 0:
                lo, flo = mid, fm
            else:
                hi = mid
        phi = 0.5 * (lo + hi)
        D, Nx, Ny = parts(phi)
        X = np.array([k.ax[0] + Nx / D, k.ay[0] + Ny / D, phi])
        for _ in range(5):
            res = approx_inverse_kinematics(geometry, X) ** 2 - r**2
            X = X - np.linalg.solve(approx_jacobian(geometry, X), res)
        X[2] = math.remainder(X[2], 2.0 * math.pi)
        if not any(np.max(np.abs(X - Z)) < 1e-7 for Z in out):
            out.append(X)
    return np.array(out).reshape(-1, 3)

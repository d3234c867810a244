"""intervalkin: certified definition sets of the planar 3-RPR parallel manipulator.

The library in five calls (each result says what is proved; see the README's "Library")::

    intervalkin.solve(rho, geometry=None)          -> DkpResult: every assembly mode, each proved unique
    intervalkin.analyse(geometry=None, depth=8)    -> Analysis: joint cells, basic regions, uniqueness domains
        Analysis.label(pose), Analysis.locate(rho), Analysis.counts()
    intervalkin.verify(path)                       -> VerifyReport: the independent checker's verdicts
    intervalkin.sweep(file, cache=None)            -> SweepResult: one analysis per design, on Dask

Layers, from the ground floor up (a layer imports only the layers below it; the
import-linter contract in ``pyproject.toml`` enforces it):

core/        the manipulator as exact data, interval arithmetic (the one rounding layer), errors,
             files, statuses and counts
kinematics/  g, A, det A and the sextic: written once, evaluated in float, intervals and arb
paving/      octree box trees, tri-state labels, adjacency with the phi seam, memory budget, predicates
solve/       certified direct kinematics; continuation of solutions along joint-space paths
space/       aspects, joint space, characteristic surfaces, basic regions, uniqueness domains, trajectories
checker/     the independent verifier of certificates (standard library, python-flint and core only)
certify/     claim files written from the results above
pipeline     the whole analysis as one library call
sweeps/      design sweeps: one analysis per design of a family, as Dask tasks, cached by content hash
app/         the ``intervalkin`` command, output folders, report, export, figures, animation

The public names below are loaded on first use, so ``import intervalkin`` and
``import intervalkin.checker`` do not pull in numpy or the paving code.
"""

from __future__ import annotations

import importlib

from intervalkin.core.version import __version__

# name -> module that defines it (loaded lazily by __getattr__)
_API = {
    "IntervalkinError": "intervalkin.core.errors",
    "GeometryError": "intervalkin.core.errors",
    "InputError": "intervalkin.core.errors",
    "ResourceError": "intervalkin.core.errors",
    "Geometry": "intervalkin.core.geometry",
    "Surd": "intervalkin.core.geometry",
    "default_geometry": "intervalkin.core.geometry",
    "load_geometry": "intervalkin.core.geometry",
    "Interval": "intervalkin.core.interval",
    "Status": "intervalkin.core.status",
    "Count": "intervalkin.core.status",
    "DkpResult": "intervalkin.solve.solutions",
    "DkpSolution": "intervalkin.solve.solutions",
    "PoseLabel": "intervalkin.space.pose_label",
    "DEFAULT_DEPTH": "intervalkin.pipeline",
    "Analysis": "intervalkin.pipeline",
    "JointLocation": "intervalkin.pipeline",
    "ProgressEvent": "intervalkin.pipeline",
    "VerifyReport": "intervalkin.pipeline",
    "analyse": "intervalkin.pipeline",
    "verify": "intervalkin.pipeline",
    "sweep": "intervalkin.sweeps.engine",
    "SweepResult": "intervalkin.sweeps.engine",
    "SweepSpec": "intervalkin.sweeps.spec",
    "load_sweep": "intervalkin.sweeps.spec",
}
# ``intervalkin.solve`` is the solve/ layer itself, which is callable (see its docstring)
_LAYERS = {"solve"}

__all__ = ["__version__", *_API, *_LAYERS]


def __getattr__(name: str):
    if name in _LAYERS:
        return importlib.import_module(f"intervalkin.{name}")
    module = _API.get(name)
    if module is None:
        raise AttributeError(f"module 'intervalkin' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)

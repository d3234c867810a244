"""An independent, vectorised re-check of every box label of a workspace paving (``intervalkin verify``).

The certificates re-prove a sample of box labels in arb; this package re-proves
all of them, millions of boxes in seconds, with numpy arrays of float64 bounds
rounded outward after every operation.  It is a second writing of the
arithmetic and of the formulas, on purpose: it imports neither the library's
rounding layer (:mod:`intervalkin.core.interval`, :mod:`intervalkin.core.ball`)
nor its kinematics, paving, solver or space code (the import-linter contract in
``pyproject.toml``), so a slip there cannot hide itself here.  Its trusted base
is numpy's correctly rounded +, -, * (outward steps included), numpy's cos and sin
within a documented margin, python-flint for the two constants L_i and alpha_i
of the geometry, and, for the few labels the float pass leaves open, the arb
checker (:mod:`intervalkin.checker.labels`).  The argument is
``proofs/lemma-box-label-recheck.md``.

Modules, from the ground up:

:mod:`~intervalkin.recheck.arith`
    interval arrays: +, -, *, square, cos and sin, each rounded outward.
:mod:`~intervalkin.recheck.model`
    rho_i^2 and det A over boxes (natural and mean value forms), the label tests.
:mod:`~intervalkin.recheck.bisect`
    every claimed label confirmed, refuted or left open, with vectorised bisection.
:mod:`~intervalkin.recheck.paving_file`
    ``pavings/workspace.npz`` read and validated, re-checked in full, one verdict.
:mod:`~intervalkin.recheck.reduced_equation`, :mod:`~intervalkin.recheck.count_range`
    the reduced equation and its phi-derivatives over joint boxes; proved ranges of the number of
    solutions at every point of a joint box.
:mod:`~intervalkin.recheck.separation_file`
    ``certificates/joint_separation.*``: count barriers between joint cells, re-proved.
"""

from intervalkin.recheck.paving_file import (
    KIND,
    RecheckReport,
    WorkspaceLabels,
    find_paving,
    read_workspace_labels,
    recheck_folder,
    recheck_paving,
)
from intervalkin.recheck.separation_file import recheck_separations

__all__ = ['KIND', 'RecheckReport', 'WorkspaceLabels', 'find_paving', 'read_workspace_labels',
           'recheck_folder', 'recheck_paving', 'recheck_separations']

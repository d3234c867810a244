"""The independent checker of intervalkin certificate files (``intervalkin verify DIR``).

A certificate folder (written by :func:`intervalkin.certify.writer.write_certificates`;
schema in that module) states claims with their evidence.  This package re-proves
every claim from the files alone, in arb ball arithmetic (python-flint), and
gives one verdict per claim.  Its trusted base is small on purpose:

* the Python standard library and python-flint (arb, acb, arb_poly, acb_poly,
  arb_mat; ``acb_poly.roots`` for certified complex root isolation);
* :mod:`intervalkin.core.geometry` (reads the geometry TOML stored in the files as
  exact decimals; constants as exact rationals and surds) and
  :mod:`intervalkin.core.errors`;
* its own model of the manipulator in arb (rho_i^2, det A, F, F' in
  :mod:`~intervalkin.checker.model`, the reduced sextic in
  :mod:`~intervalkin.checker.solutions`).  These formulas are written a second
  time on purpose, from the mathematics, instead of imported from
  :mod:`intervalkin.kinematics` or :mod:`intervalkin.solve`: the checker must
  stay independent of what it checks, and the tests compare the two writings.

It never imports the kinematics, paving, solver, space, certify or app code,
nor numpy (the import-linter contract in ``pyproject.toml``,
``tests/test_architecture.py`` and
``tests/certify/test_certificates.py::test_checker_imports_none_of_the_checked_modules``).
What each claim type proves, and what it still trusts, is in
``proofs/lemma-checker.md``.

Modules: :mod:`~intervalkin.checker.parse` (reading fields exactly),
:mod:`~intervalkin.checker.model` (the arb model), :mod:`~intervalkin.checker.labels`
(box labels), :mod:`~intervalkin.checker.solutions` (direct kinematics),
:mod:`~intervalkin.checker.aspects` and :mod:`~intervalkin.checker.taylor` (aspect covers),
:mod:`~intervalkin.checker.trajectory` (motions), :mod:`~intervalkin.checker.joint_torus`,
:mod:`~intervalkin.checker.joint_exclusion` (Krawczyk exclusion of small torus cells),
:mod:`~intervalkin.checker.joint_models` and :mod:`~intervalkin.checker.joint_join` (fold models
and joins of the joint paving), :mod:`~intervalkin.checker.claims`
(one check per kind, counts), :mod:`~intervalkin.checker.consistency` (counts against
their proofs and the summary), :mod:`~intervalkin.checker.folder` (a whole folder).

Re-proved per claim type
------------------------
``dkp`` / ``joint_cell``
    Each solution box holds exactly one solution of the ORIGINAL system
    F_i = |B_i - A_i|^2 - rho_i^2 (Krawczyk, the checker's own preconditioner,
    strict interior inclusion); det A has the declared sign on the whole box;
    the boxes are pairwise disjoint with phi read modulo 2 pi; and, for a claim
    of completeness, the checker rebuilds the reduced sextic in t = tan((phi -
    phi0)/2) by its own real-polynomial derivation, proves its leading
    coefficient non-zero, isolates its roots (``acb_poly.roots``), counts the
    real ones, proves the 2x2 system regular at each, and requires that count
    to equal the number of boxes.  A ``joint_cell`` claim also checks that the
    witness lies in the joint limits and that its count and aspect split are
    the ones declared.
``aspect_distinct``
    Each box lies in W (rho_min_i^2 <= rho_i^2 <= rho_max_i^2 on the whole box)
    and det A has the declared sign on the whole box (box subdivided in arb
    when the natural enclosure is too wide); the two signs are opposite.
``region_distinct``
    The joint vector's listed solutions are re-proved (Krawczyk, one aspect,
    pairwise disjoint), each solution box lies in its stated paving box, and
    that paving box's W and det-sign labels are re-proved in arb.  The
    "off S_c" label and the box-to-piece map are NOT re-checked (they need the
    joint-space enclosure of g(S)); the claim text says so.
``box_labels``
    Every INSIDE / OUTSIDE label of the sampled boxes (W and det_positive) is
    re-proved in arb over the whole box, subdividing when needed; BOUNDARY
    labels claim nothing.  The sample indices are re-derived from the seed.
``trajectory``
    The joint vector's complete solution list is re-proved as for ``dkp`` (it
    fixes the solution numbers: increasing phi in [-pi, pi]); the start and
    goal enclosures each hold exactly one solution (Krawczyk), lie in the
    listed solutions ``from`` and ``to``, and carry det A of the stated sign.
    For every piece [t0, t1] of every straight segment A + t (B - A) (A, B
    the segment's end enclosures), the ball A + [t0, t1] (B - A) is formed in
    arb and det A is proved of the aspect's sign and rho_min_i^2 <= rho_i^2 <=
    rho_max_i^2 proved on it (the t range bisected while undecided, within
    :data:`~intervalkin.checker.trajectory.PIECE_BUDGET` evaluations); the
    pieces tile [0, 1]; consecutive segments share their end enclosure; the
    start enclosure lies in the first segment's start, and the goal enclosure
    shifted by 2 pi phi_turns (phi unwrapped) in the last segment's end.
``aspect_connected``
    A cover of the paving domain by octree boxes, each OUT (no point of the
    aspect's sign), SINK (inside it) or retracting along an exact direction:
    the domain holds W, the boxes tile it, the sinks are face-connected, the
    boxes across each exit face come earlier in the list, and every box's kind
    is re-proved in arb (:mod:`~intervalkin.checker.aspects`, Taylor forms of
    :mod:`~intervalkin.checker.taylor`): that sign's part of W is nonempty and
    connected (proofs/lemma-aspect-retraction.md).
``joint_fold_model``
    Every singular pose whose joint vector lies in the joint box has a 2 pi-translate in
    the pose box (torus search over (theta, phi) on the circle of leg 1); the parametric
    Krawczyk image of the pose box over the box's (r_i, r_j) lies in its interior (the
    checker's own preconditioner); the stated connectivity criterion holds; each witness
    lies on its stated side of the sheet: one graph sheet of g(S) cutting the box into
    two connected pieces (proofs/lemma-joint-claims.md).
``joint_join``
    The two ends declare one count and split, and each witness's complete solution list
    proves it; every clear node is re-proved off g(S) by the torus search (small undecided
    cells discarded by Krawczyk exclusion, proofs/lemma-clear-joint-box.md), every fold
    node is a verified ``joint_fold_model`` claim of the folder; each witness and link
    lies strictly inside the joint limits and in its node(s) (the side test for pieces):
    both witnesses lie in one component of the joint box minus g(S).
``counts``
    Each declared lower bound is recomputed from the referenced claims that
    verified (rules in :func:`~intervalkin.checker.claims.count_bound`); a
    declared lower bound larger than the recomputed one, a declared upper
    bound the verified claims do not back (:func:`~intervalkin.checker.claims.count_upper`:
    the aspects, from an ``aspect_connected`` claim of each sign), a count
    declared exact whose bounds do not meet, or a library count ``found``
    outside the proved bounds is refused.
    When the folder is ``DIR/certificates`` of an output folder, the count
    blocks of ``DIR/summary.json`` (what the user was shown) must agree with
    the claims: same count and lower bound, no count below a proved bound, no
    exact count without a proved upper bound
    (:mod:`~intervalkin.checker.consistency`).
"""

from intervalkin.checker.claims import check_claim
from intervalkin.checker.folder import CheckResult, verify_directory
from intervalkin.checker.labels import box_label_proved
from intervalkin.checker.parse import (
    FORMAT,
    INDEX,
    KINDS,
    VERSION,
    parse_exact,
    sample_indices,
)
from intervalkin.core.errors import CertificateFormatError

__all__ = [
    "FORMAT",
    "VERSION",
    "KINDS",
    "INDEX",
    "CertificateFormatError",
    "CheckResult",
    "parse_exact",
    "sample_indices",
    "check_claim",
    "box_label_proved",
    "verify_directory",
]

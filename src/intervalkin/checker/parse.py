"""The independent checker of intervalkin certificate files (``intervalkin verify DIR``).

A certificate folder (written by :func:`intervalkin.certify.writer.write_certificates`;
schema in that module) states claims with their evidence.  This module re-proves
every claim from the files alone, in arb ball arithmetic (python-flint), and
prints one line per claim.  Its trusted base is small on purpose:

* the Python standard library and python-flint (arb, acb, arb_poly, acb_poly,
  arb_mat; ``acb_poly.roots`` for certified complex root isolation);
* :mod:`intervalkin.core.geometry` (reads the geometry TOML stored in the files as
  exact decimals; constants as exact rationals and surds) and
  :mod:`intervalkin.core.errors`;
* the few formulas written out below (rho_i^2, det A, F, F', the reduced
  sextic), re-derived here on purpose instead of imported from
  :mod:`intervalkin.kinematics` or :mod:`intervalkin.solve.dkp`.

It never imports the paving, predicate, joint, region, dkp or analysis code
(``tests/test_certificates.py::test_checker_imports_none_of_the_checked_modules``).
What each claim type proves, and what it still trusts, is in
``proofs/lemma-checker.md``.

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
    :data:`PIECE_BUDGET`); the pieces tile [0, 1]; consecutive segments share
    their end enclosure; the start enclosure lies in the first segment's
    start, and the goal enclosure shifted by 2 pi phi_turns (phi unwrapped)
    in the last segment's end.
``counts``
    Each declared lower bound is recomputed from the referenced claims that
    verified (rules in :func:`_count_bound`); a declared lower bound larger than
    the recomputed one, or a count declared exact, is refused.
"""

from __future__ import annotations

import decimal
import hashlib
import math
from fractions import Fraction
from typing import Any

from intervalkin.core.errors import InputError

__all__ = ['FORMAT', 'VERSION', 'KINDS', 'CertificateFormatError', 'parse_exact', 'sample_indices']

FORMAT = "intervalkin-certificate"
VERSION = 1
#: Claim files, in the order they are checked (``counts`` last: it uses the others).
KINDS = ("dkp", "joint_cell", "aspect_distinct", "region_distinct", "box_labels", "trajectory", "counts")
INDEX = "index.json"

#: Sub-box evaluations allowed per re-proved box label (the box is bisected while undecided).
LABEL_BUDGET = 20000
#: Evaluations allowed per piece of a trajectory segment (the piece's t range is bisected while undecided).
PIECE_BUDGET = 2000
#: Precisions (bits) accepted in a file.
_PREC_RANGE = (53, 4096)


class CertificateFormatError(InputError):
    """A certificate folder is missing, unreadable or not in the documented format."""


class _Refused(Exception):
    """A claim that could not be re-proved (the message says which step failed)."""


# --------------------------------------------------------------------------------------
# Exact inputs
# --------------------------------------------------------------------------------------
def parse_exact(text: Any, what: str = "value") -> Fraction:
    """An exact rational from a string "p/q" or a decimal "14.98" (JSON numbers are refused)."""
    if not isinstance(text, str):
        raise _Refused(f"{what}: expected an exact string such as \"1498/100\" or \"14.98\", got {text!r}")
    try:
        if "/" in text:
            return Fraction(text.strip())
        d = decimal.Decimal(text.strip())
    except (ValueError, ZeroDivisionError, decimal.InvalidOperation):
        raise _Refused(f"{what}: {text!r} is not an exact rational") from None
    if not d.is_finite():
        raise _Refused(f"{what}: {text!r} is not finite")
    return Fraction(d)


def _float(v: Any, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise _Refused(f"{what}: expected a number, got {v!r}")
    f = float(v)
    if not math.isfinite(f):
        raise _Refused(f"{what}: {v!r} is not finite")
    return f


def _box(obj: Any, what: str = "box", number=None) -> tuple[tuple[float, float], ...]:
    """[[xlo, xhi], [ylo, yhi], [philo, phihi]] as binary64 numbers (or ``number``-parsed strings), lo <= hi."""
    number = _float if number is None else number
    if not isinstance(obj, list) or len(obj) != 3:
        raise _Refused(f"{what}: expected [[xlo, xhi], [ylo, yhi], [philo, phihi]], got {obj!r}")
    out = []
    for j, pair in enumerate(obj):
        if not isinstance(pair, list) or len(pair) != 2:
            raise _Refused(f"{what}[{j}]: expected [lo, hi], got {pair!r}")
        lo, hi = number(pair[0], f"{what}[{j}][0]"), number(pair[1], f"{what}[{j}][1]")
        if not lo <= hi:
            raise _Refused(f"{what}[{j}]: empty interval [{lo!r}, {hi!r}]")
        out.append((lo, hi))
    return tuple(out)


def _int(v: Any, what: str, lo: int | None = None, hi: int | None = None) -> int:
    if isinstance(v, bool) or not isinstance(v, int):
        raise _Refused(f"{what}: expected an integer, got {v!r}")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise _Refused(f"{what}: {v} is outside [{lo}, {hi}]")
    return v


def _get(claim: dict, key: str) -> Any:
    if key not in claim:
        raise _Refused(f"missing field {key!r}")
    return claim[key]


def sample_indices(seed: int, population: int, size: int) -> list[int]:
    """The sampled box indices: draw j gives sha256("intervalkin-sample:{seed}:{j}") mod population.

    Duplicates are skipped until ``min(size, population)`` distinct indices are
    drawn.  Defined with the standard library only, so that a reader can check
    that a sample was not chosen by hand.
    """
    want = min(size, population)
    out: list[int] = []
    seen: set[int] = set()
    j = 0
    while len(out) < want:
        h = hashlib.sha256(f"intervalkin-sample:{seed}:{j}".encode()).digest()
        k = int.from_bytes(h[:8], "big") % population
        if k not in seen:
            seen.add(k)
            out.append(k)
        j += 1
    return out


# --------------------------------------------------------------------------------------
# The manipulator in arb (formulas written out again, see the module docstring)
# --------------------------------------------------------------------------------------
def _q(v: Fraction):
    from flint import arb, fmpq

    return arb(fmpq(v.numerator, v.denominator))


def _hex(v: Any, what: str) -> float:
    """A binary64 number written exactly as a hex string ("0x1.8p+3", float.hex)."""
    if not isinstance(v, str):
        raise _Refused(f"{what}: expected an exact hex float string such as \"0x1.8p+3\", got {v!r}")
    try:
        f = float.fromhex(v)
    except ValueError:
        raise _Refused(f"{what}: {v!r} is not a hex float") from None
    if not math.isfinite(f):
        raise _Refused(f"{what}: {v!r} is not finite")
    return f


def _hex_box(obj: Any, what: str) -> tuple[tuple[float, float], ...]:
    """[[xlo, xhi], [ylo, yhi], [philo, phihi]] as hex strings, lo <= hi."""
    return _box(obj, what, number=_hex)

"""Reading the fields of a certificate claim, refusing anything not in the documented format.

The file format (``"intervalkin-certificate"``, version 1) is specified in
:mod:`intervalkin.certify.writer`; this module is the checker's own reading of
it, with the standard library only.  Numbers enter exactly:

* joint vectors are strings, either a finite decimal ``"14.98"`` or a rational
  ``"1498/100"``, read as :class:`fractions.Fraction` (JSON numbers are refused:
  they would be binary64 approximations of the decimals the user gave);
* box bounds are JSON numbers, i.e. the binary64 values Python's ``repr`` wrote;
  trajectory segments use hex float strings (``float.hex``), which name one
  binary64 number exactly.

Every reader raises :class:`Refused` with a message naming the field: a claim
whose fields are wrong is refused, not crashed on.
"""

from __future__ import annotations

import decimal
import hashlib
import math
import re
from fractions import Fraction
from typing import Any

__all__ = ['FORMAT', 'VERSION', 'KINDS', 'INDEX', 'Refused', 'parse_exact',
           'sample_indices']

FORMAT = "intervalkin-certificate"
VERSION = 1
#: Claim files, in the order they are checked (``joint_join`` after the fold models it refers to, ``counts`` last:
#: it uses the others).
KINDS = ("dkp", "joint_cell", "aspect_distinct", "region_distinct", "box_labels", "trajectory", "aspect_connected",
         "joint_fold_model", "joint_join", "counts")
INDEX = "index.json"
#: Precisions (bits) accepted in a file.
PREC_RANGE = (53, 4096)
#: The aspect names of the files, and the sign of det A each stands for.
ASPECT_SIGN = {"WA1": 1, "WA2": -1}

#: A hex float as ``float.hex`` writes it: optional sign, then ``0x`` (or inf/nan, refused as not finite).
#: ``float.fromhex`` alone would also take "1.5", reading it as 0x1.5 = 1.3125.
_HEX_FLOAT = re.compile(r"[+-]?(0x[0-9a-f]+(\.[0-9a-f]*)?(p[+-]?[0-9]+)?|inf|nan)", re.IGNORECASE)

#: A box [[xlo, xhi], [ylo, yhi], [philo, phihi]] as read: three (lo, hi) float pairs.
Box = tuple[tuple[float, float], ...]


class Refused(Exception):
    """A claim that could not be re-proved (the message says which step failed)."""


def parse_exact(text: Any, what: str = "value") -> Fraction:
    """An exact rational from a string "p/q" or a decimal "14.98" (JSON numbers are refused)."""
    if not isinstance(text, str):
        raise Refused(f"{what}: expected an exact string such as \"1498/100\" or \"14.98\", got {text!r}")
    try:
        if "/" in text:
            return Fraction(text.strip())
        d = decimal.Decimal(text.strip())
    except (ValueError, ZeroDivisionError, decimal.InvalidOperation):
        raise Refused(f"{what}: {text!r} is not an exact rational") from None
    if not d.is_finite():
        raise Refused(f"{what}: {text!r} is not finite")
    return Fraction(d)


def read_rho(claim: dict, key: str = "rho") -> tuple[Fraction, Fraction, Fraction]:
    """The joint vector ``claim[key]``: three exact strings, each positive."""
    v = get(claim, key)
    if not isinstance(v, list) or len(v) != 3:
        raise Refused(f"{key}: expected three exact strings, got {v!r}")
    r = tuple(parse_exact(t, f"{key}[{i}]") for i, t in enumerate(v))
    if any(x <= 0 for x in r):
        raise Refused(f"{key}: leg lengths must be positive")
    return r  # type: ignore[return-value]


def read_aspect(claim: dict) -> tuple[str, int]:
    """``claim["aspect"]`` ("WA1" or "WA2") and its det A sign."""
    aspect = get(claim, "aspect")
    if aspect not in ASPECT_SIGN:
        raise Refused(f"aspect must be WA1 or WA2, got {aspect!r}")
    return aspect, ASPECT_SIGN[aspect]


def read_float(v: Any, what: str) -> float:
    """A finite JSON number."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise Refused(f"{what}: expected a number, got {v!r}")
    f = float(v)
    if not math.isfinite(f):
        raise Refused(f"{what}: {v!r} is not finite")
    return f


def read_hex(v: Any, what: str) -> float:
    """A binary64 number written exactly as a hex string ("0x1.8p+3", float.hex)."""
    if not isinstance(v, str):
        raise Refused(f"{what}: expected an exact hex float string such as \"0x1.8p+3\", got {v!r}")
    if not _HEX_FLOAT.fullmatch(v):
        raise Refused(f"{what}: {v!r} is not a hex float (expected a sign, if any, then 0x)")
    try:
        f = float.fromhex(v)
    except OverflowError:
        raise Refused(f"{what}: {v!r} is not finite (beyond binary64)") from None
    if not math.isfinite(f):
        raise Refused(f"{what}: {v!r} is not finite")
    return f


def read_box(obj: Any, what: str = "box", number=read_float) -> Box:
    """[[xlo, xhi], [ylo, yhi], [philo, phihi]], each bound read by ``number``, lo <= hi."""
    if not isinstance(obj, list) or len(obj) != 3:
        raise Refused(f"{what}: expected [[xlo, xhi], [ylo, yhi], [philo, phihi]], got {obj!r}")
    out = []
    for j, pair in enumerate(obj):
        if not isinstance(pair, list) or len(pair) != 2:
            raise Refused(f"{what}[{j}]: expected [lo, hi], got {pair!r}")
        lo, hi = number(pair[0], f"{what}[{j}][0]"), number(pair[1], f"{what}[{j}][1]")
        if not lo <= hi:
            raise Refused(f"{what}[{j}]: empty interval [{lo!r}, {hi!r}]")
        out.append((lo, hi))
    return tuple(out)


def read_hex_box(obj: Any, what: str) -> Box:
    """A box whose bounds are hex float strings."""
    return read_box(obj, what, number=read_hex)


def read_int(v: Any, what: str, lo: int | None = None, hi: int | None = None) -> int:
    """An integer (not a bool) in [lo, hi] (either end optional)."""
    if isinstance(v, bool) or not isinstance(v, int):
        raise Refused(f"{what}: expected an integer, got {v!r}")
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise Refused(f"{what}: {v} is outside [{lo}, {hi}]")
    return v


def get(claim: dict, key: str) -> Any:
    """``claim[key]``, refused when missing."""
    if key not in claim:
        raise Refused(f"missing field {key!r}")
    return claim[key]


def inside(inner: Box, outer: Box) -> bool:
    """Whether box ``inner`` lies in box ``outer`` (closed, bound by bound)."""
    return all(olo <= lo and hi <= ohi for (lo, hi), (olo, ohi) in zip(inner, outer))


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

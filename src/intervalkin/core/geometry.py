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

import decimal
import math
import tomllib
from dataclasses import dataclass
from fractions import Fraction
from importlib import resources
from pathlib import Path
from typing import Any

from flint import arb, ctx, fmpq

from intervalkin.core.errors import GeometryError
from intervalkin.core.exact import arb_to_bounds, fraction_bounds

__all__ = ['Surd', 'Geometry', 'parse_geometry', 'load_geometry', 'default_geometry']


@dataclass(frozen=True)
class Surd:
    """The exact real number ``coef * sqrt(radicand)`` (radicand >= 0)."""

    coef: Fraction
    radicand: Fraction = Fraction(1)

    def arb(self):
        """An arb ball containing the number, at the current flint precision."""
        c = arb(fmpq(self.coef.numerator, self.coef.denominator))
        if self.radicand == 1:
            return c
        r = arb(fmpq(self.radicand.numerator, self.radicand.denominator))
        return c * r.sqrt()

    def enclosure(self) -> tuple[float, float]:
        """Floats (lo, hi) with lo <= value <= hi (outward rounded via arb at 128 bits)."""
        with ctx.workprec(128):
            return arb_to_bounds(self.arb())

    def square(self) -> Fraction:
        return self.coef * self.coef * self.radicand

    def __float__(self) -> float:
        return float(self.coef) * math.sqrt(float(self.radicand))


@dataclass(frozen=True)
class Geometry:
    """A planar 3-RPR manipulator, exactly.

    Attributes
    ----------
    name : str
    base : three (x, y) pairs of Fractions, the base points A1, A2, A3.
    l2 : Surd, the platform side |B1B2| (p2 = (l2, 0) in the platform frame).
    p3x, p3y : Surd, B3 in the platform frame; p3y > 0 means B3 lies to the left
        of the directed line B1 -> B2.
    rho_min, rho_max : three Fractions each, the prismatic joint limits.
    decimals : the input numbers as the exact decimal strings that were read,
        keyed by their TOML path (``"base.a2[0]"``), for certificates.
    """

    name: str
    base: tuple[tuple[Fraction, Fraction], tuple[Fraction, Fraction], tuple[Fraction, Fraction]]
    l2: Surd
    p3x: Surd
    p3y: Surd
    rho_min: tuple[Fraction, Fraction, Fraction]
    rho_max: tuple[Fraction, Fraction, Fraction]
    decimals: tuple[tuple[str, str], ...] = ()

    # --- derived exact quantities -------------------------------------------------
    def platform_point(self, i: int) -> tuple[Surd, Surd]:
        """p_i (i = 0, 1, 2) in the platform frame."""
        zero = Surd(Fraction(0))
        return ((zero, zero), (self.l2, zero), (self.p3x, self.p3y))[i]

    def platform_radius_sq(self, i: int) -> Fraction:
        """|p_i|^2, always rational."""
        px, py = self.platform_point(i)
        return px.square() + py.square()

    @property
    def workspace_domain(self) -> tuple[tuple[float, float], tuple[float, float], tuple[float, float]]:
        """The box [A1x -+ rho_max] x [A1y -+ rho_max] x [-pi, pi] that holds W.

        B1 = (x, y) satisfies |B1 - A1| <= rho_max_1, so this box contains the
        whole workspace.  The bounds are floats: A1 and rho_max are rounded
        outward; the phi bounds are the floats nearest to -pi and pi, and the
        phi axis is periodic, so nothing is lost at the seam.
        """
        a1x, a1y = self.base[0]
        r = self.rho_max[0]
        lo_x, hi_x = fraction_bounds(a1x - r)[0], fraction_bounds(a1x + r)[1]
        lo_y, hi_y = fraction_bounds(a1y - r)[0], fraction_bounds(a1y + r)[1]
        return ((lo_x, hi_x), (lo_y, hi_y), (-math.pi, math.pi))

    def to_toml(self) -> str:
        """The geometry as TOML with the exact decimals that were read."""
        d = dict(self.decimals)
        lines = [f'name = "{self.name}"', "", "[base]"]
        for i in range(3):
            lines.append(f"a{i + 1} = [{d[f'base.a{i + 1}[0]']}, {d[f'base.a{i + 1}[1]']}]")
        lines += ["", "[platform]"]
        if "platform.b1b2" in d:
            lines += [
                f"b1b2 = {d['platform.b1b2']}",
                f"b2b3 = {d['platform.b2b3']}",
                f"b3b1 = {d['platform.b3b1']}",
                f'b3_side = "{d["platform.b3_side"]}"',
            ]
        else:
            for i in range(3):
                lines.append(f"b{i + 1} = [{d[f'platform.b{i + 1}[0]']}, {d[f'platform.b{i + 1}[1]']}]")
        lines += ["", "[limits]"]
        for key in ("rho_min", "rho_max"):
            if f"limits.{key}" in d:
                lines.append(f"{key} = {d[f'limits.{key}']}")
            else:
                lines.append(f"{key} = [{', '.join(d[f'limits.{key}[{i}]'] for i in range(3))}]")
        return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------------------
# Parsing and validation
# --------------------------------------------------------------------------------------
_TOP_KEYS = {"name", "base", "platform", "limits"}
_BASE_KEYS = {"a1", "a2", "a3"}
_SIDE_KEYS = {"b1b2", "b2b3", "b3b1", "b3_side"}
_COORD_KEYS = {"b1", "b2", "b3"}
_LIMIT_KEYS = {"rho_min", "rho_max"}


def _number(value: Any, field: str, decimals: dict[str, str]) -> Fraction:
    if isinstance(value, bool) or not isinstance(value, (int, decimal.Decimal)):
        raise GeometryError(f"{field}: expected a number, got {value!r}")
    if isinstance(value, decimal.Decimal) and not value.is_finite():
        raise GeometryError(f"{field}: expected a finite number, got {value}")
    decimals[field] = str(value)
    return Fraction(value)


def _point(value: Any, field: str, decimals: dict[str, str]) -> tuple[Fraction, Fraction]:
    if not isinstance(value, list) or len(value) != 2:
        raise GeometryError(f"{field}: expected a pair [x, y], got {value!r}")
    return (_number(value[0], f"{field}[0]", decimals), _number(value[1], f"{field}[1]", decimals))


def _table(doc: dict, key: str, allowed: set[str]) -> dict:
    if key not in doc:
        raise GeometryError(f"[{key}]: missing table")
    table = doc[key]
    if not isinstance(table, dict):
        raise GeometryError(f"{key}: expected a table, got {table!r}")
    unknown = set(table) - allowed
    if unknown:
        raise GeometryError(f"{key}.{sorted(unknown)[0]}: unknown key (allowed: {', '.join(sorted(allowed))})")
    return table


def _require(table: dict, keys, prefix: str) -> None:
    for k in keys:
        if k not in table:
            raise GeometryError(f"{prefix}.{k}: missing key")


def _limits(value: Any, field: str, decimals: dict[str, str]) -> tuple[Fraction, Fraction, Fraction]:
    if isinstance(value, list):
        if len(value) != 3:
            raise GeometryError(f"{field}: expected one number or a list of three, got {len(value)} values")
        return tuple(_number(v, f"{field}[{i}]", decimals) for i, v in enumerate(value))  # type: ignore[return-value]
    v = _number(value, field, decimals)
    return (v, v, v)


def parse_geometry(doc: dict, source: str = "geometry") -> Geometry:
    """Build a validated :class:`Geometry` from a TOML document read with Decimal floats.

    Raises :class:`GeometryError` with a one-line message naming the field, what is
    allowed and what came in.
    """
    unknown = set(doc) - _TOP_KEYS
    if unknown:
        raise GeometryError(f"{sorted(unknown)[0]}: unknown key (allowed: {', '.join(sorted(_TOP_KEYS))})")
    decimals: dict[str, str] = {}
    name = doc.get("name", Path(source).stem)
    if not isinstance(name, str) or not name.strip():
        raise GeometryError(f"name: expected a non-empty string, got {name!r}")

    base_t = _table(doc, "base", _BASE_KEYS)
    _require(base_t, sorted(_BASE_KEYS), "base")
    base = tuple(_point(base_t[f"a{i}"], f"base.a{i}", decimals) for i in (1, 2, 3))
    for i in range(3):
        for j in range(i + 1, 3):
            if base[i] == base[j]:
                raise GeometryError(f"base.a{i + 1}, base.a{j + 1}: base points must be distinct, both are {tuple(map(str, base[i]))}")

    plat_t = _table(doc, "platform", _SIDE_KEYS | _COORD_KEYS)
    has_sides = bool(set(plat_t) & _SIDE_KEYS)
    has_coords = bool(set(plat_t) & _COORD_KEYS)
    if has_sides and has_coords:
        raise GeometryError("platform: give either side lengths (b1b2, b2b3, b3b1, b3_side) or coordinates (b1, b2, b3), not both")
    if has_sides:
        _require(plat_t, ("b1b2", "b2b3", "b3b1", "b3_side"), "platform")
        l12 = _number(plat_t["b1b2"], "platform.b1b2", decimals)
        l23 = _number(plat_t["b2b3"], "platform.b2b3", decimals)
        l31 = _number(plat_t["b3b1"], "platform.b3b1", decimals)
        side = plat_t["b3_side"]
        if side not in ("left", "right"):
            raise GeometryError(f"platform.b3_side: expected \"left\" or \"right\", got {side!r}")
        decimals["platform.b3_side"] = side
        for fld, v in (("b1b2", l12), ("b2b3", l23), ("b3b1", l31)):
            if v <= 0:
                raise GeometryError(f"platform.{fld}: expected a positive length, got {v}")
        if not (l12 < l23 + l31 and l23 < l12 + l31 and l31 < l12 + l23):
            raise GeometryError(
                f"platform: sides {decimals['platform.b1b2']}, {decimals['platform.b2b3']}, "
                f"{decimals['platform.b3b1']} violate the strict triangle inequality (degenerate platform)"
            )
        p3x = (l12 * l12 + l31 * l31 - l23 * l23) / (2 * l12)
        sign = 1 if side == "left" else -1
        l2 = Surd(l12)
        s3x = Surd(p3x)
        s3y = Surd(Fraction(sign), l31 * l31 - p3x * p3x)
    elif has_coords:
        _require(plat_t, ("b1", "b2", "b3"), "platform")
        b1, b2, b3 = (_point(plat_t[f"b{i}"], f"platform.b{i}", decimals) for i in (1, 2, 3))
        ex, ey = b2[0] - b1[0], b2[1] - b1[1]
        fx, fy = b3[0] - b1[0], b3[1] - b1[1]
        s = ex * ex + ey * ey
        cross = ex * fy - ey * fx
        if s == 0 or cross == 0:
            raise GeometryError("platform: b1, b2, b3 are collinear or coincident (degenerate platform)")
        # |e| = sqrt(s); p3 = (e.f, e x f) / |e| = (e.f / s, e x f / s) * sqrt(s)
        l2 = Surd(Fraction(1), s)
        s3x = Surd((ex * fx + ey * fy) / s, s)
        s3y = Surd(cross / s, s)
    else:
        raise GeometryError("platform: expected side lengths (b1b2, b2b3, b3b1, b3_side) or coordinates (b1, b2, b3)")

    lim_t = _table(doc, "limits", _LIMIT_KEYS)
    _require(lim_t, ("rho_min", "rho_max"), "limits")
    rmin = _limits(lim_t["rho_min"], "limits.rho_min", decimals)
    rmax = _limits(lim_t["rho_max"], "limits.rho_max", decimals)
    for i in range(3):
        if rmin[i] <= 0:
            raise GeometryError(f"limits.rho_min: leg {i + 1} must be > 0, got {rmin[i]}")
        if rmin[i] >= rmax[i]:
            raise GeometryError(f"limits: leg {i + 1} needs rho_min < rho_max, got {float(rmin[i])} >= {float(rmax[i])}")
    return Geometry(
        name=name.strip(),
        base=base,  # type: ignore[arg-type]
        l2=l2,
        p3x=s3x,
        p3y=s3y,
        rho_min=rmin,
        rho_max=rmax,
        decimals=tuple(sorted(decimals.items())),
    )


def read_toml(path: str | Path, what: str, error: type[Exception] = GeometryError) -> dict:
    """The TOML document of a file, numbers as exact decimals; ``error`` with one line naming ``what`` and the problem."""
    p = Path(path)
    try:
        with p.open("rb") as f:
            return tomllib.load(f, parse_float=decimal.Decimal)
    except FileNotFoundError:
        raise error(f"{what} {str(p)!r}: not found") from None
    except IsADirectoryError:
        raise error(f"{what} {str(p)!r}: is a directory") from None
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{what} {str(p)!r}: malformed TOML ({exc})") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise error(f"{what} {str(p)!r}: cannot read ({exc})") from None


def load_geometry(path: str | Path) -> Geometry:
    """Read and validate a geometry TOML file (numbers read as exact decimals)."""
    return parse_geometry(read_toml(path, "geometry file"), source=str(Path(path)))


def default_geometry() -> Geometry:
    """The paper's manipulator (Wenger & Chablat 1997, section 2.1), shipped as package data."""
    text = resources.files("intervalkin").joinpath("data/wenger_chablat_1997.toml").read_text()
    return parse_geometry(tomllib.loads(text, parse_float=decimal.Decimal), source="wenger_chablat_1997")

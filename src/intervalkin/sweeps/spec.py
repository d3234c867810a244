"""The sweep file: a base geometry, the parameters to vary, the analysis settings; and its designs.

A sweep file is TOML whose numbers are read as exact decimals, like a geometry file::

    name = "platform scale x upper joint limit"
    geometry = "paper"                 # "paper" (the default), or a geometry TOML file (relative to
                                       # this file), or an inline [geometry] table in the same schema
    combine = "product"                # "product" (every combination, the default) or "zip"

    [analysis]
    depth = 5                          # depth of the regions paving, 3..9
    # refine_to = 6                    # optional, as `intervalkin analyze --refine-to`

    [vary]                             # parameter = a list of numbers, or a range
    "platform.scale" = { start = 0.8, stop = 1.2, step = 0.1 }   # stop included when reached
    "limits.rho_max" = [28, 32, 36]

    [best]
    by = "volume_largest_uniqueness_domain"   # any numeric column of the table
    order = "max"                             # or "min"

A parameter is the TOML path of a number of the geometry schema (``base.a2[0]``,
``platform.b1b2``, ``platform.b3[1]``, ``limits.rho_max``, ``limits.rho_min[2]``), or one of
two scales applied to the base geometry: ``platform.scale`` (every platform length or
coordinate) and ``base.scale`` (every base coordinate).  Each design is the base geometry
with its values put in, validated as a geometry file is: a design that is not a manipulator
(a flat platform, rho_min >= rho_max) is reported as degenerate, with the geometry's own
one-line error, and is not analysed.  The file itself is checked before any work, and a
bad one raises :class:`SweepFileError` naming the field, what is allowed and what came in.

Each design's result is keyed by :func:`design_key`: a SHA-256 of its exact geometry (the
decimals, as fractions, not the name), the analysis settings and the intervalkin version.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
from dataclasses import dataclass
from decimal import Decimal
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

import tomllib

from intervalkin.core.errors import GeometryError, InputError
from intervalkin.core.geometry import Geometry, parse_geometry, read_toml
from intervalkin.core.version import __version__

__all__ = ["SweepFileError", "Settings", "Design", "SweepSpec", "CRITERIA_DEFAULT", "MAX_DESIGNS",
           "parse_sweep", "load_sweep", "design_key"]

#: The column the best designs are chosen by unless the file says otherwise.
CRITERIA_DEFAULT = "volume_largest_uniqueness_domain"
#: A sweep larger than this is refused (a typo in a range should not queue a million tasks).
MAX_DESIGNS = 100_000
_TOP_KEYS = {"name", "geometry", "combine", "analysis", "vary", "best"}
_SCALES = {"platform.scale": "platform", "base.scale": "base"}


class SweepFileError(InputError):
    """A sweep file is malformed: the message names the field, what is allowed and what came in."""


@dataclass(frozen=True)
class Settings:
    """The analysis settings of every design: :func:`intervalkin.analyse` arguments."""

    depth: int
    refine_to: int | None = None

    def to_json(self) -> dict:
        return {"depth": self.depth, "refine_to": self.refine_to}


@dataclass(frozen=True)
class Design:
    """One design of a sweep: its parameter values, its geometry (or why there is none), its key.

    ``values`` are the exact decimal strings put into the base geometry, in the order of
    :attr:`SweepSpec.parameters`.  ``geometry_toml`` is the design's geometry as TOML
    (exact decimals) when it is a manipulator; otherwise it is "" and ``degenerate`` holds the
    geometry's one-line error.
    """

    index: int
    values: tuple[str, ...]
    geometry_toml: str
    key: str
    degenerate: str = ""


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep file: its name, parameters, settings, criterion and expanded designs."""

    name: str
    parameters: tuple[str, ...]
    settings: Settings
    best_by: str
    best_order: str
    designs: tuple[Design, ...]
    source: str = ""


def _decimal(value: Any, field: str) -> Decimal:
    if isinstance(value, bool) or not isinstance(value, (int, Decimal)):
        raise SweepFileError(f"{field}: expected a number, got {value!r}")
    if isinstance(value, Decimal) and not value.is_finite():
        raise SweepFileError(f"{field}: expected a finite number, got {value}")
    return Decimal(value)


def _values(spec: Any, field: str) -> list[Decimal]:
    """A parameter's values: a non-empty list of numbers, or {start, stop, step} (stop included if reached)."""
    if isinstance(spec, list):
        if not spec:
            raise SweepFileError(f"{field}: expected at least one value, got an empty list")
        return [_decimal(v, f"{field}[{i}]") for i, v in enumerate(spec)]
    if isinstance(spec, dict):
        extra = set(spec) - {"start", "stop", "step"}
        if extra or set(spec) != {"start", "stop", "step"}:
            missing = sorted({"start", "stop", "step"} - set(spec))
            what = f"unknown key {sorted(extra)[0]!r}" if extra else f"missing {missing[0]!r}"
            raise SweepFileError(f"{field}: a range is {{start, stop, step}}; {what}")
        start, stop, step = (_decimal(spec[k], f"{field}.{k}") for k in ("start", "stop", "step"))
        if step <= 0 or stop < start:
            raise SweepFileError(f"{field}: expected start <= stop and step > 0, "
                                 f"got start {start}, stop {stop}, step {step}")
        n = int((stop - start) / step) + 1
        if n > MAX_DESIGNS:
            raise SweepFileError(f"{field}: the range has {n} values, more than {MAX_DESIGNS}")
        return [start + i * step for i in range(n)]
    raise SweepFileError(f"{field}: expected a list of numbers or a range {{start, stop, step}}, got {spec!r}")


def _paper_doc() -> dict:
    text = resources.files("intervalkin").joinpath("data/wenger_chablat_1997.toml").read_text()
    return tomllib.loads(text, parse_float=Decimal)


def _base_doc(doc: dict, folder: Path) -> dict:
    """The base geometry as a TOML document (Decimal numbers), checked to be a manipulator."""
    given = doc.get("geometry", "paper")
    if isinstance(given, dict):
        base, where = given, "geometry"
    elif given == "paper":
        base, where = _paper_doc(), "geometry"
    elif isinstance(given, str):
        path = folder / given
        try:
            with path.open("rb") as f:
                base = tomllib.load(f, parse_float=Decimal)
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
            raise SweepFileError(f"geometry: cannot read the geometry file {str(path)!r} ({exc})") from None
        where = f"geometry file {str(path)!r}"
    else:
        raise SweepFileError(f"geometry: expected \"paper\", a file name or a table, got {given!r}")
    try:
        parse_geometry(copy.deepcopy(base), source="base")
    except GeometryError as exc:
        raise SweepFileError(f"{where}: {exc}") from None
    return base


def _path_parts(name: str) -> tuple[str, str, int | None]:
    """'limits.rho_max[2]' -> ('limits', 'rho_max', 2)."""
    table, _, rest = name.partition(".")
    key, index = rest, None
    if rest.endswith("]") and "[" in rest:
        key, _, idx = rest[:-1].partition("[")
        index = int(idx) if idx.isdigit() else -1
    return table, key, index


def _check_parameter(base: dict, name: str) -> None:
    """Refuse a parameter that is not a number of the base geometry (or one of the two scales)."""
    if name in _SCALES:
        return
    table, key, index = _path_parts(name)
    allowed = "platform.scale, base.scale, or the path of a number of the geometry (e.g. limits.rho_max, base.a2[0])"
    t = base.get(table)
    if not isinstance(t, dict) or key not in t:
        raise SweepFileError(f"vary.{name!r}: not a parameter of the base geometry (allowed: {allowed})")
    value = t[key]
    if index is None:
        ok = not isinstance(value, (str, bool)) and (not isinstance(value, list) or table == "limits")
    elif table == "limits":
        ok = index in (0, 1, 2)
    else:
        ok = isinstance(value, list) and index in range(len(value))
    if not ok:
        raise SweepFileError(f"vary.{name!r}: not a number of the base geometry (allowed: {allowed})")


def _put(doc: dict, name: str, value: Decimal) -> None:
    """Put one parameter value into a geometry document (in place)."""
    if name in _SCALES:
        t = doc[_SCALES[name]]
        for k, v in list(t.items()):
            if isinstance(v, list):
                t[k] = [x * value for x in v]
            elif not isinstance(v, (str, bool)):
                t[k] = v * value
        return
    table, key, index = _path_parts(name)
    if index is None:
        doc[table][key] = value
        return
    current = doc[table][key]
    if not isinstance(current, list):  # one number for all legs: make it three, then set one
        current = [current] * 3
    current = list(current)
    current[index] = value
    doc[table][key] = current


def _canonical(g: Geometry) -> dict:
    """The exact content of a geometry, independent of its name and of how its numbers were written."""
    def surd(s):
        return [str(s.coef), str(s.radicand)]
    return {"base": [[str(c) for c in p] for p in g.base], "l2": surd(g.l2), "p3x": surd(g.p3x),
            "p3y": surd(g.p3y), "rho_min": [str(v) for v in g.rho_min], "rho_max": [str(v) for v in g.rho_max]}


def design_key(geometry: Geometry, settings: Settings) -> str:
    """SHA-256 (hex) of the exact geometry, the settings and the intervalkin version: the cache key."""
    doc = {"geometry": _canonical(geometry), "settings": settings.to_json(), "intervalkin": __version__}
    return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()


def _table(doc: dict, name: str, allowed: tuple[str, ...]) -> dict:
    """The optional table ``name`` of the sweep file, refused when it is not a table or has another key."""
    table = doc.get(name, {})
    if not isinstance(table, dict):
        raise SweepFileError(f"{name}: expected a table, got {table!r}")
    extra = set(table) - set(allowed)
    if extra:
        raise SweepFileError(f"{name}.{sorted(extra)[0]}: unknown key (allowed: {', '.join(allowed)})")
    return table


def _settings(doc: dict) -> Settings:
    from intervalkin.pipeline import MAX_CHAIN_DEPTH  # light: the pipeline module is loaded by every run anyway

    table = _table(doc, "analysis", ("depth", "refine_to"))
    depth = table.get("depth", 5)
    if isinstance(depth, bool) or not isinstance(depth, int) or not 3 <= depth <= MAX_CHAIN_DEPTH:
        raise SweepFileError(f"analysis.depth: expected an integer in 3..{MAX_CHAIN_DEPTH}, got {depth!r}")
    refine = table.get("refine_to")
    if refine is not None and (isinstance(refine, bool) or not isinstance(refine, int)
                               or not depth <= refine <= MAX_CHAIN_DEPTH):
        raise SweepFileError(f"analysis.refine_to: expected an integer in {depth}..{MAX_CHAIN_DEPTH}, got {refine!r}")
    return Settings(depth, refine)


def _best(doc: dict) -> tuple[str, str]:
    from intervalkin.sweeps.table import NUMERIC_COLUMNS

    table = _table(doc, "best", ("by", "order"))
    by, order = table.get("by", CRITERIA_DEFAULT), table.get("order", "max")
    if by not in NUMERIC_COLUMNS:
        raise SweepFileError(f"best.by: expected a numeric column of the table "
                             f"({', '.join(NUMERIC_COLUMNS)}), got {by!r}")
    if order not in ("max", "min"):
        raise SweepFileError(f"best.order: expected \"max\" or \"min\", got {order!r}")
    return by, order


def parse_sweep(doc: Mapping, source: str = "sweep", folder: str | Path = ".") -> SweepSpec:
    """Validate a sweep document (read with Decimal floats) and expand its designs.

    Raises :class:`SweepFileError` (one line, naming the field) on a malformed file; designs
    that are not manipulators come back as degenerate :class:`Design` objects.
    """
    doc = dict(doc)
    unknown = set(doc) - _TOP_KEYS
    if unknown:
        raise SweepFileError(f"{sorted(unknown)[0]}: unknown key (allowed: {', '.join(sorted(_TOP_KEYS))})")
    name = doc.get("name", Path(source).stem)
    if not isinstance(name, str) or not name.strip():
        raise SweepFileError(f"name: expected a non-empty string, got {name!r}")
    base = _base_doc(doc, Path(folder))
    settings = _settings(doc)
    best_by, best_order = _best(doc)
    vary = doc.get("vary")
    if not isinstance(vary, dict) or not vary:
        raise SweepFileError(f"[vary]: expected a table of at least one parameter, got {vary!r}")
    for p in vary:
        _check_parameter(base, p)
    params = tuple(vary)
    values = [_values(vary[p], f"vary.{p!r}") for p in params]
    combine = doc.get("combine", "product")
    if combine == "product":
        n = 1
        for v in values:
            n *= len(v)
        if n > MAX_DESIGNS:
            raise SweepFileError(f"[vary]: the product has {n} designs, more than {MAX_DESIGNS}")
        combos = list(itertools.product(*values))
    elif combine == "zip":
        if len({len(v) for v in values}) != 1:
            raise SweepFileError("combine = \"zip\": every parameter needs as many values, got "
                                 + ", ".join(f"{p} {len(v)}" for p, v in zip(params, values)))
        combos = list(zip(*values))
    else:
        raise SweepFileError(f"combine: expected \"product\" or \"zip\", got {combine!r}")
    designs = []
    for i, combo in enumerate(combos):
        g_doc = copy.deepcopy(base)
        g_doc["name"] = name.strip()
        for p, v in zip(params, combo):
            _put(g_doc, p, v)
        text = tuple(str(v) for v in combo)
        try:
            g = parse_geometry(g_doc, source=name)
        except GeometryError as exc:
            designs.append(Design(i, text, "", "", degenerate=str(exc)))
            continue
        designs.append(Design(i, text, g.to_toml(), design_key(g, settings)))
    return SweepSpec(name.strip(), params, settings, best_by, best_order, tuple(designs), source)


def load_sweep(path: str | Path) -> SweepSpec:
    """Read and validate a sweep file; a geometry file it names is read relative to it."""
    p = Path(path)
    doc = read_toml(p, "sweep file", SweepFileError)
    return parse_sweep(doc, source=str(p), folder=p.parent)

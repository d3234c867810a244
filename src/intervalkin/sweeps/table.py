"""The results table of a sweep: one row per design, written as CSV and Parquet.

Columns, in order (``COLUMNS``):

* ``design`` (its index in the sweep file's order), ``key`` (the content hash of its geometry and
  settings), then one column per swept parameter, named by its path (``platform.scale``), holding
  the value as a float (the exact decimal is in the design's cached result);
* ``status``: ``ok``, ``degenerate`` (the design is not a manipulator: not analysed) or
  ``failed`` (the analysis raised, or its worker died too often); ``error``: why, else "";
* for each of ``aspects``, ``joint_cells``, ``basic_regions``, ``uniqueness_domains``:
  ``<name>_found``, ``<name>_lower`` (certified), ``<name>_upper`` (certified; empty when none is
  proved) and ``<name>_exact``, copied from the analysis's :class:`~intervalkin.core.status.Count`;
* volumes in (x, y, phi) units (phi in radians), sums of box volumes: ``volume_W``,
  ``volume_WA1``, ``volume_WA2`` (boxes certified inside W, and inside W with det A > 0, < 0),
  ``volume_largest_uniqueness_domain`` (boxes certified in the largest domain found),
  ``volume_undecided`` (boxes of W left undecided);
* ``seconds`` (the analysis, on its worker), ``memory_mb`` (peak resident memory of the worker
  process during the analysis), ``cached`` (true when this run read the result from the cache).

Cells of designs that were not analysed are empty (None).
"""

from __future__ import annotations

import csv
import io
import math
from typing import Any, Iterable, Mapping, Sequence

__all__ = ["COUNT_NAMES", "VOLUME_COLUMNS", "NUMERIC_COLUMNS", "columns", "csv_bytes", "parquet_bytes",
           "arrow_table", "best_rows"]

#: The counts of every analysed design, each with found / lower / upper / exact.
COUNT_NAMES = ("aspects", "joint_cells", "basic_regions", "uniqueness_domains")
VOLUME_COLUMNS = ("volume_W", "volume_WA1", "volume_WA2", "volume_largest_uniqueness_domain", "volume_undecided")
_COUNT_COLUMNS = tuple(f"{n}_{part}" for n in COUNT_NAMES for part in ("found", "lower", "upper", "exact"))
#: Columns a best design can be chosen by.
NUMERIC_COLUMNS = (*(f"{n}_{part}" for n in COUNT_NAMES for part in ("found", "lower")), *VOLUME_COLUMNS,
                   "seconds", "memory_mb")
_TYPES = {**{c: "int" for c in _COUNT_COLUMNS}, **{f"{n}_exact": "bool" for n in COUNT_NAMES},
          **{c: "float" for c in (*VOLUME_COLUMNS, "seconds", "memory_mb")},
          "design": "int", "key": "str", "status": "str", "error": "str", "cached": "bool"}


def columns(parameters: Sequence[str]) -> tuple[str, ...]:
    """The table's columns for a sweep over ``parameters``."""
    return ("design", "key", *parameters, "status", "error", *_COUNT_COLUMNS, *VOLUME_COLUMNS,
            "seconds", "memory_mb", "cached")


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def csv_bytes(rows: Iterable[Mapping], parameters: Sequence[str]) -> bytes:
    """The table as CSV (a header line, then one line per row; None is an empty field)."""
    cols = columns(parameters)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(cols)
    for r in rows:
        w.writerow([_cell(r.get(c)) for c in cols])
    return buf.getvalue().encode()


def arrow_table(rows: Sequence[Mapping], parameters: Sequence[str]):
    """The table as a ``pyarrow.Table`` (typed columns; None is null)."""
    import pyarrow as pa

    kinds = {"int": pa.int64(), "float": pa.float64(), "bool": pa.bool_(), "str": pa.string()}
    fields = [pa.field(c, kinds[_TYPES.get(c, "float")]) for c in columns(parameters)]
    data = {f.name: [r.get(f.name) for r in rows] for f in fields}
    return pa.Table.from_pydict(data, schema=pa.schema(fields))


def parquet_bytes(rows: Sequence[Mapping], parameters: Sequence[str]) -> bytes:
    """The table as a Parquet file, as bytes (for an atomic write)."""
    import pyarrow.parquet as pq

    buf = io.BytesIO()
    pq.write_table(arrow_table(rows, parameters), buf)
    return buf.getvalue()


def best_rows(rows: Sequence[Mapping], by: str, order: str = "max", n: int = 3) -> list[Mapping]:
    """The ``n`` analysed designs best by column ``by`` (``order`` "max" or "min"); ties keep the file's order."""
    ok = [r for r in rows if r.get("status") == "ok" and r.get(by) is not None and not
          (isinstance(r[by], float) and math.isnan(r[by]))]
    sign = -1 if order == "max" else 1
    return sorted(ok, key=lambda r: (sign * r[by], r["design"]))[:n]

"""A certificate folder re-checked from its files: :func:`verify_directory` and :class:`CheckResult`.

The folder holds ``index.json`` and the claim files it lists (schema in
:mod:`intervalkin.certify.writer`).  A folder that is missing, unreadable or not
in the format raises :class:`~intervalkin.core.errors.CertificateFormatError`:
that is not a failed claim, there is nothing to check.  Otherwise every claim
gets one :class:`CheckResult`.  Claims are checked file kind by file kind in the
order of :data:`~intervalkin.checker.parse.KINDS`, ``counts`` last, because a
count may only lean on claims verified before it.  Every file must carry the
index's geometry text, so that all claims are about one manipulator.
"""

from __future__ import annotations

import decimal
import json
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from intervalkin.checker.claims import (
    MALFORMED,
    check_count,
    malformed_message,
    run_check,
)
from intervalkin.checker.consistency import read_summary
from intervalkin.checker.parse import FORMAT, INDEX, KINDS, VERSION, Refused
from intervalkin.core.errors import CertificateFormatError, GeometryError
from intervalkin.core.geometry import Geometry, parse_geometry

__all__ = ['CheckResult', 'verify_directory']


@dataclass(frozen=True)
class CheckResult:
    """The checker's verdict on one claim.

    ``verified`` is True only when every step of the claim was re-proved;
    ``message`` says what was proved, or the first step that failed.
    """

    file: str
    claim: str
    kind: str
    verified: bool
    message: str

    def line(self) -> str:
        head = f"{self.file}#{self.claim} ({self.kind})"
        return f"verified: {head}: {self.message}" if self.verified else f"FAILED: {head} because {self.message}"


def _read_json(path: Path) -> dict:
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise CertificateFormatError(f"{path}: missing") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CertificateFormatError(f"{path}: cannot read ({exc})") from None
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise CertificateFormatError(f"{path}: not valid JSON ({exc})") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT or doc.get("version") != VERSION:
        raise CertificateFormatError(
            f"{path}: not an {FORMAT} file of version {VERSION} "
            f"(format {doc.get('format') if isinstance(doc, dict) else None!r}, "
            f"version {doc.get('version') if isinstance(doc, dict) else None!r})")
    return doc


def _geometry(text: Any) -> Geometry:
    if not isinstance(text, str):
        raise Refused("geometry_toml: expected the geometry as TOML text")
    try:
        return parse_geometry(tomllib.loads(text, parse_float=decimal.Decimal), source="certificate")
    except tomllib.TOMLDecodeError as exc:
        raise Refused(f"geometry_toml: malformed TOML ({exc})") from None
    except GeometryError as exc:
        raise Refused(f"geometry_toml: {exc}") from None


def verify_directory(path: str | Path, compare_summary: bool = True) -> list[CheckResult]:
    """Re-check every claim of a certificate folder; one :class:`CheckResult` per claim.

    Raises :class:`CertificateFormatError` when the folder, its ``index.json`` or
    a listed file is missing, unreadable or not in the format (a malformed
    folder is not a failed claim).  A claim whose fields are wrong, or whose
    evidence does not re-prove it, gives a result with ``verified`` False.

    When the folder is the ``certificates/`` of an output folder and
    ``compare_summary`` is True, each ``counts`` claim is also compared with the
    output's summary.json (:mod:`intervalkin.checker.consistency`): a printed
    count that contradicts the certificates fails that claim.
    """
    root = Path(path)
    summary = read_summary(root) if compare_summary else None
    if not root.is_dir():
        raise CertificateFormatError(f"{root}: not a certificate folder (no such directory)")
    index = _read_json(root / INDEX)
    if index.get("kind") != "index":
        raise CertificateFormatError(f"{root / INDEX}: kind must be \"index\", got {index.get('kind')!r}")
    files = index.get("files")
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        raise CertificateFormatError(f"{root / INDEX}: files: expected a list of file names")
    docs = {}
    for name in files:
        if "/" in name or "\\" in name or name in (".", ".."):
            raise CertificateFormatError(f"{root / INDEX}: file name {name!r} must be a plain name in the folder")
        doc = _read_json(root / name)
        if doc.get("kind") not in KINDS:
            raise CertificateFormatError(
                f"{root / name}: kind must be one of {', '.join(KINDS)}, got {doc.get('kind')!r}")
        claims = doc.get("claims")
        if not isinstance(claims, list) or not all(
                isinstance(c, dict) and isinstance(c.get("id"), str) for c in claims):
            raise CertificateFormatError(f"{root / name}: claims: expected a list of objects with a string id")
        ids = [c["id"] for c in claims]
        if len(set(ids)) != len(ids):
            raise CertificateFormatError(f"{root / name}: duplicate claim ids")
        docs[name] = doc

    if not any(doc["claims"] for doc in docs.values()):
        raise CertificateFormatError(f"{root}: the folder holds no claims")
    results: list[CheckResult] = []
    verified: dict[str, dict] = {}
    order = sorted(docs, key=lambda n: KINDS.index(docs[n]["kind"]))
    for name in order:
        doc = docs[name]
        kind = doc["kind"]
        file_error = None
        if doc.get("geometry_toml") != index.get("geometry_toml"):
            file_error = f"its geometry differs from the one in {INDEX}"
        elif kind != "counts":
            try:
                geometry = _geometry(doc.get("geometry_toml"))
            except Refused as exc:
                file_error = str(exc)
        for claim in doc["claims"]:
            cid = claim["id"]
            if file_error is not None:
                results.append(CheckResult(name, cid, kind, False, file_error))
                continue
            try:
                if kind == "counts":
                    msg, facts = check_count(claim, verified, summary)
                else:
                    msg, facts = run_check(geometry, kind, claim, doc.get("precision", 128), verified)
            except Refused as exc:
                results.append(CheckResult(name, cid, kind, False, str(exc)))
                continue
            except MALFORMED as exc:
                results.append(CheckResult(name, cid, kind, False, malformed_message(exc)))
                continue
            verified[f"{name}#{cid}"] = facts
            results.append(CheckResult(name, cid, kind, True, msg))
    return results

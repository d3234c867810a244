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
import json
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from intervalkin.checker.claims import _CHECKERS, _check_count
from intervalkin.checker.model import _Model
from intervalkin.checker.parse import (
    _PREC_RANGE,
    FORMAT,
    INDEX,
    KINDS,
    VERSION,
    CertificateFormatError,
    _int,
    _Refused,
)
from intervalkin.core.errors import GeometryError
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


# --------------------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------------------
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
        raise _Refused("geometry_toml: expected the geometry as TOML text")
    try:
        return parse_geometry(tomllib.loads(text, parse_float=decimal.Decimal), source="certificate")
    except tomllib.TOMLDecodeError as exc:
        raise _Refused(f"geometry_toml: malformed TOML ({exc})") from None
    except GeometryError as exc:
        raise _Refused(f"geometry_toml: {exc}") from None


def verify_directory(path: str | Path) -> list[CheckResult]:
    """Re-check every claim of a certificate folder; one :class:`CheckResult` per claim.

    Raises :class:`CertificateFormatError` when the folder, its ``index.json`` or
    a listed file is missing, unreadable or not in the format (a malformed
    folder is not a failed claim).  A claim whose fields are wrong, or whose
    evidence does not re-prove it, gives a result with ``verified`` False.
    """
    from flint import ctx

    root = Path(path)
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
        model = None
        file_error = None
        if doc.get("geometry_toml") != index.get("geometry_toml"):
            file_error = f"its geometry differs from the one in {INDEX}"
        elif kind != "counts":
            try:
                geometry = _geometry(doc.get("geometry_toml"))
            except _Refused as exc:
                file_error = str(exc)
        for claim in doc["claims"]:
            cid = claim["id"]
            if file_error is not None:
                results.append(CheckResult(name, cid, kind, False, file_error))
                continue
            try:
                if kind == "counts":
                    msg, facts = _check_count(claim, verified)
                else:
                    prec = _int(claim.get("precision", doc.get("precision", 128)), "precision", *_PREC_RANGE)
                    with ctx.workprec(prec):
                        model = _Model(geometry)
                        msg, facts = _CHECKERS[kind](model, claim, prec)
            except _Refused as exc:
                results.append(CheckResult(name, cid, kind, False, str(exc)))
                continue
            except (TypeError, KeyError, AttributeError, ValueError, OverflowError, ZeroDivisionError) as exc:
                results.append(CheckResult(name, cid, kind, False, f"malformed claim ({type(exc).__name__}: {exc})"))
                continue
            verified[f"{name}#{cid}"] = facts
            results.append(CheckResult(name, cid, kind, True, msg))
    return results

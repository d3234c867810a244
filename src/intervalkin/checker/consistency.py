"""Counts against their proofs: the numbers a run printed must not contradict its certificates.

A ``counts`` claim carries the library's number ``found`` beside its declared
``lower_bound``; the checker recomputes the lower bound the verified claims
prove (:func:`~intervalkin.checker.claims.count_bound`).  Whatever the run
printed, these must hold, and :func:`check_found` refuses the claim otherwise:

* ``lower_bound <= proved`` (the declared bound is backed; checked in ``claims``); the summary's basic-region
  bound may instead be ``barriers_at_least``, which the recheck's ``barrier_bound`` verdict backs;
* ``found >= proved``: a number of pieces found below a proved minimum is a
  contradiction (the pieces were miscounted, or a proof is wrong), never a
  result to print; likewise ``found <= proved upper bound`` when one is proved.

When the certificate folder sits in an output folder (``DIR/certificates``
beside ``DIR/summary.json``), the summary is what the user read, so
:func:`check_summary_block` compares each count block with the claim: the same
``count`` and ``lower_bound``, ``count >= lower_bound``, the claim's ``upper_bound``
(when one is given: not below them, and backed by what the certificates prove),
and ``exact`` only when the two bounds meet.
A summary of a run that did not complete (``"complete": false``) is not
compared, and the verdict says so.

Standard library only (the checker's trusted base).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from intervalkin.checker.parse import Refused

__all__ = ['SUMMARY', 'read_summary', 'check_found', 'check_summary_block']

#: The summary file of an output folder, beside its ``certificates/`` folder.
SUMMARY = "summary.json"


def read_summary(certificate_folder: str | Path) -> dict | None:
    """The summary.json of the output folder holding ``certificate_folder``, or None.

    Only a folder named ``certificates`` has one (``DIR/certificates`` and
    ``DIR/summary.json``).  A summary that exists but cannot be read as a JSON
    object is returned as ``{"unreadable": reason}``: every count claim then
    fails, since what the user was shown cannot be matched with the proofs.
    """
    root = Path(certificate_folder)
    if root.name != "certificates":
        return None
    path = root.parent / SUMMARY
    if not path.is_file():
        return None
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        return {"unreadable": f"{SUMMARY} cannot be read ({exc})"}
    if not isinstance(doc, dict):
        return {"unreadable": f"{SUMMARY} is not a JSON object"}
    return doc


def _count(v: Any, what: str) -> int:
    if isinstance(v, bool) or not isinstance(v, int) or v < 0:
        raise Refused(f"{what}: expected a non-negative integer, got {v!r}")
    return v


def check_found(name: str, found: Any, proved: int, proved_upper: int | None = None) -> None:
    """Refuse a claim whose library count ``found`` is below the lower bound ``proved`` by the verified claims,
    or above the upper bound ``proved_upper`` they prove (None: none proved)."""
    if found is None:
        return
    found = _count(found, "found")
    if found < proved:
        raise Refused(f"the library found {found} {name.replace('_', ' ')}, below the {proved} that the verified "
                      "claims prove: the count contradicts its certificates")
    if proved_upper is not None and found > proved_upper:
        raise Refused(f"the library found {found} {name.replace('_', ' ')}, above the {proved_upper} that the "
                      "verified claims prove: the count contradicts its certificates")


def check_summary_block(name: str, claim: dict, proved: int, summary: dict | None,
                        proved_upper: int | None = None) -> str:
    """Compare the ``name`` block of summary.json with its counts claim; the text to add to the verdict.

    Raises :class:`Refused` on a contradiction.  Returns "" when there is no
    summary to compare with.
    """
    if summary is None:
        return ""
    if "unreadable" in summary:
        raise Refused(str(summary["unreadable"]))
    if summary.get("complete") is False:
        return f"; {SUMMARY} not compared: its run did not complete"
    block = summary.get(name)
    if not isinstance(block, dict):
        raise Refused(f"{SUMMARY} has no {name!r} block to compare with the claim")
    count = _count(block.get("count"), f"{SUMMARY} {name}.count")
    lower = _count(block.get("lower_bound"), f"{SUMMARY} {name}.lower_bound")
    upper = block.get("upper_bound")
    if upper is not None:
        upper = _count(upper, f"{SUMMARY} {name}.upper_bound")
    exact = block.get("exact")
    problems = []
    if claim.get("found") is not None and count != claim.get("found"):
        problems.append(f"count {count} but the claim says {claim.get('found')} found")
    raised = _barrier_raise(name, block, claim, lower)
    if lower != claim.get("lower_bound") and not raised:
        problems.append(f"lower_bound {lower} but the claim declares {claim.get('lower_bound')}")
    if count < lower:
        problems.append(f"count {count} below its own lower_bound {lower}")
    if count < proved:
        problems.append(f"count {count} below the {proved} the verified claims prove")
    if upper is not None and (upper < count or upper < proved):
        problems.append(f"upper_bound {upper} below the count {count} or the proved {proved}")
    if upper != claim.get("upper_bound"):
        problems.append(f"upper_bound {upper} but the claim declares {claim.get('upper_bound')}")
    if upper is not None and (proved_upper is None or upper < proved_upper):
        problems.append(f"upper_bound {upper} is not what the certificates prove ({proved_upper})")
    if exact is not (upper is not None and upper == lower):
        problems.append(f"exact is {exact!r} with bounds {lower}..{upper}")
    if problems:
        raise Refused(f"{SUMMARY} contradicts the certificates on {name}: " + "; ".join(problems))
    bounds = f"lower bound {lower}" + ("" if upper is None else f", upper bound {upper}, exact" if exact
                                       else f", upper bound {upper}")
    if raised:
        bounds += (f": the claim's {claim.get('lower_bound')} raised by the count and pattern barriers, which the "
                   "barrier_bound verdict of the same verify run re-proves")
    return f"; {SUMMARY} agrees (count {count}, {bounds})"


def _barrier_raise(name: str, block: dict, claim: dict, lower: int) -> bool:
    """Whether the summary's basic-region ``lower_bound`` is the claim's raised by the separation barriers.

    Only one number may stand above the claim's: ``barriers_at_least``, beside ``counts_claim_lower`` equal to
    the claim's bound.  This checker does not re-prove it (the barriers are the numpy recheck's,
    ``recheck.separation_file.barrier_bound``); ``intervalkin verify`` runs that verdict whenever the summary
    states ``barriers_at_least``, so the bound holds exactly when both verdicts pass."""
    if name != "basic_regions" or block.get("barriers_at_least") is None:
        return False
    declared = claim.get("lower_bound")
    if block.get("counts_claim_lower") != declared or not isinstance(declared, int):
        raise Refused(f"{SUMMARY} basic_regions states barriers_at_least but its counts_claim_lower "
                      f"{block.get('counts_claim_lower')!r} is not the claim's lower_bound {declared!r}")
    return lower == block["barriers_at_least"] and lower > declared

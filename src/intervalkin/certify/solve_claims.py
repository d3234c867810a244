"""Claims about the solutions of joint vectors: ``dkp``, ``joint_cell`` and ``trajectory``.

Each claim lists certified direct-kinematic boxes of one exact joint vector q,
with their det A signs:

* ``dkp``: the solutions of q, "exactly n" when the solver proved the list
  complete, "at least n" otherwise;
* ``joint_cell``: the witness of a certified joint cell, whose count and aspect
  split (n_wa1, n_wa2) the library extends to the whole cell (that extension
  rests on the enclosure of g(S), which the checker does not re-check);
* ``trajectory``: a motion between two solutions of q of one aspect, with the
  complete solution list that fixes the numbering and the segment certificate
  of :meth:`~intervalkin.space.trajectory_result.Trajectory.certificate`.

Every claim goes through :func:`~intervalkin.certify.evidence.certified` (the
checker must verify it); the builders return the claim, or (None, why) and the
writer lists it under ``omitted``.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Sequence

from intervalkin.certify.evidence import box_json, certified, rho_text
from intervalkin.core.exact import exact_text
from intervalkin.core.geometry import Geometry
from intervalkin.solve.dkp import solve

__all__ = ['dkp_claim', 'joint_cell_claims', 'trajectory_claims', 'witness_end']


def _solution_entries(solutions) -> list[dict]:
    """The unique solutions with a proved det A sign, as claim entries."""
    return [{"box": box_json(s.box), "det_sign": int(s.det_sign)}
            for s in solutions if s.status == "unique" and s.det_sign != 0]


def witness_end(geometry: Geometry, q, precision: int = 128) -> tuple[dict | None, str]:
    """A joint vector with its complete, checker-verified solution list, count and aspect split (the object a
    ``joint_join`` end or a count barrier's witness is), or (None, why not)."""
    q = tuple(Fraction(v) for v in q)
    point = [exact_text(v) for v in q]
    res = solve(geometry, q)
    sols = _solution_entries(res.solutions)
    if not res.complete or len(sols) != len(res.solutions):
        return None, f"the solve at {point} is not complete"
    n1 = sum(1 for s in sols if s["det_sign"] > 0)
    claim = {"id": "end", "witness": point, "count": len(sols), "n_wa1": n1,
             "n_wa2": len(sols) - n1, "phi0": 0.0, "solutions": sols}
    got, why = certified(geometry, "joint_cell", claim, max(precision, res.precision))
    if got is None:
        return None, why
    del got["id"]
    return got, ""


def dkp_claim(geometry: Geometry, result, claim_id: str, precision: int = 128) -> tuple[dict | None, str]:
    """A ``dkp`` claim from a :class:`~intervalkin.solve.solutions.DkpResult` (checked), or (None, why not)."""
    sols = _solution_entries(result.solutions)
    complete = bool(result.complete) and len(sols) == len(result.solutions)
    claim = {
        "id": claim_id,
        "rho": [exact_text(r) for r in result.rho],
        "complete": complete,
        "count": len(sols),
        "phi0": 0.0,
        "solutions": sols,
        "statement": (f"q = ({rho_text(result.rho)}) has " + ("exactly " if complete else "at least ")
                      + f"{len(sols)} direct-kinematic solutions, one in each box, det A of the stated sign"),
    }
    if not complete:
        del claim["phi0"]
    return certified(geometry, "dkp", claim, max(precision, result.precision))


def joint_cell_claims(geometry: Geometry, joint, precision: int = 128) -> tuple[list[dict], list[dict]]:
    """One ``joint_cell`` claim per cell with a certified count (its witness re-solved); and the omitted ones."""
    claims, omitted = [], []
    for cell in joint.cells:
        if not cell.complete or cell.witness is None:
            continue
        res = solve(geometry, cell.witness)
        sols = _solution_entries(res.solutions)
        claim = {
            "id": f"cell-{cell.id}",
            "cell": int(cell.id),
            "witness": [exact_text(r) for r in cell.witness],
            "count": int(cell.count),
            "n_wa1": int(cell.n_wa1),
            "n_wa2": int(cell.n_wa2),
            "phi0": 0.0,
            "solutions": sols,
            "statement": (f"the witness q = ({rho_text(cell.witness)}) of joint cell {cell.id} has exactly "
                          f"{cell.count} solutions ({cell.n_wa1} in WA1, {cell.n_wa2} in WA2), none singular; "
                          "the library's enclosure of g(S) (not re-checked) extends this to the whole cell"),
        }
        if not res.complete or len(sols) != len(res.solutions):
            omitted.append({"what": f"joint_cell cell-{cell.id}", "why": "the re-solve of the witness is not complete"})
            continue
        got, why = certified(geometry, "joint_cell", claim, max(precision, res.precision))
        if got is None:
            omitted.append({"what": f"joint_cell cell-{cell.id}", "why": why})
        else:
            claims.append(got)
    return claims, omitted


def trajectory_claims(geometry: Geometry, trajectories: Sequence,
                      precision: int = 128) -> tuple[list[dict], list[dict]]:
    """One ``trajectory`` claim per certified trajectory (checked); and the omitted ones.

    The segments are copied from ``Trajectory.certificate()`` (exact hex
    floats); the solution list of the joint vector (which numbers the
    solutions) is padded if the checker's Krawczyk test needs it, the start
    and goal boxes never are (they are the enclosures the segments start and
    end in).  An uncertified trajectory, or one the checker refuses, is omitted.
    """
    claims, omitted = [], []
    for tr in trajectories:
        cid = f"{tr.i_from}-{tr.i_to}"
        if not tr.certified:
            omitted.append({"what": f"trajectory {cid}", "why": f"the path is not certified: {tr.reason}"})
            continue
        sols = list(tr.solutions)
        if not sols or any(s.status != "unique" or s.det_sign == 0 for s in sols):
            omitted.append({"what": f"trajectory {cid}", "why": "the solutions of rho are not all certified"})
            continue
        cert = tr.certificate()
        claim = {
            "id": cid,
            "rho": [exact_text(r) for r in tr.rho],
            "from": int(tr.i_from),
            "to": int(tr.i_to),
            "aspect": tr.aspect,
            "det_sign": int(tr.sign),
            "phi0": 0.0,
            "solutions": _solution_entries(sols),
            "start_box": box_json(sols[tr.i_from - 1].box),
            "goal_box": box_json(sols[tr.i_to - 1].box),
            "phi_turns": int(tr.phi_turns),
            "waypoints": [[float(v).hex() for v in w] for w in tr.waypoints],
            "segments": [{k: s[k] for k in ("start", "end", "pieces")} for s in cert["segments"]],
            "statement": (f"for q = ({rho_text(tr.rho)}), the straight segments between the waypoints move the "
                          f"platform from solution {tr.i_from} to solution {tr.i_to} with det A "
                          f"{'> 0' if tr.sign > 0 else '< 0'} and every leg within its limits all along: "
                          f"a non-singular change of assembly mode in {tr.aspect}"),
        }
        got, why = certified(geometry, "trajectory", claim, precision)
        (claims.append(got) if got else omitted.append({"what": f"trajectory {cid}", "why": why}))
    return claims, omitted

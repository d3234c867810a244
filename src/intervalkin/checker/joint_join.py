"""``joint_join`` claims: two points of the joint box with one count, joined off g(S) by a chain of sets.

A claim lists two *ends* (a witness joint vector each, with its complete solution list,
count and aspect split, as a ``joint_cell`` claim has), a chain of *nodes* and one *link*
point between consecutive nodes.  A node is

* ``{"clear": box}``: a joint box (exact rationals) inside the joint limits, re-proved off
  g(S) here (:func:`~intervalkin.checker.joint_torus.torus_search`);
* ``{"fold": id, "side": -1 | 1}``: the piece below (-1) or above (+1) the sheet of the
  fold model ``joint_fold_model.json#id``, which must have been verified before.

The checker proves: the two ends declare the same count and split (a component off g(S)
has one count, so ends with different counts are refused outright); every witness and
link lies strictly inside the open joint box U; the witness of end 0 lies in node 0, the
witness of end 1 in the last node, and link t in nodes t and t + 1, where "lies in" is
exact inclusion in the closed box and, for a piece, the side test of the verified model
(:meth:`~intervalkin.checker.joint_models.FoldProof.side`); each end's solution list is
complete with the declared count and split; each clear node is clear.  Each node meets U
in a connected set off g(S) and consecutive ones share their link, so both witnesses lie
in one component of U minus g(S) (proofs/lemma-joint-claims.md).  Cheap steps first, the
torus searches last.  Standard library and python-flint only.
"""

from __future__ import annotations

from intervalkin.checker.joint_models import in_joint_box, read_joint_box, read_joint_point
from intervalkin.checker.joint_torus import torus_search
from intervalkin.checker.model import ArbModel
from intervalkin.checker.parse import Refused, get, read_int
from intervalkin.checker.solutions import check_solutions

__all__ = ["MODEL_FILE", "MAX_NODES", "check_joint_join"]

#: The file whose verified claims fold nodes refer to.
MODEL_FILE = "joint_fold_model.json"
#: Longest chain accepted (a bound on the work a claim may ask for).
MAX_NODES = 200


def _read_end(end, n: int) -> tuple:
    if not isinstance(end, dict):
        raise Refused(f"ends[{n}]: expected an object")
    q = read_joint_point(get(end, "witness"), f"ends[{n}] witness")
    sig = tuple(read_int(get(end, key), f"ends[{n}] {key}", 0, 6) for key in ("count", "n_wa1", "n_wa2"))
    return q, sig


def _read_node(node, t: int, verified: dict) -> tuple:
    """("clear", box) or ("fold", proof, side, id)."""
    if not isinstance(node, dict):
        raise Refused(f"nodes[{t}]: expected an object")
    if "clear" in node:
        return "clear", read_joint_box(node["clear"], f"nodes[{t}] clear")
    ref = get(node, "fold")
    side = get(node, "side")
    if side not in (-1, 1) or isinstance(side, bool):
        raise Refused(f"nodes[{t}]: side must be -1 (below the sheet) or 1 (above), got {side!r}")
    facts = verified.get(f"{MODEL_FILE}#{ref}")
    if not isinstance(ref, str) or facts is None or "fold" not in facts:
        raise Refused(f"nodes[{t}]: fold model {ref!r} is not a verified claim of {MODEL_FILE}")
    return "fold", facts["fold"], side, ref


def _box_of(node) -> tuple:
    return node[1] if node[0] == "clear" else node[1].box


def _in_open(q, g) -> bool:
    return all(g.rho_min[a] < q[a] < g.rho_max[a] for a in range(3))


def check_joint_join(model: ArbModel, claim: dict, prec: int, verified: dict) -> tuple[str, dict]:
    """Re-prove one ``joint_join`` claim (module docstring) against the verified claims ("file#id" -> facts)."""
    g = model.geometry
    ends = get(claim, "ends")
    if not isinstance(ends, list) or len(ends) != 2:
        raise Refused("ends: expected two ends")
    (q0, s0), (q1, s1) = _read_end(ends[0], 0), _read_end(ends[1], 1)
    if s0 != s1:
        raise Refused(f"the ends declare different counts and splits {s0} and {s1}: points of one component off "
                      "g(S) have one count, so they cannot be joined")
    nodes_in, links_in = get(claim, "nodes"), get(claim, "links")
    if not isinstance(nodes_in, list) or not 1 <= len(nodes_in) <= MAX_NODES:
        raise Refused(f"nodes: expected a list of 1..{MAX_NODES} nodes")
    if not isinstance(links_in, list) or len(links_in) != len(nodes_in) - 1:
        raise Refused(f"links: expected {len(nodes_in) - 1} link points (one between consecutive nodes)")
    nodes = [_read_node(nd, t, verified) for t, nd in enumerate(nodes_in)]
    links = [read_joint_point(v, f"links[{t}]") for t, v in enumerate(links_in)]
    # every point, with the nodes it must lie in
    points = [("end 0 witness", q0, [0]), ("end 1 witness", q1, [len(nodes) - 1])]
    points += [(f"links[{t}]", q, [t, t + 1]) for t, q in enumerate(links)]
    for what, q, at in points:
        if not _in_open(q, g):
            raise Refused(f"{what}: not strictly inside the joint limits")
        for t in at:
            if not in_joint_box(q, _box_of(nodes[t])):
                raise Refused(f"{what}: not inside the box of nodes[{t}]")
    for t, nd in enumerate(nodes):
        if nd[0] == "clear" and not all(g.rho_min[a] <= nd[1][a][0] and nd[1][a][1] <= g.rho_max[a]
                                        for a in range(3)):
            raise Refused(f"nodes[{t}]: the clear box is not inside the joint limits")
    for what, q, at in points:
        for t in at:
            nd = nodes[t]
            if nd[0] == "fold" and nd[1].side(q) != nd[2]:
                raise Refused(f"{what}: not proved {'below' if nd[2] < 0 else 'above'} the sheet of fold model "
                              f"{nd[3]} (nodes[{t}])")
    for n, (end, q) in enumerate(((ends[0], q0), (ends[1], q1))):
        sols = get(end, "solutions")
        if not isinstance(sols, list):
            raise Refused(f"ends[{n}] solutions: expected a list")
        facts = check_solutions(model, q, sols, True, get(end, "phi0"), prec)
        got = (facts["n"], facts["n_wa1"], facts["n_wa2"])
        if got != s0:
            raise Refused(f"ends[{n}]: the witness has {got[0]} solutions split {got[1]} + {got[2]}, not the declared "
                          f"{s0[0]} split {s0[1]} + {s0[2]}")
    cells = 0
    for t, nd in enumerate(nodes):
        if nd[0] == "clear":
            ok, detail = torus_search(model, nd[1])
            if not ok:
                raise Refused(f"nodes[{t}]: the box is not proved off g(S): {detail}")
            cells += 1
    n_fold = len(nodes) - cells
    return (f"the witnesses ({', '.join(map(str, q0))}) and ({', '.join(map(str, q1))}), each with exactly {s0[0]} "
            f"solutions ({s0[1]} in WA1, {s0[2]} in WA2), lie in one component of the open joint box minus g(S): "
            f"a chain of {cells} clear boxes and {n_fold} fold pieces, consecutive ones sharing a placed point"), \
        {"joined": s0}

"""``aspect_connected`` claims: the covers of :mod:`intervalkin.space.aspect_topology`, one claim per sign.

Each claim holds the cover as rows ``[level, i, j, k, code]`` (integer octree
coordinates of the paving domain, written as hex floats): code -1 OUT, -2 SINK,
d >= 0 a retraction along ``directions[d]`` = (a, b, c), e = (a, b, c / phi_divisor),
-3 - c OUT by the combination ``combinations[c]`` = (w_1, ..., w_7) of the seven
constraints (sum_j w_j f_j < 0 on the box).
OUT and SINK rows come first, then the retracting boxes by increasing rank, so
that every box across an exit face of a retracting box is listed before it.  The
checker (:mod:`intervalkin.checker.aspects`) re-proves every row in arb and the
order, the tiling and the connectedness of the sinks from the rows alone.

A cover with unresolved (LEFT) boxes proves nothing about its sign: it is not
written, and the index lists it under ``omitted`` with the places left open.
"""

from __future__ import annotations

import numpy as np

from intervalkin.space.aspect_retraction import PHI_DIVISOR
from intervalkin.space.aspect_topology import LEFT, OUT, RET, SINK, AspectCover, AspectTopology

__all__ = ["aspect_cover_claim", "aspect_connected_claims"]

_NAMES = {1: "WA1", -1: "WA2"}


def aspect_cover_claim(cover: AspectCover) -> dict:
    """The ``aspect_connected`` claim of one cover without LEFT boxes (rows in the order the checker needs)."""
    if np.any(cover.kind == LEFT):
        raise ValueError("a cover with unresolved boxes proves nothing: it has no claim")
    code = np.full(len(cover.level), -1, dtype=np.int64)
    code[cover.kind == SINK] = -2
    weights = np.zeros((len(cover.level), 7), dtype=np.int64) if cover.weights is None else cover.weights
    mixed = np.flatnonzero((cover.kind == OUT) & np.any(weights > 0, axis=1))
    combos, cinv = np.unique(weights[mixed], axis=0, return_inverse=True)
    code[mixed] = -3 - cinv.reshape(-1)
    ret = np.flatnonzero(cover.kind == RET)
    dirs, inv = np.unique(cover.direction[ret], axis=0, return_inverse=True)
    code[ret] = inv.reshape(-1)
    first = np.flatnonzero((cover.kind == OUT) | (cover.kind == SINK))
    order = np.concatenate([first, ret[np.argsort(cover.rank[ret], kind="stable")]])
    rows = np.column_stack([cover.level[order], cover.ijk[order], code[order]]).tolist()
    name = _NAMES[cover.sign]
    return {
        "id": name,
        "aspect": name,
        "domain": [[float(lo).hex(), float(hi).hex()] for lo, hi in cover.domain],
        "phi_divisor": PHI_DIVISOR,
        "directions": dirs.tolist(),
        "combinations": combos.reshape(-1, 7).tolist(),
        "boxes": rows,
        "statement": (f"{name} (the poses of W with det A {'>' if cover.sign > 0 else '<'} 0) is nonempty with "
                      f"at least {cover.components_at_least} and at most {cover.groups} component(s): these "
                      f"{len(rows)} boxes tile the paving domain; the sinks lie inside {name} in {cover.groups} "
                      f"face-connected group(s); every other box is free of {name} or retracts along its direction "
                      f"onto boxes listed before it; the boxes not free of {name} make "
                      f"{cover.components_at_least} separate piece(s) holding sinks"),
    }


def aspect_connected_claims(topology: AspectTopology) -> tuple[list[dict], list[dict]]:
    """One claim per sign whose cover closed; the others under ``omitted`` with their open places."""
    claims, omitted = [], []
    for cover in topology.covers:
        left = cover.leftovers()
        if left:
            vol = sum(x["volume"] for x in left)
            omitted.append({"what": f"aspect_connected {_NAMES[cover.sign]}",
                            "why": f"{len(left)} boxes (volume {vol:.3g}) neither free of the aspect, inside it "
                                   "nor retracting onto it; first: " + repr(left[0]["box"])})
        else:
            claims.append(aspect_cover_claim(cover))
    return claims, omitted

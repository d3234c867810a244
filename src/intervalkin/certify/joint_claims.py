"""``joint_fold_model`` and ``joint_join`` claims from a direct joint paving with fold pieces.

The piece graph of :class:`~intervalkin.space.joint_paving.JointSpacePaving` joins clear
boxes and the two pieces of each fold box (:mod:`intervalkin.space.joint_pieces`) into
cells.  Face adjacency of clear boxes alone is certified for free; what the fold models add
is certified here, in two kinds of claim (checked by :mod:`intervalkin.checker.joint_models`
and :mod:`intervalkin.checker.joint_join`; proofs/lemma-joint-claims.md):

* ``joint_fold_model``: one fold box, its axis, its pose box, the connectivity criterion,
  and a witness point on each side of the sheet;
* ``joint_join``: a chain from a clear box of a cell, through fold pieces (and the links
  the paving placed on their shared faces), to another clear component of the same cell
  (a *component join*) or to a fold piece (a *piece join*: the piece belongs to the
  cell), with a complete certified solve at both ends.

What is written, within :data:`MAX_JOINS` joins and :data:`MAX_MODELS` fold models (the
checker re-proves each model's torus cover and each clear end's, so the cost of
``intervalkin verify`` grows with them):

1. every component join: for each cell made of several face-connected groups of clear
   boxes, a spanning tree of joins between the groups (breadth first from the largest);
2. then piece joins, fold box by fold box (both pieces, shortest chains first), until a cap
   is reached.

The joins and models left out are listed under ``omitted`` with the count; a join the
checker refuses (for example an end whose solve does not complete) is omitted with the
reason.  Every claim is run through the checker before it is written.
"""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import breadth_first_order

from intervalkin.certify.evidence import box_json
from intervalkin.certify.solve_claims import witness_end
from intervalkin.checker.claims import MALFORMED, run_check
from intervalkin.checker.joint_join import MODEL_FILE
from intervalkin.checker.parse import Refused
from intervalkin.core.exact import exact_text
from intervalkin.core.geometry import Geometry
from intervalkin.paving.adjacency import component_labels, shares_face
from intervalkin.solve.fold_model import side_of

__all__ = ["MAX_JOINS", "MAX_MODELS", "joint_claims"]

#: Joins written at most (component joins first).
MAX_JOINS = 64
#: Fold models written at most (those the joins use).
MAX_MODELS = 64
#: Plans passed over for want of room for their fold models before the search for joins stops.
SCAN_PAST_CAP = 5000
#: Points tried on a shared face, as fractions of its two sides (the paving's own choice, re-made here).
FACE_FRACTIONS = ((0.5, 0.5), (0.1, 0.1), (0.1, 0.9), (0.9, 0.1), (0.9, 0.9), (0.3, 0.7), (0.7, 0.3))
_CRITERIA = ({"name": "height_inside"}, {"name": "normal_signs"})


def _exact(v) -> Fraction:
    return Fraction(float(v))


def _point(q) -> list[str]:
    return [exact_text(Fraction(v)) for v in q]


def _jbox(lo, hi) -> list[list[str]]:
    return [[exact_text(_exact(a)), exact_text(_exact(b))] for a, b in zip(lo, hi)]


class _Graph:
    """Clear components (face adjacency) and fold pieces as one graph: node c < ncomp a component, ncomp + p piece p."""

    def __init__(self, jsp):
        pav, self.pieces = jsp.paving, jsp.pieces
        self.n = len(pav)
        self.lo, self.hi = pav.lo, pav.hi
        clear = jsp.cell >= 0
        face = shares_face(pav.level, pav.ijk, int(pav.level.max()), periodic=(False, False, False))
        self.comp = component_labels(self.n, face, clear).astype(np.int64)
        self.ncomp = int(self.comp.max()) + 1 if clear.any() else 0
        self.comp_cell = np.full(self.ncomp, -1, dtype=np.int64)
        self.comp_cell[self.comp[clear]] = jsp.cell[clear]
        self.comp_size = np.bincount(self.comp[clear], minlength=self.ncomp)
        e = self.pieces.edges
        keep = (e[0] >= self.n) | (self.comp[np.minimum(e[0], self.n - 1)] >= 0)
        keep &= (e[1] >= self.n) | (self.comp[np.minimum(e[1], self.n - 1)] >= 0)
        self.orig = e[:, keep]
        u, v = self.node(self.orig[0]), self.node(self.orig[1])
        self.size = self.ncomp + 2 * len(self.pieces)
        self.u, self.v = u, v
        keys = np.concatenate([u * (self.size + 1) + v, v * (self.size + 1) + u])
        self._order = np.argsort(keys, kind="stable")
        self._keys = keys[self._order]

    def edge_of(self, a: int, b: int) -> int:
        """An original edge (column of ``orig``) between graph nodes a and b."""
        at = int(np.searchsorted(self._keys, a * (self.size + 1) + b))
        return int(self._order[at]) % self.u.size

    def node(self, v: np.ndarray) -> np.ndarray:
        v = np.asarray(v, dtype=np.int64)
        return np.where(v < self.n, self.comp[np.minimum(v, self.n - 1)], self.ncomp + v - self.n)

    def leaf(self, orig: int) -> int:
        return orig if orig < self.n else int(self.pieces.box[(orig - self.n) // 2])

    def bfs(self, sources: list[int]) -> tuple[np.ndarray, np.ndarray]:
        """(predecessors, distances; -1 where not reached) of a breadth-first search from the given nodes
        (a virtual root joins them: the sources are at distance 1)."""
        root = self.size
        u = np.concatenate([self.u, np.full(len(sources), root)])
        v = np.concatenate([self.v, np.asarray(sources, dtype=np.int64)])
        g = csr_matrix((np.ones(u.size), (u, v)), shape=(root + 1, root + 1))
        order, pred = breadth_first_order(g, root, directed=False, return_predecessors=True)
        dist = np.full(root + 1, -1, dtype=np.int64)
        dist[root] = 0
        for node in order[1:].tolist():
            dist[node] = dist[pred[node]] + 1
        return pred, dist

    def path_to(self, pred: np.ndarray, target: int) -> list[int] | None:
        """Nodes from the last component on the search path to ``target`` (None: not reached)."""
        path = [target]
        while True:
            at = int(pred[path[-1]])
            if at < 0:  # not reached (scipy marks it -9999)
                return None
            if at == self.size:
                return path[::-1] if path[-1] < self.ncomp else None
            path.append(at)
            if at < self.ncomp:
                return path[::-1]


class _Writer:
    def __init__(self, geometry: Geometry, jsp, precision: int):
        self.geometry, self.jsp, self.precision = geometry, jsp, precision
        self.g = _Graph(jsp)
        self.models: dict[int, dict] = {}  # fold model row -> claim
        self.facts: dict[str, dict] = {}
        self.refused_models: dict[int, str] = {}

    # --- fold models ------------------------------------------------------------------
    def model_claim(self, t: int) -> dict | None:
        if t in self.models:
            return self.models[t]
        if t in self.refused_models:
            return None
        pc, leaf = self.g.pieces, int(self.g.pieces.box[t])
        M = pc.models
        k = int(M.axis[t])
        claim = {"id": f"fold-{leaf}", "box": _jbox(self.g.lo[leaf], self.g.hi[leaf]), "axis": k,
                 "pose": box_json(M.pose[t])}
        wit = {name: _point(map(_exact, pc.witness[2 * t + s])) for s, name in enumerate(("below", "above"))
               if np.isfinite(pc.witness[2 * t + s]).all()}
        crits = list(_CRITERIA) + [{"name": "edge_heights", "along": b} for b in range(3) if b != k]
        why = "no criterion"
        for w in ((wit, {}) if wit else ({},)):
            for crit in crits:
                c = dict(claim, criterion=crit, witnesses=w, statement=(
                    f"g(S) meets the joint box in one sheet, a graph along rho_{k + 1}, which cuts it into two "
                    "connected pieces (below and above); the pose box holds every singular pose of the box"))
                try:
                    _, facts = run_check(self.geometry, "joint_fold_model", c, self.precision)
                except (Refused, *MALFORMED) as exc:
                    why = str(exc)
                    if why.startswith("criterion"):
                        continue  # the next criterion may hold
                    break
                self.models[t] = c
                self.facts[f"{MODEL_FILE}#{c['id']}"] = facts
                return c
            if not why.startswith("witnesses"):
                break  # only a witness that cannot be placed is worth a second try, without witnesses
        self.refused_models[t] = why
        return None

    # --- joins ------------------------------------------------------------------------
    def _end(self, q) -> tuple[dict | None, str]:
        return witness_end(self.geometry, q, self.precision)

    def _link(self, a: int, b: int, side: dict) -> np.ndarray | None:
        """A point of the face shared by original nodes a and b, placed on the stated side of each fold end."""
        la, lb = self.g.leaf(a), self.g.leaf(b)
        flo = np.maximum(self.g.lo[la], self.g.lo[lb])
        fhi = np.minimum(self.g.hi[la], self.g.hi[lb])
        flat = int(np.argmin(fhi - flo))
        others = [x for x in range(3) if x != flat]
        pts = np.repeat(flo[None, :], len(FACE_FRACTIONS), axis=0)
        for c, ax in enumerate(others):
            f = np.array([fr[c] for fr in FACE_FRACTIONS])
            pts[:, ax] = np.clip(flo[ax] + f * (fhi[ax] - flo[ax]), flo[ax], fhi[ax])
        ok = np.ones(len(pts), dtype=bool)
        for v in (a, b):
            if v >= self.g.n:
                t = (v - self.g.n) // 2
                got = side_of(self.geometry, self.g.pieces.models, np.full(len(pts), t), pts)
                ok &= got == side[v]
        return pts[int(np.argmax(ok))] if ok.any() else None

    def join(self, path: list[int], target_orig: int | None) -> tuple[dict | None, str]:
        """The claim of a search path (graph nodes: a component first, then pieces, maybe a component last)."""
        g = self.g
        orig = []  # original nodes: leaf index of a clear box, or n + piece
        for s in range(len(path) - 1):
            k = g.edge_of(path[s], path[s + 1])
            a, b = (int(v) for v in g.orig[:, k])
            if g.node(np.array([a]))[0] != path[s]:
                a, b = b, a
            if not orig:
                orig.append(a)
            elif orig[-1] != a:  # a component entered at one box and left at another: not one chain
                return None, "the path crosses a clear component"
            orig.append(b)
        if target_orig is not None and orig[-1] != target_orig:
            orig.append(target_orig)
        side = {v: (1 if (v - g.n) % 2 else -1) for v in orig if v >= g.n}
        nodes, links = [], []
        for v in orig:
            if v < g.n:
                nodes.append({"clear": _jbox(g.lo[v], g.hi[v])})
            else:
                c = self.model_claim((v - g.n) // 2)
                if c is None:
                    return None, f"the fold model of leaf {g.leaf(v)} is not re-proved: {self.refused_models[(v - g.n) // 2]}"
                nodes.append({"fold": c["id"], "side": side[v]})
        for a, b in zip(orig[:-1], orig[1:]):
            p = self._link(a, b, side)
            if p is None:
                return None, "no face point placed at both ends of a link"
            links.append(_point(map(_exact, p)))
        ends = []
        for v in (orig[0], orig[-1]):
            if v < g.n:
                q = [(_exact(lo) + _exact(hi)) / 2 for lo, hi in zip(g.lo[v], g.hi[v])]
            else:
                w = g.pieces.witness[v - g.n]
                if not np.isfinite(w).all():
                    return None, "the piece has no witness"
                q = [_exact(x) for x in w]
            end, why = self._end(q)
            if end is None:
                return None, why
            ends.append(end)
        prec = max([self.precision] + [e.pop("precision", self.precision) for e in ends])
        cells = [int(self.jsp.cell[v]) if v < g.n else int(self.jsp.piece_cell[v - g.n]) for v in (orig[0], orig[-1])]
        claim = {"cells": cells, "precision": prec, "ends": ends, "nodes": nodes, "links": links,
                 "statement": (f"the two witnesses, with {ends[0]['count']} solutions each, lie in one component of "
                               f"the joint box minus g(S), joined by {len(nodes)} clear boxes and fold pieces")}
        try:
            run_check(self.geometry, "joint_join", dict(claim, id="pre"), prec, self.facts)
        except Refused as exc:
            return None, str(exc)
        return claim, ""


def joint_claims(geometry: Geometry, jsp, precision: int = 128, max_joins: int = MAX_JOINS,
                 max_models: int = MAX_MODELS) -> tuple[list[dict], list[dict], list[dict]]:
    """(fold model claims, join claims, omitted) of a :class:`~intervalkin.space.joint_paving.JointSpacePaving`.

    Empty when the paving has no fold pieces.  Each claim has been verified by the checker.
    """
    if jsp.pieces is None or not len(jsp.pieces):
        return [], [], []
    w = _Writer(geometry, jsp, precision)
    g = w.g
    plans: list[tuple[list[int], int | None, str]] = []
    unwritten: list[int] = []  # cells whose clear components join only through window pieces
    # 1. component joins: a spanning tree of the clear components of each cell
    for cell in np.unique(g.comp_cell[g.comp_cell >= 0]):
        comps = np.flatnonzero(g.comp_cell == cell)
        if comps.size < 2:
            continue
        root = int(comps[np.argmax(g.comp_size[comps])])
        pred, _ = g.bfs([root])
        for c in comps:
            if c != root:
                path = g.path_to(pred, int(c))
                if path is not None:
                    plans.append((path, None, f"clear components of cell {cell}"))
                else:
                    unwritten.append(int(cell))
    n_component = len(plans)
    # 2. piece joins: both pieces of a fold box, shortest chains first (expanded lazily: there may be 10^5)
    pred, dist = g.bfs(list(range(g.ncomp)))
    m = len(g.pieces)
    d = dist[g.ncomp:g.ncomp + 2 * m].reshape(m, 2)
    ok = (d > 0).all(axis=1) & np.isfinite(g.pieces.witness).all(axis=1).reshape(m, 2).all(axis=1)
    boxes = np.flatnonzero(ok)
    boxes = boxes[np.lexsort((boxes, d[boxes].max(axis=1)))]

    def piece_plans():
        for t in boxes.tolist():
            for s in (0, 1):
                yield (g.path_to(pred, g.ncomp + 2 * t + s), g.n + 2 * t + s,
                       f"piece {'below' if s == 0 else 'above'} of fold box {int(g.pieces.box[t])}")

    total = n_component + 2 * boxes.size
    joins, omitted, tried, capped = [], [], 0, 0
    for path, target, what in itertools.chain(plans, piece_plans()):
        if len(joins) >= max_joins or capped > SCAN_PAST_CAP:
            break
        tried += 1
        need = {(v - g.ncomp) // 2 for v in path if v >= g.ncomp} | (
            set() if target is None else {(target - g.n) // 2})
        if len(set(w.models) | need) > max_models:
            capped += 1
            continue
        claim, why = w.join(path, target)
        if claim is None:
            omitted.append({"what": f"joint_join ({what})", "why": why})
        else:
            joins.append({"id": f"join-{len(joins)}", **claim})
    skipped = total - tried + capped
    if skipped:
        omitted.append({"what": f"joint_join: {skipped} of {total} joins ({n_component} joining clear "
                                "components, the rest fold pieces to their cells)",
                        "why": f"cap: at most {max_joins} joins and {max_models} fold models are written (the time "
                               "of intervalkin verify)"})
    if unwritten:
        omitted.append({"what": f"joint_join: {len(unwritten)} joins of clear components of cells "
                                f"{sorted(set(unwritten))}",
                        "why": "they are joined through window pieces (proofs/lemma-window-fold.md), which the "
                               "certificates do not carry yet"})
    models = [w.models[t] for t in sorted(w.models)]
    return models, joins, omitted

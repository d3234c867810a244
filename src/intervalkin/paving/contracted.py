"""Undecided leaves cut by contractors into parts proved INSIDE / OUTSIDE, stored beside the grid.

The octree grid stays as it is: its leaves, integer coordinates, labels, adjacency and
everything built on them (components, regions, exports) are unchanged.  A leaf left
BOUNDARY for a label (W, WA1 or WA2) is cut here into off-grid parts:

    leaf B = (B minus H)  u  (H minus F)  u  (H n F)
               OUTSIDE        INSIDE        BOUNDARY (the remainder)

where H contains every point of B at which the label's predicate holds and F every
point at which it fails (contractors of :mod:`intervalkin.paving.contract`; H and F
are widened one ulp outward, then clipped to B, so that every CLOSED part is disjoint
from the unwidened box it avoids).  B minus a box inside it is at most 6 boxes (slabs
below and above the box along x, then y, then phi), so a leaf gives at most 13 parts,
which tile it (interiors disjoint).  The remainder may be bisected and cut again
(``refine``), each time on its own boxes.

The parts are a :class:`ContractedParts` per label (``Paving.parts``): arrays ``lo``,
``hi`` (k, 3), ``label`` (k,) and ``leaf`` (k,), the index of the grid leaf a part lies
in.  They refine the inner and outer volumes (``Paving.volume_by_label(name,
contracted=True)``) and the inner approximation of a set (the INSIDE leaves plus the
INSIDE parts); adjacency and labelling stay on the grid, so a part is never a node of
the region graph.

Certified: every point of an INSIDE part satisfies the predicate, every point of an
OUTSIDE part violates it (proofs/lemma-contractor.md;
``tests/paving/test_contract.py::test_parts_hold_in_arb``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from intervalkin.core.errors import InputError
from intervalkin.core.geometry import Geometry
from intervalkin.core.interval import round_down, round_up
from intervalkin.kinematics.constants import constants
from intervalkin.kinematics.enclosures import det_a_interval, rho_sq_interval
from intervalkin.paving.contract import contract_det, contract_leg
from intervalkin.paving.labels import Label

__all__ = ['ContractedParts', 'box_minus', 'contract_label', 'contract_labels', 'ASPECT_NAMES']

#: The labels this module cuts: W and the two aspects.
ASPECT_NAMES = ("W", "WA1", "WA2")
#: Rows per contractor call (bounds the temporaries).
CHUNK = 1 << 17


@dataclass(frozen=True, eq=False)
class ContractedParts:
    """Off-grid parts of the undecided leaves of one label.

    Attributes
    ----------
    leaf : ndarray (k,) int64, the grid leaf each part lies in.
    lo, hi : ndarray (k, 3) float64, the part's bounds (x, y, phi).
    label : ndarray (k,) uint8, INSIDE, OUTSIDE or BOUNDARY (the remainder).
    """

    leaf: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    label: np.ndarray

    def __len__(self) -> int:
        return int(self.leaf.shape[0])

    @property
    def boxes(self) -> np.ndarray:
        """The parts as one array (k, 3, 2)."""
        return np.stack([self.lo, self.hi], axis=-1)

    def volume_by_label(self) -> dict[str, float]:
        """Total volume of the INSIDE, BOUNDARY and OUTSIDE parts (float; a measure)."""
        v = np.prod(self.hi - self.lo, axis=1)
        return {k: float(v[self.label == lab].sum())
                for k, lab in (("inside", Label.INSIDE), ("boundary", Label.BOUNDARY), ("outside", Label.OUTSIDE))}

    def reindex(self, new_index: np.ndarray) -> "ContractedParts":
        """The parts of the leaves kept by a subset: ``new_index[old leaf]`` is the new index or -1."""
        nl = new_index[self.leaf]
        keep = nl >= 0
        return ContractedParts(nl[keep], self.lo[keep], self.hi[keep], self.label[keep])


def box_minus(a_lo: np.ndarray, a_hi: np.ndarray, c_lo: np.ndarray, c_hi: np.ndarray):
    """a minus c as boxes, for boxes c inside a (rows of (n, 3)): (lo, hi, row) of the pieces.

    Pieces: along x the slabs [a_lo, c_lo] and [c_hi, a_hi] (full in y, phi); then, over
    c's x range, the two slabs in y; then, over c's x and y ranges, the two in phi.  Slabs
    of zero width are dropped.  With c they tile a.
    """
    los, his, rows = [], [], []
    for j in range(3):
        for below in (True, False):
            lo = np.concatenate([c_lo[:, :j], a_lo[:, j:]], axis=1)
            hi = np.concatenate([c_hi[:, :j], a_hi[:, j:]], axis=1)
            if below:
                hi[:, j] = c_lo[:, j]
            else:
                lo[:, j] = c_hi[:, j]
            ok = lo[:, j] < hi[:, j]
            los.append(lo[ok])
            his.append(hi[ok])
            rows.append(np.flatnonzero(ok))
    return np.concatenate(los), np.concatenate(his), np.concatenate(rows)


def _widen(b_lo, b_hi, lo, hi):
    """A box one ulp wider on every side, clipped to B."""
    return np.maximum(round_down(lo), b_lo), np.minimum(round_up(hi), b_hi)


def _hull(acc, lo, hi, empty, rows):
    """Grow the accumulated hull (lo, hi; +inf / -inf when empty) by the non-empty rows."""
    a_lo, a_hi = acc
    ok = rows[~empty]
    a_lo[ok] = np.minimum(a_lo[ok], lo[~empty])
    a_hi[ok] = np.maximum(a_hi[ok], hi[~empty])


def _workspace_cut(geometry: Geometry, lo, hi, undecided=None):
    """(hold box, fail box) of W: hold contains every point of W in B, fail every point off W.

    Boxes are (lo, hi) pairs of (n, 3) arrays; an empty box has lo = +inf, hi = -inf.
    ``undecided`` (n,) bool: the rows to work on; the others must be proved inside W
    (hold = B, fail empty).  Legs proved inside their limits on B (phi-tight enclosure)
    are skipped.
    """
    k = constants(geometry)
    n = len(lo)
    fail = (np.full((n, 3), np.inf), np.full((n, 3), -np.inf))
    hold = (lo.copy(), hi.copy())
    rows = np.arange(n) if undecided is None else np.flatnonzero(undecided)
    if rows.size == 0:
        return hold, fail
    lo, hi = lo[rows], hi[rows]
    r = rho_sq_interval(geometry, np.stack([lo, hi], axis=-1))
    h_lo, h_hi = lo.copy(), hi.copy()
    h_empty = np.zeros(len(rows), dtype=bool)
    mn, mx = k.rho_min_sq_iv, k.rho_max_sq_iv
    for i in range(3):
        low = r.lo[:, i] < mn.hi[i]    # rho_i may be below its minimum somewhere in B
        high = r.hi[:, i] > mx.lo[i]   # ... or above its maximum
        h_empty |= (r.hi[:, i] < mn.lo[i]) | (r.lo[:, i] > mx.hi[i])
        for mask, target in ((low, (-np.inf, mn.hi[i])), (high, (mx.lo[i], np.inf))):
            sel = np.flatnonzero(mask)
            if sel.size:
                c_lo, c_hi, e = contract_leg(geometry, lo[sel], hi[sel], i, target)
                _hull(fail, c_lo, c_hi, e, rows[sel])
        sel = np.flatnonzero((low | high) & ~h_empty)
        if sel.size:
            c_lo, c_hi, e = contract_leg(geometry, h_lo[sel], h_hi[sel], i, (mn.lo[i], mx.hi[i]))
            h_lo[sel], h_hi[sel] = c_lo, c_hi
            h_empty[sel] |= e
    h_lo[h_empty], h_hi[h_empty] = np.inf, -np.inf
    hold[0][rows], hold[1][rows] = h_lo, h_hi
    return hold, fail


def _det_cut(geometry: Geometry, lo, hi, sign=None):
    """(box holding every point of B with det A >= 0, box holding every point with det A <= 0).

    ``sign`` (n,) int8: a certified sign of det A on each box (1, -1; 0 undecided), from the
    grid labels; None: enclosed here.
    """
    if sign is None:
        d = det_a_interval(geometry, np.stack([lo, hi], axis=-1))
        sign = np.where(d.lo > 0, 1, np.where(d.hi < 0, -1, 0))
    out = []
    for s in (1, -1):
        b_lo, b_hi = lo.copy(), hi.copy()
        rows = np.flatnonzero(sign == 0)
        if rows.size:
            c_lo, c_hi, e = contract_det(geometry, lo[rows], hi[rows], s)
            c_lo[e], c_hi[e] = np.inf, -np.inf
            b_lo[rows], b_hi[rows] = c_lo, c_hi
        none = sign == -s  # det A has the other sign on the whole box
        b_lo[none], b_hi[none] = np.inf, -np.inf
        out.append((b_lo, b_hi))
    return out


def _meet_boxes(a, b):
    lo, hi = np.maximum(a[0], b[0]), np.minimum(a[1], b[1])
    empty = np.any(lo > hi, axis=1)
    lo[empty], hi[empty] = np.inf, -np.inf
    return lo, hi


def _hull_boxes(a, b):
    return np.minimum(a[0], b[0]), np.maximum(a[1], b[1])


def _cuts(geometry: Geometry, names, lo, hi, w_undecided=None, det_sign=None) -> dict:
    """name -> (hold, fail) boxes on the boxes (lo, hi); W and det A are contracted once for all names."""
    hold, fail = _workspace_cut(geometry, lo, hi, w_undecided)
    out = {"W": (hold, fail)}
    if "WA1" in names or "WA2" in names:
        pos, neg = _det_cut(geometry, lo, hi, det_sign)
        # WA1 = W and det A > 0 fails where W fails or det A <= 0; WA2 the same with the signs swapped
        out["WA1"] = (_meet_boxes(hold, pos), _hull_boxes(fail, neg))
        out["WA2"] = (_meet_boxes(hold, neg), _hull_boxes(fail, pos))
    return {n: out[n] for n in names}


def _parts(lo, hi, hold, fail):
    """Cut boxes B = (lo, hi) by their hold and fail boxes: parts (lo, hi, row, label) and the remainder."""
    h_empty = np.any(hold[0] > hold[1], axis=1)
    f_empty = np.any(fail[0] > fail[1], axis=1)
    assert not np.any(h_empty & f_empty), "a box where the predicate neither holds nor fails: unsound contractor"
    h_lo, h_hi = _widen(lo, hi, *hold)
    f_lo, f_hi = _widen(lo, hi, *fail)
    out = []
    # OUTSIDE: B minus H (all of B where H is empty)
    rows_h = np.flatnonzero(~h_empty)
    p_lo, p_hi, r = box_minus(lo[rows_h], hi[rows_h], h_lo[rows_h], h_hi[rows_h])
    out.append((p_lo, p_hi, rows_h[r], Label.OUTSIDE))
    rows = np.flatnonzero(h_empty)
    out.append((lo[rows], hi[rows], rows, Label.OUTSIDE))
    # INSIDE: H minus (H n F) (all of H where they do not meet)
    m_lo, m_hi = np.maximum(h_lo, f_lo), np.minimum(h_hi, f_hi)
    m_empty = f_empty | np.any(m_lo > m_hi, axis=1)
    rows = np.flatnonzero(~h_empty & m_empty)
    out.append((h_lo[rows], h_hi[rows], rows, Label.INSIDE))
    rows = np.flatnonzero(~h_empty & ~m_empty)
    p_lo, p_hi, r = box_minus(h_lo[rows], h_hi[rows], m_lo[rows], m_hi[rows])
    out.append((p_lo, p_hi, rows[r], Label.INSIDE))
    return out, (m_lo[rows], m_hi[rows], rows)


def _bisect(lo, hi, scale):
    """Each box cut in two across its widest side (widths measured in ``scale`` units)."""
    j = np.argmax((hi - lo) / scale, axis=1)
    rows = np.arange(len(lo))
    mid = 0.5 * lo[rows, j] + 0.5 * hi[rows, j]
    a_hi, b_lo = hi.copy(), lo.copy()
    a_hi[rows, j], b_lo[rows, j] = mid, mid
    return np.concatenate([lo, b_lo]), np.concatenate([a_hi, hi])


def contract_label(geometry: Geometry, name: str, lo: np.ndarray, hi: np.ndarray,
                   leaf: np.ndarray, refine: int = 0, scale=None) -> ContractedParts:
    """Cut boxes (the undecided leaves of label ``name``: W, WA1 or WA2) into proved parts.

    Parameters
    ----------
    lo, hi : ndarray (n, 3), the boxes; leaf : (n,) their grid indices (stored in the parts).
    refine : times the remainders are bisected (across their widest side, widths in
        ``scale`` units, default the widths of the first box) and cut again.

    Returns the parts, which tile the boxes.  Certified (module docstring).
    """
    if name not in ASPECT_NAMES:
        raise InputError(f"name: expected one of {ASPECT_NAMES}, got {name!r}")
    n = len(lo)
    return contract_labels(geometry, lo, hi, leaf, {name: np.ones(n, dtype=bool)}, refine=refine, scale=scale)[name]


def contract_labels(geometry: Geometry, lo: np.ndarray, hi: np.ndarray, leaf: np.ndarray, rows_of: dict,
                    w_undecided=None, det_sign=None, refine: int = 0, scale=None) -> dict[str, ContractedParts]:
    """Cut boxes into proved parts for several labels at once (W and det A contracted once per box).

    ``rows_of`` : name -> (n,) bool, the boxes to cut for that label (its undecided leaves).
    ``w_undecided``, ``det_sign`` : optional certified knowledge from the grid: the rows where
    W is not proved (the others must be proved inside W), and the sign of det A (1, -1, 0).
    The remainders are then bisected and cut ``refine`` times, label by label.
    """
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    leaf = np.asarray(leaf, dtype=np.int64)
    scale = (hi[0] - lo[0]) if (scale is None and len(lo)) else scale
    names = list(rows_of)
    acc: dict[str, list] = {nm: [] for nm in names}
    rem: dict[str, list] = {nm: [] for nm in names}
    for s in range(0, len(lo), CHUNK):
        sl = slice(s, s + CHUNK)
        any_row = np.zeros(len(lo[sl]), dtype=bool)
        for nm in names:
            any_row |= rows_of[nm][sl]
        sel = np.flatnonzero(any_row)
        known_w = None if w_undecided is None else w_undecided[sl][sel]
        known_det = None if det_sign is None else det_sign[sl][sel]
        cuts = _cuts(geometry, names, lo[sl][sel], hi[sl][sel], known_w, known_det)
        for nm in names:
            mine = rows_of[nm][sl][sel]
            hold, fail = (tuple(a[mine] for a in box) for box in cuts[nm])
            _collect(acc[nm], rem[nm], lo[sl][sel][mine], hi[sl][sel][mine], leaf[sl][sel][mine], hold, fail)
    out = {}
    for nm in names:
        r_lo, r_hi, r_leaf = _joined(rem[nm])
        for _ in range(refine):
            r_lo, r_hi = _bisect(r_lo, r_hi, scale)
            r_leaf = np.concatenate([r_leaf, r_leaf])
            nxt: list = []
            for s in range(0, len(r_lo), CHUNK):
                b_lo, b_hi = r_lo[s:s + CHUNK], r_hi[s:s + CHUNK]
                hold, fail = _cuts(geometry, [nm], b_lo, b_hi)[nm]
                _collect(acc[nm], nxt, b_lo, b_hi, r_leaf[s:s + CHUNK], hold, fail)
            r_lo, r_hi, r_leaf = _joined(nxt)
        acc[nm].append((r_lo, r_hi, r_leaf, Label.BOUNDARY))
        del r_lo, r_hi, r_leaf
        out[nm] = _assembled(acc.pop(nm))
    return out


def _assembled(pieces: list) -> ContractedParts:
    """One ContractedParts from (lo, hi, leaf, label) pieces, freeing each field's pieces once copied."""
    label = np.concatenate([np.full(len(x[2]), x[3], dtype=np.uint8) for x in pieces])
    fields = [list(col) for col in zip(*[x[:3] for x in pieces])]
    pieces.clear()
    out = []
    for j, cols in enumerate(fields):
        out.append(np.concatenate(cols).reshape((-1, 3) if j < 2 else (-1,)))
        cols.clear()
    return ContractedParts(leaf=out[2].astype(np.int64, copy=False), lo=out[0], hi=out[1], label=label)


def _collect(acc: list, rem: list, lo, hi, leaf, hold, fail) -> None:
    """Append the decided parts of boxes to ``acc`` and their remainders to ``rem``."""
    parts, (m_lo, m_hi, rows) = _parts(lo, hi, hold, fail)
    acc += [(p_lo, p_hi, leaf[r], lab) for p_lo, p_hi, r, lab in parts]
    rem.append((m_lo, m_hi, leaf[rows]))


def _joined(rem: list):
    if not rem:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, dtype=np.int64)
    return (np.concatenate([r[0] for r in rem]), np.concatenate([r[1] for r in rem]),
            np.concatenate([r[2] for r in rem]).astype(np.int64))

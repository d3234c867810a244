"""Octree pavings: boxes stored as integer coordinates, subdivided level by level where undecided.

A paving is a set of axis-aligned boxes (x, y, phi) that tile a domain.  Each box
is stored twice, consistently:

* as integer coordinates ``(level, i, j, k)``: at ``level`` the domain is cut into
  ``2**level`` slices per axis and the box is slice ``(i, j, k)``;
* as float bounds ``lo``, ``hi`` of shape (n, 3), computed from the integers by one
  formula (``lo = domain_lo + i * (width * 2**-level)``), so that two boxes that
  share a face share it bit for bit, whatever their levels.

Depth d means leaf width = domain width / 2**d on every axis.  Only undecided boxes
are split, level by level, with numpy over all boxes of a level (no Python loop
per box).

Labels are ``uint8`` arrays of :class:`Label` flags: OUTSIDE = 1 (the predicate
fails at every point of the box), INSIDE = 2 (it holds at every point),
BOUNDARY = 3 (not decided).  ``a & b`` keeps the sharper of two sound labels of the
same predicate; 0 would mean a contradiction, i.e. an unsound evaluation, and is
asserted against.

The phi axis is periodic.  The phi range of the domain is widened outward to
[-PI_HI, PI_HI] (PI_HI is the float just above pi), so the boxes cover every angle
and the two boxes on either side of the seam overlap (by ~1e-16) modulo 2 pi:
their union is connected, which is what the seam adjacency claims.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field
from typing import Callable, Mapping, Sequence

import numpy as np

from intervalkin.core.errors import InputError
from intervalkin.core.interval import PI_HI
from intervalkin.paving.labels import Label, and_labels

__all__ = ['workspace_paving_domain', 'box_bounds', 'split_boxes', 'Paving', 'pave_multi', 'pave']


def workspace_paving_domain(geometry) -> np.ndarray:
    """The paving domain (3, 2): x, y from ``geometry.workspace_domain``, phi in [-PI_HI, PI_HI]."""
    (xl, xh), (yl, yh), _ = geometry.workspace_domain
    return np.array([[xl, xh], [yl, yh], [-PI_HI, PI_HI]], dtype=np.float64)


def box_bounds(domain: np.ndarray, level: np.ndarray, ijk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Float bounds (lo, hi), each (n, 3), of boxes given by level (n,) and ijk (n, 3).

    ``step = width * 2**-level`` is exact (a power of two); ``ijk * step`` is the
    correctly rounded product of the same real number for a box and for its
    neighbours at any level, so shared faces are bitwise equal.
    """
    domain = np.asarray(domain, dtype=np.float64)
    width = domain[:, 1] - domain[:, 0]
    step = np.ldexp(width[None, :], -np.asarray(level, dtype=np.int64)[:, None])
    ijk = np.asarray(ijk, dtype=np.int64)
    lo = domain[:, 0] + ijk * step
    hi = domain[:, 0] + (ijk + 1) * step
    # the last slice ends exactly on the domain bound
    top = (ijk + 1) == (np.int64(1) << np.asarray(level, dtype=np.int64))[:, None]
    hi = np.where(top, domain[:, 1][None, :], hi)
    return lo, hi


@dataclass
class Paving:
    """The leaves of an octree paving and their labels.

    Attributes
    ----------
    domain : ndarray (3, 2), the box that is paved (x, y, phi; phi periodic).
    depth : int, the maximal level: leaf width = domain width / 2**depth.
    level : ndarray (n,) int8, the level of each box.
    ijk : ndarray (n, 3) int64, integer coordinates of each box at its level.
    lo, hi : ndarray (n, 3) float64, the box bounds.
    labels : dict name -> ndarray (n,) uint8 of :class:`Label`.
    stats : list of per-level dicts (boxes evaluated, seconds, undecided volume).
    parts : dict name -> off-grid parts of the BOUNDARY leaves of that label, proved
        INSIDE / OUTSIDE by contractors (:class:`intervalkin.paving.contracted.ContractedParts`);
        empty unless asked for.  The grid above does not depend on them.
    """

    domain: np.ndarray
    depth: int
    level: np.ndarray
    ijk: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    labels: dict[str, np.ndarray] = field(default_factory=dict)
    stats: list[dict] = field(default_factory=list)
    parts: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.level.shape[0])

    @property
    def boxes(self) -> np.ndarray:
        """Boxes as one array of shape (n, 3, 2) (built on each access: use :meth:`box` for a few of them)."""
        return np.stack([self.lo, self.hi], axis=-1)

    def box(self, index) -> np.ndarray:
        """The boxes ``index`` (an int: shape (3, 2); an index array: (k, 3, 2)), without building all of them."""
        return np.stack([self.lo[index], self.hi[index]], axis=-1)

    def volume(self) -> np.ndarray:
        """Volume of each box (n,), float (a measure, not a certified quantity)."""
        return np.prod(self.hi - self.lo, axis=1)

    def volume_by_label(self, name: str, contracted: bool = False) -> dict[str, float]:
        """Total volume of INSIDE, BOUNDARY (undecided) and OUTSIDE boxes of one label.

        ``contracted``: the BOUNDARY leaves that were cut into parts (``parts[name]``)
        count by their parts instead (KeyError when the label has no parts).
        """
        v = self.volume()
        lab = self.labels[name]
        out = {
            "inside": float(v[lab == Label.INSIDE].sum()),
            "boundary": float(v[lab == Label.BOUNDARY].sum()),
            "outside": float(v[lab == Label.OUTSIDE].sum()),
        }
        if contracted:
            parts = self.parts[name]
            cut = np.unique(parts.leaf)
            out["boundary"] -= float(v[cut].sum())
            for k, pv in parts.volume_by_label().items():
                out[k] += pv
        return out

    def count_by_label(self, name: str) -> dict[str, int]:
        lab = self.labels[name]
        return {k: int(np.count_nonzero(lab == v)) for k, v in
                (("inside", Label.INSIDE), ("boundary", Label.BOUNDARY), ("outside", Label.OUTSIDE))}

    def subset(self, mask: np.ndarray) -> "Paving":
        """The boxes selected by a boolean mask or index array (labels kept)."""
        new_index = np.full(len(self), -1, dtype=np.int64)
        kept = np.arange(len(self))[mask]
        new_index[kept] = np.arange(kept.size)
        return Paving(self.domain, self.depth, self.level[mask], self.ijk[mask], self.lo[mask], self.hi[mask],
                      {k: v[mask] for k, v in self.labels.items()}, list(self.stats),
                      {k: v.reindex(new_index) for k, v in self.parts.items()})

    @functools.cached_property
    def _sorted_keys(self) -> tuple[np.ndarray, np.ndarray]:
        """Sorted integer keys (level, i, j, k) of the leaves and the sorting order (built once)."""
        nb = self.depth + 1
        level = self.level.astype(np.int64)
        keys = (level << (3 * nb)) | (self.ijk[:, 0] << (2 * nb)) | (self.ijk[:, 1] << nb) | self.ijk[:, 2]
        order = np.argsort(keys)
        return keys[order], order

    def locate_boxes(self, boxes: np.ndarray) -> np.ndarray:
        """Index of the leaf that contains each query box (m, 3, 2) entirely, or -1.

        Candidates come from integer keys (the leaf holding the query's lower
        corner, one lookup per level); containment is then checked on the float
        bounds, so the answer is exact for the float boxes given.
        """
        boxes = np.asarray(boxes, dtype=np.float64).reshape(-1, 3, 2)
        m = boxes.shape[0]
        out = np.full(m, -1, dtype=np.int64)
        if m == 0 or len(self) == 0:
            return out
        width = self.domain[:, 1] - self.domain[:, 0]
        nfine = np.int64(1) << self.depth
        t = (boxes[:, :, 0] - self.domain[:, 0]) / width * nfine
        fine = np.clip(np.floor(t), 0, nfine - 1).astype(np.int64)
        nb = self.depth + 1
        sk, order = self._sorted_keys
        for L in range(self.depth + 1):
            c = fine >> (self.depth - L)
            qk = (np.int64(L) << (3 * nb)) | (c[:, 0] << (2 * nb)) | (c[:, 1] << nb) | c[:, 2]
            pos = np.minimum(np.searchsorted(sk, qk), sk.size - 1)
            hit = (sk[pos] == qk) & (out < 0)
            out[hit] = order[pos[hit]]
        ok = out >= 0
        idx = out[ok]
        inside = np.all((self.lo[idx] <= boxes[ok, :, 0]) & (boxes[ok, :, 1] <= self.hi[idx]), axis=1)
        res = np.full(m, -1, dtype=np.int64)
        res[np.flatnonzero(ok)[inside]] = idx[inside]
        return res

    def fine_coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """Integer bounds (n, 3) in units of the leaf width at ``depth``: [lo, hi)."""
        shift = (self.depth - self.level.astype(np.int64))[:, None]
        lo = self.ijk << shift
        return lo, (self.ijk + 1) << shift


# --------------------------------------------------------------------------------------
# Paving
# --------------------------------------------------------------------------------------
PredicateFn = Callable[[np.ndarray], np.ndarray]
_OFFSETS = np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)], dtype=np.int64)


def split_boxes(level: np.ndarray, ijk: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 8 children of each box (children of box m are rows 8m..8m+7)."""
    child_ijk = (2 * ijk[:, None, :] + _OFFSETS[None, :, :]).reshape(-1, 3)
    child_level = np.repeat(level + 1, 8)
    return child_level, child_ijk


def pave_multi(
    domain,
    predicates: Sequence[tuple[str, PredicateFn]] | Mapping[str, PredicateFn],
    depth: int,
    split: Callable[[Mapping[str, np.ndarray]], np.ndarray] | None = None,
    relevant: Mapping[str, Callable[[Mapping[str, np.ndarray]], np.ndarray]] | None = None,
    progress: Callable[[dict], None] | None = None,
) -> Paving:
    """Pave ``domain`` with several tri-state predicates in one pass.

    Parameters
    ----------
    domain : array (3, 2), the box to pave.
    predicates : ordered (name, fn) pairs; ``fn(boxes (m, 3, 2)) -> (m,) uint8`` labels.
        Each fn must be sound: INSIDE / OUTSIDE only when proved for the whole box.
    depth : int >= 0, the deepest level.
    split : ``split(labels) -> bool mask`` of the boxes to subdivide; default: any
        label is BOUNDARY.  Never splits a box whose labels are all decided.
    relevant : optional name -> ``fn(labels so far) -> bool mask``: boxes on which
        that predicate needs evaluating (others keep their inherited label).  The
        predicates are evaluated in order, so a mask may use earlier labels.
    progress : called after each level with a dict of level statistics.

    A child inherits its parent's labels; a predicate is re-evaluated on the child
    only where the inherited label is BOUNDARY, and the new label is ANDed (as
    flags) with the inherited one, so labels only sharpen under subdivision.

    A predicate that is a conjunction of m parts may say so: an integer attribute
    ``conjuncts`` = m and a method ``conjunct_labels(boxes, todo (k, m) bool) -> (k, m)``
    labels of the parts asked for.  The paver then keeps each box's part labels, asks
    a child only for the parts its parent left BOUNDARY (a part proved on a box holds
    on its sub-boxes), and the label is the AND of the parts (:func:`and_labels`).
    """
    items = list(predicates.items()) if isinstance(predicates, Mapping) else list(predicates)
    names = [n for n, _ in items]
    domain = np.asarray(domain, dtype=np.float64)
    if domain.shape != (3, 2) or not np.all(domain[:, 0] < domain[:, 1]):
        raise InputError(f"domain: expected a (3, 2) array with lo < hi, got {domain.tolist()}")
    if split is None:
        def split(labels):  # noqa: E306
            m = np.zeros(next(iter(labels.values())).shape, dtype=bool)
            for v in labels.values():
                m |= v == Label.BOUNDARY
            return m
    relevant = dict(relevant or {})
    dom_vol = float(np.prod(domain[:, 1] - domain[:, 0]))

    level = np.zeros(1, dtype=np.int64)
    ijk = np.zeros((1, 3), dtype=np.int64)
    inherited = {n: np.full(1, Label.BOUNDARY, dtype=np.uint8) for n in names}
    parts_of = {n: int(getattr(fn, "conjuncts", 0) or 0) for n, fn in items}
    inherited_parts = {n: np.full((1, m), Label.BOUNDARY, dtype=np.uint8) for n, m in parts_of.items() if m}
    leaves: list[tuple] = []
    stats: list[dict] = []
    for lev in range(depth + 1):
        t0 = time.perf_counter()
        lo, hi = box_bounds(domain, level, ijk)
        boxes = np.stack([lo, hi], axis=-1)
        labels: dict[str, np.ndarray] = {}
        evaluated = {}
        for name, fn in items:
            lab = inherited[name].copy()
            todo = lab == Label.BOUNDARY
            if name in relevant:
                todo &= relevant[name](labels)
            idx = np.flatnonzero(todo)
            if idx.size and parts_of[name]:
                parts = inherited_parts[name]
                sharp_parts = parts[idx] & np.asarray(fn.conjunct_labels(boxes[idx], parts[idx] == Label.BOUNDARY),
                                                      dtype=np.uint8)
                assert np.all(sharp_parts != Label.CONTRADICTION), f"{name}: contradictory part labels (unsound)"
                parts[idx] = sharp_parts
                new = functools.reduce(and_labels, [sharp_parts[:, j] for j in range(parts_of[name])])
            elif idx.size:
                new = np.asarray(fn(boxes[idx]), dtype=np.uint8)
            if idx.size:
                sharp = lab[idx] & new
                assert np.all(sharp != Label.CONTRADICTION), f"{name}: contradictory labels (unsound evaluation)"
                lab[idx] = sharp
            evaluated[name] = int(idx.size)
            labels[name] = lab
        cut = split(labels) if lev < depth else np.zeros(len(level), dtype=bool)
        keep = ~cut
        leaves.append((level[keep], ijk[keep], lo[keep], hi[keep], {n: labels[n][keep] for n in names}))
        box_vol = dom_vol * 8.0 ** (-lev)
        st = {
            "level": lev,
            "boxes": int(len(level)),
            "evaluated": evaluated,
            "split": int(np.count_nonzero(cut)),
            "seconds": time.perf_counter() - t0,
            "undecided_volume": {n: box_vol * int(np.count_nonzero(labels[n] == Label.BOUNDARY)) for n in names},
        }
        stats.append(st)
        if progress is not None:
            progress(dict(st, depth=depth))
        if not np.any(cut):
            break
        level, ijk = split_boxes(level[cut], ijk[cut])
        inherited = {n: np.repeat(labels[n][cut], 8) for n in names}
        inherited_parts = {n: np.repeat(v[cut], 8, axis=0) for n, v in inherited_parts.items()}
        del boxes, lo, hi
    out_labels = {n: np.concatenate([lf[4][n] for lf in leaves]) for n in names}
    return Paving(
        domain=domain,
        depth=depth,
        level=np.concatenate([lf[0] for lf in leaves]).astype(np.int8),
        ijk=np.concatenate([lf[1] for lf in leaves]),
        lo=np.concatenate([lf[2] for lf in leaves]),
        hi=np.concatenate([lf[3] for lf in leaves]),
        labels=out_labels,
        stats=stats,
    )


def pave(domain, predicate: PredicateFn, depth: int, name: str = "label", progress=None) -> Paving:
    """Pave ``domain`` with one tri-state predicate: split BOUNDARY boxes down to ``depth``."""
    return pave_multi(domain, [(name, predicate)], depth, progress=progress)

"""Aspects: the connected components of W on which det A keeps one certified sign.

Definition (the paper's section 3.1; DESIGN.md section 2): an aspect is a
connected component of the workspace W minus the type-2 singular surface
det A = 0.  With the sign convention of DESIGN.md, WA1 has det A > 0 and WA2
det A < 0.

Certified here: each component of face-adjacent boxes certified inside W with
one sign of det A is connected and lies in one aspect; components of opposite
signs lie in different aspects (the sign is the witness).  Not certified: that
two components of one sign are different aspects (they may join through the
undecided layer), nor that no aspect hides wholly in that layer.
"""

from __future__ import annotations

import numpy as np

from intervalkin.paving.adjacency import component_labels, shares_face
from intervalkin.paving.labels import Label
from intervalkin.paving.tree import Paving

__all__ = ['ASPECTS', 'aspect_components']

#: The aspects' names: WA1 where det A > 0, WA2 where det A < 0.
ASPECTS = ("WA1", "WA2")


def aspect_components(paving: Paving, edges: np.ndarray | None = None):
    """The aspects as connected components of INSIDE boxes of each sign of det A.

    Parameters
    ----------
    paving : a paving from :func:`pave_workspace` (labels WA1, WA2).
    edges : its face adjacency (2, m); computed with the phi seam when None.

    Returns
    -------
    aspect : ndarray (n,) int32, the component id of each box, -1 for boxes not
        certified in an aspect.  WA1 components come first (ids 0..c1-1), then WA2
        components, each group ordered by decreasing number of boxes.
    info : list of dicts (id, sign (+1 for det A > 0), boxes, volume), one per component.

    What is certified: each component is a union of face-adjacent boxes on which
    W holds and det A has the stated sign, so it is connected and lies inside one
    aspect.  Components of OPPOSITE signs lie in different aspects (the sign is the
    witness).  Two components of the SAME sign are not proved to be different
    aspects: they may be joined through the undecided layer, so the number of
    components of one sign is only an upper bound of the number of aspects of that
    sign seen at this depth, and each aspect met contains at least one of them.
    """

    if edges is None:
        edges = shares_face(paving.level, paving.ijk, paving.depth)
    n = len(paving)
    vol = paving.volume()
    aspect = np.full(n, -1, dtype=np.int32)
    info = []
    base = 0
    for name, sign in (("WA1", 1), ("WA2", -1)):
        comp = component_labels(n, edges, paving.labels[name] == Label.INSIDE)
        m = comp >= 0
        aspect[m] = comp[m] + base
        ncomp = int(comp.max()) + 1 if np.any(m) else 0
        counts = np.bincount(comp[m], minlength=ncomp)
        vols = np.bincount(comp[m], weights=vol[m], minlength=ncomp)
        for c in range(ncomp):
            info.append({"id": base + c, "aspect": name, "sign": sign, "boxes": int(counts[c]), "volume": float(vols[c])})
        base += ncomp
    return aspect, info


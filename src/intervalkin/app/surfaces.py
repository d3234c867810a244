"""Boundary surfaces of labelled box sets: marching cubes on a label grid.

A set of labelled boxes (the basic regions, the aspects, the joint cells) is
painted onto a regular grid (:func:`intervalkin.app.boxes.rasterise`); for each
label, scikit-image's marching cubes draws the boundary of the grid cells that
carry it.  The grid is padded with one empty cell on every side, so every
surface is closed (the phi = +-180 deg planes cap a region that crosses the seam:
a drawing artefact of cutting the periodic axis, said in the captions).

The surfaces are drawings of certified labels at the grid's resolution, not
enclosures: a thin piece narrower than a grid cell is widened to one cell.
scikit-image is imported when a surface is computed, not with the module.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

import numpy as np

__all__ = ["Surface", "label_surfaces", "grid_geometry"]


@dataclass(frozen=True)
class Surface:
    """A triangulated surface: ``vertices`` (m, 3) float64 in model units, ``faces`` (k, 3) int32."""

    vertices: np.ndarray
    faces: np.ndarray

    @property
    def n_faces(self) -> int:
        return int(self.faces.shape[0])

    def is_empty(self) -> bool:
        return self.n_faces == 0


def grid_geometry(domain: np.ndarray, bits: int, scale=(1.0, 1.0, 1.0)) -> tuple[np.ndarray, np.ndarray]:
    """(origin, spacing) of a (2**bits)^3 grid over ``domain`` (3, 2), each axis multiplied by ``scale``."""
    dom = np.asarray(domain, dtype=np.float64) * np.asarray(scale, dtype=np.float64)[:, None]
    return dom[:, 0].copy(), (dom[:, 1] - dom[:, 0]) / (1 << bits)


def _bounding_slices(mask: np.ndarray) -> tuple[slice, slice, slice] | None:
    """The smallest index box holding every True cell of ``mask`` (None when there is none)."""
    out = []
    for axis in range(3):
        other = tuple(a for a in range(3) if a != axis)
        hit = np.flatnonzero(mask.any(axis=other))
        if hit.size == 0:
            return None
        out.append(slice(int(hit[0]), int(hit[-1]) + 1))
    return tuple(out)


def _pooled(mask: np.ndarray, factor: int) -> np.ndarray:
    """``mask`` on cells ``factor`` times larger: a coarse cell is set when any of its fine cells is."""
    if factor == 1:
        return mask
    pad = [(0, -n % factor) for n in mask.shape]
    m = np.pad(mask, pad)
    a, b, c = (n // factor for n in m.shape)
    return m.reshape(a, factor, b, factor, c, factor).any(axis=(1, 3, 5))


def _cell_surface(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Marching cubes around the set cells of ``mask``: (vertices in cell units, faces)."""
    from skimage.measure import marching_cubes

    # one empty cell on each side closes the surface; marching cubes works on cell centres
    verts, faces, _, _ = marching_cubes(np.pad(mask, 1).astype(np.float32), level=0.5, allow_degenerate=False)
    # a vertex at index v of the padded array sits at cell centre v - 1, half a cell above the
    # cell's lower corner
    return verts - 1.0 + 0.5, faces


def label_surfaces(grid: np.ndarray, keys: Iterable[int], origin: np.ndarray, spacing: np.ndarray,
                   max_faces: int | None = None) -> dict[int, Surface]:
    """The boundary surface of the grid cells equal to each key.

    Parameters
    ----------
    grid : int array (n0, n1, n2) of labels.
    keys : the labels to draw (a key absent from the grid gives an empty surface).
    origin, spacing : (3,) the model coordinates of the grid's lower corner and the cell size;
        cell (i, j, k) covers origin + [i, i + 1) * spacing along each axis.
    max_faces : when a surface has more faces, it is drawn again on cells twice (then four
        times) as large, a coarse cell being set when any of its cells is: big sets get
        lighter, nothing thin is lost (it grows to one coarse cell), and small sets, which
        have few faces, keep every cell.

    The surface lies on the faces of the cells (the 0.5 level between a labelled
    cell centre and an unlabelled one).
    """
    origin = np.asarray(origin, dtype=np.float64)
    spacing = np.asarray(spacing, dtype=np.float64)
    out: dict[int, Surface] = {}
    for key in keys:
        mask = grid == key
        box = _bounding_slices(mask)
        if box is None:
            out[int(key)] = Surface(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int32))
            continue
        start = np.array([s.start for s in box], dtype=np.float64)
        factor = 1
        verts, faces = _cell_surface(mask[box])
        while max_faces is not None and len(faces) > max_faces and factor < 4:
            factor *= 2
            verts, faces = _cell_surface(_pooled(mask[box], factor))
        coords = origin + (verts * factor + start) * spacing
        out[int(key)] = Surface(coords, faces.astype(np.int32))
    return out

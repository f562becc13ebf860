"""The Mesh type: vertices, triangles and what follows from them."""

from __future__ import annotations

from functools import cached_property

import numpy as np


class Mesh:
    """A 2D triangle mesh.

    Parameters
    ----------
    vertices : (N, 2) array_like of float
        Vertex positions in metres.
    triangles : (M, 3) array_like of int
        Vertex indices per triangle, counter-clockwise.
    uv : (N, 2) array_like of float, optional
        Texture coordinates in [0, 1]. By default the vertices' positions normalised to
        their bounding box.

    Examples
    --------
    >>> import deforma
    >>> m = deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
    >>> m.edges.shape
    (3, 2)
    """

    def __init__(self, vertices, triangles, uv=None):
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
            raise ValueError(f"vertices must be an (N, 2) array with N >= 3, got shape {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError("vertices must be finite (no NaN or inf)")
        t = np.asarray(triangles)
        if t.ndim != 2 or t.shape[1] != 3 or t.shape[0] < 1:
            raise ValueError(f"triangles must be an (M, 3) integer array with M >= 1, got shape {t.shape}")
        if not np.issubdtype(t.dtype, np.integer):
            raise ValueError(f"triangles must hold integers, got dtype {t.dtype}")
        if t.min() < 0 or t.max() >= len(v):
            raise ValueError(f"triangle indices must lie in [0, {len(v) - 1}]")
        self.vertices = v
        self.triangles = np.ascontiguousarray(t, dtype=np.int32)
        if uv is None:
            lo, hi = v.min(axis=0), v.max(axis=0)
            uv = (v - lo) / np.where(hi > lo, hi - lo, 1.0)
        uv = np.ascontiguousarray(uv, dtype=np.float64)
        if uv.shape != v.shape:
            raise ValueError(f"uv must have the vertices' shape {v.shape}, got {uv.shape}")
        self.uv = uv

    @cached_property
    def edges(self) -> np.ndarray:
        """(E, 2) int32: each undirected edge once, as (low, high) index pairs, sorted."""
        t = self.triangles
        e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
        e.sort(axis=1)
        return np.unique(e, axis=0).astype(np.int32)

    @property
    def triangle_areas(self) -> np.ndarray:
        """(M,) float64: signed triangle areas in square metres (positive when counter-clockwise)."""
        a, b, c = (self.vertices[self.triangles[:, k]] for k in range(3))
        return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))

    @property
    def area(self) -> float:
        """Total area in square metres."""
        return float(self.triangle_areas.sum())

    def __repr__(self) -> str:
        return f"Mesh({len(self.vertices)} vertices, {len(self.triangles)} triangles)"

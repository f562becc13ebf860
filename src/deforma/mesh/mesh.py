"""The Mesh type: vertices, triangles and what follows from them (edges, boundary, quality)."""

from __future__ import annotations

from functools import cached_property

import numpy as np

from . import quality


class Mesh:
    """A 2D triangle mesh: the geometry a soft body is built from.

    Any arrays can be turned into a Mesh; they are checked here, once, so that everything
    downstream (springs, masses, the renderer) can trust them.

    Parameters
    ----------
    vertices : (N, 2) array_like of float
        Vertex positions in metres, y up. Finite, N >= 3.
    triangles : (M, 3) array_like of int
        Vertex indices per triangle, M >= 1. Clockwise triangles are reversed so that every
        stored triangle is counter-clockwise. A triangle whose corners are collinear or
        coincide (see :func:`deforma.mesh.quality.degenerate_triangles`), a triangle listed
        twice, and an edge shared by more than two triangles are rejected.
    uv : (N, 2) array_like of float, optional, keyword-only
        Texture coordinates in [0, 1], ``u`` to the right and ``v`` up (v = 0 is the bottom
        row of the picture, as in OpenGL). By default the vertices' positions normalised to
        their bounding box.
    texture : (H, W, 4) array_like of uint8, optional, keyword-only
        The RGBA picture ``uv`` refers to, row 0 at the top (as Pillow stores it). Meshes
        made by :func:`deforma.mesh.from_image` carry their image here; ``None`` lets the
        renderer choose.

    Attributes
    ----------
    vertices : (N, 2) ndarray of float64
    triangles : (M, 3) ndarray of int32, counter-clockwise
    uv : (N, 2) ndarray of float64
    texture : (H, W, 4) ndarray of uint8 or None

    Notes
    -----
    Vertices that no triangle uses are allowed (they carry mass but no spring); the mesh
    builders in this package never produce them.

    Examples
    --------
    >>> import deforma
    >>> m = deforma.mesh.Mesh([[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 1, 2], [0, 2, 3]])
    >>> m.edges.shape, m.area, len(m.boundary)
    ((5, 2), 1.0, 1)
    >>> round(m.min_angle, 6), m.euler_characteristic
    (45.0, 1)
    """

    def __init__(self, vertices, triangles, *, uv=None, texture=None):
        v = np.array(vertices, dtype=np.float64, copy=True)
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
            raise ValueError(f"triangle indices must lie in [0, {len(v) - 1}], got [{t.min()}, {t.max()}]")
        t = np.array(t, dtype=np.int32, copy=True)

        bad = quality.degenerate_triangles(v, t)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(
                f"triangle {k} {t[k].tolist()} is degenerate (collinear or repeated corners); "
                f"{int(bad.sum())} such triangles, only triangles with positive area are allowed"
            )
        cw = quality.triangle_signed_areas(v, t) < 0
        t[cw] = t[cw][:, [0, 2, 1]]

        if len(np.unique(_row_keys(np.sort(t, axis=1), len(v)))) != len(t):
            raise ValueError("triangles contain the same triangle twice; each triangle may appear once")
        _, counts = np.unique(_row_keys(_undirected(t), len(v)), return_counts=True)
        if counts.max() > 2:
            raise ValueError(
                f"an edge is shared by {counts.max()} triangles; a mesh edge may border at most 2"
            )
        self.vertices = v
        self.triangles = t

        if uv is None:
            lo, hi = v.min(axis=0), v.max(axis=0)
            uv = (v - lo) / np.where(hi > lo, hi - lo, 1.0)
        uv = np.array(uv, dtype=np.float64, copy=True)
        if uv.shape != v.shape:
            raise ValueError(f"uv must have the vertices' shape {v.shape}, got {uv.shape}")
        if not np.all(np.isfinite(uv)) or uv.min() < 0.0 or uv.max() > 1.0:
            raise ValueError("uv must be finite texture coordinates in [0, 1]")
        self.uv = uv

        if texture is not None:
            texture = np.ascontiguousarray(texture)
            if texture.ndim != 3 or texture.shape[2] != 4 or texture.dtype != np.uint8:
                raise ValueError(
                    f"texture must be an (H, W, 4) uint8 RGBA array, got shape {texture.shape} "
                    f"and dtype {texture.dtype}"
                )
        self.texture = texture

    @classmethod
    def _trusted(cls, vertices, triangles, uv, texture) -> "Mesh":
        """A mesh from arrays known to be valid (counter-clockwise, non-degenerate triangles,
        edges in at most two, uv in [0, 1]): a torn body's mesh, rebuilt every time it tears,
        skips the checks that cost more than the rest of the tear."""
        m = cls.__new__(cls)
        m.vertices = np.asarray(vertices, dtype=np.float64)
        m.triangles = np.asarray(triangles, dtype=np.int32)
        m.uv = np.asarray(uv, dtype=np.float64)
        m.texture = texture
        return m

    # ---- topology -------------------------------------------------------------------------

    @cached_property
    def edges(self) -> np.ndarray:
        """(E, 2) int32: each undirected edge once, as (low, high) index pairs, sorted."""
        e = _undirected(self.triangles)
        _, first = np.unique(_row_keys(e, len(self.vertices)), return_index=True)
        return np.ascontiguousarray(e[first], dtype=np.int32)  # key order = (low, high) order

    @cached_property
    def boundary_edges(self) -> np.ndarray:
        """(B, 2) int32: edges used by one triangle only, directed as in that triangle.

        With counter-clockwise triangles the outside is on the right of each edge: outer
        outlines run counter-clockwise and holes clockwise.
        """
        t = self.triangles
        directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
        keys = _row_keys(np.sort(directed, axis=1), len(self.vertices))
        _, inverse, counts = np.unique(keys, return_inverse=True, return_counts=True)
        return np.ascontiguousarray(directed[counts[inverse.ravel()] == 1], dtype=np.int32)

    @cached_property
    def boundary(self) -> list[np.ndarray]:
        """Boundary loops: a list of int32 arrays of vertex indices, each a closed loop.

        Outer outlines run counter-clockwise, holes clockwise; loops are sorted by the area
        they enclose, largest first, so ``boundary[0]`` is the outline of the largest part.
        A donut has two loops, a box one.
        """
        following: dict[int, list[int]] = {}
        for a, b in self.boundary_edges.tolist():
            following.setdefault(a, []).append(b)
        loops = []
        for start in list(following):
            while following.get(start):
                loop = [start]
                here = following[start].pop()
                while here != start:
                    loop.append(here)
                    nxt = following.get(here)
                    if not nxt:  # cannot happen on a valid mesh: every boundary vertex has an exit
                        break
                    here = nxt.pop()
                loops.append(np.array(loop, dtype=np.int32))
        v = self.vertices

        def enclosed(loop):
            x, y = v[loop, 0], v[loop, 1]
            return abs(0.5 * (np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))

        return sorted(loops, key=enclosed, reverse=True)

    @property
    def euler_characteristic(self) -> int:
        """V - E + F: 1 for a disc, 0 for an annulus (one hole), 1 - h for h holes."""
        return len(self.vertices) - len(self.edges) + len(self.triangles)

    # ---- measures -------------------------------------------------------------------------

    @property
    def triangle_areas(self) -> np.ndarray:
        """(M,) float64: signed triangle areas in square metres (positive when counter-clockwise)."""
        return quality.triangle_signed_areas(self.vertices, self.triangles)

    @property
    def area(self) -> float:
        """Total area in square metres."""
        return float(self.triangle_areas.sum())

    @property
    def triangle_min_angles(self) -> np.ndarray:
        """(M,) float64: smallest interior angle of each triangle, in degrees (60 at best)."""
        return quality.triangle_min_angles(self.vertices, self.triangles)

    @property
    def min_angle(self) -> float:
        """Smallest interior angle over all triangles, in degrees."""
        return float(self.triangle_min_angles.min())

    @property
    def aspect_ratios(self) -> np.ndarray:
        """(M,) float64: radius ratio R / (2 r) of each triangle, 1 when equilateral."""
        return quality.triangle_aspect_ratios(self.vertices, self.triangles)

    @property
    def max_aspect_ratio(self) -> float:
        """Worst (largest) radius ratio over all triangles; dimensionless, >= 1."""
        return float(self.aspect_ratios.max())

    def _repr_png_(self) -> bytes:
        """A wireframe picture (PNG bytes, 400 px on the longer side): what a notebook shows
        for a Mesh. Drawn with Pillow by :func:`deforma.mesh.picture.mesh_picture`."""
        from .picture import mesh_picture, png_bytes

        return png_bytes(mesh_picture(self))

    def __repr__(self) -> str:
        return (
            f"Mesh({len(self.vertices)} vertices, {len(self.triangles)} triangles, "
            f"area {self.area:.4g} m^2, min angle {self.min_angle:.1f} deg)"
        )


def _row_keys(rows: np.ndarray, n: int) -> np.ndarray:
    """One int64 per row of indices in [0, n), ordered as the rows are lexicographically.

    np.unique over int64 keys is many times faster than np.unique(axis=0) over rows.
    """
    rows = rows.astype(np.int64)
    if rows.shape[1] == 2 or n < 2_000_000:  # n**3 < 2**63
        key = rows[:, 0]
        for k in range(1, rows.shape[1]):
            key = key * n + rows[:, k]
        return key
    # very large meshes: rank the rows instead (same order, no overflow)
    _, key = np.unique(rows, axis=0, return_inverse=True)
    return key.ravel().astype(np.int64)


def _undirected(t: np.ndarray) -> np.ndarray:
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    e.sort(axis=1)
    return e


def split_pinches(triangles: np.ndarray, n_vertices: int) -> tuple[np.ndarray, np.ndarray]:
    """Give every fan of triangles around a vertex its own vertex: a manifold mesh.

    A *pinch* is a vertex where parts of a mesh touch at that point only (two triangles
    meeting corner to corner, a thin line cut through): its triangles form two or more
    fans that share no edge, and its boundary has two ways in and two ways out, so loops,
    the Euler characteristic and a soft body's contacts are all ill defined there. Each fan
    after the first gets a copy of the vertex (same position), so the parts that touched
    only at a point are separate there; edges, triangles and areas are unchanged.

    Parameters
    ----------
    triangles : (M, 3) int array
        Counter-clockwise triangles, every edge in at most two.
    n_vertices : int
        Number of vertices the indices refer to.

    Returns
    -------
    triangles : (M, 3) int32 ndarray
        The triangles, with corners at pinches renumbered to the copies.
    source : (N', ) int64 ndarray
        For each vertex of the result the vertex it copies (``arange(n_vertices)`` first,
        then one entry per copy): take ``vertices[source]`` and ``uv[source]``.

    Examples
    --------
    >>> import numpy as np
    >>> bow_tie = np.array([[0, 1, 2], [0, 3, 4]])  # two triangles touching at vertex 0
    >>> t, src = split_pinches(bow_tie, 5)
    >>> t.tolist(), src.tolist()
    ([[0, 1, 2], [5, 3, 4]], [0, 1, 2, 3, 4, 0])
    """
    t = np.array(triangles, dtype=np.int32, copy=True)
    source = np.arange(n_vertices, dtype=np.int64)
    if len(t) == 0:
        return t, source
    # a vertex of k fans (each open, in the plane) starts k boundary edges
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    keys = _row_keys(np.sort(directed, axis=1), n_vertices)
    _, inverse, counts = np.unique(keys, return_inverse=True, return_counts=True)
    starts = np.bincount(directed[counts[inverse.ravel()] == 1, 0], minlength=n_vertices)
    pinched = np.flatnonzero(starts >= 2)
    if len(pinched) == 0:
        return t, source
    copies = []
    nxt = n_vertices
    for v in pinched.tolist():
        ring = np.flatnonzero((t == v).any(axis=1))
        # fans: triangles of v joined across the edges (v, w) they share
        parent = {int(k): int(k) for k in ring}

        def find(k):
            while parent[k] != k:
                parent[k] = parent[parent[k]]
                k = parent[k]
            return k

        by_other: dict[int, int] = {}
        for k in ring.tolist():
            for w in t[k].tolist():
                if w == v:
                    continue
                if w in by_other:
                    parent[find(k)] = find(by_other[w])
                else:
                    by_other[w] = k
        roots = sorted({find(int(k)) for k in ring})
        for root in roots[1:]:
            for k in ring.tolist():
                if find(k) == root:
                    t[k][t[k] == v] = nxt
            copies.append(v)
            nxt += 1
    return t, np.concatenate([source, np.array(copies, dtype=np.int64)])

"""Tearing: a body stretched beyond ``tear_strain`` splits along its mesh edges.

A material with ``tear_strain = t`` (``deforma.Material(..., tear_strain=0.3)``) is checked
after every step. For each interior edge of the mesh (one shared by two triangles), the
*opening stretch* is how much the material on either side is stretched across the edge:
``|F n|`` with ``n`` the edge's unit normal in the rest shape and ``F`` each neighbouring
triangle's deformation gradient (:mod:`deforma.physics.elements`), averaged over the two.
An edge whose opening strain ``|F n| - 1`` exceeds ``t`` is cut.

A cut opens only where the mesh can open: a vertex splits when the triangles around it fall
into separate fans (groups joined across uncut edges), each fan getting its own copy of the
vertex. So cracks start at the outline (or a hole) and run inward one edge per vertex per
step, along the edges most stretched across: the crack follows the stress, at the mesh's
resolution. Copies are appended after the body's vertices (the indices of pins, grabs and
the rest stay valid) with the same position, velocity and texture coordinate; the vertex's
mass is shared between its copies in proportion to the area of their fans, so mass and
momentum are kept exactly. Every triangle is kept (none is deleted or created): the torn
mesh is a valid mesh (every edge in one or two triangles) with the texture on both sides.

The body stays one :class:`~deforma.Body` whose :attr:`~deforma.Body.pieces` label its
connected pieces: its pins, grabs, material and scene entry stay whole, and a piece that
hangs by one triangle is still the same object. A body with springs and no triangles snaps
its over-stretched springs instead (there is no surface to tear).

The opening stretch is measured against the mesh's rest positions (a plastic material's
flow, which moves the rest shape of each element, does not move them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from .elements import _gradient, rest_geometry
from .strain import spring_strains


@dataclass(frozen=True)
class Tear:
    """A body's mesh after a tear (local indices).

    Attributes
    ----------
    triangles : (M, 3) int32
        The same triangles, in the same order, with split corners renumbered.
    source : (N', ) int64
        For every vertex of the torn mesh, the vertex it is a copy of (``source[k] = k`` for
        the first ``N`` vertices): positions, velocities, texture coordinates and pins
        follow it.
    mass_share : (N',) float64
        Share of the original vertex's mass each vertex keeps (1 for vertices not split;
        the copies of one vertex sum to 1).
    cut : (C, 2) int32
        The edges cut in this tear (vertex pairs before the split).
    """

    triangles: np.ndarray
    source: np.ndarray
    mass_share: np.ndarray
    cut: np.ndarray


@dataclass(frozen=True, eq=False)
class TearTopology:
    """What the tear check needs of a mesh, computed once per mesh.

    Attributes
    ----------
    triangles : (M, 3) int64
    pairs : (E, 2) int64
        Every edge once, ``(low, high)``, sorted by ``low * N + high``.
    tri_pair : (E, 2) int64
        The triangles on either side of each edge (``-1`` for the second on the outline).
    inner : (I,) int64
        Indices of the interior edges (two triangles).
    boundary : (N,) bool
        Vertices on the outline.
    b : (M, 4) float64
        Rest-shape inverses of the triangles.
    area : (M,) float64
        Rest areas (m^2).
    normal : (I, 2) float64
        Unit normal of each interior edge in the rest shape.
    keys : (E,) int64
        ``low * N + high`` of each edge (sorted: the lookup of :meth:`edge`).
    vertex_ptr, vertex_tris : (N + 1,), (3M,) int64
        The triangles around vertex ``v``: ``vertex_tris[vertex_ptr[v]:vertex_ptr[v + 1]]``.
    """

    triangles: np.ndarray
    pairs: np.ndarray
    tri_pair: np.ndarray
    inner: np.ndarray
    boundary: np.ndarray
    b: np.ndarray
    area: np.ndarray
    normal: np.ndarray
    keys: np.ndarray
    vertex_ptr: np.ndarray
    vertex_tris: np.ndarray

    @classmethod
    def of(cls, rest, tris) -> "TearTopology":
        """Build from rest positions (N, 2) and counter-clockwise triangles (M, 3)."""
        rest = np.asarray(rest, dtype=np.float64)
        t = np.asarray(tris, dtype=np.int64)
        n = len(rest)
        half = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
        owner = np.tile(np.arange(len(t)), 3)
        lo, hi = half.min(axis=1), half.max(axis=1)
        keys = lo * n + hi
        order = np.argsort(keys, kind="stable")
        keys, owner, lo, hi = keys[order], owner[order], lo[order], hi[order]
        first = np.ones(len(keys), bool)
        first[1:] = keys[1:] != keys[:-1]
        start = np.flatnonzero(first)
        two = np.diff(np.append(start, len(keys))) == 2
        pairs = np.stack([lo[start], hi[start]], axis=1)
        tri_pair = np.full((len(start), 2), -1, np.int64)
        tri_pair[:, 0] = owner[start]
        tri_pair[two, 1] = owner[start[two] + 1]
        boundary = np.zeros(n, bool)
        boundary[pairs[~two].ravel()] = True
        inner = np.flatnonzero(two)
        d = rest[pairs[inner, 1]] - rest[pairs[inner, 0]]
        normal = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.linalg.norm(d, axis=1)[:, None]
        b, area = rest_geometry(rest, t)
        # the triangles around each vertex (CSR)
        corner = t.ravel()
        order = np.argsort(corner, kind="stable")
        ptr = np.zeros(n + 1, np.int64)
        np.cumsum(np.bincount(corner, minlength=n), out=ptr[1:])
        return cls(t, pairs, tri_pair, inner, boundary, b, area, np.ascontiguousarray(normal),
                   pairs[:, 0] * n + pairs[:, 1], ptr, order // 3)

    def edge(self, a: int, b: int) -> int:
        """Index of edge ``(a, b)`` in ``pairs``."""
        n = len(self.boundary)
        return int(np.searchsorted(self.keys, min(a, b) * n + max(a, b)))


@njit(cache=True)
def opening_strain(x, tris, b, pairs_inner_tri, normal, out):
    """Opening strain (I,) of interior edges into ``out``; returns the largest.

    ``pairs_inner_tri`` (I, 2): the two triangles of each interior edge; ``normal`` (I, 2):
    the edge's unit rest normal. ``|F n|`` averaged over the two triangles, minus 1.
    """
    worst = -np.inf
    for e in range(normal.shape[0]):
        nx, ny = normal[e, 0], normal[e, 1]
        s = 0.0
        for side in range(2):
            t = pairs_inner_tri[e, side]
            i, j, k = tris[t, 0], tris[t, 1], tris[t, 2]
            f00, f01, f10, f11 = _gradient(x, i, j, k, b[t, 0], b[t, 1], b[t, 2], b[t, 3])
            ax = f00 * nx + f01 * ny
            ay = f10 * nx + f11 * ny
            s += (ax * ax + ay * ay) ** 0.5
        out[e] = 0.5 * s - 1.0
        if out[e] > worst:
            worst = out[e]
    return worst


def opening_strains(rest, tris, x):
    """Per interior edge: ``(pairs (I, 2), opening strain (I,))`` of triangles ``tris`` at ``x``
    with rest positions ``rest`` (see the module docstring).

    Examples
    --------
    >>> import numpy as np
    >>> rest = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> pairs, strain = opening_strains(rest, [[0, 1, 2], [0, 2, 3]], rest * [1.5, 1.0])
    >>> pairs.tolist(), strain.round(6).tolist()  # the diagonal opens by sqrt((1.5^2 + 1) / 2) - 1
    ([[0, 2]], [0.274755])
    """
    tt = TearTopology.of(rest, tris)
    out = np.empty(len(tt.inner))
    opening_strain(np.asarray(x, dtype=np.float64), tt.triangles, tt.b, tt.tri_pair[tt.inner], tt.normal, out)
    return tt.pairs[tt.inner], out


def tear_mesh(topo: TearTopology, x, tear_strain, strain=None):
    """Cut the edges stretched across beyond ``tear_strain`` and split their vertices.

    Parameters
    ----------
    topo : TearTopology
        The mesh (``TearTopology.of(rest, triangles)``).
    x : (N, 2) float64
        Current positions (m).
    tear_strain : float
        The opening strain beyond which an edge is cut.
    strain : (I,) float64, optional
        Opening strains already measured at ``x`` (:func:`opening_strain`).

    Returns
    -------
    Tear or None
        ``None`` when nothing opened.

    Examples
    --------
    >>> import numpy as np
    >>> rest = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0], [1.0, 1.0], [2.0, 1.0]])
    >>> topo = TearTopology.of(rest, [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]])
    >>> x = rest.copy(); x[[2, 5], 0] += 3.0  # pull the right column far to the right
    >>> t = tear_mesh(topo, x, 0.5)
    >>> t.cut.tolist(), t.source.tolist()  # the stretched cell's diagonal 1-5 cut: both ends split
    ([[1, 5]], [0, 1, 2, 3, 4, 5, 1, 5])
    >>> pieces(8, [], t.triangles).tolist()  # triangle (1, 2, 5) came off
    [0, 0, 1, 0, 0, 1, 1, 0]
    """
    t = topo.triangles
    n = len(topo.boundary)
    inner = topo.inner
    if strain is None:
        strain = np.empty(len(inner))
        opening_strain(np.asarray(x, dtype=np.float64), t, topo.b, topo.tri_pair[inner], topo.normal, strain)
    over = np.flatnonzero(strain > tear_strain)
    if not len(over):
        return None
    # strongest first; a cut must touch the outline to open, and each vertex takes one cut per
    # step (a crack advances an edge at a time, so the stress can move to its new tip)
    used = np.zeros(n, bool)
    cut = []
    for e in inner[over[np.argsort(-strain[over], kind="stable")]]:
        a, b = topo.pairs[e]
        if used[a] or used[b] or not (topo.boundary[a] or topo.boundary[b]):
            continue
        used[a] = used[b] = True
        cut.append(int(e))
    if not cut:
        return None
    is_cut = np.zeros(len(topo.pairs), bool)
    is_cut[cut] = True
    new_t = t.copy()
    source = list(range(n))
    share = [1.0] * n
    for v in np.unique(topo.pairs[cut].ravel()):
        groups = _fans(topo, int(v), is_cut)
        if len(groups) < 2:
            continue
        total = sum(topo.area[f] for g in groups for f in g)
        for k, members in enumerate(groups):
            part = sum(topo.area[f] for f in members) / total
            if k == 0:
                share[v] = part
                continue
            copy = len(source)
            source.append(int(v))
            share.append(part)
            for f in members:
                new_t[f][new_t[f] == v] = copy
    if len(source) == n:
        return None
    return Tear(new_t.astype(np.int32), np.array(source, np.int64), np.array(share),
                topo.pairs[cut].astype(np.int32))


def _fans(topo: TearTopology, v: int, is_cut) -> list[list[int]]:
    """The triangles around vertex ``v`` grouped into fans joined across uncut edges."""
    t = topo.triangles
    fan = [int(f) for f in topo.vertex_tris[topo.vertex_ptr[v]:topo.vertex_ptr[v + 1]]]
    parent = {f: f for f in fan}

    def find(f):
        while parent[f] != f:
            parent[f] = parent[parent[f]]
            f = parent[f]
        return f
    for f in fan:
        for w in t[f]:
            if w == v:
                continue
            e = topo.edge(v, int(w))
            g = int(topo.tri_pair[e, 1] if topo.tri_pair[e, 0] == f else topo.tri_pair[e, 0])
            if g >= 0 and not is_cut[e]:
                parent[find(f)] = find(g)
    groups = {}
    for f in fan:
        groups.setdefault(find(f), []).append(f)
    return list(groups.values())


def snap_springs(x, springs, rest_length, tear_strain):
    """Springs (E, 2) kept after snapping those stretched beyond ``tear_strain`` (a body
    without triangles); returns the mask of kept springs. The last spring never snaps.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [3.0, 0.0]])
    >>> snap_springs(x, np.array([[0, 1], [1, 2]]), np.ones(2), 0.5).tolist()
    [True, False]
    """
    s = np.asarray(springs)
    keep = spring_strains(x, s[:, 0], s[:, 1], rest_length) <= tear_strain
    if not keep.any():
        keep[np.argmin(spring_strains(x, s[:, 0], s[:, 1], rest_length))] = True
    return keep


def pieces(n_vertices: int, springs, triangles) -> np.ndarray:
    """Connected piece of every vertex (N,) int, numbered from 0 in order of first vertex.

    Examples
    --------
    >>> pieces(5, [[0, 1], [2, 3]], []).tolist()
    [0, 0, 1, 1, 2]
    """
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    e = [np.asarray(springs, dtype=np.int64).reshape(-1, 2)]
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    e += [t[:, [0, 1]], t[:, [1, 2]]]
    e = np.concatenate(e)
    g = sp.coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n_vertices, n_vertices))
    _, label = connected_components(g, directed=False)
    # renumber in order of first appearance, so piece 0 holds vertex 0
    _, first = np.unique(label, return_index=True)
    order = np.argsort(np.argsort(first))
    return order[label]

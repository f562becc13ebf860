"""Tearing: a body stretched beyond ``tear_strain`` splits along its mesh edges.

A material with ``tear_strain = t`` (``deforma.Material(..., tear_strain=0.3)``) is checked
after every step. For each interior edge of the mesh (one shared by two triangles), the
*opening stretch* is how much the material on either side is stretched across the edge:
``|F n|`` with ``n`` the edge's unit normal in the rest shape and ``F`` each neighbouring
triangle's deformation gradient (:mod:`deforma.physics.elements.triangles`), averaged over the two.
An edge whose opening strain ``|F n| - 1`` exceeds ``t`` is cut.

A cut opens only where the mesh can open: a vertex splits when the triangles around it fall
into separate fans (groups joined across uncut edges), each fan getting its own copy of the
vertex. So cracks start at the outline (or a hole) and run inward one edge per step, along
the edges most stretched across: the crack follows the stress, at the mesh's resolution.
Copies are appended after the body's vertices (the indices of pins, grabs and the rest stay
valid) with the same position, velocity and texture coordinate; the vertex's mass is shared
between its copies in proportion to the area of their fans, so mass and momentum are kept
exactly. Every triangle is kept (none is deleted or created): the torn mesh is a valid mesh
(every edge in one or two triangles) with the texture on both sides.

No cut leaves a chip: a cut that would leave fewer than ``MIN_PIECE`` triangles joined on
one side (while the other has at least as many) waits, and the triangles stay on as a flap
(:func:`_chip`).

One crack runs at a time in a body: while a crack's tip advanced in the last step, only the
tips advance, and a new crack starts (at the most stretched outline edge) only once every
tip has stopped. A real crack relieves the material beside it faster than the solver can
show within a step; without the rule, every outline vertex of a sheet stretched evenly past
``tear_strain`` started its own crack in the same step, and a sheet pulled apart by two
clamps (1e4 vertices, ``benchmarks/bench_behaviours.py``) shattered into 2172 pieces of
confetti instead of tearing across.

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

from ..elements.triangles import deformation_gradient, rest_geometry
from ..topology import counting_order, lengths, stable_order
from ..union_find import find_root
from .strain import spring_strains


@dataclass(frozen=True)
class Tear:
    """A body's mesh after a tear (local indices).

    Attributes
    ----------
    triangles : (M, 3) int64
        The same triangles, in the same order, with split corners renumbered (the dtype of
        :attr:`TearTopology.triangles`, which the torn mesh's takes over).
    source : (N', ) int64
        For every vertex of the torn mesh, the vertex it is a copy of (``source[k] = k`` for
        the first ``N`` vertices): positions, velocities, texture coordinates and pins
        follow it.
    mass_share : (N',) float64
        Share of the original vertex's mass each vertex keeps (1 for vertices not split;
        the copies of one vertex sum to 1).
    cut : (C, 2) int32
        The edges cut in this tear (vertex pairs before the split).
    tips : (K,) int64
        The cracks' tips after this tear: the far ends of the cuts that ran into the mesh
        (vertices that were inside it and are now on the outline, not split). Pass them to the
        next :func:`tear_mesh` so the cracks go on from there.
    changed : (C,) int64
        The triangles whose corners were renumbered (moved onto a copy), in order.
    """

    triangles: np.ndarray
    source: np.ndarray
    mass_share: np.ndarray
    cut: np.ndarray
    tips: np.ndarray
    changed: np.ndarray


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
    tri_edge : (M, 3) int64
        Index in ``pairs`` of each triangle's edges: corners 0-1, 1-2 and 2-0.
    inner_tri : (I, 2) int64
        ``tri_pair[inner]``: the two triangles of each interior edge, which the check reads
        every step (gathered once here: 0.2 ms a step at 1e4 vertices).
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
    tri_edge: np.ndarray
    inner_tri: np.ndarray

    @classmethod
    def of(cls, rest, tris) -> "TearTopology":
        """Build from rest positions (N, 2) and counter-clockwise triangles (M, 3)."""
        rest = np.asarray(rest, dtype=np.float64)
        t = np.asarray(tris, dtype=np.int64)
        n = len(rest)
        keys, pairs, tri_pair, two, half_edge = edge_table(n, t)
        boundary = np.zeros(n, bool)
        boundary[pairs[~two].ravel()] = True
        inner = np.flatnonzero(two)
        b, area = rest_geometry(rest, t)
        # the triangles around each vertex (CSR), in triangle order
        ptr = np.zeros(n + 1, np.int64)
        np.cumsum(np.bincount(t.ravel(), minlength=n), out=ptr[1:])
        return cls(t, pairs, tri_pair, inner, boundary, b, area, _rest_normals(rest, pairs[inner]), keys, ptr,
                   stable_order(t.ravel(), n) // 3, np.ascontiguousarray(half_edge.reshape(3, -1).T),
                   np.ascontiguousarray(tri_pair[inner]))

    def edge(self, a: int, b: int) -> int:
        """Index of edge ``(a, b)`` in ``pairs``."""
        n = len(self.boundary)
        return int(np.searchsorted(self.keys, min(a, b) * n + max(a, b)))


def _rest_normals(rest, pairs):
    """Unit normal (K, 2) of each edge ``(a, c)`` of ``pairs`` (K, 2) at rest: ``(-dy, dx) / length``."""
    a, c = pairs[:, 0], pairs[:, 1]
    length = lengths(rest, a, c)
    normal = np.empty((len(pairs), 2))
    normal[:, 0] = -(rest[c, 1] - rest[a, 1]) / length
    normal[:, 1] = (rest[c, 0] - rest[a, 0]) / length
    return normal


def _torn(topo: TearTopology, rest, cut: "Tear"):
    """The :class:`TearTopology` of the torn mesh ``cut`` (rest positions ``rest``, (N', 2)):
    the same arrays as ``TearTopology.of(rest, cut.triangles)``, patched where the tear
    changed the mesh (:func:`torn_edges`; a torn mesh keeps its triangles, in order, with
    corners at the same rest positions, so its rest geometry is the mesh's before the tear);
    and, for each edge of the torn mesh, the edge of ``topo`` it is (``-1`` for an edge of a
    split triangle: its numbers are new)."""
    rest = np.asarray(rest, dtype=np.float64)
    t = np.ascontiguousarray(cut.triangles, dtype=np.int64)
    keys, pairs, tri_pair, tri_edge, origin, ptr, vtris, boundary, inner, inner_tri, normal, fresh = torn_edges(
        topo.triangles, t, topo.pairs, topo.tri_pair, topo.tri_edge, len(rest), topo.vertex_ptr, topo.vertex_tris,
        np.ascontiguousarray(cut.source, dtype=np.int64), topo.normal)
    normal[fresh] = _rest_normals(rest, pairs[inner[fresh]])  # the rebuilt interior edges'
    tt = TearTopology(t, pairs, tri_pair, inner, boundary, topo.b, topo.area, normal, keys, ptr, vtris, tri_edge,
                      inner_tri)
    return tt, origin


def edge_table(n: int, t):
    """Every edge of triangles ``t`` (M, 3) over ``n`` vertices once, with its triangles.

    Half-edge ``h = k * M + f`` runs from corner ``k`` of triangle ``f`` to corner ``k + 1``;
    edges are ordered by ``low * n + high``, and the half-edges of one edge by ``h``.

    Returns
    -------
    keys : (E,) int64
        ``low * n + high`` of each edge, sorted.
    pairs : (E, 2) int64
        ``(low, high)`` of each edge, in that order.
    tri_pair : (E, 2) int64
        The triangles on either side (that of the lower-numbered half-edge first; ``-1`` for
        the second on the outline).
    two : (E,) bool
        Interior edges (two triangles).
    half_edge : (3M,) int64
        Edge of each half-edge, in the order ``t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]``.

    Examples
    --------
    >>> import numpy as np
    >>> keys, pairs, tri_pair, two, half_edge = edge_table(4, np.array([[0, 1, 2], [0, 2, 3]]))
    >>> pairs.tolist(), tri_pair[two].tolist(), half_edge.tolist()
    ([[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]], [[1, 0]], [0, 1, 3, 4, 1, 2])
    """
    return _edge_table(int(n), np.ascontiguousarray(t, dtype=np.int64))


@njit(cache=True)
def _edge_table(n, t):
    # one compiled pass: a counting sort of the half-edges by low vertex, then each low
    # vertex's few half-edges by high vertex (an insertion sort; both stable), then the runs
    # of equal (low, high). 0.8 ms for the 6e4 half-edges of a 1e4-vertex sheet, against
    # 4.4 ms for NumPy's sort and the gathers around it: a tear rebuilds this table.
    m = t.shape[0]
    nh = 3 * m
    lo = np.empty(nh, np.int64)
    hi = np.empty(nh, np.int64)
    for k in range(3):
        for f in range(m):
            a, b = t[f, k], t[f, (k + 1) % 3]
            if min(a, b) < 0 or max(a, b) >= n:  # Numba does not check indices: refuse rather than write astray
                raise ValueError("edge_table: a triangle's vertex outside [0, n)")
            lo[k * m + f], hi[k * m + f] = min(a, b), max(a, b)
    order = counting_order(lo, n)
    for i in range(1, nh):  # within each run of equal low vertex (few), by high vertex
        cur = order[i]
        j = i - 1
        while j >= 0 and lo[order[j]] == lo[cur] and hi[order[j]] > hi[cur]:
            order[j + 1] = order[j]
            j -= 1
        order[j + 1] = cur
    n_edges = 0
    for i in range(nh):
        if i == 0 or lo[order[i]] != lo[order[i - 1]] or hi[order[i]] != hi[order[i - 1]]:
            n_edges += 1
    keys = np.empty(n_edges, np.int64)
    pairs = np.empty((n_edges, 2), np.int64)
    tri_pair = np.full((n_edges, 2), -1, np.int64)
    count = np.zeros(n_edges, np.int64)
    half_edge = np.empty(nh, np.int64)
    e = -1
    for i in range(nh):
        h = order[i]
        if i == 0 or lo[h] != lo[order[i - 1]] or hi[h] != hi[order[i - 1]]:
            e += 1
            keys[e] = lo[h] * n + hi[h]
            pairs[e, 0], pairs[e, 1] = lo[h], hi[h]
            tri_pair[e, 0] = h % m
        elif count[e] == 1:  # the second half-edge of an edge: its other triangle
            tri_pair[e, 1] = h % m
        count[e] += 1
        half_edge[h] = e
    two = count == 2
    for e in range(n_edges):
        if not two[e]:  # an edge of three or more triangles is no interior edge either
            tri_pair[e, 1] = -1
    return keys, pairs, tri_pair, two, half_edge


@njit(cache=True)
def torn_edges(t_old, t, pairs, tri_pair, tri_edge, n, vertex_ptr, vertex_tris, source, normal):
    """:func:`edge_table` of triangles ``t`` (M, 3) over ``n`` vertices, patched from that of
    ``t_old`` (``pairs``, ``tri_pair``, ``tri_edge``; the triangles around each vertex
    ``vertex_ptr``, ``vertex_tris``; the interior edges' rest normals ``normal``): the same
    triangles with some corners renumbered (a tear), vertex ``i`` a copy of ``source[i]``.
    Only the edges of changed triangles are sorted again; the others keep their pairs,
    triangles and normals and move in one merge, and a vertex no changed triangle touches
    keeps its list of triangles.

    Returns ``(keys, pairs, tri_pair, tri_edge, origin, vertex_ptr, vertex_tris, boundary,
    inner, inner_tri, normal, fresh)``: those of :func:`edge_table` (``tri_edge`` as (M,
    3)); ``origin`` (E',) each edge's index in ``pairs`` when it is an edge of ``t_old``
    untouched by the change (else -1); the triangles around each vertex (CSR, in triangle
    order) as :meth:`TearTopology.of` lists them; :class:`TearTopology`'s ``boundary``,
    ``inner``, ``inner_tri`` and ``normal``, whose rows ``fresh`` (indices into ``inner``:
    the rebuilt interior edges) are left for the caller to measure. 0.57 ms (standalone) for
    a tear of a 1e4-vertex sheet, where :func:`edge_table` alone takes 0.8 ms.
    """
    m = t.shape[0]
    ne = pairs.shape[0]
    n_old = vertex_ptr.shape[0] - 1
    if source.shape[0] != n or n_old > n:
        raise ValueError("torn_edges: source must map each of the n vertices to an old one")
    for i in range(n):
        if source[i] < 0 or source[i] >= n_old:
            raise ValueError("torn_edges: source must map each of the n vertices to an old one")
    changed = np.zeros(m, np.bool_)
    hit = np.zeros(ne, np.bool_)  # edges of changed triangles: rebuilt
    touched = np.zeros(n_old, np.bool_)  # old corners of changed triangles: their lists change
    for f in range(m):
        for c in range(3):
            if t[f, c] < 0 or t[f, c] >= n:  # Numba does not check indices: refuse rather than write astray
                raise ValueError("torn_edges: a triangle's vertex outside [0, n)")
        if t[f, 0] != t_old[f, 0] or t[f, 1] != t_old[f, 1] or t[f, 2] != t_old[f, 2]:
            changed[f] = True
            for k in range(3):
                hit[tri_edge[f, k]] = True
                touched[t_old[f, k]] = True
    # the half-edges on rebuilt edges: all of the changed triangles', and those of unchanged
    # triangles that lie on a hit edge (an edge of three triangles included)
    hid = np.empty(3 * m, np.int64)
    hkey = np.empty(3 * m, np.int64)
    count = 0
    for k in range(3):  # in half-edge order h = k M + f, which orders an edge's triangles
        for f in range(m):
            if changed[f] or hit[tri_edge[f, k]]:
                a, b = t[f, k], t[f, (k + 1) % 3]
                hid[count] = k * m + f
                hkey[count] = min(a, b) * n + max(a, b)
                count += 1
    hid, hkey = hid[:count], hkey[:count]
    order = np.argsort(hkey, kind="mergesort")  # stable: by h within an edge
    n_new = 0
    for i in range(count):
        if i == 0 or hkey[order[i]] != hkey[order[i - 1]]:
            n_new += 1
    n_kept = 0
    for e in range(ne):
        if not hit[e]:
            n_kept += 1
    total = n_kept + n_new
    keys = np.empty(total, np.int64)
    out_pairs = np.empty((total, 2), np.int64)
    out_tri = np.full((total, 2), -1, np.int64)
    two = np.zeros(total, np.bool_)
    origin = np.full(total, -1, np.int64)
    out_edge = np.empty((m, 3), np.int64)
    moved = np.empty(ne, np.int64)  # a kept edge's new index
    boundary = np.zeros(n, np.bool_)
    inner = np.empty(total, np.int64)
    inner_tri = np.empty((total, 2), np.int64)
    out_normal = np.empty((total, 2))
    fresh = np.empty(total, np.int64)
    n_inner, n_fresh = 0, 0
    # merge the kept edges (in their order) with the rebuilt ones (sorted), both by key
    e, i, out = 0, 0, 0
    row = 0  # the interior edges of t_old before e: e's row in normal
    while out < total:
        while e < ne and hit[e]:
            if tri_pair[e, 1] >= 0:
                row += 1
            e += 1
        if e < ne and i < count and pairs[e, 0] * n + pairs[e, 1] == hkey[order[i]]:
            raise ValueError("torn_edges: t_old's edge table is not that of t_old")  # a kept edge is never rebuilt
        take_old = e < ne and (i >= count or pairs[e, 0] * n + pairs[e, 1] < hkey[order[i]])
        if take_old:
            keys[out] = pairs[e, 0] * n + pairs[e, 1]
            out_pairs[out, 0], out_pairs[out, 1] = pairs[e, 0], pairs[e, 1]
            out_tri[out, 0], out_tri[out, 1] = tri_pair[e, 0], tri_pair[e, 1]
            two[out] = tri_pair[e, 1] >= 0
            origin[out] = e
            moved[e] = out
            if two[out]:
                if row >= normal.shape[0]:  # Numba does not check indices
                    raise ValueError("torn_edges: fewer normals than interior edges")
                out_normal[n_inner, 0], out_normal[n_inner, 1] = normal[row, 0], normal[row, 1]
                row += 1
            e += 1
        else:
            key = hkey[order[i]]
            keys[out] = key
            out_pairs[out, 0], out_pairs[out, 1] = key // n, key % n
            c = 0
            while i < count and hkey[order[i]] == key:
                h = hid[order[i]]
                if c < 2:
                    out_tri[out, c] = h % m
                out_edge[h % m, h // m] = out
                c += 1
                i += 1
            two[out] = c == 2
            if c != 2:  # an edge of three or more triangles is no interior edge either
                out_tri[out, 1] = -1
            else:  # an interior edge, at n_inner below: its normal is new
                fresh[n_fresh] = n_inner
                n_fresh += 1
        if two[out]:
            inner[n_inner] = out
            inner_tri[n_inner, 0], inner_tri[n_inner, 1] = out_tri[out, 0], out_tri[out, 1]
            n_inner += 1
        else:
            boundary[out_pairs[out, 0]] = True
            boundary[out_pairs[out, 1]] = True
        out += 1
    for f in range(m):
        if not changed[f]:
            for k in range(3):
                if not hit[tri_edge[f, k]]:
                    out_edge[f, k] = moved[tri_edge[f, k]]
    # the triangles around each vertex, in triangle order: an untouched vertex keeps its list;
    # a touched one, and a copy, the triangles of its source's list that now have it
    ptr = np.zeros(n + 1, np.int64)
    vtris = np.empty(3 * m, np.int64)
    out = 0
    for v in range(n):
        s = source[v]
        if v < n_old and not touched[v]:
            if out + vertex_ptr[v + 1] - vertex_ptr[v] > 3 * m:  # Numba does not check indices
                raise ValueError("torn_edges: vertex lists longer than the triangles' corners")
            for p in range(vertex_ptr[v], vertex_ptr[v + 1]):
                vtris[out] = vertex_tris[p]
                out += 1
        else:
            for p in range(vertex_ptr[s], vertex_ptr[s + 1]):
                f = vertex_tris[p]
                if t[f, 0] == v or t[f, 1] == v or t[f, 2] == v:
                    if out >= 3 * m:  # Numba does not check indices: refuse rather than write astray
                        raise ValueError("torn_edges: vertex lists longer than the triangles' corners")
                    vtris[out] = f
                    out += 1
        ptr[v + 1] = out
    if out != 3 * m:
        raise ValueError("torn_edges: a corner of t is in no source's list of triangles")
    return (keys, out_pairs, out_tri, out_edge, origin, ptr, vtris, boundary, inner[:n_inner], inner_tri[:n_inner],
            out_normal[:n_inner], fresh[:n_fresh])


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
            f00, f01, f10, f11 = deformation_gradient(x, i, j, k, b[t, 0], b[t, 1], b[t, 2], b[t, 3])
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
    opening_strain(np.asarray(x, dtype=np.float64), tt.triangles, tt.b, tt.inner_tri, tt.normal, out)
    return tt.pairs[tt.inner], out


def tear_mesh(topo: TearTopology, x, tear_strain, strain=None, tips=()):
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
    tips : (K,) int, optional
        The running cracks' tips (``Tear.tips`` of the last step's tear; empty when the last
        step did not tear): while there are any, only they advance.

    Returns
    -------
    Tear or None
        ``None`` when nothing opened (every crack stopped).

    Examples
    --------
    >>> import numpy as np
    >>> rest = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0], [1.0, 1.0], [2.0, 1.0]])
    >>> topo = TearTopology.of(rest, [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]])
    >>> x = rest.copy(); x[[2, 5], 0] += 3.0  # pull the right column far to the right
    >>> t = tear_mesh(topo, x, 0.5)
    >>> t.cut.tolist(), t.source.tolist(), t.tips.tolist()  # the cell's diagonal 1-5 cut: both ends split
    ([[1, 5]], [0, 1, 2, 3, 4, 5, 1, 5], [])
    >>> pieces(8, [], t.triangles).tolist()  # triangle (1, 2, 5) came off (the rest is no larger a piece)
    [0, 0, 1, 0, 0, 1, 1, 0]
    """
    t = topo.triangles
    n = len(topo.boundary)
    inner = topo.inner
    if strain is None:
        strain = np.empty(len(inner))
        if opening_strain(np.asarray(x, dtype=np.float64), t, topo.b, topo.inner_tri, topo.normal,
                          strain) <= tear_strain:
            return None  # the common case: nothing near tearing
    over = np.flatnonzero(strain > tear_strain)
    if not len(over):
        return None
    # strongest first; a cut must touch the outline to open, and each vertex takes one cut per
    # step (a crack advances an edge at a time, so the stress can move to its new tip)
    is_tip = np.zeros(n, np.bool_)
    tips = np.asarray(tips, dtype=np.int64)
    is_tip[tips[(tips >= 0) & (tips < n)]] = True
    cut = _choose_cuts(inner[over[np.argsort(-strain[over], kind="stable")]], topo.pairs, topo.boundary, is_tip, n,
                       topo.tri_pair, topo.tri_edge)
    if not len(cut):
        return None
    ends = topo.pairs[cut].ravel()
    new_tips = np.unique(ends[~topo.boundary[ends]])  # cuts that ran in from the outline
    is_cut = np.zeros(len(topo.pairs), np.bool_)
    is_cut[cut] = True
    new_t, source, share, renumbered = _split_vertices(t, topo.tri_edge, topo.tri_pair, is_cut, topo.vertex_ptr,
                                           topo.vertex_tris, topo.area, np.unique(topo.pairs[cut].ravel()), n)
    if len(source) == n:
        return None
    return Tear(new_t, source, share, topo.pairs[cut].astype(np.int32), new_tips,
                np.flatnonzero(renumbered))


@njit(cache=True)
def _choose_cuts(candidates, pairs, boundary, is_tip, n, tri_pair, tri_edge):
    """Edges to cut, from ``candidates`` (strongest first): each touching the outline, no
    vertex in two cuts this step, none that would cut off a chip (:func:`_chip`); while any
    vertex ``is_tip``, only edges at a tip (the running cracks advance), else the strongest
    one (a new crack starts)."""
    running = is_tip.any()
    used = np.zeros(n, np.bool_)
    out = np.empty(len(candidates), np.int64)
    c = 0
    for e in candidates:
        a, b = pairs[e, 0], pairs[e, 1]
        if used[a] or used[b] or not (boundary[a] or boundary[b]):
            continue
        if running and not (is_tip[a] or is_tip[b]):
            continue
        if not running and c == 1:
            break
        if _chip(e, tri_pair, tri_edge):  # last: the search for the only edges that could be cut
            continue
        used[a] = True
        used[b] = True
        out[c] = e
        c += 1
    return out[:c]


#: A cut never leaves a piece of fewer triangles than this on one side while the other side
#: has at least as many: see :func:`_chip`.
MIN_PIECE = 4


@njit(cache=True)
def _chip(e, tri_pair, tri_edge):
    """Whether cutting interior edge ``e`` would cut off a chip: fewer than ``MIN_PIECE``
    triangles joined to one side across uncut edges, and at least that many on the other.

    A crack running along the outline or next to a clamp cut one or two triangles loose at a
    time, which flew about as confetti (15 single triangles off the clamped 1e4-vertex sheet
    of ``benchmarks/bench_behaviours.py`` under symplectic Euler). Such a triangle now stays,
    a flap on its last edges, as a torn cloth's frayed edge does. Both sides are searched
    no further than ``MIN_PIECE`` triangles, so the triangles found are kept in a list of
    that many (a mark per triangle of the mesh cost more to clear than the search).
    """
    size = np.zeros(2, np.int64)
    found = np.empty(MIN_PIECE, np.int64)  # the side's triangles found, the first `count`
    for side in range(2):
        found[0] = tri_pair[e, side]
        done, count = 0, 1  # found[done:count] are still to visit
        while done < count and count < MIN_PIECE:
            f = found[done]
            done += 1
            for k in range(3):
                g = tri_edge[f, k]
                if g == e or tri_pair[g, 1] < 0 or count >= MIN_PIECE:
                    continue
                h = tri_pair[g, 0] if tri_pair[g, 1] == f else tri_pair[g, 1]
                known = False
                for q in range(count):
                    known = known or found[q] == h
                if not known:
                    found[count] = h
                    count += 1
        size[side] = count
    small, large = min(size[0], size[1]), max(size[0], size[1])
    return small < MIN_PIECE and large >= MIN_PIECE


@njit(cache=True)
def _split_vertices(tris, tri_edge, tri_pair, is_cut, vertex_ptr, vertex_tris, area, verts, n):
    """Split each vertex of ``verts`` into one copy per fan (triangles around it joined across
    uncut edges): ``(triangles, source, mass share)`` of the torn mesh, and which triangles
    it renumbered (M,) bool.

    The first fan (in triangle order) keeps the vertex, each other fan gets a copy appended
    after the ``n`` vertices, vertex by vertex; a copy's share of the vertex's mass is its
    fan's area over the area of all its fans (summed fan by fan, triangle by triangle).
    """
    new_t = tris.copy()
    renumbered = np.zeros(tris.shape[0], np.bool_)
    cap = n
    for v in verts:
        cap += vertex_ptr[v + 1] - vertex_ptr[v]
    source = np.empty(cap, np.int64)
    share = np.ones(cap)
    for i in range(n):
        source[i] = i
    m = n
    for v in verts:
        p0 = vertex_ptr[v]
        k = vertex_ptr[v + 1] - p0
        parent = np.arange(k)
        for a in range(k):
            f = vertex_tris[p0 + a]
            for c in range(3):
                if tris[f, c] != v:
                    continue
                for e in (tri_edge[f, c], tri_edge[f, (c + 2) % 3]):  # the two edges at v
                    g = tri_pair[e, 1] if tri_pair[e, 0] == f else tri_pair[e, 0]
                    if g < 0 or is_cut[e]:
                        continue
                    for q in range(k):
                        if vertex_tris[p0 + q] == g:
                            parent[find_root(parent, a)] = find_root(parent, q)
                            break
        # fans numbered in order of their first triangle
        label = np.empty(k, np.int64)
        fan_of_root = np.full(k, -1, np.int64)
        fans = 0
        for a in range(k):
            r = find_root(parent, a)
            if fan_of_root[r] < 0:
                fan_of_root[r] = fans
                fans += 1
            label[a] = fan_of_root[r]
        if fans < 2:
            continue
        total = 0.0
        for g in range(fans):
            for a in range(k):
                if label[a] == g:
                    total += area[vertex_tris[p0 + a]]
        for g in range(fans):
            part = 0.0
            for a in range(k):
                if label[a] == g:
                    part += area[vertex_tris[p0 + a]]
            part = part / total
            if g == 0:
                share[v] = part
                continue
            source[m] = v
            share[m] = part
            for a in range(k):
                if label[a] == g:
                    f = vertex_tris[p0 + a]
                    for c in range(3):
                        if new_t[f, c] == v:
                            new_t[f, c] = m
                            renumbered[f] = True
            m += 1
    return new_t, source[:m], share[:m], renumbered


def torn_topologies(topology, tear_topology: TearTopology, cut: Tear):
    """A torn body's new ``(BodyTopology, TearTopology)`` from its old ones and the tear ``cut``.

    The same arrays as ``BodyTopology.from_arrays(rest, edges of the triangles, triangles,
    mass_share=...)`` and ``TearTopology.of(rest, triangles)`` of the torn mesh, made from one
    edge table and the triangles' rest geometry before the tear (a torn mesh keeps its
    triangles in order, with corners at the same rest positions, so none of them turns or
    changes shape): no validation, no second sort.
    """
    from ..topology import BodyTopology

    src = cut.source
    rest = np.take(topology.rest_positions, src, axis=0)  # rows: 15x faster than rest_positions[src]
    n = topology.n_vertices
    share = (np.full(n, 1.0 / n) if topology.mass_share is None else topology.mass_share)[src]
    share = share * cut.mass_share
    tt, origin = _torn(tear_topology, rest, cut)
    rest_length = None
    if _same_pairs(topology.springs, tear_topology.pairs):  # its springs are its triangles' edges
        # a kept edge keeps its rest length; the new ones are measured as _trusted measures them
        rest_length = np.take(topology.spring_rest_length, np.maximum(origin, 0))
        new = np.flatnonzero(origin < 0)
        rest_length[new] = lengths(rest, tt.pairs[new, 0], tt.pairs[new, 1])
    body = BodyTopology._trusted(rest, tt.pairs, cut.triangles, _outline_edges(tt.triangles, tt.tri_edge, tt.tri_pair),
                                 mass_share=share, geometry=(tt.b, tt.area), spring_rest_length=rest_length,
                                 before=topology)
    return body, tt


@njit(cache=True)
def _same_pairs(a, b):
    """``np.array_equal(a, b)`` for (E, 2) integer arrays of any two dtypes, in one pass
    without temporaries."""
    if a.shape[0] != b.shape[0] or a.shape[1] != b.shape[1]:
        return False
    for i in range(a.shape[0]):
        for k in range(a.shape[1]):
            if a[i, k] != b[i, k]:
                return False
    return True


@njit(cache=True)
def _outline_edges(t, tri_edge, tri_pair):
    """The half-edges (B, 2) of triangles ``t`` that lie in one triangle, in half-edge order
    (``k M + f``: corners 0-1 of every triangle, then 1-2, then 2-0). Found from the edges
    (``tri_pair``'s second triangle -1; a mesh has no edge of three), whose few half-edges
    are then sorted, rather than by reading the edge of every half-edge."""
    m = t.shape[0]
    count = 0
    for e in range(tri_pair.shape[0]):
        if tri_pair[e, 1] < 0:
            count += 1
    half = np.empty(count, np.int64)
    q = 0
    for e in range(tri_pair.shape[0]):
        if tri_pair[e, 1] < 0:
            f = tri_pair[e, 0]
            k = 0 if tri_edge[f, 0] == e else (1 if tri_edge[f, 1] == e else 2)
            half[q] = k * m + f
            q += 1
    half.sort()
    out = np.empty((count, 2), np.int64)
    for q in range(count):
        f, k = half[q] % m, half[q] // m
        out[q, 0], out[q, 1] = t[f, k], t[f, (k + 1) % 3]
    return out


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

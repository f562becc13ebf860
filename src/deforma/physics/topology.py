"""What a body is made of, before any parameter: its rest positions, springs, triangles and
outline (:class:`BodyTopology`), and the ordering and geometry helpers that build it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from .contact.clearance import clear_against, rest_clearance
from .elements.triangles import rest_geometry


def lengths(x, i, j) -> np.ndarray:
    """``|x[j] - x[i]|`` per row: the same numbers as ``np.linalg.norm(x[j] - x[i], axis=1)``
    (which squares, adds the two and takes the root too) in a third of its time."""
    dx = x[j, 0] - x[i, 0]
    dy = x[j, 1] - x[i, 1]
    return np.sqrt(dx * dx + dy * dy)


def stable_order(keys, bound):
    """``np.argsort(keys, kind="stable")`` for non-negative integer keys below ``bound``.

    Keys below a few times their number (vertex indices: a mesh's triangles by vertex) are
    counted into buckets (:func:`counting_order`, one pass: 0.1 against 0.24 ms for the 2e4
    triangles of a 1e4-vertex sheet). Others sort ``key * len + position``: one plain sort
    of distinct integers gives the same order about 10x faster than NumPy's stable argsort
    (timsort for 64-bit integers: 1.4 ms against 0.12 ms for the 14 400 half-edges of a
    2500-vertex sheet), which a tear pays for every rebuilt topology.

    Examples
    --------
    >>> stable_order([3, 1, 3, 0, 1], 4).tolist()
    [3, 1, 4, 0, 2]
    """
    keys = np.asarray(keys, dtype=np.int64)
    m = len(keys)
    if m and bound <= 4 * m + 1024:
        return counting_order(keys, int(bound))
    if m == 0 or bound * m >= 2 ** 62:  # the combined key would overflow: the slow way
        return np.argsort(keys, kind="stable")
    return np.sort(keys * m + np.arange(m, dtype=np.int64)) % m


@njit(cache=True)
def counting_order(keys, bound):
    """Stable order (M,) int64 of integer ``keys`` in ``[0, bound)``: a counting sort."""
    start = np.zeros(bound + 1, np.int64)
    for k in keys:
        if k < 0 or k >= bound:  # Numba does not check indices: refuse rather than write astray
            raise ValueError("stable_order: a key outside [0, bound)")
        start[k + 1] += 1
    for v in range(bound):
        start[v + 1] += start[v]
    order = np.empty(keys.shape[0], np.int64)
    for i in range(keys.shape[0]):
        k = keys[i]
        order[start[k]] = i
        start[k] += 1
    return order


@dataclass(frozen=True, eq=False)
class BodyTopology:
    """The constant shape of one body, in body-local vertex indices.

    Attributes
    ----------
    rest_positions : (N, 2) float64
        Vertex positions in metres at rest (the mesh, as placed in the world).
    springs : (E, 2) int32
        Unique vertex pairs joined by a spring.
    spring_rest_length : (E,) float64
        Rest length of each spring in metres (its length in ``rest_positions``).
    triangles : (M, 3) int32
        Triangles, counter-clockwise; may be empty (a chain of springs).
    boundary_edges : (B, 2) int32
        Edges used by one triangle, directed with the body on their left (outer outlines
        counter-clockwise, holes clockwise); empty without triangles.
    boundary_vertices : (V,) int32
        The vertices on those edges, sorted: the body's outline.
    boundary_clearance : (V,) float64
        Per boundary vertex, at rest: how far it lies in front of the nearest other boundary
        edge (``inf`` beyond twice the shortest boundary edge); see
        :func:`deforma.physics.contact.clearance.rest_clearance`. Caps the self-contact thickness so
        that a body at rest never touches itself.
    mass_share : (N,) float64 or None
        Share of the springs body's mass each vertex carries, summing to 1; ``None``: equal
        shares (the original's ``mass / N``). A torn body keeps each split vertex's mass
        divided among its copies (:mod:`deforma.physics.behaviours.tearing`).
    geometry : ((M, 4), (M,)) float64 or None
        The triangles' rest-shape inverses and rest areas in ``triangles`` order, when known
        already (a torn body's: its triangles keep the shape they had before the tear);
        ``None``: :func:`element_geometry` computes them.

    Examples
    --------
    >>> import numpy as np
    >>> t = BodyTopology.from_arrays([[0, 0], [1, 0], [0, 1]], [[0, 1], [1, 2], [0, 2]])
    >>> t.spring_rest_length.round(3).tolist()
    [1.0, 1.0, 1.414]
    """

    rest_positions: np.ndarray
    springs: np.ndarray
    spring_rest_length: np.ndarray
    triangles: np.ndarray
    boundary_edges: np.ndarray
    boundary_vertices: np.ndarray
    boundary_clearance: np.ndarray
    mass_share: np.ndarray | None = None
    geometry: tuple | None = None

    @classmethod
    def from_arrays(cls, vertices, springs, triangles=None, *, mass_share=None) -> "BodyTopology":
        """Validate vertices and spring pairs and measure rest lengths.

        Raises
        ------
        ValueError
            If shapes are wrong, values are not finite, an index is out of range, a spring
            joins a vertex to itself or has zero rest length.
        """
        x = np.array(vertices, dtype=np.float64)
        if x.ndim != 2 or x.shape[1] != 2 or x.shape[0] < 2:
            raise ValueError(f"vertices must be an (N, 2) array with N >= 2, got shape {x.shape}")
        if not np.all(np.isfinite(x)):
            raise ValueError("vertices must be finite (no NaN or inf)")
        s = np.asarray(springs)
        if s.ndim != 2 or s.shape[1] != 2 or s.shape[0] < 1:
            raise ValueError(f"springs/edges must be an (E, 2) integer array with E >= 1, got shape {s.shape}")
        if not np.issubdtype(s.dtype, np.integer):
            raise ValueError(f"springs/edges must hold integers, got dtype {s.dtype}")
        if s.min() < 0 or s.max() >= len(x):
            raise ValueError(f"spring vertex indices must lie in [0, {len(x) - 1}]")
        s = np.sort(s.astype(np.int64), axis=1)
        # unique pairs by one integer key (np.unique(axis=0) sorts rows as bytes: 10x slower)
        s = np.unique(s[:, 0] * len(x) + s[:, 1])
        s = np.stack([s // len(x), s % len(x)], axis=1).astype(np.int32)
        if np.any(s[:, 0] == s[:, 1]):
            raise ValueError("a spring must join two different vertices")
        rest = lengths(x, s[:, 0], s[:, 1])
        if np.any(rest <= 0.0):
            raise ValueError("every spring must have a positive rest length (two vertices coincide)")
        if triangles is None:
            t = np.zeros((0, 3), np.int32)
        else:
            t = np.array(triangles, dtype=np.int32).reshape(-1, 3)  # a copy: oriented below
            if t.size and (t.min() < 0 or t.max() >= len(x)):
                raise ValueError(f"triangle vertex indices must lie in [0, {len(x) - 1}]")
            # counter-clockwise, as a Mesh stores them (any object with triangles is accepted)
            a, b, c = x[t[:, 0]], x[t[:, 1]], x[t[:, 2]]
            cw = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
            t[cw] = t[cw][:, [0, 2, 1]]
        edges, verts, clearance = _boundary(x, t)
        return cls(x, np.ascontiguousarray(s), rest, t, edges, verts, clearance, mass_share)

    @classmethod
    def _trusted(cls, x, springs, triangles, boundary_edges, *, mass_share=None, geometry=None,
                 spring_rest_length=None, before=None) -> "BodyTopology":
        """A topology from arrays known to be valid: what :meth:`from_arrays` would make of
        ``(x, springs, triangles)`` when ``springs`` are already unique ``(low, high)`` pairs
        sorted by ``low * N + high``, ``triangles`` counter-clockwise and ``boundary_edges``
        the edges in one triangle, directed and ordered as :func:`_boundary` finds them. A
        torn body (:mod:`deforma.physics.behaviours.tearing`) has these from its tear and skips the
        checks and sorts of :meth:`from_arrays`, most of the cost of a tear;
        ``spring_rest_length``, when given, the springs' lengths in ``x`` as measured here;
        ``before``, the topology a tear made this one from (see :func:`_outline`)."""
        x = np.asarray(x, dtype=np.float64)
        s = np.ascontiguousarray(springs, dtype=np.int32)
        rest = lengths(x, s[:, 0], s[:, 1]) if spring_rest_length is None else spring_rest_length
        t = np.array(triangles, dtype=np.int32)  # its own, as from_arrays makes it
        edges, verts, clearance = _outline(x, np.ascontiguousarray(boundary_edges, dtype=np.int32), before)
        return cls(x, s, rest, t, edges, verts, clearance, mass_share, geometry)

    @property
    def n_vertices(self) -> int:
        """Number of vertices."""
        return len(self.rest_positions)

    @property
    def n_springs(self) -> int:
        """Number of springs."""
        return len(self.springs)

    @property
    def boundary_edge_lengths(self) -> np.ndarray:
        """(B,) float64: rest length of each boundary edge, m."""
        x, e = self.rest_positions, self.boundary_edges
        return lengths(x, e[:, 0], e[:, 1])


def triangles_under(x: np.ndarray, triangles: np.ndarray, point, tolerance: float = 0.0) -> np.ndarray:
    """(M,) bool: which ``triangles`` of the positions ``x`` hold ``point`` (edges included;
    ``tolerance`` widens them by that share of twice each triangle's area, for a point put
    on an edge whose rounding would decide it).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    >>> t = np.array([[0, 1, 2], [1, 3, 2]])
    >>> triangles_under(x, t, (0.2, 0.2)).tolist(), triangles_under(x, t, (0.5, 0.5)).tolist()
    ([True, False], [True, True])
    """
    p = np.asarray(point, dtype=np.float64)
    a, b, c = x[triangles[:, 0]], x[triangles[:, 1]], x[triangles[:, 2]]

    def side(o, q):  # twice the signed area of (o, q, p)
        return (q[:, 0] - o[:, 0]) * (p[1] - o[:, 1]) - (q[:, 1] - o[:, 1]) * (p[0] - o[:, 0])

    d1, d2, d3 = side(a, b), side(b, c), side(c, a)
    slack = tolerance * np.abs(d1 + d2 + d3)  # d1 + d2 + d3 is twice the triangle's area
    return (((d1 >= -slack) & (d2 >= -slack) & (d3 >= -slack))
            | ((d1 <= slack) & (d2 <= slack) & (d3 <= slack)))


def element_geometry(topology: BodyTopology):
    """A body's triangles as finite elements: ``(triangles, B, rest areas, lumped vertex areas,
    order)``, ``order`` (M,) each element's row in ``topology.triangles``.

    Triangles are sorted by their lowest vertex (a run of them touches a narrow band of
    vertices); ``B`` and the areas come from :func:`~deforma.physics.elements.triangles.rest_geometry`;
    each vertex gets a third of the area of each triangle around it (m^2).

    Raises
    ------
    ValueError
        The body has no triangles, a triangle has zero area, or a vertex is a corner of no
        triangle (it would have no mass): the message says which and what to do.
    """
    t = topology
    if not len(t.triangles):
        raise ValueError("a finite-element material needs a mesh with triangles; this body has only springs "
                         "(use the 'springs' material)")
    # rest_geometry gives the same numbers row by row, in any order of the rows
    bmat, area = t.geometry if t.geometry is not None else rest_geometry(t.rest_positions, t.triangles)
    tri, bmat, area, lumped, order = _sorted_elements(t.triangles, np.ascontiguousarray(bmat),
                                                      np.ascontiguousarray(area), t.n_vertices)
    if not np.all(lumped > 0):
        k = int(np.flatnonzero(lumped <= 0)[0])
        raise ValueError(f"vertex {k} belongs to no triangle: a finite-element body gets its mass from "
                         f"its triangles' area, so every vertex must be a corner of one (or use the "
                         f"'springs' material)")
    return tri, bmat, area, lumped, order


def _boundary(x: np.ndarray, t: np.ndarray):
    """Directed boundary edges, boundary vertices and their rest clearances of one body
    (counter-clockwise triangles ``t``)."""
    if len(t) == 0:
        return np.zeros((0, 2), np.int32), np.zeros(0, np.int32), np.zeros(0)
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]).astype(np.int64)
    lo, hi = directed.min(axis=1), directed.max(axis=1)
    _, inverse, counts = np.unique(lo * len(x) + hi, return_inverse=True, return_counts=True)
    return _outline(x, np.ascontiguousarray(directed[counts[inverse.ravel()] == 1], dtype=np.int32))


@njit(cache=True)
def _sorted_elements(c, b, area, n):
    """Triangles ``c`` (M, 3) over ``n`` vertices, their ``b`` (M, 4) and ``area`` (M,) in
    the order of their lowest vertex (stable), each vertex's third of its triangles' areas
    (:func:`lumped_areas`), and the order: one compiled pass each, where NumPy's gathers and
    bincount took 0.7 ms for a 1e4-vertex sheet."""
    m = c.shape[0]
    lumped = np.zeros(n)
    lumped_areas(c, area, lumped)  # checks the indices too
    low = np.empty(m, np.int64)
    for f in range(m):
        low[f] = min(c[f, 0], c[f, 1], c[f, 2])
    order = counting_order(low, n)
    tri = np.empty((m, 3), c.dtype)
    bs = np.empty((m, 4))
    ar = np.empty(m)
    for i in range(m):
        f = order[i]
        for k in range(3):
            tri[i, k] = c[f, k]
        for k in range(4):
            bs[i, k] = b[f, k]
        ar[i] = area[f]
    return tri, bs, ar, lumped, order


@njit(cache=True)
def lumped_areas(c, area, out):
    """Add a third of each triangle's ``area`` to each of its corners ``c`` (M, 3) in
    ``out``, triangle by triangle in row order: the same sums however the elements are
    ordered (a torn body keeps its order, a new one is sorted)."""
    n = out.shape[0]
    for f in range(c.shape[0]):
        third = area[f] / 3.0
        for k in range(3):
            if c[f, k] < 0 or c[f, k] >= n:  # Numba does not check indices: refuse rather than write astray
                raise ValueError("lumped areas: a triangle's vertex outside [0, n)")
            out[c[f, k]] += third


def _outline(x: np.ndarray, edges: np.ndarray, before=None):
    """Boundary edges (B, 2) int32, boundary vertices and their rest clearances of one body.

    ``before``: the topology this one was torn from (vertex ``i`` of it is vertex ``i``
    here, at the same rest position; copies come after): a vertex that no outline edge the
    tear added or removed comes near keeps its clearance (:func:`_torn_clearance`).
    """
    verts = np.unique(edges).astype(np.int32)
    if len(edges) == 0:
        return edges, verts, np.zeros(0)
    reach = 2.0 * float(lengths(x, edges[:, 0], edges[:, 1]).min())
    local = np.searchsorted(verts, edges).astype(np.int32)
    if before is not None and len(before.boundary_edges) and reach == 2.0 * float(before.boundary_edge_lengths.min()):
        changed = _changed_edges(edges, before.boundary_edges, len(x))
        return edges, verts, _torn_clearance(np.take(x, verts, axis=0), local, reach, verts, changed, x,
                                             before.boundary_vertices, before.boundary_clearance)
    return edges, verts, _clearance(np.take(x, verts, axis=0), local, reach)


@njit(cache=True)
def _changed_edges(new, old, n):
    """The directed edges (K, 2) in one of ``new`` and ``old`` (vertex numbers below ``n``)
    but not in both: one sort of each and a merge (``np.isin`` twice took 0.2 ms for the
    500 outline edges of a torn 1e4-vertex sheet)."""
    a = np.sort(new[:, 0].astype(np.int64) * n + new[:, 1])
    b = np.sort(old[:, 0].astype(np.int64) * n + old[:, 1])
    out = np.empty((a.shape[0] + b.shape[0], 2), np.int64)
    i = j = k = 0
    while i < a.shape[0] or j < b.shape[0]:
        if j >= b.shape[0] or (i < a.shape[0] and a[i] < b[j]):
            key = a[i]
            i += 1
        elif i >= a.shape[0] or b[j] < a[i]:
            key = b[j]
            j += 1
        else:  # in both
            i += 1
            j += 1
            continue
        out[k, 0], out[k, 1] = key // n, key % n
        k += 1
    return out[:k]


@njit(cache=True)
def _torn_clearance(xv, edges, reach, verts, changed, x, old_verts, old_clearance):
    """:func:`_clearance` of a torn body's outline (``xv`` its vertices' rest positions,
    ``edges`` local, ``verts`` their vertex numbers) from the outline before the tear
    (``old_verts``, ``old_clearance``; the same ``reach``): ``changed`` (K, 2) are the outline
    edges the tear added or removed, in vertex numbers (positions ``x``). A vertex that was
    on the outline before and lies beyond ``reach`` of every changed edge's box sees the
    same edges within reach as before, so it keeps its clearance, the same number (a
    minimum of the same distances); every other vertex tries every edge, as
    :func:`~deforma.physics.contact.clearance.rest_clearance` does."""
    nv = verts.shape[0]
    out = np.full(nv, np.inf)
    for p in range(nv):
        v = verts[p]
        px, py = xv[p, 0], xv[p, 1]
        near = False
        for j in range(changed.shape[0]):
            ax, ay, bx, by = x[changed[j, 0], 0], x[changed[j, 0], 1], x[changed[j, 1], 0], x[changed[j, 1], 1]
            if min(ax, bx) - reach <= px <= max(ax, bx) + reach and min(ay, by) - reach <= py <= max(ay, by) + reach:
                near = True
                break
        k = np.searchsorted(old_verts, v)
        if not near and k < old_verts.shape[0] and old_verts[k] == v:
            out[p] = old_clearance[k]
            continue
        for j in range(edges.shape[0]):
            clear_against(xv, p, edges[j, 0], edges[j, 1], reach, out)
    return out


def _clearance(x, edges, reach):
    """:func:`~deforma.physics.contact.clearance.rest_clearance`, the same numbers, through a grid.

    ``rest_clearance`` tries every outline edge against every outline vertex: for the long
    outline of a torn sheet (1e4 vertices torn into 1500 pieces: 7000 outline vertices) that
    was 125 ms a tear, most of it. Here each edge is listed in the grid cells its box, grown
    by ``reach``, covers, and each vertex tries the edges of its own cell only: every edge
    ``rest_clearance`` would not skip for it (cell indices are monotonic in the coordinates),
    with the same arithmetic, so each vertex gets the same minimum of the same distances.
    """
    if len(x) < 64:
        return rest_clearance(x, edges, reach)
    extent = x.max(axis=0) - x.min(axis=0)
    # about two vertices a cell on average, never below reach (an edge then spans few cells)
    size = max(float(np.sqrt(max(extent[0] * extent[1], extent.max() * reach) * 2.0 / len(x))), reach)
    return _clearance_grid(x, edges, reach, size)


@njit(cache=True)
def _clearance_grid(x, edges, reach, size):
    lo0, lo1 = x[:, 0].min(), x[:, 1].min()
    nx = int(np.floor((x[:, 0].max() - lo0) / size)) + 1
    ny = int(np.floor((x[:, 1].max() - lo1) / size)) + 1
    ne = edges.shape[0]
    box = np.empty((ne, 4), np.int64)  # first and last cell of each edge's grown box
    ptr = np.zeros(nx * ny + 1, np.int64)
    for j in range(ne):
        ax, ay, bx, by = x[edges[j, 0], 0], x[edges[j, 0], 1], x[edges[j, 1], 0], x[edges[j, 1], 1]
        box[j, 0] = max(int(np.floor((min(ax, bx) - reach - lo0) / size)), 0)
        box[j, 1] = min(int(np.floor((max(ax, bx) + reach - lo0) / size)), nx - 1)
        box[j, 2] = max(int(np.floor((min(ay, by) - reach - lo1) / size)), 0)
        box[j, 3] = min(int(np.floor((max(ay, by) + reach - lo1) / size)), ny - 1)
        for cx in range(box[j, 0], box[j, 1] + 1):
            for cy in range(box[j, 2], box[j, 3] + 1):
                ptr[cx * ny + cy + 1] += 1
    for c in range(nx * ny):
        ptr[c + 1] += ptr[c]
    fill = ptr[:-1].copy()
    cell_edges = np.empty(ptr[-1], np.int64)
    for j in range(ne):
        for cx in range(box[j, 0], box[j, 1] + 1):
            for cy in range(box[j, 2], box[j, 3] + 1):
                cell_edges[fill[cx * ny + cy]] = j
                fill[cx * ny + cy] += 1
    out = np.full(x.shape[0], np.inf)
    for p in range(x.shape[0]):
        px, py = x[p, 0], x[p, 1]
        c = int(np.floor((px - lo0) / size)) * ny + int(np.floor((py - lo1) / size))
        for k in range(ptr[c], ptr[c + 1]):
            j = cell_edges[k]
            clear_against(x, p, edges[j, 0], edges[j, 1], reach, out)
    return out


def off_outline(t: BodyTopology) -> np.ndarray:
    """The vertices of a body with triangles that are not on its outline, sorted (int32)."""
    if not len(t.triangles):
        return np.zeros(0, np.int32)
    keep = np.ones(t.n_vertices, bool)
    keep[t.boundary_vertices] = False
    return np.flatnonzero(keep).astype(np.int32)

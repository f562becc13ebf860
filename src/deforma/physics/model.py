"""Constant topology and parameters of the soft bodies: springs or triangle elements, masses, pins.

A :class:`Model` is everything a step reads but never writes. It concatenates all bodies
of a world into flat arrays (global vertex, spring and element indices) so that one kernel
call advances every body; ``body_vertex_offsets`` / ``body_spring_offsets`` /
``body_elem_offsets`` say where each body starts. A body of the springs material has
springs and no elements; a finite-element body (``deforma.Material``) has elements and no
springs. Parameters (mass, stiffness, damping, material constants, pins) can change live,
topology (and springs <-> elements) only by rebuilding.

Units: metres, kilograms, newtons per metre (stiffness), newton-seconds per metre (damping),
pascals (Lamé parameters), seconds (element damping).
"""

from __future__ import annotations

import uuid
from dataclasses import dataclass

import numpy as np
from numba import njit

from .elements import rest_geometry
from .contacts import COLLIDE, SELF_COLLIDE, SIDE_MARGIN, SPECULATIVE, ContactTopology, clear_against, rest_clearance


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


def first_index(source, n_old) -> np.ndarray:
    """For each of ``n_old`` old vertices, the lowest ``i`` with ``source[i]`` equal to it
    (-1 where none): after a tear, the vertex itself rather than one of its copies.

    Examples
    --------
    >>> first_index(np.array([0, 1, 2, 1, 2]), 4).tolist()
    [0, 1, 2, -1]
    """
    first = np.full(n_old, -1, np.int64)
    first[source[::-1]] = np.arange(len(source) - 1, -1, -1)  # the last write, the lowest index, stays
    return first


@njit(cache=True, inline="always")
def sort_few(keys, count):
    """Sort ``keys[:count]`` in place: an insertion sort, for the few rows of one column."""
    for a in range(1, count):
        r = keys[a]
        q = a - 1
        while q >= 0 and keys[q] > r:
            keys[q + 1] = keys[q]
            q -= 1
        keys[q + 1] = r


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
        :func:`deforma.physics.contacts.rest_clearance`. Caps the self-contact thickness so
        that a body at rest never touches itself.
    mass_share : (N,) float64 or None
        Share of the springs body's mass each vertex carries, summing to 1; ``None``: equal
        shares (the original's ``mass / N``). A torn body keeps each split vertex's mass
        divided among its copies (:mod:`deforma.physics.tearing`).
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
        torn body (:mod:`deforma.physics.tearing`) has these from its tear and skips the
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


def element_geometry(topology: BodyTopology):
    """A body's triangles as finite elements: ``(triangles, B, rest areas, lumped vertex areas,
    order)``, ``order`` (M,) each element's row in ``topology.triangles``.

    Triangles are sorted by their lowest vertex (a run of them touches a narrow band of
    vertices); ``B`` and the areas come from :func:`~deforma.physics.elements.rest_geometry`;
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
    (:func:`_lumped`), and the order: one compiled pass each, where NumPy's gathers and
    bincount took 0.7 ms for a 1e4-vertex sheet."""
    m = c.shape[0]
    lumped = np.zeros(n)
    _lumped(c, area, lumped)  # checks the indices too
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
def _lumped(c, area, out):
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
    :func:`~deforma.physics.contacts.rest_clearance` does."""
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
    """:func:`~deforma.physics.contacts.rest_clearance`, the same numbers, through a grid.

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


def _off_outline(t: BodyTopology) -> np.ndarray:
    """The vertices of a body with triangles that are not on its outline, sorted (int32)."""
    if not len(t.triangles):
        return np.zeros(0, np.int32)
    keep = np.ones(t.n_vertices, bool)
    keep[t.boundary_vertices] = False
    return np.flatnonzero(keep).astype(np.int32)


class Model:
    """All bodies' constant arrays, concatenated, as the kernels read them.

    Attributes
    ----------
    vertex_mass, vertex_inv_mass : (N,) float64
        Mass of each vertex in kg (a body's total mass / its vertex count) and its inverse.
    spring_i, spring_j : (E,) int32
        Global vertex indices of each spring's ends.
    spring_rest_length : (E,) float64
        Rest lengths in metres.
    spring_stiffness : (E,) float64
        Spring constants ``ks`` in N/m.
    spring_damping : (E,) float64
        Damping constants ``kd`` in N*s/m (acting on the relative velocity along the spring).
    body_vertex_offsets, body_spring_offsets, body_elem_offsets : (B + 1,) int64
        Where each body's vertices, springs and elements start. A body of a finite-element
        material has elements and no springs; a springs body has springs and no elements.
    elem : (T, 3) int32
        Triangle elements (global vertex indices, counter-clockwise at rest), each body's
        sorted by their lowest vertex (so a run of elements touches a narrow band of
        vertices); a torn body's keep the order they had (a few renumbered corners aside,
        the same band). ``elem_source`` (T,) int64: each element's row in its body's
        ``topology.triangles``.
    elem_b : (T, 4) float64
        Rest-shape inverses ``B`` (row-major, 1/m); see :mod:`deforma.physics.elements`.
    elem_area : (T,) float64
        Rest areas (m^2).
    elem_mu, elem_lambda, elem_damping : (T,) float64
        Plane-stress Lamé parameters (Pa) and damping (s) of each element's material.
    elem_kind : (T,) int32
        ``material.KIND_COROTATED`` or ``KIND_NEO_HOOKEAN``.
    vertex_area : (N,) float64
        Lumped rest area per vertex of finite-element bodies (a third of each triangle
        around it, m^2; 0 for springs bodies): its mass is ``density * vertex_area``.
    pinned : (N,) bool
        Pinned vertices: they keep their position (``vertex_inv_mass`` 0, infinite mass).
    spring_rest_length0, elem_b0, elem_area0 : arrays
        The rest shape as built: plasticity (:mod:`deforma.physics.plasticity`) moves
        ``spring_rest_length``, ``elem_b`` and ``elem_area`` and bounds them against these.
    version : int
        Incremented by every change of a parameter or rest shape made in place (the
        ``set_*`` methods, plasticity): a solver that keeps something built from the
        Model (a factored matrix) compares it instead of the arrays.
    serial : int
        A number no other Model has (a random 128-bit identifier; a copy made by
        ``copy.deepcopy`` or a pickle keeps it).
    torn_from : (int, (N,) int64, (N,) bool, int) or None
        Set by the world when a tear rebuilt this Model from another: that Model's
        ``serial``; for each vertex the vertex of that Model it comes from (a copy or
        itself); the vertices whose springs or elements the tear changed (the corners of
        the triangles it renumbered, the ends of the springs it snapped: every other vertex
        has the same ones, in the same order); and this Model's ``version`` then. A solver
        that keeps something built for the old Model (implicit Euler's factor and matrix)
        carries it over instead of starting again.
    pressure_a, pressure_b : (P,) int32
        Directed outline edges (global vertex indices, gas on the left) of the bodies that
        hold a gas (:mod:`deforma.physics.pressure`); ``body_pressure_offsets`` (B + 1,) says
        where each body's start.
    body_pressure, body_pressure_area : (B,) float64
        Each body's gas pressure at rest (N/m; 0 without gas) and the enclosed area at rest
        (m^2).
    contact : ContactTopology
        Every body as the contact stage reads it (outline and other vertices, outline edges,
        triangles, per-vertex contact thickness, per-body flags, thickness and friction);
        see :mod:`deforma.physics.contacts`.

    The constructor takes the bodies' topologies and parameters (lists, one entry per body);
    ``torn``, a dict from a finite-element body to ``(Model before, its index there)`` when a
    tear made the body's topology from that one's, builds that body's elements from the
    Model before (the same elements in the same order, with the rest shape plasticity
    moved) instead of from its topology.

    Examples
    --------
    >>> t = BodyTopology.from_arrays([[0, 0], [1, 0], [0, 1]], [[0, 1], [1, 2], [0, 2]])
    >>> m = Model([t], masses=[3.0], stiffness=[100.0], damping=[0.0])
    >>> m.vertex_mass.tolist(), m.spring_i.tolist(), m.spring_j.tolist()
    ([1.0, 1.0, 1.0], [0, 0, 1], [1, 2, 2])
    """

    def __init__(self, topologies, *, masses, stiffness, damping, materials=None, pinned=None, contact=None,
                 pressure=None, torn=None):
        self.topologies = list(topologies)
        self.version = 0
        self.serial = uuid.uuid4().int  # unique across processes too (a pickled world's Models)
        self.torn_from = None
        self._attachments = {}  # body -> its long-range attachments, until the pins change
        nb = len(self.topologies)
        materials = [None] * nb if materials is None else list(materials)
        fem = [m is not None and m.is_fem for m in materials]
        nv = [t.n_vertices for t in self.topologies]
        ne = [0 if f else t.n_springs for t, f in zip(self.topologies, fem)]
        nt = [len(t.triangles) if f else 0 for t, f in zip(self.topologies, fem)]
        self.body_vertex_offsets = np.zeros(nb + 1, np.int64)
        self.body_spring_offsets = np.zeros(nb + 1, np.int64)
        self.body_elem_offsets = np.zeros(nb + 1, np.int64)
        np.cumsum(nv, out=self.body_vertex_offsets[1:])
        np.cumsum(ne, out=self.body_spring_offsets[1:])
        np.cumsum(nt, out=self.body_elem_offsets[1:])
        n, e, ntot = int(self.body_vertex_offsets[-1]), int(self.body_spring_offsets[-1]), int(self.body_elem_offsets[-1])

        self.spring_i = np.empty(e, np.int32)
        self.spring_j = np.empty(e, np.int32)
        self.spring_rest_length = np.empty(e, np.float64)
        self.elem = np.empty((ntot, 3), np.int32)
        self.elem_b = np.empty((ntot, 4), np.float64)
        self.elem_area = np.empty(ntot, np.float64)
        self.elem_source = np.empty(ntot, np.int64)
        self.vertex_area = np.zeros(n, np.float64)
        self.elem_b0 = np.empty((ntot, 4), np.float64)
        self.elem_area0 = np.empty(ntot, np.float64)
        torn = torn or {}
        for b, t in enumerate(self.topologies):
            s0, s1 = self.body_spring_offsets[b], self.body_spring_offsets[b + 1]
            v0 = self.body_vertex_offsets[b]
            if not fem[b]:
                self.spring_i[s0:s1] = t.springs[:, 0] + v0
                self.spring_j[s0:s1] = t.springs[:, 1] + v0
                self.spring_rest_length[s0:s1] = t.spring_rest_length
                continue
            t0, t1 = self.body_elem_offsets[b], self.body_elem_offsets[b + 1]
            if b in torn:
                self._torn_elements(b, *torn[b])
                continue
            tri, bmat, area, lumped, order = element_geometry(t)
            self.elem_source[t0:t1] = order
            self.elem[t0:t1] = tri
            if v0:
                self.elem[t0:t1] += int(v0)
            self.elem_b[t0:t1] = self.elem_b0[t0:t1] = bmat
            self.elem_area[t0:t1] = self.elem_area0[t0:t1] = area
            self.vertex_area[v0:v0 + t.n_vertices] = lumped
        # every element is a finite-element body's: set_body_material below fills them all
        self.elem_mu = np.empty(ntot, np.float64)
        self.elem_lambda = np.empty(ntot, np.float64)
        self.elem_damping = np.empty(ntot, np.float64)
        self.elem_kind = np.empty(ntot, np.int32)
        self.vertex_mass = np.empty(n, np.float64)
        self.vertex_inv_mass = np.empty(n, np.float64)
        self.pinned = np.zeros(n, bool)
        if pinned is not None:
            for b, mask in enumerate(pinned):
                self.pinned[self.body_vertex_offsets[b]:self.body_vertex_offsets[b + 1]] = mask
        self.spring_stiffness = np.empty(e, np.float64)
        self.spring_damping = np.empty(e, np.float64)
        self.materials = materials
        for b in range(nb):
            if fem[b]:
                self.set_body_material(b, materials[b])
            else:
                self.set_body_parameters(b, mass=masses[b], stiffness=stiffness[b], damping=damping[b])

        self.spring_rest_length0 = self.spring_rest_length.copy()
        self._pressure(pressure if pressure is not None else [None] * nb)

        # The contact stage's view: the collision vertices are every body's outline vertices,
        # body by body, then the other vertices of each body with triangles, body by body.
        nb = len(self.topologies)
        outline = [t.boundary_vertices for t in self.topologies]
        inner = [_off_outline(t) for t in self.topologies]
        body_outline = np.zeros(nb + 1, np.int64)
        np.cumsum([len(o) for o in outline], out=body_outline[1:])
        body_interior = np.full(nb + 1, body_outline[-1], np.int64)
        np.cumsum([len(i) for i in inner], out=body_interior[1:])
        body_interior[1:] += body_outline[-1]
        cv, cb, ea, eb, ebody = [np.zeros(0, np.int32)], [np.zeros(0, np.int32)], [np.zeros(0, np.int32)], \
            [np.zeros(0, np.int32)], [np.zeros(0, np.int32)]
        for b, t in enumerate(self.topologies):
            local = np.full(t.n_vertices, -1, np.int64)
            local[outline[b]] = np.arange(len(outline[b])) + body_outline[b]
            cv.append(outline[b] + self.body_vertex_offsets[b])
            cb.append(np.full(len(outline[b]), b))
            ea.append(local[t.boundary_edges[:, 0]])
            eb.append(local[t.boundary_edges[:, 1]])
            ebody.append(np.full(len(t.boundary_edges), b))
        for b in range(nb):
            cv.append(inner[b] + self.body_vertex_offsets[b])
            cb.append(np.full(len(inner[b]), b))
        v = int(body_interior[-1])
        body_tri = np.zeros(nb + 1, np.int64)
        np.cumsum([len(t.triangles) for t in self.topologies], out=body_tri[1:])
        tri = np.empty((body_tri[-1], 3), np.int32)
        for b, t in enumerate(self.topologies):
            tri[body_tri[b]:body_tri[b + 1]] = t.triangles
            if self.body_vertex_offsets[b]:
                tri[body_tri[b]:body_tri[b + 1]] += int(self.body_vertex_offsets[b])

        def i32(parts):
            return np.ascontiguousarray(np.concatenate(parts), dtype=np.int32)
        vertex_cv = np.full(n, -1, np.int32)
        vertex_cv[i32(cv)] = np.arange(v, dtype=np.int32)
        self.contact = ContactTopology(i32(cv), i32(cb), vertex_cv, body_outline, body_interior, tri, body_tri,
                                       i32(ea), i32(eb), i32(ebody),
                                       np.zeros(v), np.zeros(v), np.zeros(nb, np.int32), np.zeros(nb),
                                       np.zeros((nb, 2)), np.zeros(1))
        for b in range(nb):
            if contact is not None:
                self.set_contact_parameters(b, **contact[b])

    def _torn_elements(self, body: int, old: "Model", old_body: int) -> None:
        """Fill body ``body``'s elements from body ``old_body`` of Model ``old``, which a tear
        turned into this one: it keeps the triangles, in order, with corners at the same rest
        positions (some renumbered onto copies), so the elements keep their order, rest shape
        (as built and where plasticity moved it) and parameters; only their corners are
        read again. Copying them costs a fraction of sorting and gathering them anew."""
        t0, t1 = self.body_elem_offsets[body], self.body_elem_offsets[body + 1]
        o0, o1 = old.body_elem_offsets[old_body], old.body_elem_offsets[old_body + 1]
        v0, v1 = self.body_vertex_offsets[body], self.body_vertex_offsets[body + 1]
        t = self.topologies[body]
        if t1 - t0 != o1 - o0:
            raise ValueError("a torn body keeps its triangles: the Model before has another number of them")
        order = old.elem_source[o0:o1]
        self.elem_source[t0:t1] = order
        np.take(t.triangles, order, axis=0, out=self.elem[t0:t1])
        if v0:
            self.elem[t0:t1] += int(v0)
        for name in ("elem_b", "elem_area", "elem_b0", "elem_area0"):
            getattr(self, name)[t0:t1] = getattr(old, name)[o0:o1]
        area = t.geometry[1] if t.geometry is not None else rest_geometry(t.rest_positions, t.triangles)[1]
        _lumped(t.triangles, np.ascontiguousarray(area), self.vertex_area[v0:v1])  # as element_geometry sums them

    def rest_shape(self, body: int):
        """Body ``body``'s rest shape where plasticity moved it, in its topology's order:
        ``(springs (E, 2), rest lengths (E,))`` and ``(B (M, 4), rest areas (M,))`` (``None``
        for a part still as built, or a body without it). A rebuilt Model starts from the
        mesh's rest shape; :meth:`take_rest_shape` gives it this one back, so that dents
        survive a tear, a new body or a new material."""
        s0, s1 = self.body_spring_offsets[body], self.body_spring_offsets[body + 1]
        t0, t1 = self.body_elem_offsets[body], self.body_elem_offsets[body + 1]
        springs = elements = None
        if not np.array_equal(self.spring_rest_length[s0:s1], self.spring_rest_length0[s0:s1]):
            springs = (self.topologies[body].springs, self.spring_rest_length[s0:s1].copy())
        if not (np.array_equal(self.elem_b[t0:t1], self.elem_b0[t0:t1])
                and np.array_equal(self.elem_area[t0:t1], self.elem_area0[t0:t1])):
            order = self.elem_source[t0:t1]
            b = np.empty((t1 - t0, 4))
            area = np.empty(t1 - t0)
            b[order], area[order] = self.elem_b[t0:t1], self.elem_area[t0:t1]
            elements = (b, area)
        return springs, elements

    def take_rest_shape(self, body: int, shape, source=None) -> None:
        """Give body ``body`` the rest shape ``shape`` (:meth:`rest_shape` of the Model before,
        for the same body), where its vertex ``i`` is the old vertex ``source[i]`` (a tear's
        copies: ``None`` for the same vertices). A spring takes the rest length of the old
        spring between its ends' sources; the elements, those of the old triangles in the
        same rows (a tear keeps them in order). Bumps :attr:`version`."""
        springs, elements = shape
        topo = self.topologies[body]
        s0, s1 = self.body_spring_offsets[body], self.body_spring_offsets[body + 1]
        t0, t1 = self.body_elem_offsets[body], self.body_elem_offsets[body + 1]
        if springs is not None and s1 > s0:
            old, rest = springs
            src = np.arange(topo.n_vertices) if source is None else np.asarray(source)
            n_old = int(max(old.max(initial=0), src.max(initial=0))) + 1
            lo, hi = np.sort(src[topo.springs], axis=1).T
            key = lo.astype(np.int64) * n_old + hi
            old_key = old[:, 0].astype(np.int64) * n_old + old[:, 1]  # sorted, as a topology keeps its springs
            at = np.minimum(np.searchsorted(old_key, key), len(old_key) - 1)
            found = old_key[at] == key
            self.spring_rest_length[s0:s1][found] = rest[at[found]]
        if elements is not None and t1 - t0 == len(elements[1]):
            order = self.elem_source[t0:t1]
            self.elem_b[t0:t1] = elements[0][order]
            self.elem_area[t0:t1] = elements[1][order]
        self.version += 1

    def _pressure(self, pressure) -> None:
        from .pressure import enclosed_area, outline_loops

        nb = len(self.topologies)
        loops = [np.zeros((0, 2), np.int32)] * nb
        self.body_pressure = np.zeros(nb)
        self.body_pressure_area = np.zeros(nb)
        for b, (t, p) in enumerate(zip(self.topologies, pressure)):
            if p is None:
                continue
            loops[b] = outline_loops(t.rest_positions, t.boundary_edges, t.springs, t.triangles)
            self.body_pressure_area[b] = enclosed_area(t.rest_positions, loops[b][:, 0], loops[b][:, 1])
            self.body_pressure[b] = p
            loops[b] = loops[b] + self.body_vertex_offsets[b]
        self.body_pressure_offsets = np.zeros(nb + 1, np.int64)
        np.cumsum([len(lp) for lp in loops], out=self.body_pressure_offsets[1:])
        edges = np.concatenate([np.zeros((0, 2), np.int32)] + loops).astype(np.int32)
        self.pressure_a = np.ascontiguousarray(edges[:, 0])
        self.pressure_b = np.ascontiguousarray(edges[:, 1])

    @property
    def n_vertices(self) -> int:
        """Total number of vertices over all bodies."""
        return len(self.vertex_mass)

    @property
    def n_springs(self) -> int:
        """Total number of springs over all bodies."""
        return len(self.spring_i)

    @property
    def n_elements(self) -> int:
        """Total number of triangle elements over all bodies."""
        return len(self.elem)

    def set_body_parameters(self, body: int, *, mass: float, stiffness: float, damping: float) -> None:
        """Write springs body ``body``'s total mass (kg), stiffness (N/m) and damping (N*s/m) into the arrays.

        The caller validates the values; this only spreads them over vertices and springs.
        A finite-element body ignores them (its material sets its masses).
        """
        if self.materials[body] is not None and self.materials[body].is_fem:
            return
        v0, v1 = self.body_vertex_offsets[body], self.body_vertex_offsets[body + 1]
        s0, s1 = self.body_spring_offsets[body], self.body_spring_offsets[body + 1]
        share = self.topologies[body].mass_share
        self.vertex_mass[v0:v1] = mass / (v1 - v0) if share is None else mass * share
        self._inverse_masses(v0, v1)
        self.spring_stiffness[s0:s1] = stiffness
        self.spring_damping[s0:s1] = damping

    def set_body_material(self, body: int, material) -> None:
        """Write finite-element body ``body``'s material: element parameters and vertex masses
        (``density`` times each vertex's lumped area). The body must have been built with a
        finite-element material (switching between springs and elements rebuilds the Model)."""
        if material is None or not material.is_fem or self.materials[body] is None \
                or not self.materials[body].is_fem:
            raise ValueError("set_body_material needs a finite-element body and material; rebuild the Model to "
                             "switch between springs and elements")
        self.materials[body] = material
        t0, t1 = self.body_elem_offsets[body], self.body_elem_offsets[body + 1]
        mu, lam = material.lame()
        self.elem_mu[t0:t1] = mu
        self.elem_lambda[t0:t1] = lam
        self.elem_damping[t0:t1] = material.damping
        self.elem_kind[t0:t1] = material.kind
        v0, v1 = self.body_vertex_offsets[body], self.body_vertex_offsets[body + 1]
        self.vertex_mass[v0:v1] = material.density * self.vertex_area[v0:v1]
        self._inverse_masses(v0, v1)

    def set_pinned(self, body: int, mask) -> None:
        """Pin (``True``) or free the vertices of body ``body`` (mask over its vertices)."""
        v0, v1 = self.body_vertex_offsets[body], self.body_vertex_offsets[body + 1]
        self.pinned[v0:v1] = mask
        self._inverse_masses(v0, v1)
        self._attachments = {}

    def attachments(self, body: int):
        """Body ``body``'s long-range attachments to its pins (body-local anchor index and path
        length, m; see :func:`deforma.physics.strain_limit.attachments`), cached until the pins
        change."""
        cache = self._attachments
        if body not in cache:
            from .strain_limit import attachments

            t = self.topologies[body]
            v0, v1 = self.body_vertex_offsets[body], self.body_vertex_offsets[body + 1]
            edges = t.springs if not len(t.triangles) else np.concatenate(
                [t.triangles[:, [0, 1]], t.triangles[:, [1, 2]], t.triangles[:, [2, 0]]])
            cache[body] = attachments(t.rest_positions, edges, self.pinned[v0:v1])
        return cache[body]

    def _inverse_masses(self, v0, v1):
        self.version += 1  # every set_* that changes masses, springs or elements comes here
        # a pinned vertex has infinite mass: no force, impulse or projection moves it
        self.vertex_inv_mass[v0:v1] = np.where(self.pinned[v0:v1], 0.0, 1.0 / self.vertex_mass[v0:v1])

    def set_contact_parameters(self, body: int, *, collide: bool, self_collision: bool, friction: float,
                               static_friction: float, thickness: float) -> None:
        """Write body ``body``'s contact switches, friction coefficients and thickness (m).

        The self-contact thickness of each boundary vertex is capped at half its rest
        clearance in front of its own outline, so that no body touches itself at rest. The
        caller validates the values.
        """
        c = self.contact
        c.body_flags[body] = (COLLIDE if collide else 0) | (SELF_COLLIDE if self_collision else 0)
        c.body_thickness[body] = thickness
        c.body_friction[body, 0] = friction
        c.body_friction[body, 1] = static_friction
        k0, k1 = c.body_outline[body], c.body_outline[body + 1]
        clear = self.topologies[body].boundary_clearance
        c.thick_other[k0:k1] = thickness
        c.thick_self[k0:k1] = np.minimum(thickness, 0.5 * clear)
        # vertices off the outline only must not cross other bodies' outlines (should their body
        # fold): a hair of thickness, so that their contacts are crossings, put back just in front
        i0, i1 = c.body_interior[body], c.body_interior[body + 1]
        c.thick_other[i0:i1] = SIDE_MARGIN * thickness
        c.margin[0] = SPECULATIVE * float(c.thick_other.max()) if len(c.thick_other) else 0.0

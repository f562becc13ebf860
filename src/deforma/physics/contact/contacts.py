"""The contact stage's data: the bodies as it reads them (:class:`ContactTopology`), its
scratch (:class:`ContactScratch`) and the contacts it finds (:class:`ContactBuffer`), the
counters (``CONTACT_STATUS``), :class:`Contacts`, which bundles them for a step, and
:class:`ContactPoints`, what ``world.contacts`` shows a user.

The three are namedtuples of arrays that :class:`~deforma.physics.model.Model`, the world
and the integrators own; the kernels of :mod:`~deforma.physics.contact` read and write them.
Units: m, m/s, kg.
"""

from __future__ import annotations

from collections import namedtuple
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..colliders.response import make_hits
from ..colliders.shapes import RECT_FRICTION, RECT_STATIC_FRICTION

# Bits of ContactTopology.body_flags.
COLLIDE = 1          # touches other bodies
SELF_COLLIDE = 2     # touches itself

CONTACT_ITERATIONS = 2   # position sweeps over the contacts per substep
SPECULATIVE = 2.0        # proximity contacts reach this many thicknesses (see solve_contacts)
VERIFY_ROUNDS = 3        # crossing checks (and re-solves) before the fail-safe
SIDE_MARGIN = 1e-3       # a crossing is put back at least this fraction of the thickness off the line

# Contact kinds in ContactBuffer.kind.
PROXIMITY = 1
CROSSING = 2

#: The stage's counters, one int64 record (``status.needed[0]``): named fields, and one array to pass.
STATUS_FIELDS = (
    ("contacts", np.int64),      # contacts found by the first narrow phase of the last substep
    ("needed", np.int64),        # > 0: the buffer's contact arrays were too small, this many are needed
    ("pairs_needed", np.int64),  # > 0: ... its candidate pair arrays
    ("failsafe", np.int64),      # substeps that needed the impact-zone fail-safe (cumulative)
    ("stamp", np.int64),         # substeps run through the stage (cumulative)
    ("pairs", np.int64),         # candidate pairs of the last substep
    ("active", np.int64),        # collision vertices tested in the last substep
    ("dirty", np.int64),         # length of ContactScratch.dirty
    ("generation", np.int64),    # generations of checks (cumulative)
    ("touched", np.int64),       # length of ContactScratch.touched
)
CONTACT_STATUS = np.dtype(list(STATUS_FIELDS))


ContactTopology = namedtuple("ContactTopology", [
    "cv_vertex",        # (V,) int32: global vertex index of each collision vertex: the outline
                        #   vertices of every body, then every body's other vertices
    "cv_body",          # (V,) int32: its body
    "vertex_cv",        # (N,) int32: the collision vertex of each world vertex (-1: none)
    "body_outline",     # (B + 1,) int64: body b's outline vertices are cv[body_outline[b]:...[b + 1]]
    "body_interior",    # (B + 1,) int64: ... its other vertices cv[body_interior[b]:...[b + 1]]
    "tri",              # (T, 3) int32: every body's triangles, global vertex indices
    "body_tri",         # (B + 1,) int64: body b's triangles are tri[body_tri[b]:body_tri[b + 1]]
    "ce_a", "ce_b",     # (Ec,) int32: outline edge ends, as collision-vertex indices
    "ce_body",          # (Ec,) int32: the edge's body
    "thick_other",      # (V,) float64: contact thickness against other bodies (m); a pair of two
                        #   outlines uses the larger of its two bodies' (body_thickness)
    "thick_self",       # (V,) float64: ... against its own body (m)
    "body_flags",       # (B,) int32: COLLIDE | SELF_COLLIDE
    "body_thickness",   # (B,) float64: each body's contact thickness (m)
    "body_friction",    # (B, 2) float64: dynamic, static coefficient for body contacts
    "margin",           # (2,) float64: growth of the edge boxes (m): SPECULATIVE times the largest
                        #   thickness; and the slack of a body's own pairs (m): narrow_phase lists
                        #   only those that may come within their reach plus 3 times this as they
                        #   move (inf: every pair whose boxes overlap, as the contact stage wants;
                        #   avbd's one search of a step, whose boxes its motion widens, gives the
                        #   stage's margin)
    "joined_start",     # (B + 1,) int64: CSR, the bodies a joint holds to body b (which it does not collide with)
    "joined",           # (P,) int32: ... are joined[joined_start[b]:joined_start[b + 1]]
    "behind",           # (1,) float64: a vertex that starts behind another body's outline edge by
                        #   less than this share of the pair's thickness, its foot on the edge, is
                        #   taken as in front (0 here; 1 in avbd's row search: pair_contact)
])

ContactScratch = namedtuple("ContactScratch", [
    "xp",               # (V, 2): collision vertices at the start of the substep
    "active",           # (V,) int32: the collision vertices tested this substep (status.active[0] of them)
    "body_box",         # (B, 4) float64: each body's swept box xmin, ymin, xmax, ymax
    "xq",               # (V, 2): ... when the grid was built
    "dirty",            # (V,) int32: vertices the response moved since the last check (status.dirty[0])
    "dirty_mark",       # (V,) int64: the check generation (status.generation[0]) a vertex was listed in dirty
    "touched",          # (V,) int32: every vertex the stage moved this substep (status.touched[0])
    "touched_mark",     # (V,) int64: the substep (status.stamp[0]) a vertex was listed in touched
    "pair_ptr",         # (V + 1,) int64: CSR, the candidate pairs each vertex is part of (out.pair_index)
    "pair_fill",        # (V,) int64: fill cursors for it
    "zone_list",        # (V,) int32: the vertices in impact zones
    "zone_mark",        # (V,) int64: the fail-safe call (status.generation[0]) a vertex joined a zone in
    "ebox",             # (Ec, 4) float64: edge boxes xmin, ymin, xmax, ymax as in the grid
    "ecell",            # (Ec, 4) int64: the cells they cover, ix0, iy0, ix1, iy1
    "cell_start",       # (T + 1,) int64: bucket starts (T a power of two)
    "cell_fill",        # (T,) int64: fill cursors
    "cell_items",       # (I,) int32: edge indices by bucket
    "grid",             # (3,) float64: origin x, origin y, 1 / cell size
    "parent",           # (V,) int32: impact zones (union-find)
    "zone",             # (V, 5) float64: zone sums m vx, m vy, m, members, still
    "status",           # (1,) CONTACT_STATUS: the counters by name
])

ContactBuffer = namedtuple("ContactBuffer", [
    "vertex", "edge",   # (C,) int32: collision vertex, outline edge
    "s",                # (C,): position along the edge, 0 at ce_a, 1 at ce_b
    "normal",           # (C, 2): unit normal toward the side the vertex must stay on
    "depth",            # (C,): how far (m) the vertex was from its target at detection
    "target",           # (C,): distance (m) from the edge's line that the response restores
    "mu",               # (C, 2): dynamic, static friction
    "kind",             # (C,) int8: PROXIMITY or CROSSING
    "pair_vertex",      # (P,) int32: candidate pairs of the first narrow phase
    "pair_edge",        # (P,) int32
    "pair_index",       # (3P,) int32: the pairs by vertex (ContactScratch.pair_ptr)
    "pair_mark",        # (P,) int64: the check generation a pair was last selected in
    "pair_sel",         # (P,) int32: the pairs one check tests
])


def empty_topology(n_bodies: int = 0) -> ContactTopology:
    """A topology without collision vertices (no body collides)."""
    i32, f64, offsets = np.zeros(0, np.int32), np.zeros(0), np.zeros(n_bodies + 1, np.int64)
    return ContactTopology(i32, i32, i32, offsets, offsets, np.zeros((0, 3), np.int32), offsets, i32, i32, i32, f64,
                           f64, np.zeros(n_bodies, np.int32),
                           np.zeros(n_bodies), np.zeros((n_bodies, 2)), np.array([0.0, np.inf]), np.zeros(n_bodies + 1, np.int64),
                           i32, np.zeros(1))


def make_scratch(n_vertices: int, n_edges: int, n_bodies: int = 0) -> ContactScratch:
    """Scratch arrays for ``n_vertices`` collision vertices, ``n_edges`` outline edges, ``n_bodies`` bodies."""
    t = 16
    while t < 2 * n_edges:
        t *= 2
    v = n_vertices
    never = np.full(v, -1, np.int64)
    return ContactScratch(np.zeros((v, 2)), np.zeros(v, np.int32), np.zeros((n_bodies, 4)),
                          np.zeros((v, 2)), np.zeros(v, np.int32), never.copy(), np.zeros(v, np.int32), never.copy(),
                          np.zeros(v + 1, np.int64), np.zeros(v, np.int64), np.zeros(v, np.int32), never.copy(),
                          np.zeros((n_edges, 4)), np.zeros((n_edges, 4), np.int64), np.zeros(t + 1, np.int64),
                          np.zeros(t, np.int64), np.zeros(16 * n_edges + 64, np.int32), np.zeros(3),
                          np.zeros(v, np.int32), np.zeros((v, 5)),
                          np.zeros(1, CONTACT_STATUS))


def make_buffer(contacts: int, pairs: int) -> ContactBuffer:
    """Room for ``contacts`` contacts and ``pairs`` candidate pairs."""
    c = max(int(contacts), 16)
    p = max(int(pairs), 16)
    return ContactBuffer(np.zeros(c, np.int32), np.zeros(c, np.int32), np.zeros(c), np.zeros((c, 2)), np.zeros(c),
                         np.zeros(c), np.zeros((c, 2)), np.zeros(c, np.int8), np.zeros(p, np.int32),
                         np.zeros(p, np.int32), np.zeros(3 * p, np.int32), np.full(p, -1, np.int64),
                         np.zeros(p, np.int32))


@njit(cache=True, inline="always")
def note_moved(k, dirty, dirty_mark, gen, touched, touched_mark, stamp, status):
    # list vertex k as moved: for the next check (dirty) and for the collider pass (touched)
    if dirty_mark[k] != gen:
        dirty_mark[k] = gen
        dirty[status.dirty[0]] = k
        status.dirty[0] += 1
    if touched_mark[k] != stamp:
        touched_mark[k] = stamp
        touched[status.touched[0]] = k
        status.touched[0] += 1


@dataclass(frozen=True)
class ContactPoints:
    """The contacts of the last substep, as arrays (struct of arrays, one row per contact).

    Collider contacts come first: the vertices the collider response put back outside a
    collider, or outside a rigid body's outline (``rigid_body``). Then body contacts: what
    the contact stage found before its response (a vertex against another body's outline
    edge, or against its own).

    Attributes
    ----------
    vertex : (C,) int64
        World vertex index (rows of the world's state arrays).
    collider : (C,) int64
        Index into ``world.colliders``, or -1 for a body or rigid-body contact.
    edge : (C, 2) int64
        World vertex indices of the boundary edge's ends, or -1 for a collider contact.
    weight : (C,) float64
        Where the vertex's foot lies on the edge: 0 at ``edge[:, 0]``, 1 at ``edge[:, 1]``.
    normal : (C, 2) float64
        Unit normal pointing from the other side toward the vertex.
    depth : (C,) float64
        Metres the vertex had to move at detection: to its target distance from the edge
        (the contact thickness, see ``docs/physics.md``) for body contacts, out of the
        collider for collider contacts.
    friction, static_friction : (C,) float64
        The coefficients the contact used.
    rigid_body : (C,) int64
        Index into ``world.bodies`` of the rigid body whose outline the vertex touched, or -1.
    """

    vertex: np.ndarray
    collider: np.ndarray
    edge: np.ndarray
    weight: np.ndarray
    normal: np.ndarray
    depth: np.ndarray
    friction: np.ndarray
    static_friction: np.ndarray
    rigid_body: np.ndarray

    def __len__(self) -> int:
        return len(self.vertex)

    @property
    def body_contacts(self) -> np.ndarray:
        """(C,) bool: rows that are body (edge) contacts."""
        return self.edge[:, 0] >= 0




class Contacts:
    """The contact data a step fills and reads: the contact stage's buffer and scratch, the
    record of collider hits, and their counters by name.

    Made by the World for its Model's contact topology (:meth:`for_topology`) and handed to
    the integrator every step; the kernels take its namedtuples (``buffer``, ``scratch``,
    ``hits``). When a substep finds more contacts or candidate pairs than the buffer holds,
    the kernels stop and say how many they need (``needed``); the World then grows the
    buffer (:meth:`grow`) and runs the step again from its start.

    Attributes
    ----------
    buffer : ContactBuffer
        The contacts and candidate pairs of the last substep.
    scratch : ContactScratch
        The stage's working arrays; ``scratch.status`` holds the counters.
    hits : ColliderHits
        Per vertex, the last collider contact (:func:`~deforma.physics.colliders.response.make_hits`).

    Examples
    --------
    >>> from deforma.physics.contact.contacts import empty_topology
    >>> c = Contacts.for_topology(empty_topology(), n_vertices=3)
    >>> c.needed, int(c.status["stamp"][0])
    ((0, 0), 0)
    """

    def __init__(self, buffer: ContactBuffer, scratch: ContactScratch, hits):
        self.buffer = buffer
        self.scratch = scratch
        self.hits = hits

    @classmethod
    def for_topology(cls, topo: ContactTopology, *, n_vertices: int, keep: "Contacts | None" = None) -> "Contacts":
        """Empty contacts for a Model's contact topology ``topo`` and ``n_vertices`` vertices;
        a buffer at least as large as ``keep``'s (a rebuilt Model, e.g. after a tear, whose
        contacts go on: a smaller buffer would make the next step run twice)."""
        n_bodies = len(topo.body_flags)
        scratch = make_scratch(len(topo.cv_vertex), len(topo.ce_a), n_bodies)
        n_outline = int(topo.body_interior[0])
        grown = (len(keep.buffer.vertex), len(keep.buffer.pair_vertex)) if keep is not None else (0, 0)
        buffer = make_buffer(max(n_outline + 64, grown[0]), max(4 * n_outline + 64, grown[1]))
        return cls(buffer, scratch, make_hits(n_vertices))

    @property
    def status(self) -> np.ndarray:
        """The counters: a (1,) record array of ``CONTACT_STATUS`` (``status["stamp"][0]``; in a
        compiled kernel ``status.stamp[0]``)."""
        return self.scratch.status

    @property
    def complete(self) -> bool:
        """Whether the buffer had room for everything the last step found."""
        st = self.scratch.status
        return not (st["needed"][0] or st["pairs_needed"][0])

    @property
    def needed(self) -> tuple[int, int]:
        """``(contacts, pairs)`` the buffer lacked room for in the last step (0, 0: it had room)."""
        st = self.scratch.status
        return int(st["needed"][0]), int(st["pairs_needed"][0])

    def clear_needed(self) -> None:
        """Forget what the last step lacked (before a step)."""
        st = self.scratch.status
        st["needed"][0] = st["pairs_needed"][0] = 0

    def grow(self) -> None:
        """Make the buffer twice what the last step needed (and no smaller than it is)."""
        need_c, need_p = self.needed
        b = self.buffer
        self.buffer = make_buffer(max(2 * need_c, len(b.vertex)), max(2 * need_p, len(b.pair_vertex)))

    def points(self, topo: ContactTopology, rects, n_colliders: int, rigid_bodies) -> "ContactPoints":
        """The contacts of the last substep as a :class:`ContactPoints`, in world vertex
        indices; ``rects`` are the packed colliders (for the coefficients each collider
        contact used): the world's ``n_colliders`` first, then the outline of each body in
        ``rigid_bodies`` (world body indices)."""
        scr, buf, hits = self.scratch, self.buffer, self.hits
        n = int(scr.status["contacts"][0])
        k = buf.vertex[:n]
        j = buf.edge[:n]
        cv = topo.cv_vertex.astype(np.int64)
        edge = np.stack([cv[topo.ce_a[j]], cv[topo.ce_b[j]]], axis=1) if n else np.zeros((0, 2), np.int64)
        stamp = scr.status["stamp"][0]
        touched = np.flatnonzero(hits.stamp == stamp) if stamp > 0 else np.zeros(0, int)
        col = hits.collider[touched].astype(np.int64)
        m = len(touched)
        rigid = np.where(col >= n_colliders, np.asarray(rigid_bodies, np.int64)[np.maximum(col - n_colliders, 0)]
                         if len(rigid_bodies) else -1, -1)
        return ContactPoints(
            vertex=np.concatenate([touched.astype(np.int64), cv[k]]),
            collider=np.concatenate([np.where(col >= n_colliders, -1, col), np.full(n, -1, np.int64)]),
            edge=np.concatenate([np.full((m, 2), -1, np.int64), edge]),
            weight=np.concatenate([np.zeros(m), buf.s[:n]]),
            normal=np.concatenate([hits.normal[touched], buf.normal[:n]]),
            depth=np.concatenate([hits.depth[touched], buf.depth[:n]]),
            friction=np.concatenate([rects[col, RECT_FRICTION], buf.mu[:n, 0]]),
            static_friction=np.concatenate([rects[col, RECT_STATIC_FRICTION], buf.mu[:n, 1]]),
            rigid_body=np.concatenate([rigid, np.full(n, -1, np.int64)]))

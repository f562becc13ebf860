"""Body-body and self contacts: collide (broad + narrow phase), then solve, then make sure.

Every body with triangles has an *outline*: the mesh edges used by one triangle, directed so
that the body is on their left (outer outlines counter-clockwise, holes clockwise). A
contact is a vertex ``p`` against an outline edge ``(a, b)``: an outline vertex against the
outline of another body, or of its own body (self contact) if ``p`` is not one of the
edge's ends; and a vertex off the outline against another body's outline, where its body
is folded (below). The stage runs once per substep, after the integrator has moved every
vertex from ``x_prev`` to ``x``; the motion in between is taken as a straight line.

0. **Which vertices.** Every outline vertex of a body with contacts on; and, of a colliding
   body, every other vertex whose swept box meets another colliding body's. Self contact
   keeps an outline from crossing itself, and a body whose triangles all keep their
   orientation lies inside its outline, so only a folded body can carry a vertex off its
   outline into another body; but a folded flap carries vertices of triangles that are not
   turned over too, and the response can fold a body after the test, so all such vertices
   are tested (measured: testing only the vertices of turned-over triangles let the `pile`
   at 1/60 s x 2 put a vertex inside another body within 2 s). They get a hair of
   thickness, so their contacts are crossings only.
1. **Broad phase.** The swept box of every outline edge (its ends at both times, grown by
   a margin: ``SPECULATIVE`` times the largest contact thickness) goes into a uniform grid
   hashed into a table twice as long as there are edges, with cells about the mean box
   size. Each vertex looks up the cells its own swept box (grown the same way by its own
   thickness) covers; a pair is listed once, in the cell of the low corner of the two
   boxes' overlap. Built anew every substep: linear in the number of outline vertices, and
   nothing can go stale. (Keeping the pairs over several substeps in boxes grown by a
   slack, as Box2D's fat boxes do, was measured and dropped: a heap of 200 bodies always
   has a vertex that leaves its slack within a substep or two, and the stage per body grew
   4x from the extra pairs.)
2. **Narrow phase.** ``d`` is the signed distance of ``p`` from the edge's line (positive in
   front, outside the edge's body) and ``s`` where its foot lies on the edge (0 at ``a``,
   1 at ``b``), at the start (``d0``) and end (``d1``, ``s1``) of the substep. The side
   ``p`` starts on is the exact sign of ``d0``. A pair is a contact if ``p`` started in
   front and ended within ``SPECULATIVE`` thicknesses in front, with its foot on the segment
   (``PROXIMITY``), or if its straight-line motion crossed the segment itself
   (``CROSSING``: continuous collision detection; the time at which ``p`` and the moving
   edge are collinear is a root of a quadratic, found by bisection on its sign change, and
   ``s`` at that time must lie in [0, 1]; a point on the same side at both ends may still
   have crossed twice, which the quadratic's extremum tells, and the first of the two
   crossings that passes through the segment counts). Pairs are watched from both sides:
   bodies start apart (the world refuses an overlap), so a vertex behind an edge lies
   beyond a part of that edge's body (across a thin limb, or a folded flap whose outline
   runs backwards) and must stay there. Two outlines use the larger of their
   bodies' thicknesses, so that both sides of a pair agree on the gap.
3. **Solve** (Gauss-Seidel over the contacts). Velocities first, once: the relative
   velocity ``v_p - (1 - s) v_a - s v_b`` may approach the edge by what is left of the gap
   to the target in the next substep, no more (a *speculative* contact: a loaded pair's
   support never lapses, where it would pop out and back in); the excess goes, with
   Coulomb friction (:func:`deforma.physics.friction.coulomb`, the rule colliders use),
   through one impulse split by inverse mass (``w_p``, ``(1 - s) w_a``, ``s w_b``), so that
   linear momentum is kept exactly. Every vertex also moves by ``h`` times its velocity
   change, so that a stuck vertex does not creep (the collider response's rule; not under
   implicit Euler, see :func:`contact_stage`). Then
   positions, in ``CONTACT_ITERATIONS`` sweeps: a vertex closer than its target is pushed
   out to it, split by inverse mass the same way (positions only: no velocity, no
   momentum). A vertex this moves into (or through) a collider meets the collider at once
   (:func:`~deforma.physics.colliders.collide_point`; colliders have infinite mass). A
   proximity contact's target is the thickness. A crossing goes back to the distance it
   started at, at most the thickness (and a hair off the line): every pair had its start
   distance at once, so these targets never contradict each other, while two corners that
   meet level cannot both be a thickness in front of the other's edge.
4. **Verify.** Crossings are looked for again, among the candidate pairs of the vertices
   the response moved (a pair it left alone keeps its answer; a vertex-to-pair index finds
   them, so the work follows what moved, not the size of the world); a vertex moved
   further than the margin rebuilds the grid first. Crossings found are solved together
   with those of earlier rounds (two that hold each other converge only together), up to
   ``VERIFY_ROUNDS`` times. Then a fail-safe makes the result crossing-free for sure:
   *impact zones* (Bridson, Fedkiw and Anderson 2002, with translations only). The
   vertices of each remaining crossing merge into a zone that moves as one rigid
   translation from its start positions at its mass-weighted mean velocity (linear
   momentum kept); zones grow until no crossing is left. The start of the substep had none
   and a translated zone keeps its members' relative positions, so this ends. A zone that
   the translation would push into (or through) a collider stays where it started. It is
   needed where the response cannot converge, e.g. a vertex at the tip of an outline
   crushed into a hairpin, which would have to be in front of both faces at once.
5. **Colliders last.** Every vertex the stage moved and left in or through a collider gets
   the collider response, and if that moved any, the check and fail-safe of step 4 run
   again on what it moved.

What is guaranteed: if no outline crossed another or itself and no vertex lay inside
another body at the start of a substep, the same holds at its end (tested at every step of
the 10 s ``pile`` scene by ``tests/physics/contact_checks.py``, which is independent of this
module).

The contact thickness keeps resting bodies a hair apart, so resting contact is found by the
cheap proximity test and the crossing test is the exception.

Everything here is a pure kernel over arrays; :class:`ContactTopology`,
:class:`ContactScratch` and :class:`ContactBuffer` are namedtuples of arrays that
:class:`~deforma.physics.model.Model`, the world and the integrators own. Units: m, m/s, kg.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass

import numpy as np
from numba import njit

from .colliders import (RECT_FRICTION, RECT_STATIC_FRICTION, RECT_XMAX, RECT_XMIN, RECT_YMAX, RECT_YMIN, n_colliders,
                        collide_point, jump_reach, path_hits, record_hit)
from .friction import coulomb, mix

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

# Slots of ContactScratch.status.
ST_CONTACTS = 0      # contacts found by the first narrow phase of the last substep
ST_NEEDED = 1        # > 0: the buffer's contact arrays were too small, this many are needed
ST_PAIRS_NEEDED = 2  # > 0: ... its candidate pair arrays
ST_FAILSAFE = 3      # substeps that needed the impact-zone fail-safe (cumulative)
ST_STAMP = 4         # substeps run through the stage (cumulative)
ST_PAIRS = 5         # candidate pairs of the last substep
ST_ACTIVE = 6        # collision vertices tested in the last substep
ST_DIRTY = 7         # length of ContactScratch.dirty
ST_GEN = 8           # generations of checks (cumulative)
ST_TOUCHED = 9       # length of ContactScratch.touched

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
    "margin",           # (1,) float64: growth of the edge boxes (m): SPECULATIVE times the largest thickness
])

ContactScratch = namedtuple("ContactScratch", [
    "xp",               # (V, 2): collision vertices at the start of the substep
    "active",           # (V,) int32: the collision vertices tested this substep (status[ST_ACTIVE] of them)
    "body_box",         # (B, 4) float64: each body's swept box xmin, ymin, xmax, ymax
    "xq",               # (V, 2): ... when the grid was built
    "dirty",            # (V,) int32: vertices the response moved since the last check (status[ST_DIRTY])
    "dirty_mark",       # (V,) int64: the check generation (status[ST_GEN]) a vertex was listed in dirty
    "touched",          # (V,) int32: every vertex the stage moved this substep (status[ST_TOUCHED])
    "touched_mark",     # (V,) int64: the substep (status[ST_STAMP]) a vertex was listed in touched
    "pair_ptr",         # (V + 1,) int64: CSR, the candidate pairs each vertex is part of (out.pair_index)
    "pair_fill",        # (V,) int64: fill cursors for it
    "zone_list",        # (V,) int32: the vertices in impact zones
    "zone_mark",        # (V,) int64: the fail-safe call (status[ST_GEN]) a vertex joined a zone in
    "ebox",             # (Ec, 4) float64: edge boxes xmin, ymin, xmax, ymax as in the grid
    "ecell",            # (Ec, 4) int64: the cells they cover, ix0, iy0, ix1, iy1
    "cell_start",       # (T + 1,) int64: bucket starts (T a power of two)
    "cell_fill",        # (T,) int64: fill cursors
    "cell_items",       # (I,) int32: edge indices by bucket
    "grid",             # (3,) float64: origin x, origin y, 1 / cell size
    "parent",           # (V,) int32: impact zones (union-find)
    "zone",             # (V, 5) float64: zone sums m vx, m vy, m, members, still
    "status",           # (10,) int64: see ST_*
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
                           np.zeros(n_bodies), np.zeros((n_bodies, 2)), np.zeros(1))


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
                          np.zeros(v, np.int32), np.zeros((v, 5)), np.zeros(10, np.int64))


def make_buffer(contacts: int, pairs: int) -> ContactBuffer:
    """Room for ``contacts`` contacts and ``pairs`` candidate pairs."""
    c = max(int(contacts), 16)
    p = max(int(pairs), 16)
    return ContactBuffer(np.zeros(c, np.int32), np.zeros(c, np.int32), np.zeros(c), np.zeros((c, 2)), np.zeros(c),
                         np.zeros(c), np.zeros((c, 2)), np.zeros(c, np.int8), np.zeros(p, np.int32),
                         np.zeros(p, np.int32), np.zeros(3 * p, np.int32), np.full(p, -1, np.int64),
                         np.zeros(p, np.int32))


# -- broad phase -------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _bucket(ix, iy, mask):
    return ((ix * np.int64(73856093)) ^ (iy * np.int64(19349663))) & mask


@njit(cache=True)
def build_grid(x, topo, scr, margin):
    """Hash the swept box of every active outline edge (grown by ``margin`` m) into the grid.

    The swept box spans the edge's ends at the start (``scr.xp``) and now (``x``). Returns
    the number of edges in the grid.
    """
    ce_a, ce_b, ce_body, cv = topo.ce_a, topo.ce_b, topo.ce_body, topo.cv_vertex
    flags = topo.body_flags
    xp, ebox, ecell = scr.xp, scr.ebox, scr.ecell
    n_edges = ce_a.shape[0]
    active = 0
    extent = 0.0
    ox = np.inf
    oy = np.inf
    for j in range(n_edges):
        if flags[ce_body[j]] == 0:
            ebox[j, 0] = np.inf  # never overlaps anything
            continue
        a = ce_a[j]
        b = ce_b[j]
        ia = cv[a]
        ib = cv[b]
        x0 = min(min(xp[a, 0], xp[b, 0]), min(x[ia, 0], x[ib, 0])) - margin
        x1 = max(max(xp[a, 0], xp[b, 0]), max(x[ia, 0], x[ib, 0])) + margin
        y0 = min(min(xp[a, 1], xp[b, 1]), min(x[ia, 1], x[ib, 1])) - margin
        y1 = max(max(xp[a, 1], xp[b, 1]), max(x[ia, 1], x[ib, 1])) + margin
        ebox[j, 0] = x0
        ebox[j, 1] = y0
        ebox[j, 2] = x1
        ebox[j, 3] = y1
        extent += max(x1 - x0, y1 - y0)
        ox = min(ox, x0)
        oy = min(oy, y0)
        active += 1
    if active == 0:
        return 0
    cell = extent / active
    if not cell > 0.0:
        cell = 1.0
    t = scr.cell_fill.shape[0]
    mask = np.int64(t - 1)
    start, fill, items = scr.cell_start, scr.cell_fill, scr.cell_items
    while True:  # a few fast edges can cover many small cells: coarsen until the items fit
        inv = 1.0 / cell
        total = 0
        for j in range(n_edges):
            if ebox[j, 0] == np.inf:
                continue
            ecell[j, 0] = np.int64((ebox[j, 0] - ox) * inv)  # >= 0: truncation is floor
            ecell[j, 1] = np.int64((ebox[j, 1] - oy) * inv)
            ecell[j, 2] = np.int64((ebox[j, 2] - ox) * inv)
            ecell[j, 3] = np.int64((ebox[j, 3] - oy) * inv)
            total += (ecell[j, 2] - ecell[j, 0] + 1) * (ecell[j, 3] - ecell[j, 1] + 1)
        if total <= items.shape[0]:
            break
        cell *= 2.0
    start[:] = 0
    for j in range(n_edges):
        if ebox[j, 0] == np.inf:
            continue
        for ix in range(ecell[j, 0], ecell[j, 2] + 1):
            for iy in range(ecell[j, 1], ecell[j, 3] + 1):
                start[_bucket(ix, iy, mask) + 1] += 1
    for k in range(t):
        start[k + 1] += start[k]
        fill[k] = start[k]
    for j in range(n_edges):  # edge by edge: an edge's entries in one bucket are adjacent
        if ebox[j, 0] == np.inf:
            continue
        for ix in range(ecell[j, 0], ecell[j, 2] + 1):
            for iy in range(ecell[j, 1], ecell[j, 3] + 1):
                bk = _bucket(ix, iy, mask)
                items[fill[bk]] = j
                fill[bk] += 1
    scr.grid[0] = ox
    scr.grid[1] = oy
    scr.grid[2] = inv
    for m in range(scr.status[ST_ACTIVE]):
        k = scr.active[m]
        scr.xq[k, 0] = x[cv[k], 0]
        scr.xq[k, 1] = x[cv[k], 1]
    return active


# -- narrow phase ------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _cross_at(t, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey):
    qx = q0x + t * dqx
    qy = q0y + t * dqy
    ex = e0x + t * dex
    ey = e0y + t * dey
    return qx * ey - qy * ex


@njit(cache=True)
def pair_contact(p0x, p0y, p1x, p1y, a0x, a0y, a1x, a1y, b0x, b0y, b1x, b1y, thickness):
    """Contact of a point moving ``p0 -> p1`` with an edge moving ``(a0, b0) -> (a1, b1)``.

    The edge's body lies on its left; ``d`` is the point's signed distance from the edge's
    line, positive in front. The side the point starts on is the exact sign of ``d0``.
    Returns ``(kind, s, nx, ny, depth, target)``: ``kind`` is 0 (no contact),
    ``PROXIMITY`` (started in front, ended within ``thickness`` m in front of the segment)
    or ``CROSSING`` (crossed the segment, from either side); ``s`` the foot's position along the edge; ``(nx, ny)`` the unit normal toward
    the side the point must stay on; ``target`` the distance from the line along it that
    the response restores, and ``depth`` how far the point is from it.

    Examples
    --------
    The edge runs from (1, 0) to (0, 0), so its body lies below it:

    >>> k, s, nx, ny, depth, target = pair_contact(0.5, 1, 0.5, -0.5, 1, 0, 1, 0, 0, 0, 0, 0, 0.01)
    >>> k == CROSSING, s, (nx, ny), depth, target     # fell through the edge from above
    (True, 0.5, (0.0, 1.0), 0.51, 0.01)
    >>> pair_contact(0.5, 0.1, 0.5, 0.005, 1, 0, 1, 0, 0, 0, 0, 0, 0.01)[0] == PROXIMITY
    True
    >>> k, s, nx, ny, depth, target = pair_contact(0.5, -0.1, 0.5, 0.2, 1, 0, 1, 0, 0, 0, 0, 0, 0.01)
    >>> k == CROSSING, (nx, ny), round(depth, 6)      # from behind: held behind, at its start distance
    (True, (-0.0, -1.0), 0.3)

    A point that stays put at (0.5, 0.5), in front of the edge's line at the start and at the
    end, while the edge swings past it: the line passes it twice, first beyond the edge's
    end (it is then behind, legitimately), then with the segment itself. Held behind:

    >>> k, s, nx, ny, depth, target = pair_contact(0.5, 0.5, 0.5, 0.5, -1, -1, -1, 2, -1, 0, 2, 0, 0.01)
    >>> k == CROSSING, round(s, 3), (round(nx, 3), round(ny, 3))  # the normal out of the back
    (True, 0.634, (0.555, 0.832))
    """
    e0x = b0x - a0x
    e0y = b0y - a0y
    l0 = e0x * e0x + e0y * e0y
    e1x = b1x - a1x
    e1y = b1y - a1y
    l1 = e1x * e1x + e1y * e1y
    if l0 <= 0.0 or l1 <= 0.0:
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0
    q0x = p0x - a0x
    q0y = p0y - a0y
    f0 = q0x * e0y - q0y * e0x          # d0 * |e0|
    front = f0 >= 0.0
    q1x = p1x - a1x
    q1y = p1y - a1y
    f1 = q1x * e1y - q1y * e1x          # d1 * |e1|
    dqx = q1x - q0x
    dqy = q1y - q0y
    dex = e1x - e0x
    dey = e1y - e0y
    # f(t) = (q0 + t dq) x (e0 + t de), |e(t)| times the distance from the moving line, is a
    # quadratic in t: on the same side at both ends, the point may still have crossed the
    # line twice (around an end of the edge, then back through the edge itself: an edge
    # turning fast at a large step). Its extremum tells.
    if (f1 >= 0.0) == front:
        qa = dqx * dey - dqy * dex
        tm = -0.5 * ((q0x * dey - q0y * dex) + (dqx * e0y - dqy * e0x)) / qa if qa != 0.0 else -1.0
        if 0.0 < tm < 1.0 and (_cross_at(tm, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey) >= 0.0) != front:
            # two crossings of the line, at t1 < tm < t2; the first through the segment counts
            t1, s1 = _line_crossing(0.0, tm, front, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey)
            if 0.0 <= s1 <= 1.0:
                return _crossed(front, s1, f0, f1, l0, e1x, e1y, l1, thickness, True)
            t2, s2 = _line_crossing(tm, 1.0, not front, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey)
            if 0.0 <= s2 <= 1.0:  # came back through the segment: the side it held in between
                return _crossed(not front, s2, f0, f1, l0, e1x, e1y, l1, thickness, False)
        if not front:
            return 0, 0.0, 0.0, 0.0, 0.0, 0.0  # stayed behind
        reach = SPECULATIVE * thickness
        if f1 * f1 >= reach * reach * l1:
            return 0, 0.0, 0.0, 0.0, 0.0, 0.0  # clear in front: the common case, no root taken
        s1 = (q1x * e1x + q1y * e1y) / l1
        if 0.0 <= s1 <= 1.0:
            r1 = math.sqrt(l1)
            return PROXIMITY, s1, e1y / r1, -e1x / r1, thickness - f1 / r1, thickness
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0
    # the point changed sides of the line (one root): did it cross the segment itself?
    t, s = _line_crossing(0.0, 1.0, front, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey)
    if s < 0.0 or s > 1.0:
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0  # passed the line beyond the segment's ends
    return _crossed(front, s, f0, f1, l0, e1x, e1y, l1, thickness, True)


@njit(cache=True, inline="always")
def _line_crossing(lo, hi, side, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey):
    """The time in ``[lo, hi]`` at which the point reaches the moving line, leaving ``side``
    (``f(lo)`` on it, ``f(hi)`` not: one sign change, found by bisection), and where along
    the edge it does (``s``; outside [0, 1]: beyond the ends, 2.0 for a vanished edge)."""
    for _ in range(48):
        mid = 0.5 * (lo + hi)
        if (_cross_at(mid, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey) >= 0.0) == side:
            lo = mid
        else:
            hi = mid
    qx = q0x + hi * dqx
    qy = q0y + hi * dqy
    ex = e0x + hi * dex
    ey = e0y + hi * dey
    lt = ex * ex + ey * ey
    if lt <= 0.0:
        return hi, 2.0
    return hi, (qx * ex + qy * ey) / lt


@njit(cache=True, inline="always")
def _crossed(side, s, f0, f1, l0, e1x, e1y, l1, thickness, from_start):
    """A ``CROSSING`` contact for a point that passed through the segment from ``side`` (True:
    the front); the response puts it back on that side."""
    r1 = math.sqrt(l1)
    d1 = f1 / r1
    nx = e1y / r1
    ny = -e1x / r1
    # Back to the distance it started at, at most the thickness, and a hair off the line so
    # that the side is unambiguous: every pair had its start distance at once, so these
    # targets never contradict each other. A point that held the side only between two
    # crossings has no start distance on it: a hair.
    d0 = f0 / math.sqrt(l0) if from_start else 0.0
    if side:
        target = max(min(thickness, d0), SIDE_MARGIN * thickness)
        return CROSSING, s, nx, ny, target - d1, target
    target = max(-d0, SIDE_MARGIN * thickness)
    return CROSSING, s, -nx, -ny, target + d1, target


# The kernels below take the namedtuples once per call and unpack them: a compiled
# helper called per pair with a namedtuple of arrays pays reference counting for every array
# in it (measured: 11 ms instead of 0.4 ms for one narrow phase of a 14-body pile).

@njit(cache=True)
def narrow_phase(x, topo, scr, out):
    """List the candidate pairs: a collision vertex and an outline edge whose boxes overlap.

    The vertex's swept box is grown by its contact thickness; pairs the flags or the outline
    rule exclude are left out. Writes ``out.pair_vertex`` / ``out.pair_edge``; returns their
    number, or ``-(needed)`` if they did not fit.
    """
    cv, body, flags = topo.cv_vertex, topo.cv_body, topo.body_flags
    ce_a, ce_b, ce_body = topo.ce_a, topo.ce_b, topo.ce_body
    thick_other, thick_self = topo.thick_other, topo.thick_self
    xp, ebox, ecell = scr.xp, scr.ebox, scr.ecell
    start, items = scr.cell_start, scr.cell_items
    pair_vertex, pair_edge = out.pair_vertex, out.pair_edge
    ox, oy, inv = scr.grid[0], scr.grid[1], scr.grid[2]
    active = scr.active  # namedtuple fields read once: each read in a loop costs reference counting
    mask = np.int64(scr.cell_fill.shape[0] - 1)
    pcap = pair_vertex.shape[0]
    n_outline = topo.body_interior[0]
    n = 0
    for m in range(scr.status[ST_ACTIVE]):
        k = active[m]
        bk = body[k]
        fk = flags[bk]
        if fk == 0:
            continue
        inner = k >= n_outline  # not on the outline: only other bodies' outlines concern it
        i = cv[k]
        grow = SPECULATIVE * max(thick_other[k], thick_self[k])
        bx0 = min(xp[k, 0], x[i, 0]) - grow
        bx1 = max(xp[k, 0], x[i, 0]) + grow
        by0 = min(xp[k, 1], x[i, 1]) - grow
        by1 = max(xp[k, 1], x[i, 1]) + grow
        ix0 = np.int64(math.floor((bx0 - ox) * inv))
        ix1 = np.int64(math.floor((bx1 - ox) * inv))
        iy0 = np.int64(math.floor((by0 - oy) * inv))
        iy1 = np.int64(math.floor((by1 - oy) * inv))
        for ix in range(ix0, ix1 + 1):
            for iy in range(iy0, iy1 + 1):
                bucket = _bucket(ix, iy, mask)
                prev = -1
                for it in range(start[bucket], start[bucket + 1]):
                    j = items[it]
                    if j == prev:
                        continue
                    prev = j
                    if ebox[j, 0] > bx1 or ebox[j, 2] < bx0 or ebox[j, 1] > by1 or ebox[j, 3] < by0:
                        continue
                    # take the pair only in the cell of the overlap's low corner
                    if max(ix0, ecell[j, 0]) != ix or max(iy0, ecell[j, 1]) != iy:
                        continue
                    eb = ce_body[j]
                    if eb == bk:
                        if inner or (fk & SELF_COLLIDE) == 0:
                            continue
                        if ce_a[j] == k or ce_b[j] == k:
                            continue
                    elif (fk & COLLIDE) == 0 or (flags[eb] & COLLIDE) == 0:
                        continue
                    if n < pcap:
                        pair_vertex[n] = k
                        pair_edge[n] = j
                    n += 1
    return n if n <= pcap else -n


@njit(cache=True)
def index_pairs(topo, scr, out, n_pairs):
    """For each collision vertex, the candidate pairs it is part of (as the vertex or an end of
    the edge): a CSR in ``scr.pair_ptr`` / ``out.pair_index``."""
    ptr, fill, index = scr.pair_ptr, scr.pair_fill, out.pair_index
    pv, pe, ce_a, ce_b = out.pair_vertex, out.pair_edge, topo.ce_a, topo.ce_b
    ptr[:] = 0
    for m in range(n_pairs):
        ptr[pv[m] + 1] += 1
        ptr[ce_a[pe[m]] + 1] += 1
        ptr[ce_b[pe[m]] + 1] += 1
    for k in range(ptr.shape[0] - 1):
        ptr[k + 1] += ptr[k]
        fill[k] = ptr[k]
    for m in range(n_pairs):
        for k in (pv[m], ce_a[pe[m]], ce_b[pe[m]]):
            index[fill[k]] = m
            fill[k] += 1


@njit(cache=True, inline="always")
def _note_moved(k, dirty, dirty_mark, gen, touched, touched_mark, stamp, status):
    # list vertex k as moved: for the next check (dirty) and for the collider pass (touched)
    if dirty_mark[k] != gen:
        dirty_mark[k] = gen
        dirty[status[ST_DIRTY]] = k
        status[ST_DIRTY] += 1
    if touched_mark[k] != stamp:
        touched_mark[k] = stamp
        touched[status[ST_TOUCHED]] = k
        status[ST_TOUCHED] += 1


@njit(cache=True)
def _collide(x, topo, scr, out):
    """Steps 0-2 of the module docstring for the motion from ``scr.xp`` to ``x``: the number
    of contacts stored in ``out`` from 0 (-1 if ``out`` was too small; ``scr.status`` says
    which part) and of candidate pairs."""
    status = scr.status
    if topo.cv_vertex.shape[0] == 0 or _activate(x, topo, scr) == 0:
        return 0, 0
    if build_grid(x, topo, scr, topo.margin[0]) == 0:
        return 0, 0
    n_pairs = narrow_phase(x, topo, scr, out)
    if n_pairs < 0:
        status[ST_PAIRS_NEEDED] = -n_pairs
        return -1, 0
    n = check_pairs(x, topo, scr, out, 0, n_pairs, True, False)
    if n < 0:
        status[ST_NEEDED] = -n
        return -1, n_pairs
    return n, n_pairs


@njit(cache=True)
def detect_contacts(x, topo, scr, out):
    """Collide only (steps 0-2 of the module docstring): the contacts of the motion from
    ``scr.xp`` to ``x``, stored in ``out`` from 0, nothing moved.

    For solvers that hold contacts inside their solve (:mod:`~deforma.physics.xpbd`): they
    call it with the predicted end of the substep, use the contacts as constraints, and the
    full stage still runs after them, from the same :func:`gather_start` (this reads
    ``scr.xp`` and only grows the body boxes). Returns the number of contacts, or -1 if
    ``out`` was too small (as :func:`contact_stage`).
    """
    n, _ = _collide(x, topo, scr, out)
    return n


@njit(cache=True, inline="always")
def _pair_distance(x, ip, ia, ib, s, nx, ny):
    """How far vertex ``ip`` is in front of the point ``(1 - s) x_ia + s x_ib`` of its
    contact's edge, along the contact's normal ``(nx, ny)`` (m)."""
    ca = 1.0 - s
    return (x[ip, 0] - ca * x[ia, 0] - s * x[ib, 0]) * nx + (x[ip, 1] - ca * x[ia, 1] - s * x[ib, 1]) * ny


@njit(cache=True)
def hold_start_distance(x_start, topo, out, count):
    """Lower each contact's target in ``out[:count]`` to the distance its pair had at the
    start of the substep (``x_start``), if that was closer: a solver that holds contacts
    in its solve then keeps such a pair from closing in but does not push it apart.

    Why: those solvers derive velocities from positions, so a pair that started closer
    than its target (a body placed within another's contact thickness) was pushed out to
    it in one substep and flew apart (a box placed 5 cm into a 10 cm thickness left at 7.8
    m/s under implicit Euler, 7.5 m/s under XPBD). The contact stage after the solve restores
    the distance by positions only, without velocity, as it does under symplectic Euler.

    Examples
    --------
    >>> import numpy as np
    >>> i32 = lambda *v: np.array(v, np.int32)
    >>> topo = empty_topology()._replace(cv_vertex=i32(0, 1, 2), ce_a=i32(1), ce_b=i32(2))
    >>> out = make_buffer(1, 1)  # vertex 0 above the edge from vertex 1 to vertex 2
    >>> out.vertex[0], out.edge[0], out.s[0], out.target[0], out.normal[0] = 0, 0, 0.5, 0.1, (0.0, 1.0)
    >>> hold_start_distance(np.array([[0.5, 0.04], [1.0, 0.0], [0.0, 0.0]]), topo, out, 1)
    >>> round(float(out.target[0]), 12)  # started 4 cm away: held there
    0.04
    """
    cv, ce_a, ce_b = topo.cv_vertex, topo.ce_a, topo.ce_b
    for c in range(count):
        ip = cv[out.vertex[c]]
        ia = cv[ce_a[out.edge[c]]]
        ib = cv[ce_b[out.edge[c]]]
        d = _pair_distance(x_start, ip, ia, ib, out.s[c], out.normal[c, 0], out.normal[c, 1])
        if d < out.target[c]:
            out.target[c] = max(d, 0.0)


@njit(cache=True)
def project_contacts(x, x_prev, inv_mass, topo, out, count, stick):
    """One Gauss-Seidel pass of position projections over the contacts ``out[:count]``.

    A vertex closer to its edge than the contact's target is pushed out to it, the
    correction split by inverse mass (``w_p``, ``(1 - s) w_a``, ``s w_b``), so that linear
    momentum is kept. Then Coulomb friction at position level (Macklin et al. 2020), as the
    XPBD sweep treats colliders: the pair's relative motion along the edge since the substep
    began (``x_prev``) is undone if it is within ``static friction * push``, the contact
    then sticks for the rest of the substep; otherwise it slides, held back by ``dynamic
    friction * push`` in each pass. ``stick[c]`` holds the decision: -1 before the first
    pass (set it so), then 1 stuck, 0 sliding (as is a pair not touching in the first pass:
    it gets friction from the pass it touches in, from its push there). Positions only: the
    solver derives velocities afterwards.

    Examples
    --------
    A vertex pressed 1 mm into a fixed edge while it slid 0.1 mm along it (static friction
    0.5): pushed back out, and its sliding undone.

    >>> import numpy as np
    >>> i32 = lambda *v: np.array(v, np.int32)
    >>> topo = empty_topology()._replace(cv_vertex=i32(0, 1, 2), ce_a=i32(1), ce_b=i32(2))
    >>> out = make_buffer(1, 1)  # vertex 0 against the edge from vertex 1 to vertex 2, at its middle
    >>> out.vertex[0], out.edge[0], out.s[0], out.target[0] = 0, 0, 0.5, 0.0
    >>> out.normal[0], out.mu[0] = (0.0, 1.0), (0.3, 0.5)
    >>> x_prev = np.array([[0.5, 0.0], [1.0, 0.0], [0.0, 0.0]])
    >>> x = np.array([[0.5001, -0.001], [1.0, 0.0], [0.0, 0.0]])
    >>> stick = np.array([-1.0])
    >>> project_contacts(x, x_prev, np.array([1.0, 0.0, 0.0]), topo, out, 1, stick)
    >>> x[0].round(12).tolist(), stick.tolist()
    ([0.5, 0.0], [1.0])
    """
    cv, ce_a, ce_b = topo.cv_vertex, topo.ce_a, topo.ce_b
    o_vertex, o_edge, o_s, o_normal, o_target, o_mu = out.vertex, out.edge, out.s, out.normal, out.target, out.mu
    for c in range(count):
        ip = cv[o_vertex[c]]
        ia = cv[ce_a[o_edge[c]]]
        ib = cv[ce_b[o_edge[c]]]
        s = o_s[c]
        ca = 1.0 - s
        nx = o_normal[c, 0]
        ny = o_normal[c, 1]
        wp = inv_mass[ip]
        wa = inv_mass[ia] * ca
        wb = inv_mass[ib] * s
        w = wp + wa * ca + wb * s
        if w <= 0.0:
            continue
        d = _pair_distance(x, ip, ia, ib, s, nx, ny)
        push = o_target[c] - d
        if push > 0.0:
            lam = push / w
            _split(x, ip, ia, ib, wp, wa, wb, lam * nx, lam * ny)
        else:
            push = 0.0
        if stick[c] == 0.0 and push == 0.0:
            continue  # sliding and not touching in this pass: no friction
        # relative motion along the edge since the substep began, t = (-ny, nx)
        rx = (x[ip, 0] - x_prev[ip, 0]) - ca * (x[ia, 0] - x_prev[ia, 0]) - s * (x[ib, 0] - x_prev[ib, 0])
        ry = (x[ip, 1] - x_prev[ip, 1]) - ca * (x[ia, 1] - x_prev[ia, 1]) - s * (x[ib, 1] - x_prev[ib, 1])
        slide = -rx * ny + ry * nx
        if stick[c] < 0.0:
            stick[c] = 1.0 if push > 0.0 and abs(slide) <= o_mu[c, 1] * push else 0.0  # touching only
        if stick[c] == 0.0:
            slide = min(abs(slide), o_mu[c, 0] * push) * (1.0 if slide > 0.0 else -1.0)
        lam = -slide / w
        _split(x, ip, ia, ib, wp, wa, wb, -lam * ny, lam * nx)


@njit(cache=True)
def check_pairs(x, topo, scr, out, first, n_pairs, every, crossings_only):
    """Test candidate pairs (:func:`pair_contact`) and store their contacts in ``out`` from ``first``.

    Every pair with ``every``; otherwise only the pairs of the vertices the response moved
    since the last check (``scr.dirty``, found through the pair index of
    :func:`index_pairs`), since a pair it left alone keeps its answer. With
    ``crossings_only`` only ``CROSSING`` contacts are kept. Empties the dirty list. Returns
    the index after the last contact stored, or ``-(needed)`` if they did not fit.
    """
    cv, body = topo.cv_vertex, topo.cv_body
    ce_a, ce_b, ce_body = topo.ce_a, topo.ce_b, topo.ce_body
    thick_other, thick_self, body_thick = topo.thick_other, topo.thick_self, topo.body_thickness
    n_outline = topo.body_interior[0]
    friction = topo.body_friction
    xp = scr.xp
    pair_vertex, pair_edge = out.pair_vertex, out.pair_edge
    o_vertex, o_edge, o_s, o_normal, o_depth, o_target, o_mu, o_kind = \
        out.vertex, out.edge, out.s, out.normal, out.depth, out.target, out.mu, out.kind
    cap = o_vertex.shape[0]
    pair_sel = out.pair_sel
    status = scr.status
    status[ST_GEN] += 1
    n_sel = n_pairs
    if not every:
        gen = status[ST_GEN]
        ptr, index, mark, sel, dirty = scr.pair_ptr, out.pair_index, out.pair_mark, out.pair_sel, scr.dirty
        n_sel = 0
        for d in range(status[ST_DIRTY]):
            k = dirty[d]
            for q in range(ptr[k], ptr[k + 1]):
                m = index[q]
                if mark[m] != gen:
                    mark[m] = gen
                    sel[n_sel] = m
                    n_sel += 1
    status[ST_DIRTY] = 0
    n = first
    for q in range(n_sel):
        m = q if every else pair_sel[q]
        k = pair_vertex[m]
        j = pair_edge[m]
        a = ce_a[j]
        b = ce_b[j]
        bk = body[k]
        eb = ce_body[j]
        own = eb == bk
        if own:
            thick = thick_self[k]
        elif k < n_outline:  # two outlines: both sides of the pair agree on the gap
            thick = max(thick_other[k], body_thick[eb])
        else:
            thick = thick_other[k]
        i = cv[k]
        ia = cv[a]
        ib = cv[b]
        kind, s, nx, ny, depth, target = pair_contact(xp[k, 0], xp[k, 1], x[i, 0], x[i, 1], xp[a, 0], xp[a, 1],
                                                      x[ia, 0], x[ia, 1], xp[b, 0], xp[b, 1], x[ib, 0], x[ib, 1],
                                                      thick)
        if kind == 0 or (crossings_only and kind != CROSSING):
            continue
        if n < cap:
            o_vertex[n] = k
            o_edge[n] = j
            o_s[n] = s
            o_normal[n, 0] = nx
            o_normal[n, 1] = ny
            o_depth[n] = depth
            o_target[n] = target
            o_mu[n, 0] = mix(friction[bk, 0], friction[eb, 0])
            o_mu[n, 1] = mix(friction[bk, 1], friction[eb, 1])
            o_kind[n] = kind
        n += 1
    return n if n <= cap else -n


# -- response ----------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _keep_out(x, v, i, x0, y0, rects, reach2, h):
    # A vertex that the response moved into a collider, or through a thin one since the start
    # of the substep, meets it there and then: the collider response (infinite mass, its
    # velocity rule and friction), after the same cheap tests as in the integrators' pass.
    px, py = x[i, 0], x[i, 1]
    near = (px - x0) * (px - x0) + (py - y0) * (py - y0) > reach2
    for r in range(n_colliders(rects)):
        if rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX] and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]:
            near = True
    if near:
        x[i, 0], x[i, 1], v[i, 0], v[i, 1], _, _, _, _ = collide_point(x0, y0, px, py, v[i, 0], v[i, 1], rects, h)


@njit(cache=True, inline="always")
def _keep_out_three(x, v, xp, rects, reach2, h, ip, ia, ib, k, a, b):
    _keep_out(x, v, ip, xp[k, 0], xp[k, 1], rects, reach2, h)
    _keep_out(x, v, ia, xp[a, 0], xp[a, 1], rects, reach2, h)
    _keep_out(x, v, ib, xp[b, 0], xp[b, 1], rects, reach2, h)


@njit(cache=True, inline="always")
def _split(a, ip, ia, ib, wp, wa, wb, px, py):
    # a change (px, py) of the pair, shared by the vertex and the edge's ends by inverse mass
    a[ip, 0] += wp * px
    a[ip, 1] += wp * py
    a[ia, 0] -= wa * px
    a[ia, 1] -= wa * py
    a[ib, 0] -= wb * px
    a[ib, 1] -= wb * py


@njit(cache=True)
def solve_contacts(x, v, inv_mass, topo, scr, out, first, last, rects, h, iterations, follow=True):
    """Impulses (once) and position corrections (``iterations`` sweeps) for contacts ``first:last``.

    See the module docstring; linear momentum is kept exactly, since every impulse is split
    between the vertex and the edge's ends by inverse mass. ``follow``: the impulses move the
    vertices too, by ``h`` times their velocity change (see :func:`contact_stage`). A vertex
    the response moves into a collider meets it at once
    (:func:`~deforma.physics.colliders.collide_point`), so that the sweeps settle with the
    colliders in place.
    """
    cv, ce_a, ce_b = topo.cv_vertex, topo.ce_a, topo.ce_b
    o_vertex, o_edge, o_s, o_normal, o_target, o_mu = out.vertex, out.edge, out.s, out.normal, out.target, out.mu
    xp = scr.xp
    check_rects = rects.shape[0] > 0
    reach2 = jump_reach(rects)
    status = scr.status
    dirty, dirty_mark, touched, touched_mark = scr.dirty, scr.dirty_mark, scr.touched, scr.touched_mark
    gen, stamp = status[ST_GEN], status[ST_STAMP]
    for c in range(first, last):  # the vertices this solve may move
        _note_moved(o_vertex[c], dirty, dirty_mark, gen, touched, touched_mark, stamp, status)
        _note_moved(ce_a[o_edge[c]], dirty, dirty_mark, gen, touched, touched_mark, stamp, status)
        _note_moved(ce_b[o_edge[c]], dirty, dirty_mark, gen, touched, touched_mark, stamp, status)
    inv_h = 1.0 / h
    for sweep in range(iterations):
        for c in range(first, last):
            ip = cv[o_vertex[c]]
            ia = cv[ce_a[o_edge[c]]]
            ib = cv[ce_b[o_edge[c]]]
            s = o_s[c]
            ca = 1.0 - s
            wp = inv_mass[ip]
            wa = inv_mass[ia] * ca
            wb = inv_mass[ib] * s
            w = wp + wa * ca + wb * s
            if w <= 0.0:
                continue  # both sides pinned
            nx = o_normal[c, 0]
            ny = o_normal[c, 1]
            if sweep == 0:
                # Speculative: a pair still farther than its target may approach by what is
                # left of the gap in the next substep, no more; closer pairs may not approach.
                # So a resting pair's support never lapses (it would pop out and back in).
                d = _pair_distance(x, ip, ia, ib, s, nx, ny)
                allowed = -max(d - o_target[c], 0.0) * inv_h
                rvx = v[ip, 0] - ca * v[ia, 0] - s * v[ib, 0]
                rvy = v[ip, 1] - ca * v[ia, 1] - s * v[ib, 1]
                vn = rvx * nx + rvy * ny
                if vn < allowed:
                    jn = allowed - vn
                    vt = ny * rvx - nx * rvy        # along t = (ny, -nx)
                    dvt = coulomb(vt, jn, o_mu[c, 1], o_mu[c, 0]) - vt
                    px = (jn * nx + dvt * ny) / w   # the pair's impulse per unit inverse mass
                    py = (jn * ny - dvt * nx) / w
                    _split(v, ip, ia, ib, wp, wa, wb, px, py)
                    if follow:  # positions follow: no creep
                        _split(x, ip, ia, ib, wp, wa, wb, h * px, h * py)
                    if check_rects:
                        _keep_out_three(x, v, xp, rects, reach2, h, ip, ia, ib, o_vertex[c], ce_a[o_edge[c]],
                                        ce_b[o_edge[c]])
            d = _pair_distance(x, ip, ia, ib, s, nx, ny)
            gap = o_target[c] - d
            if gap > 0.0:
                lam = gap / w
                _split(x, ip, ia, ib, wp, wa, wb, lam * nx, lam * ny)
                if check_rects:
                    _keep_out_three(x, v, xp, rects, reach2, h, ip, ia, ib, o_vertex[c], ce_a[o_edge[c]],
                                    ce_b[o_edge[c]])


@njit(cache=True)
def find_root(parent, k):
    """The root of ``k`` in the union-find forest ``parent``, halving the path on the way."""
    while parent[k] != k:
        parent[k] = parent[parent[k]]
        k = parent[k]
    return k


@njit(cache=True)
def _refresh(x, topo, scr, out, margin, n_pairs):
    """Rebuild the grid and the candidate pairs if a vertex moved further than ``margin`` since
    the grid was built (only moved vertices can have); returns ``(pairs, rebuilt)`` (pairs
    negative if they did not fit). After a rebuild every pair must be checked again."""
    cv, xq = topo.cv_vertex, scr.xq
    for d in range(scr.status[ST_DIRTY]):
        k = scr.dirty[d]
        if abs(x[cv[k], 0] - xq[k, 0]) > margin or abs(x[cv[k], 1] - xq[k, 1]) > margin:
            build_grid(x, topo, scr, margin)
            n = narrow_phase(x, topo, scr, out)
            if n >= 0:
                index_pairs(topo, scr, out, n)
            return n, True
    return n_pairs, False


@njit(cache=True)
def impact_zones(x, v, inv_mass, topo, scr, out, first, n_pairs, rects, h):
    """The fail-safe: merge crossing pairs into rigidly translating zones until none is left.

    Checks the pairs of the vertices moved since the last check (``scr.dirty``), and keeps
    its bookkeeping to the zones' members, so that a few crossings in a large heap cost
    little. Returns the number of merge rounds, or ``-(needed)`` if ``out`` is too small
    (then ``scr.status`` says which part).
    """
    cv, ce_a, ce_b, o_vertex, o_edge = topo.cv_vertex, topo.ce_a, topo.ce_b, out.vertex, out.edge
    parent, zone, xp = scr.parent, scr.zone, scr.xp
    zl, zm = scr.zone_list, scr.zone_mark
    status = scr.status
    dirty, dirty_mark, touched, touched_mark = scr.dirty, scr.dirty_mark, scr.touched, scr.touched_mark
    margin = topo.margin[0]
    call = status[ST_GEN]  # marks this call's zone members
    nz = 0
    for rounds in range(status[ST_ACTIVE] + 1):
        n_pairs, rebuilt = _refresh(x, topo, scr, out, margin, n_pairs)
        if n_pairs < 0:
            status[ST_PAIRS_NEEDED] = -n_pairs
            return n_pairs
        n = check_pairs(x, topo, scr, out, first, n_pairs, rebuilt, True)
        if n < 0:
            status[ST_NEEDED] = -n
            return n
        if n == first:
            return rounds
        for c in range(first, n):
            for q in (o_vertex[c], ce_a[o_edge[c]], ce_b[o_edge[c]]):
                if zm[q] != call:
                    zm[q] = call
                    parent[q] = q
                    zl[nz] = q
                    nz += 1
            k = find_root(parent, o_vertex[c])
            for q in (ce_a[o_edge[c]], ce_b[o_edge[c]]):
                r = find_root(parent, q)
                if r != k:
                    parent[r] = k
        # zone sums: m vx, m vy, m, members, still (1: a pinned member, 2: pushed into a collider)
        for m in range(nz):
            zone[zl[m], :] = 0.0
        for m in range(nz):
            k = zl[m]
            r = find_root(parent, k)
            i = cv[k]
            zone[r, 3] += 1.0
            if inv_mass[i] == 0.0:
                zone[r, 4] = 1.0
            else:
                mass = 1.0 / inv_mass[i]
                zone[r, 0] += mass * v[i, 0]
                zone[r, 1] += mass * v[i, 1]
                zone[r, 2] += mass
        gen, stamp = status[ST_GEN], status[ST_STAMP]
        frozen = False
        for m in range(nz):
            k = zl[m]
            r = find_root(parent, k)
            i = cv[k]
            vx = 0.0
            vy = 0.0
            if zone[r, 4] == 0.0 and zone[r, 2] > 0.0:
                vx = zone[r, 0] / zone[r, 2]
                vy = zone[r, 1] / zone[r, 2]
            v[i, 0] = vx
            v[i, 1] = vy
            x[i, 0] = xp[k, 0] + h * vx
            x[i, 1] = xp[k, 1] + h * vy
            _note_moved(k, dirty, dirty_mark, gen, touched, touched_mark, stamp, status)
            if path_hits(xp[k, 0], xp[k, 1], x[i, 0], x[i, 1], rects):
                zone[r, 4] = 2.0
                frozen = True
        if frozen:  # a zone pushed into a collider stays where it started (outside, like every start)
            for m in range(nz):
                k = zl[m]
                if zone[find_root(parent, k), 4] == 2.0:
                    i = cv[k]
                    v[i, 0] = 0.0
                    v[i, 1] = 0.0
                    x[i, 0] = xp[k, 0]
                    x[i, 1] = xp[k, 1]
    return status[ST_ACTIVE] + 1


@njit(cache=True)
def contact_stage(x, v, inv_mass, topo, scr, out, rects, hits, h, follow=True):
    """Collide, solve and verify the body contacts of one substep (see the module docstring).

    Call it after the integrator has moved the vertices, with ``scr.xp`` holding the
    collision vertices' positions at the start of the substep (:func:`gather_start`).
    Updates ``x`` and ``v`` in place. Returns the number of contacts found, or -1 if
    ``out`` was too small (``scr.status[ST_NEEDED]`` / ``[ST_PAIRS_NEEDED]`` then say how
    many are needed; the substep is incomplete).

    ``follow`` (default True): a velocity impulse also moves its three vertices by ``h``
    times their velocity change, as if it had acted before the substep's positions were
    updated (symplectic Euler's order; a stuck vertex then does not creep). Implicit Euler
    passes False: it solves for the positions of the whole body at once, contacts included,
    and derives velocities from them, so moving the contact's vertices alone, after its
    solve, displaced them from the rest of their body by up to the substep's approach (7 cm
    for two bodies meeting at 5 m/s at 1/60 s, which folded them and raised the energy from
    6.3 J to 50 J); without it the impulse changes only their velocities, and the next solve
    carries the change through the body.
    """
    status = scr.status
    status[ST_STAMP] += 1
    status[ST_CONTACTS] = 0
    status[ST_PAIRS] = 0
    status[ST_DIRTY] = 0
    status[ST_TOUCHED] = 0
    n0, n_pairs = _collide(x, topo, scr, out)
    if n0 < 0:
        return -1
    status[ST_CONTACTS] = n0
    status[ST_PAIRS] = n_pairs
    if n0 == 0:
        return 0  # no contact and no crossing (a crossing is a contact too): nothing moved
    index_pairs(topo, scr, out, n_pairs)
    solve_contacts(x, v, inv_mass, topo, scr, out, 0, n0, rects, h, CONTACT_ITERATIONS, follow)
    end, n_pairs = _verify(x, v, inv_mass, topo, scr, out, n0, n_pairs, rects, h, follow)
    if end < 0:
        return -1
    # colliders have the last word (infinite mass): put back outside any vertex the response
    # pushed into one, then make sure that opened no crossing (a zone that would enter a
    # collider stays where it started, outside)
    if _collider_pass(x, v, topo, scr, rects, hits, h):
        r = impact_zones(x, v, inv_mass, topo, scr, out, end, n_pairs, rects, h)
        if r < 0:
            return -1
        if r > 0:
            status[ST_FAILSAFE] += 1
    return n0


@njit(cache=True)
def _collider_pass(x, v, topo, scr, rects, hits, h):
    """The collider response (:func:`~deforma.physics.colliders.collide_point`) for every vertex
    the stage moved into (or through) a collider; returns how many it moved, which it lists
    as moved for the next check."""
    cv, xp = topo.cv_vertex, scr.xp
    reach2 = jump_reach(rects)
    n_rects = n_colliders(rects)
    status = scr.status
    dirty, dirty_mark, touched, touched_mark = scr.dirty, scr.dirty_mark, scr.touched, scr.touched_mark
    moved = 0
    for m in range(status[ST_TOUCHED]):
        k = touched[m]
        i = cv[k]
        px, py = x[i, 0], x[i, 1]
        near = (px - xp[k, 0]) * (px - xp[k, 0]) + (py - xp[k, 1]) * (py - xp[k, 1]) > reach2
        for r in range(n_rects):  # the integrators' cheap tests first
            if rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX] and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]:
                near = True
        if near and path_hits(xp[k, 0], xp[k, 1], px, py, rects):
            x[i, 0], x[i, 1], v[i, 0], v[i, 1], hit, nx, ny, depth = collide_point(
                xp[k, 0], xp[k, 1], px, py, v[i, 0], v[i, 1], rects, h)
            record_hit(hits, i, status[ST_STAMP], hit, nx, ny, depth)
            _note_moved(k, dirty, dirty_mark, status[ST_GEN], touched, touched_mark, status[ST_STAMP], status)
            moved += 1
    return moved


@njit(cache=True)
def _verify(x, v, inv_mass, topo, scr, out, n0, n_pairs, rects, h, follow):
    """Step 4 of the module docstring; returns the end of the contacts stored (-1 if they did
    not fit) and the number of candidate pairs (which a rebuilt grid changes)."""
    status = scr.status
    margin = topo.margin[0]
    # Crossings left after the solve are solved again, together with those of earlier rounds:
    # two that hold each other (each corner against the other's edge) converge only together.
    end = n0
    for _ in range(VERIFY_ROUNDS):
        n_pairs, rebuilt = _refresh(x, topo, scr, out, margin, n_pairs)
        if n_pairs < 0:
            status[ST_PAIRS_NEEDED] = -n_pairs
            return -1, n_pairs
        n = check_pairs(x, topo, scr, out, end, n_pairs, rebuilt, True)
        if n < 0:
            status[ST_NEEDED] = -n
            return -1, n_pairs
        if n == end:
            return end, n_pairs
        end = n
        solve_contacts(x, v, inv_mass, topo, scr, out, n0, end, rects, h, CONTACT_ITERATIONS, follow)
    r = impact_zones(x, v, inv_mass, topo, scr, out, end, n_pairs, rects, h)
    if r < 0:
        return -1, n_pairs
    if r > 0:
        status[ST_FAILSAFE] += 1
    return end, n_pairs


@njit(cache=True)
def _colliding_bodies(topo):
    n = 0
    flags = topo.body_flags
    for b in range(flags.shape[0]):
        if flags[b] & COLLIDE:
            n += 1
    return n


@njit(cache=True)
def gather_start(x, topo, scr):
    """Note where the collision vertices are at the start of a substep (``scr.xp``).

    Every outline vertex; the other vertices of colliding bodies too when two or more bodies
    collide (they must not enter another body either, should their body fold), with each
    body's box of them, which :func:`contact_stage` grows to the swept box.
    """
    cv, xp, box = topo.cv_vertex, scr.xp, scr.body_box
    for k in range(topo.body_interior[0]):
        xp[k, 0] = x[cv[k], 0]
        xp[k, 1] = x[cv[k], 1]
    if _colliding_bodies(topo) < 2:
        return
    for b in range(topo.body_flags.shape[0]):
        box[b, 0] = np.inf
        box[b, 1] = np.inf
        box[b, 2] = -np.inf
        box[b, 3] = -np.inf
        if (topo.body_flags[b] & COLLIDE) == 0:
            continue
        for lo, hi in ((topo.body_outline[b], topo.body_outline[b + 1]),
                       (topo.body_interior[b], topo.body_interior[b + 1])):
            for k in range(lo, hi):
                px = x[cv[k], 0]
                py = x[cv[k], 1]
                xp[k, 0] = px
                xp[k, 1] = py
                box[b, 0] = min(box[b, 0], px)
                box[b, 1] = min(box[b, 1], py)
                box[b, 2] = max(box[b, 2], px)
                box[b, 3] = max(box[b, 3], py)


@njit(cache=True)
def _activate_inner(x, topo, scr, b, n, near, n_near):
    """Append to ``scr.active`` the off-outline vertices of body ``b`` whose swept box meets
    the box of one of the bodies ``near[:n_near]`` (grown by the margin)."""
    cv, xp, box, active = topo.cv_vertex, scr.xp, scr.body_box, scr.active
    margin = topo.margin[0]
    for k in range(topo.body_interior[b], topo.body_interior[b + 1]):
        x0 = min(xp[k, 0], x[cv[k], 0]) - margin
        x1 = max(xp[k, 0], x[cv[k], 0]) + margin
        y0 = min(xp[k, 1], x[cv[k], 1]) - margin
        y1 = max(xp[k, 1], x[cv[k], 1]) + margin
        for m in range(n_near):
            c = near[m]
            if x0 <= box[c, 2] and box[c, 0] <= x1 and y0 <= box[c, 3] and box[c, 1] <= y1:
                active[n] = k
                n += 1
                break
    return n


@njit(cache=True)
def _activate(x, topo, scr):
    """List the collision vertices to test this substep in ``scr.active``; returns how many.

    None if nothing can touch (no self contact and fewer than two colliding bodies). Else
    every outline vertex of a body with contacts on; and, of a colliding body, the other
    vertices whose swept box meets another colliding body's swept box (grown by the
    margin). Self contact keeps an outline from crossing itself, and a body whose
    triangles all keep their orientation lies inside its outline, so only a folded body
    can carry a vertex that is not on the outline into another; but where a body is folded
    at the end of the stage is not known before it (the response moves outline vertices),
    and a folded flap carries along vertices of triangles that are not turned over. So
    every vertex that may meet another body is tested: sound, and cheap, since a vertex
    off the outline meets another body's edges only where it has entered it.
    """
    cv, flags, box, active = topo.cv_vertex, topo.body_flags, scr.body_box, scr.active
    n = 0
    touching = _colliding_bodies(topo) >= 2
    for b in range(flags.shape[0]):
        touching = touching or (flags[b] & SELF_COLLIDE) != 0
    if not touching:  # one colliding body, without self contact: nothing can touch
        scr.status[ST_ACTIVE] = 0
        return 0
    for b in range(flags.shape[0]):
        if flags[b] != 0:
            for k in range(topo.body_outline[b], topo.body_outline[b + 1]):
                active[n] = k
                n += 1
    nb = flags.shape[0]
    if _colliding_bodies(topo) >= 2:
        margin = topo.margin[0]
        for b in range(nb):  # the start box (gather_start) grown to the end positions
            if (flags[b] & COLLIDE) == 0:
                continue
            for lo, hi in ((topo.body_outline[b], topo.body_outline[b + 1]),
                           (topo.body_interior[b], topo.body_interior[b + 1])):
                for k in range(lo, hi):
                    box[b, 0] = min(box[b, 0], x[cv[k], 0])
                    box[b, 1] = min(box[b, 1], x[cv[k], 1])
                    box[b, 2] = max(box[b, 2], x[cv[k], 0])
                    box[b, 3] = max(box[b, 3], x[cv[k], 1])
        near = np.empty(nb, np.int64)
        for b in range(nb):
            if (flags[b] & COLLIDE) == 0:
                continue
            n_near = 0
            for c in range(nb):
                if c == b or (flags[c] & COLLIDE) == 0:
                    continue
                if box[b, 0] - margin <= box[c, 2] and box[c, 0] - margin <= box[b, 2] \
                        and box[b, 1] - margin <= box[c, 3] and box[c, 1] - margin <= box[b, 3]:
                    near[n_near] = c
                    n_near += 1
            if n_near:
                n = _activate_inner(x, topo, scr, b, n, near, n_near)
    scr.status[ST_ACTIVE] = n
    return n


@njit(cache=True)
def rest_clearance(x, edges, reach):
    """How far each outline vertex lies in front of the nearest other outline edge, at rest.

    Only edges it is not an end of count, and only with its foot on the edge.

    Parameters
    ----------
    x : (V, 2) float64
        Rest positions of the outline vertices (m).
    edges : (E, 2) int32
        Directed outline edges into ``x`` (the body on their left).
    reach : float
        Distances at or beyond this (m) are reported as ``inf``.

    Returns
    -------
    (V,) float64

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0, 0], [2, 0], [2, 1], [1.0, 1.0], [1.0, 0.1], [0.9, 1.0], [0, 1]], float)
    >>> e = np.array([[k, (k + 1) % 7] for k in range(7)], np.int32)  # a slit from the top
    >>> round(float(rest_clearance(x, e, 10.0)[5]), 6)   # across the slit from edge 3-4
    0.1
    """
    out = np.full(x.shape[0], np.inf)
    for p in range(x.shape[0]):
        for j in range(edges.shape[0]):
            clear_against(x, p, edges[j, 0], edges[j, 1], reach, out)
    return out


@njit(cache=True, inline="always")
def clear_against(x, p, a, b, reach, out):
    """Lower ``out[p]`` to vertex ``p``'s distance in front of the edge ``a -> b`` (the body on
    its left) if ``p`` is not one of its ends, lies within ``reach`` of its box and its foot
    falls on the edge: the one test of :func:`rest_clearance` and its grid version
    (``deforma.physics.model``)."""
    if a == p or b == p:
        return
    px, py = x[p, 0], x[p, 1]
    ax, ay, bx, by = x[a, 0], x[a, 1], x[b, 0], x[b, 1]
    if px < min(ax, bx) - reach or px > max(ax, bx) + reach or py < min(ay, by) - reach \
            or py > max(ay, by) + reach:
        return
    ex = bx - ax
    ey = by - ay
    l2 = ex * ex + ey * ey
    s = ((px - ax) * ex + (py - ay) * ey) / l2
    if s < 0.0 or s > 1.0:
        return
    d = ((px - ax) * ey - (py - ay) * ex) / math.sqrt(l2)
    if 0.0 <= d < out[p]:
        out[p] = d


@dataclass(frozen=True)
class Contacts:
    """The contacts of the last substep, as arrays (struct of arrays, one row per contact).

    Collider contacts come first: the vertices the collider response put back outside a
    collider. Then body contacts: what the contact stage found before its response (a
    vertex against another body's outline edge, or against its own).

    Attributes
    ----------
    vertex : (C,) int64
        World vertex index (rows of the world's state arrays).
    collider : (C,) int64
        Index into ``world.colliders``, or -1 for a body contact.
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
    """

    vertex: np.ndarray
    collider: np.ndarray
    edge: np.ndarray
    weight: np.ndarray
    normal: np.ndarray
    depth: np.ndarray
    friction: np.ndarray
    static_friction: np.ndarray

    def __len__(self) -> int:
        return len(self.vertex)

    @property
    def body_contacts(self) -> np.ndarray:
        """(C,) bool: rows that are body (edge) contacts."""
        return self.collider < 0


def snapshot(topo: ContactTopology, scr: ContactScratch, buf: ContactBuffer, hits, rects) -> Contacts:
    """The contacts of the last substep as a :class:`Contacts`, in world vertex indices.

    ``hits`` is the world's ``ColliderHits`` record and ``rects`` the packed colliders (for
    the coefficients each collider contact used).
    """
    n = int(scr.status[ST_CONTACTS])
    k = buf.vertex[:n]
    j = buf.edge[:n]
    cv = topo.cv_vertex.astype(np.int64)
    edge = np.stack([cv[topo.ce_a[j]], cv[topo.ce_b[j]]], axis=1) if n else np.zeros((0, 2), np.int64)
    touched = np.flatnonzero(hits.stamp == scr.status[ST_STAMP]) if scr.status[ST_STAMP] > 0 else np.zeros(0, int)
    col = hits.collider[touched].astype(np.int64)
    m = len(touched)
    return Contacts(
        vertex=np.concatenate([touched.astype(np.int64), cv[k]]),
        collider=np.concatenate([col, np.full(n, -1, np.int64)]),
        edge=np.concatenate([np.full((m, 2), -1, np.int64), edge]),
        weight=np.concatenate([np.zeros(m), buf.s[:n]]),
        normal=np.concatenate([hits.normal[touched], buf.normal[:n]]),
        depth=np.concatenate([hits.depth[touched], buf.depth[:n]]),
        friction=np.concatenate([rects[col, RECT_FRICTION], buf.mu[:n, 0]]),
        static_friction=np.concatenate([rects[col, RECT_STATIC_FRICTION], buf.mu[:n, 1]]))


@njit(cache=True)
def _segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
    d1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    d2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    d3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    d4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    return ((d1 > 0.0) != (d2 > 0.0) or d1 == 0.0 or d2 == 0.0) and \
        ((d3 > 0.0) != (d4 > 0.0) or d3 == 0.0 or d4 == 0.0) and \
        max(ax, bx) >= min(cx, dx) and max(cx, dx) >= min(ax, bx) and \
        max(ay, by) >= min(cy, dy) and max(cy, dy) >= min(ay, by)


@njit(cache=True)
def _inside_outline(px, py, x, edges):
    inside = False  # even-odd rule: holes are outlines too
    for j in range(edges.shape[0]):
        ax, ay = x[edges[j, 0], 0], x[edges[j, 0], 1]
        bx, by = x[edges[j, 1], 0], x[edges[j, 1], 1]
        if (ay > py) != (by > py):
            if px < ax + (py - ay) * (bx - ax) / (by - ay):
                inside = not inside
    return inside


@njit(cache=True)
def outlines_overlap(xa, ea, xb, eb):
    """Whether two bodies overlap: an outline segment of one touches one of the other, or a
    boundary vertex of one lies inside the other's outlines (holes excluded).

    Parameters
    ----------
    xa, xb : (N, 2) float64
        Vertex positions (m).
    ea, eb : (E, 2) int32
        Boundary edges (vertex indices).

    Examples
    --------
    >>> import numpy as np
    >>> sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    >>> e = np.array([[0, 1], [1, 2], [2, 3], [3, 0]], np.int32)
    >>> outlines_overlap(sq, e, sq + 0.5, e), outlines_overlap(sq, e, sq + 1.5, e)
    (True, False)
    >>> outlines_overlap(sq, e, 0.25 * sq + 0.3, e)   # one inside the other
    True
    """
    lo_a = np.full(2, np.inf)
    hi_a = np.full(2, -np.inf)
    lo_b = np.full(2, np.inf)
    hi_b = np.full(2, -np.inf)
    for j in range(ea.shape[0]):
        for c in range(2):
            lo_a[c] = min(lo_a[c], xa[ea[j, 0], c])
            hi_a[c] = max(hi_a[c], xa[ea[j, 0], c])
    for j in range(eb.shape[0]):
        for c in range(2):
            lo_b[c] = min(lo_b[c], xb[eb[j, 0], c])
            hi_b[c] = max(hi_b[c], xb[eb[j, 0], c])
    if lo_a[0] > hi_b[0] or lo_b[0] > hi_a[0] or lo_a[1] > hi_b[1] or lo_b[1] > hi_a[1]:
        return False
    for i in range(ea.shape[0]):
        ax, ay = xa[ea[i, 0], 0], xa[ea[i, 0], 1]
        bx, by = xa[ea[i, 1], 0], xa[ea[i, 1], 1]
        if max(ax, bx) < lo_b[0] or min(ax, bx) > hi_b[0] or max(ay, by) < lo_b[1] or min(ay, by) > hi_b[1]:
            continue
        for j in range(eb.shape[0]):
            if _segments_cross(ax, ay, bx, by, xb[eb[j, 0], 0], xb[eb[j, 0], 1], xb[eb[j, 1], 0], xb[eb[j, 1], 1]):
                return True
    # no outline touches: overlapping only if one lies inside the other, then all its vertices do
    return _inside_outline(xa[ea[0, 0], 0], xa[ea[0, 0], 1], xb, eb) or \
        _inside_outline(xb[eb[0, 0], 0], xb[eb[0, 0], 1], xa, ea)

"""The point collision + Coulomb friction response against colliders of every shape.

A leaf module: it knows shapes (:mod:`~deforma.physics.colliders.shapes`, packed into one array) and
points, not worlds or bodies.

The scheme, per vertex and substep of length ``h`` (velocities already updated by the
integrator, ``p = p_prev + h*v``; the colliders already moved to the end of the substep):

1. Test the point against every collider (a bounding box rejects far points first; then
   per kind: the rectangle's local-axes test, the distance to a circle's centre or a
   capsule's segment, an even-odd crossing count over a polygon's edges, holes included).
2. If it is inside, choose where to leave by, from the *previous* position seen from the
   collider (where it would be had it ridden on it): a rectangle's face among those the
   previous position was outside of (the way it came in), the one with the least
   penetration; a polygon's edge the path came in through; a round shape's nearest
   surface point. If it was inside already (spawned there, or the collider moved onto
   it), the shortest way out.
3. Split the velocity *relative to the collider's surface there* (``v + w x (q - c)``:
   zero for a fixed collider) into normal ``vn`` and tangential ``vt`` parts. An inward
   ``vn`` is removed; its size ``jn = -vn`` is the normal impulse per unit mass this
   substep, i.e. ``h * N / m``. Coulomb friction then acts on ``vt``
   (:func:`deforma.physics.contact.friction.coulomb`, the rule body contacts use too): if
   ``|vt| <= static_friction * jn`` the vertex sticks (``vt = 0``: it moves with the
   surface, so a conveyor carries it), otherwise dynamic friction removes
   ``friction * jn`` from ``|vt|`` (never reversing it).
4. Put the point on the surface (plus a nanometre skin so it is strictly outside) and
   move it along the surface by ``h * (vt_new - vt_old)``: the position is the one the
   *corrected* velocity would have produced. Correcting only the velocity after the
   position update (as many codes do) lets a stuck vertex creep by ``h * vt`` every
   substep; correcting only the position (the original restored the whole previous
   position) makes sliding impossible.

With this, the total friction on a block is exactly ``friction * sum(N)`` while it slides
(acceleration ``g (sin a - mu cos a)`` on a slope) and a block whose bottom vertices all
satisfy the static test does not move at all. A point that moved further in a substep than
a collider's half-thickness gets a swept test of its path (it may have jumped a thin one).

A rigid body's outline (a row with ``INV_MASS`` > 0, :mod:`deforma.physics.rigid`) is not a
collider here: :func:`collide_point` and :func:`contact_planes` pass it by, and
:func:`collide_dynamic` resolves the points in it, one at a time, with the impulse between two
masses (the point's and the body's, which takes the opposite at once), so a light crate hit by
a heavy jelly moves off as the jelly arrives rather than stopping it as a wall would.

Units: m, m/s; the packed array holds angles in radians.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from ..contact.friction import coulomb
from .geometry import exit_face, point_inside, n_colliders, relative_start, swept_entry
from .shapes import (
    EDGE_AX,
    EDGE_AY,
    INV_INERTIA,
    INV_MASS,
    KIND,
    OMEGA,
    POLYGON,
    RECT,
    RECT_CX,
    RECT_CY,
    RECT_FRICTION,
    RECT_HX,
    RECT_HY,
    RECT_REACH,
    RECT_SKIN,
    RECT_STATIC_FRICTION,
    RECT_UX,
    RECT_UY,
    RECT_XMAX,
    RECT_XMIN,
    RECT_YMAX,
    RECT_YMIN,
    VEL_X,
    VEL_Y,
)

# Per vertex of a world, the last collider contact: written only when a vertex touches one.
ColliderHits = namedtuple("ColliderHits", [
    "stamp",            # (N,) int64: the substep it happened in (see contacts.ST_STAMP)
    "collider",         # (N,) int32: which collider
    "normal",           # (N, 2) float64: the face's outward normal
    "depth",            # (N,) float64: how deep inside it the vertex was (m)
    "dv",               # (N, 2) float64: the velocity changes the collider response made (m/s), summed
                        #   until cleared: times the vertex's mass, the impulse it took (a rigid body
                        #   takes the opposite, deforma.physics.rigid)
    "dm",               # (N,) float64: the change of x cross v each made, about the origin (m^2/s): times
                        #   the mass, the angular momentum the vertex took
    "dv_collider",      # (N,) int32: the collider of the last of them
])


def make_hits(n_vertices: int) -> ColliderHits:
    """An empty record for ``n_vertices`` vertices (no substep has stamp -1)."""
    return ColliderHits(np.full(n_vertices, -1, np.int64), np.zeros(n_vertices, np.int32),
                        np.zeros((n_vertices, 2)), np.zeros(n_vertices), np.zeros((n_vertices, 2)),
                        np.zeros(n_vertices), np.full(n_vertices, -1, np.int32))


def clear_impulses(hits: ColliderHits) -> None:
    """Forget the velocity changes ``hits`` summed (``dv``, ``dm``, ``dv_collider``)."""
    hits.dv[...] = 0.0
    hits.dm[...] = 0.0
    hits.dv_collider[...] = -1


# Pushing a point out of one collider can push it into a touching one; a few passes settle
# every sane arrangement, and a point still trapped falls back to its previous position.
MAX_PASSES = 4


@njit(cache=True)
def collide_point(x0, y0, px, py, vx, vy, rects, h):
    """Resolve one point against all colliders.

    Returns ``(px, py, vx, vy, hit, nx, ny, depth)``: the new position and velocity, the
    index of the last collider the point was put out of (-1 if none), that surface's
    outward normal and how deep (m) the point was inside it. A moving collider's surface
    velocity (``v + w x (q - c)`` at the surface point ``q``) is the reference for the
    normal and friction response: what rests on a moving platform moves with it.

    Parameters
    ----------
    x0, y0 : float
        Position at the start of the substep (m), tells which face the point came through.
    px, py, vx, vy : float
        Position (m) and velocity (m/s) after the unconstrained substep.
    rects : (R, RECT_COLUMNS) float64
        From :func:`~deforma.physics.colliders.shapes.pack_colliders`, at the end of the substep.
    h : float
        Substep length in seconds.

    Examples
    --------
    >>> from deforma.physics.colliders.shapes import Rect, pack_colliders
    >>> r = pack_colliders([Rect((0, -1), (10, 2), 0.0)], friction=0.3, static_friction=0.5)
    >>> px, py, vx, vy, hit, nx, ny, depth = collide_point(0.0, 0.0, 0.01, -0.01, 1.0, -1.0, r, 0.01)
    >>> round(py, 6), vy, round(vx, 3), hit, (nx, ny), round(depth, 6)
    (0.0, 0.0, 0.7, 0, (-0.0, 1.0), 0.01)

    A point that jumped over a thin rectangle within the substep is caught too:

    >>> thin = pack_colliders([Rect((0, 0), (10, 0.02), 0.0)], friction=0.3, static_friction=0.5)
    >>> px, py, vx, vy, hit, nx, ny, depth = collide_point(0.0, 0.05, 0.0, -0.05, 0.0, -10.0, thin, 0.01)
    >>> hit, round(py, 6), vy
    (0, 0.01, 0.0)

    A point at rest on a platform rising at 1 m/s (its top at 0 a substep ago, 1 cm up now)
    rises with it:

    >>> lift = pack_colliders([Rect((0, -0.99), (10, 2), 0.0, velocity=(0, 1))], friction=0.3, static_friction=0.5)
    >>> px, py, vx, vy, hit, nx, ny, depth = collide_point(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, lift, 0.01)
    >>> round(py, 6), vy
    (0.01, 1.0)
    """
    # the swept test only for a point that moved further than some collider's half-thickness
    # (rare), and decided inline: a call per point would cost reference counting on rects
    d2 = (px - x0) * (px - x0) + (py - y0) * (py - y0)
    jumpy = False
    for r in range(n_colliders(rects)):
        if d2 > rects[r, RECT_REACH]:
            jumpy = True
    if jumpy:
        inside = False
        for r in range(n_colliders(rects)):
            if rects[r, INV_MASS] == 0.0 and point_inside(rects, r, px, py):
                inside = True
        if not inside:
            px, py = swept_entry(x0, y0, px, py, rects)
    hit = False
    last = -1
    hx_n = 0.0
    hy_n = 0.0
    last_depth = 0.0
    for _ in range(MAX_PASSES):
        hit = False
        for r in range(n_colliders(rects)):
            if rects[r, INV_MASS] != 0.0 or not point_inside(rects, r, px, py):
                continue  # outside, or a rigid body's outline (collide_dynamic's)
            hit = True
            rx0, ry0 = relative_start(rects, r, x0, y0, h)
            nx, ny, qx, qy, best = exit_face(rects, r, rx0, ry0, px, py)
            tx, ty = -ny, nx
            w = rects[r, OMEGA]
            sx = rects[r, VEL_X] - w * (qy - rects[r, RECT_CY])  # the surface's velocity at q
            sy = rects[r, VEL_Y] + w * (qx - rects[r, RECT_CX])
            vn = (vx - sx) * nx + (vy - sy) * ny
            vt = (vx - sx) * tx + (vy - sy) * ty
            jn = 0.0
            if vn < 0.0:
                jn = -vn
                vn = 0.0
            vt_new = coulomb(vt, jn, rects[r, RECT_STATIC_FRICTION], rects[r, RECT_FRICTION])
            shift = h * (vt_new - vt)
            last = r
            hx_n = nx
            hy_n = ny
            last_depth = best
            skin = rects[r, RECT_SKIN]
            px = qx + skin * nx + shift * tx
            py = qy + skin * ny + shift * ty
            vx = sx + vn * nx + vt_new * tx
            vy = sy + vn * ny + vt_new * ty
        if not hit:
            break
    if hit:
        for r in range(n_colliders(rects)):
            if rects[r, INV_MASS] == 0.0 and point_inside(rects, r, px, py):
                # trapped between colliders: the original's answer, back to where it was
                return x0, y0, 0.0, 0.0, last, hx_n, hy_n, last_depth
    return px, py, vx, vy, last, hx_n, hy_n, last_depth


@njit(cache=True)
def contact_planes(x0, y, rects, planes, index, rows, dynamic, h):
    """The collider contacts a stable solver puts inside its solve: which vertices, and where.

    A vertex whose predicted end of substep ``y`` lies inside a collider gets the plane
    tangent to the surface point it would leave by (chosen as :func:`collide_point`
    chooses it, from where it started, ``x0``); of several colliders, the one it is
    deepest in. A point ``p`` is outside that plane when ``n . p >= c``. Only vertices
    headed inside are listed: the solvers hold a listed vertex near its iterate, and
    listing vertices a hair outside too made the next row up of a body on the floor
    follow its free fall (``docs/integrators.md``).

    Parameters
    ----------
    x0, y : (N, 2) float64
        Positions at the start of the substep and predicted at its end (m).
    rects : (R, RECT_COLUMNS) float64
        From :func:`~deforma.physics.colliders.shapes.pack_colliders`.
    planes : (N, 7) float64 or wider
        Output: ``nx, ny, c, static_friction, friction, sx, sy`` per listed vertex (the
        first ``count`` rows); ``(sx, sy)`` is how far the collider's surface moved there
        in the substep (m), which friction measures slip against.
    index : (N,) int32
        Output: the listed vertices, ascending.
    rows : (N,) int32
        Output: the packed row each listed vertex's plane is of.
    dynamic : bool
        Whether rigid bodies' outlines (rows with ``INV_MASS`` > 0) give planes too: for a
        solver that gives the body back what its planes did (implicit Euler,
        :func:`~deforma.physics.integrators.implicit.solver.rigid_plane_impulses`); else
        they are met after the solve, by :func:`collide_dynamic`.
    h : float
        Substep (s).

    Returns
    -------
    int
        ``count``, the number of listed vertices.

    Examples
    --------
    >>> import numpy as np
    >>> from deforma.physics.colliders.shapes import Rect, pack_colliders
    >>> floor = pack_colliders([Rect((0, -0.5), (10, 1.0), 0.0)], friction=0.3, static_friction=0.5)
    >>> planes, index, rows = np.zeros((2, 7)), np.zeros(2, np.int32), np.zeros(2, np.int32)
    >>> x0 = np.array([[0.0, 0.01], [1.0, 2.0]])
    >>> contact_planes(x0, x0 - [0.0, 0.02], floor, planes, index, rows, False, 0.01)  # the low one only
    1
    >>> int(index[0]), (planes[0] + 0.0).round(6).tolist()  # + 0.0 turns -0.0 into 0.0
    (0, [0.0, 1.0, 0.0, 0.5, 0.3, 0.0, 0.0])
    """
    count = 0
    for i in range(y.shape[0]):
        px, py = y[i, 0], y[i, 1]
        best_depth = -np.inf
        for r in range(n_colliders(rects)):
            if (rects[r, INV_MASS] != 0.0 and not dynamic) or not point_inside(rects, r, px, py):
                continue
            rx0, ry0 = relative_start(rects, r, x0[i, 0], x0[i, 1], h)
            nx, ny, qx, qy, depth = exit_face(rects, r, rx0, ry0, px, py)
            if depth > best_depth:
                best_depth = depth
                w = rects[r, OMEGA]
                rows[count] = r
                planes[count, 0] = nx
                planes[count, 1] = ny
                planes[count, 2] = qx * nx + qy * ny + rects[r, RECT_SKIN]
                planes[count, 3] = rects[r, RECT_STATIC_FRICTION]
                planes[count, 4] = rects[r, RECT_FRICTION]
                planes[count, 5] = h * (rects[r, VEL_X] - w * (qy - rects[r, RECT_CY]))
                planes[count, 6] = h * (rects[r, VEL_Y] + w * (qx - rects[r, RECT_CX]))
        if best_depth > -np.inf:
            index[count] = i
            count += 1
    return count


@njit(cache=True, inline="always")
def note_impulse(hits, i, r, qx, qy, ux, uy, px, py, vx, vy):
    """Add to ``hits.dv`` and ``hits.dm`` what a collider ``r`` did to vertex ``i``'s velocity
    and angular momentum (from ``(qx, qy)`` at ``(ux, uy)`` to ``(px, py)`` at ``(vx, vy)``).
    The moment counts the move too (``p x v - q x u``, not ``p x (v - u)``): what a rigid
    outline takes back is then exactly what the vertex gained, angular momentum included."""
    hits.dv[i, 0] += vx - ux
    hits.dv[i, 1] += vy - uy
    hits.dm[i] += (px * vy - py * vx) - (qx * uy - qy * ux)
    hits.dv_collider[i] = r


@njit(cache=True, inline="always")
def record_hit(hits, i, stamp, r, nx, ny, depth, qx, qy, ux, uy, px, py, vx, vy):
    """Note in ``hits`` (a :class:`ColliderHits`) that vertex ``i`` touched collider ``r`` in
    substep ``stamp``, and that the response took it from ``(qx, qy)`` m moving at ``(ux, uy)``
    m/s to ``(px, py)`` moving at ``(vx, vy)``."""
    hits.stamp[i] = stamp
    hits.collider[i] = r
    hits.normal[i, 0] = nx
    hits.normal[i, 1] = ny
    hits.depth[i] = depth
    note_impulse(hits, i, r, qx, qy, ux, uy, px, py, vx, vy)


@njit(cache=True, inline="always")
def push_rigid_row(rects, r, ax, ay, jx, jy):
    """Give the rigid body of packed row ``r`` the impulse ``-(jx, jy)`` (N s) at the arm
    ``(ax, ay)`` from its centre: the opposite of what a soft vertex took from it, so that
    the next vertex meets it moving (its row's velocity and spin)."""
    rects[r, VEL_X] -= rects[r, INV_MASS] * jx
    rects[r, VEL_Y] -= rects[r, INV_MASS] * jy
    rects[r, OMEGA] -= rects[r, INV_INERTIA] * (ax * jy - ay * jx)


@njit(cache=True, inline="always")
def has_rigid_rows(rects) -> bool:
    """Whether any packed row is a rigid body's outline (``INV_MASS`` > 0)."""
    for r in range(n_colliders(rects)):
        if rects[r, INV_MASS] != 0.0:
            return True
    return False


@njit(cache=True)
def collide_dynamic(x, v, inv_mass, x_start, rects, hits, stamp, h):
    """Points against rigid bodies' outlines (rows with ``INV_MASS`` > 0), in turn: each point
    inside one leaves it as from a collider (the exit of :func:`collide_point`'s step 2, from
    where it started, seen from the body), and the two take equal and opposite impulses at the
    surface point ``q``: along the normal, what stops their approach (``jn = -vn / kn``, with
    ``kn = w + W + I^-1 (r x n)^2``, ``w`` the point's 1/mass, ``W`` the body's, ``r = q - c``),
    along the surface Coulomb's rule on the pair (sticking takes ``-vt / kt``; more than
    ``static_friction * jn`` slides with ``friction * jn``). The body's velocity in its row
    changes at once, so the next point meets it moving: a pile of points arriving together
    pushes a light body off instead of each stopping as against a wall. Each point's change
    goes to ``hits`` as any collider hit's (the rigid stage gives the body its total).

    Parameters
    ----------
    x, v : (N, 2) float64
        Positions (m) and velocities (m/s) at the end of the substep, updated in place.
    inv_mass : (N,) float64
        1/kg (0: pinned or a rigid body's own vertex, not moved).
    x_start : (N, 2) float64
        Where each was at the start of the substep (m). Every vertex is tested, not only
        the outlines: a coarse body's inner vertices meet a rigid body too when it is hit
        hard (a rubber donut whose outline alone was kept out blew up).
    rects : (R, RECT_COLUMNS) float64
        Packed colliders, rigid outlines among them (their velocity columns updated).
    hits : ColliderHits
    stamp : int
        This substep's number (see :func:`record_hit`).
    h : float
        Substep (s).

    Returns
    -------
    int
        How many points it moved.

    Examples
    --------
    A 1 kg point at 2 m/s into the left face of a resting 1 kg square: both end at 1 m/s
    (a perfectly inelastic collision along the normal through the centre).

    >>> import numpy as np
    >>> from deforma.physics.colliders.shapes import INV_INERTIA, INV_MASS, Rect, pack_colliders
    >>> r = pack_colliders([Rect((0, 0), (1, 1), 0.0)], friction=0.0, static_friction=0.0)
    >>> r[0, INV_MASS], r[0, INV_INERTIA] = 1.0, 6.0
    >>> x, v = np.array([[-0.49, 0.0]]), np.array([[2.0, 0.0]])
    >>> collide_dynamic(x, v, np.ones(1), np.array([[-0.51, 0.0]]), r, make_hits(1), 1, 0.01)
    1
    >>> v.tolist(), r[0, 15:18].tolist(), round(float(x[0, 0]), 6)
    ([[1.0, 0.0]], [1.0, 0.0, 0.0], -0.5)
    """
    moved = 0
    n_rects = n_colliders(rects)
    if not has_rigid_rows(rects):
        return 0
    for i in range(x.shape[0]):
        w = inv_mass[i]
        if w == 0.0:
            continue
        px, py = x[i, 0], x[i, 1]
        for r in range(n_rects):
            big_w = rects[r, INV_MASS]
            if big_w == 0.0 or not (rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX]
                                    and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]):
                continue
            if not point_inside(rects, r, px, py):
                continue
            rx0, ry0 = relative_start(rects, r, x_start[i, 0], x_start[i, 1], h)
            nx, ny, qx, qy, depth = exit_face(rects, r, rx0, ry0, px, py)
            tx, ty = -ny, nx
            cx, cy = rects[r, RECT_CX], rects[r, RECT_CY]
            ax, ay = qx - cx, qy - cy
            om = rects[r, OMEGA]
            ux, uy = v[i, 0], v[i, 1]
            rvx, rvy = ux - rects[r, VEL_X] + om * ay, uy - rects[r, VEL_Y] - om * ax  # relative to q on the body
            vn = rvx * nx + rvy * ny
            vt = rvx * tx + rvy * ty
            big_i = rects[r, INV_INERTIA]
            an = ax * ny - ay * nx
            at = ax * ty - ay * tx
            kn = w + big_w + big_i * an * an
            kt = w + big_w + big_i * at * at
            jn = -vn / kn if vn < 0.0 else 0.0
            # Coulomb's rule on the relative motion: sticking changes vt by -vt, i.e. takes
            # -vt / kt; the cone's bound on that change is static_friction * kt * jn
            jt = (coulomb(vt, jn * kt, rects[r, RECT_STATIC_FRICTION], rects[r, RECT_FRICTION]) - vt) / kt
            jx, jy = jn * nx + jt * tx, jn * ny + jt * ty
            vx, vy = ux + w * jx, uy + w * jy
            push_rigid_row(rects, r, ax, ay, jx, jy)
            skin = rects[r, RECT_SKIN]
            shift = h * w * jt  # the position the corrected velocity would have reached
            qx2, qy2 = qx + skin * nx + shift * tx, qy + skin * ny + shift * ty
            record_hit(hits, i, stamp, r, nx, ny, depth, px, py, ux, uy, qx2, qy2, vx, vy)
            # a collider has the last word: a point the body pushed into one (squeezed between
            # a crate and the floor) goes back out of it, as the collider response puts it
            fx, fy, fvx, fvy, hit, fnx, fny, fdepth = collide_point(px, py, qx2, qy2, vx, vy, rects, h)
            if hit >= 0:
                record_hit(hits, i, stamp, hit, fnx, fny, fdepth, qx2, qy2, vx, vy, fx, fy, fvx, fvy)
                qx2, qy2, vx, vy = fx, fy, fvx, fvy
            x[i, 0], x[i, 1], v[i, 0], v[i, 1] = qx2, qy2, vx, vy
            px, py = qx2, qy2
            moved += 1
    return moved


@njit(cache=True, inline="always")
def collider_corner(rects, r, k):
    """Corner ``k`` of collider ``r`` (a rectangle's four counter-clockwise from its local (+x,
    -y) corner, or a polygon's edges' first ends), in metres."""
    if rects[r, KIND] == RECT:
        cx, cy = rects[r, RECT_CX], rects[r, RECT_CY]
        ux, uy = rects[r, RECT_UX], rects[r, RECT_UY]
        sx = rects[r, RECT_HX] if k == 0 or k == 3 else -rects[r, RECT_HX]
        sy = rects[r, RECT_HY] if k < 2 else -rects[r, RECT_HY]
        return cx + sx * ux - sy * uy, cy + sx * uy + sy * ux
    e = np.int64(rects[r, RECT_HX]) + k
    return rects[e, EDGE_AX], rects[e, EDGE_AY]


@njit(cache=True, inline="always")
def corner_count(rects, r):
    """How many corners collider ``r`` has (0: a round shape, which has none)."""
    kind = rects[r, KIND]
    if kind == RECT:
        return 4
    if kind == POLYGON:
        return np.int64(rects[r, RECT_HY])
    return 0


#: Columns of :func:`corner_contacts`' float output: the edge point's parameter ``s``, the
#: row's unit normal into the body (the edge's, or from the corner to the edge's end), the
#: corner at the end of the substep, how far it moved in the substep, the static and dynamic
#: friction coefficients and the gap to hold (m).
CORNER_S, CORNER_NX, CORNER_NY, CORNER_PX, CORNER_PY, CORNER_MX, CORNER_MY = 0, 1, 2, 3, 4, 5, 6
CORNER_STATIC, CORNER_DYNAMIC, CORNER_TARGET = 7, 8, 9
CORNER_COLUMNS = 10


@njit(cache=True)
def corner_contacts(x0, y, rects, edge_a, edge_b, vertex, margin, h, pairs, out):
    """Collider corners an outline edge may meet in a substep, for a solver that holds them
    as rows (the stable solvers' counterpart of :func:`push_edges_off_corners`).

    Per outline edge ``(a, b)`` (directed with the body on its left) and fixed or moving
    collider (not a rigid body's outline), the corner that reaches furthest toward the body
    across the edge at the predicted end ``y``, if it lies beside the edge (``0 < s < 1``),
    within ``margin`` of it or through it by less than its length, and was outside the body
    across this edge at the start, ``x0`` (seen from the collider, by under 1 % of the edge's
    length): a corner already through an edge, or one behind the body's far side, is no
    contact of this edge's. A corner beside the edge at the start but predicted past an end
    is the edge's too, held by that end (``s`` 0 or 1) along the line from the corner to it,
    within ``margin``: the solve may end it beside the edge again, and listed by the
    prediction alone a corner at a resting body's outline vertex had a row every other step.

    Parameters
    ----------
    x0, y : (N, 2) float64
        Positions at the start of the substep and predicted at its end (m).
    rects : (R, RECT_COLUMNS) float64
        From :func:`~deforma.physics.colliders.shapes.pack_colliders`, at the end of the substep.
    edge_a, edge_b : (E,) int32
        Outline edges as collision-vertex indices (``ContactTopology.ce_a`` / ``ce_b``).
    vertex : (V,) int32
        Collision vertex -> row of ``x`` (``ContactTopology.cv_vertex``).
    margin : float
        How far a corner may be outside the edge and still be listed (m).
    h : float
        Substep (s).
    pairs : (K, 4) int64
        Output: the edge's two vertices (rows of ``x``), the edge and the collider.
    out : (K, CORNER_COLUMNS) float64
        Output: per contact, the columns ``CORNER_*``.

    Returns
    -------
    int
        The number of contacts, or ``-needed`` if ``pairs`` holds fewer.

    Examples
    --------
    >>> import numpy as np
    >>> from deforma.physics.colliders.shapes import Rect, pack_colliders
    >>> r = pack_colliders([Rect((0, 0), (2, 2), 45.0)], friction=0.3, static_friction=0.5)
    >>> x0 = np.array([[-1.0, 1.5], [1.0, 1.5]])  # an edge above the diamond's top corner, body above
    >>> pairs, out = np.zeros((4, 4), np.int64), np.zeros((4, CORNER_COLUMNS))
    >>> corner_contacts(x0, x0 - [0.0, 0.2], r, np.array([0], np.int32), np.array([1], np.int32),
    ...                 np.arange(2, dtype=np.int32), 0.3, 0.01, pairs, out)
    1
    >>> out[0, [CORNER_S, CORNER_NY, CORNER_PY]].round(6).tolist()  # beside the middle, the body above
    [0.5, 1.0, 1.414214]
    """
    count = 0
    n_rects = n_colliders(rects)
    for e in range(edge_a.shape[0]):
        ia = vertex[edge_a[e]]
        ib = vertex[edge_b[e]]
        ax, ay, bx, by = y[ia, 0], y[ia, 1], y[ib, 0], y[ib, 1]
        dx, dy = bx - ax, by - ay
        length2 = dx * dx + dy * dy
        if length2 == 0.0:
            continue
        inv_len = 1.0 / np.sqrt(length2)
        nx, ny = -dy * inv_len, dx * inv_len  # toward the body
        a0x, a0y, b0x, b0y = x0[ia, 0], x0[ia, 1], x0[ib, 0], x0[ib, 1]
        d0x, d0y = b0x - a0x, b0y - a0y
        len0 = np.sqrt(d0x * d0x + d0y * d0y)
        if len0 == 0.0:
            continue
        n0x, n0y = -d0y / len0, d0x / len0
        for r in range(n_rects):
            if rects[r, INV_MASS] != 0.0:
                continue
            if min(ax, bx) - margin >= rects[r, RECT_XMAX] or max(ax, bx) + margin <= rects[r, RECT_XMIN] \
                    or min(ay, by) - margin >= rects[r, RECT_YMAX] or max(ay, by) + margin <= rects[r, RECT_YMIN]:
                continue
            best, best_s, best_k = -margin, 0.0, -1
            best_px = best_py = best_mx = best_my = 0.0
            best_nx, best_ny = nx, ny
            w = rects[r, OMEGA]
            for k in range(corner_count(rects, r)):
                px, py = collider_corner(rects, r, k)
                # how far the corner moved in the substep: where it was at the start, against
                # where the edge was
                mx = h * (rects[r, VEL_X] - w * (py - rects[r, RECT_CY]))
                my = h * (rects[r, VEL_Y] + w * (px - rects[r, RECT_CX]))
                sx, sy = px - mx - a0x, py - my - a0y  # from the edge's start, as the substep began
                t = ((px - ax) * dx + (py - ay) * dy) / length2
                cnx, cny = nx, ny
                if 0.0 < t < 1.0:
                    depth = (px - ax) * nx + (py - ay) * ny
                else:
                    # predicted past an end but beside the edge as the substep began: the
                    # solve may well end it beside the edge again (a 2-step cycle left the
                    # ``demo`` bunny's ear buzzing on a ramp's corner, listed every other
                    # step), so the end holds it, along the line from the corner to the end
                    t0 = (sx * d0x + sy * d0y) / (len0 * len0)
                    if not 0.0 < t0 < 1.0:
                        continue
                    t = 1.0 if t > 0.0 else 0.0
                    qx, qy = ax + t * dx - px, ay + t * dy - py
                    dist = np.sqrt(qx * qx + qy * qy)
                    if dist == 0.0:
                        continue
                    depth = -dist
                    cnx, cny = qx / dist, qy / dist
                if not (depth > best and depth * depth < length2):
                    continue
                if sx * n0x + sy * n0y > 0.01 * len0:
                    continue
                best, best_s, best_k = depth, t, k
                best_px, best_py, best_mx, best_my = px, py, mx, my
                best_nx, best_ny = cnx, cny
            if best_k < 0:
                continue
            if count >= pairs.shape[0]:
                count += 1
                continue
            pairs[count, 0], pairs[count, 1], pairs[count, 2], pairs[count, 3] = ia, ib, e, r
            out[count, CORNER_S] = best_s
            out[count, CORNER_NX], out[count, CORNER_NY] = best_nx, best_ny
            out[count, CORNER_PX], out[count, CORNER_PY] = best_px, best_py
            out[count, CORNER_MX], out[count, CORNER_MY] = best_mx, best_my
            out[count, CORNER_STATIC] = rects[r, RECT_STATIC_FRICTION]
            out[count, CORNER_DYNAMIC] = rects[r, RECT_FRICTION]
            out[count, CORNER_TARGET] = rects[r, RECT_SKIN]
            count += 1
    return count if count <= pairs.shape[0] else -count


@njit(cache=True)
def push_edges_off_corners(x, v, inv_mass, edge_a, edge_b, vertex, rects, hits):
    """Collider corners against body outlines: push every outline edge a corner pokes through
    back off it; returns how many edges moved.

    The response above keeps *vertices* out of colliders; a rectangle's corner can still
    slip between two outline vertices into a body. The body then hangs on the corner as it
    moves on (measured: the ``demo`` bunny hooked on a ramp's end, one triangle stretched
    over metres, others folded flat). Per edge ``(a, b)`` (directed with the body on its
    left) that crosses a rectangle, the corner deepest on the body's side, at depth ``d``,
    is a contact with an infinitely heavy point: the edge point ``p = (1 - s) a + s b``
    facing it moves out by ``d`` (plus the collider's nanometre skin) along the edge's normal, split by the inverse masses as for
    a vertex against an edge (``da = (1 - s) w_a lam n``, ``db = s w_b lam n``, ``lam = d /
    ((1 - s)^2 w_a + s^2 w_b)``), and the edge point's velocity into the corner is taken away by
    an impulse split the same way (the end far from the corner keeps most of its motion, so a
    body overhanging a ledge tips off it).
    Frictionless: a body slides off a corner rather than snagging on it. A push that would
    put either end inside a collider is not made (found by the suite: a vertex resting on a
    thin plank's face beside its corner was nudged 3e-8 m into it).

    Parameters
    ----------
    x, v : (N, 2) float64
        Positions (m) and velocities (m/s), updated in place.
    inv_mass : (N,) float64
        1/kg (0: pinned, not moved).
    edge_a, edge_b : (E,) int32
        Outline edges as collision-vertex indices (``ContactTopology.ce_a`` / ``ce_b``).
    vertex : (V,) int32
        Collision vertex -> row of ``x`` (``ContactTopology.cv_vertex``).
    rects : (R, RECT_COLUMNS) float64
        From :func:`~deforma.physics.colliders.shapes.pack_colliders`.
    hits : ColliderHits
        Each end's velocity change is added to ``dv`` with the collider in ``dv_collider``
        (a rigid body's outline takes the opposite impulse: :mod:`deforma.physics.rigid`).

    Examples
    --------
    >>> import numpy as np
    >>> from deforma.physics.colliders.response import make_hits
    >>> from deforma.physics.colliders.shapes import Rect, pack_colliders
    >>> r = pack_colliders([Rect((0, 0), (2, 2), 45.0)], friction=0.3, static_friction=0.5)
    >>> x = np.array([[-1.0, 1.3], [1.0, 1.3]])  # an edge running right: the body is above it
    >>> v = np.array([[0.0, -1.0], [0.0, -1.0]])
    >>> push_edges_off_corners(x, v, np.ones(2), np.array([0], np.int32), np.array([1], np.int32),
    ...                        np.arange(2, dtype=np.int32), r, make_hits(2))
    1
    >>> x.round(6).tolist(), v.tolist()  # the top corner is at y = sqrt 2: the edge moved up past it
    ([[-1.0, 1.414214], [1.0, 1.414214]], [[0.0, 0.0], [0.0, 0.0]])
    """
    moved = 0
    n_rects = n_colliders(rects)
    for e in range(edge_a.shape[0]):
        ia = vertex[edge_a[e]]
        ib = vertex[edge_b[e]]
        ax, ay, bx, by = x[ia, 0], x[ia, 1], x[ib, 0], x[ib, 1]
        for r in range(n_rects):
            # bounding boxes first: most edges are nowhere near a collider
            if max(ax, bx) <= rects[r, RECT_XMIN] or min(ax, bx) >= rects[r, RECT_XMAX] \
                    or max(ay, by) <= rects[r, RECT_YMIN] or min(ay, by) >= rects[r, RECT_YMAX]:
                continue
            kind = rects[r, KIND]
            if kind != RECT and kind != POLYGON:
                continue  # round shapes have no corner to poke through an edge
            cx, cy = rects[r, RECT_CX], rects[r, RECT_CY]
            ux, uy = rects[r, RECT_UX], rects[r, RECT_UY]
            hx, hy = rects[r, RECT_HX], rects[r, RECT_HY]
            dx, dy = bx - ax, by - ay
            length2 = dx * dx + dy * dy
            if length2 == 0.0:
                continue
            inv_len = 1.0 / np.sqrt(length2)
            nx, ny = -dy * inv_len, dx * inv_len  # toward the body
            n_corners = 4
            if kind == RECT:
                # does the edge cross the rectangle? (separating axes: its two axes, the edge's normal)
                pax, pay = (ax - cx) * ux + (ay - cy) * uy, -(ax - cx) * uy + (ay - cy) * ux
                pbx, pby = (bx - cx) * ux + (by - cy) * uy, -(bx - cx) * uy + (by - cy) * ux
                if min(pax, pbx) >= hx or max(pax, pbx) <= -hx or min(pay, pby) >= hy or max(pay, pby) <= -hy:
                    continue
                mx, my = nx * ux + ny * uy, -nx * uy + ny * ux  # the normal in the rectangle's frame
                if abs(pax * mx + pay * my) >= hx * abs(mx) + hy * abs(my):
                    continue
            else:
                n_corners = np.int64(hy)  # a polygon's corners: the first ends of its edges
            best, best_s = 0.0, 0.0
            for k in range(n_corners):
                px, py = collider_corner(rects, r, k)
                t = ((px - ax) * dx + (py - ay) * dy) / length2
                depth = (px - ax) * nx + (py - ay) * ny
                # a corner poking through this edge: beside it, on the body's side, and not
                # deeper than the edge is long (deeper, a vertex would be inside the collider)
                if 0.0 < t < 1.0 and depth > best and depth * depth < length2:
                    best, best_s = depth, t
            if best == 0.0:
                continue
            wa, wb = inv_mass[ia], inv_mass[ib]
            sa, sb = 1.0 - best_s, best_s
            den = sa * sa * wa + sb * sb * wb
            if den == 0.0:
                continue  # both ends pinned
            lam = (best + rects[r, RECT_SKIN]) / den  # to just outside, as the response puts vertices
            qax = ax + sa * wa * lam * nx
            qay = ay + sa * wa * lam * ny
            qbx = bx + sb * wb * lam * nx
            qby = by + sb * wb * lam * ny
            # colliders keep the last word on vertices: a push that would move an end into a
            # collider (an end resting on the face next to the corner, nudged through it by
            # the push's normal) is not made; the corner stays that little way in the edge
            blocked = False
            for q in range(n_rects):
                if point_inside(rects, q, qax, qay) or point_inside(rects, q, qbx, qby):
                    blocked = True
            if blocked:
                continue
            uax, uay, ubx, uby = v[ia, 0], v[ia, 1], v[ib, 0], v[ib, 1]
            x[ia, 0], x[ia, 1], x[ib, 0], x[ib, 1] = qax, qay, qbx, qby
            # the edge point on the corner stops moving into it: the impulse acts there,
            # split as the push is, so the end far from the corner keeps most of its motion
            # (zeroing both ends' motion into the corner held a block overhanging a ledge
            # level on the corner instead of letting it tip off)
            vn = (sa * uax + sb * ubx) * nx + (sa * uay + sb * uby) * ny
            if vn < 0.0:  # into the corner
                dv = -vn / den
                v[ia, 0] += sa * wa * dv * nx
                v[ia, 1] += sa * wa * dv * ny
                v[ib, 0] += sb * wb * dv * nx
                v[ib, 1] += sb * wb * dv * ny
            note_impulse(hits, ia, r, ax, ay, uax, uay, qax, qay, v[ia, 0], v[ia, 1])
            note_impulse(hits, ib, r, bx, by, ubx, uby, qbx, qby, v[ib, 0], v[ib, 1])
            ax, ay, bx, by = qax, qay, qbx, qby
            moved += 1
    return moved

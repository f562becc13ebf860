"""The point collision + Coulomb friction response against colliders of every shape.

A leaf module: it knows shapes (:mod:`~deforma.physics.shapes`, packed into one array) and
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
   (:func:`deforma.physics.friction.coulomb`, the rule body contacts use too): if
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

Units: m, m/s; the packed array holds angles in radians.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit

from .friction import coulomb
from .shapes import (CIRCLE, COUNT, EDGE, EDGE_AX, EDGE_AY, EDGE_BX, EDGE_BY, EDGE_NX, EDGE_NY, KIND, OMEGA, POLYGON, RECT,
                     RECT_COLUMNS, RECT_CX, RECT_CY, RECT_FRICTION, RECT_HX, RECT_HY, RECT_REACH, RECT_SKIN,
                     RECT_STATIC_FRICTION, RECT_UX, RECT_UY, RECT_XMAX, RECT_XMIN, RECT_YMAX, RECT_YMIN, SEGMENT,
                     VEL_X, VEL_Y, Circle, Polygon, Rect, Segment, pack_colliders)

__all__ = ["Circle", "Polygon", "Rect", "Segment", "collide_point", "contact_planes", "finish_position_step",
           "n_colliders", "pack_colliders", "path_hits", "push_edges_off_corners", "RECT_COLUMNS"]

@njit(cache=True, inline="always")
def n_colliders(rects):
    """How many of the packed rows are colliders (the polygons' edge rows follow them)."""
    return 0 if rects.shape[0] == 0 else np.int64(rects[0, COUNT])


# Per vertex of a world, the last collider contact: written only when a vertex touches one.
ColliderHits = namedtuple("ColliderHits", [
    "stamp",            # (N,) int64: the substep it happened in (see contacts.ST_STAMP)
    "collider",         # (N,) int32: which collider
    "normal",           # (N, 2) float64: the face's outward normal
    "depth",            # (N,) float64: how deep inside it the vertex was (m)
])


def make_hits(n_vertices: int) -> ColliderHits:
    """An empty record for ``n_vertices`` vertices (no substep has stamp -1)."""
    return ColliderHits(np.full(n_vertices, -1, np.int64), np.zeros(n_vertices, np.int32),
                        np.zeros((n_vertices, 2)), np.zeros(n_vertices))


# Pushing a point out of one collider can push it into a touching one; a few passes settle
# every sane arrangement, and a point still trapped falls back to its previous position.
MAX_PASSES = 4


@njit(cache=True, inline="always")
def _inside(rects, r, px, py):
    if px <= rects[r, RECT_XMIN] or px >= rects[r, RECT_XMAX] or py <= rects[r, RECT_YMIN] or py >= rects[r, RECT_YMAX]:
        return False  # (a polygon's edge rows have an empty box: never inside)
    kind = rects[r, KIND]
    dx = px - rects[r, RECT_CX]
    dy = py - rects[r, RECT_CY]
    if kind == RECT:
        ux = rects[r, RECT_UX]
        uy = rects[r, RECT_UY]
        return abs(dx * ux + dy * uy) < rects[r, RECT_HX] and abs(dy * ux - dx * uy) < rects[r, RECT_HY]
    if kind == CIRCLE:
        return dx * dx + dy * dy < rects[r, RECT_HX] * rects[r, RECT_HX]
    if kind == SEGMENT:
        along = abs(dx * rects[r, RECT_UX] + dy * rects[r, RECT_UY]) - rects[r, RECT_HX]
        across = dy * rects[r, RECT_UX] - dx * rects[r, RECT_UY]
        along = max(along, 0.0)
        return along * along + across * across < rects[r, RECT_HY] * rects[r, RECT_HY]
    # polygon: even-odd over its edges (holes included)
    first = np.int64(rects[r, RECT_HX])
    odd = False
    for e in range(first, first + np.int64(rects[r, RECT_HY])):
        ay = rects[e, EDGE_AY]
        by = rects[e, EDGE_BY]
        if (ay > py) != (by > py):
            ax = rects[e, EDGE_AX]
            if px < ax + (py - ay) * (rects[e, EDGE_BX] - ax) / (by - ay):
                odd = not odd
    return odd


@njit(cache=True, inline="always")
def _relative_start(rects, r, x0, y0, h):
    """Where a point that was at ``(x0, y0)`` at the start of the substep would be now had it
    ridden on collider ``r`` (which the substep moved): the start seen from the collider."""
    w = rects[r, OMEGA]
    return (x0 + h * (rects[r, VEL_X] - w * (y0 - rects[r, RECT_CY])),
            y0 + h * (rects[r, VEL_Y] + w * (x0 - rects[r, RECT_CX])))


@njit(cache=True, inline="always")
def _exit_face(rects, r, x0, y0, px, py):
    """The surface point by which a point inside collider ``r`` leaves it (see the module
    docstring), from where it started, ``(x0, y0)``, seen from the collider.

    Returns ``(nx, ny, qx, qy, depth)``: the outward normal there, the point on the
    surface (for a flat face, the point's own projection onto the face's line) and how
    deep the point is inside (m).
    """
    kind = rects[r, KIND]
    cx = rects[r, RECT_CX]
    cy = rects[r, RECT_CY]
    ux = rects[r, RECT_UX]
    uy = rects[r, RECT_UY]
    hx = rects[r, RECT_HX]
    hy = rects[r, RECT_HY]
    if kind == RECT:
        a = (px - cx) * ux + (py - cy) * uy
        b = (py - cy) * ux - (px - cx) * uy
        a0 = (x0 - cx) * ux + (y0 - cy) * uy
        b0 = (y0 - cy) * ux - (x0 - cx) * uy
        came_in = a0 >= hx or a0 <= -hx or b0 >= hy or b0 <= -hy
        # faces: 0 = +x, 1 = -x, 2 = +y, 3 = -y (local); pick the least penetration among
        # those the start was outside of
        face = -1
        best = np.inf
        if (not came_in or a0 >= hx) and hx - a < best:
            best = hx - a
            face = 0
        if (not came_in or a0 <= -hx) and hx + a < best:
            best = hx + a
            face = 1
        if (not came_in or b0 >= hy) and hy - b < best:
            best = hy - b
            face = 2
        if (not came_in or b0 <= -hy) and hy + b < best:
            best = hy + b
            face = 3
        if face == 0:
            nx, ny = ux, uy
        elif face == 1:
            nx, ny = -ux, -uy
        elif face == 2:
            nx, ny = -uy, ux
        else:
            nx, ny = uy, -ux
        return nx, ny, px + best * nx, py + best * ny, best
    if kind == CIRCLE or kind == SEGMENT:
        # round: out along the line from the nearest point of the core (the centre, or the
        # segment) through the point, to the radius
        kx, ky, radius = cx, cy, hx
        beside = False
        if kind == SEGMENT:
            along = (px - cx) * ux + (py - cy) * uy
            t = min(max(along, -hx), hx)
            kx, ky, radius = cx + t * ux, cy + t * uy, hy
            # beside the segment (not at an end cap) and come from outside: out by the side it
            # came from, so that a point that crossed a thin capsule or a wire within the
            # substep goes back, whichever side of the line its end landed on
            across0 = (y0 - cy) * ux - (x0 - cx) * uy
            beside = abs(along) <= hx and across0 * across0 >= hy * hy
        dx = px - kx
        dy = py - ky
        dist = math.sqrt(dx * dx + dy * dy)
        if beside:
            nx, ny = (-uy, ux) if across0 > 0.0 else (uy, -ux)
            across = dx * nx + dy * ny
            return nx, ny, kx + radius * nx, ky + radius * ny, radius - across
        if dist > 1e-12 * radius:
            nx, ny = dx / dist, dy / dist
        else:  # on the core itself: back toward the side it came from
            sx, sy = x0 - kx, y0 - ky
            if kind == SEGMENT:
                side = sy * ux - sx * uy
                nx, ny = (-uy, ux) if side >= 0.0 else (uy, -ux)
            else:
                ls = math.sqrt(sx * sx + sy * sy)
                nx, ny = (sx / ls, sy / ls) if ls > 0.0 else (0.0, 1.0)
        return nx, ny, kx + radius * nx, ky + radius * ny, radius - dist
    # polygon: out by the edge the path came in through, if it came in from outside
    first = np.int64(hx)
    last = first + np.int64(hy)
    entry = -1
    if not _inside(rects, r, x0, y0):
        t_first = np.inf
        for e in range(first, last):
            t = _path_crosses(x0, y0, px, py, rects[e, EDGE_AX], rects[e, EDGE_AY], rects[e, EDGE_BX],
                              rects[e, EDGE_BY])
            if t < t_first:
                t_first = t
                entry = e
    if entry >= 0:
        nx, ny = rects[entry, EDGE_NX], rects[entry, EDGE_NY]
        depth = (rects[entry, EDGE_AX] - px) * nx + (rects[entry, EDGE_AY] - py) * ny
        return nx, ny, px + depth * nx, py + depth * ny, depth
    # else the nearest point of the boundary
    best = np.inf
    bnx, bny, bqx, bqy = 0.0, 1.0, px, py
    for e in range(first, last):
        ax, ay = rects[e, EDGE_AX], rects[e, EDGE_AY]
        ex, ey = rects[e, EDGE_BX] - ax, rects[e, EDGE_BY] - ay
        t = ((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey)
        end = t <= 0.0 or t >= 1.0
        t = min(max(t, 0.0), 1.0)
        qx, qy = ax + t * ex, ay + t * ey
        d = math.sqrt((qx - px) * (qx - px) + (qy - py) * (qy - py))
        if d < best:
            best = d
            bqx, bqy = qx, qy
            if end and d > 0.0:  # nearest at a corner: out along the way to it
                bnx, bny = (qx - px) / d, (qy - py) / d
            else:
                bnx, bny = rects[e, EDGE_NX], rects[e, EDGE_NY]
    return bnx, bny, bqx, bqy, best


@njit(cache=True, inline="always")
def _path_crosses(x0, y0, px, py, ax, ay, bx, by):
    """Where (0..1 along it) the path from (x0, y0) to (px, py) crosses segment a-b; inf if not."""
    dx, dy = px - x0, py - y0
    ex, ey = bx - ax, by - ay
    den = dx * ey - dy * ex
    if den == 0.0:
        return np.inf
    t = ((ax - x0) * ey - (ay - y0) * ex) / den
    u = ((ax - x0) * dy - (ay - y0) * dx) / den
    if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
        return t
    return np.inf


@njit(cache=True)
def jump_reach(rects):
    """Squared half-thickness (m^2) of the thinnest collider: a point that moves further in
    one substep may have jumped over it, and gets the swept test of :func:`collide_point`."""
    reach = np.inf
    for r in range(n_colliders(rects)):
        reach = min(reach, rects[r, RECT_REACH])
    return reach


@njit(cache=True, inline="always")
def _path_interval(x0, y0, px, py, rects, r):
    """The part ``[t_in, t_out]`` of the path from (x0, y0) to (px, py) inside collider ``r``
    (``t_in > t_out``: it misses)."""
    kind = rects[r, KIND]
    cx, cy, ux, uy = rects[r, RECT_CX], rects[r, RECT_CY], rects[r, RECT_UX], rects[r, RECT_UY]
    hx, hy = rects[r, RECT_HX], rects[r, RECT_HY]
    dx, dy = px - x0, py - y0
    if kind == RECT:
        a0 = (x0 - cx) * ux + (y0 - cy) * uy
        b0 = (y0 - cy) * ux - (x0 - cx) * uy
        da = dx * ux + dy * uy
        db = dy * ux - dx * uy
        lo = 0.0
        hi = 1.0
        for o, d, half in ((a0, da, hx), (b0, db, hy)):  # slab clipping
            if d == 0.0:
                if abs(o) >= half:
                    lo = 2.0
                continue
            t1 = (-half - o) / d
            t2 = (half - o) / d
            lo = max(lo, min(t1, t2))
            hi = min(hi, max(t1, t2))
        return lo, hi
    if kind == CIRCLE:
        fx, fy = x0 - cx, y0 - cy
        qa = dx * dx + dy * dy
        qb = 2.0 * (fx * dx + fy * dy)
        qc = fx * fx + fy * fy - hx * hx
        disc = qb * qb - 4.0 * qa * qc
        if qa == 0.0 or disc <= 0.0:
            return 2.0, 0.0
        root = math.sqrt(disc)
        return max((-qb - root) / (2.0 * qa), 0.0), min((-qb + root) / (2.0 * qa), 1.0)
    if kind == SEGMENT:
        # the path's point nearest the core segment, if within the radius (a capsule is thin:
        # one point of the path inside it stands for the chord). Closest points of two
        # segments (Ericson, Real-Time Collision Detection, 5.1.9): s along the path, t along
        # the core from one end to the other.
        qx, qy = cx - hx * ux, cy - hx * uy
        ex, ey = 2.0 * hx * ux, 2.0 * hx * uy
        rx, ry = x0 - qx, y0 - qy
        a = dx * dx + dy * dy
        e = ex * ex + ey * ey
        f = ex * rx + ey * ry
        c = dx * rx + dy * ry
        if a == 0.0:
            return 2.0, 0.0  # no motion: nothing to sweep
        if e == 0.0:  # a disc: no core length
            s = min(max(-c / a, 0.0), 1.0)
            t = 0.0
        else:
            b = dx * ex + dy * ey
            den = a * e - b * b
            s = min(max((b * f - c * e) / den, 0.0), 1.0) if den > 0.0 else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                t = 0.0
                s = min(max(-c / a, 0.0), 1.0)
            elif t > 1.0:
                t = 1.0
                s = min(max((b - c) / a, 0.0), 1.0)
        gx = x0 + s * dx - (qx + t * ex)
        gy = y0 + s * dy - (qy + t * ey)
        if gx * gx + gy * gy < hy * hy:
            return s, s
        return 2.0, 0.0
    # polygon: the first two crossings of its boundary
    t1 = np.inf
    t2 = np.inf
    first = np.int64(hx)
    for e in range(first, first + np.int64(hy)):
        t = _path_crosses(x0, y0, px, py, rects[e, EDGE_AX], rects[e, EDGE_AY], rects[e, EDGE_BX], rects[e, EDGE_BY])
        if t < t1:
            t2 = t1
            t1 = t
        elif t < t2:
            t2 = t
    if t2 <= 1.0:
        return t1, t2
    return 2.0, 0.0


@njit(cache=True)
def _swept_entry(x0, y0, px, py, rects):
    """A point that ended outside every collider but whose path from ``(x0, y0)`` went
    through one: moved back to the middle of its path's chord in the first one it entered
    (so the response below puts it on the face it came in by). Unchanged otherwise."""
    first = 2.0
    t_in = 0.0
    t_out = 0.0
    d2 = (px - x0) * (px - x0) + (py - y0) * (py - y0)
    for r in range(n_colliders(rects)):
        if d2 <= rects[r, RECT_REACH]:
            continue  # moved less than this collider's half-thickness: it cannot have jumped it
        if max(x0, px) <= rects[r, RECT_XMIN] or min(x0, px) >= rects[r, RECT_XMAX] \
                or max(y0, py) <= rects[r, RECT_YMIN] or min(y0, py) >= rects[r, RECT_YMAX]:
            continue
        lo, hi = _path_interval(x0, y0, px, py, rects, r)
        if lo <= hi and lo < first:
            first = lo
            t_in = lo
            t_out = hi
    if first > 1.0:
        return px, py
    t = 0.5 * (t_in + t_out)
    return x0 + t * (px - x0), y0 + t * (py - y0)


@njit(cache=True)
def path_hits(x0, y0, px, py, rects):
    """Whether a point moving from ``(x0, y0)`` to ``(px, py)`` ends inside a collider or
    passes through one on the way.

    Examples
    --------
    >>> thin = pack_colliders([Rect((0, 0), (10, 0.02), 0.0)], friction=0.3, static_friction=0.5)
    >>> path_hits(0.0, 0.05, 0.0, -0.05, thin), path_hits(0.0, 0.05, 0.0, 0.02, thin)
    (True, False)
    """
    for r in range(n_colliders(rects)):
        if _inside(rects, r, px, py):
            return True
    qx, qy = _swept_entry(x0, y0, px, py, rects)
    return qx != px or qy != py


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
        From :func:`~deforma.physics.shapes.pack_colliders`, at the end of the substep.
    h : float
        Substep length in seconds.

    Examples
    --------
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
            if _inside(rects, r, px, py):
                inside = True
        if not inside:
            px, py = _swept_entry(x0, y0, px, py, rects)
    hit = False
    last = -1
    hx_n = 0.0
    hy_n = 0.0
    last_depth = 0.0
    for _ in range(MAX_PASSES):
        hit = False
        for r in range(n_colliders(rects)):
            if not _inside(rects, r, px, py):
                continue
            hit = True
            rx0, ry0 = _relative_start(rects, r, x0, y0, h)
            nx, ny, qx, qy, best = _exit_face(rects, r, rx0, ry0, px, py)
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
            if _inside(rects, r, px, py):
                # trapped between colliders: the original's answer, back to where it was
                return x0, y0, 0.0, 0.0, last, hx_n, hy_n, last_depth
    return px, py, vx, vy, last, hx_n, hy_n, last_depth


@njit(cache=True)
def contact_planes(x0, y, rects, planes, index, h):
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
        From :func:`~deforma.physics.shapes.pack_colliders`.
    planes : (N, 7) float64 or wider
        Output: ``nx, ny, c, static_friction, friction, sx, sy`` per listed vertex (the
        first ``count`` rows); ``(sx, sy)`` is how far the collider's surface moved there
        in the substep (m), which friction measures slip against.
    index : (N,) int32
        Output: the listed vertices, ascending.
    h : float
        Substep (s).

    Returns
    -------
    int
        ``count``, the number of listed vertices.

    Examples
    --------
    >>> import numpy as np
    >>> floor = pack_colliders([Rect((0, -0.5), (10, 1.0), 0.0)], friction=0.3, static_friction=0.5)
    >>> planes, index = np.zeros((2, 7)), np.zeros(2, np.int32)
    >>> x0 = np.array([[0.0, 0.01], [1.0, 2.0]])
    >>> contact_planes(x0, x0 - [0.0, 0.02], floor, planes, index, 0.01)  # the low one only
    1
    >>> int(index[0]), (planes[0] + 0.0).round(6).tolist()  # + 0.0 turns -0.0 into 0.0
    (0, [0.0, 1.0, 0.0, 0.5, 0.3, 0.0, 0.0])
    """
    count = 0
    for i in range(y.shape[0]):
        px, py = y[i, 0], y[i, 1]
        best_depth = -np.inf
        for r in range(n_colliders(rects)):
            if not _inside(rects, r, px, py):
                continue
            rx0, ry0 = _relative_start(rects, r, x0[i, 0], x0[i, 1], h)
            nx, ny, qx, qy, depth = _exit_face(rects, r, rx0, ry0, px, py)
            if depth > best_depth:
                best_depth = depth
                w = rects[r, OMEGA]
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


@njit(cache=True)
def advance_colliders(rects, h):
    """Move every moving collider in the packed array by one substep of ``h`` s: its centre
    by ``h v``, its frame (and a polygon's edges) turned by ``h w`` about the centre, its
    bounding box to match. Returns whether any moved. The world repacks from the collider
    objects before each step, so the packed poses never drift from them.

    Examples
    --------
    >>> a = pack_colliders([Rect((0, 0), (2, 2), 0.0, velocity=(1, 0), angular_velocity=90)],
    ...                    friction=0.3, static_friction=0.5)
    >>> advance_colliders(a, 1.0), a[0, :4].round(6).tolist()  # a quarter turn, 1 m right
    (True, [1.0, 0.0, 0.0, 1.0])
    """
    moved = False
    for r in range(n_colliders(rects)):
        kind = rects[r, KIND]
        if kind == EDGE:
            continue
        vx, vy, w = rects[r, VEL_X], rects[r, VEL_Y], rects[r, OMEGA]
        if vx == 0.0 and vy == 0.0 and w == 0.0:
            continue
        moved = True
        cx, cy = rects[r, RECT_CX], rects[r, RECT_CY]
        c, sn = math.cos(h * w), math.sin(h * w)
        ux, uy = rects[r, RECT_UX], rects[r, RECT_UY]
        ux, uy = c * ux - sn * uy, sn * ux + c * uy
        norm = math.sqrt(ux * ux + uy * uy)  # keep it a unit vector over many substeps
        ux, uy = ux / norm, uy / norm
        nx_, ny_ = cx + h * vx, cy + h * vy
        rects[r, RECT_CX], rects[r, RECT_CY], rects[r, RECT_UX], rects[r, RECT_UY] = nx_, ny_, ux, uy
        hx, hy = rects[r, RECT_HX], rects[r, RECT_HY]
        if kind == RECT:
            ex = abs(hx * ux) + abs(hy * uy)
            ey = abs(hx * uy) + abs(hy * ux)
        elif kind == CIRCLE:
            ex = ey = hx
        elif kind == SEGMENT:
            ex = abs(hx * ux) + hy
            ey = abs(hx * uy) + hy
        else:
            lox = loy = np.inf
            hix = hiy = -np.inf
            for e in range(np.int64(hx), np.int64(hx) + np.int64(hy)):
                for col in (0, 2):  # the two ends: turned about the old centre, then moved
                    px, py = rects[e, col] - cx, rects[e, col + 1] - cy
                    px, py = nx_ + c * px - sn * py, ny_ + sn * px + c * py
                    rects[e, col], rects[e, col + 1] = px, py
                    lox, hix, loy, hiy = min(lox, px), max(hix, px), min(loy, py), max(hiy, py)
                enx, eny = rects[e, EDGE_NX], rects[e, EDGE_NY]
                rects[e, EDGE_NX], rects[e, EDGE_NY] = c * enx - sn * eny, sn * enx + c * eny
            rects[r, RECT_XMIN], rects[r, RECT_XMAX], rects[r, RECT_YMIN], rects[r, RECT_YMAX] = lox, hix, loy, hiy
            continue
        rects[r, RECT_XMIN], rects[r, RECT_XMAX] = nx_ - ex, nx_ + ex
        rects[r, RECT_YMIN], rects[r, RECT_YMAX] = ny_ - ey, ny_ + ey
    return moved


@njit(cache=True, inline="always")
def is_bad(px, py, vx, vy, vmax2):
    """1 if the vertex state is non-finite or faster than ``sqrt(vmax2)`` m/s, else 0."""
    # written so that NaN fails the test too; p - p is NaN for inf and NaN
    if vx * vx + vy * vy <= vmax2 and (px - px) == 0.0 and (py - py) == 0.0:
        return 0
    return 1


@njit(cache=True, inline="always")
def record_hit(hits, i, stamp, r, nx, ny, depth):
    """Note in ``hits`` (a :class:`ColliderHits`) that vertex ``i`` touched collider ``r`` in substep ``stamp``."""
    hits.stamp[i] = stamp
    hits.collider[i] = r
    hits.normal[i, 0] = nx
    hits.normal[i, 1] = ny
    hits.depth[i] = depth


@njit(cache=True)
def finish_position_step(x, v, x_prev, rects, hits, stamp, h, vmax2):
    """End a substep of a position-based integrator: velocities, contacts, the bad-vertex count.

    Implicit Euler and XPBD both produce new positions; the velocity is then
    ``(x - x_prev) / h`` and contacts with friction act as in symplectic Euler.

    Parameters
    ----------
    x, v : (N, 2) float64
        Solved positions (m), updated in place with the collided positions; velocities
        (m/s), output.
    x_prev : (N, 2) float64
        Positions at the start of the substep (m).
    rects : (R, RECT_COLUMNS) float64
        From :func:`~deforma.physics.shapes.pack_colliders`.
    hits : ColliderHits
        Where each vertex that touches a collider is noted, with ``stamp``.
    h : float
        Substep (s).
    vmax2 : float
        Squared runaway speed (m^2/s^2).

    Returns
    -------
    int
        Vertices that ended non-finite or faster than ``sqrt(vmax2)``.
    """
    # serial on purpose: a few percent of a step (the solves dominate), and a parallel loop
    # waits out other processes' time slices at its barrier when the cores are busy (the
    # 4 s jelly comparison once took 27.6 s instead of 1.7 s while the other core was busy)
    inv_h = 1.0 / h
    reach2 = jump_reach(rects)
    n_rects = n_colliders(rects)
    bad = 0
    for i in range(x.shape[0]):
        x0, y0 = x_prev[i, 0], x_prev[i, 1]
        px, py = x[i, 0], x[i, 1]
        vx = (px - x0) * inv_h
        vy = (py - y0) * inv_h
        near = False
        for r in range(n_rects):  # broad phase: bounding boxes
            if rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX] and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]:
                near = True
        if near or (px - x0) ** 2 + (py - y0) ** 2 > reach2:
            px, py, vx, vy, hit, nx, ny, depth = collide_point(x0, y0, px, py, vx, vy, rects, h)
            if hit >= 0:
                record_hit(hits, i, stamp, hit, nx, ny, depth)
        x[i, 0], x[i, 1], v[i, 0], v[i, 1] = px, py, vx, vy
        bad += is_bad(px, py, vx, vy, vmax2)
    return bad


@njit(cache=True)
def push_edges_off_corners(x, v, inv_mass, edge_a, edge_b, vertex, rects):
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
        From :func:`~deforma.physics.shapes.pack_colliders`.

    Examples
    --------
    >>> import numpy as np
    >>> r = pack_colliders([Rect((0, 0), (2, 2), 45.0)], friction=0.3, static_friction=0.5)
    >>> x = np.array([[-1.0, 1.3], [1.0, 1.3]])  # an edge running right: the body is above it
    >>> v = np.array([[0.0, -1.0], [0.0, -1.0]])
    >>> push_edges_off_corners(x, v, np.ones(2), np.array([0], np.int32), np.array([1], np.int32),
    ...                        np.arange(2, dtype=np.int32), r)
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
                if kind == RECT:
                    sx = hx if k == 0 or k == 3 else -hx
                    sy = hy if k < 2 else -hy
                    px = cx + sx * ux - sy * uy
                    py = cy + sx * uy + sy * ux
                else:
                    e = np.int64(hx) + k
                    px, py = rects[e, EDGE_AX], rects[e, EDGE_AY]
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
                if _inside(rects, q, qax, qay) or _inside(rects, q, qbx, qby):
                    blocked = True
            if blocked:
                continue
            ax, ay, bx, by = qax, qay, qbx, qby
            x[ia, 0], x[ia, 1], x[ib, 0], x[ib, 1] = ax, ay, bx, by
            # the edge point on the corner stops moving into it: the impulse acts there,
            # split as the push is, so the end far from the corner keeps most of its motion
            # (zeroing both ends' motion into the corner held a block overhanging a ledge
            # level on the corner instead of letting it tip off)
            vn = (sa * v[ia, 0] + sb * v[ib, 0]) * nx + (sa * v[ia, 1] + sb * v[ib, 1]) * ny
            if vn < 0.0:  # into the corner
                dv = -vn / den
                v[ia, 0] += sa * wa * dv * nx
                v[ia, 1] += sa * wa * dv * ny
                v[ib, 0] += sb * wb * dv * nx
                v[ib, 1] += sb * wb * dv * ny
            moved += 1
    return moved

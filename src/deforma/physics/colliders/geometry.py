"""The packed colliders as compiled geometry: is a point inside, by which face does it leave,
did its path cross one, and how they move.

A leaf: it knows the packed array (:func:`~deforma.physics.colliders.shapes.pack_colliders`)
and points, not worlds, bodies or responses.

Units: m, m/s; the packed array holds angles in radians.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .shapes import (
    CIRCLE,
    COUNT,
    EDGE,
    EDGE_AX,
    EDGE_AY,
    EDGE_BX,
    EDGE_BY,
    EDGE_NX,
    EDGE_NY,
    KIND,
    OMEGA,
    RECT,
    RECT_CX,
    RECT_CY,
    RECT_HX,
    RECT_HY,
    RECT_REACH,
    RECT_UX,
    RECT_UY,
    RECT_XMAX,
    RECT_XMIN,
    RECT_YMAX,
    RECT_YMIN,
    SEGMENT,
    VEL_X,
    VEL_Y,
)


@njit(cache=True, inline="always")
def n_colliders(rects):
    """How many of the packed rows are colliders (the polygons' edge rows follow them)."""
    return 0 if rects.shape[0] == 0 else np.int64(rects[0, COUNT])


@njit(cache=True, inline="always")
def point_inside(rects, r, px, py):
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
def relative_start(rects, r, x0, y0, h):
    """Where a point that was at ``(x0, y0)`` at the start of the substep would be now had it
    ridden on collider ``r`` (which the substep moved): the start seen from the collider."""
    w = rects[r, OMEGA]
    return (x0 + h * (rects[r, VEL_X] - w * (y0 - rects[r, RECT_CY])),
            y0 + h * (rects[r, VEL_Y] + w * (x0 - rects[r, RECT_CX])))


@njit(cache=True, inline="always")
def exit_face(rects, r, x0, y0, px, py):
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
    if not point_inside(rects, r, x0, y0):
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
def swept_entry(x0, y0, px, py, rects):
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
    >>> from deforma.physics.colliders.shapes import Rect, pack_colliders
    >>> thin = pack_colliders([Rect((0, 0), (10, 0.02), 0.0)], friction=0.3, static_friction=0.5)
    >>> path_hits(0.0, 0.05, 0.0, -0.05, thin), path_hits(0.0, 0.05, 0.0, 0.02, thin)
    (True, False)
    """
    for r in range(n_colliders(rects)):
        if point_inside(rects, r, px, py):
            return True
    qx, qy = swept_entry(x0, y0, px, py, rects)
    return qx != px or qy != py


@njit(cache=True)
def advance_colliders(rects, h):
    """Move every moving collider in the packed array by one substep of ``h`` s: its centre
    by ``h v``, its frame (and a polygon's edges) turned by ``h w`` about the centre, its
    bounding box to match. Returns whether any moved. The world repacks from the collider
    objects before each step, so the packed poses never drift from them.

    Examples
    --------
    >>> from deforma.physics.colliders.shapes import Rect, pack_colliders
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

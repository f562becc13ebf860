"""Rotated-rectangle colliders and the point collision + Coulomb friction response.

A leaf module: it knows shapes and points, not worlds or bodies.

The scheme, per vertex and substep of length ``h`` (velocities already updated by the
integrator, ``p = p_prev + h*v``):

1. Test the point against every rectangle (local coordinates along the rectangle's axes,
   the original's dot-product test; an axis-aligned bounding box rejects far points first).
2. If it is inside, choose the face to leave by: among the faces the *previous* position
   was outside of (the way it came in), the one with the least penetration; if it was
   inside already (spawned there, or the rectangle moved onto it) any face, i.e. the
   shortest way out.
3. Split the velocity into normal ``vn`` and tangential ``vt`` parts of that face. An
   inward ``vn`` is removed; its size ``jn = -vn`` is the normal impulse per unit mass
   this substep, i.e. ``h * N / m``. Coulomb friction then acts on ``vt``
   (:func:`deforma.physics.friction.coulomb`, the rule body contacts use too): if
   ``|vt| <= static_friction * jn`` the vertex sticks (``vt = 0``), otherwise dynamic
   friction removes ``friction * jn`` from ``|vt|`` (never reversing it).
4. Put the point on the face (plus a nanometre skin so it is strictly outside) and move it
   along the face by ``h * (vt_new - vt_old)``: the position is the one the *corrected*
   velocity would have produced. Correcting only the velocity after the position update
   (as many codes do) lets a stuck vertex creep by ``h * vt`` every substep; correcting
   only the position (the original restored the whole previous position) makes sliding
   impossible.

With this, the total friction on a block is exactly ``friction * sum(N)`` while it slides
(acceleration ``g (sin a - mu cos a)`` on a slope) and a block whose bottom vertices all
satisfy the static test does not move at all.

Angles are degrees in the API, radians nowhere outside this module. Units: m, m/s.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..checks import coefficient as _coefficient
from ..checks import pair as _pair
from .friction import coulomb

# Columns of the packed collider array read by the kernels.
RECT_CX, RECT_CY, RECT_UX, RECT_UY, RECT_HX, RECT_HY = 0, 1, 2, 3, 4, 5
RECT_FRICTION, RECT_STATIC_FRICTION = 6, 7
RECT_XMIN, RECT_XMAX, RECT_YMIN, RECT_YMAX, RECT_SKIN = 8, 9, 10, 11, 12
RECT_REACH = 13  # the squared half-thickness: a vertex moving further per substep may jump it
RECT_COLUMNS = 14

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


# Pushing a point out of one rectangle can push it into a touching one; a few passes settle
# every sane arrangement, and a point still trapped falls back to its previous position.
MAX_PASSES = 4


@dataclass(frozen=True)
class Rect:
    """A fixed rotated rectangle that vertices collide with.

    Parameters
    ----------
    center : (float, float)
        Centre in metres.
    size : (float, float)
        Width and height in metres (before rotation), both > 0.
    angle : float
        Counter-clockwise rotation in degrees.
    friction, static_friction : float, optional
        Dynamic and static Coulomb coefficients (>= 0, dimensionless). ``None`` uses the
        world's coefficients, also when those change later.

    Examples
    --------
    >>> r = Rect((0, 0), (4, 1), 90.0)
    >>> r.contains([[0.0, 1.5], [1.5, 0.0]]).tolist()
    [True, False]
    >>> r.corners.round(3).tolist()
    [[0.5, 2.0], [-0.5, 2.0], [-0.5, -2.0], [0.5, -2.0]]
    """

    center: tuple[float, float]
    size: tuple[float, float]
    angle: float = 0.0
    friction: float | None = None
    static_friction: float | None = None

    def __init__(self, center, size, angle=0.0, *, friction=None, static_friction=None):
        a = float(angle)
        if not math.isfinite(a):
            raise ValueError(f"angle must be a finite number of degrees, got {angle!r}")
        object.__setattr__(self, "center", _pair(center, "center"))
        object.__setattr__(self, "size", _pair(size, "size", positive=True))
        object.__setattr__(self, "angle", a)
        object.__setattr__(self, "friction", _coefficient(friction, "friction"))
        object.__setattr__(self, "static_friction", _coefficient(static_friction, "static_friction"))

    @property
    def axes(self) -> np.ndarray:
        """(2, 2): the rectangle's unit x axis (along the width) and y axis (along the height)."""
        t = math.radians(self.angle)
        c, s = math.cos(t), math.sin(t)
        return np.array([[c, s], [-s, c]])

    @property
    def corners(self) -> np.ndarray:
        """(4, 2) corners in metres, counter-clockwise from the local (+x, -y) corner."""
        u, w = self.axes
        hx, hy = self.size[0] / 2, self.size[1] / 2
        c = np.array(self.center)
        return np.array([c + hx * u - hy * w, c + hx * u + hy * w, c - hx * u + hy * w, c - hx * u - hy * w])

    def contains(self, points) -> np.ndarray:
        """Whether each point (N, 2) lies strictly inside the rectangle, as (N,) bool."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2) - np.array(self.center)
        u, w = self.axes
        return (np.abs(p @ u) < self.size[0] / 2) & (np.abs(p @ w) < self.size[1] / 2)


def pack_rects(rects, *, friction: float, static_friction: float, out=None) -> np.ndarray:
    """Pack rectangles into the (R, RECT_COLUMNS) float64 array the kernels read.

    ``friction`` / ``static_friction`` fill in coefficients a rectangle leaves as ``None``.

    Examples
    --------
    >>> pack_rects([Rect((0, 0), (2, 1), 0.0)], friction=0.3, static_friction=0.5).shape
    (1, 14)
    """
    a = np.empty((len(rects), RECT_COLUMNS)) if out is None else out
    for k, r in enumerate(rects):
        u = r.axes[0]
        hx, hy = r.size[0] / 2, r.size[1] / 2
        ext = np.abs(r.corners - np.array(r.center)).max(axis=0)
        scale = abs(r.center[0]) + abs(r.center[1]) + hx + hy
        a[k] = (r.center[0], r.center[1], u[0], u[1], hx, hy,
                friction if r.friction is None else r.friction,
                static_friction if r.static_friction is None else r.static_friction,
                r.center[0] - ext[0], r.center[0] + ext[0], r.center[1] - ext[1], r.center[1] + ext[1],
                # strictly outside after rounding back to world coordinates
                1e-9 + 1e-13 * scale,
                min(hx, hy) ** 2)
    return a


@njit(cache=True, inline="always")
def _inside(rects, r, px, py):
    if px <= rects[r, RECT_XMIN] or px >= rects[r, RECT_XMAX] or py <= rects[r, RECT_YMIN] or py >= rects[r, RECT_YMAX]:
        return False
    dx = px - rects[r, RECT_CX]
    dy = py - rects[r, RECT_CY]
    ux = rects[r, RECT_UX]
    uy = rects[r, RECT_UY]
    return abs(dx * ux + dy * uy) < rects[r, RECT_HX] and abs(dy * ux - dx * uy) < rects[r, RECT_HY]


@njit(cache=True, inline="always")
def _exit_face(rects, r, x0, y0, px, py):
    """The face of rectangle ``r`` by which a point inside it leaves (see the module docstring).

    Returns ``(nx, ny, tx, ty, s, d, depth)``: the face's outward normal and tangent, the
    point's coordinate along the tangent and the face's distance from the centre (so the
    point on the face is ``centre + d n + s t``), and how deep the point is inside (m).
    """
    cx = rects[r, RECT_CX]
    cy = rects[r, RECT_CY]
    ux = rects[r, RECT_UX]
    uy = rects[r, RECT_UY]
    hx = rects[r, RECT_HX]
    hy = rects[r, RECT_HY]
    a = (px - cx) * ux + (py - cy) * uy
    b = (py - cy) * ux - (px - cx) * uy
    a0 = (x0 - cx) * ux + (y0 - cy) * uy
    b0 = (y0 - cy) * ux - (x0 - cx) * uy
    came_in = a0 >= hx or a0 <= -hx or b0 >= hy or b0 <= -hy
    # faces: 0 = +x, 1 = -x, 2 = +y, 3 = -y (local); pick the least penetration
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
        return ux, uy, -uy, ux, b, hx, best
    if face == 1:
        return -ux, -uy, -uy, ux, b, hx, best
    if face == 2:
        return -uy, ux, ux, uy, a, hy, best
    return uy, -ux, ux, uy, a, hy, best


@njit(cache=True)
def jump_reach(rects):
    """Squared half-thickness (m^2) of the thinnest rectangle: a point that moves further in
    one substep may have jumped over it, and gets the swept test of :func:`collide_point`."""
    reach = np.inf
    for r in range(rects.shape[0]):
        reach = min(reach, rects[r, RECT_REACH])
    return reach


@njit(cache=True)
def _swept_entry(x0, y0, px, py, rects):
    """A point that ended outside every rectangle but whose path from ``(x0, y0)`` went
    through one: moved back to the middle of its path's chord in the first one it entered
    (so the response below puts it on the face it came in by). Unchanged otherwise."""
    first = 2.0
    t_in = 0.0
    t_out = 0.0
    d2 = (px - x0) * (px - x0) + (py - y0) * (py - y0)
    for r in range(rects.shape[0]):
        if d2 <= rects[r, RECT_REACH]:
            continue  # moved less than this rectangle's half-thickness: it cannot have jumped it
        cx, cy, ux, uy = rects[r, RECT_CX], rects[r, RECT_CY], rects[r, RECT_UX], rects[r, RECT_UY]
        a0 = (x0 - cx) * ux + (y0 - cy) * uy
        b0 = (y0 - cy) * ux - (x0 - cx) * uy
        da = (px - x0) * ux + (py - y0) * uy
        db = (py - y0) * ux - (px - x0) * uy
        lo = 0.0
        hi = 1.0
        for o, d, half in ((a0, da, rects[r, RECT_HX]), (b0, db, rects[r, RECT_HY])):  # slab clipping
            if d == 0.0:
                if abs(o) >= half:
                    lo = 2.0
                continue
            t1 = (-half - o) / d
            t2 = (half - o) / d
            lo = max(lo, min(t1, t2))
            hi = min(hi, max(t1, t2))
        if lo < hi and lo < first:
            first = lo
            t_in = lo
            t_out = hi
    if first > 1.0:
        return px, py
    t = 0.5 * (t_in + t_out)
    return x0 + t * (px - x0), y0 + t * (py - y0)


@njit(cache=True)
def path_hits(x0, y0, px, py, rects):
    """Whether a point moving from ``(x0, y0)`` to ``(px, py)`` ends inside a rectangle or
    passes through one on the way.

    Examples
    --------
    >>> thin = pack_rects([Rect((0, 0), (10, 0.02), 0.0)], friction=0.3, static_friction=0.5)
    >>> path_hits(0.0, 0.05, 0.0, -0.05, thin), path_hits(0.0, 0.05, 0.0, 0.02, thin)
    (True, False)
    """
    for r in range(rects.shape[0]):
        if _inside(rects, r, px, py):
            return True
    qx, qy = _swept_entry(x0, y0, px, py, rects)
    return qx != px or qy != py


@njit(cache=True)
def collide_point(x0, y0, px, py, vx, vy, rects, h):
    """Resolve one point against all rectangles.

    Returns ``(px, py, vx, vy, hit, nx, ny, depth)``: the new position and velocity, the
    index of the last rectangle the point was put out of (-1 if none), that face's outward
    normal and how deep (m) the point was inside it.

    Parameters
    ----------
    x0, y0 : float
        Position at the start of the substep (m), tells which face the point came through.
    px, py, vx, vy : float
        Position (m) and velocity (m/s) after the unconstrained substep.
    rects : (R, RECT_COLUMNS) float64
        From :func:`pack_rects`.
    h : float
        Substep length in seconds.

    Examples
    --------
    >>> r = pack_rects([Rect((0, -1), (10, 2), 0.0)], friction=0.3, static_friction=0.5)
    >>> px, py, vx, vy, hit, nx, ny, depth = collide_point(0.0, 0.0, 0.01, -0.01, 1.0, -1.0, r, 0.01)
    >>> round(py, 6), vy, round(vx, 3), hit, (nx, ny), round(depth, 6)
    (0.0, 0.0, 0.7, 0, (-0.0, 1.0), 0.01)

    A point that jumped over a thin rectangle within the substep is caught too:

    >>> thin = pack_rects([Rect((0, 0), (10, 0.02), 0.0)], friction=0.3, static_friction=0.5)
    >>> px, py, vx, vy, hit, nx, ny, depth = collide_point(0.0, 0.05, 0.0, -0.05, 0.0, -10.0, thin, 0.01)
    >>> hit, round(py, 6), vy
    (0, 0.01, 0.0)
    """
    # the swept test only for a point that moved further than some rectangle's half-thickness
    # (rare), and decided inline: a call per point would cost reference counting on rects
    d2 = (px - x0) * (px - x0) + (py - y0) * (py - y0)
    jumpy = False
    for r in range(rects.shape[0]):
        if d2 > rects[r, RECT_REACH]:
            jumpy = True
    if jumpy:
        inside = False
        for r in range(rects.shape[0]):
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
        for r in range(rects.shape[0]):
            if not _inside(rects, r, px, py):
                continue
            hit = True
            nx, ny, tx, ty, s, d, best = _exit_face(rects, r, x0, y0, px, py)
            vn = vx * nx + vy * ny
            vt = vx * tx + vy * ty
            jn = 0.0
            if vn < 0.0:
                jn = -vn
                vn = 0.0
            vt_new = coulomb(vt, jn, rects[r, RECT_STATIC_FRICTION], rects[r, RECT_FRICTION])
            s += h * (vt_new - vt)
            last = r
            hx_n = nx
            hy_n = ny
            last_depth = best
            d += rects[r, RECT_SKIN]
            px = rects[r, RECT_CX] + d * nx + s * tx
            py = rects[r, RECT_CY] + d * ny + s * ty
            vx = vn * nx + vt_new * tx
            vy = vn * ny + vt_new * ty
        if not hit:
            break
    if hit:
        for r in range(rects.shape[0]):
            if _inside(rects, r, px, py):
                # trapped between rectangles: the original's answer, back to where it was
                return x0, y0, 0.0, 0.0, last, hx_n, hy_n, last_depth
    return px, py, vx, vy, last, hx_n, hy_n, last_depth


@njit(cache=True)
def contact_planes(x0, y, rects, planes, index):
    """The collider contacts a stable solver puts inside its solve: which vertices, and where.

    A vertex whose predicted end of substep ``y`` lies inside a rectangle gets the plane of
    the face it would leave by (chosen as :func:`collide_point` chooses it, from where it
    started, ``x0``); of several rectangles, the one it is deepest in. A point ``p`` is
    outside that face when ``n . p >= c``. Only vertices headed inside are listed: the
    solvers hold a listed vertex near its iterate, and listing vertices a hair outside too
    made the next row up of a body on the floor follow its free fall
    (``docs/integrators.md``).

    Parameters
    ----------
    x0, y : (N, 2) float64
        Positions at the start of the substep and predicted at its end (m).
    rects : (R, RECT_COLUMNS) float64
        From :func:`pack_rects`.
    planes : (N, 5) float64
        Output: ``nx, ny, c, static_friction, friction`` per listed vertex (the first
        ``count`` rows).
    index : (N,) int32
        Output: the listed vertices, ascending.

    Returns
    -------
    int
        ``count``, the number of listed vertices.

    Examples
    --------
    >>> import numpy as np
    >>> floor = pack_rects([Rect((0, -0.5), (10, 1.0), 0.0)], friction=0.3, static_friction=0.5)
    >>> planes, index = np.zeros((2, 5)), np.zeros(2, np.int32)
    >>> x0 = np.array([[0.0, 0.01], [1.0, 2.0]])
    >>> contact_planes(x0, x0 - [0.0, 0.02], floor, planes, index)  # the low one only
    1
    >>> int(index[0]), (planes[0] + 0.0).round(6).tolist()  # + 0.0 turns -0.0 into 0.0
    (0, [0.0, 1.0, 0.0, 0.5, 0.3])
    """
    count = 0
    for i in range(y.shape[0]):
        px, py = y[i, 0], y[i, 1]
        best_depth = -np.inf
        for r in range(rects.shape[0]):
            if not _inside(rects, r, px, py):
                continue
            nx, ny, tx, ty, t, d, depth = _exit_face(rects, r, x0[i, 0], x0[i, 1], px, py)
            if depth > best_depth:
                best_depth = depth
                planes[count, 0] = nx
                planes[count, 1] = ny
                planes[count, 2] = rects[r, RECT_CX] * nx + rects[r, RECT_CY] * ny + d + rects[r, RECT_SKIN]
                planes[count, 3] = rects[r, RECT_STATIC_FRICTION]
                planes[count, 4] = rects[r, RECT_FRICTION]
        if best_depth > -np.inf:
            index[count] = i
            count += 1
    return count


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
        From :func:`pack_rects`.
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
    bad = 0
    for i in range(x.shape[0]):
        x0, y0 = x_prev[i, 0], x_prev[i, 1]
        px, py = x[i, 0], x[i, 1]
        vx = (px - x0) * inv_h
        vy = (py - y0) * inv_h
        near = False
        for r in range(rects.shape[0]):  # broad phase: bounding boxes
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
    ((1 - s)^2 w_a + s^2 w_b)``), and the two vertices lose their velocity into the corner.
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
        From :func:`pack_rects`.

    Examples
    --------
    >>> import numpy as np
    >>> r = pack_rects([Rect((0, 0), (2, 2), 45.0)], friction=0.3, static_friction=0.5)
    >>> x = np.array([[-1.0, 1.3], [1.0, 1.3]])  # an edge running right: the body is above it
    >>> v = np.array([[0.0, -1.0], [0.0, -1.0]])
    >>> push_edges_off_corners(x, v, np.ones(2), np.array([0], np.int32), np.array([1], np.int32),
    ...                        np.arange(2, dtype=np.int32), r)
    1
    >>> x.round(6).tolist(), v.tolist()  # the top corner is at y = sqrt 2: the edge moved up past it
    ([[-1.0, 1.414214], [1.0, 1.414214]], [[0.0, 0.0], [0.0, 0.0]])
    """
    moved = 0
    for e in range(edge_a.shape[0]):
        ia = vertex[edge_a[e]]
        ib = vertex[edge_b[e]]
        ax, ay, bx, by = x[ia, 0], x[ia, 1], x[ib, 0], x[ib, 1]
        for r in range(rects.shape[0]):
            # bounding boxes first: most edges are nowhere near a collider
            if max(ax, bx) <= rects[r, RECT_XMIN] or min(ax, bx) >= rects[r, RECT_XMAX] \
                    or max(ay, by) <= rects[r, RECT_YMIN] or min(ay, by) >= rects[r, RECT_YMAX]:
                continue
            cx, cy = rects[r, RECT_CX], rects[r, RECT_CY]
            ux, uy = rects[r, RECT_UX], rects[r, RECT_UY]
            hx, hy = rects[r, RECT_HX], rects[r, RECT_HY]
            dx, dy = bx - ax, by - ay
            length2 = dx * dx + dy * dy
            if length2 == 0.0:
                continue
            inv_len = 1.0 / np.sqrt(length2)
            nx, ny = -dy * inv_len, dx * inv_len  # toward the body
            # does the edge cross the rectangle? (separating axes: its two axes, the edge's normal)
            pax, pay = (ax - cx) * ux + (ay - cy) * uy, -(ax - cx) * uy + (ay - cy) * ux
            pbx, pby = (bx - cx) * ux + (by - cy) * uy, -(bx - cx) * uy + (by - cy) * ux
            if min(pax, pbx) >= hx or max(pax, pbx) <= -hx or min(pay, pby) >= hy or max(pay, pby) <= -hy:
                continue
            mx, my = nx * ux + ny * uy, -nx * uy + ny * ux  # the normal in the rectangle's frame
            if abs(pax * mx + pay * my) >= hx * abs(mx) + hy * abs(my):
                continue
            best, best_s = 0.0, 0.0
            for k in range(4):
                sx = hx if k == 0 or k == 3 else -hx
                sy = hy if k < 2 else -hy
                px = cx + sx * ux - sy * uy
                py = cy + sx * uy + sy * ux
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
            for q in range(rects.shape[0]):
                if _inside(rects, q, qax, qay) or _inside(rects, q, qbx, qby):
                    blocked = True
            if blocked:
                continue
            ax, ay, bx, by = qax, qay, qbx, qby
            x[ia, 0], x[ia, 1], x[ib, 0], x[ib, 1] = ax, ay, bx, by
            for i in (ia, ib):
                vn = v[i, 0] * nx + v[i, 1] * ny
                if vn < 0.0:  # into the corner
                    v[i, 0] -= vn * nx
                    v[i, 1] -= vn * ny
            moved += 1
    return moved

"""Collider shapes: rectangles, circles, polygons and capsules, fixed or moving.

A collider is a solid that vertices cannot enter, with infinite mass. Every shape has a
pose (``center`` in metres, ``angle`` in degrees counter-clockwise), a motion
(``velocity`` in m/s, ``angular_velocity`` in degrees per second about its centre: a
*kinematic* collider, moved by the world each substep, whose surface carries touching
bodies along by friction) and Coulomb coefficients (``None``: the world's). Pose, motion
and coefficients can be set at any time; the world notices at its next step.

The kernels read all colliders from one packed float64 array (:func:`pack_colliders`):
one row per collider (its kind, pose, motion, bounding box and size), then one row per
polygon edge. Loops over colliders run over the first ``COUNT`` rows only (the edge rows
also have empty bounding boxes, so a test that reads them as colliders rejects them). :mod:`~deforma.physics.colliders` holds the
closest-feature and inside tests per kind and the response.

Units: m, m/s, degrees, degrees/s; radians only inside the packed array.
"""

from __future__ import annotations

import copy
import math
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np
from numpy.typing import ArrayLike

from ...checks import coefficient as _coefficient
from ...checks import number as _number
from ...checks import pair as _pair
from ...mesh.polygons import inside_loops, segments_meet, signed_area

if TYPE_CHECKING:
    from ...mesh.image import Background, ImageSource

# Columns of the packed array. Collider rows:
RECT_CX, RECT_CY, RECT_UX, RECT_UY = 0, 1, 2, 3   # centre; unit x axis of the shape's frame
RECT_HX, RECT_HY = 4, 5       # rect: half sizes; circle: radius, -; segment: half length, radius;
#                               polygon: first edge row, number of edge rows
RECT_FRICTION, RECT_STATIC_FRICTION = 6, 7
RECT_XMIN, RECT_XMAX, RECT_YMIN, RECT_YMAX, RECT_SKIN = 8, 9, 10, 11, 12
RECT_REACH = 13   # squared half-thickness: a vertex moving further per substep may jump it
KIND = 14
VEL_X, VEL_Y, OMEGA = 15, 16, 17   # m/s, m/s, rad/s
COUNT = 18        # the number of collider rows (the edge rows follow them), in every row
# a rigid body's outline (deforma.physics.rigid): its 1/mass (1/kg) and 1/moment of inertia
# (1/(kg m^2)); 0 on a collider, which nothing a body does moves
INV_MASS, INV_INERTIA = 19, 20
RECT_COLUMNS = 21
# Edge rows (KIND = EDGE): ends a, b in columns 0-3, outward unit normal in 4-5.
EDGE_AX, EDGE_AY, EDGE_BX, EDGE_BY, EDGE_NX, EDGE_NY = 0, 1, 2, 3, 4, 5

RECT, CIRCLE, POLYGON, SEGMENT, EDGE = 0, 1, 2, 3, -1
# m: the radius the kernels give a segment of radius 0, so that it has an inside. Thinner
# colliders are not stable yet: a box resting on a 2e-5 m thick rectangle (or a 1e-5 m
# wire) at 1/600 s jitters at 1 m/s, while at 1e-3 m it rests as on a thick floor (measured)
WIRE = 1e-3
MAX_SPEED = 1e4            # m/s: a collider's velocity bound (checks.LIMITS keeps bodies' below 1e100)
MAX_ANGULAR_SPEED = 1e6    # degrees/s


def _rotation(angle_deg: float) -> np.ndarray:
    t = math.radians(angle_deg)
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s], [s, c]])


def _finite(value, name, *, bound=None, positive=False, non_negative=False) -> float:
    v = _number(value, name)
    if bound is not None and abs(v) > bound:
        raise ValueError(f"{name} must be a finite number within +-{bound:g}, got {value!r}")
    if positive and not v > 0:
        raise ValueError(f"{name} must be > 0, got {value!r}")
    if non_negative and v < 0:
        raise ValueError(f"{name} must be >= 0, got {value!r}")
    return v


def _points(value, name, *, minimum: int) -> np.ndarray:
    try:
        p = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a list of (x, y) points, got {type(value).__name__}") from None
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < minimum:
        raise ValueError(f"{name} must be at least {minimum} (x, y) points, got shape {p.shape}")
    if not np.all(np.isfinite(p)) or np.abs(p).max() > 1e9:
        raise ValueError(f"{name} must be finite coordinates within +-1e9 m")
    return p


def _check_simple(loops: list[np.ndarray], name: str) -> None:
    """Refuse loops that cross themselves or each other (edges sharing an end excepted)."""
    a = np.concatenate(loops)
    b = np.concatenate([np.roll(p, -1, axis=0) for p in loops])
    n = len(a)
    if n > 4000:
        raise ValueError(f"{name} has {n} edges, at most 4000 are allowed (simplify the outline)")
    ids = np.concatenate([np.arange(len(p)) + off for p, off in zip(loops, np.cumsum([0] + [len(p) for p in loops]))])
    nxt = np.concatenate([np.roll(np.arange(len(p)), -1) + off
                          for p, off in zip(loops, np.cumsum([0] + [len(p) for p in loops]))])
    hit = segments_meet(a[:, None], b[:, None], a[None], b[None])
    share = (ids[:, None] == ids[None]) | (ids[:, None] == nxt[None]) | (nxt[:, None] == ids[None]) \
        | (nxt[:, None] == nxt[None])
    hit &= ~share
    if hit.any():
        i, j = np.argwhere(hit)[0]
        raise ValueError(f"{name} must be simple: edge {i} crosses edge {j} (edges may meet only at shared ends)")


class Collider:
    """What every collider shape has: a pose, a motion and friction (see the module docstring).

    Not made directly: use :class:`Rect`, :class:`Circle`, :class:`Polygon` or :class:`Segment`.
    """

    kind = -2  # set by each shape

    def __init__(self, center: ArrayLike, angle: float, friction: float | None, static_friction: float | None,
                 velocity: ArrayLike, angular_velocity: float) -> None:
        self._version = 0
        self.center = center
        self.angle = angle
        self.friction = friction
        self.static_friction = static_friction
        self.velocity = velocity
        self.angular_velocity = angular_velocity

    def _changed(self):
        self._version += 1

    @property
    def center(self) -> tuple[float, float]:
        """Centre (m): the point the shape turns about."""
        return self._center

    @center.setter
    def center(self, value: ArrayLike) -> None:
        self._center = self._origin_center = _pair(value, "center")  # within +-1e9 m
        self._changed()

    @property
    def angle(self) -> float:
        """Counter-clockwise rotation in degrees."""
        return self._angle

    @angle.setter
    def angle(self, value: float) -> None:
        self._angle = self._origin_angle = _finite(value, "angle")
        self._changed()

    @property
    def origin(self) -> tuple[tuple[float, float], float]:
        """``(center, angle)`` where it was put (made, or last given a centre or angle), before
        its own motion moved it: where a saved scene puts it, and where a reset starts it."""
        return self._origin_center, self._origin_angle

    def _set_pose(self, center, angle) -> None:
        """Put it at a pose reached by its motion (the origin stays)."""
        self._center, self._angle = center, angle
        self._changed()

    def at_origin(self) -> "Collider":
        """A copy of it at its :attr:`origin`, with the same motion and friction."""
        twin = copy.copy(self)
        twin._center, twin._angle = self.origin
        return twin

    @property
    def velocity(self) -> tuple[float, float]:
        """Velocity of the centre (m/s): the world moves the collider by it every substep."""
        return self._velocity

    @velocity.setter
    def velocity(self, value: ArrayLike) -> None:
        v = _pair(value, "velocity")
        if max(abs(v[0]), abs(v[1])) > MAX_SPEED:
            raise ValueError(f"velocity must be within +-{MAX_SPEED:g} m/s, got {value!r}")
        self._velocity = v
        self._changed()

    @property
    def angular_velocity(self) -> float:
        """Rotation rate about the centre, degrees per second (counter-clockwise)."""
        return self._angular_velocity

    @angular_velocity.setter
    def angular_velocity(self, value: float) -> None:
        self._angular_velocity = _finite(value, "angular_velocity", bound=MAX_ANGULAR_SPEED)
        self._changed()

    @property
    def friction(self) -> float | None:
        """Dynamic Coulomb coefficient (>= 0), or ``None`` for the world's."""
        return self._friction

    @friction.setter
    def friction(self, value: float | None) -> None:
        self._friction = _coefficient(value, "friction")
        self._changed()

    @property
    def static_friction(self) -> float | None:
        """Static Coulomb coefficient (>= 0), or ``None`` for the world's."""
        return self._static_friction

    @static_friction.setter
    def static_friction(self, value: float | None) -> None:
        self._static_friction = _coefficient(value, "static_friction")
        self._changed()

    @property
    def moving(self) -> bool:
        """Whether it has a velocity or an angular velocity."""
        return self._velocity != (0.0, 0.0) or self._angular_velocity != 0.0

    def surface_velocity(self, points: ArrayLike) -> np.ndarray:
        """(N, 2) velocity (m/s) of the collider's material at each point: ``v + w x (p - c)``."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        w = math.radians(self._angular_velocity)
        return np.column_stack([self._velocity[0] - w * (p[:, 1] - self._center[1]),
                                self._velocity[1] + w * (p[:, 0] - self._center[0])])

    def advance(self, dt: float) -> None:
        """Move by the velocity and turn by the angular velocity over ``dt`` seconds."""
        if self.moving:
            self._set_pose((self._center[0] + self._velocity[0] * dt, self._center[1] + self._velocity[1] * dt),
                           self._angle + self._angular_velocity * dt)

    def contains(self, points: ArrayLike) -> np.ndarray:
        """Whether each point (N, 2) lies strictly inside, as (N,) bool."""
        raise NotImplementedError

    def outline(self, segments: int = 48) -> np.ndarray:
        """(K, 2) points around the shape's boundary (m), counter-clockwise, not closed;
        curves are approximated by ``segments`` points per full turn. For drawing."""
        raise NotImplementedError

    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` in metres."""
        o = self.outline()
        return float(o[:, 0].min()), float(o[:, 1].min()), float(o[:, 0].max()), float(o[:, 1].max())

    def _motion_repr(self) -> str:
        s = ""
        if self._velocity != (0.0, 0.0):
            s += f", velocity={self._velocity}"
        if self._angular_velocity:
            s += f", angular_velocity={self._angular_velocity:g}"
        return s

    def _local(self, points) -> np.ndarray:
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2) - np.array(self._center)
        return p @ _rotation(self._angle)  # R^T p, row-wise


class Rect(Collider):
    """A rotated rectangle.

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
    velocity : (float, float)
        m/s: a moving platform, or a conveyor (what rests on it is carried by friction).
    angular_velocity : float
        Degrees per second about the centre.

    Examples
    --------
    >>> r = Rect((0, 0), (4, 1), 90.0)
    >>> r.contains([[0.0, 1.5], [1.5, 0.0]]).tolist()
    [True, False]
    >>> r.corners.round(3).tolist()
    [[0.5, 2.0], [-0.5, 2.0], [-0.5, -2.0], [0.5, -2.0]]
    """

    kind = RECT

    def __init__(self, center: ArrayLike, size: ArrayLike, angle: float = 0.0, *, friction: float | None = None, static_friction: float | None = None,
                 velocity: ArrayLike = (0.0, 0.0), angular_velocity: float = 0.0) -> None:
        self.size = size
        super().__init__(center, angle, friction, static_friction, velocity, angular_velocity)

    @property
    def size(self) -> tuple[float, float]:
        """Width and height in metres."""
        return self._size

    @size.setter
    def size(self, value: ArrayLike) -> None:
        self._size = _pair(value, "size", positive=True)  # at most 1e9 m
        if hasattr(self, "_version"):
            self._changed()

    @property
    def axes(self) -> np.ndarray:
        """(2, 2): the rectangle's unit x axis (along the width) and y axis (along the height)."""
        return _rotation(self._angle).T.copy()

    @property
    def corners(self) -> np.ndarray:
        """(4, 2) corners in metres, counter-clockwise from the local (+x, -y) corner."""
        u, w = self.axes
        hx, hy = self._size[0] / 2, self._size[1] / 2
        c = np.array(self._center)
        return np.array([c + hx * u - hy * w, c + hx * u + hy * w, c - hx * u + hy * w, c - hx * u - hy * w])

    def contains(self, points: ArrayLike) -> np.ndarray:
        q = self._local(points)
        return (np.abs(q[:, 0]) < self._size[0] / 2) & (np.abs(q[:, 1]) < self._size[1] / 2)

    def outline(self, segments: int = 48) -> np.ndarray:
        return self.corners

    def __repr__(self):
        return (f"Rect(center={self._center}, size={self._size}, angle={self._angle:g}"
                f"{self._motion_repr()})")


class Circle(Collider):
    """A disc.

    Parameters
    ----------
    center : (float, float)
        Centre in metres.
    radius : float
        Metres, > 0.
    friction, static_friction, velocity, angular_velocity
        As for :class:`Rect`; a turning disc (a wheel, a roller) carries what rests on it.

    Examples
    --------
    >>> Circle((0, 0), 1.0).contains([[0.5, 0.5], [0.8, 0.8]]).tolist()
    [True, False]
    """

    kind = CIRCLE

    def __init__(self, center: ArrayLike, radius: float, *, friction: float | None = None, static_friction: float | None = None,
                 velocity: ArrayLike = (0.0, 0.0), angular_velocity: float = 0.0) -> None:
        self.radius = radius
        super().__init__(center, 0.0, friction, static_friction, velocity, angular_velocity)

    @property
    def radius(self) -> float:
        """Metres."""
        return self._radius

    @radius.setter
    def radius(self, value: float) -> None:
        self._radius = _finite(value, "radius", bound=1e9, positive=True)
        if hasattr(self, "_version"):
            self._changed()

    def contains(self, points: ArrayLike) -> np.ndarray:
        q = self._local(points)
        return np.einsum("ij,ij->i", q, q) < self._radius ** 2

    def outline(self, segments: int = 48) -> np.ndarray:
        t = np.linspace(0.0, 2 * np.pi, max(int(segments), 8), endpoint=False) + math.radians(self._angle)
        return np.column_stack([self._center[0] + self._radius * np.cos(t), self._center[1] + self._radius * np.sin(t)])

    def bounds(self) -> tuple[float, float, float, float]:
        (x, y), r = self._center, self._radius
        return x - r, y - r, x + r, y + r

    def __repr__(self):
        return f"Circle(center={self._center}, radius={self._radius:g}{self._motion_repr()})"


class Segment(Collider):
    """A segment with a radius: a capsule (``radius > 0``) or a wire (``radius = 0``).

    A wire has no inside (``contains`` is always False): a vertex cannot cross it, and
    rests on either side, 1 mm off its line (the kernels give it that radius).

    Parameters
    ----------
    a, b : (float, float)
        Ends in metres (equal ends with a radius make a disc).
    radius : float
        Metres, >= 0.
    friction, static_friction, velocity, angular_velocity
        As for :class:`Rect`; it turns about its midpoint.

    Examples
    --------
    >>> s = Segment((0, 0), (2, 0), radius=0.1)
    >>> s.center, s.contains([[1.0, 0.05], [1.0, 0.2], [2.05, 0.0]]).tolist()
    ((1.0, 0.0), [True, False, True])
    """

    kind = SEGMENT

    def __init__(self, a: ArrayLike, b: ArrayLike, *, radius: float = 0.0, friction: float | None = None, static_friction: float | None = None,
                 velocity: ArrayLike = (0.0, 0.0), angular_velocity: float = 0.0) -> None:
        pa, pb = np.array(_pair(a, "a")), np.array(_pair(b, "b"))
        d = pb - pa
        length = float(np.hypot(*d))
        if length > 1e9:
            raise ValueError("a segment must be at most 1e9 m long")
        self._half = length / 2
        self.radius = radius
        if not length > 0 and not self._radius > 0:
            raise ValueError(f"a segment of radius 0 needs two different ends, got a={a!r}, b={b!r}")
        super().__init__(tuple((pa + pb) / 2), math.degrees(math.atan2(d[1], d[0])), friction, static_friction,
                         velocity, angular_velocity)

    @property
    def radius(self) -> float:
        """Metres (0: a wire)."""
        return self._radius

    @radius.setter
    def radius(self, value: float) -> None:
        self._radius = _finite(value, "radius", bound=1e9, non_negative=True)
        if hasattr(self, "_version"):
            self._changed()

    @property
    def length(self) -> float:
        """Distance between the ends, metres."""
        return 2 * self._half

    @property
    def a(self) -> tuple[float, float]:
        """First end (m)."""
        u = _rotation(self._angle)[:, 0]
        return (float(self._center[0] - self._half * u[0]), float(self._center[1] - self._half * u[1]))

    @property
    def b(self) -> tuple[float, float]:
        """Second end (m)."""
        u = _rotation(self._angle)[:, 0]
        return (float(self._center[0] + self._half * u[0]), float(self._center[1] + self._half * u[1]))

    def contains(self, points: ArrayLike) -> np.ndarray:
        q = self._local(points)
        dx = np.abs(q[:, 0]) - self._half
        dx = np.maximum(dx, 0.0)
        return dx * dx + q[:, 1] ** 2 < self._radius ** 2

    def outline(self, segments: int = 48) -> np.ndarray:
        k = max(int(segments) // 2, 4)
        t = np.linspace(-np.pi / 2, np.pi / 2, k)
        r = self._radius
        right = np.column_stack([self._half + r * np.cos(t), r * np.sin(t)])
        left = np.column_stack([-self._half - r * np.cos(t), -r * np.sin(t)])
        local = np.concatenate([right, left]) if r > 0 else np.array([[self._half, 0.0], [-self._half, 0.0]])
        return local @ _rotation(self._angle).T + np.array(self._center)

    def bounds(self) -> tuple[float, float, float, float]:
        (ax, ay), (bx, by), r = self.a, self.b, self._radius
        return min(ax, bx) - r, min(ay, by) - r, max(ax, bx) + r, max(ay, by) + r

    def __repr__(self):
        return f"Segment(a={self.a}, b={self.b}, radius={self._radius:g}{self._motion_repr()})"


class Polygon(Collider):
    """A simple polygon, concave allowed, with optional holes.

    Parameters
    ----------
    points : (K, 2) array_like
        The outer boundary in metres, at least 3 points, either orientation, not closed; it
        must not cross itself.
    holes : sequence of (K, 2) array_like
        Boundaries of holes inside it (the solid is the outer region minus the holes).
    friction, static_friction, velocity, angular_velocity
        As for :class:`Rect`; it turns about its centroid (``center``).

    Examples
    --------
    An L-shaped block:

    >>> p = Polygon([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]])
    >>> p.contains([[0.5, 1.5], [1.5, 1.5], [1.5, 0.5]]).tolist()
    [True, False, True]
    >>> round(p.area, 6), p.center
    (3.0, (0.833333, 0.833333))
    """

    kind = POLYGON

    def __init__(self, points: ArrayLike, *, holes: Sequence[ArrayLike] = (), friction: float | None = None, static_friction: float | None = None,
                 velocity: ArrayLike = (0.0, 0.0), angular_velocity: float = 0.0) -> None:
        outer = _points(points, "points", minimum=3)
        if abs(signed_area(outer)) <= 1e-12 * max(1.0, float(np.ptp(outer, axis=0).max()) ** 2):
            spread = np.linalg.svd(outer - outer.mean(axis=0), compute_uv=False)
            if spread[1] > 1e-9 * max(spread[0], 1e-300):  # not on one line: a bow-tie whose halves cancel
                _check_simple([outer], "a polygon")
            raise ValueError("a polygon's points must enclose an area (they are collinear or repeated)")
        if signed_area(outer) < 0:
            outer = outer[::-1]
        loops = [outer]
        for k, h in enumerate(holes):
            hole = _points(h, f"holes[{k}]", minimum=3)
            if signed_area(hole) > 0:
                hole = hole[::-1]
            if not inside_loops(hole[:1], [outer])[0]:
                raise ValueError(f"holes[{k}] must lie inside the polygon")
            for j, other in enumerate(loops[1:]):
                if inside_loops(hole[:1], [other])[0] or inside_loops(other[:1], [hole])[0]:
                    raise ValueError(f"holes[{k}] and holes[{j}] are nested: an island in a hole is a polygon of "
                                     f"its own")
            loops.append(hole)
        _check_simple(loops, "a polygon")
        area = sum(signed_area(p) for p in loops)
        # the centroid of the solid (outer minus holes): the point it turns about
        cx = cy = 0.0
        for p in loops:
            q = np.roll(p, -1, axis=0)
            cr = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
            cx += float(np.sum((p[:, 0] + q[:, 0]) * cr)) / 6
            cy += float(np.sum((p[:, 1] + q[:, 1]) * cr)) / 6
        c = np.array([round(cx / area, 6), round(cy / area, 6)])
        self._area = area
        self._local_loops = [p - c for p in loops]
        self._reach = _polygon_reach(self._local_loops)  # the same in any pose
        super().__init__(tuple(float(v) for v in c), 0.0, friction, static_friction, velocity, angular_velocity)

    @property
    def area(self) -> float:
        """Area of the solid, m^2."""
        return self._area

    def _world(self, p):
        return p @ _rotation(self._angle).T + np.array(self._center)

    @property
    def points(self) -> np.ndarray:
        """(K, 2) outer boundary now (m), counter-clockwise."""
        return self._world(self._local_loops[0])

    @property
    def holes(self) -> list[np.ndarray]:
        """The holes' boundaries now (m), clockwise."""
        return [self._world(p) for p in self._local_loops[1:]]

    @property
    def loops(self) -> list[np.ndarray]:
        """The outer boundary, then the holes."""
        return [self._world(p) for p in self._local_loops]

    def contains(self, points: ArrayLike) -> np.ndarray:
        q = self._local(points)
        return inside_loops(q, self._local_loops)

    def outline(self, segments: int = 48) -> np.ndarray:
        return self.points

    def __repr__(self):
        holes = f", holes={len(self._local_loops) - 1}" if len(self._local_loops) > 1 else ""
        return f"Polygon({len(self._local_loops[0])} points, center={self._center}{holes}{self._motion_repr()})"


SHAPES = (Rect, Circle, Polygon, Segment)


def pack_colliders(colliders: Sequence[Collider], *, friction: float, static_friction: float) -> np.ndarray:
    """Pack colliders into the (R + E, RECT_COLUMNS) float64 array the kernels read.

    ``friction`` / ``static_friction`` fill in coefficients a collider leaves as ``None``.
    Rows ``0..R-1`` are the colliders in order; the polygons' edges follow.

    Examples
    --------
    >>> pack_colliders([Rect((0, 0), (2, 1), 0.0)], friction=0.3, static_friction=0.5).shape
    (1, 21)
    >>> a = pack_colliders([Polygon([[0, 0], [1, 0], [0, 1]])], friction=0.3, static_friction=0.5)
    >>> a.shape, int(a[0, KIND]), int(a[0, RECT_HX]), int(a[0, RECT_HY])  # 3 edge rows from row 1
    ((4, 21), 2, 1, 3)
    """
    rows: list[np.ndarray] = []
    edges: list[np.ndarray] = []
    n = len(colliders)
    c: Any  # each shape's own fields, by its kind
    for c in colliders:
        row = np.zeros(RECT_COLUMNS)
        row[KIND] = c.kind
        row[RECT_CX], row[RECT_CY] = c.center
        t = math.radians(c.angle)
        row[RECT_UX], row[RECT_UY] = math.cos(t), math.sin(t)
        row[RECT_FRICTION] = friction if c.friction is None else c.friction
        row[RECT_STATIC_FRICTION] = static_friction if c.static_friction is None else c.static_friction
        row[VEL_X], row[VEL_Y] = c.velocity
        row[OMEGA] = math.radians(c.angular_velocity)
        row[COUNT] = n
        if c.kind == RECT:
            row[RECT_HX], row[RECT_HY] = c.size[0] / 2, c.size[1] / 2
            reach = min(row[RECT_HX], row[RECT_HY])
            box = c.corners
        elif c.kind == CIRCLE:
            row[RECT_HX] = c.radius
            reach = c.radius
            box = np.array([np.subtract(c.center, c.radius), np.add(c.center, c.radius)])
        elif c.kind == SEGMENT:
            row[RECT_HX], row[RECT_HY] = c.length / 2, max(c.radius, WIRE)
            reach = row[RECT_HY]
            box = np.array([c.a, c.b])
            box = np.concatenate([box - row[RECT_HY], box + row[RECT_HY]])
        elif c.kind == POLYGON:
            loops = c.loops
            p = np.concatenate(loops)
            q = np.concatenate([np.roll(lp, -1, axis=0) for lp in loops])
            d = q - p
            length = np.hypot(d[:, 0], d[:, 1])
            e = np.zeros((len(p), RECT_COLUMNS))
            e[:, EDGE_AX], e[:, EDGE_AY], e[:, EDGE_BX], e[:, EDGE_BY] = p[:, 0], p[:, 1], q[:, 0], q[:, 1]
            # outward: the solid lies left of a counter-clockwise outer loop and of a clockwise
            # hole alike, so outward is the right-hand normal
            e[:, EDGE_NX], e[:, EDGE_NY] = d[:, 1] / length, -d[:, 0] / length
            e[:, RECT_XMIN], e[:, RECT_XMAX], e[:, RECT_YMIN], e[:, RECT_YMAX] = np.inf, -np.inf, np.inf, -np.inf
            e[:, RECT_REACH] = np.inf
            e[:, KIND] = EDGE
            e[:, COUNT] = n
            row[RECT_HX], row[RECT_HY] = n + sum(len(b) for b in edges), len(p)
            edges.append(e)
            reach = c._reach
            box = p
        else:
            raise ValueError(f"colliders must be deforma.Rect, Circle, Polygon or Segment, found {type(c).__name__}")
        lo, hi = box.min(axis=0), box.max(axis=0)
        row[RECT_XMIN], row[RECT_YMIN] = lo
        row[RECT_XMAX], row[RECT_YMAX] = hi
        scale = float(np.abs(lo).max() + np.abs(hi).max())
        row[RECT_SKIN] = 1e-9 + 1e-13 * scale  # strictly outside after rounding back to world coordinates
        row[RECT_REACH] = reach * reach
        rows.append(row)
    if not rows:
        return np.zeros((0, RECT_COLUMNS))
    return np.concatenate([np.array(rows)] + edges)


def _polygon_reach(loops: list[np.ndarray]) -> float:
    """Half the polygon's thinnest part (m), from below: half the least distance from a
    vertex to an edge not at it. A vertex moving less per substep cannot jump the solid."""
    p = np.concatenate(loops)
    a = p
    b = np.concatenate([np.roll(q, -1, axis=0) for q in loops])
    offs = np.cumsum([0] + [len(q) for q in loops])
    ids = np.concatenate([np.arange(len(q)) + o for q, o in zip(loops, offs)])
    nxt = np.concatenate([np.roll(np.arange(len(q)), -1) + o for q, o in zip(loops, offs)])
    best = np.inf
    for s in range(0, len(p), 512):  # chunks: at most 512 x E distances at once
        v = p[s:s + 512, None]
        d = b - a
        t = np.clip(np.einsum("ijk,jk->ij", v - a[None], d) / np.maximum(np.einsum("jk,jk->j", d, d), 1e-300), 0, 1)
        q = a[None] + t[..., None] * d[None]
        dist = np.hypot(*(v - q).transpose(2, 0, 1))
        own = (ids[s:s + 512, None] == ids[None]) | (ids[s:s + 512, None] == nxt[None])
        dist[own] = np.inf
        best = min(best, float(dist.min()))
    return 0.5 * best if np.isfinite(best) else 0.0


def colliders_from_image(source: ImageSource, *, scale: float = 0.01, position: ArrayLike = (0.0, 0.0),
                         tolerance: float = 1.0, background: Background = "black", threshold: float | None = None,
                         min_area: float = 4.0, friction: float | None = None, static_friction: float | None = None) -> list[Polygon]:
    """A level drawn as a picture: its foreground as static :class:`Polygon` colliders.

    One polygon per connected piece of foreground, holes kept, its outline simplified to
    ``tolerance`` pixels (:func:`deforma.mesh.outline`, which places the picture as
    :func:`deforma.mesh.from_image` does, centred on its bounding box).

    Parameters
    ----------
    source : str, os.PathLike, PIL.Image.Image or array_like
        As for :func:`deforma.mesh.from_image`.
    scale : float
        Metres per pixel, > 0.
    position : (float, float)
        Where the picture's centre goes (m).
    tolerance, background, threshold, min_area
        As for :func:`deforma.mesh.outline`.
    friction, static_friction : float, optional
        Coulomb coefficients of every polygon (``None``: the world's).

    Examples
    --------
    >>> import numpy as np, deforma
    >>> picture = np.zeros((40, 80), np.uint8)
    >>> picture[30:, :] = 255          # a floor
    >>> picture[10:30, 60:70] = 255    # and a pillar standing on it
    >>> level = colliders_from_image(picture, scale=0.05, position=(0, 1))
    >>> len(level), len(level[0].points)  # one piece: an upside-down T, 8 corners
    (1, 8)
    """
    from ...mesh.outline import outline

    x, y = _pair(position, "position")
    pieces = outline(source, scale=scale, tolerance=tolerance, background=background, threshold=threshold,
                     min_area=min_area)
    return [Polygon(outer + (x, y), holes=[h + (x, y) for h in holes], friction=friction,
                    static_friction=static_friction) for outer, holes in pieces]

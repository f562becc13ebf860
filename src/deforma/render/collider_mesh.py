"""Vertex data that draws colliders: a filled, softly shaded inside and a dark border.

Every shape is drawn from its boundary loops in its current pose: a rectangle's corners, a
circle or a capsule as a polygon of :data:`CURVE_SEGMENTS` points per turn, a polygon's
outer boundary and holes. The inside is cut into triangles (:mod:`.fill`), the border is a
band of :data:`COLLIDER_EDGE_PIXELS` inside the boundary, and a wire (a segment of radius 0,
which has no inside) is a band :data:`WIRE_PIXELS` wide along it. Borders are given as a
boundary point plus an offset in pixels that the vertex shader scales, so their width stays
the same at any zoom without rebuilding anything.

Pure NumPy; it reads colliders only through their public attributes (``loops``,
``outline()``, ``center``, ``angle``, ``radius``), so it also draws look-alikes and
``(center, size, angle)`` tuples of rectangles.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from .fill import fill_triangles, loop_depths, loops_area, triangles_still_fit

__all__ = ["COLLIDER_EDGE_PIXELS", "CURVE_SEGMENTS", "WIRE_PIXELS", "ColliderGeometry", "ColliderShape",
           "collider_corners", "collider_shape"]

#: Pixels: the dark border drawn inside a collider's boundary.
COLLIDER_EDGE_PIXELS = 2.0
#: Pixels: the width of a wire (a segment of radius 0).
WIRE_PIXELS = 4.0
#: Points per full turn of a circle or a capsule's ends as drawn (the collider is the true
#: curve; the polygon's flat sides then lie within 0.06% of the radius of it).
CURVE_SEGMENTS = 96
#: A sharp corner's border is cut this many border widths from the corner.
MITER_LIMIT = 4.0
#: The slab's shading: the fill colour times 1 - SHADE at the bottom, 1 at the top.
SHADE = 0.08

# per-vertex floats of the collider buffer: position (m), offset (px), colour (RGBA)
FLOATS_PER_VERTEX = 8


def collider_corners(center: Sequence[float], size: Sequence[float], angle: float) -> np.ndarray:
    """The four corners (4, 2) of a rectangle, counter-clockwise; ``angle`` in degrees."""
    cx, cy = center
    hw, hh = size[0] / 2.0, size[1] / 2.0
    a = np.radians(angle)
    c, s = np.cos(a), np.sin(a)
    local = np.array([[-hw, -hh], [hw, -hh], [hw, hh], [-hw, hh]])
    rot = np.array([[c, -s], [s, c]])
    return local @ rot.T + (cx, cy)


class ColliderShape:
    """A collider's boundary now: ``loops`` (outer first, then holes), whether it is a
    ``wire`` (one open line), its ``center`` and ``angle`` (degrees) for the shading, and a
    ``spoke`` (2, 2) drawn from a circle's centre to its rim at its angle, so that a
    turning wheel is seen to turn."""

    __slots__ = ("loops", "wire", "center", "angle", "spoke")

    def __init__(self, loops: list[np.ndarray], *, wire: bool = False, center: Sequence[float] = (0.0, 0.0),
                 angle: float = 0.0, spoke: np.ndarray | None = None) -> None:
        self.loops = loops
        self.wire = wire
        self.center = center
        self.angle = angle
        self.spoke = spoke


def collider_shape(c: Any) -> ColliderShape:
    """The :class:`ColliderShape` of a collider as it is now.

    ``c`` is a ``deforma`` collider (Rect, Circle, Polygon, Segment), anything with
    ``loops`` or ``outline()`` like them, or a rectangle as an object with ``center``,
    ``size`` and ``angle`` or a ``(center, size, angle_degrees)`` tuple.

    Examples
    --------
    >>> import deforma
    >>> s = collider_shape(deforma.Segment((0, 0), (2, 0)))   # radius 0: a wire
    >>> s.wire, s.loops[0].tolist()
    (True, [[2.0, 0.0], [0.0, 0.0]])
    >>> len(collider_shape(((0, 0), (2, 1), 30.0)).loops[0])
    4
    """
    if isinstance(c, (tuple, list)):
        center, size, angle = c
        return ColliderShape([collider_corners(center, size, angle)], center=tuple(center), angle=float(angle))
    center = tuple(float(v) for v in getattr(c, "center", (0.0, 0.0)))
    angle = float(getattr(c, "angle", 0.0))
    loops = getattr(c, "loops", None)
    if loops is not None:
        return ColliderShape([np.asarray(p, np.float64) for p in loops], center=center, angle=angle)
    outline = getattr(c, "outline", None)
    if callable(outline):
        o = np.asarray(outline(CURVE_SEGMENTS), np.float64)
        spoke = None
        if hasattr(c, "radius") and not hasattr(c, "a"):  # a circle: mark its turning
            t = math.radians(angle)
            r = float(c.radius)
            spoke = np.array([center, (center[0] + r * math.cos(t), center[1] + r * math.sin(t))])
        return ColliderShape([o], wire=len(o) == 2, center=center, angle=angle, spoke=spoke)
    return ColliderShape([collider_corners(c.center, c.size, c.angle)], center=center, angle=angle)


def _band(p: np.ndarray, closed: bool, width: float, *, caps: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Triangles (positions, pixel offsets) of a band ``width`` pixels wide along the line
    through ``p``: inside a closed loop (left of its direction), or centred on an open line,
    its ends reaching half a width past the ends of the line with ``caps``."""
    n = len(p)
    q = np.roll(p, -1, axis=0) if closed else p[1:]
    d = q - (p if closed else p[:-1])
    length = np.hypot(d[:, 0], d[:, 1])
    ok = length > 0
    normal = np.zeros_like(d)
    normal[ok] = np.c_[-d[ok, 1], d[ok, 0]] / length[ok, None]   # left of the direction
    if closed:
        before = np.roll(normal, 1, axis=0)
        m = before + normal
        denom = 1.0 + np.einsum("ij,ij->i", before, normal)
        # a miter whose projection on both sides' normals is one width; flat or reversed
        # corners (a spike) get the later side's normal, long ones are cut
        sharp = denom < 1e-6
        m[~sharp] /= denom[~sharp, None]
        m[sharp] = normal[sharp]
        lens = np.hypot(m[:, 0], m[:, 1])
        long = lens > MITER_LIMIT
        m[long] *= (MITER_LIMIT / lens[long])[:, None]
        inner = m * width
        a, b = np.arange(n), (np.arange(n) + 1) % n
        zero = np.zeros((n, 2))
        # quad per edge: boundary a-b and its inner copy
        pos = np.stack([p[a], p[b], p[b], p[a], p[b], p[a]], axis=1).reshape(-1, 2)
        off = np.stack([zero, zero, inner[b], zero, inner[b], inner[a]], axis=1).reshape(-1, 2)
        return pos, off
    half = 0.5 * width * normal                      # one normal per piece of the line
    along = np.zeros_like(d)
    along[ok] = d[ok] / length[ok, None] * (0.5 * width)
    start, end = p[:-1], p[1:]
    ext = along if caps else np.zeros_like(along)
    pos = np.stack([start, end, end, start, end, start], axis=1).reshape(-1, 2)
    off = np.stack([-ext + half, ext + half, ext - half, -ext + half, ext - half, -ext - half],
                   axis=1).reshape(-1, 2)
    return pos, off


class ColliderGeometry:
    """The vertex data of one collider in one pose: ``fill`` (positions, shade factors),
    ``border`` and ``core`` (positions, pixel offsets). A wire has a dark ``border`` band and
    a thinner ``core`` in its fill colour, and no fill."""

    __slots__ = ("fill_pos", "fill_shade", "border_pos", "border_off", "core_pos", "core_off", "triangles")

    def __init__(self, shape: ColliderShape, triangles: np.ndarray | None = None) -> None:
        loops = shape.loops
        empty2 = np.zeros((0, 2))
        self.triangles: np.ndarray | None = None
        if shape.wire:
            line = loops[0]
            self.fill_pos, self.fill_shade = empty2, np.zeros(0)
            self.border_pos, self.border_off = _band(line, False, WIRE_PIXELS, caps=True)
            self.core_pos, self.core_off = _band(line, False, WIRE_PIXELS - COLLIDER_EDGE_PIXELS, caps=True)
            return
        # boundaries of solid counter-clockwise and holes clockwise: the solid is then left of
        # every edge, which is where the border goes
        depths = loop_depths(loops) if len(loops) > 1 else [0]
        loops = [p if (_area(p) >= 0) == (d % 2 == 0) else p[::-1] for p, d in zip(loops, depths)]
        pts = np.concatenate(loops)
        area = loops_area(loops, depths)
        if triangles is None or len(triangles) == 0 or triangles.max() >= len(pts) \
                or not triangles_still_fit(pts, triangles, area):
            triangles = fill_triangles(loops)
        self.triangles = triangles
        # shading: darker toward the shape's own bottom (its local -y), as light from above
        t = math.radians(shape.angle)
        local_y = (pts[:, 0] - shape.center[0]) * -math.sin(t) + (pts[:, 1] - shape.center[1]) * math.cos(t)
        span = max(float(np.abs(local_y).max()), 1e-12)
        shade = 1.0 - SHADE / 2 + (SHADE / 2) * local_y / span
        self.fill_pos = pts[triangles].reshape(-1, 2)
        self.fill_shade = shade[triangles].reshape(-1)
        parts = [_band(p, True, COLLIDER_EDGE_PIXELS) for p in loops]
        if shape.spoke is not None:
            parts.append(_band(shape.spoke, False, COLLIDER_EDGE_PIXELS))
        self.border_pos = np.concatenate([a for a, _ in parts])
        self.border_off = np.concatenate([b for _, b in parts])
        self.core_pos, self.core_off = empty2, empty2

    def vertices(self, fill: Sequence[float], edge: Sequence[float], out: list[np.ndarray]) -> None:
        """Append this collider's rows (position, offset, colour) to ``out``, fill first."""
        if len(self.fill_pos):
            rgba = np.empty((len(self.fill_pos), 4))
            rgba[:, :3] = np.outer(self.fill_shade, fill[:3])
            rgba[:, 3] = fill[3]
            out.append(np.c_[self.fill_pos, np.zeros_like(self.fill_pos), rgba])
        for pos, off, color in ((self.border_pos, self.border_off, edge), (self.core_pos, self.core_off, fill)):
            if len(pos):
                out.append(np.c_[pos, off, np.tile(np.asarray(color, np.float64), (len(pos), 1))])


def _area(p: np.ndarray) -> float:
    q = np.roll(p, -1, axis=0)
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))

"""Framing: which camera shows a box of the world inside the part of a picture left free.

The viewer draws its status line over the bottom of the world's area and the headless
overlay (``deforma run --overlay``) writes the time at the top and a scale bar at the bottom.
Instead of drawing text over whatever is there, both reserve those bands of pixels and frame
the world in the rest: :func:`fit_camera` returns the camera that puts a box of the world
(the scene's camera rectangle, grown by :func:`content_bounds` where the scene reaches past
it) wholly inside the free part of the picture, centred in it, with square pixels.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, overload

import numpy as np

from .renderer import Camera

if TYPE_CHECKING:
    from ..physics import World

__all__ = ["Box", "camera_box", "content_bounds", "fit_camera", "union"]

#: ``(xmin, ymin, xmax, ymax)`` in metres.
Box = tuple[float, float, float, float]


def camera_box(center: Sequence[float], size: Sequence[float]) -> Box:
    """The rectangle a camera of ``center`` and ``size`` must show, as a box.

    Examples
    --------
    >>> camera_box((0.0, 2.0), (8.0, 4.0))
    (-4.0, 0.0, 4.0, 4.0)
    """
    cx, cy = (float(v) for v in center)
    w, h = (float(v) for v in size)
    return (cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2)


@overload
def union(a: Box, b: Box | None) -> Box: ...
@overload
def union(a: Box | None, b: Box) -> Box: ...
@overload
def union(a: Box | None, b: Box | None) -> Box | None: ...
def union(a: Box | None, b: Box | None) -> Box | None:
    """The smallest box holding both (``None`` is empty)."""
    if a is None or b is None:
        return a if b is None else b
    return (min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3]))


def content_bounds(world: World, *, colliders: bool = True, bodies: bool = True) -> Box | None:
    """The box around every collider's shape and every body's vertices now; None if empty.

    Examples
    --------
    >>> import deforma
    >>> [round(v, 2) for v in content_bounds(deforma.load_scene("sample"))]
    [-3.5, -0.2, 3.5, 3.0]
    """
    box: Box | None = None
    if colliders:
        for c in world.colliders:
            box = union(box, tuple(float(v) for v in c.bounds()))  # type: ignore[arg-type]  # four floats
    if bodies:
        for b in world.bodies:
            p = np.asarray(b.positions)
            if len(p) and np.isfinite(p).all():
                lo, hi = p.min(axis=0), p.max(axis=0)
                box = union(box, (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])))
    return box


def fit_camera(box: Box, viewport: tuple[int, int], *,
               insets: tuple[int, int, int, int] = (0, 0, 0, 0)) -> Camera:
    """The camera that shows ``box`` whole, centred in the part of ``viewport`` the insets leave.

    Parameters
    ----------
    box : (xmin, ymin, xmax, ymax)
        Metres that must be visible.
    viewport : (int, int)
        The picture's width and height in pixels.
    insets : (left, top, right, bottom), optional
        Pixels along each edge kept free (for text drawn over the picture). Insets that would
        leave less than half the picture in either direction are scaled down to leave half.

    Returns
    -------
    Camera
        Its ``size`` has the viewport's aspect ratio, so it is exactly what the picture shows;
        the box is as large as fits, centred in the free rectangle.

    Examples
    --------
    >>> cam = fit_camera((-4.0, 0.0, 4.0, 4.0), (800, 500), insets=(0, 0, 0, 100))
    >>> cam.metres_per_pixel((800, 500)), cam.center     # 8 m in 800 px; the box's middle 50 px up
    (0.01, (0.0, 1.5))
    """
    W, H = (int(v) for v in viewport)
    left, top, right, bottom = (max(0.0, float(v)) for v in insets)
    # never give the bands more than half the picture: a thumbnail still shows the world
    sx = min(1.0, 0.5 * W / (left + right)) if left + right > 0 else 1.0
    sy = min(1.0, 0.5 * H / (top + bottom)) if top + bottom > 0 else 1.0
    left, right, top, bottom = left * sx, right * sx, top * sy, bottom * sy
    free_w, free_h = W - left - right, H - top - bottom
    x0, y0, x1, y1 = (float(v) for v in box)
    bw, bh = max(x1 - x0, 1e-9), max(y1 - y0, 1e-9)
    mpp = max(bw / free_w, bh / free_h)
    # the free rectangle's middle, in pixels from the picture's middle (rows grow downward)
    dx = left + free_w / 2 - W / 2
    dy = top + free_h / 2 - H / 2
    center = ((x0 + x1) / 2 - dx * mpp, (y0 + y1) / 2 + dy * mpp)
    return Camera(center, (W * mpp, H * mpp))

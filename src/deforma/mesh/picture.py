"""Small pictures of meshes and worlds, drawn with Pillow: what a notebook shows for them.

``Mesh._repr_png_`` and ``World._repr_png_`` call these, so a ``Mesh`` or a ``World`` left
as the last line of a Jupyter (or VS Code) cell shows itself. No OpenGL: this module needs
only NumPy and Pillow, like the rest of the core, and reads a world only through its public
attributes (``bodies``: ``positions``, ``triangles``, ``mesh``; ``colliders``).

The picture fits everything in a square of ``size`` pixels (400 by default), y up, with a
small margin. Drawing is at twice the size and shrunk, for smooth edges; it costs about
3 microseconds per triangle (a 20 000-triangle mesh in about 0.1 s).
"""

from __future__ import annotations

import io

import numpy as np

__all__ = ["content_bounds", "mesh_picture", "png_bytes", "world_picture"]

BACKGROUND = (246, 244, 239)
MESH_FILL = (236, 206, 190)
MESH_EDGE = (31, 58, 104)
COLLIDER_FILL = (92, 102, 120)
COLLIDER_EDGE = (51, 59, 71)
#: Fill of bodies without a picture, in order of the bodies (the renderer's palette).
BODY_FILLS = ((224, 122, 95), (61, 153, 112), (242, 165, 65), (91, 141, 239), (181, 101, 118), (129, 178, 154))

_SUPERSAMPLE = 2
_MARGIN = 0.04          # of the picture's longer side, on every side
_MIN_EDGE_PIXELS = 3.0  # a wireframe whose edges are shorter than this on average is a solid blot
_CIRCLE_SIDES = 48


def _check_size(size) -> int:
    if isinstance(size, (bool, np.bool_)) or not isinstance(size, (int, np.integer)) or not 16 <= size <= 4096:
        raise ValueError(f"size must be a whole number of pixels in [16, 4096], got {size!r}")
    return int(size)


def _collider_outline(c) -> np.ndarray:
    """(K, 2) outer boundary of a collider in metres, in its pose now: what its ``outline()``
    gives (a Rect's corners, a polygon's outer points, a circle or a capsule as a polygon, a
    wire's two ends), or, for look-alikes without it, a Rect's corners, a polygon's points, a
    circle or a segment (a capsule when it has a radius) from their attributes."""
    outline = getattr(c, "outline", None)
    if callable(outline):
        return np.asarray(outline(_CIRCLE_SIDES), dtype=np.float64)
    if hasattr(c, "corners"):
        return np.asarray(c.corners, dtype=np.float64)
    if hasattr(c, "points"):
        return np.asarray(c.points, dtype=np.float64)
    a = np.linspace(0.0, 2.0 * np.pi, _CIRCLE_SIDES, endpoint=False)
    ring = np.c_[np.cos(a), np.sin(a)]
    if hasattr(c, "a") and hasattr(c, "b"):
        p, q = np.asarray(c.a, np.float64), np.asarray(c.b, np.float64)
        r = float(getattr(c, "radius", 0.0))
        if r <= 0.0:
            return np.array([p, q])
        # the capsule: the convex hull of a circle around each end
        d = q - p
        angle = np.arctan2(d[1], d[0])
        half = np.linspace(-np.pi / 2, np.pi / 2, _CIRCLE_SIDES // 2 + 1)
        ends = [q + r * np.c_[np.cos(angle + half), np.sin(angle + half)],
                p + r * np.c_[np.cos(angle + np.pi + half), np.sin(angle + np.pi + half)]]
        return np.concatenate(ends)
    if hasattr(c, "radius") and hasattr(c, "center"):
        return np.asarray(c.center, np.float64) + float(c.radius) * ring
    raise TypeError(f"cannot draw a collider of type {type(c).__name__}: it has no corners, points, "
                    f"radius or ends")


def _collider_loops(c) -> list[np.ndarray]:
    """The boundary loops of a collider now (m): the outer one first, then its holes (a
    Polygon's ``loops``); one loop of 2 points is a wire."""
    loops = getattr(c, "loops", None)
    if loops is not None:
        return [np.asarray(p, np.float64) for p in loops]
    return [_collider_outline(c)]


def content_bounds(world) -> tuple[np.ndarray, np.ndarray]:
    """Lower-left and upper-right corners (metres) of every body and collider of ``world``.

    A world with nothing in it gives the square from (-1, -1) to (1, 1).

    Examples
    --------
    >>> import deforma
    >>> w = deforma.World()
    >>> _ = w.add_collider(deforma.Rect(center=(0, 0), size=(4, 1), angle=0.0))
    >>> lo, hi = content_bounds(w)
    >>> lo.tolist(), hi.tolist()
    ([-2.0, -0.5], [2.0, 0.5])
    """
    # a polygon's holes lie inside its outer boundary, so outlines are enough
    parts = [b.positions for b in world.bodies] + [_collider_outline(c) for c in world.colliders]
    if not parts:
        return np.array([-1.0, -1.0]), np.array([1.0, 1.0])
    points = np.concatenate(parts)
    return points.min(axis=0), points.max(axis=0)


class _Canvas:
    """A supersampled Pillow picture mapping metres (y up) into ``size`` pixels."""

    def __init__(self, lo, hi, size: int):
        from PIL import Image, ImageDraw

        lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
        span = np.maximum(hi - lo, 1e-9 * max(1.0, float(np.abs(np.r_[lo, hi]).max())))
        self.size = size
        pad = _MARGIN * size
        self.scale = (size - 2 * pad) / float(span.max())  # pixels per metre
        w, h = np.maximum(np.round(span * self.scale + 2 * pad), 1).astype(int)
        self.out_size = (int(w), int(h))
        ss = _SUPERSAMPLE
        self.image = Image.new("RGB", (int(w) * ss, int(h) * ss), BACKGROUND)
        self.draw = ImageDraw.Draw(self.image)
        # the content is centred in the picture, which is exactly the content's size plus the margin
        self._origin = np.array([lo[0] - pad / self.scale, hi[1] + pad / self.scale])

    def pixels(self, points) -> np.ndarray:
        p = np.asarray(points, np.float64)
        return np.c_[p[:, 0] - self._origin[0], self._origin[1] - p[:, 1]] * (self.scale * _SUPERSAMPLE)

    def triangles(self, points, triangles, fills) -> None:
        """Fill each triangle; ``fills`` is one RGB triple or (M, 3) uint8, one per triangle."""
        corners = self.pixels(points)[np.asarray(triangles)].reshape(-1, 6).tolist()
        fills = np.asarray(fills, np.uint8)
        if fills.ndim == 1:
            fill = tuple(int(v) for v in fills)
            for q in corners:
                self.draw.polygon(q, fill=fill)
        else:
            for q, f in zip(corners, map(tuple, fills.tolist())):
                self.draw.polygon(q, fill=f)

    def edges(self, points, edges, color, *, min_pixels: float = _MIN_EDGE_PIXELS) -> bool:
        """Draw the edges (E, 2) unless they are on average shorter than ``min_pixels``;
        returns whether they were drawn."""
        px = self.pixels(points)
        seg = px[np.asarray(edges)]
        if len(seg) == 0:
            return False
        if np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1).mean() < min_pixels * _SUPERSAMPLE:
            return False
        for q in seg.reshape(-1, 4).tolist():
            self.draw.line(q, fill=color, width=1)
        return True

    def shape(self, loops, fill, edge) -> None:
        """A collider: the inside of ``loops[0]`` minus the other loops (holes) filled, every
        loop bordered; a single loop of 2 points is a wire, drawn as a line."""
        from PIL import Image, ImageDraw

        px = [self.pixels(p) for p in loops]
        if len(px) == 1 and len(px[0]) == 2:
            self.draw.line([tuple(p) for p in px[0].tolist()], fill=edge, width=2 * _SUPERSAMPLE)
            return
        # the fill through a mask of the shape's box, even-odd as a collider's inside test
        # (a hole is cut out, an island in it filled again), so whatever was drawn before
        # shows through the holes (another collider, the background)
        lo = np.floor(np.concatenate(px).min(axis=0)).astype(int) - 1
        hi = np.ceil(np.concatenate(px).max(axis=0)).astype(int) + 2
        lo = np.maximum(lo, 0)
        hi = np.minimum(hi, self.image.size)
        if np.all(hi > lo):
            box = tuple(int(v) for v in hi - lo)
            solid = np.zeros(box[::-1], bool)
            for p in px:
                ring = Image.new("L", box, 0)
                ImageDraw.Draw(ring).polygon([tuple(q) for q in (p - lo).tolist()], fill=255)
                solid ^= np.asarray(ring) > 0
            mask = Image.fromarray(solid.astype(np.uint8) * 255)
            self.image.paste(fill, (int(lo[0]), int(lo[1]), int(hi[0]), int(hi[1])), mask)
        for p in px:
            ring = [tuple(q) for q in p.tolist()]
            self.draw.line(ring + ring[:1], fill=edge, width=_SUPERSAMPLE, joint="curve")

    def finish(self):
        from PIL import Image

        return self.image.resize(self.out_size, Image.LANCZOS)


def _triangle_colors(triangles, uv, texture, fallback) -> np.ndarray:
    """One RGB colour per triangle: ``texture`` at the triangle's uv centre, or ``fallback``.

    A centre that falls on a transparent pixel (a thin triangle along the outline) takes the
    mean colour of the picture's opaque pixels.
    """
    triangles = np.asarray(triangles)
    if texture is None or uv is None:
        return np.tile(np.asarray(fallback, np.uint8), (len(triangles), 1))
    h, w = texture.shape[:2]
    centre = np.asarray(uv)[triangles].mean(axis=1)
    col = np.clip(np.round(centre[:, 0] * (w - 1)), 0, w - 1).astype(int)
    row = np.clip(np.round((1.0 - centre[:, 1]) * (h - 1)), 0, h - 1).astype(int)  # v = 0 is the bottom row
    rgba = texture[row, col]
    opaque = texture[..., 3] >= 128
    mean = texture[opaque][:, :3].mean(axis=0) if opaque.any() else np.asarray(fallback, np.float64)
    rgb = np.where(rgba[:, 3:4] >= 128, rgba[:, :3], np.round(mean).astype(np.uint8))
    return rgb.astype(np.uint8)


def mesh_picture(mesh, *, size: int = 400):
    """A picture of a mesh: its triangles, filled with its texture's colours if it has one, and
    its edges.

    Parameters
    ----------
    mesh : deforma.mesh.Mesh
    size : int, optional
        The longer side of the picture in pixels, in [16, 4096]; the mesh is scaled to fit.

    Returns
    -------
    PIL.Image.Image
        RGB. The edges are left out when they would be under 3 pixels long on average (a mesh
        of tens of thousands of triangles at 400 px): they would only cover the picture.

    Examples
    --------
    >>> import deforma
    >>> m = deforma.mesh.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=4)
    >>> mesh_picture(m).size
    (400, 216)
    """
    size = _check_size(size)
    v = np.asarray(mesh.vertices)
    canvas = _Canvas(v.min(axis=0), v.max(axis=0), size)
    canvas.triangles(v, mesh.triangles, _triangle_colors(mesh.triangles, mesh.uv, mesh.texture, MESH_FILL))
    canvas.edges(v, mesh.edges, MESH_EDGE)
    return canvas.finish()


def world_picture(world, *, size: int = 400):
    """A picture of a world as it is now: colliders in grey, bodies as filled triangles.

    Every collider is drawn in its current pose (a moving one where it has got to): a
    rectangle, a circle, a capsule, a polygon with its holes (what is behind shows through
    them), a wire as a line.

    A body made from a picture takes its colours; other bodies get one colour each. The view
    fits every body and collider (see :func:`content_bounds`), unlike a scene's camera.

    Parameters
    ----------
    world : deforma.World
    size : int, optional
        The longer side of the picture in pixels, in [16, 4096].

    Returns
    -------
    PIL.Image.Image
        RGB.

    Examples
    --------
    >>> import deforma
    >>> world = deforma.load_scene("sample")
    >>> world_picture(world, size=200).size
    (200, 100)
    """
    size = _check_size(size)
    lo, hi = content_bounds(world)
    canvas = _Canvas(lo, hi, size)
    for c in world.colliders:
        canvas.shape(_collider_loops(c), COLLIDER_FILL, COLLIDER_EDGE)
    for k, b in enumerate(world.bodies):
        fallback = BODY_FILLS[k % len(BODY_FILLS)]
        if len(b.triangles) == 0:  # a body of springs only: its springs are all there is to see
            canvas.edges(b.positions, b.springs, fallback, min_pixels=0.0)
            continue
        # the mesh's uv and picture, while the body still has the mesh's vertices (tearing adds some)
        mesh = getattr(b, "mesh", None)
        uv = getattr(mesh, "uv", None)
        uv = uv if uv is not None and len(uv) == len(b.positions) else None
        colors = _triangle_colors(b.triangles, uv, getattr(mesh, "texture", None), fallback)
        canvas.triangles(b.positions, b.triangles, colors)
    return canvas.finish()


def png_bytes(image) -> bytes:
    """The PNG file of a Pillow image, as bytes (what ``_repr_png_`` returns).

    Examples
    --------
    >>> from PIL import Image
    >>> png_bytes(Image.new("RGB", (4, 4)))[:8]
    b'\\x89PNG\\r\\n\\x1a\\n'
    """
    buf = io.BytesIO()
    image.save(buf, format="PNG", optimize=True)
    return buf.getvalue()

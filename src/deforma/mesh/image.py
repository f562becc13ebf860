"""Meshes from pictures: the foreground of an image, triangulated so that it follows the shape.

How it works (the reasons are in ``docs/mesh.md``):

1. **Foreground.** A pixel is foreground when its alpha is above half (images with
   transparency) or, without transparency, when its brightest channel is above about 6 %
   (not black, with room for JPEG noise). Specks and pin-holes smaller than a few pixels
   are dropped: they would become tiny separate pieces or tiny holes in the body.
2. **Outline** (``detect_edges=True``). Sub-pixel contours (marching squares,
   :func:`skimage.measure.find_contours`): of the alpha channel at the threshold, so an
   antialiased edge is located to a fraction of a pixel, or of the mask itself for pictures
   without transparency. One closed ring per outline and per hole, resampled every
   ``edge_step`` pixels of arc length; where a straight segment would stray more than half
   a pixel from the contour (a narrow notch, a sharp tip) the farthest contour point is
   added, so concave parts stay concave.
3. **Interior points.** Every ``resolution``-th pixel in each direction that is foreground.
   With an outline, points closer to it than about half the larger spacing are left out:
   they would be near-duplicates of outline points and would make slivers.
4. **Triangulation.** :func:`deforma.delaunay` is unconstrained, so the outline is made to
   appear in it: each outline segment missing from the triangulation is split at the
   middle of its arc (the new point lies on the true outline) and interior points inside
   that segment's diametral circle are removed, then the points are triangulated again,
   for a few rounds (on the built-in pictures none is needed). Once every outline segment
   is an edge, each triangle lies wholly inside or wholly outside the outline, and the
   ones whose centroid is outside (even-odd over all rings) are dropped. Holes stay holes.
   Last, the rare tiny triangle against the outline whose centroid falls in a pixel whose
   centre is background is dropped too, so every centroid is on a foreground pixel, and so
   are sliver "ears" (two or three outline edges, an angle under 10 degrees): they hold
   almost no area, flatten inside out against a wall and set a finite element's step.
5. **Without an outline** (``detect_edges=False``, the original's behaviour made safe): the
   grid points are triangulated and every triangle that covers a background pixel centre
   is dropped, so the mesh is a slightly shrunken, stair-stepped version of the shape.

Coordinates: pixel ``(row, col)`` covers ``[col, col+1] x [row, row+1]`` in image units;
``x = (col + 0.5 - cx) * scale`` and ``y = (cy - row - 0.5) * scale`` with ``(cx, cy)`` the
centre of the vertices' bounding box, so y points up and the mesh is centred on the origin.
``uv = (x_img / W, 1 - y_img / H)``: v = 0 is the bottom row, as in OpenGL.
"""

from __future__ import annotations

import operator
import os
import warnings
from importlib import resources

import numpy as np
from numba import njit
from PIL import Image, UnidentifiedImageError
from scipy import ndimage

from . import quality
from .delaunay import delaunay
from .mesh import Mesh

#: Names of the pictures shipped in ``deforma/assets/textures``.
BUILTIN_TEXTURES = ("bunny", "donut", "armadillo")
#: Largest picture accepted, in pixels (about 6300 x 6300): the per-pixel arrays of a
#: larger one take gigabytes before a single point is made.
MAX_PIXELS = 40_000_000
#: Default cap on the number of mesh points: beyond it triangulation and the soft body
#: need more memory and time than an interactive simulation can use.
DEFAULT_MAX_POINTS = 1_000_000
#: Rounds of outline recovery (split missing segments, triangulate again).
RECOVERY_ROUNDS = 8

_ALPHA_LEVEL = 0.5
_BRIGHTNESS_LEVEL = 0.06


def from_image(
    source,
    *,
    resolution=4,
    detect_edges=True,
    edge_step=2,
    scale=0.01,
    threshold=None,
    max_points=DEFAULT_MAX_POINTS,
) -> Mesh:
    """A mesh of a picture's foreground that follows its outline, holes and concavities.

    Parameters
    ----------
    source : str, os.PathLike, PIL.Image.Image or array_like
        A built-in texture name (``"bunny"``, ``"donut"``, ``"armadillo"``), a path to a
        PNG or JPEG file, a Pillow image, or an array: ``(H, W)`` grey or boolean,
        ``(H, W, 3)`` RGB or ``(H, W, 4)`` RGBA, as uint8 or floats in [0, 1].
    resolution : int, keyword-only
        Spacing of the interior points in pixels: every ``resolution``-th foreground pixel
        in each direction becomes a point. Smaller gives more points. At least 1.
    detect_edges : bool, keyword-only
        Put points along the traced outline (sub-pixel contours) so the mesh boundary
        follows the picture. Without it only grid points are used and triangles that would
        cover background are dropped, which gives a stair-stepped, slightly smaller mesh.
    edge_step : int, keyword-only
        Spacing of the outline points, in pixels of outline length. At least 1. Sharp
        features (a narrow notch, a tip) get an extra point where a segment would stray
        more than half a pixel from the outline; a regular point next to such a feature is
        merged into it, so spacings range from below ``edge_step`` to ``1.5 * edge_step``.
    scale : float, keyword-only
        Metres per pixel, > 0.
    threshold : float, optional, keyword-only
        Level in (0, 1) above which a pixel is foreground: of the alpha channel when the
        picture has transparency (default 0.5), otherwise of its brightest colour channel
        (default 0.06, so only black and near-black is background).
    max_points : int, keyword-only
        Refuse pictures that would give more mesh points than this (they would exhaust
        memory or take minutes); raise ``resolution`` and ``edge_step`` instead.

    Returns
    -------
    Mesh
        Vertices in metres, centred on the origin, y up; ``uv`` into the picture (v up);
        ``texture`` the picture as an RGBA array (row 0 at the top).

    Raises
    ------
    ValueError
        On a missing or unreadable file, a picture larger than ``MAX_PIXELS``, no
        foreground, a parameter out of range, or more points than ``max_points``.

    Examples
    --------
    >>> import deforma
    >>> m = deforma.mesh.from_image("donut", resolution=8, edge_step=4, scale=0.01)
    >>> len(m.boundary), m.euler_characteristic
    (2, 0)
    >>> bool(abs(m.vertices.mean(axis=0)).max() < 0.05)  # centred on the origin
    True
    """
    r = _check_int("resolution", resolution, 1)
    e = _check_int("edge_step", edge_step, 1)
    limit = _check_int("max_points", max_points, 3)
    if not isinstance(detect_edges, (bool, np.bool_)):
        raise ValueError(f"detect_edges must be True or False, got {detect_edges!r}")
    try:
        scale = float(scale)
    except (TypeError, ValueError):
        raise ValueError(f"scale must be a number of metres per pixel > 0, got {scale!r}") from None
    if not (np.isfinite(scale) and scale > 0):
        raise ValueError(f"scale must be a finite number of metres per pixel > 0, got {scale!r}")

    rgba, field, level, by_alpha = _load(source, threshold)
    mask = _clean(field > level)
    if not mask.any():
        raise ValueError(
            "the picture has no foreground: every pixel is transparent or black at threshold "
            f"{level / 255:.3g}; need pixels above it"
        )
    h, w = mask.shape
    off = r // 2
    grid = np.zeros_like(mask)
    grid[off::r, off::r] = True
    grid &= mask
    n_grid = int(grid.sum())
    n_outline = _boundary_pixel_count(mask) // e if detect_edges else 0
    if n_grid + n_outline > limit:
        raise ValueError(
            f"the picture would give about {n_grid + n_outline} points with resolution={r} and "
            f"edge_step={e}; at most max_points={limit} allowed (raise resolution or edge_step)"
        )

    if detect_edges:
        if by_alpha:
            # alpha is coverage: its level line is the antialiased edge to a fraction of a
            # pixel. Specks and pin-holes removed from the mask are removed here too.
            outline_field = np.where(mask == (field > level), field, np.where(mask, 255.0, 0.0))
            outline_level = level
        else:
            # brightness is not coverage (a dark-red shape on black would shrink or grow
            # with the threshold): trace the mask itself, along the pixel borders
            outline_field, outline_level = np.where(mask, 255.0, 0.0), 127.5
        rings = _outline_rings(outline_field, outline_level, e)
        margin = max(0.5 * r, 0.5 * e + 1.0)
        depth = ndimage.distance_transform_edt(mask) - 0.5  # ~distance to the contour
        rows, cols = np.nonzero(grid & (depth >= margin))
        interior = np.c_[cols + 0.5, rows + 0.5]
        points, tris = _mesh_with_outline(rings, interior)
        # The outline is sub-pixel; a tiny triangle against it can still have its centroid
        # in a pixel whose centre is background. Drop those few, so that every triangle's
        # centroid is on a foreground pixel (the definition the tests check).
        if len(tris):
            cen = points[tris].mean(axis=1)
            rr = np.clip(cen[:, 1].astype(np.int64), 0, h - 1)
            cc = np.clip(cen[:, 0].astype(np.int64), 0, w - 1)
            tris = tris[mask[rr, cc]]
        tris = _peel_ears(points, tris)
    else:
        rows, cols = np.nonzero(grid)
        points = np.c_[cols + 0.5, rows + 0.5]
        if len(points) < 3:
            raise ValueError(
                f"resolution={r} leaves {len(points)} foreground points; need at least 3 "
                "(use a smaller resolution or detect_edges=True)"
            )
        tris = _triangulate(points)
        tris = tris[~_covers_background(points, tris, mask)]
        tris = _peel_slivers(points, tris)

    if len(tris):
        tris = tris[~quality.degenerate_triangles(points, tris)]
    if len(tris) == 0:
        raise ValueError(
            f"no triangle fits inside the foreground with resolution={r}; use a smaller "
            "resolution or detect_edges=True"
        )
    used = np.unique(tris)
    remap = np.full(len(points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    points, tris = points[used], remap[tris].astype(np.int32)

    lo, hi = points.min(axis=0), points.max(axis=0)
    cx, cy = 0.5 * (lo + hi)
    vertices = np.c_[(points[:, 0] - cx) * scale, (cy - points[:, 1]) * scale]
    uv = np.clip(np.c_[points[:, 0] / w, 1.0 - points[:, 1] / h], 0.0, 1.0)
    return Mesh(vertices, tris, uv, texture=rgba)


def foreground_mask(source, *, threshold=None) -> np.ndarray:
    """The pixels :func:`from_image` treats as the shape.

    Parameters
    ----------
    source : str, os.PathLike, PIL.Image.Image or array_like
        As for :func:`from_image`.
    threshold : float, optional, keyword-only
        As for :func:`from_image`.

    Returns
    -------
    (H, W) ndarray of bool
        True on foreground pixels, row 0 at the top of the picture (specks and pin-holes
        of a few pixels removed, as the mesher does).

    Examples
    --------
    >>> m = foreground_mask("donut")
    >>> m.shape, bool(m[m.shape[0] // 2, m.shape[1] // 2])  # the hole is background
    ((384, 384), False)
    """
    _, field, level, _ = _load(source, threshold)
    return _clean(field > level)


# ---- loading -------------------------------------------------------------------------------


def _load(source, threshold):
    """(rgba uint8 (H, W, 4), field float (H, W) in 0..255, level, field is alpha)."""
    if threshold is not None:
        try:
            threshold = float(threshold)
        except (TypeError, ValueError):
            raise ValueError(f"threshold must be a number in (0, 1), got {threshold!r}") from None
        if not 0.0 < threshold < 1.0:
            raise ValueError(f"threshold must be a number in (0, 1), got {threshold!r}")

    if isinstance(source, Image.Image):
        rgba, has_alpha = _from_pil(source, "the image")
    elif isinstance(source, (str, os.PathLike)):
        rgba, has_alpha = _from_path(source)
    else:
        rgba, has_alpha = _from_array(source)

    if has_alpha and rgba[..., 3].min() < 255:
        field = rgba[..., 3].astype(np.float32)
        level = 255.0 * (threshold if threshold is not None else _ALPHA_LEVEL)
        return rgba, field, level, True
    field = rgba[..., :3].max(axis=2).astype(np.float32)
    level = 255.0 * (threshold if threshold is not None else _BRIGHTNESS_LEVEL)
    return rgba, field, level, False


def _from_path(source):
    name = os.fspath(source)
    if isinstance(source, str) and name in BUILTIN_TEXTURES:
        ref = resources.files("deforma") / "assets" / "textures" / f"{name}.png"
        with resources.as_file(ref) as path:
            return _open(path, name)
    if not os.path.isfile(name):
        raise ValueError(
            f"image file not found: {name!r}; give a path to a PNG or JPEG file or one of "
            f"{', '.join(map(repr, BUILTIN_TEXTURES))}"
        )
    return _open(name, name)


def _open(path, label):
    try:
        with Image.open(path) as im:
            return _from_pil(im, label)
    except Image.DecompressionBombError:
        raise ValueError(f"image {label!r} is too large; at most {MAX_PIXELS} pixels allowed") from None
    except (UnidentifiedImageError, OSError, SyntaxError) as exc:
        raise ValueError(f"cannot read image {label!r} ({exc}); a PNG or JPEG file is needed") from None


def _from_pil(im, label):
    w, h = im.size
    if w * h > MAX_PIXELS:
        raise ValueError(f"image {label!r} has {w}x{h} = {w * h} pixels; at most {MAX_PIXELS} allowed")
    if w == 0 or h == 0:
        raise ValueError(f"image {label!r} is empty ({w}x{h}); it needs at least one pixel")
    has_alpha = im.mode in ("RGBA", "LA", "La", "RGBa", "PA") or "transparency" in im.info
    try:
        rgba = np.asarray(im.convert("RGBA"), dtype=np.uint8)
    except OSError as exc:  # truncated or corrupt data surfaces when pixels are decoded
        raise ValueError(f"cannot read image {label!r} ({exc}); a PNG or JPEG file is needed") from None
    return np.ascontiguousarray(rgba), has_alpha


def _from_array(source):
    try:
        a = np.asarray(source)
    except Exception:  # noqa: BLE001 - any object that is not an image at all
        a = None
    if a is None or a.dtype == object or a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] not in (3, 4)):
        shape = getattr(a, "shape", None)
        raise ValueError(
            "source must be a texture name, a path, a PIL image or an (H, W), (H, W, 3) or "
            f"(H, W, 4) array, got {type(source).__name__} with shape {shape}"
        )
    if a.shape[0] * a.shape[1] > MAX_PIXELS:
        raise ValueError(f"image array has {a.shape[0] * a.shape[1]} pixels; at most {MAX_PIXELS} allowed")
    if a.shape[0] == 0 or a.shape[1] == 0:
        raise ValueError(f"image array is empty (shape {a.shape}); it needs at least one pixel")
    if a.dtype == bool:
        a = a.astype(np.uint8) * 255
    elif np.issubdtype(a.dtype, np.floating):
        if not np.all(np.isfinite(a)) or a.min() < 0 or a.max() > 1:
            raise ValueError("a float image array must hold finite values in [0, 1]")
        a = np.round(a * 255).astype(np.uint8)
    elif a.dtype != np.uint8:
        if not np.issubdtype(a.dtype, np.integer) or a.min() < 0 or a.max() > 255:
            raise ValueError(f"an integer image array must be uint8-valued (0..255), got dtype {a.dtype}")
        a = a.astype(np.uint8)
    if a.ndim == 2:
        a = np.repeat(a[..., None], 3, axis=2)
    has_alpha = a.shape[2] == 4
    if not has_alpha:
        a = np.concatenate([a, np.full(a.shape[:2] + (1,), 255, np.uint8)], axis=2)
    return np.ascontiguousarray(a), has_alpha


# ---- foreground and outline ----------------------------------------------------------------

_MIN_PIECE = 9  # pixels: smaller specks and holes are noise, not shape
_OUTLINE_TOLERANCE = 0.5  # pixels: how far an outline segment may stray from the contour


def _clean(mask):
    labels, n = ndimage.label(mask)
    if n:
        sizes = np.bincount(labels.ravel())
        small = sizes < _MIN_PIECE
        small[0] = False
        mask = mask & ~small[labels]
    # holes: background components that do not reach the border
    padded = np.pad(~mask, 1, constant_values=True)
    labels, n = ndimage.label(padded)
    if n > 1:
        sizes = np.bincount(labels.ravel())
        small = sizes < _MIN_PIECE
        small[0] = False
        small[labels[0, 0]] = False  # the outside
        mask = mask | small[labels][1:-1, 1:-1]
    return mask


def _boundary_pixel_count(mask):
    return int((mask & ~ndimage.binary_erosion(mask, border_value=0)).sum())


class _Ring:
    """One closed outline: the dense contour and the arc positions of its mesh points."""

    def __init__(self, dense, step):
        closed = np.vstack([dense, dense[:1]])
        seg = np.hypot(*np.diff(closed, axis=0).T)
        self.dense = closed
        self.cum = np.concatenate([[0.0], np.cumsum(seg)])
        self.length = float(self.cum[-1])
        self.step = step
        n = max(3, int(round(self.length / step)))
        self.s = np.arange(n) * (self.length / n)

    def refine(self, tolerance):
        """Add points where a straight segment strays more than ``tolerance`` px from the arc.

        Uniform spacing alone cuts across notches narrower than ``edge_step`` and rounds
        off sharp tips; a point at the farthest contour vertex of each such segment (as in
        Douglas-Peucker) keeps concave parts concave. A uniform point left a fraction of a
        pixel from such a feature point would only make a sliver, so uniform points closer
        than half a step (along the outline) to a feature point are dropped and the check
        runs again.
        """
        uniform = self.s.copy()
        features = np.zeros(0)
        for _ in range(4):
            added = self._split_far(tolerance)
            if added.size == 0:
                return
            features = np.union1d(features, added)
            gap = np.abs(uniform[:, None] - features[None, :]).min(axis=1)
            gap = np.minimum(gap, self.length - gap)  # the ring is closed
            crowded = gap < 0.5 * self.step
            if not crowded.any():
                return
            uniform = uniform[~crowded]
            self.s = np.union1d(uniform, features)
        self._split_far(tolerance)  # whatever happened above, end within tolerance

    def _split_far(self, tolerance):
        """Split until every segment is within tolerance; return the arc positions added."""
        t = self.cum[:-1]
        v = self.dense[:-1]
        added = []
        for _ in range(64):
            p = self.points()
            n = len(p)
            j = np.searchsorted(self.s, t, side="right") - 1
            a, b = p[j], p[(j + 1) % n]
            ab = b - a
            norm = np.hypot(ab[:, 0], ab[:, 1])
            cross = ab[:, 0] * (v[:, 1] - a[:, 1]) - ab[:, 1] * (v[:, 0] - a[:, 0])
            dist = np.where(norm > 0, np.abs(cross) / np.where(norm > 0, norm, 1.0), np.hypot(*(v - a).T))
            far = dist > tolerance
            if not far.any():
                break
            # the farthest contour vertex of each offending segment
            order = np.lexsort((dist, j))
            last = np.r_[j[order][1:] != j[order][:-1], True]
            pick = order[last]
            pick = pick[far[pick]]
            added.append(t[pick])
            self.s = np.union1d(self.s, t[pick])
        return np.concatenate(added) if added else np.zeros(0)

    def points(self):
        s = self.s
        x = np.interp(s, self.cum, self.dense[:, 0])
        y = np.interp(s, self.cum, self.dense[:, 1])
        return np.c_[x, y]

    def split(self, k):
        """Insert a point halfway along the arc from point k to point k + 1."""
        a = self.s[k]
        b = self.s[k + 1] if k + 1 < len(self.s) else self.length
        self.s = np.insert(self.s, k + 1, 0.5 * (a + b))


def _outline_rings(field, level, step):
    from skimage.measure import find_contours

    # a background border closes every contour
    padded = np.pad(field, 1, constant_values=min(0.0, level - 1.0))
    rings = []
    for c in find_contours(padded, level):
        xy = np.c_[c[:, 1] - 1 + 0.5, c[:, 0] - 1 + 0.5]  # (row, col) centres -> image x, y
        if len(xy) > 1 and np.array_equal(xy[0], xy[-1]):
            xy = xy[:-1]
        if len(xy) < 3 or abs(_polygon_area(xy)) < 1.0:
            continue
        ring = _Ring(xy, step)
        ring.refine(_OUTLINE_TOLERANCE)
        rings.append(ring)
    return rings


def _polygon_area(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * (np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


# ---- triangulation -------------------------------------------------------------------------


def _triangulate(points):
    if len(points) < 3:
        return np.zeros((0, 3), dtype=np.int64)
    d = points - points[0]
    far = d[np.argmax(np.hypot(d[:, 0], d[:, 1]))]
    if not np.any(d[:, 0] * far[1] - d[:, 1] * far[0]):
        return np.zeros((0, 3), dtype=np.int64)  # all on one line: no triangle
    try:
        return np.asarray(delaunay(points), dtype=np.int64)
    except ValueError:
        # fewer than three non-collinear points: nothing to mesh (caller reports it)
        return np.zeros((0, 3), dtype=np.int64)


def _edge_keys(tris, n):
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    e.sort(axis=1)
    return np.unique(e[:, 0] * n + e[:, 1])


def _mesh_with_outline(rings, interior):
    """Triangulate outline + interior points until every outline segment is an edge."""
    if not rings:
        raise ValueError("the foreground has no outline larger than a pixel; need a larger shape")
    keep = np.ones(len(interior), dtype=bool)
    for _ in range(RECOVERY_ROUNDS + 1):
        ring_pts = [ring.points() for ring in rings]
        starts = np.cumsum([0] + [len(p) for p in ring_pts])
        outline = np.concatenate(ring_pts)
        points = np.concatenate([outline, interior[keep]])
        n = len(points)
        tris = _triangulate(points)
        seg_a = np.arange(len(outline))
        seg_b = seg_a + 1
        for k in range(len(rings)):
            seg_b[starts[k + 1] - 1] = starts[k]
        lo, hi = np.minimum(seg_a, seg_b), np.maximum(seg_a, seg_b)
        missing = ~np.isin(lo * n + hi, _edge_keys(tris, n)) if len(tris) else np.ones(len(lo), bool)
        if not missing.any():
            break
        # interior points inside a missing segment's diametral circle encroach on it
        a, b = outline[seg_a[missing]], outline[seg_b[missing]]
        mid, rad = 0.5 * (a + b), 0.5 * np.hypot(*(b - a).T)
        idx = np.flatnonzero(keep)
        for m, rr in zip(mid, rad):
            d = np.hypot(*(interior[idx] - m).T)
            keep[idx[d <= rr * 1.0001]] = False
        # split from the back so earlier indices in a ring stay valid
        for g in np.flatnonzero(missing)[::-1]:
            k = int(np.searchsorted(starts, g, side="right") - 1)
            rings[k].split(int(g - starts[k]))
    else:
        warnings.warn(
            f"{int(missing.sum())} outline segments are not mesh edges after {RECOVERY_ROUNDS} "
            "rounds; the mesh may cross the outline there",
            RuntimeWarning,
            stacklevel=3,
        )
    if len(tris) == 0:
        return points, tris
    cen = points[tris].mean(axis=1)
    inside = np.zeros(len(tris), dtype=bool)
    from skimage.measure import points_in_poly

    for k in range(len(rings)):
        inside ^= points_in_poly(cen, outline[starts[k] : starts[k + 1]])
    return points, tris[inside]


@njit(cache=True)
def _covers_background_kernel(p, t, mask, out):
    h, w = mask.shape
    for k in range(t.shape[0]):
        ax, ay = p[t[k, 0], 0], p[t[k, 0], 1]
        bx, by = p[t[k, 1], 0], p[t[k, 1], 1]
        cx, cy = p[t[k, 2], 0], p[t[k, 2], 1]
        area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        if area == 0.0:
            out[k] = True
            continue
        c0 = max(int(np.floor(min(ax, bx, cx) - 0.5)), 0)
        c1 = min(int(np.ceil(max(ax, bx, cx) - 0.5)), w - 1)
        r0 = max(int(np.floor(min(ay, by, cy) - 0.5)), 0)
        r1 = min(int(np.ceil(max(ay, by, cy) - 0.5)), h - 1)
        hit = False
        for r in range(r0, r1 + 1):
            y = r + 0.5
            for c in range(c0, c1 + 1):
                x = c + 0.5
                # inside or on the closed triangle: all three edge functions agree in sign
                d0 = ((bx - ax) * (y - ay) - (by - ay) * (x - ax)) * area
                d1 = ((cx - bx) * (y - by) - (cy - by) * (x - bx)) * area
                d2 = ((ax - cx) * (y - cy) - (ay - cy) * (x - cx)) * area
                if d0 >= 0.0 and d1 >= 0.0 and d2 >= 0.0 and not mask[r, c]:
                    hit = True
                    break
            if hit:
                break
        out[k] = hit


def _covers_background(points, tris, mask):
    """True for each triangle (in image pixel units) that holds a background pixel centre."""
    out = np.zeros(len(tris), dtype=np.bool_)
    if len(tris):
        _covers_background_kernel(
            np.ascontiguousarray(points, np.float64), np.ascontiguousarray(tris, np.int64), mask, out
        )
    return out


#: Degrees: boundary triangles thinner than this are peeled off grid-only meshes.
_PEEL_ANGLE = 10.0


def _peel_slivers(points, tris):
    """Repeatedly drop boundary triangles with a tiny angle (grid-only meshes).

    Between grid points along a stair-stepped outline Delaunay forms long thin triangles
    that hold no background pixel centre; they add almost no area and make stiff, badly
    conditioned springs, so they go.
    """
    return _peel(points, tris, 1)


def _peel_ears(points, tris):
    """Repeatedly drop sliver "ears": triangles with two or three outline edges and an angle
    below ``_PEEL_ANGLE``.

    Three outline points almost in a line (two resampled points a fraction of a pixel apart,
    or a triangle left behind by the centroid check above) make a triangle of almost no
    area whose corners are all on the outline. Nothing inside holds it open: pressed against
    a wall it is flattened onto it, inside out by a hair, and as a finite element its tiny
    height sets a tiny stable step. Dropping it cuts that corner of the outline by less than
    the triangle's own area (its middle point leaves the mesh).
    """
    return _peel(points, tris, 2, keep_all=True)


def _peel(points, tris, outline_edges, keep_all=False):
    """Repeatedly drop triangles with at least ``outline_edges`` outline edges and an angle
    below ``_PEEL_ANGLE`` (``keep_all``: unless that would drop every triangle)."""
    for _ in range(16):
        if len(tris) == 0:
            return tris
        e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
        e.sort(axis=1)
        _, inv, counts = np.unique(e, axis=0, return_inverse=True, return_counts=True)
        on_outline = (counts[inv.ravel()] == 1).reshape(3, -1).sum(axis=0)
        thin = (on_outline >= outline_edges) & (quality.triangle_min_angles(points, tris) < _PEEL_ANGLE)
        if not thin.any() or (keep_all and thin.all()):
            return tris
        tris = tris[~thin]
    return tris


def _check_int(name, value, low):
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    try:
        v = operator.index(value)
    except TypeError:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}") from None
    if v < low:
        raise ValueError(f"{name} must be an integer >= {low}, got {v}")
    return v

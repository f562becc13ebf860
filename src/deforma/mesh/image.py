"""Meshes from pictures: the foreground of an image, triangulated so that it follows the shape.

How it works (the reasons are in ``docs/mesh.md``):

1. **Foreground.** In a picture with transparency (some alpha below 255) a pixel is
   foreground when its alpha is above half. Without transparency it is foreground when its
   colour differs from the background's by more than ``threshold`` in at least one channel
   (``max(|R - Rb|, |G - Gb|, |B - Bb|) / 255``); the background is black unless the
   caller names another (``"white"``, ``"auto"``: the colour of the picture's border, or any
   colour), and the default threshold, about 6 %, leaves room for JPEG noise. With a black
   background this is the seed's rule, "the brightest channel is not black". Specks and
   pin-holes smaller than a few pixels are dropped: they would become tiny separate pieces
   or tiny holes in the body.
2. **Outline** (``detect_edges=True``). Sub-pixel contours (marching squares,
   :func:`skimage.measure.find_contours`): of the alpha channel at the threshold, so an
   antialiased edge is located to a fraction of a pixel, or of the mask itself for pictures
   without transparency. One closed ring per outline and per hole, resampled every
   ``edge_step`` pixels of arc length; where a straight segment would stray more than half
   a pixel from the contour (a narrow notch, a sharp tip) the farthest contour point is
   added, so concave parts stay concave. Points closer than 0.4 ``edge_step`` are then
   merged into one where the outline stays within a pixel (each such pair would make a
   needle triangle with an interior point).
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
6. **Manifold.** Where dropped triangles leave two parts touching at one vertex only (a
   pinch: a thin ring or crossing lines cut there), the vertex is split, one copy per fan
   of triangles (:func:`deforma.mesh.mesh.split_pinches`): every vertex has one fan and
   every boundary vertex one boundary edge in and one out.

Coordinates: pixel ``(row, col)`` covers ``[col, col+1] x [row, row+1]`` in image units;
``x = (col + 0.5 - cx) * scale`` and ``y = (cy - row - 0.5) * scale`` with ``(cx, cy)`` the
centre of the vertices' bounding box, so y points up and the mesh is centred on the origin.
``uv = (x_img / W, 1 - y_img / H)``: v = 0 is the bottom row, as in OpenGL.
"""

from __future__ import annotations

import operator
import os
import struct
import warnings
import zlib
from importlib import resources
from pathlib import Path
from typing import Any, Union

import numpy as np
from numba import njit
from numpy.typing import ArrayLike
from PIL import Image, UnidentifiedImageError

from ..checks import MAX_BODY_POINTS, positive
from . import quality
from .delaunay import delaunay
from .mesh import Mesh, split_pinches

#: What a picture argument may be: a built-in texture's name, a path, a PIL image or an (H, W[, C]) array.
ImageSource = Union[str, "os.PathLike[str]", Image.Image, ArrayLike]
#: A ``background`` argument: ``"black"``, ``"white"``, ``"auto"``, ``"#rrggbb"`` or (r, g, b) ints 0-255.
Background = Union[str, tuple[int, int, int], list[int]]

#: File types a built-in texture may be stored as (what Pillow reads).
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".gif", ".tif", ".tiff", ".webp")


def builtin_textures() -> dict:
    """The pictures shipped in ``deforma/assets/textures``: name -> file, sorted by name.

    The one list of built-in textures: ``from_image``, scene files, the CLI and the viewer
    all take their names from here, so a picture added to the folder is everywhere at once.

    Returns
    -------
    dict of str to pathlib.Path

    Examples
    --------
    >>> sorted(builtin_textures())
    ['armadillo', 'bunny', 'donut']
    """
    folder = Path(str(resources.files("deforma") / "assets" / "textures"))
    if not folder.is_dir():
        return {}
    return {p.stem: p for p in sorted(folder.iterdir()) if p.suffix.lower() in IMAGE_SUFFIXES}


#: Names of the pictures shipped in ``deforma/assets/textures`` (``builtin_textures()``'s keys).
BUILTIN_TEXTURES = tuple(builtin_textures())
#: Largest picture accepted, in pixels (about 6300 x 6300): the per-pixel arrays of a
#: larger one take gigabytes before a single point is made.
MAX_PIXELS = 40_000_000
#: Default cap on the number of mesh points: the most one body may have
#: (``deforma.checks.MAX_BODY_POINTS``, where the measurements behind it are), also the
#: largest ``max_points`` accepted.
DEFAULT_MAX_POINTS = MAX_BODY_POINTS
#: Rounds of outline recovery (split missing segments, triangulate again).
RECOVERY_ROUNDS = 8

_NAMED_RGB = {"black": (0, 0, 0), "white": (255, 255, 255)}
#: Names ``background`` accepts besides a colour.
BACKGROUND_NAMES = (*_NAMED_RGB, "auto")
#: Default ``threshold`` of the alpha channel (pictures with transparency).
ALPHA_THRESHOLD = 0.5
#: Default ``threshold`` of the colour distance to the background (pictures without
#: transparency): about 15 of 255, above the noise of a JPEG's flat background.
COLOR_THRESHOLD = 0.06
# "auto" needs a border that is mostly one colour: at least this share of the border pixels
# within ``threshold`` of its median colour, or the guess would be a colour nobody chose
_AUTO_AGREEMENT = 0.5


def from_image(
    source: ImageSource,
    *,
    resolution: int = 4,
    detect_edges: bool = True,
    edge_step: int = 2,
    scale: float = 0.01,
    background: Background = "black",
    threshold: float | None = None,
    max_points: int = DEFAULT_MAX_POINTS,
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
        merged into it, and so are two points closer than ``0.4 * edge_step`` where the
        outline then stays within a pixel, so spacings are ``edge_step`` along smooth parts
        and range from about 0.15 times it (a narrow notch's two corners) to under twice it.
    scale : float, keyword-only
        Metres per pixel, > 0.
    background : str or tuple of int, keyword-only
        What the shape is on, for pictures without transparency: ``"black"`` (the default,
        the seed's rule), ``"white"``, ``"auto"`` (the median colour of the picture's
        outermost pixels, which must mostly agree with it) or a colour, ``"#rrggbb"`` or an
        ``(r, g, b)`` tuple of integers 0-255. Ignored when the picture has transparency
        (some alpha below 255): then alpha decides, whatever the colours.
    threshold : float, optional, keyword-only
        In [0, 1), a fraction of full scale. Without transparency: how far a pixel's colour
        must be from the background to be foreground, measured in the channel that differs
        most, ``max(|R - Rb|, |G - Gb|, |B - Bb|) / 255`` (default ``COLOR_THRESHOLD`` =
        0.06, about 15 of 255). With transparency: the alpha level above which a pixel is
        foreground (default ``ALPHA_THRESHOLD`` = 0.5).
    max_points : int, keyword-only
        Refuse pictures that would give more mesh points than this, counted from the
        foreground pixels on the ``resolution`` grid and the outline's length before any
        triangulation; the message names the ``resolution`` (and, where the outline alone
        is too long, the ``edge_step``) that fits. In [3, ``MAX_BODY_POINTS``] (100,000,
        the default: the most one body may have; a step of a million points took 29 s).

    Returns
    -------
    Mesh
        Vertices in metres, centred on the origin, y up; ``uv`` into the picture (v up);
        ``texture`` the picture as an RGBA array (row 0 at the top), see :func:`load_rgba`.

    Raises
    ------
    ValueError
        On a missing or unreadable file, a picture larger than ``MAX_PIXELS``, an unknown
        or malformed ``background``, ``threshold`` outside [0, 1), a border with no main
        colour for ``"auto"``, no foreground or nothing but foreground (the picture is not
        on that background), a parameter out of range, or more points than ``max_points``
        (at most ``MAX_BODY_POINTS``).

    Examples
    --------
    >>> import deforma
    >>> m = deforma.mesh.from_image("donut", resolution=8, edge_step=4, scale=0.01)
    >>> len(m.boundary), m.euler_characteristic
    (2, 0)
    >>> bool(abs(m.vertices.mean(axis=0)).max() < 0.05)  # centred on the origin
    True

    A dark square on white, 40 x 40 px at 1 cm per pixel:

    >>> import numpy as np
    >>> picture = np.full((60, 60, 3), 255, np.uint8)
    >>> picture[10:50, 10:50] = (40, 30, 30)
    >>> round(deforma.mesh.from_image(picture, background="white").area, 3)  # m^2
    0.16
    """
    r = _check_int("resolution", resolution, 1)
    e = _check_int("edge_step", edge_step, 1)
    limit = _check_int("max_points", max_points, 3, MAX_BODY_POINTS)
    if not isinstance(detect_edges, (bool, np.bool_)):
        raise ValueError(f"detect_edges must be True or False, got {detect_edges!r}")
    scale = positive(scale, "scale", "m per pixel")

    pic = _load(source, background, threshold)
    field, level, by_alpha = pic.field, pic.level, pic.by_alpha
    raw = field > level
    mask = _clean(raw)
    _check_foreground(pic, mask, raw)
    h, w = mask.shape
    off = r // 2
    grid = np.zeros_like(mask)
    grid[off::r, off::r] = True
    grid &= mask
    n_grid = int(grid.sum())
    n_border = _boundary_pixel_count(mask) if detect_edges else 0
    if n_grid + n_border // e > limit:
        allowed = (f"max_points={limit}" if limit < MAX_BODY_POINTS else
                   f"{limit} (MAX_BODY_POINTS, the most one body may have)")
        raise ValueError(f"the picture would give about {n_grid + n_border // e} points with resolution={r} and "
                         f"edge_step={e}; at most {allowed} allowed: {_what_fits(mask, r, e, n_border, limit)}")

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
        from scipy import ndimage  # here, not at import: 0.3 s that a box-only run never needs

        depth = ndimage.distance_transform_edt(mask) - 0.5  # ~distance to the contour
        rows, cols = np.nonzero(grid & (depth >= margin))
        interior = np.c_[cols + 0.5, rows + 0.5]
        points, tris = _mesh_with_outline(rings, interior)
        # The outline is sub-pixel; a tiny triangle against it can still have its centroid
        # in a pixel whose centre is background. Drop those few, so that every triangle's
        # centroid is on a foreground pixel (the definition the tests check).
        if len(tris):
            cen = np.take(points, tris, axis=0).mean(axis=1)  # np.take: 10x faster than points[tris]
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
    # pieces that touch only at a vertex (a thin line cut where a triangle was dropped, two
    # parts meeting corner to corner) are separated there: every vertex gets one fan
    tris, source = split_pinches(tris, len(points))
    # np.take: gathers (N, 2) rows ~10x faster than points[source]
    points = np.take(points, source, axis=0)
    used = np.unique(tris)
    remap = np.full(len(points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    points, tris = np.take(points, used, axis=0), remap[tris].astype(np.int32)

    lo, hi = points.min(axis=0), points.max(axis=0)
    cx, cy = 0.5 * (lo + hi)
    vertices = np.c_[(points[:, 0] - cx) * scale, (cy - points[:, 1]) * scale]
    uv = np.clip(np.c_[points[:, 0] / w, 1.0 - points[:, 1] / h], 0.0, 1.0)
    return Mesh(vertices, tris, uv=uv, texture=_with_alpha(pic, None if by_alpha else mask))


def foreground_mask(source: ImageSource, *, background: Background = "black",
                    threshold: float | None = None) -> np.ndarray:
    """The pixels :func:`from_image` treats as the shape.

    Parameters
    ----------
    source : str, os.PathLike, PIL.Image.Image or array_like
        As for :func:`from_image`.
    background : str or tuple of int, keyword-only
        As for :func:`from_image`.
    threshold : float, optional, keyword-only
        As for :func:`from_image`.

    Returns
    -------
    (H, W) ndarray of bool
        True on foreground pixels, row 0 at the top of the picture (specks and pin-holes
        of a few pixels removed, as the mesher does). Unlike :func:`from_image` an empty or
        full mask is returned, not refused: it shows what a background choice does.

    Examples
    --------
    >>> m = foreground_mask("donut")
    >>> m.shape, bool(m[m.shape[0] // 2, m.shape[1] // 2])  # the hole is background
    ((384, 384), False)
    """
    pic = _load(source, background, threshold)
    return _clean(pic.field > pic.level)


def load_rgba(source: ImageSource, *, background: Background = "black",
              threshold: float | None = None) -> np.ndarray:
    """The picture as :func:`from_image` reads it and puts in ``Mesh.texture``.

    The one image loader of the package (scene textures use it too). A picture without
    transparency gets alpha 0 on its background pixels (by :func:`foreground_mask`'s test
    with the same ``background`` and ``threshold``), so a renderer draws no fringe of the
    background colour around the body; a picture with transparency keeps its alpha.

    Parameters
    ----------
    source, background, threshold
        As for :func:`from_image`.

    Returns
    -------
    (H, W, 4) ndarray of uint8
        RGBA, row 0 at the top of the picture.

    Raises
    ------
    ValueError
        An unreadable source, or a bad ``background`` or ``threshold``. A picture that is
        all background or all foreground is not an error here (a texture may be either).

    Examples
    --------
    >>> import numpy as np
    >>> picture = np.zeros((20, 20, 3), np.uint8)
    >>> picture[5:15, 5:15] = 200
    >>> rgba = load_rgba(picture)
    >>> rgba.shape, int(rgba[0, 0, 3]), int(rgba[10, 10, 3])  # black is see-through
    ((20, 20, 4), 0, 255)
    """
    pic = _load(source, background, threshold)
    return _with_alpha(pic, None if pic.by_alpha else _clean(pic.field > pic.level))


# ---- loading -------------------------------------------------------------------------------


class _Picture:
    """A loaded picture and its foreground test: ``field > level`` is foreground."""

    __slots__ = ("rgba", "field", "level", "by_alpha", "background", "rgb")

    def __init__(self, rgba, field, level, by_alpha, background, rgb):
        self.rgba = rgba          # (H, W, 4) uint8, as read
        self.field = field        # (H, W) float32 in 0..255: alpha, or distance to the background
        self.level = level        # 255 * threshold
        self.by_alpha = by_alpha  # alpha decides (the picture has transparency)
        self.background = background  # as the caller gave it (for messages)
        self.rgb = rgb            # the background colour used, or None when alpha decides


def _load(source, background, threshold):
    """Read ``source`` and set up its foreground test (a :class:`_Picture`)."""
    named = check_background(background)
    threshold = check_threshold(threshold)
    rgba = read_rgba(source)
    if rgba[..., 3].min() < 255:
        # transparency always wins: alpha is coverage, drawn by whoever made the picture
        level = 255.0 * (ALPHA_THRESHOLD if threshold is None else threshold)
        return _Picture(rgba, rgba[..., 3].astype(np.float32), level, True, background, None)
    level = 255.0 * (COLOR_THRESHOLD if threshold is None else threshold)
    rgb = _border_rgb(rgba, level) if named == "auto" else named
    return _Picture(rgba, _colour_distance(rgba, rgb), level, False, background, rgb)


def check_background(background: Any) -> str | tuple[int, ...]:
    """What a ``background`` argument means: an (r, g, b) tuple of ints 0-255, or ``"auto"``.

    Accepted: ``"black"``, ``"white"``, ``"auto"`` (any case), a colour ``"#rrggbb"``, or a
    sequence of three integers 0-255. Scene files use it to check their ``background`` key.

    Raises
    ------
    ValueError
        Anything else, in one line listing what is allowed.

    Examples
    --------
    >>> check_background("white"), check_background("#1E78C8"), check_background("auto")
    ((255, 255, 255), (30, 120, 200), 'auto')
    """
    if isinstance(background, str):
        name = background.strip().lower()
        if name == "auto":
            return "auto"
        if name in _NAMED_RGB:
            return _NAMED_RGB[name]
        if len(name) == 7 and name[0] == "#":
            try:
                return tuple(int(name[k : k + 2], 16) for k in (1, 3, 5))
            except ValueError:
                pass
    elif isinstance(background, (tuple, list, np.ndarray)) and len(background) == 3:
        try:
            rgb = tuple(operator.index(c) for c in background)
        except TypeError:
            rgb = None
        if rgb is not None and all(0 <= c <= 255 for c in rgb) and not any(
            isinstance(c, (bool, np.bool_)) for c in background
        ):
            return rgb
    raise ValueError(
        'background must be "black", "white", "auto" (the colour of the picture\'s border), '
        f'a colour "#rrggbb" or an (r, g, b) tuple of integers 0-255, got {background!r}'
    )


def check_threshold(threshold: Any) -> float | None:
    """What a ``threshold`` argument means: a float in [0, 1), or None for the default.

    Raises
    ------
    ValueError
        Anything else (including ``True``), in one line saying what is allowed.

    Examples
    --------
    >>> check_threshold(0.1), check_threshold(None)
    (0.1, None)
    """
    if threshold is None:
        return None
    try:
        # True is not a level (float(True) would be 1.0 and pass as a number)
        t = float("nan") if isinstance(threshold, (bool, np.bool_)) else float(threshold)
    except (TypeError, ValueError):
        t = float("nan")
    if not 0.0 <= t < 1.0:  # also refuses nan
        raise ValueError(
            "threshold must be a number in [0, 1), a fraction of full scale (of the colour distance to "
            f"the background, or of alpha for pictures with transparency), got {threshold!r}"
        )
    return t


def _colour_distance(rgba, rgb):
    """(H, W) float32: ``max(|R - Rb|, |G - Gb|, |B - Bb|)`` in 0..255.

    The channel that differs most, not the Euclidean distance: against black it is the
    brightest channel, the seed's rule, exactly; it spans 0..255 for every background; and
    a shape that differs in one channel only (red on black) counts fully.
    """
    out = np.zeros(rgba.shape[:2], np.float32)
    for c in range(3):  # one channel at a time: a (H, W, 3) int16 copy of a large picture is big
        np.maximum(out, np.abs(rgba[..., c].astype(np.int16) - rgb[c]), out=out)
    return out


def _border_rgb(rgba, level):
    """The colour of the picture's outermost pixels (per-channel median) for ``"auto"``.

    The median, not the mean: a shape touching the border on one side, or JPEG noise, does
    not move it. It must describe the border, though: if fewer than half the border pixels
    are within ``level`` of it, there is no background colour to guess and saying so beats
    meshing a colour nobody chose.
    """
    h, w = rgba.shape[:2]
    rim = np.concatenate([rgba[0, :, :3], rgba[h - 1, :, :3], rgba[1 : h - 1, 0, :3], rgba[1 : h - 1, w - 1, :3]])
    rgb = tuple(int(v) for v in np.median(rim, axis=0).round())
    near = (np.abs(rim.astype(np.int16) - np.array(rgb, np.int16)).max(axis=1) <= level).mean()
    if near < _AUTO_AGREEMENT:
        raise ValueError(
            f'background="auto" found no main colour on the picture\'s border: only {near:.0%} of its pixels '
            f"are within threshold {level / 255:.3g} of their median {_hex(rgb)}; give the background "
            '("black", "white", "#rrggbb" or (r, g, b)) or a larger threshold'
        )
    return rgb


def _hex(rgb):
    return "#{:02x}{:02x}{:02x}".format(*rgb)


def _describe(pic):
    """How a message names the background: ``'white' (#ffffff)``."""
    return f"{pic.background!r} ({_hex(pic.rgb)})" if isinstance(pic.background, str) else _hex(pic.rgb)


def _check_foreground(pic, mask, raw=None):
    """Refuse a mask that is empty or full: the picture is not on that background.

    ``raw`` is the mask before specks were dropped: a picture whose foreground is nothing
    but specks (a tiny picture, a thin diagonal line) is told so, not that it has none.
    """
    t = f"{pic.level / 255:.3g}"
    choose = ('choose the background the shape is on ("black", "white", "auto" for the border\'s colour, '
              '"#rrggbb" or (r, g, b))')
    if not mask.any() and raw is not None and raw.any():
        h, w = raw.shape
        raise ValueError(f"the picture's foreground is only specks: {int(raw.sum())} of its {h}x{w} pixels are "
                         f"foreground, in pieces smaller than {_MIN_PIECE} pixels joined side to side, which are "
                         f"dropped as noise; need a shape of at least {_MIN_PIECE} such pixels (a larger or "
                         "thicker shape)")
    if not mask.any():
        if pic.by_alpha:
            raise ValueError(f"the picture has no foreground: every pixel's alpha is at or below threshold {t} "
                             "(transparent); need pixels above it (a lower threshold, or a picture with an "
                             "opaque shape)")
        raise ValueError(f"the picture has no foreground: no pixel differs from the background {_describe(pic)} "
                         f"by more than threshold {t}; {choose} or lower threshold")
    if mask.all():
        if pic.by_alpha:
            raise ValueError(f"the whole picture is foreground: every pixel's alpha is above threshold {t}; "
                             "need transparent pixels around the shape (or a higher threshold)")
        border = _border_rgb_or_none(pic.rgba)
        seen = f" (its border is {_hex(border)})" if border is not None and border != pic.rgb else ""
        raise ValueError(f"the whole picture is foreground: every pixel differs from the background "
                         f"{_describe(pic)} by more than threshold {t}, so the body would be the picture's "
                         f"rectangle{seen}; {choose} or raise threshold")


def _border_rgb_or_none(rgba):
    try:
        return _border_rgb(rgba, 255.0 * COLOR_THRESHOLD)
    except ValueError:
        return None


def _with_alpha(pic, mask):
    """The picture with alpha 0 off ``mask`` (None: keep the picture's own alpha)."""
    if mask is None:
        return pic.rgba
    rgba = pic.rgba.copy()
    rgba[..., 3] = np.where(mask, 255, 0).astype(np.uint8)
    return rgba


def read_rgba(source: ImageSource) -> np.ndarray:
    """Read a picture as it is, without any foreground test: (H, W, 4) uint8 RGBA, row 0 on top.

    Parameters
    ----------
    source : str, os.PathLike, PIL.Image.Image or array_like
        As for :func:`from_image`. Pictures without alpha get alpha 255 everywhere, so "has
        transparency" is simply "some alpha below 255", whatever the file's mode was.

    Raises
    ------
    ValueError
        A missing or unreadable file, a picture over ``MAX_PIXELS``, an array that is not an
        image.

    Examples
    --------
    >>> read_rgba("bunny").shape
    (384, 384, 4)
    """
    if isinstance(source, Image.Image):
        return _from_pil(source, "the image")
    if isinstance(source, (str, os.PathLike)):
        return _from_path(source)
    return _from_array(source)


def _from_path(source):
    name = os.fspath(source)
    textures = builtin_textures()
    if isinstance(source, str) and name in textures:
        return _open(textures[name], name)
    if not os.path.isfile(name):
        raise ValueError(
            f"image file not found: {name!r}; give a path to a PNG or JPEG file or one of "
            f"{', '.join(map(repr, textures))}"
        )
    return _open(name, name)


def check_picture(path: str | os.PathLike[str]) -> None:
    """Read the picture at ``path`` as :func:`from_image` would, to refuse at once what it
    would refuse later (not a picture, truncated or corrupt data, a header that lies about its
    size, no pixels, more than ``MAX_PIXELS``): a scene file's texture is checked when the
    file is read, so that the error names its key, not only when a frame is drawn.

    Raises
    ------
    ValueError
        One line naming the file and what is wrong with it.
    """
    _open(path, str(path))


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
    try:
        if im.format == "PNG" and getattr(im, "filename", ""):
            _check_png_data(im.filename, label)  # before a pixel is decoded: the full image is never made
        elif im.format == "PNG" and im.tile and getattr(im, "fp", None) is not None:
            # a PNG opened from memory (Image.open(BytesIO)) and not decoded yet lies the same way
            _check_png_stream(im.fp, label)
        if im.mode in _WIDE_GREY_MODES:
            return _from_array(_wide_grey_to_8bit(np.asarray(im), im.mode, label))
        rgba = np.asarray(im.convert("RGBA"), dtype=np.uint8)
    except OSError as exc:  # truncated or corrupt data surfaces when pixels are decoded
        raise ValueError(f"cannot read image {label!r} ({exc}); a PNG or JPEG file is needed") from None
    return np.ascontiguousarray(rgba)


#: PNG colour type -> samples per pixel (grey, RGB, palette, grey and alpha, RGBA).
_PNG_SAMPLES = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}
#: Adam7's seven passes: (first column, first row, column step, row step).
_ADAM7 = ((0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2))
#: Bytes inflated (and read) at a time when a PNG's data is counted.
_PNG_PIECE = 1 << 20


def _png_data_size(width: int, height: int, bit_depth: int, colour_type: int, interlaced: bool) -> int:
    """Bytes a PNG of this header inflates to: its rows of samples, each after a filter byte
    (the rows of each of Adam7's passes when interlaced)."""
    bits = _PNG_SAMPLES.get(colour_type, 4) * bit_depth
    total = 0
    for x0, y0, dx, dy in _ADAM7 if interlaced else ((0, 0, 1, 1),):
        w, h = -(-(width - x0) // dx), -(-(height - y0) // dy)
        if w > 0 and h > 0:
            total += h * (1 + (w * bits + 7) // 8)
    return total


def _check_png_data(path, label) -> None:
    """Refuse a PNG whose data ends before the rows its header promises.

    Pillow decodes such a file without a word when its compressed stream ends cleanly at the
    end of a row, and the missing rows come out black: a 97-byte file whose header said 6000 x
    6000 became a 36-megapixel picture that took gigabytes and tens of seconds to mesh. Here
    the IDAT chunks are inflated a megabyte at a time and the bytes counted, not kept, only
    until the header's size is reached (so a zip bomb costs no more than an honest file).
    A file that does not start as a PNG does is left to Pillow.
    """
    with open(path, "rb") as f:
        _check_png_file(f, label)


def _check_png_stream(fp, label) -> None:
    """:func:`_check_png_data` on the open file object of a PNG not decoded yet, put back where it was."""
    try:
        where = fp.tell()
    except (OSError, ValueError, AttributeError):  # not seekable, or closed: left to Pillow
        return
    try:
        fp.seek(0)
        _check_png_file(fp, label)
    finally:
        fp.seek(where)


def _check_png_file(f, label) -> None:
    """The check of :func:`_check_png_data`, on an open binary file (seekable)."""
    head = f.read(33)
    if len(head) < 33 or head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        return
    width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", head[16:29])
    need = _png_data_size(width, height, depth, colour, interlace == 1)
    inflate, got = zlib.decompressobj(), 0
    try:
        f.seek(8)
        while got < need and not inflate.eof:
            top = f.read(8)
            if len(top) < 8:
                break
            length, kind = struct.unpack(">I4s", top)
            if kind == b"IEND":
                break
            if kind != b"IDAT":
                f.seek(length + 4, os.SEEK_CUR)  # another chunk, and its CRC
                continue
            left = length
            while left and got < need and not inflate.eof:
                data = f.read(min(left, _PNG_PIECE))
                if not data:
                    break
                left -= len(data)
                while data and got < need and not inflate.eof:
                    got += len(inflate.decompress(data, _PNG_PIECE))
                    data = inflate.unconsumed_tail
            f.seek(left + 4, os.SEEK_CUR)  # what was not needed, and the CRC
        if got < need and not inflate.eof:
            got += len(inflate.flush())  # what the last piece still held
    except zlib.error as exc:
        raise ValueError(f"cannot read image {label!r} (corrupt compressed data: {exc}); a whole PNG or JPEG "
                         f"file is needed") from None
    if got < need:
        raise ValueError(f"cannot read image {label!r} (image file is truncated: its header says {width}x{height} "
                         f"pixels, its data ends {100 * got / need:.2g} % of the way through them); a whole PNG or "
                         f"JPEG file is needed")


# Pillow's convert("RGBA") clips these to 0..255, so a 16-bit disc (say 60000 on 20000)
# became white on white: the whole square was meshed, or nothing, without a word
_WIDE_GREY_MODES = ("I;16", "I;16L", "I;16B", "I;16N", "I", "F")


def _wide_grey_to_8bit(a, mode, label):
    """A 16-bit ("I;16*", "I") or float ("F") greyscale picture as 8-bit grey.

    16-bit values map 0..65535 to 0..255 (65535 is white, as in PNG); "I" holds 32-bit
    integers, which must be in 0..65535 (what Pillow reads 16-bit files as); "F" floats
    must be in [0, 1]. Anything else has no agreed brightness and is refused.
    """
    if mode == "F":
        if not (np.isfinite(a).all() and a.min() >= 0.0 and a.max() <= 1.0):
            raise ValueError(f"image {label!r} is 32-bit float greyscale (mode F) with values outside [0, 1]; "
                             "need 8-bit or 16-bit pictures, or floats in [0, 1]")
        return a.astype(np.float64)
    a = a.astype(np.int64)
    if a.min() < 0 or a.max() > 65535:
        raise ValueError(f"image {label!r} is 32-bit integer greyscale (mode {mode}) with values in "
                         f"[{a.min()}, {a.max()}]; need 8-bit pictures or 16-bit values in 0..65535")
    return ((a * 255 + 32767) // 65535).astype(np.uint8)


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
    if a.shape[2] == 3:
        a = np.concatenate([a, np.full(a.shape[:2] + (1,), 255, np.uint8)], axis=2)
    return np.ascontiguousarray(a)


# ---- foreground and outline ----------------------------------------------------------------

_MIN_PIECE = 9  # pixels: smaller specks and holes are noise, not shape
_OUTLINE_TOLERANCE = 0.5  # pixels: how far an outline segment may stray from the contour
_MERGE_GAP = 0.4  # of edge_step: outline points closer than this are merged ...
_MERGE_TOLERANCE = 1.0  # pixels: ... where the merged outline strays at most this far (a pixel)
_MERGE_CANDIDATES = 64  # places tried for a merged point at most


def _clean(mask):
    from scipy import ndimage

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
    from scipy import ndimage

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

    def merge_close(self, gap, tolerance):
        """Merge points closer than ``gap`` px of arc where the outline allows it.

        Feature points land on contour vertices, and two of them can end a pixel apart (both
        sides of a rounded tip, a notch's two corners). With an interior point a spacing
        away, such a pair makes a needle triangle whose tiny height sets a finite element's
        stable step (a bunny at ``edge_step=16`` had a 0.9 px high triangle). Each close
        pair, closest first, becomes one point: the contour vertex between its neighbours
        that keeps both new segments closest to the contour, provided they stay within
        ``tolerance``; otherwise the pair is kept (a narrow notch needs both its corners).
        """
        t = self.cum[:-1]
        t3 = np.concatenate([t - self.length, t, t + self.length])  # the closed arc unrolled
        v3 = np.concatenate([self.dense[:-1]] * 3)
        kept = set()  # pairs that cannot merge (looked at once)
        # in passes, closest pairs first; a pair next to one merged in this pass waits for the
        # next pass (its neighbours, the ends of its new segments, have moved): each pass costs
        # one sort, however many pairs merge
        while len(self.s) > 4:
            s, n = self.s, len(self.s)
            p = self.points()
            d = np.diff(np.r_[s, s[0] + self.length])
            order = np.argsort(d, kind="stable")
            order = order[d[order] < gap]
            touched = np.zeros(n, bool)
            drop, add = [], []
            for i in order:
                j, before, after = (i + 1) % n, i - 1, (i + 2) % n
                if touched[i] or touched[j] or touched[before] or touched[after] \
                        or (s[i], s[j]) in kept or n - len(drop) <= 4:
                    continue
                # the pair between its neighbours, unrolled along the closed arc so that
                # positions increase
                lo = s[before] - (self.length if i == 0 else 0.0)
                hi = s[after] + (self.length if i + 2 >= n else 0.0)
                cand, worst = self._deviation(t3, v3, lo, hi, p[before], p[after])
                if cand.size == 0:
                    continue
                k = int(np.argmin(worst))
                if worst[k] > tolerance:
                    kept.add((s[i], s[j]))
                    continue
                touched[[i, j]] = True
                drop += [i, j]
                add.append(cand[k] % self.length)
            if not drop:
                return
            keep = np.ones(n, bool)
            keep[drop] = False
            self.s = np.union1d(s[keep], add)

    def _deviation(self, t3, v3, lo, hi, a, b):
        """For contour vertices strictly between arc positions ``lo`` and ``hi`` taken as the
        middle point (all of them, or ``_MERGE_CANDIDATES`` evenly spread over a long
        stretch, so memory stays bounded at a large ``edge_step``): their positions and the
        largest distance of the contour from the two segments lo-mid and mid-hi.

        ``t3``, ``v3``: the contour's arc positions and vertices three times over (shifted by
        minus one, zero and one length), so that positions past the ends of ``[0, length)``
        (a pair across the ring's start) are found by one sorted search; ``a``, ``b``: the
        points at ``lo`` and ``hi``.
        """
        i0, i1 = np.searchsorted(t3, lo, side="right"), np.searchsorted(t3, hi, side="left")
        t, v = t3[i0:i1], v3[i0:i1]
        pick = np.unique(np.linspace(0, len(t) - 1, _MERGE_CANDIDATES).astype(np.int64)) if len(t) else []
        tm, m = t[pick], v[pick]  # the candidate middle points
        first = t[None, :] <= tm[:, None]  # which segment each contour vertex is measured to
        start = np.where(first[..., None], a, m[:, None, :])
        end = np.where(first[..., None], m[:, None, :], b)
        ab = end - start
        rel = v[None, :, :] - start
        length = np.hypot(ab[..., 0], ab[..., 1])
        cross = np.abs(ab[..., 0] * rel[..., 1] - ab[..., 1] * rel[..., 0])
        dist = np.where(length > 0, cross / np.where(length > 0, length, 1.0), np.hypot(rel[..., 0], rel[..., 1]))
        return tm, dist.max(axis=1) if len(t) else np.zeros(0)

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
        ring.merge_close(_MERGE_GAP * step, _MERGE_TOLERANCE)
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
    cen = np.take(points, tris, axis=0).mean(axis=1)  # np.take: 10x faster than points[tris]
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


def _what_fits(mask, r, e, n_border, limit):
    """Say the smallest ``resolution`` (and, if the outline alone passes half the limit, the
    ``edge_step``) whose points fit in ``limit``: grid points at resolution q are counted on
    the mask as from_image samples it (about foreground / q**2), outline points n_border / e."""
    hint = ""
    if n_border // e > limit // 2:
        e = -(-n_border // (limit // 2))  # ceil: the outline in half the points
        hint = f"edge_step={e} or more and "
    room = limit - n_border // e

    def fits(q):
        return int(mask[q // 2::q, q // 2::q].sum()) <= room

    q = max(r + 1, int(np.sqrt(mask.sum() / max(room, 1))))
    while not fits(q):
        q += 1
    while q - 1 > r and fits(q - 1):
        q -= 1
    return f"give {hint}resolution={q} or more"


def _check_int(name, value, low, high=None):
    allowed = f">= {low}" if high is None else f"in [{low}, {high}]"
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be an integer {allowed}, got {value!r}")
    try:
        v = operator.index(value)
    except TypeError:
        raise ValueError(f"{name} must be an integer {allowed}, got {value!r}") from None
    if v < low or (high is not None and v > high):
        raise ValueError(f"{name} must be an integer {allowed}, got {v}")
    return v

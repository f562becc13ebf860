"""Triangle quality figures: angles, aspect ratios, and the test for degenerate triangles.

All functions take a vertex array ``(N, 2)`` and a triangle array ``(M, 3)`` and return one
value per triangle, so a caller can look at the worst triangle, a histogram, or a mask.

Definitions
-----------
minimum angle
    The smallest interior angle of a triangle, in degrees; 60 for an equilateral triangle,
    towards 0 for a sliver.
aspect ratio
    The radius ratio ``R / (2 r)`` (circumradius over twice the inradius): exactly 1 for an
    equilateral triangle, growing without bound as the triangle flattens. Unlike longest edge
    over shortest altitude it is symmetric in the three edges and is the figure mesh
    generators (Shewchuk's Triangle, CGAL) report.
degenerate
    A triangle whose area is below ``DEGENERATE_RELATIVE_AREA`` times its longest edge
    squared: three (nearly) collinear points. Such a triangle has no stiffness across its
    flat direction and makes spring and area computations divide by zero.
"""

from __future__ import annotations

import numpy as np

#: Twice the area over the longest edge squared below which a triangle counts as degenerate.
#: An equilateral triangle scores ``sqrt(3)/2``; rounding error on exactly collinear points
#: scores about 1e-16, so 1e-9 separates the two by many orders of magnitude.
DEGENERATE_RELATIVE_AREA = 1e-9


def _corners(vertices, triangles):
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles)
    if t.dtype.kind in "iu":
        # np.take: gathers (N, 2) rows ~10x faster than v[t[:, k]] (NumPy 2.4)
        return np.take(v, t[:, 0], axis=0), np.take(v, t[:, 1], axis=0), np.take(v, t[:, 2], axis=0)
    return v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]  # float, bool, object indices: fancy indexing's errors and meaning


def triangle_signed_areas(vertices, triangles) -> np.ndarray:
    """Signed area of each triangle.

    Parameters
    ----------
    vertices : (N, 2) array_like of float
        Vertex positions (any length unit; the result is in that unit squared).
    triangles : (M, 3) array_like of int
        Vertex indices per triangle.

    Returns
    -------
    (M,) ndarray of float64
        Positive for counter-clockwise triangles, negative for clockwise ones.

    Examples
    --------
    >>> triangle_signed_areas([[0, 0], [2, 0], [0, 1]], [[0, 1, 2], [0, 2, 1]])
    array([ 1., -1.])
    """
    a, b, c = _corners(vertices, triangles)
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def triangle_edge_lengths(vertices, triangles) -> np.ndarray:
    """Edge lengths of each triangle.

    Parameters
    ----------
    vertices : (N, 2) array_like of float
        Vertex positions.
    triangles : (M, 3) array_like of int
        Vertex indices per triangle.

    Returns
    -------
    (M, 3) ndarray of float64
        Column k is the length of the edge opposite corner k (from corner k+1 to corner k+2),
        in the vertices' length unit.

    Examples
    --------
    >>> triangle_edge_lengths([[0, 0], [3, 0], [0, 4]], [[0, 1, 2]])
    array([[5., 4., 3.]])
    """
    a, b, c = _corners(vertices, triangles)
    return np.stack(
        [np.hypot(*(c - b).T), np.hypot(*(a - c).T), np.hypot(*(b - a).T)], axis=1
    )


def triangle_angles(vertices, triangles) -> np.ndarray:
    """Interior angles of each triangle, in degrees.

    Parameters
    ----------
    vertices : (N, 2) array_like of float
        Vertex positions.
    triangles : (M, 3) array_like of int
        Vertex indices per triangle.

    Returns
    -------
    (M, 3) ndarray of float64
        Column k is the angle at corner k, in degrees; each row sums to 180 (0 for a
        triangle with a repeated vertex).

    Examples
    --------
    >>> triangle_angles([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]).round(6)
    array([[90., 45., 45.]])
    """
    a, b, c = _corners(vertices, triangles)
    out = np.empty((len(a), 3))
    for k, (p, q, r) in enumerate(((a, b, c), (b, c, a), (c, a, b))):
        u, w = q - p, r - p
        # atan2(|cross|, dot) stays accurate for angles near 0 and 180 where acos does not.
        cross = u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]
        dot = u[:, 0] * w[:, 0] + u[:, 1] * w[:, 1]
        out[:, k] = np.degrees(np.arctan2(np.abs(cross), dot))
    return out


def triangle_min_angles(vertices, triangles) -> np.ndarray:
    """Smallest interior angle of each triangle, in degrees (60 at best).

    Parameters
    ----------
    vertices : (N, 2) array_like of float
        Vertex positions.
    triangles : (M, 3) array_like of int
        Vertex indices per triangle.

    Returns
    -------
    (M,) ndarray of float64
        Degrees.

    Examples
    --------
    >>> triangle_min_angles([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]).round(6)
    array([45.])
    """
    return triangle_angles(vertices, triangles).min(axis=1)


def triangle_aspect_ratios(vertices, triangles) -> np.ndarray:
    """Radius ratio ``R / (2 r)`` of each triangle: 1 when equilateral, larger when worse.

    Parameters
    ----------
    vertices : (N, 2) array_like of float
        Vertex positions.
    triangles : (M, 3) array_like of int
        Vertex indices per triangle.

    Returns
    -------
    (M,) ndarray of float64
        Dimensionless; ``inf`` for a degenerate (zero-area) triangle.

    Examples
    --------
    >>> import numpy as np
    >>> tri = [[0, 0], [1, 0], [0.5, np.sqrt(3) / 2]]
    >>> triangle_aspect_ratios(tri, [[0, 1, 2]]).round(12)
    array([1.])
    """
    lengths = triangle_edge_lengths(vertices, triangles)
    area = np.abs(triangle_signed_areas(vertices, triangles))
    a, b, c = lengths.T
    s = 0.5 * (a + b + c)
    # R = abc / (4 A), r = A / s  =>  R / (2 r) = abc s / (8 A^2)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = a * b * c * s / (8.0 * area * area)
    return np.where(area > 0, ratio, np.inf)


def degenerate_triangles(vertices, triangles) -> np.ndarray:
    """Mask of triangles whose corners are (nearly) collinear or coincide.

    Parameters
    ----------
    vertices : (N, 2) array_like of float
        Vertex positions.
    triangles : (M, 3) array_like of int
        Vertex indices per triangle.

    Returns
    -------
    (M,) ndarray of bool
        True where ``2 |area| < DEGENERATE_RELATIVE_AREA * longest_edge**2``.

    Examples
    --------
    >>> degenerate_triangles([[0, 0], [1, 0], [2, 0], [0, 1]], [[0, 1, 2], [0, 1, 3]])
    array([ True, False])
    """
    if len(triangles) == 0:
        return np.zeros(0, dtype=bool)
    longest = triangle_edge_lengths(vertices, triangles).max(axis=1)
    area2 = 2.0 * np.abs(triangle_signed_areas(vertices, triangles))
    return ~(area2 >= DEGENERATE_RELATIVE_AREA * longest * longest)

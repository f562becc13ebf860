"""Outlines at rest: how far each outline vertex is from its own outline (the self-contact
thickness it can have), and whether two bodies' outlines overlap (bodies must start apart).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def rest_clearance(x, edges, reach):
    """How far each outline vertex lies in front of the nearest other outline edge, at rest.

    Only edges it is not an end of count, and only with its foot on the edge.

    Parameters
    ----------
    x : (V, 2) float64
        Rest positions of the outline vertices (m).
    edges : (E, 2) int32
        Directed outline edges into ``x`` (the body on their left).
    reach : float
        Distances at or beyond this (m) are reported as ``inf``.

    Returns
    -------
    (V,) float64

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0, 0], [2, 0], [2, 1], [1.0, 1.0], [1.0, 0.1], [0.9, 1.0], [0, 1]], float)
    >>> e = np.array([[k, (k + 1) % 7] for k in range(7)], np.int32)  # a slit from the top
    >>> round(float(rest_clearance(x, e, 10.0)[5]), 6)   # across the slit from edge 3-4
    0.1
    """
    out = np.full(x.shape[0], np.inf)
    for p in range(x.shape[0]):
        for j in range(edges.shape[0]):
            clear_against(x, p, edges[j, 0], edges[j, 1], reach, out)
    return out


@njit(cache=True, inline="always")
def clear_against(x, p, a, b, reach, out):
    """Lower ``out[p]`` to vertex ``p``'s distance in front of the edge ``a -> b`` (the body on
    its left) if ``p`` is not one of its ends, lies within ``reach`` of its box and its foot
    falls on the edge: the one test of :func:`rest_clearance` and its grid version
    (``deforma.physics.model``)."""
    if a == p or b == p:
        return
    px, py = x[p, 0], x[p, 1]
    ax, ay, bx, by = x[a, 0], x[a, 1], x[b, 0], x[b, 1]
    if px < min(ax, bx) - reach or px > max(ax, bx) + reach or py < min(ay, by) - reach \
            or py > max(ay, by) + reach:
        return
    ex = bx - ax
    ey = by - ay
    l2 = ex * ex + ey * ey
    s = ((px - ax) * ex + (py - ay) * ey) / l2
    if s < 0.0 or s > 1.0:
        return
    d = ((px - ax) * ey - (py - ay) * ex) / math.sqrt(l2)
    if 0.0 <= d < out[p]:
        out[p] = d


@njit(cache=True)
def _segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
    d1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    d2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    d3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    d4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    return ((d1 > 0.0) != (d2 > 0.0) or d1 == 0.0 or d2 == 0.0) and \
        ((d3 > 0.0) != (d4 > 0.0) or d3 == 0.0 or d4 == 0.0) and \
        max(ax, bx) >= min(cx, dx) and max(cx, dx) >= min(ax, bx) and \
        max(ay, by) >= min(cy, dy) and max(cy, dy) >= min(ay, by)


@njit(cache=True)
def _inside_outline(px, py, x, edges):
    inside = False  # even-odd rule: holes are outlines too
    for j in range(edges.shape[0]):
        ax, ay = x[edges[j, 0], 0], x[edges[j, 0], 1]
        bx, by = x[edges[j, 1], 0], x[edges[j, 1], 1]
        if (ay > py) != (by > py):
            if px < ax + (py - ay) * (bx - ax) / (by - ay):
                inside = not inside
    return inside


@njit(cache=True)
def outlines_overlap(xa, ea, xb, eb):
    """Whether two bodies overlap: an outline segment of one touches one of the other, or a
    boundary vertex of one lies inside the other's outlines (holes excluded).

    Parameters
    ----------
    xa, xb : (N, 2) float64
        Vertex positions (m).
    ea, eb : (E, 2) int32
        Boundary edges (vertex indices).

    Examples
    --------
    >>> import numpy as np
    >>> sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    >>> e = np.array([[0, 1], [1, 2], [2, 3], [3, 0]], np.int32)
    >>> outlines_overlap(sq, e, sq + 0.5, e), outlines_overlap(sq, e, sq + 1.5, e)
    (True, False)
    >>> outlines_overlap(sq, e, 0.25 * sq + 0.3, e)   # one inside the other
    True
    """
    lo_a = np.full(2, np.inf)
    hi_a = np.full(2, -np.inf)
    lo_b = np.full(2, np.inf)
    hi_b = np.full(2, -np.inf)
    for j in range(ea.shape[0]):
        for c in range(2):
            lo_a[c] = min(lo_a[c], xa[ea[j, 0], c])
            hi_a[c] = max(hi_a[c], xa[ea[j, 0], c])
    for j in range(eb.shape[0]):
        for c in range(2):
            lo_b[c] = min(lo_b[c], xb[eb[j, 0], c])
            hi_b[c] = max(hi_b[c], xb[eb[j, 0], c])
    if lo_a[0] > hi_b[0] or lo_b[0] > hi_a[0] or lo_a[1] > hi_b[1] or lo_b[1] > hi_a[1]:
        return False
    for i in range(ea.shape[0]):
        ax, ay = xa[ea[i, 0], 0], xa[ea[i, 0], 1]
        bx, by = xa[ea[i, 1], 0], xa[ea[i, 1], 1]
        if max(ax, bx) < lo_b[0] or min(ax, bx) > hi_b[0] or max(ay, by) < lo_b[1] or min(ay, by) > hi_b[1]:
            continue
        for j in range(eb.shape[0]):
            if _segments_cross(ax, ay, bx, by, xb[eb[j, 0], 0], xb[eb[j, 0], 1], xb[eb[j, 1], 0], xb[eb[j, 1], 1]):
                return True
    # no outline touches: overlapping only if one lies inside the other, then all its vertices do
    return _inside_outline(xa[ea[0, 0], 0], xa[ea[0, 0], 1], xb, eb) or \
        _inside_outline(xb[eb[0, 0], 0], xb[eb[0, 0], 1], xa, ea)

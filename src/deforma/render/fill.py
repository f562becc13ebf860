"""Triangles that fill a polygon with holes, for drawing colliders with OpenGL.

OpenGL fills triangles only, and moderngl offers no stencil operations for an even-odd
fill, so a concave polygon with holes is cut into triangles here, by ear clipping: each
hole is first joined to the outer boundary by a bridge (a pair of coincident edges) to a
vertex it can see, which leaves one simple loop; then ears (corners whose triangle holds no
other vertex) are cut off until one triangle is left. O(n^2) in the worst case, about
10 ms for a 500-point outline: the renderer keeps the triangles while the shape only
moves (see :func:`triangles_still_fit`).

Pure NumPy: nothing here needs a GL context.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..mesh.polygons import inside_loops, segments_meet, signed_area

__all__ = ["fill_triangles", "loop_depths", "loops_area", "triangles_still_fit"]


def _cross(o, a, b) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _in_wedge(v, prev, nxt, d) -> bool:
    """Whether direction ``d`` from corner ``v`` points into the solid (left of a
    counter-clockwise loop) between its edges to ``prev`` and ``nxt``."""
    a, b = prev - v, nxt - v
    if _cross(v, nxt, prev) > 0 or (_cross(v, nxt, prev) == 0 and np.dot(a, b) < 0):  # convex (or straight)
        return (b[0] * d[1] - b[1] * d[0]) > 0 and (d[0] * a[1] - d[1] * a[0]) > 0
    return not ((a[0] * d[1] - a[1] * d[0]) >= 0 and (d[0] * b[1] - d[1] * b[0]) >= 0)


def _bridge(ring: list[int], pts: np.ndarray, hole: list[int], others: list[np.ndarray], loops) -> list[int]:
    """``ring`` (indices into ``pts``, counter-clockwise) with ``hole`` (clockwise) spliced in
    through a bridge from the hole's rightmost vertex to the nearest ring vertex it sees."""
    h = max(range(len(hole)), key=lambda k: (pts[hole[k], 0], -pts[hole[k], 1]))
    m = pts[hole[h]]
    ring_a = pts[ring]
    ring_b = pts[np.roll(ring, -1)]
    walls_a = np.concatenate([ring_a] + [o for o in others] + [pts[hole]])
    walls_b = np.concatenate([ring_b] + [np.roll(o, -1, axis=0) for o in others] + [pts[np.roll(hole, -1)]])
    order = np.argsort(np.hypot(*(ring_a - m).T), kind="stable")
    n = len(ring)
    for k in order:
        v = ring_a[k]
        if np.array_equal(v, m):
            continue
        if not _in_wedge(v, ring_a[(k - 1) % n], ring_a[(k + 1) % n], m - v):
            continue
        # no wall may touch the bridge except where it ends (walls at v or at m are allowed)
        hits = segments_meet(m, v, walls_a, walls_b)
        at_end = np.all(walls_a == v, axis=1) | np.all(walls_b == v, axis=1) \
            | np.all(walls_a == m, axis=1) | np.all(walls_b == m, axis=1)
        if np.any(hits & ~at_end):
            continue
        if not inside_loops([(m + v) / 2], loops)[0]:
            continue
        spliced = hole[h:] + hole[:h + 1]     # around the hole, back to its start
        return ring[:k + 1] + spliced + ring[k:]   # ... v, m, ..., m, v, ...
    raise ValueError("a hole could not be joined to the polygon's boundary (do the loops cross?)")


def _ear_clip(pts: np.ndarray, ring: list[int]) -> list[tuple[int, int, int]]:
    """Triangles of one counter-clockwise loop that may touch itself (bridges).

    Works on nodes (places in ``ring``), not on point indices: a bridge's ends appear twice.
    """
    n = len(ring)
    at = np.asarray(ring)
    prev = [(k - 1) % n for k in range(n)]
    nxt = [(k + 1) % n for k in range(n)]

    def corner(k) -> float:
        return _cross(pts[at[prev[k]]], pts[at[k]], pts[at[nxt[k]]])

    reflex = {k for k in range(n) if corner(k) <= 0}
    tris = []
    left = n
    i = 0
    stalled = 0
    while left > 3:
        a, c = prev[i], nxt[i]
        ear = corner(i) > 0
        if ear and reflex:
            r = np.fromiter(reflex - {a, i, c}, dtype=np.int64)
            if len(r):
                q = pts[at[r]]
                pa, pi, pc = pts[at[a]], pts[at[i]], pts[at[c]]
                # inside or on the triangle, and not a copy of one of its corners (a bridge's)
                d1 = (pi[0] - pa[0]) * (q[:, 1] - pa[1]) - (pi[1] - pa[1]) * (q[:, 0] - pa[0])
                d2 = (pc[0] - pi[0]) * (q[:, 1] - pi[1]) - (pc[1] - pi[1]) * (q[:, 0] - pi[0])
                d3 = (pa[0] - pc[0]) * (q[:, 1] - pc[1]) - (pa[1] - pc[1]) * (q[:, 0] - pc[0])
                inside = (d1 >= 0) & (d2 >= 0) & (d3 >= 0)
                same = np.all(q == pa, axis=1) | np.all(q == pi, axis=1) | np.all(q == pc, axis=1)
                ear = not np.any(inside & ~same)
        if not ear and stalled > left:
            # a whole round without an ear: only degenerate corners are left (a zero-area
            # spike or a straight run); drop a flat corner, else cut the most convex one
            ring_now = list(_walk(nxt, i, left))
            flat = [j for j in ring_now if corner(j) == 0]
            i = flat[0] if flat else max(ring_now, key=corner)
            a, c = prev[i], nxt[i]
            ear = True
        if ear:
            if corner(i) > 0:
                tris.append((int(at[a]), int(at[i]), int(at[c])))
            nxt[a], prev[c] = c, a
            reflex.discard(i)
            for j in (a, c):
                if corner(j) <= 0:
                    reflex.add(j)
                else:
                    reflex.discard(j)
            left -= 1
            i = c
            stalled = 0
        else:
            i = nxt[i]
            stalled += 1
    a, c = prev[i], nxt[i]
    if corner(i) > 0:
        tris.append((int(at[a]), int(at[i]), int(at[c])))
    return tris


def _walk(nxt, start, count):
    i = start
    for _ in range(count):
        yield i
        i = nxt[i]


def fill_triangles(loops: Sequence[np.ndarray]) -> np.ndarray:
    """Triangles that fill the region inside ``loops[0]`` and outside ``loops[1:]``.

    Inside and outside are even-odd, as :meth:`deforma.Polygon.contains` has them: a loop
    within a hole is an island, filled again.

    Parameters
    ----------
    loops : sequence of (K, 2) array_like
        The outer boundary, then the holes, each at least 3 points, not closed, of either
        orientation; they must not cross each other or themselves.

    Returns
    -------
    (M, 3) int32
        Indices into the loops' points taken in order (``np.concatenate(loops)``), each
        triangle counter-clockwise. The triangles' areas add up to the region's.

    Raises
    ------
    ValueError
        If a hole cannot be joined to the boundary (loops that cross).

    Examples
    --------
    A square with a square hole needs 8 triangles:

    >>> outer = [[0, 0], [3, 0], [3, 3], [0, 3]]
    >>> hole = [[1, 1], [2, 1], [2, 2], [1, 2]]
    >>> fill_triangles([outer, hole]).shape
    (8, 3)
    """
    loops = [np.asarray(p, dtype=np.float64).reshape(-1, 2) for p in loops]
    if not loops or len(loops[0]) < 3:
        return np.zeros((0, 3), np.int32)
    offsets = np.cumsum([0] + [len(p) for p in loops])
    pts = np.concatenate(loops)
    inside = _nesting(loops)
    depth = [sum(row) for row in inside]
    tris = []
    for k in (k for k in range(len(loops)) if depth[k] % 2 == 0):
        ring = list(range(offsets[k], offsets[k + 1]))
        if signed_area(loops[k]) < 0:
            ring.reverse()
        holes = []
        for j in range(len(loops)):
            if depth[j] == depth[k] + 1 and inside[j][k]:   # a hole right inside this loop
                h = list(range(offsets[j], offsets[j + 1]))
                if signed_area(loops[j]) > 0:
                    h.reverse()  # holes run clockwise, so the bridged ring stays one counter-clockwise loop
                holes.append(h)
        # rightmost holes first: each then sees the outer boundary or a hole joined before it
        holes.sort(key=lambda h: -pts[h, 0].max())
        for i, h in enumerate(holes):
            ring = _bridge(ring, pts, h, [pts[o] for o in holes[i + 1:]], loops)
        tris += _ear_clip(pts, ring)
    return np.asarray(tris, dtype=np.int32).reshape(-1, 3)


def _nesting(loops: Sequence[np.ndarray]) -> list[list[bool]]:
    """``[k][j]``: whether loop k lies inside loop j (k != j; loops do not cross, so one
    vertex tells)."""
    return [[j != k and inside_loops(loops[k][:1], [loops[j]])[0] for j in range(len(loops))] for k in range(len(loops))]


def loop_depths(loops: Sequence[np.ndarray]) -> list[int]:
    """How many other loops each loop lies in. Even-odd, as the colliders' inside test: a
    loop at an odd depth is a hole, one at an even depth bounds solid (the outer boundary,
    or an island in a hole)."""
    return [sum(row) for row in _nesting(loops)]


def triangles_still_fit(points: np.ndarray, triangles: np.ndarray, area: float) -> bool:
    """Whether ``triangles`` made for a shape still fill it after it moved or changed size:
    every triangle still counter-clockwise and their areas still adding up to ``area``.

    A rigid motion keeps any triangulation; resizing a convex shape keeps a fan. Checking
    is cheap, cutting ears again is not.
    """
    t = points[triangles]
    a = 0.5 * ((t[:, 1, 0] - t[:, 0, 0]) * (t[:, 2, 1] - t[:, 0, 1])
               - (t[:, 1, 1] - t[:, 0, 1]) * (t[:, 2, 0] - t[:, 0, 0]))
    return bool(len(a)) and bool(np.all(a > 0)) and abs(float(a.sum()) - area) <= 1e-6 * abs(area)


def loops_area(loops: Sequence[np.ndarray], depths: Sequence[int] | None = None) -> float:
    """Area of the solid the loops bound (either orientation; even-odd, see :func:`loop_depths`)."""
    depths = loop_depths(loops) if depths is None else depths
    return sum(abs(signed_area(np.asarray(p, np.float64))) * (-1) ** d for p, d in zip(loops, depths))

"""Independent checks that a triangulation is the Delaunay triangulation of its points.

The sign tests use Python's exact arithmetic, not deforma's predicates, so a bug in the
predicates cannot hide a bug in the triangulation: rationals (``orient_exact``,
``incircle_exact``) and, in ``check_delaunay``, the same formulas on Python integers (every
coordinate times one common power of two), which give the same signs many times faster.
"""

from __future__ import annotations

from collections import Counter
from fractions import Fraction

import numpy as np


def orient_exact(a, b, c) -> int:
    ax, ay, bx, by, cx, cy = (Fraction(float(v)) for v in (*a, *b, *c))
    d = (ax - cx) * (by - cy) - (ay - cy) * (bx - cx)
    return (d > 0) - (d < 0)


def incircle_exact(a, b, c, d) -> int:
    """+1 when d is strictly inside the circle through the CCW triangle a, b, c."""
    rows = []
    for p in (a, b, c):
        dx = Fraction(float(p[0])) - Fraction(float(d[0]))
        dy = Fraction(float(p[1])) - Fraction(float(d[1]))
        rows.append((dx, dy, dx * dx + dy * dy))
    (a1, a2, a3), (b1, b2, b3), (c1, c2, c3) = rows
    det = a1 * (b2 * c3 - b3 * c2) - a2 * (b1 * c3 - b3 * c1) + a3 * (b1 * c2 - b2 * c1)
    return (det > 0) - (det < 0)


def _as_integers(pts: np.ndarray) -> list:
    """The points as exact integer pairs: every coordinate times one power of two D.

    A double is an integer times a power of two (down to 2**-1074), so with D the largest
    denominator of the coordinates every product is an integer. Scaling all points by D > 0
    multiplies orientations and twice-areas by D**2 and incircle determinants by D**4: the
    signs, and the equality of two areas, are those of the doubles themselves.
    """
    ratios = [float(v).as_integer_ratio() for v in np.asarray(pts, dtype=np.float64).ravel().tolist()]
    if not ratios:
        return []
    big = max(d for _, d in ratios)
    flat = [n * (big // d) for n, d in ratios]
    return list(zip(flat[0::2], flat[1::2]))


def _orient_int(a, b, c) -> int:
    d = (a[0] - c[0]) * (b[1] - c[1]) - (a[1] - c[1]) * (b[0] - c[0])
    return (d > 0) - (d < 0)


def _incircle_int(a, b, c, d) -> int:
    """+1 when d is strictly inside the circle through the CCW triangle a, b, c (integers)."""
    rows = []
    for p in (a, b, c):
        dx, dy = p[0] - d[0], p[1] - d[1]
        rows.append((dx, dy, dx * dx + dy * dy))
    (a1, a2, a3), (b1, b2, b3), (c1, c2, c3) = rows
    det = a1 * (b2 * c3 - b3 * c2) - a2 * (b1 * c3 - b3 * c1) + a3 * (b1 * c2 - b2 * c1)
    return (det > 0) - (det < 0)


def edge_counts(tris: np.ndarray) -> Counter:
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    e.sort(axis=1)
    return Counter(map(tuple, e.tolist()))


def check_delaunay(points: np.ndarray, tris: np.ndarray, *, brute_force: bool | None = None):
    """Assert every property of a Delaunay triangulation over the exact convex hull.

    - int32, indices in range, every triangle counter-clockwise with positive area;
    - each edge in one or two triangles; the one-triangle edges are exactly on the hull
      (all points on or left of each) and every distinct point is a vertex;
    - the areas sum to the area inside the hull edges (no overlaps);
    - empty circles: every edge is locally Delaunay (equivalent to global emptiness), and
      for small sets every point is tested against every triangle as well.
    """
    pts = np.asarray(points, dtype=np.float64)
    assert tris.dtype == np.int32 and tris.ndim == 2 and tris.shape[1] == 3
    assert tris.min() >= 0 and tris.max() < len(pts)
    uniq = np.unique(pts, axis=0)
    # exact integers (see _as_integers): the points, then the distinct points
    P = _as_integers(np.vstack([pts, uniq]))
    U, P = P[len(pts):], P[: len(pts)]
    T = tris.tolist()
    for t in T:
        assert _orient_int(P[t[0]], P[t[1]], P[t[2]]) > 0, f"triangle {t} is not CCW"

    counts = edge_counts(tris)
    assert set(counts.values()) <= {1, 2}, "an edge is shared by more than two triangles"
    boundary = [e for e, c in counts.items() if c == 1]
    # hull edges: oriented as in their triangle, every point on or left of them
    directed = {}
    for t in T:
        for i in range(3):
            u, v = int(t[i]), int(t[(i + 1) % 3])
            directed[(min(u, v), max(u, v))] = (u, v)
    for e in boundary:
        u, v = directed[e]
        side = [_orient_int(P[u], P[v], q) for q in U]
        assert min(side) >= 0, f"boundary edge {e} is not a hull edge"

    # every distinct point is used; of duplicates, the lowest index
    used = set(np.unique(tris).tolist())
    _, first = np.unique(pts, axis=0, return_index=True)
    assert used == set(first.tolist()), "the vertices are not the distinct points (first occurrences)"

    # no overlaps: twice the triangles' areas add up exactly to twice the area inside the
    # hull edges (shoelace), both in exact integers (the same scale on both sides)
    area2 = sum(
        (P[b][0] - P[a][0]) * (P[c][1] - P[a][1]) - (P[b][1] - P[a][1]) * (P[c][0] - P[a][0])
        for a, b, c in T
    )
    hull2 = sum(P[u][0] * P[v][1] - P[v][0] * P[u][1] for u, v in (directed[e] for e in boundary))
    assert area2 == hull2, (area2, hull2)

    # local Delaunay: across every interior edge, the opposite vertex is not strictly inside
    opposite = {}
    for k, t in enumerate(T):
        for i in range(3):
            e = tuple(sorted((int(t[(i + 1) % 3]), int(t[(i + 2) % 3]))))
            opposite.setdefault(e, []).append((k, int(t[i])))
    for e, sides in opposite.items():
        if len(sides) == 2:
            (k1, o1), (k2, o2) = sides
            t = T[k1]
            assert _incircle_int(P[t[0]], P[t[1]], P[t[2]], P[o2]) <= 0, f"edge {e} is not locally Delaunay"

    if brute_force is None:
        brute_force = len(tris) * len(uniq) <= 20000
    if brute_force:
        for t in T:
            for q in U:
                assert _incircle_int(P[t[0]], P[t[1]], P[t[2]], q) <= 0, f"a point is inside {t}'s circle"


def canonical(tris: np.ndarray) -> set:
    """The set of triangles, independent of vertex rotation and row order."""
    return set(map(tuple, np.sort(tris, axis=1).tolist()))

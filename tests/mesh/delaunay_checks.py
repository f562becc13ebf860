"""Independent checks that a triangulation is the Delaunay triangulation of its points.

The sign tests use Python's exact rationals, not deforma's predicates, so a bug in the
predicates cannot hide a bug in the triangulation.
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
    for t in tris:
        assert orient_exact(pts[t[0]], pts[t[1]], pts[t[2]]) > 0, f"triangle {t} is not CCW"

    counts = edge_counts(tris)
    assert set(counts.values()) <= {1, 2}, "an edge is shared by more than two triangles"
    boundary = [e for e, c in counts.items() if c == 1]
    # hull edges: oriented as in their triangle, every point on or left of them
    directed = {}
    for t in tris:
        for i in range(3):
            u, v = int(t[i]), int(t[(i + 1) % 3])
            directed[(min(u, v), max(u, v))] = (u, v)
    uniq = np.unique(pts, axis=0)
    for e in boundary:
        u, v = directed[e]
        side = [orient_exact(pts[u], pts[v], q) for q in uniq]
        assert min(side) >= 0, f"boundary edge {e} is not a hull edge"

    # every distinct point is used; of duplicates, the lowest index
    used = set(np.unique(tris).tolist())
    _, first = np.unique(pts, axis=0, return_index=True)
    assert used == set(first.tolist()), "the vertices are not the distinct points (first occurrences)"

    # no overlaps: twice the triangles' areas add up exactly to twice the area inside the
    # hull edges (shoelace), both in exact rationals
    F = [(Fraction(float(x)), Fraction(float(y))) for x, y in pts]
    area2 = sum(
        (F[b][0] - F[a][0]) * (F[c][1] - F[a][1]) - (F[b][1] - F[a][1]) * (F[c][0] - F[a][0])
        for a, b, c in tris.tolist()
    )
    hull2 = sum(F[u][0] * F[v][1] - F[v][0] * F[u][1] for u, v in (directed[e] for e in boundary))
    assert area2 == hull2, (float(area2), float(hull2))

    # local Delaunay: across every interior edge, the opposite vertex is not strictly inside
    opposite = {}
    for k, t in enumerate(tris):
        for i in range(3):
            e = tuple(sorted((int(t[(i + 1) % 3]), int(t[(i + 2) % 3]))))
            opposite.setdefault(e, []).append((k, int(t[i])))
    for e, sides in opposite.items():
        if len(sides) == 2:
            (k1, o1), (k2, o2) = sides
            t = tris[k1]
            assert incircle_exact(pts[t[0]], pts[t[1]], pts[t[2]], pts[o2]) <= 0, f"edge {e} is not locally Delaunay"

    if brute_force is None:
        brute_force = len(tris) * len(uniq) <= 20000
    if brute_force:
        for t in tris:
            for q in uniq:
                assert incircle_exact(pts[t[0]], pts[t[1]], pts[t[2]], q) <= 0, f"a point is inside {t}'s circle"


def canonical(tris: np.ndarray) -> set:
    """The set of triangles, independent of vertex rotation and row order."""
    return set(map(tuple, np.sort(tris, axis=1).tolist()))

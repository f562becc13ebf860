"""Plain polygon geometry over NumPy arrays: shoelace areas, segment intersection, even-odd inside.

Shared by the collider shapes (:mod:`deforma.physics.colliders.shapes`, which validate and test
polygons) and the renderer's fill (:mod:`deforma.render.fill`), so that both agree on what
crosses and what is inside. Floating-point signs: exact predicates live in
:mod:`deforma.mesh.predicates`, for the triangulation, where a wrong sign breaks the mesh.
"""

from __future__ import annotations

import numpy as np

__all__ = ["inside_loops", "segments_meet", "signed_area"]


def signed_area(loop) -> float:
    """Shoelace area of a closed loop (K, 2), not repeated at its end; > 0 counter-clockwise.

    Examples
    --------
    >>> signed_area([[0, 0], [2, 0], [2, 1], [0, 1]]), signed_area([[0, 0], [0, 1], [1, 0]])
    (2.0, -0.5)
    """
    p = np.asarray(loop, dtype=np.float64)
    q = np.roll(p, -1, axis=0)
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


def segments_meet(a, b, c, d) -> np.ndarray:
    """Whether closed segments a-b and c-d cross or touch (an end on the other segment
    counts), for points of shape (..., 2) that broadcast together.

    Examples
    --------
    >>> import numpy as np
    >>> a, b = np.array([[0, 0]]), np.array([[2, 0]])
    >>> segments_meet(a, b, np.array([[1, -1], [1, 0], [3, 0]]), np.array([[1, 1], [1, 1], [4, 0]])).tolist()
    [True, True, False]
    """
    a, b, c, d = (np.asarray(v, dtype=np.float64) for v in (a, b, c, d))

    def orient(p, q, r):
        return np.sign((q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1])
                       - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0]))

    def on(o, p, q, r):  # r on p-q when collinear: within its box
        return (o == 0) & np.all((np.minimum(p, q) <= r) & (r <= np.maximum(p, q)), axis=-1)

    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    return ((o1 * o2 < 0) & (o3 * o4 < 0)) | on(o1, a, b, c) | on(o2, a, b, d) | on(o3, c, d, a) | on(o4, c, d, b)


def inside_loops(points, loops) -> np.ndarray:
    """Even-odd test of points (N, 2) against a set of loops (the outer boundary and holes,
    either orientation): (N,) bool.

    Examples
    --------
    >>> ring = [[[0, 0], [4, 0], [4, 4], [0, 4]], [[1, 1], [3, 1], [3, 3], [1, 3]]]
    >>> inside_loops([[0.5, 2], [2, 2], [5, 2]], ring).tolist()
    [True, False, False]
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    inside = np.zeros(len(pts), bool)
    px, py = pts[:, 0][:, None], pts[:, 1][:, None]
    for loop in loops:
        p = np.asarray(loop, dtype=np.float64)
        q = np.roll(p, -1, axis=0)
        ax, ay, bx, by = p[:, 0][None], p[:, 1][None], q[:, 0][None], q[:, 1][None]
        crosses = (ay > py) != (by > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            xs = ax + (py - ay) * (bx - ax) / (by - ay)
        inside ^= (np.sum(crosses & (px < xs), axis=1) % 2).astype(bool)
    return inside

"""Gas pressure inside a body: JellyCar's pressure bodies.

A body added with ``pressure=p`` (N/m: force per metre of outline, in 2D) holds a gas that
fills the area ``A`` enclosed by its outer outline and pushes on that outline with the ideal
gas law at constant temperature, ``P = p A0 / A`` (``A0`` the enclosed area at rest): each
outline edge of length ``l`` and outward normal ``n`` feels ``P l n``, half on each end. A
squashed body pushes back harder; a ring of springs, which alone would collapse, holds its
shape like a balloon.

The outer outline is the body's outline loops that run counter-clockwise (holes, which run
clockwise, are part of the gas: a hollow ring is inflated through its hole), or, for a body
without triangles, its springs when they form closed loops (each vertex on exactly two
springs). The force is applied as an impulse over each step (``v += dt f / m`` before the
integrator runs), evaluated at the start of the step: the gas is soft next to the springs,
so that is stable at any step the body is.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def outline_loops(rest_positions, boundary_edges, springs, triangles) -> np.ndarray:
    """The directed edges ``(L, 2)`` (local vertex indices, gas on the left) that hold the gas.

    Raises
    ------
    ValueError
        If the body has no closed outline: the message says what is needed.

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> ring = np.array([[0, 1], [1, 2], [2, 3], [0, 3]])  # springs, no triangles
    >>> outline_loops(square, np.zeros((0, 2), int), ring, np.zeros((0, 3), int)).tolist()
    [[0, 1], [1, 2], [2, 3], [3, 0]]
    """
    x = np.asarray(rest_positions, dtype=np.float64)
    if len(triangles):
        loops = _loops(np.asarray(boundary_edges))
    else:
        s = np.asarray(springs)
        degree = np.bincount(s.ravel(), minlength=len(x))
        if len(s) < 3 or np.any(degree[np.unique(s)] != 2):
            raise ValueError("pressure needs a closed outline: a mesh with triangles, or springs that form "
                             "closed loops (every vertex on exactly two springs)")
        # direct each spring along its loop, then turn every loop counter-clockwise
        loops = [loop if _area(x, loop) > 0 else loop[::-1, ::-1] for loop in _loops(_chain(s))]
    outer = [loop for loop in loops if _area(x, loop) > 0]
    if not outer:
        raise ValueError("pressure needs a closed outline, and this body has none")
    return np.ascontiguousarray(np.concatenate(outer), dtype=np.int32)


def _chain(springs) -> np.ndarray:
    """Springs of closed loops (each vertex on two), directed head to tail along each loop."""
    nbr = {}
    for a, b in springs:
        nbr.setdefault(int(a), []).append(int(b))
        nbr.setdefault(int(b), []).append(int(a))
    seen, edges = set(), []
    for start in nbr:
        if start in seen:
            continue
        prev, cur = -1, start
        while True:
            seen.add(cur)
            a, b = nbr[cur]
            nxt = a if a != prev else b
            edges.append((cur, nxt))
            prev, cur = cur, nxt
            if cur == start:
                break
    return np.array(edges, np.int64)


def _loops(edges) -> list:
    """Split directed edges, head to tail, into closed loops ((k, 2) arrays)."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    out = {}
    for e, a in enumerate(edges[:, 0]):
        out.setdefault(int(a), []).append(e)
    used = np.zeros(len(edges), bool)
    loops = []
    for e0 in range(len(edges)):
        if used[e0]:
            continue
        loop, e = [], e0
        while not used[e]:
            used[e] = True
            loop.append(e)
            nxt = [k for k in out.get(int(edges[e, 1]), []) if not used[k]]
            if not nxt:
                break
            e = nxt[0]
        loops.append(edges[loop])
    return loops


def _area(x, loop) -> float:
    return float(enclosed_area(x, loop[:, 0], loop[:, 1]))


@njit(cache=True)
def enclosed_area(x, edge_a, edge_b):
    """Signed area (m^2) enclosed by directed edges (shoelace; positive counter-clockwise)."""
    a = 0.0
    for e in range(edge_a.shape[0]):
        i, j = edge_a[e], edge_b[e]
        a += x[i, 0] * x[j, 1] - x[j, 0] * x[i, 1]
    return 0.5 * a


@njit(cache=True)
def pressure_kick(x, v, inv_mass, edge_a, edge_b, pressure, rest_area, dt):
    """Add ``dt f / m`` of the gas force to ``v``; returns the gas pressure ``P`` (N/m).

    The enclosed area is floored at 1% of the rest area, so a body squashed flat pushes back
    with at most 100 times its pressure rather than infinitely.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]); v = np.zeros((4, 2))
    >>> a, b = np.array([0, 1, 2, 3]), np.array([1, 2, 3, 0])
    >>> pressure_kick(x, v, np.ones(4), a, b, 2.0, 2.0, 0.5)  # at half its rest area: twice the pressure
    4.0
    >>> v[2].tolist()  # the top-right corner: 4 N/m on two half edges, outward, for 0.5 s
    [1.0, 1.0]
    """
    area = enclosed_area(x, edge_a, edge_b)
    p = pressure * rest_area / max(area, 0.01 * rest_area)
    for e in range(edge_a.shape[0]):
        i, j = edge_a[e], edge_b[e]
        # outward normal times length of a counter-clockwise edge i -> j: (dy, -dx)
        fx = 0.5 * p * (x[j, 1] - x[i, 1])
        fy = -0.5 * p * (x[j, 0] - x[i, 0])
        v[i, 0] += dt * fx * inv_mass[i]
        v[i, 1] += dt * fy * inv_mass[i]
        v[j, 0] += dt * fx * inv_mass[j]
        v[j, 1] += dt * fy * inv_mass[j]
    return p

"""The 2 x 2 block of one vertex in Vertex Block Descent: what each element kind adds to the
vertex's gradient and Hessian of the step's objective.

Backward Euler's step minimises (Chen, Ferguson, Yuksel, "Vertex Block Descent", 2024)

    G(x) = 1 / (2 h^2) |x - y|_M^2 + E(x) + D(x),

``y`` the inertial target, ``E`` the elastic energy and ``D`` the damping's dissipation
potential. Block descent moves one vertex ``i`` at a time, the others held, by one Newton
step on ``G`` restricted to ``x_i``: ``x_i -= H_i^-1 g_i`` with ``g_i = dG/dx_i`` and ``H_i``
the 2 x 2 block ``d^2 G / dx_i^2`` projected to be positive semi-definite. Vertices that share
no element move independently, so a colour of them is a Jacobi step (and a parallel loop).

Each element kind gives one element's share of a vertex's block as ``(gx, gy, hxx, hxy,
hyy)``: the gradient (N) and the symmetric Hessian block (N/m)
(:func:`~deforma.physics.elements.triangles.triangle_vertex_block`,
:func:`~deforma.physics.elements.springs.spring_vertex_block`; a kind that is not built in
through :meth:`~deforma.physics.elements.kind.ElementKind.vertex_blocks`). Here: which
elements each vertex is a corner of, and the kinds' fallback.

- a triangle (:mod:`~deforma.physics.elements.triangles`), corner ``a`` with shape-function
  gradient ``D_a``: the elastic gradient ``A P D_a`` and block ``A G_a^T (d^2 psi / dF^2) G_a``
  (``G_a`` maps the corner's two coordinates to ``vec F``), its negative eigenvalues clamped
  to zero; the damping stress ``beta R (2 mu sym(R^T Fdot) + lambda tr(R^T Fdot) I)`` of the
  rate ``Fdot = F(x - x_n) / h`` (the symplectic step's, evaluated at the end of the step),
  whose block is ``beta / h`` times the corotated linear stiffness: rigid motion is not
  damped, a mode of angular frequency ``omega`` gets the damping ratio ``beta omega / 2``;
- a spring (:mod:`~deforma.physics.elements.springs`): ``ks (L - l) u`` with block ``ks (u
  u^T + max(1 - l / L, 0) (I - u u^T))``, and the seed's damping ``kd ((v_j - v_i) . u) u``
  with ``v = (x - x_n) / h`` and block ``kd / h u u^T``.

Units: m, s, kg, N, N/m.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def incidence(items, n_vertices):
    """Which items (springs (E, 2) or triangles (T, 3)) each vertex is a corner of, as CSR:
    ``(start (N + 1,), item (K,), corner (K,))``: vertex ``v``'s are ``item[start[v]:start[v +
    1]]``, it being their corner ``corner[...]``.

    Examples
    --------
    >>> import numpy as np
    >>> start, item, corner = incidence(np.array([[0, 1], [1, 2]]), 3)
    >>> start.tolist(), item.tolist(), corner.tolist()
    ([0, 1, 3, 4], [0, 0, 1, 1], [0, 1, 0, 1])
    """
    k = items.shape[1]
    start = np.zeros(n_vertices + 1, np.int64)
    for e in range(items.shape[0]):
        for c in range(k):
            start[items[e, c] + 1] += 1
    for v in range(n_vertices):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    item = np.empty(start[-1], np.int64)
    corner = np.empty(start[-1], np.int64)
    for e in range(items.shape[0]):
        for c in range(k):
            v = items[e, c]
            item[fill[v]] = e
            corner[fill[v]] = c
            fill[v] += 1
    return start, item, corner


@njit(cache=True, inline="always")
def outer_block(x, y, i, mass_h2, grab_slot, grab_pull):
    """Vertex ``i``'s block from its inertia ``M / h^2 (x - y)`` and its grab (a zero-length
    spring of strength S to the target: ``S (x - t)``): ``(gx, gy, hxx, hxy, hyy)``. Its
    contact rows are :func:`~deforma.physics.integrators.avbd.rows.row_blocks`', added by
    the callers only where ``rs.rowed`` (a kernel that hands the rows to a helper for
    every vertex pays for the hand-over of each of their arrays)."""
    m = mass_h2[i]
    gx = m * (x[i, 0] - y[i, 0])
    gy = m * (x[i, 1] - y[i, 1])
    hxx = hyy = m
    hxy = 0.0
    s = grab_slot[i]
    if s >= 0:
        gx += grab_pull[s, 0] * x[i, 0] - grab_pull[s, 1]
        gy += grab_pull[s, 0] * x[i, 1] - grab_pull[s, 2]
        hxx += grab_pull[s, 0]
        hyy += grab_pull[s, 0]
    return gx, gy, hxx, hxy, hyy

"""Springs along mesh edges (the original's model), as pure Numba kernels.

Spring force on vertex ``i`` from ``j`` (the original's formula)::

    f_ij = ks * (|x_ij| - l_ij) * x_ij / |x_ij|  +  kd * ((v_j - v_i) . d) * d,
    x_ij = x_j - x_i,  d = x_ij / |x_ij|

and ``f_ji = -f_ij``. The symplectic step scatters one contiguous run of springs per thread
into private buffers (:func:`scatter_spring_forces`); gravity and the grab pull ``strength *
(target - x)`` are added there.

Units: m, m/s, N.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def scatter_spring_forces(x, v, spring_i, spring_j, rest, ks, kd, f):
    """Add the force (N) of every spring to both of its ends in ``f`` (N, 2).

    Examples
    --------
    >>> import numpy as np
    >>> f = np.zeros((2, 2))
    >>> scatter_spring_forces(np.array([[0., 0.], [2., 0.]]), np.zeros((2, 2)), np.array([0], np.int32),
    ...                       np.array([1], np.int32), np.ones(1), np.full(1, 10.0), np.zeros(1), f)
    >>> f.tolist()
    [[10.0, 0.0], [-10.0, 0.0]]
    """
    # Indices that Numba knows are >= 0 skip its negative-index wraparound test: the loop
    # runs over range(len) (not range(lo, hi)) and vertex ids are read as unsigned; together
    # this made the kernel 25-35% faster.
    for e in range(spring_i.shape[0]):
        a = np.uint64(spring_i[e])
        b = np.uint64(spring_j[e])
        fx, fy = spring_force(x[a, 0], x[a, 1], x[b, 0], x[b, 1], v[a, 0], v[a, 1], v[b, 0], v[b, 1],
                              rest[e], ks[e], kd[e])
        f[a, 0] += fx
        f[a, 1] += fy
        f[b, 0] -= fx
        f[b, 1] -= fy


@njit(cache=True, inline="always")
def spring_force(xi0, xi1, xj0, xj1, vi0, vi1, vj0, vj1, rest, ks, kd):
    """Force (N) on the ``i`` end of one spring; the ``j`` end feels the opposite.

    Examples
    --------
    >>> spring_force(0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 10.0, 0.0)
    (10.0, 0.0)
    """
    dx = xj0 - xi0
    dy = xj1 - xi1
    length = np.sqrt(dx * dx + dy * dy)
    if length > 0.0:
        inv = 1.0 / length  # one division, not two: 5% of the spring pass
        nx = dx * inv
        ny = dy * inv
    else:  # coincident ends have no direction; no force rather than NaN
        nx = 0.0
        ny = 0.0
    s = ks * (length - rest) + kd * ((vj0 - vi0) * nx + (vj1 - vi1) * ny)
    return s * nx, s * ny


@njit(cache=True)
def project_springs(x, x_prev, inv_mass, spring_i, spring_j, rest, ks, kd, order, lam, h):
    """One XPBD Gauss-Seidel sweep over the springs in ``order`` (Macklin et al. 2016).

    With compliance ``1 / ks`` and damping ``kd`` along each spring, multiplied through by
    ``ks h^2`` (so that ``ks = 0`` needs no special case)::

        C = |x_ij| - l,   d = x_ij / |x_ij|
        dlam = -(ks h^2 C + lam + kd h d . (dx_j - dx_i)) / ((ks h^2 + kd h)(w_i + w_j) + 1)

    with ``w = 1/m`` and ``dx = x - x_prev``; ``lam`` (E,) accumulates the multipliers of
    the substep (N s^2; zeroed by the caller at its start).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.5, 0.0]])
    >>> project_springs(x, x.copy(), np.ones(2), np.array([0], np.int32), np.array([1], np.int32), np.ones(1),
    ...                 np.full(1, 1e9), np.zeros(1), np.zeros(1, np.int64), np.zeros(1), 0.01)
    >>> round(float(x[1, 0] - x[0, 0]), 4)  # a very stiff spring snaps to its rest length
    1.0
    """
    h2 = h * h
    for q in range(order.shape[0]):
        e = order[q]
        i = np.uint64(spring_i[e])
        j = np.uint64(spring_j[e])
        wi = inv_mass[i]
        wj = inv_mass[j]
        dx = x[j, 0] - x[i, 0]
        dy = x[j, 1] - x[i, 1]
        length = np.sqrt(dx * dx + dy * dy)
        if length == 0.0:
            continue  # no direction to push along
        nx = dx / length
        ny = dy / length
        kt = ks[e] * h2
        dt = kd[e] * h
        rate = ((x[j, 0] - x_prev[j, 0]) - (x[i, 0] - x_prev[i, 0])) * nx \
            + ((x[j, 1] - x_prev[j, 1]) - (x[i, 1] - x_prev[i, 1])) * ny
        dlam = -(kt * (length - rest[e]) + lam[e] + dt * rate) / ((kt + dt) * (wi + wj) + 1.0)
        lam[e] += dlam
        x[i, 0] -= wi * nx * dlam
        x[i, 1] -= wi * ny * dlam
        x[j, 0] += wj * nx * dlam
        x[j, 1] += wj * ny * dlam

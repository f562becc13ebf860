"""Forces on the vertices: springs, gravity and the mouse pull, as pure Numba kernels.

Spring force on vertex ``i`` from ``j`` (the original's formula)::

    f_ij = ks * (|x_ij| - l_ij) * x_ij / |x_ij|  +  kd * ((v_j - v_i) . d) * d,
    x_ij = x_j - x_i,  d = x_ij / |x_ij|

and ``f_ji = -f_ij``. Total force = springs + m * g + grab pull, where the grab pull on a
held vertex is ``strength * (target - x)``.

Here springs are computed once per spring into ``fe`` (a parallel loop without conflicts)
and gathered per vertex through a CSR adjacency (again conflict-free), for code that wants
the whole force vector (``total_forces``). The symplectic Euler step instead scatters one
contiguous run of springs per thread into private buffers (see ``integrators``), which
moves fewer bytes.

Kernels take their outputs as arguments and allocate nothing. Units: m, m/s, kg, N.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .jit import serial_and_parallel


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


def _spring_forces(x, v, spring_i, spring_j, rest, ks, kd, fe):
    """Write into ``fe[e]`` the force (N) of spring ``e`` on its ``spring_i[e]`` end.

    Built twice: ``spring_forces_serial`` (one thread) and ``spring_forces_parallel`` (all
    cores); same arguments, same result.

    Parameters
    ----------
    x, v : (N, 2) float64
        Positions (m) and velocities (m/s).
    spring_i, spring_j : (E,) int32
        Spring ends.
    rest, ks, kd : (E,) float64
        Rest lengths (m), stiffness (N/m), damping (N*s/m).
    fe : (E, 2) float64
        Output.

    Examples
    --------
    >>> import numpy as np
    >>> fe = np.zeros((1, 2))
    >>> spring_forces_serial(np.array([[0., 0.], [2., 0.]]), np.zeros((2, 2)), np.array([0], np.int32),
    ...                      np.array([1], np.int32), np.ones(1), np.full(1, 10.0), np.zeros(1), fe)
    >>> fe.tolist()
    [[10.0, 0.0]]
    """
    for e in prange(spring_i.shape[0]):
        i = spring_i[e]
        j = spring_j[e]
        fx, fy = spring_force(x[i, 0], x[i, 1], x[j, 0], x[j, 1], v[i, 0], v[i, 1], v[j, 0], v[j, 1],
                              rest[e], ks[e], kd[e])
        fe[e, 0] = fx
        fe[e, 1] = fy


spring_forces_serial, spring_forces_parallel = serial_and_parallel(_spring_forces, "spring_forces")


@njit(cache=True, inline="always")
def gather_spring_force(fe, adj_ptr, adj_spring, adj_sign, i):
    """Sum (N) of the spring forces on vertex ``i`` from per-spring forces ``fe``."""
    fx = 0.0
    fy = 0.0
    for k in range(adj_ptr[i], adj_ptr[i + 1]):
        e = adj_spring[k]
        s = adj_sign[k]
        fx += s * fe[e, 0]
        fy += s * fe[e, 1]
    return fx, fy


@njit(cache=True, inline="always")
def grab_force(x0, x1, slot, grab_pull):
    """Mouse pull (N) on a vertex at ``(x0, x1)`` held through grab entry ``slot`` (-1: none).

    ``grab_pull[slot] = (S, S*tx, S*ty)`` with ``S`` the summed strength (N/m) of the grabs
    holding the vertex and ``(tx, ty)`` their strength-weighted target, so several grabs on
    one vertex add up to ``sum_k strength_k * (target_k - x)``.
    """
    if slot < 0:
        return 0.0, 0.0
    s = grab_pull[slot, 0]
    return grab_pull[slot, 1] - s * x0, grab_pull[slot, 2] - s * x1


@njit(cache=True)
def total_forces(x, v, vertex_mass, spring_i, spring_j, rest, ks, kd, adj_ptr, adj_spring, adj_sign,
                 gx, gy, grab_slot, grab_pull, fe, f):
    """Total force (N) per vertex: springs + gravity ``m*g`` + grab pull, written into ``f``.

    For integrators that want the whole force vector (and for tests); the symplectic Euler
    step fuses the same pieces into its own passes. ``fe`` (E, 2) is scratch space.

    Examples
    --------
    >>> import numpy as np
    >>> f, fe = np.zeros((2, 2)), np.zeros((1, 2))
    >>> total_forces(np.array([[0., 0.], [2., 0.]]), np.zeros((2, 2)), np.ones(2),
    ...              np.array([0], np.int32), np.array([1], np.int32), np.ones(1), np.full(1, 10.0),
    ...              np.zeros(1), np.array([0, 1, 2]), np.array([0, 0], np.int32), np.array([1.0, -1.0]),
    ...              0.0, -9.81, np.full(2, -1, np.int32), np.zeros((0, 3)), fe, f)
    >>> f.tolist()
    [[10.0, -9.81], [-10.0, -9.81]]
    """
    spring_forces_serial(x, v, spring_i, spring_j, rest, ks, kd, fe)
    for i in range(x.shape[0]):
        fx, fy = gather_spring_force(fe, adj_ptr, adj_spring, adj_sign, i)
        px, py = grab_force(x[i, 0], x[i, 1], grab_slot[i], grab_pull)
        f[i, 0] = fx + px + vertex_mass[i] * gx
        f[i, 1] = fy + py + vertex_mass[i] * gy

"""The spring force, as a pure Numba kernel.

Spring force on vertex ``i`` from ``j`` (the original's formula)::

    f_ij = ks * (|x_ij| - l_ij) * x_ij / |x_ij|  +  kd * ((v_j - v_i) . d) * d,
    x_ij = x_j - x_i,  d = x_ij / |x_ij|

and ``f_ji = -f_ij``. The integrators call it inside their own passes (the symplectic Euler
step scatters one contiguous run of springs per thread into private buffers; see
``integrators``); gravity and the grab pull ``strength * (target - x)`` are added there.

Units: m, m/s, N.
"""

from __future__ import annotations

import numpy as np
from numba import njit


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

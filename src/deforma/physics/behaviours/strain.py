"""Principal stretches: how much a triangle is stretched, and in which direction.

The deformation gradient of a triangle (:mod:`deforma.physics.elements.triangles`) factors as ``F = R
S`` (``R`` a rotation, ``S`` symmetric, the 2D polar decomposition of
:func:`~deforma.physics.elements.corotated.polar_rotation`). The eigenvalues ``s1 >= s2`` of ``S``
are the principal stretches (1 at rest; 1.1 means 10% longer along that direction; a
negative ``s2`` means the triangle is inverted) and its unit eigenvectors ``v1``, ``v2 =
perp(v1)`` the directions, in the rest shape, along which they act; ``R v1`` is the same
direction in the world. Tearing, plasticity and the stretch limit all read these.

The derivative of a principal stretch is simple: ``d s_i / dF = R v_i v_i^T`` (the singular
value's derivative ``u_i v_i^T`` with ``u_i = R v_i``), so a constraint on a stretch has the
gradient :func:`~deforma.physics.elements.triangles.vertex_gradients` turns into vertex gradients.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..elements.corotated import polar_rotation
from ..elements.triangles import deformation_gradients


@njit(cache=True, inline="always")
def principal_stretches(f00, f01, f10, f11):
    """``(s1, s2, v1x, v1y, c, s)``: principal stretches ``s1 >= s2`` of ``F``, the rest-frame
    direction ``v1`` of ``s1`` (unit) and the rotation ``R = [[c, -s], [s, c]]``.

    Examples
    --------
    >>> s1, s2, vx, vy, c, s = principal_stretches(1.0, 0.0, 0.0, 1.5)  # 50% longer along y
    >>> round(s1, 12), round(s2, 12), round(abs(vy), 12)
    (1.5, 1.0, 1.0)
    """
    c, s, _ = polar_rotation(f00, f01, f10, f11)
    a = c * f00 + s * f10  # S = R^T F (symmetric)
    b = c * f01 + s * f11
    d = -s * f01 + c * f11
    m = 0.5 * (a + d)
    h = 0.5 * (a - d)
    r = np.sqrt(h * h + b * b)
    theta = 0.5 * np.arctan2(b, h)
    return m + r, m - r, np.cos(theta), np.sin(theta), c, s


def stretch_field(x, tris, b):
    """Principal stretches ``(T, 2)`` (``s1 >= s2``) and the world direction of ``s1`` ``(T, 2)``
    of triangles ``tris`` (rest-shape inverses ``b``, (T, 4)) at positions ``x``; NumPy.

    Examples
    --------
    >>> import numpy as np
    >>> from deforma.physics.elements.triangles import rest_geometry
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    >>> bb, _ = rest_geometry(x, [[0, 1, 2]])
    >>> s, d = stretch_field(x * [2.0, 1.0], [[0, 1, 2]], bb)
    >>> s.round(12).tolist(), np.abs(d).round(12).tolist()
    ([[2.0, 1.0]], [[1.0, 0.0]])
    """
    f = deformation_gradients(x, np.asarray(tris).reshape(-1, 3), np.asarray(b).reshape(-1, 4))
    f00, f01, f10, f11 = f[:, 0, 0], f[:, 0, 1], f[:, 1, 0], f[:, 1, 1]
    c, s = f00 + f11, f10 - f01
    r = np.hypot(c, s)
    safe = np.where(r > 0, r, 1.0)
    c, s = np.where(r > 0, c / safe, 1.0), np.where(r > 0, s / safe, 0.0)
    a = c * f00 + s * f10
    bb = c * f01 + s * f11
    d = -s * f01 + c * f11
    m, h = 0.5 * (a + d), 0.5 * (a - d)
    rad = np.hypot(h, bb)
    theta = 0.5 * np.arctan2(bb, h)
    vx, vy = np.cos(theta), np.sin(theta)
    return np.stack([m + rad, m - rad], axis=1), np.stack([c * vx - s * vy, s * vx + c * vy], axis=1)


def spring_strains(x, spring_i, spring_j, rest):
    """Strain ``|x_j - x_i| / rest - 1`` (E,) of springs; NumPy.

    Examples
    --------
    >>> import numpy as np
    >>> spring_strains(np.array([[0.0, 0.0], [1.5, 0.0]]), [0], [1], np.array([1.0])).tolist()
    [0.5]
    """
    x = np.asarray(x, dtype=np.float64)
    return np.linalg.norm(x[np.asarray(spring_j)] - x[np.asarray(spring_i)], axis=1) / rest - 1.0

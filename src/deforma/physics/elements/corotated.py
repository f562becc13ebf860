"""Linear corotated elasticity of one triangle: stress, energy and XPBD constraints.

With ``F = R S`` the polar decomposition of the deformation gradient (``R`` a rotation,
``S`` symmetric), the energy density (J/m^2 of rest area) is

    psi = mu |S - I|^2 + lambda / 2 (tr S - 2)^2,

linear elasticity measured in the triangle's own rotated frame, so a rigid turn costs
nothing. Its first Piola-Kirchhoff stress is ``P = 2 mu (F - R) + lambda (tr S - 2) R``.

In 2D the polar rotation has a closed form: with ``c = F00 + F11`` and ``s = F10 - F01``,
``R = [[c, -s], [s, c]] / sqrt(c^2 + s^2)`` and ``tr S = sqrt(c^2 + s^2)``. ``R`` is a proper
rotation even for an inverted triangle (``det F < 0``): then ``S`` has a negative eigenvalue,
``|S - I|`` is large, and the stress pushes the triangle back out.

For XPBD the same energy splits into terms with positive stiffness for every admissible
Poisson ratio (``kappa = mu + lambda > 0``):

    psi = mu / 2 (C_a^2 + C_b^2) + kappa / 2 C_vol^2,
    C_a = F00 - F11,   C_b = F01 + F10,   C_vol = tr S - 2,

since ``F - (tr S / 2) R``, the part of ``F`` that is not a scaled rotation, is
``[[C_a, C_b], [C_b, -C_a]] / 2``: ``C_a`` and ``C_b`` measure shear (linear in ``F``, shared
with the Neo-Hookean model) and ``C_vol`` the change of size (gradient ``R``).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def polar_rotation(f00, f01, f10, f11):
    """``(cos, sin, tr S)`` of the rotation ``R`` of ``F = R S`` (``R = I`` for ``F = 0``).

    Examples
    --------
    >>> c, s, t = polar_rotation(0.0, -2.0, 2.0, 0.0)  # 90 degrees, scaled by 2
    >>> round(c, 9), round(s, 9), round(t, 9)
    (0.0, 1.0, 4.0)
    """
    c = f00 + f11
    s = f10 - f01
    r = np.sqrt(c * c + s * s)
    if r == 0.0:  # F with no rotational part (e.g. a triangle flattened onto a reflection)
        return 1.0, 0.0, f00 + f11
    return c / r, s / r, r


@njit(cache=True, inline="always")
def stress(f00, f01, f10, f11, mu, lam):
    """First Piola-Kirchhoff stress ``P`` (Pa, 4 entries, row-major) of deformation ``F``.

    Examples
    --------
    >>> stress(1.0, 0.0, 0.0, 1.0, 1.0, 1.0)  # at rest
    (0.0, 0.0, 0.0, 0.0)
    >>> stress(1.1, 0.0, 0.0, 1.0, 1.0, 1.0)[0]  # stretched by 10% along x: 2 mu 0.1 + lambda 0.1
    0.30000000000000027
    """
    c, s, t = polar_rotation(f00, f01, f10, f11)
    v = lam * (t - 2.0)
    return (2.0 * mu * (f00 - c) + v * c, 2.0 * mu * (f01 + s) - v * s,
            2.0 * mu * (f10 - s) + v * s, 2.0 * mu * (f11 - c) + v * c)


def energy_density(f, mu, lam):
    """Energy density (J/m^2) of deformation gradients ``f`` (T, 2, 2); vectorised NumPy.

    Examples
    --------
    >>> import numpy as np
    >>> round(float(energy_density(np.array([[[1.1, 0.0], [0.0, 1.0]]]), 1.0, 1.0)[0]), 12)  # mu 0.01 + lam/2 0.01
    0.015
    """
    c = f[:, 0, 0] + f[:, 1, 1]
    s = f[:, 1, 0] - f[:, 0, 1]
    t = np.hypot(c, s)
    safe = np.where(t > 0, t, 1.0)
    cc, ss = np.where(t > 0, c / safe, 1.0), np.where(t > 0, s / safe, 0.0)
    d = (f[:, 0, 0] - cc) ** 2 + (f[:, 0, 1] + ss) ** 2 + (f[:, 1, 0] - ss) ** 2 + (f[:, 1, 1] - cc) ** 2
    return mu * d + 0.5 * lam * (t - 2.0) ** 2


@njit(cache=True, inline="always")
def size_constraint(f00, f01, f10, f11):
    """XPBD's size constraint of ``F``: ``(C_vol, gradient (4))`` with ``C_vol = tr S - 2``
    and gradient ``R`` (stiffness ``mu + lambda`` per unit area; the shear constraints are
    :func:`~deforma.physics.elements.triangles.project_elements`'s).

    Examples
    --------
    >>> size_constraint(2.0, 0.0, 0.0, 2.0)  # a uniform scaling by 2: size +2
    (2.0, 1.0, -0.0, 0.0, 1.0)
    """
    c, s, t = polar_rotation(f00, f01, f10, f11)
    return t - 2.0, c, -s, s, c


@njit(cache=True)
def stress_derivative(f00, f01, f10, f11, mu, lam, out):
    """The energy density's Hessian in ``F`` (Pa), ``d^2 psi / dF^2`` as a 4 x 4 matrix over
    ``vec F = (F00, F01, F10, F11)``, into ``out``.

    With ``c = F00 + F11``, ``s = F10 - F01`` and ``r = |(c, s)| = tr S``, the energy is
    ``mu (|F|^2 - 2 r + 2) + lambda / 2 (r - 2)^2``; ``(c, s) = A vec F`` with ``A = [[1, 0,
    0, 1], [0, -1, 1, 0]]``, so ``dr = A^T (c, s) / r`` and ``d^2 r = A^T (I / r - (c, s)(c,
    s)^T / r^3) A``, and the Hessian is ``2 mu I + (lambda (r - 2) - 2 mu) d^2 r + lambda dr
    dr^T``. Where ``r = 0`` (no rotational part) the ``d^2 r`` term is left out.

    Examples
    --------
    >>> import numpy as np
    >>> h = np.zeros((4, 4))
    >>> stress_derivative(1.0, 0.0, 0.0, 1.0, 1.0, 0.0, h)  # at rest, lambda 0: 2 mu on the shear
    >>> np.linalg.eigvalsh(h).round(9).tolist()
    [0.0, 2.0, 2.0, 2.0]
    """
    c = f00 + f11
    s = f10 - f01
    r = np.sqrt(c * c + s * s)
    # A's rows as tuples, not arrays: this runs for every element at every vertex of every
    # sweep, and two small arrays allocated a call were a third of avbd's sweep
    a0 = (1.0, 0.0, 0.0, 1.0)
    a1 = (0.0, -1.0, 1.0, 0.0)
    for p in range(4):
        for q in range(4):
            out[p, q] = 2.0 * mu if p == q else 0.0
    if r == 0.0:
        return
    u0, u1 = c / r, s / r
    dr = (a0[0] * u0 + a1[0] * u1, a0[1] * u0 + a1[1] * u1, a0[2] * u0 + a1[2] * u1, a0[3] * u0 + a1[3] * u1)
    k = (lam * (r - 2.0) - 2.0 * mu) / r
    for p in range(4):
        for q in range(4):
            # d^2 r = A^T (I - u u^T) A / r, u = (c, s) / r
            m = a0[p] * a0[q] + a1[p] * a1[q] - dr[p] * dr[q]
            out[p, q] += k * m + lam * dr[p] * dr[q]


@njit(cache=True, inline="always")
def _hessian_entry(p, q, mu, lam, k, dr):
    """Entry ``(p, q)`` of :func:`stress_derivative`'s matrix where ``r > 0`` (the same
    arithmetic, so the same bits)."""
    a0 = (1.0, 0.0, 0.0, 1.0)
    a1 = (0.0, -1.0, 1.0, 0.0)
    m = a0[p] * a0[q] + a1[p] * a1[q] - dr[p] * dr[q]
    return (2.0 * mu if p == q else 0.0) + (k * m + lam * dr[p] * dr[q])


@njit(cache=True, inline="always")
def vertex_stiffness(f00, f01, f10, f11, mu, lam, d0, d1):
    """:func:`stress_derivative` contracted for one corner that moves: ``(k_xx, k_xy, k_yy)``
    (Pa / m^2 per unit rest area), ``K_st = sum_{c, c'} dP/dF[2 s + c, 2 t + c'] d_c d_c'``
    with ``(d0, d1)`` the corner's shape-function gradient. Only the twelve entries the
    contraction reads are formed, each by :func:`stress_derivative`'s own arithmetic, and no
    matrix is stored: the vertex sweeps run this for every element at every corner.

    Examples
    --------
    >>> import numpy as np
    >>> h = np.zeros((4, 4))
    >>> f, d = (1.1, 0.2, -0.1, 0.9), (0.3, -0.7)
    >>> stress_derivative(*f, 2.0, 3.0, h)
    >>> D = np.array([[d[0], d[1], 0, 0], [0, 0, d[0], d[1]]])
    >>> k = vertex_stiffness(*f, 2.0, 3.0, *d)
    >>> bool(np.allclose(D @ h @ D.T, [[k[0], k[1]], [k[1], k[2]]]))
    True
    """
    c = f00 + f11
    s = f10 - f01
    r = np.sqrt(c * c + s * s)
    if r == 0.0:
        tm = 2.0 * mu
        return (tm * d0 * d0 + (0.0 + 0.0) * d0 * d1 + tm * d1 * d1, 0.0 * d0 * d0 + (0.0 + 0.0) * d0 * d1
                + 0.0 * d1 * d1, tm * d0 * d0 + (0.0 + 0.0) * d0 * d1 + tm * d1 * d1)
    u0, u1 = c / r, s / r
    dr = (1.0 * u0 + 0.0 * u1, 0.0 * u0 + -1.0 * u1, 0.0 * u0 + 1.0 * u1, 1.0 * u0 + 0.0 * u1)
    k = (lam * (r - 2.0) - 2.0 * mu) / r
    kxx = (_hessian_entry(0, 0, mu, lam, k, dr) * d0 * d0
           + (_hessian_entry(0, 1, mu, lam, k, dr) + _hessian_entry(1, 0, mu, lam, k, dr)) * d0 * d1
           + _hessian_entry(1, 1, mu, lam, k, dr) * d1 * d1)
    kxy = (_hessian_entry(0, 2, mu, lam, k, dr) * d0 * d0
           + (_hessian_entry(0, 3, mu, lam, k, dr) + _hessian_entry(1, 2, mu, lam, k, dr)) * d0 * d1
           + _hessian_entry(1, 3, mu, lam, k, dr) * d1 * d1)
    kyy = (_hessian_entry(2, 2, mu, lam, k, dr) * d0 * d0
           + (_hessian_entry(2, 3, mu, lam, k, dr) + _hessian_entry(3, 2, mu, lam, k, dr)) * d0 * d1
           + _hessian_entry(3, 3, mu, lam, k, dr) * d1 * d1)
    return kxx, kxy, kyy

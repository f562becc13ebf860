"""Stable Neo-Hookean elasticity of one triangle (Smith, de Goes and Kim 2018), in 2D.

Energy density (J/m^2 of rest area), with ``J = det F`` and the 2D bulk modulus
``lambda' = lambda + mu``:

    psi = mu / 2 (|F|^2 - 2) + lambda' / 2 (J - alpha)^2 - mu^2 / (2 lambda'),
    alpha = 1 + mu / lambda'.

``alpha`` makes the rest shape stress-free (``mu F + lambda' (J - alpha) cof F = 0`` at
``F = I``), and ``lambda' = lambda + mu`` makes the energy agree with linear elasticity of
Lamé parameters ``(mu, lambda)`` for small strains (the ``J`` term's curvature shifts the
linearised ``lambda`` by ``-mu`` in 2D). The last term only puts the rest energy at zero.
Unlike the classical ``log J`` Neo-Hookean this is finite for every ``F``: a flattened or
inverted triangle (``J <= 0``) has a finite energy whose stress pushes it back out.

Stress: ``P = mu F + lambda' (J - alpha) cof F`` with ``cof F = dJ/dF =
[[F11, -F10], [-F01, F00]]``.

In 2D the energy has an exact form with two terms that vanish at rest. Since ``|F|^2 - 2 J
= (F00 - F11)^2 + (F01 + F10)^2 =: C_S^2`` (``C_S`` measures how far ``F`` is from a scaled
rotation: the shear), ``psi = mu / 2 C_S^2 + lambda' / 2 (J - 1)^2``.

XPBD (Macklin and Mueller 2021, "A Constraint-based Formulation of Stable Neo-Hookean
Materials") solves the energy's terms as constraints with compliances ``1 / mu`` and ``1 /
lambda'`` (per unit rest area). Their deviatoric constraint ``|F|`` is not zero at rest:
its multiplier must carry the rest stress, which XPBD restarts from zero every substep, and
the shear stiffness then acts only through the constraint's curvature, one substep late
(explicitly): a box at rest measured unstable with one substep at 1/60 s. The 2D form's
shear and ``C_H = J - 1`` are both zero at rest, so the rest shape carries no multiplier
and shear is resisted directly; the shear enters as its two linear parts ``C_a = F00 - F11``
and ``C_b = F01 + F10`` (``C_S^2 = C_a^2 + C_b^2``), whose projection is exact, and the three
are solved together (see :func:`~deforma.physics.elements.triangles.project_elements`): a body rests
at any step.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def bulk(mu, lam):
    """``(lambda', alpha)``: the 2D bulk modulus ``lambda + mu`` (Pa) and the rest ``J`` shift.

    Examples
    --------
    >>> bulk(1.0, 1.0)
    (2.0, 1.5)
    """
    lp = lam + mu
    return lp, 1.0 + mu / lp


@njit(cache=True, inline="always")
def stress(f00, f01, f10, f11, mu, lam):
    """First Piola-Kirchhoff stress ``P`` (Pa, 4 entries, row-major) of deformation ``F``.

    Examples
    --------
    >>> stress(1.0, 0.0, 0.0, 1.0, 1.0, 1.0)  # at rest
    (0.0, 0.0, 0.0, 0.0)
    >>> [round(p, 6) for p in stress(1.0, 0.0, 0.0, -1.0, 1.0, 1.0)]  # mirrored: pushed back
    [6.0, 0.0, 0.0, -6.0]
    """
    lp, alpha = bulk(mu, lam)
    k = lp * (f00 * f11 - f01 * f10 - alpha)
    return mu * f00 + k * f11, mu * f01 - k * f10, mu * f10 - k * f01, mu * f11 + k * f00


@njit(cache=True, inline="always")
def max_curvature(f00, f01, f10, f11, mu, lam):
    """The largest eigenvalue (Pa) of the energy's Hessian in ``F`` at ``F``: exactly ``2 (mu +
    lambda)`` at rest, larger when stretched or squashed.

    In the conformal / anti-conformal coordinates ``a = (F00 + F11) / 2``, ``b = (F10 - F01)
    / 2``, ``c = (F00 - F11) / 2``, ``d = (F01 + F10) / 2`` the energy is ``2 mu (c^2 + d^2) +
    lambda' / 2 (a^2 + b^2 - c^2 - d^2 - 1)^2``, whose Hessian splits into two tangential
    eigenvalues and one 2 x 2 radial block (halved, as ``|dF|^2 = 2 |dq|^2``).

    Examples
    --------
    >>> max_curvature(1.0, 0.0, 0.0, 1.0, 1.0, 2.0)  # 2 (mu + lambda)
    6.0
    """
    lp = lam + mu
    r2 = 0.25 * ((f00 + f11) ** 2 + (f10 - f01) ** 2)
    s2 = 0.25 * ((f00 - f11) ** 2 + (f01 + f10) ** 2)
    g = r2 - s2 - 1.0  # J - 1
    p = lp * g + 2.0 * lp * r2
    q = 2.0 * mu - lp * g + 2.0 * lp * s2
    off = 2.0 * lp * np.sqrt(r2 * s2)
    radial = 0.5 * (p + q) + np.sqrt(0.25 * (p - q) ** 2 + off * off)
    return max(radial, lp * g, 2.0 * mu - lp * g)


def energy_density(f, mu, lam):
    """Energy density (J/m^2) of deformation gradients ``f`` (T, 2, 2); vectorised NumPy.

    Examples
    --------
    >>> import numpy as np
    >>> float(energy_density(np.array([[[1.0, 0.0], [0.0, 1.0]]]), 1.0, 1.0)[0])
    0.0
    """
    # the 2D form (module docstring): exactly zero at rest, no cancellation of large terms
    j = f[:, 0, 0] * f[:, 1, 1] - f[:, 0, 1] * f[:, 1, 0]
    shear2 = (f[:, 0, 0] - f[:, 1, 1]) ** 2 + (f[:, 0, 1] + f[:, 1, 0]) ** 2
    return 0.5 * mu * shear2 + 0.5 * (lam + mu) * (j - 1.0) ** 2


@njit(cache=True, inline="always")
def size_constraint(f00, f01, f10, f11):
    """XPBD's size constraint of ``F``: ``(C_H, gradient (4))`` with ``C_H = J - 1`` and
    gradient ``cof F`` (stiffness ``lambda'`` per unit area; the shear constraints ``C_a``,
    ``C_b``, whose squares sum to ``C_S^2``, are
    :func:`~deforma.physics.elements.triangles.project_elements`'s).

    Examples
    --------
    >>> size_constraint(1.0, 0.0, 0.0, 1.0)[0]  # at rest: zero
    0.0
    >>> round(size_constraint(1.0, 0.0, 0.0, -1.0)[0], 6)  # mirrored: J - 1 = -2
    -2.0
    """
    return f00 * f11 - f01 * f10 - 1.0, f11, -f10, -f01, f00


@njit(cache=True)
def stress_derivative(f00, f01, f10, f11, mu, lam, out):
    """The energy density's Hessian in ``F`` (Pa), ``d^2 psi / dF^2`` as a 4 x 4 matrix over
    ``vec F = (F00, F01, F10, F11)``, into ``out``: ``mu I + lambda' g g^T + lambda' (J -
    alpha) H_J`` with ``g = dJ/dF = (F11, -F10, -F01, F00)`` and ``H_J`` the constant Hessian of
    ``J = F00 F11 - F01 F10`` (1 at (F00, F11), -1 at (F01, F10), and their mirrors).

    Examples
    --------
    >>> import numpy as np
    >>> h = np.zeros((4, 4))
    >>> stress_derivative(1.0, 0.0, 0.0, 1.0, 1.0, 1.0, h)
    >>> round(float(np.linalg.eigvalsh(h).max()), 9)  # 2 (mu + lambda) at rest, as max_curvature says
    4.0
    """
    lp, alpha = bulk(mu, lam)
    g0, g1, g2, g3 = f11, -f10, -f01, f00
    g = (g0, g1, g2, g3)
    k = lp * (f00 * f11 - f01 * f10 - alpha)
    for p in range(4):
        for q in range(4):
            out[p, q] = (mu if p == q else 0.0) + lp * g[p] * g[q]
    out[0, 3] += k
    out[3, 0] += k
    out[1, 2] -= k
    out[2, 1] -= k


@njit(cache=True, inline="always")
def vertex_stiffness(f00, f01, f10, f11, mu, lam, d0, d1):
    """:func:`stress_derivative` contracted for one corner that moves: ``(k_xx, k_xy, k_yy)``
    (as :func:`~deforma.physics.elements.corotated.vertex_stiffness`: the twelve entries the
    contraction reads, by :func:`stress_derivative`'s own arithmetic, and no matrix).

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
    lp, alpha = bulk(mu, lam)
    g0, g1, g2, g3 = f11, -f10, -f01, f00
    k = lp * (f00 * f11 - f01 * f10 - alpha)
    kxx = ((mu + lp * g0 * g0) * d0 * d0 + ((0.0 + lp * g0 * g1) + (0.0 + lp * g1 * g0)) * d0 * d1
           + (mu + lp * g1 * g1) * d1 * d1)
    kxy = ((0.0 + lp * g0 * g2) * d0 * d0 + ((0.0 + lp * g0 * g3 + k) + (0.0 + lp * g1 * g2 - k)) * d0 * d1
           + (0.0 + lp * g1 * g3) * d1 * d1)
    kyy = ((mu + lp * g2 * g2) * d0 * d0 + ((0.0 + lp * g2 * g3) + (0.0 + lp * g3 * g2)) * d0 * d1
           + (mu + lp * g3 * g3) * d1 * d1)
    return kxx, kxy, kyy

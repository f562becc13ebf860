"""Triangle finite elements: geometry and the passes every integrator runs over them.

A triangle ``(i, j, k)`` (counter-clockwise) maps its rest shape to its current shape by
the constant deformation gradient

    F = [x_j - x_i | x_k - x_i] B,     B = [X_j - X_i | X_k - X_i]^-1   (rest positions X),

so ``F[r, :] = sum_v x_v[r] D_v`` with shape-function gradients ``D_j = B[0, :]``, ``D_k =
B[1, :]``, ``D_i = -D_j - D_k``. An element of rest area ``A`` and energy density ``psi(F)``
puts the force ``f_v = -A P D_v`` on its vertices (``P = dpsi/dF``, from the element kind's
module: :mod:`~deforma.physics.elements.corotated`, :mod:`~deforma.physics.elements.neo_hookean`); the three
forces sum to zero, so elements keep momentum.

Damping (``beta`` seconds, per element) is a viscous stress ``beta R (2 mu E' + lambda tr(E')
I)`` with ``E' = sym(R^T dF/dt)``, the corotated linear stress of the strain rate: rigid
motion is never damped, and a mode of angular frequency ``omega`` gets the damping ratio
``beta omega / 2``.

Here: the element forces (:func:`element_forces`, used by the symplectic step), the
implicit solve's right-hand side (:func:`implicit_element_rhs`), the XPBD projection (:func:`project_elements`), and NumPy helpers
(deformation gradients, energies, the stable-step bound).

Units: m, s, kg, Pa (N/m per metre of thickness), J.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from ..material import KIND_COROTATED
from .kind import ElementKind, sweep_order
from . import corotated, neo_hookean


class TriangleArrays(NamedTuple):
    """The triangle elements as the compiled drivers read them (see the module docstring)."""

    elem: np.ndarray   # (T, 3) int32: corners, global vertex indices, counter-clockwise at rest
    b: np.ndarray      # (T, 4) float64: rest-shape inverses, row-major (1/m)
    area: np.ndarray   # (T,) float64: rest areas (m^2)
    mu: np.ndarray     # (T,) float64: Lame parameters (Pa)
    lam: np.ndarray    # (T,) float64
    beta: np.ndarray   # (T,) float64: damping (s)
    kind: np.ndarray   # (T,) int32: material.KIND_*

    @classmethod
    def empty(cls) -> "TriangleArrays":
        """No elements."""
        return cls(np.zeros((0, 3), np.int32), np.zeros((0, 4)), *(np.zeros(0),) * 4, np.zeros(0, np.int32))


def rest_geometry(x, tris):
    """Rest-shape inverses ``B`` (T, 4; row-major) and rest areas (T,) of triangles ``tris``.

    Raises
    ------
    ValueError
        If a triangle has (numerically) zero area: it has no shape to return to.

    Examples
    --------
    >>> import numpy as np
    >>> b, area = rest_geometry(np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]]), np.array([[0, 1, 2]]))
    >>> (b + 0.0).tolist(), area.tolist()  # + 0.0: no negative zeros
    ([[0.5, 0.0, 0.0, 1.0]], [1.0])
    """
    x = np.asarray(x, dtype=np.float64)
    t = np.asarray(tris, dtype=np.int64)
    e1 = x[t[:, 1]] - x[t[:, 0]]
    e2 = x[t[:, 2]] - x[t[:, 0]]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    scale = np.maximum(np.einsum("ij,ij->i", e1, e1), np.einsum("ij,ij->i", e2, e2))
    bad = np.flatnonzero(~(np.abs(det) > 1e-12 * scale))
    if len(bad):
        k = int(bad[0])
        raise ValueError(f"triangle {k} (vertices {t[k].tolist()}) has zero area: a finite-element body needs "
                         f"every triangle to enclose area (remove degenerate triangles or use the 'springs' "
                         f"material)")
    inv = 1.0 / det
    # Dm = [[e1x, e2x], [e1y, e2y]]; B = Dm^-1
    b = np.stack([e2[:, 1] * inv, -e2[:, 0] * inv, -e1[:, 1] * inv, e1[:, 0] * inv], axis=1)
    return np.ascontiguousarray(b), 0.5 * np.abs(det)


def deformation_gradients(x, tris, b):
    """Deformation gradients (T, 2, 2) of triangles ``tris`` at positions ``x`` (NumPy).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    >>> deformation_gradients(2 * x, [[0, 1, 2]], np.array([[1.0, 0.0, 0.0, 1.0]]))[0].tolist()
    [[2.0, 0.0], [0.0, 2.0]]
    """
    x = np.asarray(x, dtype=np.float64)
    t = np.asarray(tris, dtype=np.int64)
    ds = np.stack([x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]]], axis=2)  # columns: edges
    return ds @ np.asarray(b).reshape(-1, 2, 2)


def element_energy(x, tris, b, area, mu, lam, kind):
    """Elastic energy (J) of each element (T,) at positions ``x``.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    >>> b, a = rest_geometry(x, [[0, 1, 2]])
    >>> float(element_energy(x, [[0, 1, 2]], b, a, np.ones(1), np.ones(1), np.zeros(1, np.int32))[0])
    0.0
    """
    f = deformation_gradients(x, tris, b)
    kind = np.asarray(kind)
    psi = np.where(kind == KIND_COROTATED, corotated.energy_density(f, mu, lam),
                   neo_hookean.energy_density(f, mu, lam))
    return area * psi


def signed_areas(x, tris):
    """Signed areas (T,) in m^2 of triangles at positions ``x``: negative means inverted."""
    x = np.asarray(x, dtype=np.float64)
    t = np.asarray(tris, dtype=np.int64)
    e1 = x[t[:, 1]] - x[t[:, 0]]
    e2 = x[t[:, 2]] - x[t[:, 0]]
    return 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])


def max_stiffness(mu, lam):
    """Largest curvature ``2 (mu + max(lambda, 0))`` (Pa) of either energy at rest in ``F``.

    Bounds how stiff an element is: it sets the stable explicit step and the implicit
    solve's matrix weight.
    """
    return 2.0 * (mu + np.maximum(lam, 0.0))


def gradient_row_sums(tris, b, area, weight, n):
    """Per vertex, ``sum_e weight_e A_e sum_w |D_v . D_w|``: the Gershgorin row sum (N/m per
    unit ``weight``) of the elements' stiffness matrices at vertex ``v`` (n,)."""
    t = np.asarray(tris, dtype=np.int64)
    bb = np.asarray(b).reshape(-1, 2, 2)
    d = np.stack([-bb[:, 0] - bb[:, 1], bb[:, 0], bb[:, 1]], axis=1)  # (T, 3, 2): D_i, D_j, D_k
    dots = np.abs(np.einsum("tvc,twc->tvw", d, d)).sum(axis=2)  # (T, 3)
    out = np.zeros(n)
    np.add.at(out, t.ravel(), ((weight * area)[:, None] * dots).ravel())
    return out


@njit(cache=True, inline="always")
def deformation_gradient(x, i, j, k, b0, b1, b2, b3):
    """``F`` (4 entries) of one triangle."""
    e1x = x[j, 0] - x[i, 0]
    e1y = x[j, 1] - x[i, 1]
    e2x = x[k, 0] - x[i, 0]
    e2y = x[k, 1] - x[i, 1]
    return e1x * b0 + e2x * b2, e1x * b1 + e2x * b3, e1y * b0 + e2y * b2, e1y * b1 + e2y * b3


@njit(cache=True, inline="always")
def stress(kind, f00, f01, f10, f11, mu, lam):
    """The elastic stress ``P`` (4) of element kind ``kind`` at ``F``."""
    if kind == KIND_COROTATED:
        return corotated.stress(f00, f01, f10, f11, mu, lam)
    return neo_hookean.stress(f00, f01, f10, f11, mu, lam)


@njit(cache=True, inline="always")
def rate_stress(f00, f01, f10, f11, r00, r01, r10, r11, mu, lam):
    """The corotated linear stress ``R (2 mu sym(R^T G) + lambda tr(R^T G) I)`` of a rate (or
    increment) ``G`` (4 entries ``r..``) in the rotated frame of ``F``: the damping stress per
    unit ``beta``."""
    c, s, _ = corotated.polar_rotation(f00, f01, f10, f11)
    # G' = R^T G, R = [[c, -s], [s, c]]
    g00 = c * r00 + s * r10
    g01 = c * r01 + s * r11
    g10 = -s * r00 + c * r10
    g11 = -s * r01 + c * r11
    off = mu * (g01 + g10)
    tr = lam * (g00 + g11)
    q00 = 2.0 * mu * g00 + tr
    q11 = 2.0 * mu * g11 + tr
    return c * q00 - s * off, c * off - s * q11, s * q00 + c * off, s * off + c * q11


@njit(cache=True, inline="always")
def corners(elem, b, e):
    """Vertex indices (unsigned: no negative-index test) and rest-shape inverse of element ``e``."""
    return (np.uint64(elem[e, 0]), np.uint64(elem[e, 1]), np.uint64(elem[e, 2]),
            b[e, 0], b[e, 1], b[e, 2], b[e, 3])


@njit(cache=True, inline="always")
def _columns(m00, m01, m10, m11, b0, b1, b2, b3, scale):
    """``scale M B^T`` (4): the vectors ``scale M D_j`` and ``scale M D_k`` (``D_i`` is minus
    their sum). With ``M = P`` and ``scale = -A`` they are the element's forces on ``j`` and
    ``k``; with a constraint's gradient in ``F``, its gradients at ``j`` and ``k``."""
    return (scale * (m00 * b0 + m01 * b1), scale * (m10 * b0 + m11 * b1),
            scale * (m00 * b2 + m01 * b3), scale * (m10 * b2 + m11 * b3))


@njit(cache=True, inline="always")
def _scatter(f, i, j, k, fjx, fjy, fkx, fky):
    f[j, 0] += fjx
    f[j, 1] += fjy
    f[k, 0] += fkx
    f[k, 1] += fky
    f[i, 0] -= fjx + fkx
    f[i, 1] -= fjy + fky


@njit(cache=True)
def element_forces(x, v, elem, b, area, mu, lam, beta, kind, damped, f):
    """Add every element's force (N) to ``f`` (N, 2): ``-A (P + beta P_rate) D_v`` on each vertex.

    Parameters
    ----------
    x, v : (N, 2) float64
        Positions (m), velocities (m/s).
    elem : (T, 3) int32
        Triangles (global vertex indices, counter-clockwise at rest).
    b : (T, 4) float64
        Rest-shape inverses, row-major (1/m).
    area, mu, lam, beta : (T,) float64
        Rest areas (m^2), Lamé parameters (Pa), damping (s).
    kind : (T,) int32
        Element kinds (``material.KIND_*``).
    damped : bool
        Whether any ``beta`` is positive. Without damping a loop with no damping code runs:
        the damping branch alone, never taken, made the loop 1.6x slower (7.6 against 4.6 ms
        for 2e5 elements, one thread), the code size costing the compiler its registers.
    f : (N, 2) float64
        Accumulated into.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    >>> bb, a = rest_geometry(x, [[0, 1, 2]])
    >>> f = np.zeros((3, 2))
    >>> x[1, 0] = 1.1  # stretch along x
    >>> element_forces(x, np.zeros((3, 2)), np.array([[0, 1, 2]], np.int32), bb, a, np.ones(1), np.ones(1),
    ...                np.zeros(1), np.zeros(1, np.int32), False, f)
    >>> f.sum(axis=0).round(12).tolist(), bool(f[1, 0] < 0)  # no net force; the stretch pulls back
    ([0.0, 0.0], True)
    """
    if not damped:
        for e in range(elem.shape[0]):
            i, j, k, b0, b1, b2, b3 = corners(elem, b, e)
            f00, f01, f10, f11 = deformation_gradient(x, i, j, k, b0, b1, b2, b3)
            p00, p01, p10, p11 = stress(kind[e], f00, f01, f10, f11, mu[e], lam[e])
            fjx, fjy, fkx, fky = _columns(p00, p01, p10, p11, b0, b1, b2, b3, -area[e])
            _scatter(f, i, j, k, fjx, fjy, fkx, fky)
        return
    for e in range(elem.shape[0]):
        i, j, k, b0, b1, b2, b3 = corners(elem, b, e)
        f00, f01, f10, f11 = deformation_gradient(x, i, j, k, b0, b1, b2, b3)
        p00, p01, p10, p11 = stress(kind[e], f00, f01, f10, f11, mu[e], lam[e])
        r00, r01, r10, r11 = deformation_gradient(v, i, j, k, b0, b1, b2, b3)
        d00, d01, d10, d11 = rate_stress(f00, f01, f10, f11, r00, r01, r10, r11, mu[e], lam[e])
        be = beta[e]
        fjx, fjy, fkx, fky = _columns(p00 + be * d00, p01 + be * d01, p10 + be * d10, p11 + be * d11, b0, b1, b2,
                                      b3, -area[e])
        _scatter(f, i, j, k, fjx, fjy, fkx, fky)


@njit(cache=True)
def implicit_element_rhs(x, x_n, elem, b, area, mu, lam, beta, kind, weight, h, rhs):
    """Add the elements' part of the implicit solve's right-hand side to ``rhs`` (N, 2).

    Element ``e`` enters the solve as ``weight_e / 2 |F_e(x) - T_e|^2`` with the target
    ``T = F - A (h^2 P(F) + h beta P_rate(F - F_n)) / weight``: then solving with the fixed
    matrix steps the backward Euler objective along its exact gradient (for the corotated
    model, ``T`` is exactly the projective-dynamics projection: the blend of the nearest
    rotation and the nearest shape of rest area). ``weight = A (h^2 + h beta) k`` with ``k``
    the element's stiffness bound (:func:`max_stiffness`). Adds ``weight D^T T``.

    The corotated target is a projection, so the iteration lowers the objective every time
    (projective dynamics); for Neo-Hookean it is a gradient step, which the element blends
    toward the corotated projection where its curvature exceeds 1.9 times the matrix's (far
    from rest), so that it cannot overshoot.
    """
    h2 = h * h
    for e in range(elem.shape[0]):
        i, j, k, b0, b1, b2, b3 = corners(elem, b, e)
        f00, f01, f10, f11 = deformation_gradient(x, i, j, k, b0, b1, b2, b3)
        p00, p01, p10, p11 = stress(kind[e], f00, f01, f10, f11, mu[e], lam[e])
        if kind[e] != KIND_COROTATED:
            # Neo-Hookean stiffens beyond the matrix's 2 (mu + lambda) when stretched or
            # squashed; a step along its gradient then overshoots (and can run away) where its
            # curvature passes twice the matrix's. There the step blends toward the corotated
            # one, a projection, which cannot overshoot and still pulls with the full force of
            # the stretch (only shortening the step let a vertex stretched 9x over a corner
            # stay behind, held by friction). At rest and at moderate strain (curvature below
            # 1.9x) the step, and the answer, are Neo-Hookean's exactly.
            c = neo_hookean.max_curvature(f00, f01, f10, f11, mu[e], lam[e])
            bound = 1.9 * weight[e] / (area[e] * (h2 + h * beta[e]))
            if c > bound:
                s_nh = bound / c
                c00, c01, c10, c11 = corotated.stress(f00, f01, f10, f11, mu[e], lam[e])
                p00 = s_nh * p00 + (1.0 - s_nh) * c00
                p01 = s_nh * p01 + (1.0 - s_nh) * c01
                p10 = s_nh * p10 + (1.0 - s_nh) * c10
                p11 = s_nh * p11 + (1.0 - s_nh) * c11
        p00 *= h2
        p01 *= h2
        p10 *= h2
        p11 *= h2
        if beta[e] > 0.0:
            n00, n01, n10, n11 = deformation_gradient(x_n, i, j, k, b0, b1, b2, b3)
            d00, d01, d10, d11 = rate_stress(f00, f01, f10, f11, f00 - n00, f01 - n01, f10 - n10, f11 - n11,
                                             mu[e], lam[e])
            hb = h * beta[e]
            p00 += hb * d00
            p01 += hb * d01
            p10 += hb * d10
            p11 += hb * d11
        w = weight[e]
        s = area[e] / w
        t00 = w * (f00 - s * p00)
        t01 = w * (f01 - s * p01)
        t10 = w * (f10 - s * p10)
        t11 = w * (f11 - s * p11)
        # weight D_v^T T for v = j (D_j = b[0:2]), k (D_k = b[2:4]), i (minus both)
        jx, jy, kx, ky = _columns(t00, t01, t10, t11, b0, b1, b2, b3, 1.0)
        _scatter(rhs, i, j, k, jx, jy, kx, ky)


@njit(cache=True, inline="always")
def vertex_gradients(g00, g01, g10, g11, b0, b1, b2, b3):
    """Gradients at vertices ``i, j, k`` (6) of a constraint whose gradient in ``F`` is ``g``:
    ``g D_v`` with ``D_j = (b0, b1)``, ``D_k = (b2, b3)``, ``D_i = -D_j - D_k``."""
    jx, jy, kx, ky = _columns(g00, g01, g10, g11, b0, b1, b2, b3, 1.0)
    return -jx - kx, -jy - ky, jx, jy, kx, ky


@njit(cache=True, inline="always")
def weighted_dot(wi, wj, wk, a, b):
    """Inverse-mass weighted dot product of two vertex gradients (6 entries each)."""
    return wi * (a[0] * b[0] + a[1] * b[1]) + wj * (a[2] * b[2] + a[3] * b[3]) + wk * (a[4] * b[4] + a[5] * b[5])


@njit(cache=True, inline="always")
def _rate(x, x_prev, i, j, k, a):
    """``grad C . (x - x_prev)`` over the three vertices."""
    return a[0] * (x[i, 0] - x_prev[i, 0]) + a[1] * (x[i, 1] - x_prev[i, 1]) \
        + a[2] * (x[j, 0] - x_prev[j, 0]) + a[3] * (x[j, 1] - x_prev[j, 1]) \
        + a[4] * (x[k, 0] - x_prev[k, 0]) + a[5] * (x[k, 1] - x_prev[k, 1])


@njit(cache=True)
def project_elements(x, x_prev, inv_mass, elem, b, area, mu, lam, beta, kind, order, starts, sequence, lam_acc, h):
    """One Gauss-Seidel XPBD sweep over the elements, the three constraints of each solved together.

    Both models share their shear term: ``mu / 2 (C_a^2 + C_b^2)`` per unit rest area with
    ``C_a = F00 - F11`` and ``C_b = F01 + F10`` (the part of ``F`` that is not a scaled
    rotation; corotated ``mu C_dev^2`` and Neo-Hookean ``mu / 2 C_S^2`` are both this), so
    each has the two shear constraints ``C_a``, ``C_b`` (stiffness ``mu A``) and a size
    constraint (``(mu + lambda) A``): corotated ``tr S - 2``
    (:func:`~deforma.physics.elements.neo_hookean.size_constraint`), Neo-Hookean ``J - 1`` (after
    Macklin and Mueller 2021; :func:`~deforma.physics.elements.neo_hookean.size_constraint`).
    Damping ``beta`` gives each constraint ``kd = beta * stiffness``. ``order`` (T,) is the
    order of the sweep (:func:`deforma.physics.elements.kind.sweep_order`); ``lam_acc`` (T, 3) holds
    the multipliers of the substep.

    The shear constraints are linear in the positions (their gradients are constant), which
    is what keeps a sweep from adding energy. Written as one constraint, the distance
    ``|F - (tr S / 2) R|`` or ``C_S = sqrt(C_a^2 + C_b^2)`` (the same energy), it is zero at
    rest with a gradient that turns with the smallest shear, and its linearised projection
    moved vertices by more than the shear they undid: a 2500-vertex corotated sheet held
    stretched 2% by two clamps and let go (1/600 s, 4 substeps) rose from 8.8 J of strain
    energy to 27.6 J plus 2.6 J of motion and kept boiling; with the linear pair it comes to
    rest (``tests/physics/test_integrators.py``). The three are solved as one 3 x 3 system
    per element rather than one after the other, so that none undoes another's correction
    within a sweep (one sequential sweep left a hanging column's width barely contracted:
    Poisson ratio 0.09 measured instead of 0.3).
    """
    h2 = h * h
    for c in range(sequence.shape[0]):
        colour = sequence[c]
        for q in range(starts[colour], starts[colour + 1]):
            e = order[q]
            i, j, k, b0, b1, b2, b3 = corners(elem, b, e)
            a, m, lm, be = area[e], mu[e], lam[e], beta[e]
            f00, f01, f10, f11 = deformation_gradient(x, i, j, k, b0, b1, b2, b3)
            if kind[e] == KIND_COROTATED:
                c3, v00, v01, v10, v11 = corotated.size_constraint(f00, f01, f10, f11)
            else:
                c3, v00, v01, v10, v11 = neo_hookean.size_constraint(f00, f01, f10, f11)
            k1 = m * a
            k3 = (m + lm) * a
            wi, wj, wk = inv_mass[i], inv_mass[j], inv_mass[k]
            g1 = vertex_gradients(1.0, 0.0, 0.0, -1.0, b0, b1, b2, b3)  # C_a = F00 - F11
            g2 = vertex_gradients(0.0, 1.0, 1.0, 0.0, b0, b1, b2, b3)  # C_b = F01 + F10
            g3 = vertex_gradients(v00, v01, v10, v11, b0, b1, b2, b3)
            # Row n of XPBD's system, divided by s_n = (1 + beta / h) k_n h^2 (kt + dt, dt = beta
            # k h) so that the matrix is symmetric: (G + diag(1 / s)) dlam = -(kt C + lam + dt
            # rate) / s, G the inverse-mass Gram matrix of the gradients (positive definite with
            # the diagonal added, also where corners are pinned)
            s1 = (1.0 + be / h) * k1 * h2
            s3 = (1.0 + be / h) * k3 * h2
            r1 = -(k1 * h2 * (f00 - f11) + lam_acc[e, 0] + be * k1 * h * _rate(x, x_prev, i, j, k, g1)) / s1
            r2 = -(k1 * h2 * (f01 + f10) + lam_acc[e, 1] + be * k1 * h * _rate(x, x_prev, i, j, k, g2)) / s1
            r3 = -(k3 * h2 * c3 + lam_acc[e, 2] + be * k3 * h * _rate(x, x_prev, i, j, k, g3)) / s3
            p = weighted_dot(wi, wj, wk, g1, g1) + 1.0 / s1
            u = weighted_dot(wi, wj, wk, g2, g2) + 1.0 / s1
            z = weighted_dot(wi, wj, wk, g3, g3) + 1.0 / s3
            q12 = weighted_dot(wi, wj, wk, g1, g2)
            q13 = weighted_dot(wi, wj, wk, g1, g3)
            q23 = weighted_dot(wi, wj, wk, g2, g3)
            c00 = u * z - q23 * q23  # cofactors of the symmetric matrix
            c01 = q13 * q23 - q12 * z
            c02 = q12 * q23 - u * q13
            c11 = p * z - q13 * q13
            c12 = q12 * q13 - p * q23
            c22 = p * u - q12 * q12
            inv = 1.0 / (p * c00 + q12 * c01 + q13 * c02)
            dl1 = (c00 * r1 + c01 * r2 + c02 * r3) * inv
            dl2 = (c01 * r1 + c11 * r2 + c12 * r3) * inv
            dl3 = (c02 * r1 + c12 * r2 + c22 * r3) * inv
            lam_acc[e, 0] += dl1
            lam_acc[e, 1] += dl2
            lam_acc[e, 2] += dl3
            x[i, 0] += wi * (g1[0] * dl1 + g2[0] * dl2 + g3[0] * dl3)
            x[i, 1] += wi * (g1[1] * dl1 + g2[1] * dl2 + g3[1] * dl3)
            x[j, 0] += wj * (g1[2] * dl1 + g2[2] * dl2 + g3[2] * dl3)
            x[j, 1] += wj * (g1[3] * dl1 + g2[3] * dl2 + g3[3] * dl3)
            x[k, 0] += wk * (g1[4] * dl1 + g2[4] * dl2 + g3[4] * dl3)
            x[k, 1] += wk * (g1[5] * dl1 + g2[5] * dl2 + g3[5] * dl3)


@njit(cache=True)
def triangle_gradient_hessian(x, elem, b, area, mu, lam, kind, grad, hess):
    """Gradient (T, 3, 2) and Hessian blocks (T, 6, 6) of each element's energy ``A psi(F)``,
    corners ``i, j, k`` (x then y). The gradient at corner ``v`` is ``A P D_v``; the block is
    ``A G^T H_F G`` with ``H_F`` the energy density's Hessian in ``F``
    (``corotated.stress_derivative``, ``neo_hookean.stress_derivative``) projected to its
    positive part (its negative eigenvalues set to zero) and ``G`` the map from the corners'
    coordinates to ``vec F``, so the block is positive semi-definite."""
    hf = np.empty((4, 4))
    g = np.zeros((4, 6))
    for e in range(elem.shape[0]):
        i, j, k, b0, b1, b2, b3 = corners(elem, b, e)
        f00, f01, f10, f11 = deformation_gradient(x, i, j, k, b0, b1, b2, b3)
        p00, p01, p10, p11 = stress(kind[e], f00, f01, f10, f11, mu[e], lam[e])
        jx, jy, kx, ky = _columns(p00, p01, p10, p11, b0, b1, b2, b3, area[e])
        grad[e, 0, 0], grad[e, 0, 1] = -jx - kx, -jy - ky
        grad[e, 1, 0], grad[e, 1, 1] = jx, jy
        grad[e, 2, 0], grad[e, 2, 1] = kx, ky
        if kind[e] == KIND_COROTATED:
            corotated.stress_derivative(f00, f01, f10, f11, mu[e], lam[e], hf)
        else:
            neo_hookean.stress_derivative(f00, f01, f10, f11, mu[e], lam[e], hf)
        w, vec = np.linalg.eigh(hf)
        for p in range(4):
            for q in range(4):
                s = 0.0
                for m in range(4):
                    if w[m] > 0.0:
                        s += vec[p, m] * w[m] * vec[q, m]
                hf[p, q] = s
        # vec F = G (x_i, y_i, x_j, y_j, x_k, y_k): F[r, c] = sum_v x_v[r] D_v[c]
        d = ((-b0 - b2, -b1 - b3), (b0, b1), (b2, b3))
        for v in range(3):
            for r in range(2):
                for c in range(2):
                    g[2 * r + c, 2 * v + r] = d[v][c]
        for p in range(6):
            for q in range(6):
                s = 0.0
                for m in range(4):
                    for n in range(4):
                        s += g[m, p] * hf[m, n] * g[n, q]
                hess[e, p, q] = area[e] * s


@njit(cache=True, inline="always")
def shape_gradient(corner, b0, b1, b2, b3):
    """``D_a`` of corner ``corner`` (0, 1, 2 for ``i, j, k``) from the rest-shape inverse."""
    if corner == 1:
        return b0, b1
    if corner == 2:
        return b2, b3
    return -b0 - b2, -b1 - b3


@njit(cache=True, inline="always")
def psd2(hxx, hxy, hyy):
    """The symmetric 2 x 2 block ``[[hxx, hxy], [hxy, hyy]]`` with its negative eigenvalues
    set to zero."""
    tr = 0.5 * (hxx + hyy)
    d = 0.5 * (hxx - hyy)
    r = np.sqrt(d * d + hxy * hxy)
    lo = tr - r
    if lo >= 0.0:
        return hxx, hxy, hyy
    hi = tr + r
    if hi <= 0.0:
        return 0.0, 0.0, 0.0
    # only the larger eigenvalue stays: hi q q^T, q its unit eigenvector
    if r == 0.0:
        return hi, 0.0, hi
    cx, cy = d + r, hxy  # an eigenvector of hi (or (hxy, r - d) when this one is zero)
    n2 = cx * cx + cy * cy
    if n2 < 1e-300:
        cx, cy = hxy, r - d
        n2 = cx * cx + cy * cy
    return hi * cx * cx / n2, hi * cx * cy / n2, hi * cy * cy / n2


@njit(cache=True)
def triangle_vertex_block(x, x_n, e, corner, elem, b, area, mu, lam, beta, kind, inv_h):
    """Element ``e``'s share of the block of its corner ``corner``: ``(gx, gy, hxx, hxy,
    hyy)``."""
    i, j, k = elem[e, 0], elem[e, 1], elem[e, 2]
    b0, b1, b2, b3 = b[e, 0], b[e, 1], b[e, 2], b[e, 3]
    d0, d1 = shape_gradient(corner, b0, b1, b2, b3)
    f00, f01, f10, f11 = deformation_gradient(x, i, j, k, b0, b1, b2, b3)
    p00, p01, p10, p11 = stress(kind[e], f00, f01, f10, f11, mu[e], lam[e])
    a = area[e]
    gx = a * (p00 * d0 + p01 * d1)
    gy = a * (p10 * d0 + p11 * d1)
    # H[s, t] = A sum_{c, c'} dP/dF[2 s + c, 2 t + c'] d_c d_c'
    if kind[e] == KIND_COROTATED:
        kxx, kxy, kyy = corotated.vertex_stiffness(f00, f01, f10, f11, mu[e], lam[e], d0, d1)
    else:
        kxx, kxy, kyy = neo_hookean.vertex_stiffness(f00, f01, f10, f11, mu[e], lam[e], d0, d1)
    hxx, hxy, hyy = psd2(a * kxx, a * kxy, a * kyy)
    be = beta[e]
    if be > 0.0:
        # the damping stress of the rate F(x - x_n) / h, and beta / h times its linear stiffness
        q00, q01, q10, q11 = deformation_gradient(x_n, i, j, k, b0, b1, b2, b3)
        s00, s01, s10, s11 = rate_stress(f00, f01, f10, f11, (f00 - q00) * inv_h, (f01 - q01) * inv_h,
                                         (f10 - q10) * inv_h, (f11 - q11) * inv_h, mu[e], lam[e])
        gx += a * be * (s00 * d0 + s01 * d1)
        gy += a * be * (s10 * d0 + s11 * d1)
        w = a * be * inv_h
        u00, u01, _, _ = rate_stress(f00, f01, f10, f11, d0, d1, 0.0, 0.0, mu[e], lam[e])  # x moves
        v00, v01, v10, v11 = rate_stress(f00, f01, f10, f11, 0.0, 0.0, d0, d1, mu[e], lam[e])  # y moves
        hxx += w * (u00 * d0 + u01 * d1)
        hxy += w * (v00 * d0 + v01 * d1)
        hyy += w * (v10 * d0 + v11 * d1)
    return gx, gy, hxx, hxy, hyy



@njit(cache=True)
def triangle_vertex_blocks(x, x_n, elem, b, area, mu, lam, beta, kind, inv_h, g, hb):
    """Every element's share of each corner's block (:func:`triangle_vertex_block`), added
    to ``g`` (N, 2) and ``hb`` (N, 3: xx, xy, yy)."""
    for e in range(elem.shape[0]):
        for c in range(3):
            v = elem[e, c]
            gx, gy, hxx, hxy, hyy = triangle_vertex_block(x, x_n, e, c, elem, b, area, mu, lam, beta, kind, inv_h)
            g[v, 0] += gx
            g[v, 1] += gy
            hb[v, 0] += hxx
            hb[v, 1] += hxy
            hb[v, 2] += hyy


def triangle_weights(area, beta, mu, lam, h: float) -> np.ndarray:
    """Weight (kg) of each element in implicit Euler's constant matrix: ``A (h^2 + h beta) k``,
    ``k`` its stiffness bound (:func:`max_stiffness`)."""
    return area * (h * h + h * beta) * max_stiffness(mu, lam)


class TriangleKind(ElementKind):
    """The triangle elements of every body of a ``"corotated"`` or ``"neo-hookean"``
    material: a view of the Model's ``elem*`` arrays (which plasticity and a new material
    change in place).

    Examples
    --------
    >>> import deforma
    >>> w = deforma.World(material=deforma.Material("corotated", youngs_modulus=1e3, poisson_ratio=0.3,
    ...                                              density=1.0))
    >>> _ = w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]))
    >>> kind = w._model.elements[1]
    >>> kind.name, kind.n_elements, float(kind.energy(w.bodies[0].positions).sum())
    ('triangles', 1, 0.0)
    """

    name = "triangles"
    models = ("corotated", "neo-hookean")
    fused = True

    def __init__(self, model):
        # the Model's arrays (changed in place, never replaced) as the compiled drivers read
        # them; no reference to the Model itself, so that a Model is freed as soon as it is
        # dropped (a cycle would keep a torn body's old arrays until the garbage collector ran)
        self._n = model.n_vertices
        self.arrays = TriangleArrays(model.elem, model.elem_b, model.elem_area, model.elem_mu, model.elem_lambda,
                                     model.elem_damping, model.elem_kind)
        self._order = None  # XPBD's order: (elements by colour, where each colour starts)
        self._lam = None  # XPBD's multipliers, made on first use

    @property
    def vertices(self) -> np.ndarray:
        return self.arrays.elem

    def energy(self, x) -> np.ndarray:
        a = self.arrays
        return element_energy(x, a.elem, a.b, a.area, a.mu, a.lam, a.kind)

    def gradient_hessian(self, x):
        a = self.arrays
        grad, hess = np.zeros((len(a.elem), 3, 2)), np.zeros((len(a.elem), 6, 6))
        triangle_gradient_hessian(x, a.elem, a.b, a.area, a.mu, a.lam, a.kind, grad,
                                  hess)
        return grad, hess

    def forces(self, x, v, f) -> None:
        a = self.arrays
        if len(a.elem):
            element_forces(x, v, a.elem, a.b, a.area, a.mu, a.lam, a.beta,
                           a.kind, bool(a.beta.any()), f)

    def vertex_blocks(self, x, x_n, h, g, hb) -> None:
        a = self.arrays
        triangle_vertex_blocks(x, x_n, a.elem, a.b, a.area, a.mu, a.lam, a.beta, a.kind, 1.0 / h, g, hb)

    def begin_substep(self) -> None:
        if self._lam is None:
            self._lam = np.zeros((len(self.arrays.elem), 3))
        self._lam[:] = 0.0

    def project(self, x, x_prev, inv_mass, h, sequence) -> None:
        a = self.arrays
        if self._order is None:
            self._order = sweep_order(a.elem, self._n)
        project_elements(x, x_prev, inv_mass, a.elem, a.b, a.area, a.mu, a.lam,
                         a.beta, a.kind, self._order[0], self._order[1], sequence, self._lam, h)

    def matrix_weights(self, h):
        a = self.arrays
        return triangle_weights(a.area, a.beta, a.mu, a.lam, h)

    def matrix_entries(self, h, weights=None):
        """``sum_e w_e D D^T``: each element's weight times the dot products of its
        shape-function gradients, over its corners' pairs."""
        a = self.arrays
        w = self.matrix_weights(h) if weights is None else weights
        bb = a.b.reshape(-1, 2, 2)
        d = np.stack([-bb[:, 0] - bb[:, 1], bb[:, 0], bb[:, 1]], axis=1)  # (T, 3, 2): D_i, D_j, D_k
        dots = np.einsum("tvc,twc->tvw", d, d) * w[:, None, None]
        t = a.elem.astype(np.int64)
        return np.repeat(t, 3, axis=1).ravel(), np.tile(t, (1, 3)).ravel(), dots.ravel()

    def rhs(self, x, x_n, h, weights, b) -> None:
        a = self.arrays
        if len(a.elem):
            implicit_element_rhs(x, x_n, a.elem, a.b, a.area, a.mu, a.lam, a.beta,
                                 a.kind, weights, h, b)

    def stiffness_rows(self, n: int) -> np.ndarray:
        a = self.arrays
        if not len(a.elem):
            return np.zeros(n)
        return gradient_row_sums(a.elem, a.b, a.area, max_stiffness(a.mu, a.lam), n)

    def damping_rows(self, n: int) -> np.ndarray:
        a = self.arrays
        if not len(a.elem):
            return np.zeros(n)
        k = max_stiffness(a.mu, a.lam)
        return gradient_row_sums(a.elem, a.b, a.area, k * a.beta, n)

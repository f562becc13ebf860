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

from typing import NamedTuple

import numpy as np
from numba import njit

from .kind import ElementKind, sweep_order


class SpringArrays(NamedTuple):
    """The springs as the compiled drivers read them (global vertex indices; m, N/m, N*s/m)."""

    i: np.ndarray      # (E,) int32: one end
    j: np.ndarray      # (E,) int32: the other
    rest: np.ndarray   # (E,) float64: rest length
    ks: np.ndarray     # (E,) float64: stiffness
    kd: np.ndarray     # (E,) float64: damping along the spring

    @classmethod
    def empty(cls) -> "SpringArrays":
        """No springs."""
        return cls(np.zeros(0, np.int32), np.zeros(0, np.int32), np.zeros(0), np.zeros(0), np.zeros(0))


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


@njit(cache=True)
def spring_rhs(x, x_n, spring_i, spring_j, rest, wk, wd, b):
    """Add the springs' local step at the iterate ``x`` to implicit Euler's right-hand side
    ``b`` (N, 2): ``sum_e (wk_e l_e d_e + wd_e p_e) (e_j - e_i)``, with ``d_e`` the spring's
    direction and ``p_e`` its vector minus its stretch since the substep began (``x_n``),
    ``wk = h^2 ks``, ``wd = h kd`` (kg). See :mod:`deforma.physics.integrators.implicit.solver`.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [2.0, 0.0]])
    >>> b = np.zeros((2, 2))
    >>> spring_rhs(x, x, np.array([0], np.int32), np.array([1], np.int32), np.ones(1), np.ones(1), np.zeros(1), b)
    >>> b.tolist()  # the rest-length target 1 m along the spring
    [[-1.0, 0.0], [1.0, 0.0]]
    """
    for e in range(spring_i.shape[0]):
        i = np.uint64(spring_i[e])
        j = np.uint64(spring_j[e])
        dx = x[j, 0] - x[i, 0]
        dy = x[j, 1] - x[i, 1]
        length = np.sqrt(dx * dx + dy * dy)
        if length > 0.0:
            nx = dx / length
            ny = dy / length
        else:  # coincident ends: no direction, target the current (zero) vector
            nx = 0.0
            ny = 0.0
        # p_e: x_ij minus its stretch since the substep began, along d
        s = (dx - (x_n[j, 0] - x_n[i, 0])) * nx + (dy - (x_n[j, 1] - x_n[i, 1])) * ny
        tx = wk[e] * rest[e] * nx + wd[e] * (dx - s * nx)
        ty = wk[e] * rest[e] * ny + wd[e] * (dy - s * ny)
        b[i, 0] -= tx
        b[i, 1] -= ty
        b[j, 0] += tx
        b[j, 1] += ty


@njit(cache=True)
def spring_gradient_hessian(x, spring_i, spring_j, rest, ks, grad, hess):
    """Gradient (E, 2, 2) and Hessian blocks (E, 4, 4) of each spring's energy ``ks/2 (L -
    l)^2``, corners ``i`` then ``j``, x then y. The block is ``[[K, -K], [-K, K]]`` with
    ``K = ks (d d^T + max(1 - l / L, 0) (I - d d^T))``: the transverse term of a compressed
    spring (negative) is left out, so that the block is positive semi-definite."""
    for e in range(spring_i.shape[0]):
        i, j = spring_i[e], spring_j[e]
        dx = x[j, 0] - x[i, 0]
        dy = x[j, 1] - x[i, 1]
        length = np.sqrt(dx * dx + dy * dy)
        k = ks[e]
        if length > 0.0:
            nx, ny = dx / length, dy / length
            t = max(1.0 - rest[e] / length, 0.0)
        else:  # coincident ends: no direction; the stiffness along any is k, none across
            nx, ny, t = 1.0, 0.0, 0.0
        f = k * (length - rest[e])
        grad[e, 0, 0], grad[e, 0, 1] = -f * nx, -f * ny
        grad[e, 1, 0], grad[e, 1, 1] = f * nx, f * ny
        k00 = k * (nx * nx + t * (1.0 - nx * nx))
        k01 = k * (nx * ny - t * nx * ny)
        k11 = k * (ny * ny + t * (1.0 - ny * ny))
        for a in range(2):
            for c in range(2):
                sign = 1.0 if a == c else -1.0
                hess[e, 2 * a, 2 * c] = sign * k00
                hess[e, 2 * a, 2 * c + 1] = sign * k01
                hess[e, 2 * a + 1, 2 * c] = sign * k01
                hess[e, 2 * a + 1, 2 * c + 1] = sign * k11


@njit(cache=True, inline="always")
def spring_vertex_block(x, x_n, i, j, rest, ks, kd, inv_h):
    """A spring's share of the block of its end ``i`` (the other end ``j``): ``(gx, gy, hxx,
    hxy, hyy)``."""
    dx = x[j, 0] - x[i, 0]
    dy = x[j, 1] - x[i, 1]
    length = np.sqrt(dx * dx + dy * dy)
    if length > 0.0:
        ux, uy = dx / length, dy / length
        t = max(1.0 - rest / length, 0.0)
    else:  # coincident ends: no direction; the stiffness along any is ks, none across
        ux, uy, t = 1.0, 0.0, 0.0
    f = ks * (length - rest)
    # relative velocity along the spring, (v_j - v_i) . u with v = (x - x_n) / h
    rv = ((x[j, 0] - x_n[j, 0] - x[i, 0] + x_n[i, 0]) * ux + (x[j, 1] - x_n[j, 1] - x[i, 1] + x_n[i, 1]) * uy) * inv_h
    f += kd * rv
    kk = ks + kd * inv_h
    hxx = kk * ux * ux + ks * t * (1.0 - ux * ux)
    hxy = kk * ux * uy - ks * t * ux * uy
    hyy = kk * uy * uy + ks * t * (1.0 - uy * uy)
    return -f * ux, -f * uy, hxx, hxy, hyy



@njit(cache=True)
def spring_vertex_blocks(x, x_n, spring_i, spring_j, rest, ks, kd, inv_h, g, hb):
    """Every spring's share of both its ends' blocks (:func:`spring_vertex_block`), added to
    ``g`` (N, 2) and ``hb`` (N, 3: xx, xy, yy)."""
    for s in range(spring_i.shape[0]):
        for end in range(2):
            i, j = (spring_i[s], spring_j[s]) if end == 0 else (spring_j[s], spring_i[s])
            gx, gy, hxx, hxy, hyy = spring_vertex_block(x, x_n, i, j, rest[s], ks[s], kd[s], inv_h)
            g[i, 0] += gx
            g[i, 1] += gy
            hb[i, 0] += hxx
            hb[i, 1] += hxy
            hb[i, 2] += hyy


class SpringKind(ElementKind):
    """The springs of every body of the ``"springs"`` material: a view of the Model's
    ``spring_*`` arrays (which plasticity and the body parameters change in place).

    Examples
    --------
    >>> import deforma
    >>> w = deforma.World()
    >>> _ = w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]))
    >>> kind = w._model.elements[0]
    >>> kind.name, kind.n_elements, float(kind.energy(w.bodies[0].positions).sum())
    ('springs', 3, 0.0)
    """

    name = "springs"
    models = ("springs",)
    fused = True

    def __init__(self, model):
        # the Model's arrays (changed in place, never replaced) as the compiled drivers read
        # them; no reference to the Model itself, so that a Model is freed as soon as it is
        # dropped (a cycle would keep a torn body's old arrays until the garbage collector ran)
        self.arrays = SpringArrays(model.spring_i, model.spring_j, model.spring_rest_length, model.spring_stiffness,
                                   model.spring_damping)
        self._n = model.n_vertices
        self._order = None  # XPBD's sweep order, made on first use (a Model's springs never change)
        self._lam = None  # XPBD's multipliers, made on first use

    @property
    def vertices(self) -> np.ndarray:
        a = self.arrays
        return np.stack([a.i, a.j], axis=1)

    def energy(self, x) -> np.ndarray:
        a = self.arrays
        stretch = np.linalg.norm(x[a.j] - x[a.i], axis=1) - a.rest
        return 0.5 * a.ks * stretch * stretch

    def gradient_hessian(self, x):
        a = self.arrays
        grad, hess = np.zeros((len(a.i), 2, 2)), np.zeros((len(a.i), 4, 4))
        spring_gradient_hessian(x, a.i, a.j, a.rest, a.ks, grad, hess)
        return grad, hess

    def forces(self, x, v, f) -> None:
        a = self.arrays
        scatter_spring_forces(x, v, a.i, a.j, a.rest, a.ks,
                              a.kd, f)

    def vertex_blocks(self, x, x_n, h, g, hb) -> None:
        a = self.arrays
        spring_vertex_blocks(x, x_n, a.i, a.j, a.rest, a.ks, a.kd, 1.0 / h, g, hb)

    def begin_substep(self) -> None:
        if self._lam is None:
            self._lam = np.zeros(len(self.arrays.i))
        self._lam[:] = 0.0

    def project(self, x, x_prev, inv_mass, h, sequence) -> None:
        a = self.arrays
        if self._order is None:
            self._order = sweep_order(self.vertices, self._n)[0]
        project_springs(x, x_prev, inv_mass, a.i, a.j, a.rest, a.ks,
                        a.kd, self._order, self._lam, h)

    def matrix_weights(self, h):
        """``(h^2 ks, h kd)`` per spring (kg): the stretch's and the damping's weights."""
        a = self.arrays
        return h * h * a.ks, h * a.kd

    def matrix_entries(self, h, weights=None):
        """The springs' graph Laplacian weighted by ``h^2 ks + h kd``."""
        a = self.arrays
        wk, wd = self.matrix_weights(h) if weights is None else weights
        w = wk + wd
        i, j = a.i.astype(np.int64), a.j.astype(np.int64)
        return np.concatenate([i, j, i, j]), np.concatenate([i, j, j, i]), np.concatenate([w, w, -w, -w])

    def rhs(self, x, x_n, h, weights, b) -> None:
        a = self.arrays
        wk, wd = weights
        spring_rhs(x, x_n, a.i, a.j, a.rest, wk, wd, b)

    def stiffness_rows(self, n: int) -> np.ndarray:
        a = self.arrays
        # (float: bincount of no springs gives integers)
        return np.bincount(a.i, a.ks, n) + \
            np.bincount(a.j, a.ks, n).astype(np.float64)

    def damping_rows(self, n: int) -> np.ndarray:
        a = self.arrays
        return np.bincount(a.i, a.kd, n) + \
            np.bincount(a.j, a.kd, n).astype(np.float64)

"""Gas pressure inside avbd's solve: the ideal gas's energy as part of each vertex's block.

A body that holds a gas (:mod:`deforma.physics.behaviours.pressure`: pressure ``p`` at its
rest area ``A0``, ``P = p A0 / A``) has the energy ``U(A) = -p A0 ln A``, whose gradient is the
gas force ``-P dA/dx``. The enclosed area ``A = 1/2 sum_e x_a x x_b`` over the outline's
directed edges ``a -> b`` is linear in each vertex's position with the others held:

    dA/dx_i = 1/2 (y_next - y_prev, x_prev - x_next),

so a vertex's block gains the gradient ``-P dA/dx_i`` and the Hessian ``p A0 / A^2 (dA/dx_i)
(dA/dx_i)^T`` (positive semi-definite, exact), and the area moves by ``dA/dx_i . dx`` when the
vertex does. The force so acts at the end of the step, as backward Euler's elastic forces
do: a balloon landing at 1/60 s meets a gas that stiffens as it squashes, where a kick from
the step's start (the other integrators') let it squash to 0.84 of its area. As there, the area
is floored at 1 % of the rest area. Rigid motions leave ``A`` unchanged, so the whole-body
step of :mod:`~deforma.physics.integrators.avbd.solver` has no share of it. A world with gas
sweeps by the general per-colour path (``sweep_colour_given``), not the built-in sweep: the
gas's code there, even where it never ran, halved that sweep's speed for every world.

Units: m, N/m (a pressure in 2D), J per metre of depth.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

#: A step's gas as the sweeps read it: per vertex its entries into the outline edges
#: (``start`` (N + 1,), ``entry`` ``2 e + role``: role 0 the edge's first end, 1 its second),
#: the edges' ends ``a``, ``b`` and body ``body``, and per body ``load = p A0`` (N m; 0 without
#: gas), ``area`` (the current enclosed area, m^2, kept as the vertices move) and ``floor``
#: (1 % of the rest area).
GasSet = namedtuple("GasSet", ["start", "entry", "a", "b", "body", "load", "area", "floor"])


def gas_set(model) -> GasSet:
    """The Model's gas as a :class:`GasSet` (``load`` and ``area`` filled by :func:`gas_areas`
    each sweep). A Model without gas gives an empty one (no vertex has an entry)."""
    n = model.n_vertices
    a, b = model.pressure_a.astype(np.int64), model.pressure_b.astype(np.int64)
    offsets = model.body_pressure_offsets
    body = np.repeat(np.arange(len(offsets) - 1), np.diff(offsets)).astype(np.int64)
    start = np.zeros(n + 1, np.int64)
    np.add.at(start, a + 1, 1)
    np.add.at(start, b + 1, 1)
    np.cumsum(start, out=start)
    entry = np.empty(2 * len(a), np.int64)
    fill = start[:-1].copy()
    for role, ends in enumerate((a, b)):
        for e, i in enumerate(ends):
            entry[fill[i]] = 2 * e + role
            fill[i] += 1
    nb = len(offsets) - 1
    return GasSet(start, entry, a, b, body, np.zeros(nb), np.zeros(nb), 0.01 * model.body_pressure_area)


@njit(cache=True)
def gas_areas(x, gas):
    """Each gas body's enclosed area at ``x``, into ``gas.area`` (m^2)."""
    gas.area[:] = 0.0
    for e in range(gas.a.shape[0]):
        i, j = gas.a[e], gas.b[e]
        gas.area[gas.body[e]] += 0.5 * (x[i, 0] * x[j, 1] - x[j, 0] * x[i, 1])


@njit(cache=True, inline="always")
def gas_share(x, i, gas, e, role):
    """``dA/dx_i`` of outline edge ``e``'s term, vertex ``i`` being its end ``role``."""
    if role == 0:
        j = gas.b[e]
        return 0.5 * x[j, 1], -0.5 * x[j, 0]
    j = gas.a[e]
    return -0.5 * x[j, 1], 0.5 * x[j, 0]


@njit(cache=True, inline="always")
def gas_block(x, i, gas):
    """Vertex ``i``'s share of its body's gas energy: ``(gx, gy, hxx, hxy, hyy)`` (zeros off
    every gas outline). A vertex is of one body, so all its entries are of one gas."""
    if gas.start[i + 1] == gas.start[i]:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    bdy = gas.body[gas.entry[gas.start[i]] // 2]
    load = gas.load[bdy]
    if load == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0
    ax = ay = 0.0
    for p in range(gas.start[i], gas.start[i + 1]):
        sx, sy = gas_share(x, i, gas, gas.entry[p] // 2, gas.entry[p] % 2)
        ax += sx
        ay += sy
    area = max(gas.area[bdy], gas.floor[bdy])
    pressure = load / area
    k = pressure / area
    return -pressure * ax, -pressure * ay, k * ax * ax, k * ax * ay, k * ay * ay


@njit(cache=True, inline="always")
def gas_moved(x, i, gas, dx, dy):
    """Vertex ``i`` moved by ``(dx, dy)`` (the others held): every area it encloses changes by
    ``dA/dx_i . (dx, dy)`` (exact: ``A`` is linear in ``x_i``). ``x`` holds the others'
    positions."""
    for p in range(gas.start[i], gas.start[i + 1]):
        e = gas.entry[p] // 2
        sx, sy = gas_share(x, i, gas, e, gas.entry[p] % 2)
        gas.area[gas.body[e]] += sx * dx + sy * dy


__all__ = ["GasSet", "gas_areas", "gas_block", "gas_moved", "gas_set"]

"""Contact rows of Augmented Vertex Block Descent (Giles, Diaz, Yuksel, SIGGRAPH 2025): a vertex
against a collider, as an augmented-Lagrangian constraint with Coulomb friction.

A contact of vertex ``i`` with the plane ``n . p >= c`` (the collider's surface where the
vertex meets it, :func:`~deforma.physics.colliders.response.contact_planes`) is two rows:

- the normal row, gap ``C_n = n . x_i - c`` with force ``f_n = max(0, lambda_n - k_n C_n)``
  along ``n``: the vertex's block gains the gradient ``-f_n n`` and, while it pushes, the
  Hessian ``k_n n n^T``;
- the friction row, the slip ``C_t = t . (x_i - x_n - s)`` since the step began relative to
  the surface (which moved by ``s``), with force ``f_t = lambda_t - k_t C_t`` bounded by ``mu
  lambda_n`` (the normal multiplier, steadier than the force at an iterate): ``mu`` is the static coefficient while the contact sticks and the dynamic one once
  it slides. The gradient is ``-f_t t`` and, while it sticks, the Hessian ``k_t t t^T``.

After every sweep the multipliers take the rows' forces (``lambda_n = f_n``; ``lambda_t =
f_t`` clamped to ``mu lambda_n``) and a row inside its bounds stiffens by ``beta |C|`` up to ``k_max``: the
penalty ramp, so a row ends up enforced as tightly as the iterations allow while its force
is carried by ``lambda``, not by a penetration. A contact that began the step at rest on its
surface (slower than :data:`STICK_SPEED`) is bounded by ``static_friction lambda_n`` and holds
its vertex exactly while that bound allows (a block on a slope rests while ``tan a`` is below
the static coefficient); one that began it sliding is bounded by ``friction lambda_n`` (``g
(sin a - friction cos a)`` down a slope).

Rows are warm-started from the last step by a persistent id, the (vertex, collider) pair:
the same pair keeps ``lambda alpha gamma`` and ``k gamma`` (at least ``k_start``). Each row's
state lives in per-vertex arrays ``memory`` (N, 5): collider row (-1: none), ``lambda_n``,
``lambda_t``, ``k_n``, ``k_t``.

Units: m, N, N/m.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Columns of a step's contact rows (K, ROW_COLUMNS).
LAM_N, LAM_T, K_N, K_T, STICK, BOUND = 0, 1, 2, 3, 4, 5
ROW_COLUMNS = 6
#: Columns of the per-vertex warm-start memory (N, MEMORY_COLUMNS): the collider row, then the same four.
MEM_ROW = 0
MEMORY_COLUMNS = 5


#: A contact whose vertex slides slower than this over its collider's surface at the start
#: of a step (m/s) is held by static friction in the step, a faster one by dynamic friction.
STICK_SPEED = 0.01


@njit(cache=True)
def start_rows(touch, rows, count, memory, vertex_row, state, k_start, carry, soften, k_max, planes, v, h):
    """Open the step's collider rows: ``vertex_row[i]`` is vertex ``i``'s row or -1, and each
    row's multipliers and penalties come from ``memory`` when the same vertex touched the same
    collider last step (``lambda * carry``, ``k * soften``, at least ``k_start[i]``), else
    ``(0, k_start[i])``. A row sticks (static friction) for the step when its vertex's
    velocity ``v`` over the surface (which moves by ``planes[k, 5:7]`` in ``h`` s) is below
    :data:`STICK_SPEED`."""
    for k in range(count):
        i = touch[k]
        vertex_row[i] = k
        if memory[i, MEM_ROW] == rows[k]:
            state[k, LAM_N] = memory[i, 1] * carry
            state[k, LAM_T] = memory[i, 2] * carry
            state[k, K_N] = min(max(memory[i, 3] * soften, k_start[i]), k_max)
            state[k, K_T] = min(max(memory[i, 4] * soften, k_start[i]), k_max)
        else:
            state[k, LAM_N] = 0.0
            state[k, LAM_T] = 0.0
            state[k, K_N] = k_start[i]
            state[k, K_T] = k_start[i]
        # static or dynamic friction for the whole step, from how the vertex moved over the
        # surface when the step began (deciding it from the sweeps' own slip flipped a block
        # that the first sweep, with no normal force yet, let slip a little into sliding for good)
        slide = (v[i, 0] - planes[k, 5] / h) * -planes[k, 1] + (v[i, 1] - planes[k, 6] / h) * planes[k, 0]
        state[k, STICK] = 1.0 if abs(slide) <= STICK_SPEED else 0.0


@njit(cache=True)
def close_rows(touch, rows, count, memory, vertex_row, state):
    """Keep the rows' multipliers and penalties for the next step's warm start (by vertex and
    collider) and forget those of vertices that touch nothing now."""
    for k in range(count):
        vertex_row[touch[k]] = -1
    for i in range(memory.shape[0]):
        if vertex_row[i] == -1:
            memory[i, MEM_ROW] = -1.0
    for k in range(count):
        i = touch[k]
        memory[i, MEM_ROW] = rows[k]
        memory[i, 1] = state[k, LAM_N]
        memory[i, 2] = state[k, LAM_T]
        memory[i, 3] = state[k, K_N]
        memory[i, 4] = state[k, K_T]


@njit(cache=True, inline="always")
def contact_forces(x, x_n, i, planes, state, k):
    """Row ``k``'s normal and friction force at the vertex ``i``: ``(f_n, f_t, C_n, C_t, mu)``
    (friction unclamped; ``mu`` the coefficient that bounds it now)."""
    nx, ny = planes[k, 0], planes[k, 1]
    gap = x[i, 0] * nx + x[i, 1] * ny - planes[k, 2]
    fn = max(0.0, state[k, LAM_N] - state[k, K_N] * gap)
    slip = (x[i, 0] - x_n[i, 0] - planes[k, 5]) * -ny + (x[i, 1] - x_n[i, 1] - planes[k, 6]) * nx
    ft = state[k, LAM_T] - state[k, K_T] * slip
    mu = planes[k, 3] if state[k, STICK] > 0.0 else planes[k, 4]
    return fn, ft, gap, slip, mu


@njit(cache=True, inline="always")
def contact_energy(px, py, x_n, i, planes, state, k):
    """Row ``k``'s energy (J, up to a constant) with its vertex ``i`` at ``(px, py)``: the
    potential whose gradient :func:`contact_block` gives. Normal: ``f_n^2 / (2 k_n)``;
    friction: ``f_t^2 / (2 k_t)`` while ``|f_t|`` is within its bound ``B = mu lambda_n``, and
    continued linearly (slope ``B``) beyond."""
    nx, ny = planes[k, 0], planes[k, 1]
    kn, kt = state[k, K_N], state[k, K_T]
    fn = max(0.0, state[k, LAM_N] - kn * (px * nx + py * ny - planes[k, 2]))
    e = 0.5 * fn * fn / kn
    if fn <= 0.0:
        return e
    bound = state[k, BOUND]
    slip = (px - x_n[i, 0] - planes[k, 5]) * -ny + (py - x_n[i, 1] - planes[k, 6]) * nx
    ft = state[k, LAM_T] - kt * slip
    if abs(ft) <= bound:
        return e + 0.5 * ft * ft / kt
    return e + 0.5 * bound * bound / kt + bound * (abs(ft) - bound) / kt


@njit(cache=True, inline="always")
def contact_block(x, x_n, i, planes, state, k, whole):
    """Row ``k``'s share of vertex ``i``'s block: ``(gx, gy, hxx, hxy, hyy)``. With ``whole``
    the normal stiffness is in the block even where the row does not push now (for a step of
    the body as a whole, which a row that starts to push within it must bound)."""
    fn, ft, _, _, mu = contact_forces(x, x_n, i, planes, state, k)
    if fn <= 0.0:
        if not whole:
            return 0.0, 0.0, 0.0, 0.0, 0.0
        nx, ny = planes[k, 0], planes[k, 1]
        kn = state[k, K_N]
        return 0.0, 0.0, kn * nx * nx, kn * nx * ny, kn * ny * ny
    # bounded by the normal force at this iterate (for a step of the whole body, by the
    # bound frozen before it, so that the line search sees one potential)
    bound = state[k, BOUND] if whole else mu * fn
    kn, kt = state[k, K_N], state[k, K_T]
    if abs(ft) >= bound:
        # sliding: the friction force is mu f_n whatever the slip, so it adds no stiffness
        # (with k_t in the block the sweep crept along the surface: a frictionless block on
        # a slope fell at 2 % of g sin a in ten sweeps)
        ft = bound if ft > 0.0 else -bound
        kt = 0.0
    nx, ny = planes[k, 0], planes[k, 1]
    tx, ty = -ny, nx
    return (-fn * nx - ft * tx, -fn * ny - ft * ty, kn * nx * nx + kt * tx * tx, kn * nx * ny + kt * tx * ty,
            kn * ny * ny + kt * ty * ty)


@njit(cache=True)
def freeze_bounds(x, x_n, touch, planes, state, count):
    """Each row's friction bound ``mu f_n`` at the iterate ``x``, into ``state[:, BOUND]``."""
    for k in range(count):
        fn, _, _, _, mu = contact_forces(x, x_n, touch[k], planes, state, k)
        state[k, BOUND] = mu * fn


@njit(cache=True)
def update_rows(x, x_n, touch, planes, state, count, beta, k_max):
    """The dual step after a sweep: the normal multiplier takes its force (``lambda_n = max(0,
    lambda_n - k_n C_n)``), the friction multiplier its force clamped to ``mu lambda_n``, and a
    row inside its bounds stiffens by ``beta |C|`` (N/m per m of violation) up to ``k_max``."""
    for k in range(count):
        i = touch[k]
        fn, ft, gap, slip, mu = contact_forces(x, x_n, i, planes, state, k)
        state[k, LAM_N] = fn
        if fn > 0.0:
            state[k, K_N] = min(state[k, K_N] + beta * abs(gap), k_max)
        bound = mu * fn
        if abs(ft) < bound:
            state[k, LAM_T] = ft
            state[k, K_T] = min(state[k, K_T] + beta * abs(slip), k_max)
        else:
            state[k, LAM_T] = bound if ft > 0.0 else -bound

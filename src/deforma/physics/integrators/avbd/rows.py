"""Contact rows of Augmented Vertex Block Descent (Giles, Diaz, Yuksel, SIGGRAPH 2025): a vertex
against a collider, as an augmented-Lagrangian constraint with Coulomb friction.

A contact of vertex ``i`` with the plane ``n . p >= c`` (the collider's surface where the
vertex meets it, :func:`~deforma.physics.colliders.response.contact_planes`) is two rows:

- the normal row, gap ``C_n = n . x_i - c`` with force ``f_n = max(0, lambda_n - k_n C_n)``
  along ``n``: the vertex's block gains the gradient ``-f_n n`` and, while it pushes, the
  Hessian ``k_n n n^T``;
- the friction row, the slip ``C_t = t . (x_i - x_n - s)`` since the step began relative to
  the surface (which moved by ``s``), with force ``f_t = lambda_t - k_t C_t`` bounded by ``mu
  lambda_n`` (the normal force the contact ended the last step with, steadier than the
  force at an iterate; the iterate's for a contact new this step, :func:`friction_bound`): ``mu`` is the static coefficient while the contact sticks and the dynamic one once
  it slides. The gradient is ``-f_t t`` and, while it sticks, the Hessian ``k_t t t^T``.

Once a step, after the sweeps, the multipliers take the rows' forces (``lambda_n = f_n``; ``lambda_t =
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

from collections import namedtuple

import numpy as np
from numba import njit

from ...colliders.response import (
    CORNER_DYNAMIC,
    CORNER_MX,
    CORNER_MY,
    CORNER_NX,
    CORNER_NY,
    CORNER_PX,
    CORNER_PY,
    CORNER_S,
    CORNER_STATIC,
    CORNER_TARGET,
)
from ...contact.pairs import ContactImpulses
from .joints import joint_vertex_block

#: A step's contact rows as the sweeps read them: the collider rows (``vertex_row`` (N,),
#: ``planes`` (N, 7), ``rows`` (N, ROW_COLUMNS)) and the body rows (their vertices ``bidx``
#: (C, 3) and geometry ``bgeo`` (C, BODY_COLUMNS), taken from the contact stage's buffer by
#: :func:`start_body_rows`, their state ``bstate`` (C, ROW_COLUMNS), and which rows each
#: vertex takes part in, ``b_start`` (N + 1,) and ``b_entry``) and the corner rows
#: (:func:`~deforma.physics.colliders.response.corner_contacts`' ``cpairs`` and ``cf``, their
#: state ``cstate`` and incidence ``c_start``, ``c_entry``), and which vertices hold a gas
#: (``gas_start``, :class:`~deforma.physics.integrators.avbd.gas.GasSet`'s ``start``), the
#: joints on soft bodies (``jv``, ``ji``, ``jf``: the
#: :class:`~deforma.physics.integrators.avbd.joints.JointRows`' ``v``, ``ji`` and ``jf``),
#: and whether each vertex takes part in any row, holds a gas or a joint (``rowed`` (N,)
#: bool, :func:`mark_rowed`).
#: Every field is an array, and kernels hand the set to a helper only for vertices with
#: rows: Numba counts a reference to each of its arrays at every hand-over, 60 ns for these
#: fields (170 ns when it nested the contact stage's topology and buffer), which made a
#: vertex sweep of the README bunny's springs three times slower and its affine patches
#: five times.
RowSet = namedtuple("RowSet", ["vertex_row", "planes", "rows", "bidx", "bgeo", "bstate", "b_start", "b_entry",
                               "cpairs", "cf", "cstate", "c_start", "c_entry", "gas_start", "jv", "ji", "jf",
                               "rowed"])

#: Columns of a step's body-row geometry ``bgeo`` (C, BODY_COLUMNS): where on the edge, the
#: normal, the distance held, and the pair's dynamic and static friction.
BODY_S, BODY_NX, BODY_NY, BODY_TARGET, BODY_DYNAMIC, BODY_STATIC = 0, 1, 2, 3, 4, 5
BODY_COLUMNS = 6

#: Columns of a step's contact rows (K, ROW_COLUMNS). ``LAG``: the normal force the same pair
#: ended the last step with (N; -1 for a pair new this step), which bounds the friction.
LAM_N, LAM_T, K_N, K_T, STICK, BOUND, LAG = 0, 1, 2, 3, 4, 5, 6
ROW_COLUMNS = 7
#: Columns of the per-vertex warm-start memory (N, MEMORY_COLUMNS): the collider row, then the same four.
MEM_ROW = 0
MEMORY_COLUMNS = 5


#: A contact whose vertex slides slower than this over its collider's surface at the start
#: of a step (m/s) is held by static friction in the step, a faster one by dynamic friction.
STICK_SPEED = 0.01

#: A row between two soft bodies starts at this share of the softer side's start (``k_start``
#: of its collision vertex against its edge's stiffer end). As stiff as the stiffer side, a row
#: pinned its vertices to each other: a sweep moves each only a little towards the other's
#: place, the ten sweeps of a step left the rows' forces scattered by newtons about the
#: load, and the dual step, which keeps only what pushes, summed them 28 % over it (a block
#: sliding down a soft plank was braked 29 % too hard, 76 % on a stiffer plank). The load
#: is carried by the multipliers, warm-started from the step before.
BODY_PENALTY_SHARE = 0.1
#: ... but no softer than lets a row sink this far (m) in a step by the share of its load
#: its warm start does not carry over (``(1 - carry) lambda / k``): at a tenth of the softer
#: side's start, a box's corner carrying 22 N on another box's side in the resting ``pile``
#: sank 0.2 mm a step, past the fail-safe's line, and the fail-safe put it back in every step.
BODY_SINK = 1e-4


@njit(cache=True, inline="always")
def warm_start(state, k, memory, m, same, k0, carry, soften, k_max):
    """Row ``k``'s multipliers and penalties from ``memory[m]`` when it is the same pair as
    last step (``same``: ``lambda * carry``, ``k * soften``, within ``[k0, k_max]``), else ``(0,
    k0)``."""
    if same:
        state[k, LAG] = memory[m, 1]
        state[k, LAM_N] = memory[m, 1] * carry
        state[k, LAM_T] = memory[m, 2] * carry
        state[k, K_N] = min(max(memory[m, 3] * soften, k0), k_max)
        state[k, K_T] = min(max(memory[m, 4] * soften, k0), k_max)
    else:
        state[k, LAG] = -1.0
        state[k, LAM_N] = 0.0
        state[k, LAM_T] = 0.0
        state[k, K_N] = k0
        state[k, K_T] = k0


@njit(cache=True, inline="always")
def friction_bound(state, k, mu, fn):
    """Row ``k``'s friction bound in the sweeps (N): ``mu`` times the normal force its pair
    ended the last step with, or, for a pair new this step, times ``fn``, its normal force at
    the iterate. The iterate's own force swings by newtons between sweeps (a micrometre of
    gap times a penalty of 1e5-1e6 N/m): bounded by it, a block sliding down a slope at 1.1
    times its static limit gained speed at 2.16 m/s^2 with its vertices swept in one order
    and at 0.08 m/s^2 in the reverse order (2.15 is right)."""
    lag = state[k, LAG]
    return mu * (lag if lag >= 0.0 else fn)


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
        warm_start(state, k, memory, i, memory[i, MEM_ROW] == rows[k], k_start[i], carry, soften, k_max)
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
def weighted_row(w, fn, ft, kn, kt, nx, ny, bound, whole):
    """A row's share of the block of a vertex that moves its distance with weight ``w``, from
    the row's normal force ``fn``, unclamped friction ``ft`` (bounded by ``bound``) and
    penalties: ``(gx, gy, hxx, hxy, hyy)``. With ``whole`` the normal stiffness is in the
    block even where the row does not push now (for a step of the body as a whole, which a
    row that starts to push within it must bound)."""
    if fn <= 0.0:
        if not whole:
            return 0.0, 0.0, 0.0, 0.0, 0.0
        kw = w * w * kn
        return 0.0, 0.0, kw * nx * nx, kw * nx * ny, kw * ny * ny
    if abs(ft) >= bound:
        # sliding: the friction force is mu f_n whatever the slip, so it adds no stiffness
        # (with k_t in the block the sweep crept along the surface: a frictionless block on
        # a slope fell at 2 % of g sin a in ten sweeps)
        ft = bound if ft > 0.0 else -bound
        kt = 0.0
    tx, ty = -ny, nx
    ww = w * w
    return (-w * (fn * nx + ft * tx), -w * (fn * ny + ft * ty), ww * (kn * nx * nx + kt * tx * tx),
            ww * (kn * nx * ny + kt * tx * ty), ww * (kn * ny * ny + kt * ty * ty))


@njit(cache=True, inline="always")
def contact_block(x, x_n, i, planes, state, k, whole):
    """Row ``k``'s share of vertex ``i``'s block: ``(gx, gy, hxx, hxy, hyy)`` (``whole``: as
    :func:`weighted_row` takes it)."""
    fn, ft, _, _, mu = contact_forces(x, x_n, i, planes, state, k)
    # bounded by friction_bound (for a step of the whole body, by the bound frozen before
    # it, so that the line search sees one potential)
    bound = state[k, BOUND] if whole else friction_bound(state, k, mu, fn)
    return weighted_row(1.0, fn, ft, state[k, K_N], state[k, K_T], planes[k, 0], planes[k, 1], bound, whole)


@njit(cache=True)
def freeze_bounds(x, x_n, touch, planes, state, count):
    """Each row's friction bound (:func:`friction_bound`) at the iterate ``x``, into ``state[:, BOUND]``."""
    for k in range(count):
        fn, _, _, _, mu = contact_forces(x, x_n, touch[k], planes, state, k)
        state[k, BOUND] = friction_bound(state, k, mu, fn)


@njit(cache=True, inline="always")
def dual_step(state, k, fn, ft, gap, slip, mu, beta, k_max):
    """Row ``k``'s dual step from its forces at the iterate (``f_n``, unclamped ``f_t``, the
    violations ``C_n``, ``C_t`` and the friction coefficient ``mu``): the normal multiplier
    takes ``f_n``, the friction multiplier ``f_t`` clamped to ``mu f_n``, and a row inside its
    bounds stiffens by ``beta |C|`` up to ``k_max``."""
    state[k, LAM_N] = fn
    if fn > 0.0:
        state[k, K_N] = min(state[k, K_N] + beta * abs(gap), k_max)
    bound = mu * fn
    if abs(ft) < bound:
        state[k, LAM_T] = ft
        state[k, K_T] = min(state[k, K_T] + beta * abs(slip), k_max)
    else:
        state[k, LAM_T] = bound if ft > 0.0 else -bound


@njit(cache=True)
def update_rows(x, x_n, touch, planes, state, count, beta, k_max):
    """The dual step after a sweep: the normal multiplier takes its force (``lambda_n = max(0,
    lambda_n - k_n C_n)``), the friction multiplier its force clamped to ``mu lambda_n``, and a
    row inside its bounds stiffens by ``beta |C|`` (N/m per m of violation) up to ``k_max``."""
    for k in range(count):
        i = touch[k]
        fn, ft, gap, slip, mu = contact_forces(x, x_n, i, planes, state, k)
        dual_step(state, k, fn, ft, gap, slip, mu, beta, k_max)


# -- body contacts: a vertex against an outline edge of another body or its own ---------------
#
# Row c of the contact stage's buffer (:mod:`deforma.physics.contact`) holds vertex p against
# the point (1 - s) x_a + s x_b of an edge, with a normal n fixed for the step and a target
# distance: C_n = n . (x_p - (1 - s) x_a - s x_b) - target, and the slip C_t along t = (-n_y,
# n_x) of that relative point since the step began. The rows take the same forces as a
# collider's, shared by the three vertices with the weights (1, -(1 - s), -s): the pair's
# momentum is kept. Warm start by the pair (collision vertex, edge).


@njit(cache=True, inline="always")
def body_row_forces(x, x_n, ip, ia, ib, s, nx, ny, target, bgeo, state, c):
    """Body row ``c``'s normal and friction force: ``(f_n, f_t, C_n, C_t, mu)`` (friction
    unclamped; ``mu`` static or dynamic by the row's stick flag)."""
    ca = 1.0 - s
    gap = (x[ip, 0] - ca * x[ia, 0] - s * x[ib, 0]) * nx + (x[ip, 1] - ca * x[ia, 1] - s * x[ib, 1]) * ny - target
    fn = max(0.0, state[c, LAM_N] - state[c, K_N] * gap)
    rx = (x[ip, 0] - x_n[ip, 0]) - ca * (x[ia, 0] - x_n[ia, 0]) - s * (x[ib, 0] - x_n[ib, 0])
    ry = (x[ip, 1] - x_n[ip, 1]) - ca * (x[ia, 1] - x_n[ia, 1]) - s * (x[ib, 1] - x_n[ib, 1])
    slip = -rx * ny + ry * nx
    ft = state[c, LAM_T] - state[c, K_T] * slip
    m = bgeo[c, BODY_STATIC] if state[c, STICK] > 0.0 else bgeo[c, BODY_DYNAMIC]
    return fn, ft, gap, slip, m


@njit(cache=True)
def start_body_rows(topo, buf, count, memory, state, bidx, bgeo, k_start, carry, soften, k_max, v, rigid):
    """Open the step's body rows (``buf[:count]``): their vertices into ``bidx`` and their
    geometry into ``bgeo`` (:data:`RowSet`), warm-started from ``memory`` (per collision
    vertex: edge, ``lambda_n``, ``lambda_t``, ``k_n``, ``k_t``) when the same vertex met the
    same edge, or the edge next to it, last step; a row between two soft bodies at least
    :data:`BODY_PENALTY_SHARE` of the softer side's ``k_start`` (and as :data:`BODY_SINK`
    asks), any other at least its stiffest vertex's; static friction for the step when the pair's relative velocity
    along the edge was below :data:`STICK_SPEED` as it began. Where two outlines lie face to
    face each contact comes twice (a vertex of each side against the other's edge), and
    both rows keep their friction: each is bounded by its own normal force, and the normal
    load is shared between them. With friction on one side's rows only, the contact held
    with only that side's share of the load: a block on a plank on a 15 degree slope,
    static friction 0.5, slid at 1.5 m/s^2."""
    cv, ce_a, ce_b = topo.cv_vertex, topo.ce_a, topo.ce_b
    # a vertex that slid onto the next edge of the same outline keeps its row's warm start:
    # the contact goes on. (Begun again from nothing at every edge it crossed, a block
    # sliding at 2 m/s, half an edge a step, met the plank with rows that carried no load
    # yet, sank into it and was braked by the rows that did.) One row per vertex inherits:
    # the same edge's if it has one, else the first neighbouring edge's.
    claimed = np.zeros(memory.shape[0], np.bool_)
    for c in range(count):
        if memory[buf.vertex[c], MEM_ROW] == buf.edge[c]:
            claimed[buf.vertex[c]] = True
    for c in range(count):
        q, e = buf.vertex[c], buf.edge[c]
        ip, ia, ib = cv[q], cv[ce_a[e]], cv[ce_b[e]]
        soft_pair = not (rigid[ip] or rigid[ia] or rigid[ib] or topo.cv_body[q] == topo.ce_body[e])
        if not soft_pair:
            # a rigid vertex's own start is its share of the body's inertia, not what holds
            # it (that is :func:`start_rigid_rows`' business): the soft side's start; and a
            # body against itself (an ear folded onto a head) has one material on both sides
            k0 = max(k_start[ip], k_start[ia], k_start[ib])
        else:
            k0 = BODY_PENALTY_SHARE * min(k_start[ip], max(k_start[ia], k_start[ib]))
        m = int(memory[q, MEM_ROW])
        same = m == e
        if not same and m >= 0 and not claimed[q] and (ce_a[m] == ce_a[e] or ce_a[m] == ce_b[e]
                                                        or ce_b[m] == ce_a[e] or ce_b[m] == ce_b[e]):
            same = claimed[q] = True
        warm_start(state, c, memory, q, same, k0, carry, soften, k_max)
        if same and soft_pair:  # (see BODY_SINK)
            state[c, K_N] = min(max(state[c, K_N], (1.0 - carry) * state[c, LAG] / BODY_SINK), k_max)
        s = buf.s[c]
        nx, ny = buf.normal[c, 0], buf.normal[c, 1]
        bidx[c, 0], bidx[c, 1], bidx[c, 2] = ip, ia, ib
        bgeo[c, BODY_S], bgeo[c, BODY_NX], bgeo[c, BODY_NY], bgeo[c, BODY_TARGET] = s, nx, ny, buf.target[c]
        bgeo[c, BODY_DYNAMIC], bgeo[c, BODY_STATIC] = buf.mu[c, 0], buf.mu[c, 1]
        rvx = v[ip, 0] - (1.0 - s) * v[ia, 0] - s * v[ib, 0]
        rvy = v[ip, 1] - (1.0 - s) * v[ia, 1] - s * v[ib, 1]
        state[c, STICK] = 1.0 if abs(-rvx * ny + rvy * nx) <= STICK_SPEED else 0.0


@njit(cache=True)
def close_body_rows(buf, count, memory, state):
    """Keep the body rows' multipliers and penalties by (collision vertex, edge) for the next
    step; forget the rest."""
    memory[:, MEM_ROW] = -1.0
    for c in range(count):
        q = buf.vertex[c]
        if memory[q, MEM_ROW] >= 0.0 and state[c, LAM_N] <= memory[q, 1]:
            continue  # a vertex on two edges (a corner) keeps the one that pushes more
        memory[q, MEM_ROW] = buf.edge[c]
        memory[q, 1] = state[c, LAM_N]
        memory[q, 2] = state[c, LAM_T]
        memory[q, 3] = state[c, K_N]
        memory[q, 4] = state[c, K_T]


@njit(cache=True)
def body_row_incidence(bidx, count, n_vertices, start, entry):
    """Which body rows each vertex takes part in, as CSR into ``start`` (N + 1) and ``entry``
    (3 count,): ``entry`` holds ``3 c + role`` (role 0: the vertex, 1: the edge's first end,
    2: its second)."""
    for i in range(n_vertices + 1):
        start[i] = 0
    for c in range(count):
        for role in range(3):
            start[bidx[c, role] + 1] += 1
    for i in range(n_vertices):
        start[i + 1] += start[i]
    fill = start[:n_vertices].copy()
    for c in range(count):
        for role in range(3):
            i = bidx[c, role]
            entry[fill[i]] = 3 * c + role
            fill[i] += 1


@njit(cache=True, inline="always")
def body_row_parts(bidx, bgeo, c):
    """``(ip, ia, ib, s, nx, ny, target)`` of body row ``c``."""
    return (bidx[c, 0], bidx[c, 1], bidx[c, 2], bgeo[c, BODY_S], bgeo[c, BODY_NX], bgeo[c, BODY_NY],
            bgeo[c, BODY_TARGET])


@njit(cache=True, inline="always")
def role_weight(role, s):
    """How vertex ``role`` of a body row moves its distance: 1, -(1 - s), -s."""
    if role == 0:
        return 1.0
    if role == 1:
        return -(1.0 - s)
    return -s


@njit(cache=True)
def body_blocks(x, x_n, i, bidx, bgeo, state, start, entry, whole):
    """Vertex ``i``'s share of its body rows: ``(gx, gy, hxx, hxy, hyy)`` (``whole``: the
    normal stiffness of rows that do not push now too, and the frozen friction bounds)."""
    gx = gy = hxx = hxy = hyy = 0.0
    for p in range(start[i], start[i + 1]):
        c = entry[p] // 3
        role = entry[p] - 3 * c
        ip, ia, ib, s, nx, ny, target = body_row_parts(bidx, bgeo, c)
        w = role_weight(role, s)
        fn, ft, _, _, mu = body_row_forces(x, x_n, ip, ia, ib, s, nx, ny, target, bgeo, state, c)
        bound = state[c, BOUND] if whole else friction_bound(state, c, mu, fn)
        a, b, c0, c1, c2 = weighted_row(w, fn, ft, state[c, K_N], state[c, K_T], nx, ny, bound, whole)
        gx += a
        gy += b
        hxx += c0
        hxy += c1
        hyy += c2
    return gx, gy, hxx, hxy, hyy


@njit(cache=True, inline="always")
def row_energy(fn, ft, kn, kt, bound):
    """A row's energy from its normal and (unclamped) friction force: ``f_n^2 / 2 k_n`` and
    the friction's ``f_t^2 / 2 k_t`` continued linearly beyond ``bound``."""
    e = 0.5 * fn * fn / kn
    if fn <= 0.0:
        return e
    if abs(ft) <= bound:
        return e + 0.5 * ft * ft / kt
    return e + 0.5 * bound * bound / kt + bound * (abs(ft) - bound) / kt


@njit(cache=True)
def freeze_body_bounds(x, x_n, bidx, bgeo, state, count):
    """Each body row's friction bound (:func:`friction_bound`) at the iterate ``x``, into ``state[:, BOUND]``."""
    for c in range(count):
        ip, ia, ib, s, nx, ny, target = body_row_parts(bidx, bgeo, c)
        fn, _, _, _, mu = body_row_forces(x, x_n, ip, ia, ib, s, nx, ny, target, bgeo, state, c)
        state[c, BOUND] = friction_bound(state, c, mu, fn)


@njit(cache=True)
def update_body_rows(x, x_n, bidx, bgeo, state, count, beta, k_max):
    """The body rows' dual step, as :func:`update_rows`'s."""
    for c in range(count):
        ip, ia, ib, s, nx, ny, target = body_row_parts(bidx, bgeo, c)
        fn, ft, gap, slip, mu = body_row_forces(x, x_n, ip, ia, ib, s, nx, ny, target, bgeo, state, c)
        dual_step(state, c, fn, ft, gap, slip, mu, beta, k_max)


# -- collider corners against outline edges --------------------------------------------------
#
# Row c holds the edge point (1 - s) x_a + s x_b off a collider's corner p (which moves by m
# in the step): C_n = n . ((1 - s) x_a + s x_b - p) - target, n the edge's normal into the
# body, fixed for the step, and the slip C_t along t = (-n_y, n_x) of the edge point
# relative to the corner since the step began. The forces are a body row's with the corner
# as an immovable vertex: the edge's ends take them with the weights (1 - s, s). Warm start
# by the pair (edge, collider). Without these rows a corner poking between two outline
# vertices was met only by the contact stage after the solve, which the sweeps then undid:
# the ``demo`` bunny's ear rested on a ramp's corner with three triangles inverted.


@njit(cache=True, inline="always")
def corner_row_forces_at(ax, ay, bx, by, a0x, a0y, b0x, b0y, cf, state, c):
    """Corner row ``c``'s normal and friction force with its edge's ends at ``(ax, ay)`` and
    ``(bx, by)``, which began the step at ``(a0x, a0y)`` and ``(b0x, b0y)``: ``(f_n, f_t, C_n,
    C_t, mu)`` (friction unclamped)."""
    s = cf[c, CORNER_S]
    ca = 1.0 - s
    nx, ny = cf[c, CORNER_NX], cf[c, CORNER_NY]
    ex, ey = ca * ax + s * bx, ca * ay + s * by
    gap = (ex - cf[c, CORNER_PX]) * nx + (ey - cf[c, CORNER_PY]) * ny - cf[c, CORNER_TARGET]
    fn = max(0.0, state[c, LAM_N] - state[c, K_N] * gap)
    rx = ex - ca * a0x - s * b0x - cf[c, CORNER_MX]
    ry = ey - ca * a0y - s * b0y - cf[c, CORNER_MY]
    slip = -rx * ny + ry * nx
    ft = state[c, LAM_T] - state[c, K_T] * slip
    m = cf[c, CORNER_STATIC] if state[c, STICK] > 0.0 else cf[c, CORNER_DYNAMIC]
    return fn, ft, gap, slip, m


@njit(cache=True, inline="always")
def corner_row_forces(x, x_n, ia, ib, cf, state, c):
    """Corner row ``c``'s forces at the iterate ``x`` (:func:`corner_row_forces_at`)."""
    return corner_row_forces_at(x[ia, 0], x[ia, 1], x[ib, 0], x[ib, 1], x_n[ia, 0], x_n[ia, 1], x_n[ib, 0],
                                x_n[ib, 1], cf, state, c)


@njit(cache=True)
def start_corner_rows(pairs, cf, count, memory, state, k_start, carry, soften, k_max, v):
    """Open the step's corner rows, warm-started from ``memory`` (per edge: collider,
    ``lambda_n``, ``lambda_t``, ``k_n``, ``k_t``) when the same edge met the same collider last
    step; static friction for the step when the edge point slid over the corner slower than
    :data:`STICK_SPEED` as it began."""
    for c in range(count):
        ia, ib, e, r = pairs[c, 0], pairs[c, 1], pairs[c, 2], pairs[c, 3]
        k0 = max(k_start[ia], k_start[ib])
        warm_start(state, c, memory, e, memory[e, MEM_ROW] == r, k0, carry, soften, k_max)
        s = cf[c, CORNER_S]
        rvx = (1.0 - s) * v[ia, 0] + s * v[ib, 0]
        rvy = (1.0 - s) * v[ia, 1] + s * v[ib, 1]
        state[c, STICK] = 1.0 if abs(-rvx * cf[c, CORNER_NY] + rvy * cf[c, CORNER_NX]) <= STICK_SPEED else 0.0


@njit(cache=True)
def close_corner_rows(pairs, count, memory, state):
    """Keep the corner rows' multipliers and penalties by (edge, collider) for the next step."""
    memory[:, MEM_ROW] = -1.0
    for c in range(count):
        e = pairs[c, 2]
        if memory[e, MEM_ROW] >= 0.0 and state[c, LAM_N] <= memory[e, 1]:
            continue  # an edge on two colliders' corners keeps the one that pushes more
        memory[e, MEM_ROW] = pairs[c, 3]
        memory[e, 1] = state[c, LAM_N]
        memory[e, 2] = state[c, LAM_T]
        memory[e, 3] = state[c, K_N]
        memory[e, 4] = state[c, K_T]


@njit(cache=True)
def corner_row_incidence(pairs, count, n_vertices, start, entry):
    """Which corner rows each vertex takes part in, as CSR into ``start`` (N + 1) and ``entry``
    (2 count,): ``entry`` holds ``2 c + role`` (role 0: the edge's first end, 1: its second)."""
    for i in range(n_vertices + 1):
        start[i] = 0
    for c in range(count):
        start[pairs[c, 0] + 1] += 1
        start[pairs[c, 1] + 1] += 1
    for i in range(n_vertices):
        start[i + 1] += start[i]
    fill = start[:n_vertices].copy()
    for c in range(count):
        for role in range(2):
            i = pairs[c, role]
            entry[fill[i]] = 2 * c + role
            fill[i] += 1


@njit(cache=True, inline="always")
def corner_blocks(x, x_n, i, rs, whole):
    """Vertex ``i``'s share of its corner rows: ``(gx, gy, hxx, hxy, hyy)`` (``whole`` as in
    :func:`body_blocks`)."""
    gx = gy = hxx = hxy = hyy = 0.0
    cf, state = rs.cf, rs.cstate
    for p in range(rs.c_start[i], rs.c_start[i + 1]):
        c = rs.c_entry[p] // 2
        role = rs.c_entry[p] - 2 * c
        s = cf[c, CORNER_S]
        w = s if role == 1 else 1.0 - s
        fn, ft, _, _, mu = corner_row_forces(x, x_n, rs.cpairs[c, 0], rs.cpairs[c, 1], cf, state, c)
        bound = state[c, BOUND] if whole else friction_bound(state, c, mu, fn)
        a, b, c0, c1, c2 = weighted_row(w, fn, ft, state[c, K_N], state[c, K_T], cf[c, CORNER_NX], cf[c, CORNER_NY],
                                        bound, whole)
        gx += a
        gy += b
        hxx += c0
        hxy += c1
        hyy += c2
    return gx, gy, hxx, hxy, hyy


@njit(cache=True)
def freeze_corner_bounds(x, x_n, pairs, cf, state, count):
    """Each corner row's friction bound (:func:`friction_bound`) at the iterate ``x``."""
    for c in range(count):
        fn, _, _, _, mu = corner_row_forces(x, x_n, pairs[c, 0], pairs[c, 1], cf, state, c)
        state[c, BOUND] = friction_bound(state, c, mu, fn)


@njit(cache=True)
def update_corner_rows(x, x_n, pairs, cf, state, count, beta, k_max):
    """The corner rows' dual step, as :func:`update_rows`'s."""
    for c in range(count):
        fn, ft, gap, slip, mu = corner_row_forces(x, x_n, pairs[c, 0], pairs[c, 1], cf, state, c)
        dual_step(state, c, fn, ft, gap, slip, mu, beta, k_max)


@njit(cache=True, inline="always")
def row_blocks(x, x_n, i, rs, whole):
    """Vertex ``i``'s share of all its contact rows, collider, corner and body: ``(gx, gy,
    hxx, hxy, hyy)``."""
    gx = gy = hxx = hxy = hyy = 0.0
    if rs.b_start[i + 1] > rs.b_start[i]:
        gx, gy, hxx, hxy, hyy = body_blocks(x, x_n, i, rs.bidx, rs.bgeo, rs.bstate, rs.b_start, rs.b_entry, whole)
    if rs.c_start[i + 1] > rs.c_start[i]:
        cgx, cgy, cxx, cxy, cyy = corner_blocks(x, x_n, i, rs, whole)
        gx += cgx
        gy += cgy
        hxx += cxx
        hxy += cxy
        hyy += cyy
    k = rs.vertex_row[i]
    if k >= 0:
        cgx, cgy, cxx, cxy, cyy = contact_block(x, x_n, i, rs.planes, rs.rows, k, whole)
        gx += cgx
        gy += cgy
        hxx += cxx
        hxy += cxy
        hyy += cyy
    if not whole and rs.jv[i + 1] > rs.jv[i]:  # (the whole-body step takes the joints whole)
        cgx, cgy, cxx, cxy, cyy = joint_vertex_block(x, i, rs.jv, rs.ji, rs.jf)
        gx += cgx
        gy += cgy
        hxx += cxx
        hxy += cxy
        hyy += cyy
    return gx, gy, hxx, hxy, hyy


def mark_rowed(vertex_row, b_start, c_start, gas_start, jv, rowed):
    """Into ``rowed`` (N,) bool: whether each vertex takes part in any contact row this step,
    holds a gas or holds a soft body's joint."""
    np.greater_equal(vertex_row, 0, out=rowed)
    rowed |= b_start[1:] > b_start[:-1]
    rowed |= c_start[1:] > c_start[:-1]
    rowed |= gas_start[1:] > gas_start[:-1]
    n = len(rowed)
    rowed |= jv[1:n + 1] > jv[:n]


@njit(cache=True)
def update_rigid_rows(x, x_n, rigid, touch, planes, state, count, rs, n_body, n_corner, beta, k_max):
    """The dual step of the rows whose every vertex is a rigid body's (``rigid`` (N,) bool),
    after each pass over the rigid blocks: a block is solved to the rows' current forces in
    one Newton step, so its rows' multipliers can follow every pass, as the AVBD paper's
    follow every iteration (once a step, a stack of ten boxes sank into itself and fell
    over); the soft bodies' rows wait for the step's end (see :func:`update_rows`)."""
    for k in range(count):
        i = touch[k]
        if rigid[i]:
            fn, ft, gap, slip, mu = contact_forces(x, x_n, i, planes, state, k)
            dual_step(state, k, fn, ft, gap, slip, mu, beta, k_max)
    for c in range(n_body):
        ip, ia, ib, s, nx, ny, target = body_row_parts(rs.bidx, rs.bgeo, c)
        if rigid[ip] and rigid[ia] and rigid[ib]:
            fn, ft, gap, slip, mu = body_row_forces(x, x_n, ip, ia, ib, s, nx, ny, target, rs.bgeo, rs.bstate, c)
            dual_step(rs.bstate, c, fn, ft, gap, slip, mu, beta, k_max)
    for c in range(n_corner):
        ia, ib = rs.cpairs[c, 0], rs.cpairs[c, 1]
        if rigid[ia] and rigid[ib]:
            fn, ft, gap, slip, mu = corner_row_forces(x, x_n, ia, ib, rs.cf, rs.cstate, c)
            dual_step(rs.cstate, c, fn, ft, gap, slip, mu, beta, k_max)



@njit(cache=True)
def freeze_rigid_bounds(x, x_n, rigid, touch, planes, state, count, rs, n_body, n_corner):
    """The friction bound of each row whose every vertex is a rigid body's, before a pass over
    the rigid blocks: ``mu`` times the row's normal force at the iterate, as the AVBD paper
    bounds it. The last step's force (:func:`friction_bound`, for the soft bodies' sweeps)
    bounds a landing by what the contact held before it was loaded: a box landing on a
    slope it should stand on (tan a 0.36, static friction 0.5) slid on for good."""
    for k in range(count):
        i = touch[k]
        if rigid[i]:
            fn, _, _, _, mu = contact_forces(x, x_n, i, planes, state, k)
            state[k, BOUND] = mu * fn
    for c in range(n_body):
        ip, ia, ib, s, nx, ny, target = body_row_parts(rs.bidx, rs.bgeo, c)
        if rigid[ip] and rigid[ia] and rigid[ib]:
            fn, _, _, _, mu = body_row_forces(x, x_n, ip, ia, ib, s, nx, ny, target, rs.bgeo, rs.bstate, c)
            rs.bstate[c, BOUND] = mu * fn
    for c in range(n_corner):
        ia, ib = rs.cpairs[c, 0], rs.cpairs[c, 1]
        if rigid[ia] and rigid[ib]:
            fn, _, _, _, mu = corner_row_forces(x, x_n, ia, ib, rs.cf, rs.cstate, c)
            rs.cstate[c, BOUND] = mu * fn


@njit(cache=True, inline="always")
def _impact_sticks(rvx, rvy, nx, ny, mu_static):
    """Whether a contact whose relative velocity is ``rv`` (m/s, the body side less the
    other, ``n`` toward the body side) holds by static friction this step: it slides slower
    than :data:`STICK_SPEED`, or it comes in along ``n`` fast enough that the impulse
    stopping it bounds a friction impulse that stops its slide too (``|v_t| <= mu_s v_in``,
    Coulomb's law for an impact)."""
    v_in = max(0.0, -(rvx * nx + rvy * ny))
    return abs(-rvx * ny + rvy * nx) <= max(STICK_SPEED, mu_static * v_in)


@njit(cache=True, inline="always")
def _stiffen(state, k, k0):
    state[k, K_N] = max(state[k, K_N], k0)
    state[k, K_T] = max(state[k, K_T], k0)


@njit(cache=True)
def start_rigid_rows(rigid, k_rigid, v, touch, planes, state, count, rs, n_body, n_corner, h):
    """Open the rows between rigid bodies and colliders (after the others': this overrides
    two things). Their penalties start at least at ``k_rigid`` of their stiffest vertex
    (N/m; the body's mass over ``h^2`` times the option ``penalty_start``: a rigid body's
    vertex moves with the whole body behind it, and at its own mass a stack of boxes sank
    into itself and fell). A row with a soft vertex keeps the soft side's start: stiffened
    to the rigid body's, a jelly resting on a crate buzzed at 8 cm/s. And each row's
    static-or-dynamic choice is :func:`_impact_sticks`': a box landing on a slope it should
    stand on (tan a 0.95 of its static friction) came in sliding at 2.6 cm/s, the speed
    alone gave it the dynamic coefficient, and it slid down for good."""
    for k in range(count):
        i = touch[k]
        if rigid[i]:
            _stiffen(state, k, k_rigid[i])
            state[k, STICK] = 1.0 if _impact_sticks(v[i, 0] - planes[k, 5] / h, v[i, 1] - planes[k, 6] / h,
                                                     planes[k, 0], planes[k, 1], planes[k, 3]) else 0.0
    for c in range(n_body):
        ip, ia, ib = rs.bidx[c, 0], rs.bidx[c, 1], rs.bidx[c, 2]
        if rigid[ip] and rigid[ia] and rigid[ib]:
            _stiffen(rs.bstate, c, max(k_rigid[ip], k_rigid[ia], k_rigid[ib]))
            s = rs.bgeo[c, BODY_S]
            rvx = v[ip, 0] - (1.0 - s) * v[ia, 0] - s * v[ib, 0]
            rvy = v[ip, 1] - (1.0 - s) * v[ia, 1] - s * v[ib, 1]
            rs.bstate[c, STICK] = 1.0 if _impact_sticks(rvx, rvy, rs.bgeo[c, BODY_NX], rs.bgeo[c, BODY_NY],
                                                         rs.bgeo[c, BODY_STATIC]) else 0.0
    for c in range(n_corner):
        ia, ib = rs.cpairs[c, 0], rs.cpairs[c, 1]
        if rigid[ia] and rigid[ib]:
            _stiffen(rs.cstate, c, max(k_rigid[ia], k_rigid[ib]))
            s, cf = rs.cf[c, CORNER_S], rs.cf
            rvx = (1.0 - s) * v[ia, 0] + s * v[ib, 0] - cf[c, CORNER_MX] / h
            rvy = (1.0 - s) * v[ia, 1] + s * v[ib, 1] - cf[c, CORNER_MY] / h
            rs.cstate[c, STICK] = 1.0 if _impact_sticks(rvx, rvy, cf[c, CORNER_NX], cf[c, CORNER_NY],
                                                         cf[c, CORNER_STATIC]) else 0.0


@njit(cache=True)
def _fill_impulses(x, touch, plane_rows, planes, state, count, bidx, bgeo, bstate, n_body, cpairs, cf, cstate,
                   n_corner, h, vertex, edge, collider, point, normal, jn, jt):
    """:func:`row_impulses`' columns, row by row (one loop: as NumPy's concatenations it cost
    2.5 % of a 10-box stack's step, every step, read or not)."""
    for k in range(count):
        i = touch[k]
        vertex[k], edge[k, 0], edge[k, 1], collider[k] = i, -1, -1, plane_rows[k]
        point[k, 0], point[k, 1] = x[i, 0], x[i, 1]
        normal[k, 0], normal[k, 1] = planes[k, 0], planes[k, 1]
        jn[k], jt[k] = h * state[k, LAM_N], h * state[k, LAM_T]
    for c in range(n_body):
        r, i = count + c, bidx[c, 0]
        vertex[r], edge[r, 0], edge[r, 1], collider[r] = i, bidx[c, 1], bidx[c, 2], -1
        point[r, 0], point[r, 1] = x[i, 0], x[i, 1]
        normal[r, 0], normal[r, 1] = bgeo[c, BODY_NX], bgeo[c, BODY_NY]
        jn[r], jt[r] = h * bstate[c, LAM_N], h * bstate[c, LAM_T]
    for c in range(n_corner):
        r = count + n_body + c
        vertex[r], edge[r, 0], edge[r, 1], collider[r] = -1, cpairs[c, 0], cpairs[c, 1], cpairs[c, 3]
        point[r, 0], point[r, 1] = cf[c, CORNER_PX], cf[c, CORNER_PY]
        normal[r, 0], normal[r, 1] = cf[c, CORNER_NX], cf[c, CORNER_NY]
        jn[r], jt[r] = h * cstate[c, LAM_N], h * cstate[c, LAM_T]


def row_impulses(x, touch, plane_rows, planes, state, count, bidx, bgeo, bstate, n_body, cpairs, cf, cstate,
                 n_corner, h):
    """The impulses of a substep's rows (N s, their multipliers after the dual step times ``h``)
    as a :class:`~deforma.physics.contact.pairs.ContactImpulses`: the collider rows
    (``touch``, ``plane_rows``, ``planes``, ``state``), the body rows (``bidx``, ``bgeo``,
    ``bstate``) and the corner rows (``cpairs``, ``cf``, ``cstate``), the first ``count``,
    ``n_body`` and ``n_corner`` of each; the points at ``x``. Each row's force on its pushed
    side is ``lambda_n n + lambda_t t`` (``t = (-n_y, n_x)``), as its block takes it."""
    n = count + n_body + n_corner
    out = ContactImpulses(np.empty(n, np.int64), np.empty((n, 2), np.int64), np.empty(n, np.int64),
                          np.empty((n, 2)), np.empty((n, 2)), np.empty(n), np.empty(n))
    _fill_impulses(x, touch, plane_rows, planes, state, count, bidx, bgeo, bstate, n_body, cpairs, cf, cstate,
                   n_corner, h, *(getattr(out, f) for f in ("vertex", "edge", "collider", "point", "normal",
                                                             "normal_impulse", "friction_impulse")))
    return out

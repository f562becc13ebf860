"""Joints as rows of the avbd sweep (Giles, Diaz, Yuksel, "Augmented Vertex Block Descent",
SIGGRAPH 2025: a joint is a set of augmented-Lagrangian rows on the blocks it joins).

A joint holds a point of rigid block ``a`` on a point of block ``b`` or of the world. Each
side's point is carried by its body: at the start of a substep it is read from two of the
body's vertices (``p = x_0 + alpha d + beta perp(d)``, ``d = x_1 - x_0``: exact for a rigid
body, and where the joint was made), and within the substep it turns and moves with the
block's pose, ``p = c + R(phi) r`` (``r`` its arm from the centre at the start).

Rows, with ``C`` the constraint, ``k`` its penalty and ``lambda`` its multiplier, the force
``f = k C + lambda`` acting on ``a`` as ``-f`` and on ``b`` as ``+f``:

- the point (a pin, a weld): ``C = p_a - p_b`` (2 rows);
- the angle (a weld): ``C = (theta_a - theta_b) - theta_0``, the bodies' relative turn since
  the weld was made;
- a motor (on a pin): ``C = (phi_a - phi_b) - h omega``, ``a``'s turn relative to ``b`` over
  the substep against the motor's; its force (a torque) is bounded by ``max_torque``;
- a spring is not a row but an energy: ``(k_s / 2) |C|^2`` and the damper's
  ``(c / 2h) |C - C_n|^2`` (backward Euler's dissipation of ``c |dC/dt|^2 / 2``), exact
  and stable at any stiffness.

A block's share of each row enters its Newton step as ``J^T f`` and ``k J^T J`` with
``J = +-[I | perp(R r)]``, and a turn's curvature as ``|f . R r|`` on the angle (the
absolute value keeps the 3 x 3 system positive definite, as the paper's diagonal
approximation of the geometric stiffness does). After each pass over the rigid blocks the
rows take their dual step: ``lambda = k C + lambda`` (a motor's clamped to its bound) and
``k += beta |C|`` up to ``k_max`` (a clamped motor's stays). Between steps ``lambda`` and ``k``
are carried whole (:func:`start_joint_rows`), ``k`` no softer than the lighter body's
``m / h^2``.

Arrays of :class:`JointRows` per joint ``j``: ``block`` (J, 2) the blocks (``-1``: the world),
``fv`` (J, 4) the two frame vertices of ``a`` then of ``b`` (``-1`` for the world), ``fw``
(J, 4) their ``(alpha, beta)`` (for the world, ``b``'s point), ``kind`` (J,)
(:data:`~deforma.physics.rigid.joints.KINDS`), ``param`` (J, 5) the reference angle of the
frames ``theta_a - theta_b`` (rad), the motor's speed (rad/s) and torque bound (N m),
spring stiffness (N/m) and damping (N s/m), ``motor`` (J,), ``lam`` and ``pen`` (J, 4) the
rows' multipliers and penalties (x, y, angle, motor), and per substep ``arm`` (J, 4) the
arms (for the world, its point), ``err0`` (J, 3) the point's and angle's error at the
start, ``total`` (J, 3) the force and torque on ``a`` times the time so far (N s, N m s);
``j_start`` (K + 1,) and ``j_entry`` (2 J,) list each block's joints as ``2 j + side``;
``island`` (K,) labels the blocks joints hold together, and ``island_ok``, ``island_touch``
(K,) say per island whether it takes BDF2 and whether it has a contact row or grab this
substep (:func:`~deforma.physics.integrators.avbd.rigid.rigid_second_order`).

Units: m, kg, s, rad; N, N/m, N m.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from ...rigid.joints import SPRING, WELD

JointRows = namedtuple("JointRows", ["block", "fv", "fw", "kind", "param", "motor", "lam", "pen", "arm", "err0",
                                     "total", "j_start", "j_entry", "island", "island_ok", "island_touch"])


def make_joint_rows(block, fv, fw, kind, param, motor, lam, pen, n_blocks: int) -> JointRows:
    """:class:`JointRows` from the packed arrays (``lam``, ``pen``: the warm start), with
    each block's joints listed."""
    n = len(kind)
    j_start = np.zeros(n_blocks + 1, np.int64)
    for j in range(n):
        for side in range(2):
            if block[j, side] >= 0:
                j_start[block[j, side] + 1] += 1
    j_start = np.cumsum(j_start)
    fill = j_start[:-1].copy()
    j_entry = np.zeros(max(int(j_start[-1]), 1), np.int64)
    for j in range(n):
        for side in range(2):
            k = block[j, side]
            if k >= 0:
                j_entry[fill[k]] = 2 * j + side
                fill[k] += 1
    # the islands: blocks joints hold together (through other blocks)
    island = np.arange(n_blocks)

    def root(k):
        while island[k] != k:
            island[k] = island[island[k]]
            k = island[k]
        return k
    for j in range(n):
        if block[j, 0] >= 0 and block[j, 1] >= 0:
            island[root(block[j, 0])] = root(block[j, 1])
    island = np.array([root(k) for k in range(n_blocks)], np.int64)
    return JointRows(np.asarray(block, np.int64), np.asarray(fv, np.int64), np.asarray(fw, np.float64),
                     np.asarray(kind, np.int64), np.asarray(param, np.float64), np.asarray(motor, np.bool_),
                     np.asarray(lam, np.float64), np.asarray(pen, np.float64), np.zeros((n, 4)), np.zeros((n, 3)),
                     np.zeros((n, 3)), j_start, j_entry, island, np.zeros(n_blocks, np.bool_),
                     np.zeros(n_blocks, np.bool_))


@njit(cache=True, inline="always")
def frame_point(x, i0, i1, alpha, beta):
    """The point ``x_0 + alpha d + beta perp(d)`` (``d = x_1 - x_0``) and the frame's angle
    ``atan2(d)`` (rad)."""
    dx, dy = x[i1, 0] - x[i0, 0], x[i1, 1] - x[i0, 1]
    return x[i0, 0] + alpha * dx - beta * dy, x[i0, 1] + alpha * dy + beta * dx, np.arctan2(dy, dx)


@njit(cache=True)
def start_joint_rows(x_n, blocks, jr, k_floor):
    """Start a substep: each joint's arms from its blocks' centres ``blocks.c_n``, its errors
    there, and its rows warm-started: ``lambda`` and ``k`` as the last substep left them, ``k``
    at least ``k_floor`` times the lighter body's mass (``penalty_start / h^2``).
    ``jr.total`` is kept (the step's sum).

    Unlike the contact rows' (``lambda * 0.98``, ``k * 0.99``), a joint's rows are carried
    whole: a joint holds for good, and its load changes smoothly. Decayed, the multipliers of
    a chain of 20 equal links hanging still fell short of its weight every step, and with the
    chain on BDF2 throughout it swung up to 0.12 m/s; carried whole it hung at 1e-10 m/s
    (with :func:`~deforma.physics.integrators.avbd.rigid.rigid_second_order`'s switching it
    sways at up to 2 mm/s)."""
    for j in range(jr.kind.shape[0]):
        ka, kb = jr.block[j, 0], jr.block[j, 1]
        pax, pay, tha = frame_point(x_n, jr.fv[j, 0], jr.fv[j, 1], jr.fw[j, 0], jr.fw[j, 1])
        jr.arm[j, 0], jr.arm[j, 1] = pax - blocks.c_n[ka, 0], pay - blocks.c_n[ka, 1]
        floor = blocks.mass[ka]
        if kb >= 0:
            pbx, pby, thb = frame_point(x_n, jr.fv[j, 2], jr.fv[j, 3], jr.fw[j, 2], jr.fw[j, 3])
            jr.arm[j, 2], jr.arm[j, 3] = pbx - blocks.c_n[kb, 0], pby - blocks.c_n[kb, 1]
            if not blocks.held[kb]:
                floor = min(floor, blocks.mass[kb])
        else:
            pbx, pby, thb = jr.fw[j, 2], jr.fw[j, 3], 0.0
            jr.arm[j, 2], jr.arm[j, 3] = pbx, pby
        jr.err0[j, 0], jr.err0[j, 1] = pax - pbx, pay - pby
        turn = tha - thb - jr.param[j, 0]
        jr.err0[j, 2] = np.arctan2(np.sin(turn), np.cos(turn))  # wrapped to (-pi, pi]
        k0 = k_floor * floor
        for r in range(4):
            jr.pen[j, r] = max(k0, jr.pen[j, r])


@njit(cache=True, inline="always")
def _side(jr, blocks, j, side, k, cx, cy, phi):
    """Side ``side`` of joint ``j``: its point and its arm ``R(phi) r`` now, with block ``k``
    at the pose ``(cx, cy, phi)`` and any other block at its own pose (the world's point
    where it is)."""
    kb = jr.block[j, side]
    rx0, ry0 = jr.arm[j, 2 * side], jr.arm[j, 2 * side + 1]
    if kb < 0:
        return rx0, ry0, 0.0, 0.0, 0.0
    if kb == k:
        px, py, ph = cx, cy, phi
    else:
        p = blocks.pose
        px, py, ph = p[kb, 0], p[kb, 1], p[kb, 2]
    co, si = np.cos(ph), np.sin(ph)
    rx, ry = co * rx0 - si * ry0, si * rx0 + co * ry0
    return px + rx, py + ry, rx, ry, ph


@njit(cache=True, inline="always")
def _rows(jr, blocks, j, k, cx, cy, phi, h):
    """Joint ``j``'s constraints with block ``k`` at ``(cx, cy, phi)``: the point's ``C``,
    the forces ``f`` of its point, angle and motor rows, their stiffnesses, whether the
    motor is clamped, and the arms of both sides."""
    pax, pay, rax, ray, pha = _side(jr, blocks, j, 0, k, cx, cy, phi)
    pbx, pby, rbx, rby, phb = _side(jr, blocks, j, 1, k, cx, cy, phi)
    cx_, cy_ = pax - pbx, pay - pby
    kind = jr.kind[j]
    if kind == SPRING:
        stiff, damp = jr.param[j, 3], jr.param[j, 4]
        kp = stiff + damp / h
        fx = kp * cx_ - damp / h * jr.err0[j, 0]
        fy = kp * cy_ - damp / h * jr.err0[j, 1]
    else:
        kp = jr.pen[j, 0]
        fx = kp * cx_ + jr.lam[j, 0]
        fy = kp * cy_ + jr.lam[j, 1]
    fa = ka_ = 0.0
    if kind == WELD:
        ka_ = jr.pen[j, 2]
        fa = ka_ * (jr.err0[j, 2] + pha - phb) + jr.lam[j, 2]
    fm = km = 0.0
    clamped = False
    if jr.motor[j]:
        km = jr.pen[j, 3]
        fm = km * (pha - phb - h * jr.param[j, 1]) + jr.lam[j, 3]
        bound = jr.param[j, 2]
        if abs(fm) > bound:
            fm = bound if fm > 0.0 else -bound
            clamped = True
    return cx_, cy_, fx, fy, kp, fa, ka_, fm, km, clamped, rax, ray, rbx, rby


@njit(cache=True)
def joint_block(jr, blocks, k, cx, cy, phi, h, acc):
    """Add block ``k``'s joints at the pose ``(cx, cy, phi)`` to its gradient and Hessian
    ``acc`` (g0, g1, g2, a00, a01, a02, a11, a12, a22; see the module docstring)."""
    for p in range(jr.j_start[k], jr.j_start[k + 1]):
        j, side = jr.j_entry[p] // 2, jr.j_entry[p] % 2
        _, _, fx, fy, kp, fa, ka_, fm, km, clamped, rax, ray, rbx, rby = _rows(jr, blocks, j, k, cx, cy, phi, h)
        sg = 1.0 if side == 0 else -1.0
        rx, ry = (rax, ray) if side == 0 else (rbx, rby)
        acc[0] += sg * fx
        acc[1] += sg * fy
        acc[2] += sg * (rx * fy - ry * fx + fa + fm)
        acc[3] += kp
        acc[5] += -kp * ry
        acc[6] += kp
        acc[7] += kp * rx
        # the turn's curvature of the point: d2 p / d phi2 = -R r
        acc[8] += kp * (rx * rx + ry * ry) + abs(fx * rx) + abs(fy * ry) + ka_ + (0.0 if clamped else km)


@njit(cache=True, inline="always")
def _energy(f, k):
    return 0.5 * f * f / k if k > 0.0 else 0.0


@njit(cache=True)
def joint_energy(jr, blocks, k, cx, cy, phi, h):
    """Block ``k``'s joints' energy (J) with it at the pose ``(cx, cy, phi)``, up to a
    constant: ``f^2 / 2k`` per row (``lambda C + k C^2 / 2`` and ``lambda^2 / 2k``), a
    clamped motor's continued linearly; a spring's own."""
    e = 0.0
    for p in range(jr.j_start[k], jr.j_start[k + 1]):
        j = jr.j_entry[p] // 2
        cx_, cy_, fx, fy, kp, fa, ka_, fm, km, clamped, _, _, _, _ = _rows(jr, blocks, j, k, cx, cy, phi, h)
        if jr.kind[j] == SPRING:
            damp = jr.param[j, 4] / h
            e += 0.5 * jr.param[j, 3] * (cx_ * cx_ + cy_ * cy_) + 0.5 * damp * (
                (cx_ - jr.err0[j, 0]) ** 2 + (cy_ - jr.err0[j, 1]) ** 2)
        else:
            e += _energy(fx, kp) + _energy(fy, kp)
        e += _energy(fa, ka_)
        if jr.motor[j]:
            if clamped:
                # the unclamped force, continued linearly past the bound
                u = km * (_rows_turn(jr, blocks, j, k, phi) - h * jr.param[j, 1]) + jr.lam[j, 3]
                bound = jr.param[j, 2]
                e += 0.5 * bound * bound / km + bound * (abs(u) - bound) / km
            else:
                e += _energy(fm, km)
    return e


@njit(cache=True, inline="always")
def _rows_turn(jr, blocks, j, k, phi):
    """``phi_a - phi_b`` of joint ``j`` with block ``k`` turned by ``phi``."""
    t = 0.0
    for side in range(2):
        kb = jr.block[j, side]
        if kb < 0:
            continue
        ph = phi if kb == k else blocks.pose[kb, 2]
        t += ph if side == 0 else -ph
    return t


@njit(cache=True)
def update_joint_rows(jr, blocks, beta, k_max, h):
    """The joints' dual step at the blocks' poses (see the module docstring)."""
    for j in range(jr.kind.shape[0]):
        ka = jr.block[j, 0]
        p = blocks.pose
        cx_, cy_, fx, fy, kp, fa, ka_, fm, km, clamped, _, _, _, _ = _rows(jr, blocks, j, ka, p[ka, 0], p[ka, 1],
                                                                          p[ka, 2], h)
        kind = jr.kind[j]
        if kind != SPRING:
            jr.lam[j, 0], jr.lam[j, 1] = fx, fy
            jr.pen[j, 0] = min(k_max, kp + beta * np.sqrt(cx_ * cx_ + cy_ * cy_))
        turn = _rows_turn(jr, blocks, j, ka, p[ka, 2])
        if kind == WELD:
            jr.lam[j, 2] = fa
            jr.pen[j, 2] = min(k_max, ka_ + beta * abs(jr.err0[j, 2] + turn))
        if jr.motor[j]:
            turn -= h * jr.param[j, 1]
            jr.lam[j, 3] = fm
            if not clamped:
                jr.pen[j, 3] = min(k_max, km + beta * abs(turn))


@njit(cache=True)
def joint_totals(jr, blocks, h):
    """Add each joint's force and torque on ``a`` over the substep of ``h`` s to ``jr.total``
    (N s, N m s): after the last dual step, a row's force is its multiplier (a spring's is
    its energy's gradient at the blocks' poses)."""
    for j in range(jr.kind.shape[0]):
        if jr.kind[j] == SPRING:
            ka = jr.block[j, 0]
            p = blocks.pose
            _, _, fx, fy, _, _, _, _, _, _, _, _, _, _ = _rows(jr, blocks, j, ka, p[ka, 0], p[ka, 1], p[ka, 2], h)
        else:
            fx, fy = jr.lam[j, 0], jr.lam[j, 1]
        jr.total[j, 0] -= h * fx
        jr.total[j, 1] -= h * fy
        jr.total[j, 2] -= h * ((jr.lam[j, 2] if jr.kind[j] == WELD else 0.0) + (jr.lam[j, 3] if jr.motor[j] else 0.0))


@njit(cache=True)
def joint_gap(jr, blocks, h):
    """The widest a pin's or weld's points are apart at the blocks' poses (m), over the
    islands without contacts (``jr.island_touch``)."""
    most = 0.0
    for j in range(jr.kind.shape[0]):
        ka = jr.block[j, 0]
        if jr.kind[j] == SPRING or jr.island_touch[jr.island[ka]]:
            continue
        p = blocks.pose
        cx_, cy_, _, _, _, _, _, _, _, _, _, _, _, _ = _rows(jr, blocks, j, ka, p[ka, 0], p[ka, 1], p[ka, 2], h)
        most = max(most, np.sqrt(cx_ * cx_ + cy_ * cy_))
    return most

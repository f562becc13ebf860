"""Joints as rows of the avbd sweep (Giles, Diaz, Yuksel, "Augmented Vertex Block Descent",
SIGGRAPH 2025: a joint is a set of augmented-Lagrangian rows on the blocks it joins).

A joint holds a point of body ``a`` on a point of body ``b`` or of the world. A side's point
is carried by its body:

- on a rigid block, at the start of a substep it is read from two of the body's vertices
  (``p = x_0 + alpha d + beta perp(d)``, ``d = x_1 - x_0``: exact for a rigid body, and where
  the joint was made), and within the substep it turns and moves with the block's pose,
  ``p = c + R(phi) r`` (``r`` its arm from the centre at the start);
- on a soft body, it is the point of the triangle it was made on, by its barycentric
  weights, ``p = sum w_i x_i``: the three vertices share the joint's force by their weights,
  so a hinge in a soft body pulls no single vertex out of it (no hole, no tear). The row is
  then part of each of those vertices' blocks in the vertex sweep (:func:`joint_vertex_block`,
  through the :class:`~deforma.physics.integrators.avbd.rows.RowSet`), and those vertices are
  swept with the contact rows' (one by one, after their colour's others).

Rows, with ``C`` the constraint, ``k`` its penalty and ``lambda`` its multiplier, the force
``f = k C + lambda`` acting on ``a`` as ``-f`` and on ``b`` as ``+f``:

- the point (a pin, a weld): ``C = p_a - p_b`` (2 rows);
- the angle (a weld of rigid bodies): ``C = (theta_a - theta_b) - theta_0``, the bodies'
  relative turn since the weld was made;
- a motor (on a pin of rigid bodies): ``C = (phi_a - phi_b) - h omega``, ``a``'s turn relative
  to ``b`` over the substep against the motor's; its force (a torque) is bounded by
  ``max_torque``;
- a spring is not a row but an energy: ``(k_s / 2) |C|^2`` and the damper's
  ``(c / 2h) |C - C_n|^2`` (backward Euler's dissipation of ``c |dC/dt|^2 / 2``), exact
  and stable at any stiffness.

A rigid block's share of each row enters its Newton step as ``J^T f`` and ``k J^T J`` with
``J = +-[I | perp(R r)]``, and a turn's curvature as ``|f . R r|`` on the angle (the
absolute value keeps the 3 x 3 system positive definite, as the paper's diagonal
approximation of the geometric stiffness does); a soft vertex's, with weight ``w``, as
``+-w f`` and ``k w^2 I``. The rows of rigid bodies alone take their dual step after each
pass over the rigid blocks: ``lambda = k C + lambda`` (a motor's clamped to its bound) and
``k += beta |C|`` up to ``k_max`` (a clamped motor's stays); those with a soft side after
each step, as the contact rows' (:func:`update_joint_rows`). Between steps ``lambda`` and
``k`` are carried whole (:func:`start_joint_rows`), ``k`` no softer than the softer side's
start: a rigid block's ``m / h^2``, a soft side's its vertices' contact rows start at (their
inertia and their elements' stiffness, summed over the triangle).

Arrays of :class:`JointRows`, per joint ``j`` in two tables, ``ji`` (J, :data:`JI_COLUMNS`)
of integers and ``jf`` (J, :data:`JF_COLUMNS`) of floats, whose columns start at the
constants named here: ``ji[:, BLOCK:BLOCK + 2]`` the rigid blocks (``-1``: a soft body or
the world), ``ji[:, FV:FV + 6]`` per side three vertices (global indices): a rigid block's
two frame vertices (and -1), a soft side's triangle, or -1 for the world; ``ji[:, KIND]``
(:data:`~deforma.physics.rigid.joints.KINDS`), ``ji[:, MOTOR]`` whether a motor drives it,
``ji[:, SOFT]`` whether a side is soft; ``jf[:, FW:FW + 6]`` per side the frame's ``(alpha,
beta, 0)``, the triangle's weights, or the world's point ``(x, y, 0)``; ``jf[:, PARAM:PARAM
+ 6]`` the reference angle of the frames ``theta_a - theta_b`` (rad), the motor's speed
(rad/s) and torque bound (N m), spring stiffness (N/m) and damping (N s/m), and the
substep's ``h`` (s, set by :func:`start_joint_rows`); ``jf[:, LAM:LAM + 4]`` and ``jf[:,
PEN:PEN + 4]`` the rows' multipliers and penalties (x, y, angle, motor); and per substep
``jf[:, ARM:ARM + 4]`` the rigid sides' arms, ``jf[:, ERR0:ERR0 + 3]`` the point's and
angle's error at the start, ``jf[:, POINT:POINT + 4]`` the rigid sides' points now (kept by
the passes over the rigid blocks, for the soft vertices' blocks), ``jf[:, TOTAL:TOTAL + 3]``
the force and torque on ``a`` times the time so far (N s, N m s). Then ``j_start`` (K + 1,)
and ``j_entry`` (2 J,) list each rigid block's joints as ``2 j + side``; ``v`` lists each
soft vertex's as ``6 j + 3 side + slot`` in one array, ``v[v[i]:v[i + 1]]`` for vertex
``i`` (``v[:N + 1]`` the starts, past which the entries follow); ``island`` (K,) labels the
blocks joints hold together, and ``island_ok``, ``island_touch`` (K,) say per island whether
it takes BDF2 and whether it has a contact row, grab or soft joint this substep
(:func:`~deforma.physics.integrators.avbd.rigid.rigid_second_order`). Two tables, not a
field per quantity: Numba counts a reference to every array of a tuple each time a kernel
hands it to another, and the rigid blocks' kernels hand the rows over several times per
block and pass: with a field each (20), the ``chain`` scene stepped in 1.5 times the time
it took before the soft joints' fields came, with the two tables in 1.1-1.2 times.

Units: m, kg, s, rad; N, N/m, N m.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from ...rigid.joints import SPRING, WELD

JointRows = namedtuple("JointRows", ["ji", "jf", "j_start", "j_entry", "v", "island", "island_ok", "island_touch"])

#: Where each quantity's columns start in ``ji`` and ``jf`` (see the module docstring).
BLOCK, FV, KIND, MOTOR, SOFT, JI_COLUMNS = 0, 2, 8, 9, 10, 11
FW, PARAM, LAM, PEN, ERR0, POINT, ARM, TOTAL, JF_COLUMNS = 0, 6, 12, 16, 20, 23, 27, 31, 34

#: Which joints :func:`update_joint_rows` steps: those of rigid bodies and the world alone,
#: or those with a soft side.
RIGID_JOINTS, SOFT_JOINTS = 0, 1


def _incidence(owner, n_owners, codes):
    """``(start (n_owners + 1,), entry)``: for each owner the codes listed with it."""
    owner = np.asarray(owner, np.int64)
    codes = np.asarray(codes, np.int64)
    order = np.argsort(owner, kind="stable")
    start = np.zeros(n_owners + 1, np.int64)
    np.add.at(start, owner + 1, 1)
    entry = codes[order] if len(codes) else np.zeros(1, np.int64)
    return np.cumsum(start), entry


def make_joint_rows(block, fv, fw, kind, param, motor, lam, pen, n_blocks: int, n_vertices: int) -> JointRows:
    """:class:`JointRows` from the packed arrays (``lam``, ``pen``: the warm start), with
    each rigid block's and each soft vertex's joints listed."""
    block, fv = np.asarray(block, np.int64), np.asarray(fv, np.int64)
    n = len(kind)
    owners, codes = [], []
    for j in range(n):
        for side in range(2):
            if block[j, side] >= 0:
                owners.append(block[j, side])
                codes.append(2 * j + side)
    j_start, j_entry = _incidence(owners, n_blocks, codes)
    owners, codes = [], []
    soft = np.zeros(n, np.bool_)
    for j in range(n):
        for side in range(2):
            if block[j, side] < 0 and fv[j, 3 * side] >= 0:
                soft[j] = True
                for slot in range(3):
                    owners.append(fv[j, 3 * side + slot])
                    codes.append(6 * j + 3 * side + slot)
    v_start, v_entry = _incidence(owners, n_vertices, codes)
    v = np.concatenate([v_start + len(v_start), v_entry])
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
    ji = np.zeros((n, JI_COLUMNS), np.int64)
    ji[:, BLOCK:BLOCK + 2], ji[:, FV:FV + 6], ji[:, KIND] = block, fv, kind
    ji[:, MOTOR], ji[:, SOFT] = motor, soft
    jf = np.zeros((n, JF_COLUMNS))
    jf[:, FW:FW + 6], jf[:, PARAM:PARAM + 6], jf[:, LAM:LAM + 4], jf[:, PEN:PEN + 4] = fw, param, lam, pen
    return JointRows(ji, jf, j_start, j_entry, v, island, np.zeros(n_blocks, np.bool_),
                     np.zeros(n_blocks, np.bool_))


def no_joint_rows(n_blocks: int, n_vertices: int) -> JointRows:
    """:class:`JointRows` without joints."""
    z = np.zeros((0, 4))
    return make_joint_rows(np.zeros((0, 2), np.int64), np.zeros((0, 6), np.int64), np.zeros((0, 6)),
                           np.zeros(0, np.int64), np.zeros((0, 6)), np.zeros(0, np.bool_), z, z, n_blocks,
                           n_vertices)


@njit(cache=True, inline="always")
def frame_point(x, i0, i1, alpha, beta):
    """The point ``x_0 + alpha d + beta perp(d)`` (``d = x_1 - x_0``) and the frame's angle
    ``atan2(d)`` (rad)."""
    dx, dy = x[i1, 0] - x[i0, 0], x[i1, 1] - x[i0, 1]
    return x[i0, 0] + alpha * dx - beta * dy, x[i0, 1] + alpha * dy + beta * dx, np.arctan2(dy, dx)


@njit(cache=True, inline="always")
def held_point(x, ji, jf, j, side):
    """Side ``side`` of joint ``j`` (:data:`JointRows`' ``ji``, ``jf``) where it is now, for a
    soft vertex's block: a rigid side at its kept point, a soft side by its triangle's
    weights, the world's where it is."""
    if ji[j, BLOCK + side] >= 0:
        return jf[j, POINT + 2 * side], jf[j, POINT + 2 * side + 1]
    b = 3 * side
    if ji[j, FV + b] < 0:
        return jf[j, FW + b], jf[j, FW + b + 1]
    px = py = 0.0
    for s in range(3):
        i, w = ji[j, FV + b + s], jf[j, FW + b + s]
        px += w * x[i, 0]
        py += w * x[i, 1]
    return px, py


@njit(cache=True, inline="always")
def point_force(ji, jf, j, cx, cy):
    """The point rows' force ``(fx, fy)`` (N) and stiffness (N/m) at the error ``(cx, cy)``:
    ``k C + lambda``, or a spring's gradient."""
    if ji[j, KIND] == SPRING:
        damp = jf[j, PARAM + 4] / jf[j, PARAM + 5]
        kp = jf[j, PARAM + 3] + damp
        return kp * cx - damp * jf[j, ERR0], kp * cy - damp * jf[j, ERR0 + 1], kp
    kp = jf[j, PEN]
    return kp * cx + jf[j, LAM], kp * cy + jf[j, LAM + 1], kp


@njit(cache=True, inline="always")
def joint_point_energy(ji, jf, j, cx, cy):
    """The point rows' energy (J) at the error ``(cx, cy)``, up to a constant: ``|k C +
    lambda|^2 / 2k``, or a spring's own."""
    if ji[j, KIND] == SPRING:
        damp = jf[j, PARAM + 4] / jf[j, PARAM + 5]
        return 0.5 * jf[j, PARAM + 3] * (cx * cx + cy * cy) + 0.5 * damp * ((cx - jf[j, ERR0]) ** 2
                                                                             + (cy - jf[j, ERR0 + 1]) ** 2)
    kp = jf[j, PEN]
    if not kp > 0.0:
        return 0.0
    fx, fy = kp * cx + jf[j, LAM], kp * cy + jf[j, LAM + 1]
    return 0.5 * (fx * fx + fy * fy) / kp


@njit(cache=True, inline="always")
def joint_vertex_block(x, i, v, ji, jf):
    """Soft vertex ``i``'s share of its joints' point rows (:data:`JointRows`' ``v``, ``ji``,
    ``jf``): ``(gx, gy, hxx, hxy, hyy)``."""
    gx = gy = hh = 0.0
    for p in range(v[i], v[i + 1]):
        e = v[p]
        j, side, slot = e // 6, (e // 3) % 2, e % 3
        pax, pay = held_point(x, ji, jf, j, 0)
        pbx, pby = held_point(x, ji, jf, j, 1)
        fx, fy, kp = point_force(ji, jf, j, pax - pbx, pay - pby)
        w = jf[j, FW + 3 * side + slot]
        sw = w if side == 0 else -w
        gx += sw * fx
        gy += sw * fy
        hh += kp * w * w
    return gx, gy, hh, 0.0, hh


@njit(cache=True)
def start_joint_rows(x_n, blocks, jr, k_floor, vertex_mass, inv_mass, carry, soften, h):
    """Start a substep of ``h`` s: each rigid side's arm from its block's centre
    ``blocks.c_n`` and its point at the block's starting pose, each joint's errors at the
    start, and its rows warm-started, ``k`` at least the softer side's inertia: a rigid
    block's mass times ``k_floor`` (``penalty_start / h^2``), a soft side's its free
    vertices' masses ``vertex_mass`` summed. The totals are kept (the step's sum).

    A joint of rigid bodies alone carries ``lambda`` and ``k`` whole: a joint holds for good,
    and its load changes smoothly. Decayed, the multipliers of a chain of 20 equal links
    hanging still fell short of its weight every step, and with the chain on BDF2 throughout
    it swung up to 0.12 m/s; carried whole it hung at 1e-10 m/s (with
    :func:`~deforma.physics.integrators.avbd.rigid.rigid_second_order`'s switching it sways
    at up to 2 mm/s). A joint with a soft side decays them as the contact rows do
    (``lambda * carry``, ``k * soften``), and starts no stiffer than the inertia: two soft
    links hinged end to end swung with 7-9 J more energy than they began with where the
    rows started as stiff as the elements around them, and blew up where ``k`` grew without
    decay; with both they settle, their pin 30 micrometres apart."""
    for j in range(jr.ji.shape[0]):
        jr.jf[j, PARAM + 5] = h
        floor = np.inf
        ex = ey = turn = 0.0  # side a's point and frame angle less side b's
        for side in range(2):
            kb = jr.ji[j, BLOCK + side]
            b = 3 * side
            sg = 1.0 if side == 0 else -1.0
            if kb >= 0:
                px, py, theta = frame_point(x_n, jr.ji[j, FV + b], jr.ji[j, FV + b + 1], jr.jf[j, FW + b],
                                            jr.jf[j, FW + b + 1])
                turn += sg * theta
                rx, ry = px - blocks.c_n[kb, 0], py - blocks.c_n[kb, 1]
                jr.jf[j, ARM + 2 * side], jr.jf[j, ARM + 2 * side + 1] = rx, ry
                if not blocks.held[kb]:
                    floor = min(floor, blocks.mass[kb])
                # where the block starts the substep
                co, si = np.cos(blocks.pose[kb, 2]), np.sin(blocks.pose[kb, 2])
                jr.jf[j, POINT + 2 * side] = blocks.pose[kb, 0] + co * rx - si * ry
                jr.jf[j, POINT + 2 * side + 1] = blocks.pose[kb, 1] + si * rx + co * ry
            else:
                px, py = held_point(x_n, jr.ji, jr.jf, j, side)
                if jr.ji[j, FV + b] >= 0:
                    k_side = 0.0
                    for slot in range(3):
                        i = jr.ji[j, FV + b + slot]
                        if inv_mass[i] != 0.0:
                            k_side += vertex_mass[i]
                    if k_side > 0.0:
                        floor = min(floor, k_side)
            ex += sg * px
            ey += sg * py
        jr.jf[j, ERR0], jr.jf[j, ERR0 + 1] = ex, ey
        turn -= jr.jf[j, PARAM]
        jr.jf[j, ERR0 + 2] = np.arctan2(np.sin(turn), np.cos(turn))  # wrapped to (-pi, pi]
        k0 = k_floor * floor if floor < np.inf else 0.0
        for r in range(4):
            if jr.ji[j, SOFT]:
                jr.jf[j, LAM + r] *= carry
                jr.jf[j, PEN + r] *= soften
            jr.jf[j, PEN + r] = max(k0, jr.jf[j, PEN + r])


@njit(cache=True, inline="always")
def _side(jr, blocks, x, j, side, k, cx, cy, phi):
    """Side ``side`` of joint ``j``: its point, its arm ``R(phi) r`` and its block's turn
    now, with block ``k`` at the pose ``(cx, cy, phi)`` and any other block at its own pose
    (a soft side where its triangle is, the world's point where it is; no arm, no turn)."""
    kb = jr.ji[j, BLOCK + side]
    if kb < 0:
        px, py = held_point(x, jr.ji, jr.jf, j, side)
        return px, py, 0.0, 0.0, 0.0
    rx0, ry0 = jr.jf[j, ARM + 2 * side], jr.jf[j, ARM + 2 * side + 1]
    if kb == k:
        px, py, ph = cx, cy, phi
    else:
        p = blocks.pose
        px, py, ph = p[kb, 0], p[kb, 1], p[kb, 2]
    co, si = np.cos(ph), np.sin(ph)
    rx, ry = co * rx0 - si * ry0, si * rx0 + co * ry0
    return px + rx, py + ry, rx, ry, ph


@njit(cache=True, inline="always")
def _rows(jr, blocks, x, j, k, cx, cy, phi):
    """Joint ``j``'s constraints with block ``k`` at ``(cx, cy, phi)`` (``k = -1``: every
    block at its pose): the point's ``C``, the forces ``f`` of its point, angle and motor
    rows, their stiffnesses, whether the motor is clamped, and the arms of both sides."""
    pax, pay, rax, ray, pha = _side(jr, blocks, x, j, 0, k, cx, cy, phi)
    pbx, pby, rbx, rby, phb = _side(jr, blocks, x, j, 1, k, cx, cy, phi)
    cx_, cy_ = pax - pbx, pay - pby
    fx, fy, kp = point_force(jr.ji, jr.jf, j, cx_, cy_)
    fa = ka_ = 0.0
    if jr.ji[j, KIND] == WELD:
        ka_ = jr.jf[j, PEN + 2]
        fa = ka_ * (jr.jf[j, ERR0 + 2] + pha - phb) + jr.jf[j, LAM + 2]
    fm = km = 0.0
    clamped = False
    if jr.ji[j, MOTOR]:
        km = jr.jf[j, PEN + 3]
        fm = km * (pha - phb - jr.jf[j, PARAM + 5] * jr.jf[j, PARAM + 1]) + jr.jf[j, LAM + 3]
        bound = jr.jf[j, PARAM + 2]
        if abs(fm) > bound:
            fm = bound if fm > 0.0 else -bound
            clamped = True
    return cx_, cy_, fx, fy, kp, fa, ka_, fm, km, clamped, rax, ray, rbx, rby


@njit(cache=True)
def joint_block(jr, blocks, x, k, cx, cy, phi, acc):
    """Add rigid block ``k``'s joints at the pose ``(cx, cy, phi)`` to its gradient and
    Hessian ``acc`` (g0, g1, g2, a00, a01, a02, a11, a12, a22; see the module docstring)."""
    for p in range(jr.j_start[k], jr.j_start[k + 1]):
        j, side = jr.j_entry[p] // 2, jr.j_entry[p] % 2
        _, _, fx, fy, kp, fa, ka_, fm, km, clamped, rax, ray, rbx, rby = _rows(jr, blocks, x, j, k, cx, cy, phi)
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


@njit(cache=True)
def carry_joint_points(jr, blocks, k):
    """Rigid block ``k`` took a new pose: its sides' points where it holds them now
    (``jr.jf[:, POINT:POINT + 4]``, what the soft vertices' blocks read)."""
    p = blocks.pose
    co, si = np.cos(p[k, 2]), np.sin(p[k, 2])
    for q in range(jr.j_start[k], jr.j_start[k + 1]):
        j, side = jr.j_entry[q] // 2, jr.j_entry[q] % 2
        rx0, ry0 = jr.jf[j, ARM + 2 * side], jr.jf[j, ARM + 2 * side + 1]
        jr.jf[j, POINT + 2 * side] = p[k, 0] + co * rx0 - si * ry0
        jr.jf[j, POINT + 2 * side + 1] = p[k, 1] + si * rx0 + co * ry0


@njit(cache=True, inline="always")
def _energy(f, k):
    return 0.5 * f * f / k if k > 0.0 else 0.0


@njit(cache=True)
def joint_energy(jr, blocks, x, k, cx, cy, phi):
    """Rigid block ``k``'s joints' energy (J) with it at the pose ``(cx, cy, phi)``, up to a
    constant: ``f^2 / 2k`` per row (``lambda C + k C^2 / 2`` and ``lambda^2 / 2k``), a
    clamped motor's continued linearly; a spring's own."""
    e = 0.0
    for p in range(jr.j_start[k], jr.j_start[k + 1]):
        j = jr.j_entry[p] // 2
        cx_, cy_, fx, fy, kp, fa, ka_, fm, km, clamped, _, _, _, _ = _rows(jr, blocks, x, j, k, cx, cy, phi)
        e += joint_point_energy(jr.ji, jr.jf, j, cx_, cy_)
        e += _energy(fa, ka_)
        if jr.ji[j, MOTOR]:
            if clamped:
                # the unclamped force, continued linearly past the bound
                u = (km * (_rows_turn(jr, blocks, j, k, phi) - jr.jf[j, PARAM + 5] * jr.jf[j, PARAM + 1])
                     + jr.jf[j, LAM + 3])
                bound = jr.jf[j, PARAM + 2]
                e += 0.5 * bound * bound / km + bound * (abs(u) - bound) / km
            else:
                e += _energy(fm, km)
    return e


@njit(cache=True, inline="always")
def _rows_turn(jr, blocks, j, k, phi):
    """``phi_a - phi_b`` of joint ``j`` with block ``k`` turned by ``phi``."""
    t = 0.0
    for side in range(2):
        kb = jr.ji[j, BLOCK + side]
        if kb < 0:
            continue
        ph = phi if kb == k else blocks.pose[kb, 2]
        t += ph if side == 0 else -ph
    return t


@njit(cache=True)
def update_joint_rows(jr, blocks, x, beta, k_max, which):
    """The dual step of the joints ``which`` (:data:`RIGID_JOINTS` or :data:`SOFT_JOINTS`)
    at the blocks' poses and the vertices' positions (see the module docstring)."""
    for j in range(jr.ji.shape[0]):
        if (jr.ji[j, SOFT] != 0) != (which == SOFT_JOINTS):
            continue
        cx_, cy_, fx, fy, kp, fa, ka_, fm, km, clamped, _, _, _, _ = _rows(jr, blocks, x, j, -1, 0.0, 0.0, 0.0)
        kind = jr.ji[j, KIND]
        if kind != SPRING:
            jr.jf[j, LAM], jr.jf[j, LAM + 1] = fx, fy
            jr.jf[j, PEN] = min(k_max, kp + beta * np.sqrt(cx_ * cx_ + cy_ * cy_))
        turn = _rows_turn(jr, blocks, j, -1, 0.0)
        if kind == WELD:
            jr.jf[j, LAM + 2] = fa
            jr.jf[j, PEN + 2] = min(k_max, ka_ + beta * abs(jr.jf[j, ERR0 + 2] + turn))
        if jr.ji[j, MOTOR]:
            turn -= jr.jf[j, PARAM + 5] * jr.jf[j, PARAM + 1]
            jr.jf[j, LAM + 3] = fm
            if not clamped:
                jr.jf[j, PEN + 3] = min(k_max, km + beta * abs(turn))


@njit(cache=True)
def joint_totals(jr, blocks, x, h):
    """Add each joint's force and torque on ``a`` over the substep of ``h`` s to the totals ``jf[:, TOTAL:TOTAL + 3]``
    (N s, N m s): after the last dual step, a row's force is its multiplier (a spring's is
    its energy's gradient at the blocks' poses)."""
    for j in range(jr.ji.shape[0]):
        if jr.ji[j, KIND] == SPRING:
            _, _, fx, fy, _, _, _, _, _, _, _, _, _, _ = _rows(jr, blocks, x, j, -1, 0.0, 0.0, 0.0)
        else:
            fx, fy = jr.jf[j, LAM], jr.jf[j, LAM + 1]
        jr.jf[j, TOTAL] -= h * fx
        jr.jf[j, TOTAL + 1] -= h * fy
        jr.jf[j, TOTAL + 2] -= h * ((jr.jf[j, LAM + 2] if jr.ji[j, KIND] == WELD else 0.0)
                                    + (jr.jf[j, LAM + 3] if jr.ji[j, MOTOR] else 0.0))


@njit(cache=True)
def joint_gap(jr, blocks, x):
    """The widest a pin's or weld's points are apart at the blocks' poses (m), over the
    joints of rigid bodies alone in islands without contacts (``jr.island_touch``)."""
    most = 0.0
    for j in range(jr.ji.shape[0]):
        ka = jr.ji[j, BLOCK]
        if jr.ji[j, KIND] == SPRING or jr.ji[j, SOFT] != 0 or ka < 0 or jr.island_touch[jr.island[ka]]:
            continue
        cx_, cy_, _, _, _, _, _, _, _, _, _, _, _, _ = _rows(jr, blocks, x, j, -1, 0.0, 0.0, 0.0)
        most = max(most, np.sqrt(cx_ * cx_ + cy_ * cy_))
    return most

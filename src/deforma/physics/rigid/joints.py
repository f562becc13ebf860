"""Joints between rigid bodies (or a rigid body and the world) inside the rigid solver.

A joint holds a point of body ``a`` on a point of body ``b`` (``b = -1``: a fixed point of
the world), each given in its body's frame about its centre of mass:

- ``PIN``: the two points stay together; the bodies turn freely about them (a hinge). A
  motor may drive ``a``'s spin relative to ``b`` towards ``motor_speed`` with at most
  ``max_torque``.
- ``WELD``: a pin that also keeps the bodies' relative angle.
- ``SPRING``: a zero-length spring and damper between the two points, ``stiffness`` N/m and
  ``damping`` N s/m, solved implicitly within each substep (Catto's soft constraint: the
  impulse solves ``Cdot + (beta / h) C + gamma lambda = 0`` with ``gamma = 1 / (h (c + h k))``,
  ``beta = h k / (c + h k)``), so any stiffness is stable.

Per substep of the rigid solver (:func:`~deforma.physics.rigid.solver.solve_rigid`): the
impulses of the last substep are applied again (warm start), then each Gauss-Seidel pass
solves every joint's velocity constraint before the contacts; after the positions move,
:func:`joint_positions` removes what is left of a pin's or weld's drift, moving the
velocities with the positions (as XPBD does), so that a pendulum keeps its period and swing.

Arrays per joint ``j`` (``J`` joints):

- ``body`` (J, 2) int64: ``a``, ``b`` (rigid-body indices; ``b`` = -1 for the world);
- ``local`` (J, 4) float64: the anchor on ``a`` and on ``b`` in their body frames (m; on
  the world, the world point);
- ``kind`` (J,) int64: ``PIN``, ``WELD`` or ``SPRING``;
- ``param`` (J, 5) float64: the weld's reference angle ``angle_a - angle_b`` (rad), the
  motor speed (rad/s) and its torque bound (N m; ``inf``: none), stiffness, damping;
  ``motor`` (J,) bool: whether the motor is on;
- ``acc`` (J, 4) float64: accumulated impulses of the substep (point x, y in N s, angle,
  motor in N m s), kept between substeps and steps for the warm start;
- ``total`` (J, 3) float64: the point impulse on ``a`` (N s) and the angular impulse on
  ``a`` (N m s) summed over the step: the joint's force and torque times the step.

Units: m, kg, s, rad.
"""

from __future__ import annotations

import math

from numba import njit

PIN, WELD, SPRING = 0, 1, 2
KINDS = {"pin": PIN, "weld": WELD, "spring": SPRING}


@njit(cache=True, inline="always")
def _arm(center, angle, local, k, col):
    """The anchor of side ``k`` (-1: the world) relative to its centre, and its world point."""
    lx, ly = local[col], local[col + 1]
    if k < 0:
        return 0.0, 0.0, lx, ly
    cs, sn = math.cos(angle[k]), math.sin(angle[k])
    rx, ry = cs * lx - sn * ly, sn * lx + cs * ly
    return rx, ry, center[k, 0] + rx, center[k, 1] + ry


@njit(cache=True, inline="always")
def _masses(inv_mass, inv_inertia, k):
    if k < 0:
        return 0.0, 0.0
    return inv_mass[k], inv_inertia[k]


@njit(cache=True, inline="always")
def apply_impulse(vel, omega, inv_mass, inv_inertia, k, rx, ry, px, py, ang, sign):
    """Give rigid body ``k`` (-1: a collider or the world, which nothing moves) the impulse
    ``sign * (px, py)`` (N s) at its arm ``(rx, ry)`` from its centre, and ``sign * ang``
    (N m s) about its centre: the joints' and the contacts' one way to push a body."""
    if k < 0:
        return
    vel[k, 0] += sign * inv_mass[k] * px
    vel[k, 1] += sign * inv_mass[k] * py
    omega[k] += sign * inv_inertia[k] * (rx * py - ry * px + ang)


@njit(cache=True)
def warm_start_joints(center, angle, vel, omega, inv_mass, inv_inertia, body, local, kind, motor, acc):
    """Apply the last substep's joint impulses again (a motor or weld's angular part too)."""
    for j in range(body.shape[0]):
        a, b = body[j, 0], body[j, 1]
        rax, ray, _, _ = _arm(center, angle, local[j], a, 0)
        rbx, rby, _, _ = _arm(center, angle, local[j], b, 2)
        ang = acc[j, 2] + (acc[j, 3] if motor[j] else 0.0)
        apply_impulse(vel, omega, inv_mass, inv_inertia, a, rax, ray, acc[j, 0], acc[j, 1], ang, 1.0)
        apply_impulse(vel, omega, inv_mass, inv_inertia, b, rbx, rby, acc[j, 0], acc[j, 1], ang, -1.0)


@njit(cache=True)
def joint_velocities(center, angle, vel, omega, inv_mass, inv_inertia, body, local, kind, param, motor, acc, h):
    """One Gauss-Seidel pass over the joints' velocity constraints (see the module docstring)."""
    for j in range(body.shape[0]):
        a, b = body[j, 0], body[j, 1]
        ma, ia = _masses(inv_mass, inv_inertia, a)
        mb, ib = _masses(inv_mass, inv_inertia, b)
        rax, ray, pax, pay = _arm(center, angle, local[j], a, 0)
        rbx, rby, pbx, pby = _arm(center, angle, local[j], b, 2)
        wa = omega[a] if a >= 0 else 0.0
        wb = omega[b] if b >= 0 else 0.0
        k_ang = ia + ib
        if motor[j] and k_ang > 0.0:  # the motor: a's spin relative to b towards the speed
            old = acc[j, 3]
            bound = param[j, 2] * h
            lam = min(max(old - ((wa - wb) - param[j, 1]) / k_ang, -bound), bound)
            d = lam - old
            acc[j, 3] = lam
            wa += ia * d
            wb -= ib * d
            if a >= 0:
                omega[a] = wa
            if b >= 0:
                omega[b] = wb
        if kind[j] == WELD and k_ang > 0.0:
            d = -(wa - wb) / k_ang
            acc[j, 2] += d
            if a >= 0:
                omega[a] += ia * d
            if b >= 0:
                omega[b] -= ib * d
            wa = omega[a] if a >= 0 else 0.0
            wb = omega[b] if b >= 0 else 0.0
        # the point: relative velocity of a's anchor to b's
        dvx = (vel[a, 0] - wa * ray if a >= 0 else 0.0) - (vel[b, 0] - wb * rby if b >= 0 else 0.0)
        dvy = (vel[a, 1] + wa * rax if a >= 0 else 0.0) - (vel[b, 1] + wb * rbx if b >= 0 else 0.0)
        k11 = ma + mb + ia * ray * ray + ib * rby * rby
        k12 = -ia * rax * ray - ib * rbx * rby
        k22 = ma + mb + ia * rax * rax + ib * rbx * rbx
        if kind[j] == SPRING:
            stiff, damp = param[j, 3], param[j, 4]
            soft = h * (damp + h * stiff)
            if soft <= 0.0:
                continue
            gamma = 1.0 / soft
            beta = h * stiff / (damp + h * stiff)
            dvx += beta / h * (pax - pbx) + gamma * acc[j, 0]
            dvy += beta / h * (pay - pby) + gamma * acc[j, 1]
            k11 += gamma
            k22 += gamma
        det = k11 * k22 - k12 * k12
        if det <= 0.0:
            continue  # both sides held
        px = -(k22 * dvx - k12 * dvy) / det
        py = -(k11 * dvy - k12 * dvx) / det
        acc[j, 0] += px
        acc[j, 1] += py
        apply_impulse(vel, omega, inv_mass, inv_inertia, a, rax, ray, px, py, 0.0, 1.0)
        apply_impulse(vel, omega, inv_mass, inv_inertia, b, rbx, rby, px, py, 0.0, -1.0)


@njit(cache=True)
def joint_positions(center, angle, vel, omega, inv_mass, inv_inertia, body, local, kind, param, h):
    """Move positions so that every pin's and weld's points meet again and every weld's angle
    is back at its reference (the drift a substep's straight-line motion left), and the
    velocities by the same move over ``h``: the motion is then the chord of the arc the
    joint allows, not its first tangent, whose part across the joint the next substep would
    take away (a pendulum lost 8 % of its energy in 8 s that way, at 1/240 s substeps)."""
    for j in range(body.shape[0]):
        if kind[j] == SPRING:
            continue
        a, b = body[j, 0], body[j, 1]
        ma, ia = _masses(inv_mass, inv_inertia, a)
        mb, ib = _masses(inv_mass, inv_inertia, b)
        if kind[j] == WELD and ia + ib > 0.0:
            err = (angle[a] if a >= 0 else 0.0) - (angle[b] if b >= 0 else 0.0) - param[j, 0]
            d = -err / (ia + ib)
            if a >= 0:
                angle[a] += ia * d
                omega[a] += ia * d / h
            if b >= 0:
                angle[b] -= ib * d
                omega[b] -= ib * d / h
        rax, ray, pax, pay = _arm(center, angle, local[j], a, 0)
        rbx, rby, pbx, pby = _arm(center, angle, local[j], b, 2)
        k11 = ma + mb + ia * ray * ray + ib * rby * rby
        k12 = -ia * rax * ray - ib * rbx * rby
        k22 = ma + mb + ia * rax * rax + ib * rbx * rbx
        det = k11 * k22 - k12 * k12
        if det <= 0.0:
            continue
        cx, cy = pax - pbx, pay - pby
        px = -(k22 * cx - k12 * cy) / det
        py = -(k11 * cy - k12 * cx) / det
        if a >= 0:
            center[a, 0] += ma * px
            center[a, 1] += ma * py
            angle[a] += ia * (rax * py - ray * px)
        if b >= 0:
            center[b, 0] -= mb * px
            center[b, 1] -= mb * py
            angle[b] -= ib * (rbx * py - rby * px)
        apply_impulse(vel, omega, inv_mass, inv_inertia, a, rax, ray, px / h, py / h, 0.0, 1.0)
        apply_impulse(vel, omega, inv_mass, inv_inertia, b, rbx, rby, px / h, py / h, 0.0, -1.0)

"""The rigid stage of a step: after the soft integrator, the rigid bodies take the impulses
soft bodies gave them and advance in the rigid solver (:mod:`deforma.physics.rigid`)."""

from __future__ import annotations

import numpy as np

from ..colliders.response import clear_impulses
from ..colliders.shapes import RECT_HY
from .bodies import RigidSet
from .solver import solve_rigid

#: Rigid substeps per step of at most this long (s), and impulse passes per substep.
RIGID_SUBSTEP = 1 / 240
RIGID_ITERATIONS = 8
#: The rigid substep with joints (s). A hinge's positions are put back on its circle each
#: substep, which takes about (h omega)^2 of the energy there: a 60 degree pendulum lost 10 %
#: of its energy in 8 s at 1/240 s, 2.8 % at 1/960 s; the solver's cost is small beside a
#: soft body's.
JOINT_SUBSTEP = 1 / 960


def rigid_set(model) -> RigidSet:
    """The Model's rigid bodies as arrays (built once per Model)."""
    rs = getattr(model, "_rigid_set", None)
    if rs is None:
        rs = model._rigid_set = RigidSet(model)
    return rs


def outline_edges(rects, rs: RigidSet, first_row: int) -> tuple[np.ndarray, np.ndarray]:
    """The rigid bodies' packed outline edges in their body frames (ax, ay, bx, by, nx, ny),
    and where each body's start: what :func:`~deforma.physics.rigid.solver.place_outlines`
    turns into world rows. Read from rows packed at angle 0 about the rest centre."""
    ptr = np.zeros(len(rs) + 1, np.int64)
    parts = []
    for k in range(len(rs)):
        loops = rs.loops_local[k]
        p = np.concatenate(loops)
        q = np.concatenate([np.roll(lp, -1, axis=0) for lp in loops])
        d = q - p
        length = np.hypot(d[:, 0], d[:, 1])
        parts.append(np.column_stack([p, q, d[:, 1] / length, -d[:, 0] / length]))
        ptr[k + 1] = ptr[k] + len(p)
        assert int(rects[first_row + k, RECT_HY]) == len(p)
    return ptr, (np.concatenate(parts) if parts else np.zeros((0, 6)))


def pack_joints(joints, rs: RigidSet) -> tuple:
    """The joints as the rigid solver's arrays ``(body, local, kind, param, motor, acc,
    total)`` (:mod:`~deforma.physics.rigid.joints`); ``acc`` starts from each joint's warm
    start, ``total`` at zero."""
    n = len(joints)
    where = {int(b): k for k, b in enumerate(rs.bodies)}
    body = np.full((n, 2), -1, np.int64)
    local, kind, param = np.zeros((n, 4)), np.zeros(n, np.int64), np.zeros((n, 5))
    motor, acc = np.zeros(n, np.bool_), np.zeros((n, 4))
    for i, j in enumerate(joints):
        body[i, 0] = where[j.a._index]
        if j.b is not None:
            body[i, 1] = where[j.b._index]
        local[i] = j._local
        kind[i], param[i], motor[i] = j._pack()
        acc[i] = j._acc
    return body, local, kind, param, motor, acc, np.zeros((n, 3))


def begin_joint_forces(world) -> None:
    """Start summing each joint's impulse over a step."""
    for j in world._joints:
        j._impulse[...] = 0.0


def end_joint_forces(world, dt: float) -> None:
    """Each joint's force and torque: its impulse over the step ``dt`` (s), per second."""
    for j in world._joints:
        j._force[...] = j._impulse / dt


def step_rigid_bodies(world, start, state, control, hits, rects, first_row: int, dt: float) -> None:
    """Advance the rigid bodies of ``world`` over the step ``dt`` (s): read their poses from
    ``start``, take the soft bodies' impulses from ``hits``, solve, and write their vertices
    into ``state``. ``rects`` is the packed array the soft integrator used (the rigid rows
    from ``first_row``)."""
    model = world._model
    rs = rigid_set(model)
    center, angle, vel, omega = rs.poses(model, start.x, start.v)
    k = len(rs)
    force = np.zeros((k, 3))
    impulse = np.zeros((k, 3))
    off = model.body_vertex_offsets
    # the soft bodies' side: each vertex a rigid outline pushed took m dv; the body takes -m dv
    # with the moment the vertex's change had (about the origin: where each happened)
    row = hits.dv_collider
    # (a rigid body's own vertices go through the soft kernels' collider response too, at
    # their stand-in positions; what they noted is not an impulse anything took)
    touched = np.flatnonzero((row >= first_row) & ~model.rigid)
    if len(touched):
        m = model.vertex_mass[touched]
        which = row[touched] - first_row
        np.add.at(impulse[:, 0], which, -m * hits.dv[touched, 0])
        np.add.at(impulse[:, 1], which, -m * hits.dv[touched, 1])
        np.add.at(impulse[:, 2], which, -m * hits.dm[touched])
    for n, b in enumerate(rs.bodies):
        sl = slice(off[b], off[b + 1])
        f = np.zeros((off[b + 1] - off[b], 2))
        if control.has_force:
            f += control.force[sl]
        slot = control.grab_slot[sl]
        held = slot >= 0
        if held.any():
            pull = control.grab_pull[slot[held]]
            f[held] += pull[:, 1:3] - pull[:, :1] * start.x[sl][held]
        if f.any():
            r = start.x[sl] - center[n]
            force[n, :2] = f.sum(axis=0)
            force[n, 2] = float((r[:, 0] * f[:, 1] - r[:, 1] * f[:, 0]).sum())
    if rs.edges is None:
        rs.edges = outline_edges(rects, rs, first_row)
    edge_ptr, edges = rs.edges
    friction = np.array([[world._bodies[b].friction, world._bodies[b].static_friction] for b in rs.bodies],
                        dtype=np.float64).reshape(-1, 2)
    substeps = max(1, int(np.ceil(dt / (JOINT_SUBSTEP if world._joints else RIGID_SUBSTEP) - 1e-9)))
    gravity = np.asarray(model.gravity, np.float64)
    inv_mass, inv_inertia = rs.inverse_masses(model)
    joints = pack_joints(world._joints, rs)
    solve_rigid(center, angle, vel, omega, inv_mass, inv_inertia, force, impulse, gravity, rs.outline_ptr,
                rs.outline_local, rs.cache_row, rs.cache_impulse, friction, rects, first_row, edge_ptr, edges, dt,
                substeps, RIGID_ITERATIONS, *joints)
    for j, acc, total in zip(world._joints, joints[5], joints[6]):
        j._acc[...] = acc
        j._impulse += total
    rs.place(model, state.x, state.v, center, angle, vel, omega)
    clear_impulses(hits)

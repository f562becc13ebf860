"""The rigid-body solver: substeps of sequential impulses over the contacts of rigid bodies'
outline vertices with colliders and with each other.

Per substep of ``h`` s:

1. velocities: gravity, the step's applied force and torque, and a share of the impulses
   soft bodies gave (:mod:`deforma.physics.rigid`);
2. the rigid bodies' packed outlines are put at their poses (:func:`place_outlines`);
   every outline vertex inside a collider or another rigid body's outline is a contact,
   with the normal and surface point the collider response would take
   (:func:`~deforma.physics.colliders.geometry.exit_face`);
3. ``iterations`` Gauss-Seidel passes of impulses over the joints
   (:mod:`~deforma.physics.rigid.joints`) and the contacts (Catto's sequential
   impulses): the normal impulse accumulated and kept >= 0 so that no contact pulls, the
   friction impulse accumulated and held within ``static_friction * normal`` while the
   contact sticks, else within ``friction * normal`` (Coulomb, static and dynamic, the rule
   of every other contact in deforma); each pass starts from the impulses of the last
   substep at the same vertex against the same thing (warm start), so a resting stack
   carries its weight from the first pass;
4. positions from the velocities, the joints' drift removed, then one projection pass that removes the overlap left
   beyond ``SLOP`` (a fraction ``BAUMGARTE`` per substep, positions only: it adds no energy).

A collider is the infinite-mass side (its surface velocity, as for soft vertices); two
rigid bodies mix their coefficients as ``sqrt(a * b)``. Units: m, kg, s, rad.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..colliders.geometry import exit_face, n_colliders, point_inside
from ..colliders.shapes import (
    EDGE_NX,
    EDGE_NY,
    OMEGA,
    RECT_CX,
    RECT_CY,
    RECT_FRICTION,
    RECT_HX,
    RECT_STATIC_FRICTION,
    RECT_UX,
    RECT_UY,
    RECT_XMAX,
    RECT_XMIN,
    RECT_YMAX,
    RECT_YMIN,
    VEL_X,
    VEL_Y,
)
from .joints import apply_impulse, joint_positions, joint_velocities, warm_start_joints

SLOP = 5e-4        # m: overlap the projection leaves (a resting contact stays a contact)
BAUMGARTE = 0.5    # share of the overlap beyond SLOP removed per substep
MAX_PUSH = 0.05    # m: the most the projection moves a contact per substep


@njit(cache=True)
def place_outlines(rects, first_row, edge_ptr, edges_local, center, angle, vel, omega):
    """Put the packed outline of every rigid body ``k`` (row ``first_row + k`` of ``rects``
    and its edge rows) at pose ``center[k]``, ``angle[k]``, moving at ``vel[k]``, ``omega[k]``.
    ``edges_local[edge_ptr[k]:edge_ptr[k + 1]]`` are its edges in the body frame (ax, ay, bx,
    by, nx, ny)."""
    for k in range(center.shape[0]):
        r = first_row + k
        cs, sn = math.cos(angle[k]), math.sin(angle[k])
        cx, cy = center[k, 0], center[k, 1]
        rects[r, RECT_CX], rects[r, RECT_CY] = cx, cy
        rects[r, RECT_UX], rects[r, RECT_UY] = cs, sn
        rects[r, VEL_X], rects[r, VEL_Y], rects[r, OMEGA] = vel[k, 0], vel[k, 1], omega[k]
        lox = loy = np.inf
        hix = hiy = -np.inf
        e0 = np.int64(rects[r, RECT_HX])
        for j in range(edge_ptr[k], edge_ptr[k + 1]):
            e = e0 + j - edge_ptr[k]
            for col in (0, 2):
                lx, ly = edges_local[j, col], edges_local[j, col + 1]
                px, py = cx + cs * lx - sn * ly, cy + sn * lx + cs * ly
                rects[e, col], rects[e, col + 1] = px, py
                lox, hix, loy, hiy = min(lox, px), max(hix, px), min(loy, py), max(hiy, py)
            nx, ny = edges_local[j, 4], edges_local[j, 5]
            rects[e, EDGE_NX], rects[e, EDGE_NY] = cs * nx - sn * ny, sn * nx + cs * ny
        rects[r, RECT_XMIN], rects[r, RECT_XMAX], rects[r, RECT_YMIN], rects[r, RECT_YMAX] = lox, hix, loy, hiy


@njit(cache=True, inline="always")
def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


@njit(cache=True)
def _point_velocity(vel, omega, rects, k, row, rx, ry, qx, qy):
    """Velocity of the contact point on side ``k`` (a rigid body; -1: the collider ``row``)."""
    if k >= 0:
        return vel[k, 0] - omega[k] * ry, vel[k, 1] + omega[k] * rx
    w = rects[row, OMEGA]
    return rects[row, VEL_X] - w * (qy - rects[row, RECT_CY]), rects[row, VEL_Y] + w * (qx - rects[row, RECT_CX])


@njit(cache=True)
def solve_rigid(center, angle, vel, omega, inv_mass, inv_inertia, force, impulse, gravity, outline_ptr,
                outline_local, cache_row, cache_impulse, friction, rects, first_row, edge_ptr, edges_local, dt,
                substeps, iterations, j_body, j_local, j_kind, j_param, j_motor, j_acc, j_total):
    """Advance the rigid bodies by ``dt`` s in ``substeps`` substeps (see the module docstring).

    Parameters
    ----------
    center, angle, vel, omega : (K, 2), (K,), (K, 2), (K,) float64
        Poses (m, rad) and velocities (m/s, rad/s), advanced in place.
    inv_mass, inv_inertia : (K,) float64
        1/kg, 1/(kg m^2).
    force : (K, 3) float64
        Applied force (N) and torque about the centre of mass (N m) over the step.
    impulse : (K, 3) float64
        Impulse (N s) and angular impulse about the world's origin (N m s) to take over the
        step (from soft bodies), in equal parts per substep: each part turns the body by its
        moment about where the centre is then, so the angular momentum about any fixed point
        changes by exactly the soft side's loss.
    gravity : (2,) float64
        m/s^2.
    outline_ptr, outline_local : (K + 1,) int64, (No, 2) float64
        Each body's outline vertices in the body frame, relative to its centre of mass.
    cache_row, cache_impulse : (No,) int64, (No, 2) float64
        Warm starts per outline vertex: the row it touched last substep and the normal and
        friction impulse it took; updated.
    friction : (K, 2) float64
        Dynamic and static coefficients of each body against other rigid bodies.
    rects : packed colliders, user colliders first, then one row per rigid body from ``first_row``.
    edge_ptr, edges_local
        The rigid bodies' outline edges in their body frames (see :func:`place_outlines`).
    dt, substeps, iterations : float, int, int
    j_body, j_local, j_kind, j_param, j_motor, j_acc, j_total
        The joints (:mod:`~deforma.physics.rigid.joints`); ``j_acc`` is updated (warm starts)
        and ``j_total`` summed into.

    Returns
    -------
    int
        The number of contacts in the last substep.
    """
    nk = center.shape[0]
    h = dt / substeps
    n_rows = n_colliders(rects)
    n_out = outline_local.shape[0]
    # contacts: body a (its outline vertex o), the other side (body b or -1 and the row),
    # normal, anchors from the centres (world frame), local anchor and normal on b, masses
    c_a = np.empty(n_out, np.int64)
    c_b = np.empty(n_out, np.int64)
    c_o = np.empty(n_out, np.int64)
    c_row = np.empty(n_out, np.int64)
    c_n = np.empty((n_out, 2))
    c_ra = np.empty((n_out, 2))
    c_rb = np.empty((n_out, 2))
    c_q = np.empty((n_out, 2))          # the surface point on b in b's frame (a collider: world)
    c_nb = np.empty((n_out, 2))         # the normal in b's frame (a collider: world)
    c_mass = np.empty((n_out, 2))       # effective mass along the normal and the tangent
    c_mu = np.empty((n_out, 2))         # dynamic, static
    c_j = np.empty((n_out, 2))          # accumulated normal, friction impulse
    body_of = np.empty(n_out, np.int64)
    joined = np.zeros((nk, nk), np.bool_)  # bodies a joint holds together do not collide
    for j in range(j_body.shape[0]):
        if j_body[j, 1] >= 0:
            joined[j_body[j, 0], j_body[j, 1]] = joined[j_body[j, 1], j_body[j, 0]] = True
    for k in range(nk):
        for o in range(outline_ptr[k], outline_ptr[k + 1]):
            body_of[o] = k
    count = 0
    for _ in range(substeps):
        for k in range(nk):
            if inv_mass[k] == 0.0:
                continue  # held (a pinned vertex): nothing moves it
            vel[k, 0] += h * (gravity[0] + force[k, 0] * inv_mass[k]) + impulse[k, 0] * inv_mass[k] / substeps
            vel[k, 1] += h * (gravity[1] + force[k, 1] * inv_mass[k]) + impulse[k, 1] * inv_mass[k] / substeps
            turn = impulse[k, 2] - (center[k, 0] * impulse[k, 1] - center[k, 1] * impulse[k, 0])
            omega[k] += (h * force[k, 2] + turn / substeps) * inv_inertia[k]
        place_outlines(rects, first_row, edge_ptr, edges_local, center, angle, vel, omega)
        # contacts: each outline vertex against the thing it is deepest in
        count = 0
        for o in range(n_out):
            k = body_of[o]
            if inv_mass[k] == 0.0:
                continue  # a held body's corners push nothing: what touches it meets its outline
            cs, sn = math.cos(angle[k]), math.sin(angle[k])
            lx, ly = outline_local[o, 0], outline_local[o, 1]
            rx, ry = cs * lx - sn * ly, sn * lx + cs * ly
            px, py = center[k, 0] + rx, center[k, 1] + ry
            best = -1.0
            best_row = -1
            bnx = bny = bqx = bqy = 0.0
            for r in range(n_rows):
                if r == first_row + k or (r >= first_row and r - first_row < nk and joined[k, r - first_row]):
                    continue
                if not (rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX]
                        and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]):
                    continue
                if not point_inside(rects, r, px, py):
                    continue
                nx, ny, qx, qy, depth = exit_face(rects, r, px, py, px, py)
                if depth > best:
                    best, best_row, bnx, bny, bqx, bqy = depth, r, nx, ny, qx, qy
            if best_row < 0:
                cache_row[o] = -1
                continue
            c = count
            count += 1
            b = best_row - first_row if best_row >= first_row else -1
            c_a[c], c_b[c], c_o[c], c_row[c] = k, b, o, best_row
            c_n[c, 0], c_n[c, 1] = bnx, bny
            c_ra[c, 0], c_ra[c, 1] = rx, ry
            if b >= 0:
                c_rb[c, 0], c_rb[c, 1] = bqx - center[b, 0], bqy - center[b, 1]
                cb, sb = math.cos(angle[b]), math.sin(angle[b])
                c_q[c, 0] = cb * c_rb[c, 0] + sb * c_rb[c, 1]
                c_q[c, 1] = -sb * c_rb[c, 0] + cb * c_rb[c, 1]
                c_nb[c, 0], c_nb[c, 1] = cb * bnx + sb * bny, -sb * bnx + cb * bny
                c_mu[c, 0] = math.sqrt(friction[k, 0] * friction[b, 0])
                c_mu[c, 1] = math.sqrt(friction[k, 1] * friction[b, 1])
            else:
                c_rb[c, 0], c_rb[c, 1] = 0.0, 0.0
                c_q[c, 0], c_q[c, 1] = bqx, bqy
                c_nb[c, 0], c_nb[c, 1] = bnx, bny
                c_mu[c, 0] = rects[best_row, RECT_FRICTION]
                c_mu[c, 1] = rects[best_row, RECT_STATIC_FRICTION]
            tx, ty = -bny, bnx
            kn = inv_mass[k] + inv_inertia[k] * _cross(rx, ry, bnx, bny) ** 2
            kt = inv_mass[k] + inv_inertia[k] * _cross(rx, ry, tx, ty) ** 2
            if b >= 0:
                kn += inv_mass[b] + inv_inertia[b] * _cross(c_rb[c, 0], c_rb[c, 1], bnx, bny) ** 2
                kt += inv_mass[b] + inv_inertia[b] * _cross(c_rb[c, 0], c_rb[c, 1], tx, ty) ** 2
            c_mass[c, 0] = 1.0 / kn
            c_mass[c, 1] = 1.0 / kt
            if cache_row[o] == best_row:  # warm start
                c_j[c, 0], c_j[c, 1] = cache_impulse[o, 0], cache_impulse[o, 1]
                jx = c_j[c, 0] * bnx + c_j[c, 1] * tx
                jy = c_j[c, 0] * bny + c_j[c, 1] * ty
                apply_impulse(vel, omega, inv_mass, inv_inertia, k, rx, ry, jx, jy, 0.0, 1.0)
                apply_impulse(vel, omega, inv_mass, inv_inertia, b, c_rb[c, 0], c_rb[c, 1], jx, jy, 0.0, -1.0)
            else:
                c_j[c, 0] = c_j[c, 1] = 0.0
        warm_start_joints(center, angle, vel, omega, inv_mass, inv_inertia, j_body, j_local, j_kind, j_motor, j_acc)
        for _it in range(iterations):
            joint_velocities(center, angle, vel, omega, inv_mass, inv_inertia, j_body, j_local, j_kind, j_param,
                             j_motor, j_acc, h)
            for c in range(count):
                k, b, row = c_a[c], c_b[c], c_row[c]
                nx, ny = c_n[c, 0], c_n[c, 1]
                tx, ty = -ny, nx
                rx, ry = c_ra[c, 0], c_ra[c, 1]
                sx, sy = c_rb[c, 0], c_rb[c, 1]
                ax_, ay_ = _point_velocity(vel, omega, rects, k, row, rx, ry, 0.0, 0.0)
                bx_, by_ = _point_velocity(vel, omega, rects, b, row, sx, sy, c_q[c, 0], c_q[c, 1])
                dvx, dvy = ax_ - bx_, ay_ - by_
                # normal: no approach, never a pull
                jn_old = c_j[c, 0]
                jn = max(jn_old - (dvx * nx + dvy * ny) * c_mass[c, 0], 0.0)
                d = jn - jn_old
                c_j[c, 0] = jn
                apply_impulse(vel, omega, inv_mass, inv_inertia, k, rx, ry, d * nx, d * ny, 0.0, 1.0)
                apply_impulse(vel, omega, inv_mass, inv_inertia, b, sx, sy, d * nx, d * ny, 0.0, -1.0)
                # friction: stick within static friction, else slide against dynamic friction
                ax_, ay_ = _point_velocity(vel, omega, rects, k, row, rx, ry, 0.0, 0.0)
                bx_, by_ = _point_velocity(vel, omega, rects, b, row, sx, sy, c_q[c, 0], c_q[c, 1])
                vt = (ax_ - bx_) * tx + (ay_ - by_) * ty
                jt_old = c_j[c, 1]
                jt = jt_old - vt * c_mass[c, 1]
                if abs(jt) > c_mu[c, 1] * jn:
                    limit = c_mu[c, 0] * jn
                    jt = min(max(jt, -limit), limit)
                d = jt - jt_old
                c_j[c, 1] = jt
                apply_impulse(vel, omega, inv_mass, inv_inertia, k, rx, ry, d * tx, d * ty, 0.0, 1.0)
                apply_impulse(vel, omega, inv_mass, inv_inertia, b, sx, sy, d * tx, d * ty, 0.0, -1.0)
        for c in range(count):
            o = c_o[c]
            cache_row[o] = c_row[c]
            cache_impulse[o, 0], cache_impulse[o, 1] = c_j[c, 0], c_j[c, 1]
        for j in range(j_body.shape[0]):
            j_total[j, 0] += j_acc[j, 0]
            j_total[j, 1] += j_acc[j, 1]
            j_total[j, 2] += j_acc[j, 2] + (j_acc[j, 3] if j_motor[j] else 0.0)
        for k in range(nk):
            center[k, 0] += h * vel[k, 0]
            center[k, 1] += h * vel[k, 1]
            angle[k] += h * omega[k]
        joint_positions(center, angle, vel, omega, inv_mass, inv_inertia, j_body, j_local, j_kind, j_param, h)
        # the overlap left: a share of it removed by positions alone
        for c in range(count):
            k, b, o = c_a[c], c_b[c], c_o[c]
            cs, sn = math.cos(angle[k]), math.sin(angle[k])
            lx, ly = outline_local[o, 0], outline_local[o, 1]
            rx, ry = cs * lx - sn * ly, sn * lx + cs * ly
            px, py = center[k, 0] + rx, center[k, 1] + ry
            if b >= 0:
                cb, sb = math.cos(angle[b]), math.sin(angle[b])
                sx = cb * c_q[c, 0] - sb * c_q[c, 1]
                sy = sb * c_q[c, 0] + cb * c_q[c, 1]
                qx, qy = center[b, 0] + sx, center[b, 1] + sy
                nx = cb * c_nb[c, 0] - sb * c_nb[c, 1]
                ny = sb * c_nb[c, 0] + cb * c_nb[c, 1]
            else:
                # a collider: its surface point where the contact was found (kinematic ones
                # were moved to the end of the step by the soft integrator)
                sx = sy = 0.0
                qx, qy = c_q[c, 0], c_q[c, 1]
                nx, ny = c_nb[c, 0], c_nb[c, 1]
            gap = (px - qx) * nx + (py - qy) * ny  # < 0: overlap
            err = gap + SLOP
            if err >= 0.0:
                continue
            push = min(-BAUMGARTE * err, MAX_PUSH)
            kn = inv_mass[k] + inv_inertia[k] * _cross(rx, ry, nx, ny) ** 2
            if b >= 0:
                kn += inv_mass[b] + inv_inertia[b] * _cross(sx, sy, nx, ny) ** 2
            lam = push / kn
            center[k, 0] += lam * nx * inv_mass[k]
            center[k, 1] += lam * ny * inv_mass[k]
            angle[k] += lam * _cross(rx, ry, nx, ny) * inv_inertia[k]
            if b >= 0:
                center[b, 0] -= lam * nx * inv_mass[b]
                center[b, 1] -= lam * ny * inv_mass[b]
                angle[b] -= lam * _cross(sx, sy, nx, ny) * inv_inertia[b]
    place_outlines(rects, first_row, edge_ptr, edges_local, center, angle, vel, omega)
    return count

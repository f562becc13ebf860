"""Rigid bodies as blocks of the avbd sweep (Giles, Diaz, Yuksel, "Augmented Vertex Block
Descent", SIGGRAPH 2025: a rigid body is one block of three degrees of freedom).

A rigid body (``Material("rigid")``) keeps its vertices in the State, but in the sweep they
move as one: its block is its pose ``q = (c, phi)``, ``c`` its centre of mass and ``phi`` how
far it has turned since the substep began, and its vertices are placed at

    x_i = c + R(phi) (x_n,i - c_n)

(``c_n`` the centre at the start). Its share of backward Euler's objective is

    M / 2h^2 |c - c~|^2 + I / 2h^2 (phi - phi~)^2 + its grabs + its vertices' contact rows

with ``c~ = c_n + h v + h^2 (g + F / M)`` and ``phi~ = h omega + h^2 tau / I`` (``F``, ``tau``
the applied forces' total and moment): the true mass and moment of inertia of its
triangles (:func:`~deforma.physics.rigid.bodies.triangle_inertia`), not its vertices'
lumped ones. A block's step is one Newton step over ``q``: the rows' gradients and
stiffnesses at its vertices carried by ``J_i = [I | perp(x_i - c)]``, the 3 x 3 system solved,
and a backtracking line search on the objective (the rows are piecewise quadratic: across
their kinks a full step rocked a block on its contacts). Without rows or grabs one step
lands exactly on the inertial pose: a free body keeps its momentum and spin to rounding.

A rigid body's outline is an outline like any body's: its vertices meet other bodies'
edges, and others' vertices its edges, as the same rows (:mod:`~deforma.physics.integrators.avbd.rows`),
so soft and rigid bodies, rigid and rigid, and rigid and colliders share one contact model
and one sweep. After the sweeps its vertices' velocities are the pose's rate, ``v_i =
(c - c_n) / h + (phi / h) perp(x_i - c)``: read back, the body's spin is exactly ``phi / h``.

A rigid body with a pinned vertex is held as a whole (it stands as a collider would).

Units: m, kg, s, rad; N, N/m.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from ...colliders.response import CORNER_NX, CORNER_NY, CORNER_S
from .blocks import outer_block
from ...rigid.joints import SPRING, WELD
from .joints import (
    ERR0,
    FV,
    FW,
    KIND,
    MOTOR,
    RIGID_JOINTS,
    SOFT,
    carry_joint_points,
    held_point,
    joint_block,
    joint_energy,
    joint_point_energy,
    point_force,
    update_joint_rows,
)
from .rows import (
    BOUND,
    K_N,
    K_T,
    LAM_N,
    LAM_T,
    body_row_forces,
    body_row_parts,
    contact_energy,
    contact_forces,
    corner_row_forces,
    corner_row_forces_at,
    freeze_rigid_bounds,
    row_blocks,
    row_energy,
    update_rigid_rows,
)


@njit(cache=True, inline="always")
def newton_step3(a00, a01, a02, a11, a12, a22, g0, g1, g2):
    """``(ok, d0, d1, d2)``: the solution of the symmetric 3 x 3 system ``A d = -g`` by its
    adjugate; ``ok`` False where ``A`` is not positive definite enough to give one."""
    c00 = a11 * a22 - a12 * a12
    c01 = a02 * a12 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    det = a00 * c00 + a01 * c01 + a02 * c02
    if not det > 0.0:
        return False, 0.0, 0.0, 0.0
    c11 = a00 * a22 - a02 * a02
    c12 = a01 * a02 - a00 * a12
    c22 = a00 * a11 - a01 * a01
    return (True, -(c00 * g0 + c01 * g1 + c02 * g2) / det, -(c01 * g0 + c11 * g1 + c12 * g2) / det,
            -(c02 * g0 + c12 * g1 + c22 * g2) / det)


@njit(cache=True, inline="always")
def _inertia_change(sm, ux, uy, ru, rxu, dx, dy, th):
    """How the inertia's energy ``1/2 sum m |c + d + R(th) r - y|^2`` of a body (``r`` its
    vertices about their centre ``c``, weighted by ``m``) changes when it is shifted by ``d``
    and turned by ``th``: ``1/2 M |d|^2 + d . sum m u + (cos th - 1) sum m r . u + sin th sum
    m r x u`` with ``u = c - y`` (``sum m r = 0`` drops the cross term). ``ux, uy, ru, rxu``
    are those sums, ``sm`` is ``M``."""
    return 0.5 * sm * (dx * dx + dy * dy) + dx * ux + dy * uy - 2.0 * np.sin(0.5 * th) ** 2 * ru + np.sin(th) * rxu


@njit(cache=True)
def rigid_correction(x, x_n, y, mass_h2, inv_mass, body_start, grab_slot, grab_pull, rs):
    """Move each body as a whole by the Newton step of the objective over its rigid motions.

    A vertex sweep moves a stiff body's rigid modes slowly: each vertex is held by its
    elements (stiffness ~ E) while the inertia pulls with only ``m / h^2``, so a block
    sliding down a frictionless slope took 2 % of ``g sin a`` in ten sweeps. Over a rigid
    motion (a translation ``d`` and a turn ``theta`` about the centre of mass) the elements'
    energy does not change, so the objective there is the inertia's, the grabs' and the
    contact rows' alone: its gradient ``(sum g_i, sum r_i x g_i)`` and 3 x 3 Hessian ``sum
    J_i^T H_i J_i`` (``J_i = [I | perp(r_i)]``) cost one pass over the vertices, and one
    Newton step solves the rigid modes as well as the iterate allows. Without outside
    forces it makes ``sum m (x - y) = 0``: the step keeps the body's momentum. A body with a
    pinned vertex does not move as a whole. Its joints take part as rows on a point of the
    body (their triangles move with it; their other sides stay): without them, a soft link
    hinged to another hung from its three joint vertices while the sweeps carried its weight
    to them ring by ring, and the multipliers, driven by what that left, flailed the links.

    The line search's inertia term is closed-form (:func:`_inertia_change`), from sums the
    gradient's pass gathers, so each trial visits only the vertices with a row or a grab:
    visiting them all, this step took 17 % of the 48-body heap's time."""
    n = x.shape[0]
    act = np.empty(n, np.int64)  # per body, its vertices with a row or a grab, at act[lo:lo + count]
    zeros = np.zeros(n)  # the rows' and grabs' energy alone (the inertia's is closed-form)
    for body in range(body_start.shape[0] - 1):
        lo, hi = body_start[body], body_start[body + 1]
        sm = cx = cy = 0.0
        pinned = False
        joined = False
        for i in range(lo, hi):
            if inv_mass[i] == 0.0:
                pinned = True
                break
            joined = joined or rs.jv[i + 1] > rs.jv[i]
            m = mass_h2[i]
            sm += m
            cx += m * x[i, 0]
            cy += m * x[i, 1]
        if pinned or sm == 0.0:
            continue
        cx /= sm
        cy /= sm
        g0 = g1 = g2 = 0.0
        a00 = a01 = a02 = a11 = a12 = a22 = 0.0
        e_in = ux = uy = ru = rxu = 0.0  # the inertia's energy, sum m u, sum m r.u, sum m r x u (u = c - y)
        listed = lo
        for i in range(lo, hi):
            # the rows' gradient where they are, and their stiffness whether they push now or
            # not: a row that starts to push within the step bounds the step (with only the
            # active rows a resting block rocked on its warm-started contacts)
            gx, gy, hxx, hxy, hyy = outer_block(x, y, i, mass_h2, grab_slot, grab_pull)
            if rs.rowed[i]:
                ex, ey, exx, exy, eyy = row_blocks(x, x_n, i, rs, True)
                gx += ex
                gy += ey
                hxx += exx
                hxy += exy
                hyy += eyy
            if rs.rowed[i] or grab_slot[i] >= 0:
                act[listed] = i
                listed += 1
            # J = [[1, 0, -ry], [0, 1, rx]]
            rx, ry = x[i, 0] - cx, x[i, 1] - cy
            m = mass_h2[i]
            wx, wy = cx - y[i, 0], cy - y[i, 1]
            e_in += 0.5 * m * ((rx + wx) ** 2 + (ry + wy) ** 2)
            ux += m * wx
            uy += m * wy
            ru += m * (rx * wx + ry * wy)
            rxu += m * (rx * wy - ry * wx)
            g0 += gx
            g1 += gy
            g2 += rx * gy - ry * gx
            a00 += hxx
            a01 += hxy
            a11 += hyy
            a02 += -hxx * ry + hxy * rx
            a12 += -hxy * ry + hyy * rx
            a22 += hxx * ry * ry - 2.0 * hxy * rx * ry + hyy * rx * rx
        if joined:
            # its joints' point rows, each as a point of the body: J = [I | perp(p - c)]
            for i in range(lo, hi):
                for p in range(rs.jv[i], rs.jv[i + 1]):
                    code = rs.jv[p]
                    if code % 3:
                        continue
                    j, side = code // 6, (code // 3) % 2
                    pax, pay = held_point(x, rs.ji, rs.jf, j, 0)
                    pbx, pby = held_point(x, rs.ji, rs.jf, j, 1)
                    fx, fy, kp = point_force(rs.ji, rs.jf, j, pax - pbx, pay - pby)
                    sg = 1.0 if side == 0 else -1.0
                    rx, ry = (pax - cx, pay - cy) if side == 0 else (pbx - cx, pby - cy)
                    g0 += sg * fx
                    g1 += sg * fy
                    g2 += sg * (rx * fy - ry * fx)
                    a00 += kp
                    a11 += kp
                    a02 += -kp * ry
                    a12 += kp * rx
                    a22 += kp * (rx * rx + ry * ry) + abs(fx * rx) + abs(fy * ry)
        # solve the 3 x 3 system A d = -g (symmetric positive definite: A includes sum m / h^2)
        ok, dx, dy, th = newton_step3(a00, a01, a02, a11, a12, a22, g0, g1, g2)
        if not ok:
            continue
        # Backtracking on the objective: the rows are piecewise quadratic, and a full Newton
        # step across their kinks rocked a block on the floor from step to step until it
        # walked off sideways. The turn is exact (a rotation, not its linearisation, leaves
        # the elements unstrained, so they need no part in the test).
        slope = g0 * dx + g1 * dy + g2 * th
        if not slope < 0.0:
            continue
        e0 = e_in + rigid_energy(x, x_n, y, zeros, act, lo, listed, lo, hi, grab_slot, grab_pull, rs, cx, cy,
                                 0.0, 0.0, 0.0)
        t = 1.0
        while t > 1e-3:
            e1 = e_in + _inertia_change(sm, ux, uy, ru, rxu, t * dx, t * dy, t * th) + rigid_energy(
                x, x_n, y, zeros, act, lo, listed, lo, hi, grab_slot, grab_pull, rs, cx, cy, t * dx, t * dy, t * th)
            if e1 <= e0 + 1e-4 * t * slope + 1e-12 * abs(e0):  # (rounding: a step too small to measure is taken)
                break
            t *= 0.5
        if t <= 1e-3:
            continue
        co, si = np.cos(t * th), np.sin(t * th)
        for i in range(lo, hi):
            rx, ry = x[i, 0] - cx, x[i, 1] - cy
            x[i, 0] = cx + t * dx + co * rx - si * ry
            x[i, 1] = cy + t * dy + si * rx + co * ry


@njit(cache=True, inline="always")
def _moved(x, v, lo, hi, cx, cy, dx, dy, co, si):
    """Vertex ``v`` turned about ``(cx, cy)`` and shifted if it is one of ``lo:hi``."""
    if lo <= v < hi:
        ux, uy = x[v, 0] - cx, x[v, 1] - cy
        return cx + dx + co * ux - si * uy, cy + dy + si * ux + co * uy
    return x[v, 0], x[v, 1]


@njit(cache=True, inline="always")
def _soft_joint_energy(x, jv, ji, jf, i, lo, hi, cx, cy, dx, dy, co, si):
    """The energy (J) of the soft bodies' joints whose triangle vertex ``i`` is the first of
    (``jv``: :class:`~deforma.physics.integrators.avbd.rows.RowSet`'s), each side once, with
    the vertices ``lo:hi`` moved as :func:`_moved` moves them."""
    e = 0.0
    for p in range(jv[i], jv[i + 1]):
        code = jv[p]
        if code % 3:
            continue
        j, side = code // 6, (code // 3) % 2
        px, py = 0.0, 0.0
        for slot in range(3):
            vx, vy = _moved(x, ji[j, FV + 3 * side + slot], lo, hi, cx, cy, dx, dy, co, si)
            px += jf[j, FW + 3 * side + slot] * vx
            py += jf[j, FW + 3 * side + slot] * vy
        ox, oy = held_point(x, ji, jf, j, 1 - side)
        sg = 1.0 if side == 0 else -1.0
        e += joint_point_energy(ji, jf, j, sg * (px - ox), sg * (py - oy))
    return e


@njit(cache=True)
def rigid_energy(x, x_n, y, mass_h2, verts, p0, p1, lo, hi, grab_slot, grab_pull, rs, cx, cy, dx, dy, th):
    """The objective's inertia, grab and contact-row part (J) over the vertices ``verts[p0:p1]``
    of the body ``lo:hi``, with the body moved as a whole: turned by ``th`` about ``(cx, cy)``
    and shifted by ``(dx, dy)`` (its other vertices add nothing: no rows, no grab, no mass).
    One loop with no helper taking the rows: Numba counts a reference to each of their
    arrays at every hand-over, and a helper per vertex made the rigid blocks' sweep twice as
    slow."""
    co, si = np.cos(th), np.sin(th)
    e = 0.0
    for q in range(p0, p1):
        i = verts[q]
        rx, ry = x[i, 0] - cx, x[i, 1] - cy
        px = cx + dx + co * rx - si * ry
        py = cy + dy + si * rx + co * ry
        e += 0.5 * mass_h2[i] * ((px - y[i, 0]) ** 2 + (py - y[i, 1]) ** 2)
        s = grab_slot[i]
        if s >= 0:
            tx, ty = grab_pull[s, 1] / grab_pull[s, 0], grab_pull[s, 2] / grab_pull[s, 0]
            e += 0.5 * grab_pull[s, 0] * ((px - tx) ** 2 + (py - ty) ** 2)
        k = rs.vertex_row[i]
        if k >= 0:
            e += contact_energy(px, py, x_n, i, rs.planes, rs.rows, k)
        # body rows, each once (at its first vertex in the body), with its vertices in the
        # body moved and the others where they are
        for p in range(rs.b_start[i], rs.b_start[i + 1]):
            c = rs.b_entry[p] // 3
            ip, ia, ib, s, nx, ny, target = body_row_parts(rs.bidx, rs.bgeo, c)
            first = ip if lo <= ip < hi else (ia if lo <= ia < hi else ib)
            if first != i:
                continue
            p0x, p0y = _moved(x, ip, lo, hi, cx, cy, dx, dy, co, si)
            p1x, p1y = _moved(x, ia, lo, hi, cx, cy, dx, dy, co, si)
            p2x, p2y = _moved(x, ib, lo, hi, cx, cy, dx, dy, co, si)
            ca = 1.0 - s
            gap = (p0x - ca * p1x - s * p2x) * nx + (p0y - ca * p1y - s * p2y) * ny - target
            st = rs.bstate
            fn = max(0.0, st[c, LAM_N] - st[c, K_N] * gap)
            rx = (p0x - x_n[ip, 0]) - ca * (p1x - x_n[ia, 0]) - s * (p2x - x_n[ib, 0])
            ry = (p0y - x_n[ip, 1]) - ca * (p1y - x_n[ia, 1]) - s * (p2y - x_n[ib, 1])
            ft = st[c, LAM_T] - st[c, K_T] * (-rx * ny + ry * nx)
            e += row_energy(fn, ft, st[c, K_N], st[c, K_T], st[c, BOUND])
        # corner rows, each once (at its first end in the body)
        for p in range(rs.c_start[i], rs.c_start[i + 1]):
            c = rs.c_entry[p] // 2
            ia, ib = rs.cpairs[c, 0], rs.cpairs[c, 1]
            if ia != i and lo <= ia < hi:
                continue
            pax, pay = _moved(x, ia, lo, hi, cx, cy, dx, dy, co, si)
            pbx, pby = _moved(x, ib, lo, hi, cx, cy, dx, dy, co, si)
            st = rs.cstate
            fn, ft, _, _, _ = corner_row_forces_at(pax, pay, pbx, pby, x_n[ia, 0], x_n[ia, 1], x_n[ib, 0], x_n[ib, 1],
                                                   rs.cf, st, c)
            e += row_energy(fn, ft, st[c, K_N], st[c, K_T], st[c, BOUND])
        if rs.jv[i + 1] > rs.jv[i]:  # a soft body's joints
            e += _soft_joint_energy(x, rs.jv, rs.ji, rs.jf, i, lo, hi, cx, cy, dx, dy, co, si)
    return e


#: The rigid bodies of a Model as the sweep reads them: vertex ranges ``lo``, ``hi`` (K,),
#: mass (kg) and moment of inertia about the centre of mass (kg m^2) (K,), ``held`` (K,)
#: (a pinned vertex), and per substep the start centre ``c_n`` (K, 2), the inertial target
#: ``target`` (K, 3: c~, phi~), the pose ``pose`` (K, 3: c, phi) and the velocities it
#: ended the substep with, ``rate`` (K, 3: m/s, m/s, rad/s), the farthest vertex from the
#: centre ``radius`` (K,, m), and the vertices with a contact row or a grab, body by body, as
#: CSR ``act_start`` (K + 1,), ``act`` (the sweep moves only those; :func:`rigid_active`).
#: For BDF2 (:func:`rigid_second_order`): the velocities at the start ``v_n`` (K, 3), the
#: outside accelerations ``load`` (K, 3: gravity and applied forces, m/s^2, rad/s^2), the
#: step each block's inertia takes this substep ``h_eff`` (K,: ``h``, or ``2h/3`` for
#: BDF2), and the last substep's start ``prev`` (K, 6: c, turn over it, velocities), how it
#: ended ``end`` (K, 6: c, 0, velocities) and its length ``hist`` (K,; 0: no history).
RigidBlocks = namedtuple("RigidBlocks", ["lo", "hi", "mass", "inertia", "held", "c_n", "target", "pose", "rate",
                                         "radius", "act_start", "act", "v_n", "load", "h_eff", "prev", "end", "hist"])


def rigid_blocks(model, rigid_set) -> RigidBlocks:
    """The rigid bodies of ``model`` as blocks (``rigid_set``: its
    :class:`~deforma.physics.rigid.bodies.RigidSet`)."""
    off = model.body_vertex_offsets
    bodies = rigid_set.bodies
    lo, hi = off[bodies].astype(np.int64), off[bodies + 1].astype(np.int64)
    held = np.array([model.pinned[a:b].any() for a, b in zip(lo, hi)], np.bool_)
    # the vertices' lumped masses sum to the body's (density times area): its momentum is
    # theirs
    mass = np.array([model.vertex_mass[a:b].sum() for a, b in zip(lo, hi)], np.float64)
    k = len(bodies)
    return RigidBlocks(lo, hi, mass, rigid_set.inertia.astype(np.float64), held, np.zeros((k, 2)),
                       np.zeros((k, 3)), np.zeros((k, 3)), np.zeros((k, 3)), np.zeros(k), np.zeros(k + 1, np.int64),
                       np.zeros(int((hi - lo).sum()), np.int64), np.zeros((k, 3)), np.zeros((k, 3)), np.zeros(k),
                       np.zeros((k, 6)), np.zeros((k, 6)), np.zeros(k))


@njit(cache=True)
def rigid_active(blocks, rowed, grab_slot):
    """List each rigid body's vertices that have a contact row or a grab this substep
    (``blocks.act``): the sweep's blocks read and move only those (a box of 16 vertices
    resting on another has 3 to 6), and :func:`rigid_place` puts every vertex at its pose
    at the end."""
    n = 0
    for k in range(blocks.lo.shape[0]):
        blocks.act_start[k] = n
        for i in range(blocks.lo[k], blocks.hi[k]):
            if rowed[i] or grab_slot[i] >= 0:
                blocks.act[n] = i
                n += 1
    blocks.act_start[blocks.lo.shape[0]] = n


@njit(cache=True, inline="always")
def _place(x, x_n, a, b, cnx, cny, cx, cy, phi):
    """Put vertices ``a:b`` at the pose ``(cx, cy, phi)`` from where they began, about ``(cnx, cny)``."""
    co, si = np.cos(phi), np.sin(phi)
    for i in range(a, b):
        rx, ry = x_n[i, 0] - cnx, x_n[i, 1] - cny
        x[i, 0] = cx + co * rx - si * ry
        x[i, 1] = cy + si * rx + co * ry


@njit(cache=True, inline="always")
def _place_listed(x, x_n, act, p0, p1, cnx, cny, cx, cy, phi):
    """:func:`_place` for the vertices ``act[p0:p1]`` only."""
    co, si = np.cos(phi), np.sin(phi)
    for q in range(p0, p1):
        i = act[q]
        rx, ry = x_n[i, 0] - cnx, x_n[i, 1] - cny
        x[i, 0] = cx + co * rx - si * ry
        x[i, 1] = cy + si * rx + co * ry


@njit(cache=True, inline="always")
def centre_velocity_spin(x, v, mass, a, b):
    """``(M, cx, cy, vx, vy, omega)``: the mass of vertices ``a:b``, their centre of mass,
    its velocity and the vertices' spin about it (angular momentum over moment of inertia;
    0 for a single vertex)."""
    sm = cx = cy = px = py = 0.0
    for i in range(a, b):
        m = mass[i]
        sm += m
        cx += m * x[i, 0]
        cy += m * x[i, 1]
        px += m * v[i, 0]
        py += m * v[i, 1]
    cx, cy, vx, vy = cx / sm, cy / sm, px / sm, py / sm
    moment = spin = 0.0
    for i in range(a, b):
        m = mass[i]
        rx, ry = x[i, 0] - cx, x[i, 1] - cy
        moment += m * (rx * rx + ry * ry)
        spin += m * (rx * (v[i, 1] - vy) - ry * (v[i, 0] - vx))
    return sm, cx, cy, vx, vy, (spin / moment if moment > 0.0 else 0.0)


@njit(cache=True)
def rigid_targets(x, v, x_n, y, vertex_mass, blocks, gx, gy, keep, force, has_force, h):
    """Start a substep for the rigid bodies (after :func:`~deforma.physics.integrators.avbd.solver.predict`,
    which left their vertices where they were): each body's centre ``c_n``, its inertial
    target (``blocks.target``), its vertices' targets ``y`` at that pose (what the collision
    stage sees of its motion), and its pose started where its velocity alone takes it."""
    h2 = h * h
    for k in range(blocks.lo.shape[0]):
        a, b = blocks.lo[k], blocks.hi[k]
        _, cx, cy, vx, vy, omega = centre_velocity_spin(x_n, v, vertex_mass, a, b)
        fx = fy = tau = 0.0
        if has_force:
            for i in range(a, b):
                fx += force[i, 0]
                fy += force[i, 1]
                tau += (x_n[i, 0] - cx) * force[i, 1] - (x_n[i, 1] - cy) * force[i, 0]
        blocks.c_n[k, 0], blocks.c_n[k, 1] = cx, cy
        blocks.v_n[k, 0], blocks.v_n[k, 1], blocks.v_n[k, 2] = vx, vy, omega
        blocks.load[k, 0] = gx + fx / blocks.mass[k]
        blocks.load[k, 1] = gy + fy / blocks.mass[k]
        blocks.load[k, 2] = tau / blocks.inertia[k]
        blocks.h_eff[k] = h
        reach = 0.0
        for i in range(a, b):
            reach = max(reach, (x_n[i, 0] - cx) ** 2 + (x_n[i, 1] - cy) ** 2)
        blocks.radius[k] = np.sqrt(reach)
        t = blocks.target
        p = blocks.pose
        if blocks.held[k]:
            t[k, 0], t[k, 1], t[k, 2] = cx, cy, 0.0
        else:
            t[k, 0] = cx + h * keep * vx + h2 * keep * (gx + fx / blocks.mass[k])
            t[k, 1] = cy + h * keep * vy + h2 * keep * (gy + fy / blocks.mass[k])
            t[k, 2] = h * keep * omega + h2 * keep * tau / blocks.inertia[k]
        _place(y, x_n, a, b, cx, cy, t[k, 0], t[k, 1], t[k, 2])
        if blocks.held[k]:
            p[k, 0], p[k, 1], p[k, 2] = cx, cy, 0.0
        else:
            p[k, 0], p[k, 1], p[k, 2] = cx + h * keep * vx, cy + h * keep * vy, h * keep * omega
        _place(x, x_n, a, b, cx, cy, p[k, 0], p[k, 1], p[k, 2])


@njit(cache=True, inline="always")
def _inertia_energy(blocks, k, cx, cy, phi, inv_h2):
    t = blocks.target
    return 0.5 * inv_h2 * (blocks.mass[k] * ((cx - t[k, 0]) ** 2 + (cy - t[k, 1]) ** 2)
                           + blocks.inertia[k] * (phi - t[k, 2]) ** 2)


@njit(cache=True, inline="always")
def _add_row(acc, fn, ft, kn, kt, bound, nx, ny, w, wr_n, wr_t):
    """Add a row to a rigid block's gradient and Hessian ``acc`` (g0, g1, g2, a00, a01, a02,
    a11, a12, a22): its normal force ``fn``, unclamped friction ``ft`` bounded by ``bound``,
    penalties, normal ``n``, and how the body's pose moves its distance: ``w`` (the sum of
    its vertices' weights in the row) along ``n``, and ``wr_n``, ``wr_t`` the weighted moments
    ``sum w r x n`` and ``sum w r x t`` (``r`` from the centre, ``t = perp(n)``). The
    normal stiffness counts whether the row pushes now or not (a row that starts to push
    within the step bounds it), the friction's only while it sticks."""
    tx, ty = -ny, nx
    jn0, jn1, jn2 = w * nx, w * ny, wr_n
    jt0, jt1, jt2 = w * tx, w * ty, wr_t
    if fn <= 0.0:
        fn = ft = kt = 0.0
    elif abs(ft) >= bound:
        ft = bound if ft > 0.0 else -bound
        kt = 0.0
    acc[0] -= fn * jn0 + ft * jt0
    acc[1] -= fn * jn1 + ft * jt1
    acc[2] -= fn * jn2 + ft * jt2
    acc[3] += kn * jn0 * jn0 + kt * jt0 * jt0
    acc[4] += kn * jn0 * jn1 + kt * jt0 * jt1
    acc[5] += kn * jn0 * jn2 + kt * jt0 * jt2
    acc[6] += kn * jn1 * jn1 + kt * jt1 * jt1
    acc[7] += kn * jn1 * jn2 + kt * jt1 * jt2
    acc[8] += kn * jn2 * jn2 + kt * jt2 * jt2


@njit(cache=True, inline="always")
def _share(x, v, a, b, w, cx, cy, nx, ny, sums):
    """Add vertex ``v``'s weight ``w`` in a row to ``sums`` (w, w r x n, w r x t) if it is one
    of the body's ``a:b``."""
    if a <= v < b:
        rx, ry = x[v, 0] - cx, x[v, 1] - cy
        sums[0] += w
        sums[1] += w * (rx * ny - ry * nx)
        sums[2] += w * (rx * nx + ry * ny)  # r x t with t = (-ny, nx)


@njit(cache=True)
def block_rows(x, x_n, a, b, act, p0, p1, cx, cy, grab_slot, grab_pull, rs, acc):
    """The gradient and Hessian over a rigid body's pose (vertices ``a:b``, centre ``(cx,
    cy)``, those with a row or a grab ``act[p0:p1]``) of its grabs and contact rows, into
    ``acc[:9]`` (see :func:`_add_row`), and their energy where the body is (J, what
    :func:`rigid_energy` gives for no move) into ``acc[9]``: the line search's start, from the
    same pass over the rows (a pass of its own was a third of the pyramid's step). A row between
    two of its own vertices (an edge of its outline) is counted once with the moments of
    both: summed vertex by vertex, its stiffness lost the cross terms and a box met on an
    edge's middle took half of it."""
    for j in range(10):
        acc[j] = 0.0
    sums = np.zeros(3)
    e = 0.0
    for q in range(p0, p1):
        i = act[q]
        s = grab_slot[i]
        rx, ry = x[i, 0] - cx, x[i, 1] - cy
        if rs.jv[i + 1] > rs.jv[i]:  # a soft body's joints: their energy alone (the gradient is the joint's block's)
            e += _soft_joint_energy(x, rs.jv, rs.ji, rs.jf, i, a, b, cx, cy, 0.0, 0.0, 1.0, 0.0)
        if s >= 0:  # a zero-length spring of strength S to the target
            k = grab_pull[s, 0]
            tx, ty = grab_pull[s, 1] / k, grab_pull[s, 2] / k
            e += 0.5 * k * ((x[i, 0] - tx) ** 2 + (x[i, 1] - ty) ** 2)
            gx, gy = k * x[i, 0] - grab_pull[s, 1], k * x[i, 1] - grab_pull[s, 2]
            acc[0] += gx
            acc[1] += gy
            acc[2] += rx * gy - ry * gx
            acc[3] += k
            acc[5] += -k * ry
            acc[6] += k
            acc[7] += k * rx
            acc[8] += k * (rx * rx + ry * ry)
        if not rs.rowed[i]:
            continue
        k = rs.vertex_row[i]
        if k >= 0:  # against a collider: this vertex alone
            fn, ft, _, _, _ = contact_forces(x, x_n, i, rs.planes, rs.rows, k)
            nx, ny = rs.planes[k, 0], rs.planes[k, 1]
            st = rs.rows
            e += row_energy(fn, ft, st[k, K_N], st[k, K_T], st[k, BOUND])
            _add_row(acc, fn, ft, st[k, K_N], st[k, K_T], st[k, BOUND], nx, ny, 1.0, rx * ny - ry * nx,
                     rx * nx + ry * ny)
        for p in range(rs.b_start[i], rs.b_start[i + 1]):
            c = rs.b_entry[p] // 3
            ip, ia, ib, s, nx, ny, target = body_row_parts(rs.bidx, rs.bgeo, c)
            if (ip if a <= ip < b else (ia if a <= ia < b else ib)) != i:
                continue  # each row once, at its first vertex in the body
            sums[0] = sums[1] = sums[2] = 0.0
            _share(x, ip, a, b, 1.0, cx, cy, nx, ny, sums)
            _share(x, ia, a, b, -(1.0 - s), cx, cy, nx, ny, sums)
            _share(x, ib, a, b, -s, cx, cy, nx, ny, sums)
            fn, ft, _, _, _ = body_row_forces(x, x_n, ip, ia, ib, s, nx, ny, target, rs.bgeo, rs.bstate, c)
            st = rs.bstate
            e += row_energy(fn, ft, st[c, K_N], st[c, K_T], st[c, BOUND])
            _add_row(acc, fn, ft, st[c, K_N], st[c, K_T], st[c, BOUND], nx, ny, sums[0], sums[1], sums[2])
        for p in range(rs.c_start[i], rs.c_start[i + 1]):
            c = rs.c_entry[p] // 2
            ia, ib = rs.cpairs[c, 0], rs.cpairs[c, 1]
            if (ia if a <= ia < b else ib) != i:
                continue
            s = rs.cf[c, CORNER_S]
            nx, ny = rs.cf[c, CORNER_NX], rs.cf[c, CORNER_NY]
            sums[0] = sums[1] = sums[2] = 0.0
            _share(x, ia, a, b, 1.0 - s, cx, cy, nx, ny, sums)
            _share(x, ib, a, b, s, cx, cy, nx, ny, sums)
            fn, ft, _, _, _ = corner_row_forces(x, x_n, ia, ib, rs.cf, rs.cstate, c)
            st = rs.cstate
            e += row_energy(fn, ft, st[c, K_N], st[c, K_T], st[c, BOUND])
            _add_row(acc, fn, ft, st[c, K_N], st[c, K_T], st[c, BOUND], nx, ny, sums[0], sums[1], sums[2])
    acc[9] = e


@njit(cache=True)
def rigid_sweep(x, x_n, zeros, blocks, grab_slot, grab_pull, rs, jr, h, joined_only):
    """One Newton step with a line search per rigid body, in turn (see the module
    docstring), over the vertices with a row or a grab (:func:`rigid_active`) and its joints
    (``jr``: :class:`~deforma.physics.integrators.avbd.joints.JointRows`; with
    ``joined_only``, only the bodies with joints in islands without contacts). ``zeros``
    (N,): no mass per vertex (the body's own inertia replaces its vertices'). Returns the
    largest squared vertex move (m^2)."""
    most = 0.0
    acc = np.zeros(10)
    act, act_start = blocks.act, blocks.act_start
    for k in range(blocks.lo.shape[0]):
        if blocks.held[k] or (joined_only and (jr.j_start[k + 1] == jr.j_start[k] or jr.island_touch[jr.island[k]])):
            continue
        inv_h2 = 1.0 / (blocks.h_eff[k] * blocks.h_eff[k])
        a, b = blocks.lo[k], blocks.hi[k]
        p0, p1 = act_start[k], act_start[k + 1]
        p, t = blocks.pose, blocks.target
        cx, cy, phi = p[k, 0], p[k, 1], p[k, 2]
        m, inertia = blocks.mass[k] * inv_h2, blocks.inertia[k] * inv_h2
        g0 = m * (cx - t[k, 0])
        g1 = m * (cy - t[k, 1])
        g2 = inertia * (phi - t[k, 2])
        block_rows(x, x_n, a, b, act, p0, p1, cx, cy, grab_slot, grab_pull, rs, acc)
        joined = jr.j_start[k + 1] > jr.j_start[k]
        if joined:
            joint_block(jr, blocks, x, k, cx, cy, phi, acc)
        g0 += acc[0]
        g1 += acc[1]
        g2 += acc[2]
        a00, a01, a02, a11, a12, a22 = m + acc[3], acc[4], acc[5], m + acc[6], acc[7], inertia + acc[8]
        ok, dx, dy, th = newton_step3(a00, a01, a02, a11, a12, a22, g0, g1, g2)
        if not ok:
            continue
        slope = g0 * dx + g1 * dy + g2 * th
        if not slope < 0.0:
            continue
        step = 1.0
        if p1 > p0 or joined:  # rows, grabs or joints: backtrack on the objective (else it is quadratic: exact)
            e0 = _inertia_energy(blocks, k, cx, cy, phi, inv_h2) + acc[9]
            if joined:
                e0 += joint_energy(jr, blocks, x, k, cx, cy, phi)
            while step > 1e-3:
                e1 = _inertia_energy(blocks, k, cx + step * dx, cy + step * dy, phi + step * th, inv_h2) + rigid_energy(
                    x, x_n, x_n, zeros, act, p0, p1, a, b, grab_slot, grab_pull, rs, cx, cy, step * dx, step * dy,
                    step * th)
                if joined:
                    e1 += joint_energy(jr, blocks, x, k, cx + step * dx, cy + step * dy, phi + step * th)
                if e1 <= e0 + 1e-4 * step * slope + 1e-12 * abs(e0):  # (a step too small to measure is taken)
                    break
                step *= 0.5
            if step <= 1e-3:
                continue
        p[k, 0], p[k, 1], p[k, 2] = cx + step * dx, cy + step * dy, phi + step * th
        _place_listed(x, x_n, act, p0, p1, blocks.c_n[k, 0], blocks.c_n[k, 1], p[k, 0], p[k, 1], p[k, 2])
        if joined:
            carry_joint_points(jr, blocks, k)
        # the furthest a vertex moved: the centre's move plus the turn at the farthest vertex
        move = np.sqrt((step * dx) ** 2 + (step * dy) ** 2) + abs(step * th) * blocks.radius[k]
        most = max(most, move * move)
    return most


@njit(cache=True)
def rigid_pass(x, x_n, zeros, rigid, blocks, grab_slot, grab_pull, rs, jr, touch, planes, state, count, n_body,
               n_corner, h, beta, k_max, last, joined_only=False):
    """One pass over the rigid blocks (:func:`rigid_sweep`), after the friction bounds of the
    rows between rigid bodies follow their normal force
    (:func:`~deforma.physics.integrators.avbd.rows.freeze_rigid_bounds`) and before those rows'
    dual step (:func:`~deforma.physics.integrators.avbd.rows.update_rigid_rows`) and the
    joints' (:func:`~deforma.physics.integrators.avbd.joints.update_joint_rows`; not after the
    ``last`` pass of a step, whose dual step is every row's; ``joined_only``: a pass over the
    bodies with joints alone). Returns the largest squared vertex move (m^2)."""
    freeze_rigid_bounds(x, x_n, rigid, touch, planes, state, count, rs, n_body, n_corner)
    most = rigid_sweep(x, x_n, zeros, blocks, grab_slot, grab_pull, rs, jr, h, joined_only)
    if not last:
        update_rigid_rows(x, x_n, rigid, touch, planes, state, count, rs, n_body, n_corner, beta, k_max)
        update_joint_rows(jr, blocks, x, beta, k_max, RIGID_JOINTS)
    return most


#: A joint whose points (or a weld's angle, at the body's reach) began a substep further
#: apart than this (m) keeps its island on backward Euler (:func:`rigid_second_order`).
JOINT_SLACK = 1e-6


@njit(cache=True)
def rigid_second_order(blocks, jr, keep, h):
    """BDF2 for the rigid blocks that can take it this substep of ``h`` s: their inertial
    targets and ``h_eff = 2h/3``. Backward Euler damps a swing of period ``T`` by about
    ``(2 pi h / T)^2 / 2`` of its amplitude a step (a 1 m pendulum hinged at its end lost
    half its swing in 8 s at 1/60 s); BDF2 by ``(2 pi h / T)^4 / 4``. A block takes it where
    the last substep was as long and whole, it ended where this one starts (nothing set its
    pose or velocity since), and it has no contact row, grab or motor this substep: as the
    soft vertices, whose velocity history at a stop threw them back out, a bounce the
    material did not make, a contact keeps backward Euler, and a motor's row is a velocity
    of backward Euler's. Nor where a joint began the substep apart (:data:`JOINT_SLACK`):
    BDF2 does not damp what an unconverged solve leaves, and a chain of 20 links with a
    weight of 100 links swung at 0.6 m/s after 10 s. The blocks joints hold together
    (``jr.island``) take one scheme: mixed, the chain of 20 equal links never came to rest
    (5 mm/s); all on BDF2 it hung at 1e-10 m/s. (Switching an island between the two as its
    joints' error crosses :data:`JOINT_SLACK` still leaves that chain swaying at up to 2 mm/s.) With ``y = 4/3 q_n - 1/3 q_(n-1)``, ``w = 4/3 v_n - 1/3 v_(n-1)``:
    the target is ``y + h' w + h'^2 a`` for the inertia ``M / h'^2``, ``h' = 2h/3``."""
    hp = 2.0 * h / 3.0
    island_ok = jr.island_ok
    island_ok[:] = True
    jr.island_touch[:] = False
    for k in range(blocks.lo.shape[0]):
        if blocks.held[k]:
            continue  # held as the world is: no part of its island's choice
        touched = blocks.act_start[k + 1] > blocks.act_start[k]
        for p in range(jr.j_start[k], jr.j_start[k + 1]):
            # a soft body's joint: its vertices are swept with the contact rows' (and no
            # pass over the jointed blocks alone moves it)
            touched = touched or jr.ji[jr.j_entry[p] // 2, SOFT] != 0
        if touched:
            jr.island_touch[jr.island[k]] = True
        ok = blocks.hist[k] == h and not touched
        if ok:
            e, v = blocks.end[k], blocks.v_n[k]
            scale = 1e-9 * (1.0 + abs(v[0]) + abs(v[1]) + blocks.radius[k] * abs(v[2]))
            ok = (abs(e[0] - blocks.c_n[k, 0]) + abs(e[1] - blocks.c_n[k, 1]) <= scale * h
                  and abs(e[3] - v[0]) + abs(e[4] - v[1]) + blocks.radius[k] * abs(e[5] - v[2]) <= scale)
        if ok:
            for p in range(jr.j_start[k], jr.j_start[k + 1]):
                j = jr.j_entry[p] // 2
                slack = abs(jr.jf[j, ERR0]) + abs(jr.jf[j, ERR0 + 1])
                if jr.ji[j, KIND] == WELD:
                    slack += abs(jr.jf[j, ERR0 + 2]) * blocks.radius[k]
                if jr.ji[j, MOTOR] != 0 or jr.ji[j, SOFT] != 0 or (jr.ji[j, KIND] != SPRING and slack > JOINT_SLACK):
                    ok = False
        if not ok:
            island_ok[jr.island[k]] = False
    for k in range(blocks.lo.shape[0]):
        if blocks.held[k] or not island_ok[jr.island[k]]:
            continue
        q, v, a, t = blocks.prev[k], blocks.v_n[k], blocks.load[k], blocks.target
        for d in range(2):
            t[k, d] = (4.0 * blocks.c_n[k, d] - q[d]) / 3.0 + keep * (
                hp * (4.0 * v[d] - q[3 + d]) / 3.0 + hp * hp * a[d])
        t[k, 2] = q[2] / 3.0 + keep * (hp * (4.0 * v[2] - q[5]) / 3.0 + hp * hp * a[2])
        blocks.h_eff[k] = hp


@njit(cache=True)
def rigid_passes(x, x_n, zeros, rigid, blocks, grab_slot, grab_pull, rs, jr, touch, planes, state, count, n_body,
                 n_corner, h, beta, k_max, passes, last_sweep):
    """``passes`` passes of :func:`rigid_pass` in one call (the last of the ``last_sweep``
    without its dual step), where no soft vertex is swept between them: called pass by pass
    from Python, the calls' overhead was a third of a rigid pendulum's step. Returns the
    largest squared vertex move (m^2)."""
    most = 0.0
    for q in range(passes):
        most = max(most, rigid_pass(x, x_n, zeros, rigid, blocks, grab_slot, grab_pull, rs, jr, touch, planes, state,
                                    count, n_body, n_corner, h, beta, k_max, last_sweep and q == passes - 1))
    return most


@njit(cache=True)
def rigid_rates(blocks, h):
    """The rigid bodies' velocities over the substep of ``h`` s, from their poses, into
    ``blocks.rate``: backward Euler's ``(c - c_n) / h`` and spin ``phi / h``, or BDF2's
    ``(c - 4/3 c_n + 1/3 c_(n-1)) / h'`` and ``(phi - 1/3 phi_(n-1)) / h'``
    (:func:`rigid_second_order`); and the substep kept as the next one's history."""
    for k in range(blocks.lo.shape[0]):
        p, q, c_n = blocks.pose, blocks.prev[k], blocks.c_n
        he = blocks.h_eff[k]
        if he != h:
            blocks.rate[k, 0] = (p[k, 0] - (4.0 * c_n[k, 0] - q[0]) / 3.0) / he
            blocks.rate[k, 1] = (p[k, 1] - (4.0 * c_n[k, 1] - q[1]) / 3.0) / he
            blocks.rate[k, 2] = (p[k, 2] - q[2] / 3.0) / he
        else:
            blocks.rate[k, 0] = (p[k, 0] - c_n[k, 0]) / h
            blocks.rate[k, 1] = (p[k, 1] - c_n[k, 1]) / h
            blocks.rate[k, 2] = p[k, 2] / h
        q[0], q[1], q[2] = c_n[k, 0], c_n[k, 1], p[k, 2]
        q[3], q[4], q[5] = blocks.v_n[k, 0], blocks.v_n[k, 1], blocks.v_n[k, 2]
        e = blocks.end[k]
        e[0], e[1], e[3], e[4], e[5] = p[k, 0], p[k, 1], blocks.rate[k, 0], blocks.rate[k, 1], blocks.rate[k, 2]
        blocks.hist[k] = h


@njit(cache=True)
def rigid_place(x, x_n, v, blocks):
    """The rigid bodies' vertices at their poses, with their rates as velocities
    (:func:`rigid_rates`): what ends a substep, after the collider projection and the
    contact stage, which move vertices one by one."""
    for k in range(blocks.lo.shape[0]):
        a, b = blocks.lo[k], blocks.hi[k]
        p, r = blocks.pose, blocks.rate
        _place(x, x_n, a, b, blocks.c_n[k, 0], blocks.c_n[k, 1], p[k, 0], p[k, 1], p[k, 2])
        for i in range(a, b):
            rx, ry = x[i, 0] - p[k, 0], x[i, 1] - p[k, 1]
            v[i, 0] = r[k, 0] - r[k, 2] * ry
            v[i, 1] = r[k, 1] + r[k, 2] * rx

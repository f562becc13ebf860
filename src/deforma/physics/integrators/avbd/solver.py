"""``"avbd"``: Augmented Vertex Block Descent (Chen, Ferguson, Yuksel, "Vertex Block Descent",
SIGGRAPH 2024; Giles, Diaz, Yuksel, "Augmented Vertex Block Descent", SIGGRAPH 2025).

One step of ``h`` (per substep; split into equal parts where it reaches deep into a contact
or a body, option ``reach``: see :meth:`AVBD.step`)::

    collide: collider and body contacts of the predicted motion, as rows (rows.py), warm-started
    y = x_n + h v_n + h^2 (g + f / m)                    # the inertial target
    x = x_n + h v_n + h^2 a~                             # adaptive start (a~: last step's
                                                         #   acceleration along g, in [0, g])
    repeat iterations (or until every vertex moves less than tolerance * h):
        for colour in colours:                           # vertices sharing no element
            for vertex i in colour:
                g = M/h^2 (x_i - y_i) + sum element gradients + grab + rows
                H = M/h^2 + sum element blocks (PSD) + grab + rows
                x_i -= H^-1 g
        for patch in patches: affine Newton step        # the coarse level
        for body: rigid Newton step with a line search
        for rigid body: Newton step over its pose (x, y, angle) with a line search
        x = omega (x - x'') + x''                        # Chebyshev, if rho > 0
    rows: lambda = clamp(k C + lambda); k += beta |C| inside the bounds   # once a step
    v = (x - x_n) / h;  the collider fail-safe and the body contact stage

Each vertex block is one Newton step on backward Euler's objective restricted to the vertex
(:mod:`~deforma.physics.integrators.avbd.blocks`), so any iteration budget is stable, and run
to a tolerance the step is backward Euler's. A plain sweep carries information about one ring
of vertices per colour pass, so a large stiff body is softer than its material at a small
budget: the coarse level below takes most of that. Chebyshev's semi-iterative acceleration
(VBD's, ``chebyshev`` the spectral radius it assumes) is an option, off by default: with
contacts it made them chatter.

Between sweeps, patches of about ``cluster_size`` vertices each take a Newton step over their
affine motions (:mod:`~deforma.physics.integrators.avbd.clusters`, a coarse level that moves a
correction a patch per visit), and every body without a pin one over its rigid motions
(:func:`~deforma.physics.integrators.avbd.rigid.rigid_correction`). A rigid body is
one block of three degrees of freedom, its pose (:mod:`~deforma.physics.integrators.avbd.rigid`).

Contacts are found once, before the solve, for the predicted motion: a vertex against a
collider, and a vertex against an outline edge of another body or its own. Each is a row
inside the sweep with Coulomb friction (:mod:`~deforma.physics.integrators.avbd.rows`),
warm-started by its pair; the shared contact stage after the sweep stays as the fail-safe.
Pins stay put (infinite mass); a grab is a zero-length spring of its strength to its target.
Joints are rows too (:mod:`~deforma.physics.integrators.avbd.joints`): on a rigid body's
block, or on a soft body's triangle, whose vertices take them with their contact rows.
Each colour's vertices without contact rows are swept in parallel and those with rows after
them one by one (:func:`_sweep`; option ``mode`` picks the build, measured by default): every
build gives the same result bit for bit.

Units: m, s, kg, N, N/m.
"""

from __future__ import annotations

import math
import time

import numba
import numpy as np
from numba import njit, prange

from ...colliders.geometry import advance_colliders
from ...colliders.response import CORNER_COLUMNS, contact_planes, corner_contacts, push_edges_off_corners
from ...contact.broad_phase import gather_start
from ...contact.contacts import SPECULATIVE, make_buffer, make_scratch
from ...contact.narrow_phase import detect_contacts
from ...contact.pairs import ContactImpulses
from ...contact.response import hold_start_distance
from ...elements.springs import spring_vertex_block
from ...elements.triangles import triangle_vertex_block
from ...jit import serial_and_parallel
from ...rigid.stage import rigid_set
from ...rigid_motion import linear_and_angular_velocity, rigid_velocities
from ...topology import lengths
from ..base import (
    Integrator,
    Option,
    StepReport,
    contact_epilogue,
    finish_position_step,
    register_integrator,
)
from ..driver import MODE_OPTION_DOC, PARALLEL_MIN_VERTICES, DriverChoice
from .blocks import incidence, outer_block
from .clusters import cluster_members, cluster_sweep, make_clusters
from .colouring import colour_vertices
from .gas import gas_areas, gas_block, gas_moved, gas_set
from .joints import (
    BLOCK,
    FV,
    RIGID_JOINTS,
    SOFT,
    SOFT_JOINTS,
    joint_gap,
    joint_totals,
    no_joint_rows,
    start_joint_rows,
    update_joint_rows,
)
from .rigid import (
    centre_velocity_spin,
    rigid_active,
    rigid_blocks,
    rigid_correction,
    rigid_pass,
    rigid_passes,
    rigid_place,
    rigid_rates,
    rigid_second_order,
    rigid_targets,
)
from .rows import (
    BODY_COLUMNS,
    MEMORY_COLUMNS,
    ROW_COLUMNS,
    RowSet,
    body_row_incidence,
    close_body_rows,
    close_corner_rows,
    close_rows,
    corner_row_incidence,
    freeze_body_bounds,
    freeze_bounds,
    freeze_corner_bounds,
    mark_rowed,
    row_blocks,
    row_impulses,
    start_body_rows,
    start_corner_rows,
    start_rigid_rows,
    start_rows,
    update_body_rows,
    update_corner_rows,
    update_rows,
)


@njit(cache=True)
def predict(x, v, x_n, y, v_last, has_last, inv_mass, gx, gy, keep, force, has_force, h):
    """Start a substep: ``x_n = x``, the inertial target ``y`` (gravity, the applied
    ``force`` if ``has_force``, air drag's ``keep``), and ``x`` moved to the adaptive start
    ``x_n + h v + h^2 a~``: ``a~`` is gravity scaled by how much of it the vertex took last
    substep (its acceleration then, ``(v - v_last) / h``, along gravity, clamped to ``[0,
    g]``): a resting vertex starts where it is, a falling one where free fall takes it.
    ``v_last`` then takes ``v``."""
    g2 = gx * gx + gy * gy
    h2 = h * h
    for i in range(x.shape[0]):
        x_n[i, 0] = x[i, 0]
        x_n[i, 1] = x[i, 1]
        if inv_mass[i] == 0.0:  # pinned: it stays
            y[i, 0], y[i, 1] = x[i, 0], x[i, 1]
            v_last[i, 0] = v_last[i, 1] = 0.0
            continue
        ax, ay = gx, gy
        if has_force:
            ax += force[i, 0] * inv_mass[i]
            ay += force[i, 1] * inv_mass[i]
        vx, vy = v[i, 0] * keep, v[i, 1] * keep
        y[i, 0] = x[i, 0] + h * vx + h2 * keep * ax
        y[i, 1] = x[i, 1] + h * vy + h2 * keep * ay
        share = 1.0
        if has_last and g2 > 0.0:
            along = ((v[i, 0] - v_last[i, 0]) * gx + (v[i, 1] - v_last[i, 1]) * gy) / (h * g2)
            share = min(max(along, 0.0), 1.0)
        v_last[i, 0], v_last[i, 1] = v[i, 0], v[i, 1]
        x[i, 0] = x[i, 0] + h * vx + h2 * keep * (share * gx + ax - gx)
        x[i, 1] = x[i, 1] + h * vy + h2 * keep * (share * gy + ay - gy)


@njit(cache=True)
def start_rigidly(x, x_n, v, mass, inv_mass, body_start, hk):
    """The option ``start="rigid"``: move each body's start of the sweeps (:func:`predict`'s
    ``x_n + hk v + ...``, ``hk`` the step times air drag's keep) to carry its rigid motion
    alone, the velocity of its centre of mass and its spin, not its vertices' own velocities.
    A mode the sweeps do not converge keeps much of where they start: from ``x_n + h v`` a
    deformation's velocity is carried on as an explicit step would, and the rocking of an
    E = 1e9 plate on an E = 1e4 block grew until it was thrown off at 2.5 s; started
    rigidly it rests. A body with a pinned vertex keeps its vertices' velocities."""
    for body in range(body_start.shape[0] - 1):
        lo, hi = body_start[body], body_start[body + 1]
        pinned = False
        for i in range(lo, hi):
            pinned = pinned or inv_mass[i] == 0.0
        if hi == lo or pinned:
            continue
        _, cx, cy, vx, vy, w = centre_velocity_spin(x_n, v, mass, lo, hi)
        for i in range(lo, hi):
            rx, ry = x_n[i, 0] - cx, x_n[i, 1] - cy
            x[i, 0] += hk * (vx - w * ry - v[i, 0])
            x[i, 1] += hk * (vy + w * rx - v[i, 1])


@njit(cache=True)
def second_order_targets(x_n, y, v_n, x_prev, v_prev, x_end, v_end, anchor, mass_h2, vertex_mass, inv_mass, held,
                         held_before, gx, gy, drag, force, has_force, h):
    """Make every free vertex that is in no contact row (``held``) a BDF2 vertex: its
    ``anchor`` ``(4 x_n - x_prev) / 3``, its target ``y`` that plus ``h' (4 v_n - v_prev) / 3
    + h'^2 a`` and its inertia ``mass_h2`` ``m / h'^2``, with ``h' = 2 h / 3``: backward
    Euler's objective around that anchor with that step is BDF2's step, and its velocity is
    ``(x - anchor) / h'``. The others keep backward Euler's (``anchor = x_n``; ``y`` and
    ``mass_h2`` as :func:`predict` made them). A vertex moved or given a velocity since the
    last step ended (``x_end``, ``v_end``) starts a history of its own, as if it had moved
    at ``v_n`` (a velocity set between steps was otherwise taken for a jump in speed).
    Returns how many are BDF2 vertices."""
    hb = 2.0 * h / 3.0
    hb2 = hb * hb
    keep = 1.0 / (1.0 + hb * drag)
    free = 0
    for i in range(x_n.shape[0]):
        if inv_mass[i] == 0.0 or held[i]:
            anchor[i, 0], anchor[i, 1] = x_n[i, 0], x_n[i, 1]
            continue
        ax, ay = gx, gy
        if has_force:
            ax += force[i, 0] * inv_mass[i]
            ay += force[i, 1] * inv_mass[i]
        same = (not held_before[i] and x_n[i, 0] == x_end[i, 0] and x_n[i, 1] == x_end[i, 1]
                and v_n[i, 0] == v_end[i, 0] and v_n[i, 1] == v_end[i, 1])
        for d in range(2):
            xp, vp = (x_prev[i, d], v_prev[i, d]) if same else (x_n[i, d] - h * v_n[i, d], v_n[i, d])
            a = (4.0 * x_n[i, d] - xp) / 3.0
            anchor[i, d] = a
            y[i, d] = a + keep * (hb * (4.0 * v_n[i, d] - vp) / 3.0 + hb2 * (ax if d == 0 else ay))
        mass_h2[i] = vertex_mass[i] / (keep * hb2)
        free += 1
    return free


@njit(cache=True)
def rows_held(held, touch, count, topo, buf, n_body, cpairs, n_corner):
    """Mark the vertices of this step's contact rows (the collider rows', each body row's
    vertex and edge ends, each corner row's edge ends): they step by backward Euler
    (:func:`second_order_targets`)."""
    held[:] = False
    for k in range(count):
        held[touch[k]] = True
    cv = topo.cv_vertex
    for c in range(n_body):
        held[cv[buf.vertex[c]]] = True
        held[cv[topo.ce_a[buf.edge[c]]]] = True
        held[cv[topo.ce_b[buf.edge[c]]]] = True
    for c in range(n_corner):
        held[cpairs[c, 0]] = True
        held[cpairs[c, 1]] = True


@njit(cache=True)
def second_order_velocities(x, v, anchor, solved, held, inv_mass, h):
    """BDF2's velocity ``(x - anchor) / h'`` (``h' = 2 h / 3``) for the BDF2 vertices the
    contact stage after the solve left where the solve put them (``solved``); the others
    keep backward Euler's, which that stage set."""
    inv = 1.5 / h
    for i in range(x.shape[0]):
        if inv_mass[i] == 0.0 or held[i] or x[i, 0] != solved[i, 0] or x[i, 1] != solved[i, 1]:
            continue
        v[i, 0] = (x[i, 0] - anchor[i, 0]) * inv
        v[i, 1] = (x[i, 1] - anchor[i, 1]) * inv


@njit(cache=True, inline="always")
def descend(x, y, i, gx, gy, hxx, hxy, hyy, mass_h2, grab_slot, grab_pull):
    """Finish vertex ``i``'s block (its elements' and rows' share ``g``, ``H`` given): add the
    inertia and its grab, and take the Newton step. Returns the squared move (m^2)."""
    ogx, ogy, oxx, oxy, oyy = outer_block(x, y, i, mass_h2, grab_slot, grab_pull)
    gx += ogx
    gy += ogy
    hxx += oxx
    hxy += oxy
    hyy += oyy
    det = hxx * hyy - hxy * hxy
    if not det > 0.0:
        return 0.0
    dx = (hyy * gx - hxy * gy) / det
    dy = (hxx * gy - hxy * gx) / det
    x[i, 0] -= dx
    x[i, 1] -= dy
    return dx * dx + dy * dy


@njit(cache=True, inline="always")
def element_block(x, x_n, i, tri_start, tri_item, tri_corner, elem, b, area, mu, lam, beta, kind, spring_start,
                  spring_item, spring_corner, spring_i, spring_j, rest, ks, kd, inv_h):
    """Vertex ``i``'s share of its elements' energy (the built-in kinds): ``(gx, gy, hxx, hxy,
    hyy)``."""
    gx = gy = hxx = hxy = hyy = 0.0
    for q in range(tri_start[i], tri_start[i + 1]):
        ex, ey, exx, exy, eyy = triangle_vertex_block(x, x_n, tri_item[q], tri_corner[q], elem, b, area, mu, lam,
                                                      beta, kind, inv_h)
        gx += ex
        gy += ey
        hxx += exx
        hxy += exy
        hyy += eyy
    for q in range(spring_start[i], spring_start[i + 1]):
        s = spring_item[q]
        j = spring_j[s] if spring_corner[q] == 0 else spring_i[s]
        ex, ey, exx, exy, eyy = spring_vertex_block(x, x_n, i, j, rest[s], ks[s], kd[s], inv_h)
        gx += ex
        gy += ey
        hxx += exx
        hxy += exy
        hyy += eyy
    return gx, gy, hxx, hxy, hyy


def _sweep(x, x_n, y, mass_h2, inv_mass, order, starts, tri_start, tri_item, tri_corner, elem, b, area, mu, lam,
           beta, kind, spring_start, spring_item, spring_corner, spring_i, spring_j, rest, ks, kd, grab_slot,
           grab_pull, rs, inv_h, moves):
    """One Gauss-Seidel sweep, colour after colour, over every free vertex's block (the
    built-in element kinds). Returns the largest squared move (m^2); ``moves`` (N,) is scratch.

    A colour's vertices share no element, so those without contact rows are independent and
    go in parallel (``prange``); a row can join two vertices of one colour (a vertex and the
    edge it meets), so those with rows follow one by one. A row's vertices all have rows, so
    this order gives what any order within the colour gives: the one-thread and all-threads
    builds (:data:`sweep_serial`, :data:`sweep_parallel`) agree bit for bit."""
    for c in range(starts.shape[0] - 1):
        lo, hi = starts[c], starts[c + 1]
        for p in prange(lo, hi):
            i = order[p]
            moves[p] = 0.0
            if inv_mass[i] != 0.0 and not rs.rowed[i]:
                gx, gy, hxx, hxy, hyy = element_block(x, x_n, i, tri_start, tri_item, tri_corner, elem, b, area, mu,
                                                      lam, beta, kind, spring_start, spring_item, spring_corner,
                                                      spring_i, spring_j, rest, ks, kd, inv_h)
                moves[p] = descend(x, y, i, gx, gy, hxx, hxy, hyy, mass_h2, grab_slot, grab_pull)
        for p in range(lo, hi):
            i = order[p]
            if inv_mass[i] != 0.0 and rs.rowed[i]:
                gx, gy, hxx, hxy, hyy = element_block(x, x_n, i, tri_start, tri_item, tri_corner, elem, b, area, mu,
                                                      lam, beta, kind, spring_start, spring_item, spring_corner,
                                                      spring_i, spring_j, rest, ks, kd, inv_h)
                ex, ey, exx, exy, eyy = row_blocks(x, x_n, i, rs, False)
                moves[p] = descend(x, y, i, gx + ex, gy + ey, hxx + exx, hxy + exy, hyy + eyy, mass_h2, grab_slot,
                                   grab_pull)
    most = 0.0
    for p in range(starts[-1]):
        most = max(most, moves[p])
    return most


sweep_serial, sweep_parallel = serial_and_parallel(_sweep, "avbd_sweep")


@njit(cache=True)
def sweep_colour_given(x, x_n, y, mass_h2, inv_mass, order, start, stop, g, hb, grab_slot, grab_pull, rs, gas):
    """The vertices ``order[start:stop]`` (one colour) with their elements' share of the
    block given (``g`` (N, 2), ``hb`` (N, 3)): the path for element kinds that are not
    built in, and for a world with gas (``gas``, :class:`~deforma.physics.integrators.avbd.gas.GasSet`,
    whose share each outline vertex adds here; in :func:`_sweep`, the gas's code, even never
    run, cost the built-in path half its speed). Returns the largest squared move (m^2)."""
    most = 0.0
    for p in range(start, stop):
        i = order[p]
        if inv_mass[i] == 0.0:
            continue
        gx, gy, hxx, hxy, hyy = g[i, 0], g[i, 1], hb[i, 0], hb[i, 1], hb[i, 2]
        if rs.rowed[i]:
            ex, ey, exx, exy, eyy = row_blocks(x, x_n, i, rs, False)
            gx += ex
            gy += ey
            hxx += exx
            hxy += exy
            hyy += eyy
        on_gas = gas.start[i + 1] > gas.start[i]
        if on_gas:
            ggx, ggy, gxx, gxy, gyy = gas_block(x, i, gas)
            gx += ggx
            gy += ggy
            hxx += gxx
            hxy += gxy
            hyy += gyy
        x0, y0 = x[i, 0], x[i, 1]
        moved = descend(x, y, i, gx, gy, hxx, hxy, hyy, mass_h2, grab_slot, grab_pull)
        if on_gas:
            gas_moved(x, i, gas, x[i, 0] - x0, x[i, 1] - y0)
        most = max(most, moved)
    return most


@njit(cache=True)
def ease_apart(topo, buf, count, full, rigid, share, step):
    """Raise the target of each contact between soft vertices that
    :func:`~deforma.physics.contact.response.hold_start_distance` held closer than ``share``
    of its thickness ``full`` towards that share, by at most ``step`` (m). Held only where it
    began, such a pair (after a hard landing) sank by the rows' tolerance in every step and
    the fail-safe put it back: the resting ``jelly`` stack, in every step for good. (Rigid
    pairs rest closer by design: their fail-safe keeps the bodies whole.)"""
    cv, ce_a, ce_b = topo.cv_vertex, topo.ce_a, topo.ce_b
    for c in range(count):
        held = buf.target[c]
        if held >= share * full[c]:
            continue
        e = buf.edge[c]
        if rigid[cv[buf.vertex[c]]] or rigid[cv[ce_a[e]]] or rigid[cv[ce_b[e]]]:
            continue
        buf.target[c] = min(share * full[c], held + step)


@njit(cache=True)
def narrow_targets(topo, buf, count, margin):
    """Take the margin back off the targets of the contacts between two bodies found with
    their thickness widened by it (:meth:`AVBD._collide`)."""
    body = topo.cv_body
    for c in range(count):
        if body[buf.vertex[c]] != topo.ce_body[buf.edge[c]]:
            buf.target[c] = max(buf.target[c] - margin, 0.0)


@njit(cache=True)
def deepest_reach(y, v, planes, touch, count, topo, buf, n_body, size, h):
    """How far the step's motion reaches into its contacts, as a multiple of the vertex's
    ``size`` (its shortest edge, m), at most over the contacts: the larger of how far the
    predicted ``y`` lies past the contact (collider: ``c - n . y``; bodies: the target
    distance less the one at ``y``) and how far the pair approaches along the normal at its
    velocity ``v`` in ``h`` s."""
    most = 0.0
    for k in range(count):
        i = touch[k]
        nx, ny = planes[k, 0], planes[k, 1]
        depth = planes[k, 2] - y[i, 0] * nx - y[i, 1] * ny
        approach = -((v[i, 0] * h - planes[k, 5]) * nx + (v[i, 1] * h - planes[k, 6]) * ny)
        most = max(most, max(depth, approach) / size[i])
    cv, ce_a, ce_b = topo.cv_vertex, topo.ce_a, topo.ce_b
    for c in range(n_body):
        ip, ia, ib = cv[buf.vertex[c]], cv[ce_a[buf.edge[c]]], cv[ce_b[buf.edge[c]]]
        s = buf.s[c]
        nx, ny = buf.normal[c, 0], buf.normal[c, 1]
        dx = y[ip, 0] - (1.0 - s) * y[ia, 0] - s * y[ib, 0]
        dy = y[ip, 1] - (1.0 - s) * y[ia, 1] - s * y[ib, 1]
        depth = buf.target[c] - dx * nx - dy * ny
        ux = v[ip, 0] - (1.0 - s) * v[ia, 0] - s * v[ib, 0]
        uy = v[ip, 1] - (1.0 - s) * v[ia, 1] - s * v[ib, 1]
        approach = -(ux * nx + uy * ny) * h
        most = max(most, max(depth, approach) / min(size[ip], size[ia], size[ib]))
    return most


@njit(cache=True)
def chebyshev(x, x_prev, x_prev2, inv_mass, vertex_row, omega):
    """VBD's Chebyshev step ``x = omega (x - x'') + x''`` (``x''`` the iterate two sweeps back),
    then the history shifts (``x'' = x'``, ``x' = x``). Vertices on a contact row are left
    alone (extrapolated, they overshot their rows' multipliers and a block on a slope slid)."""
    for i in range(x.shape[0]):
        if inv_mass[i] != 0.0 and omega != 1.0 and vertex_row[i] < 0:
            x[i, 0] = omega * (x[i, 0] - x_prev2[i, 0]) + x_prev2[i, 0]
            x[i, 1] = omega * (x[i, 1] - x_prev2[i, 1]) + x_prev2[i, 1]
        x_prev2[i, 0], x_prev2[i, 1] = x_prev[i, 0], x_prev[i, 1]
        x_prev[i, 0], x_prev[i, 1] = x[i, 0], x[i, 1]


def deepest_strain_reach(x, v, mass, body_start, size, h, rigid=None) -> float:
    """How far the bodies' deformation moves a vertex in ``h`` s, as a multiple of its
    ``size`` (m), at most over the vertices: its velocity less its body's rigid motion
    (:func:`~deforma.physics.rigid_motion.linear_and_angular_velocity`). A body that falls,
    slides or turns as a whole reaches nothing; one crushed by an impact does."""
    most = 0.0
    for lo, hi in zip(body_start[:-1], body_start[1:]):
        if hi <= lo or (rigid is not None and rigid[lo]):  # (a rigid body moves rigidly)
            continue
        xb, vb, mb = x[lo:hi], v[lo:hi], mass[lo:hi]
        if not mb.sum() > 0.0:
            continue
        own = vb - rigid_velocities(xb, mb, *linear_and_angular_velocity(xb, vb, mb))
        most = max(most, float((np.sqrt((own * own).sum(axis=1)) / size[lo:hi]).max()) * h)
    return most


def chebyshev_omega(k: int, rho: float, previous: float) -> float:
    """Chebyshev's weight for sweep ``k`` (0-based) with spectral radius ``rho``."""
    if rho <= 0.0 or k == 0:
        return 1.0
    if k == 1:
        return 2.0 / (2.0 - rho * rho)
    return 4.0 / (4.0 - rho * rho * previous)


#: The contact stage after the solve, the fail-safe, acts on pairs closer than this share of
#: their contact thickness (:meth:`AVBD._failsafe_topology`).
FAILSAFE_SHARE = 0.5
#: A pair of soft outlines that begins a step closer than ``EASE_SHARE * FAILSAFE_SHARE`` of its
#: contact thickness has its row's target raised towards that by at most ``EASE_SPEED`` (m/s)
#: times the step: the rows, not the fail-safe, take it back out, slowly enough that it
#: does not fly apart (:func:`ease_apart`).
EASE_SHARE = 1.2
EASE_SPEED = 0.01


@register_integrator("avbd")
class AVBD(Integrator):
    """Augmented Vertex Block Descent: backward Euler by Gauss-Seidel over per-vertex blocks,
    contacts as augmented-Lagrangian rows (see the module docstring).

    Options
    -------
    iterations : int
        Sweeps per step (in [1, 10000]): the budget, or with ``tolerance`` the most.
    reach : float
        Split a step into equal parts (at most :attr:`MAX_PARTS`) where its motion would move a
        vertex further than this many of its shortest edges into a contact (the pair's
        approach at its speed, or the prediction past the surface), or :attr:`STRAIN_SHARE`
        times as far within its body (its speed less the body's rigid motion). Ten sweeps
        spread an impact's load only about ten rings into a body: a soft box met at 5 m/s
        crushed the one below it in one step. 0: never split.
    order : int
        1 (the default): backward Euler, which damps a vibration of period ``T`` by about
        ``(2 pi h / T)^2 / 2`` of its amplitude a step. 2: BDF2 (second order; by about
        ``(2 pi h / T)^4 / 4``) for every vertex outside this step's contact rows, whose
        vertices keep backward Euler (BDF2's velocity history at a stop threw them back out,
        a bounce the material did not make). A step split into parts is backward Euler's.
    tolerance : float
        Stop once no vertex moves faster than this in a sweep (m/s; 0, the default: run the
        budget). Run to a tight tolerance the step is backward Euler's.
    cluster_size : int
        Vertices per patch of the coarse level: after every sweep each patch takes a
        Newton step over its affine motions (:mod:`~deforma.physics.integrators.avbd.clusters`;
        0: none). Over the built-in element kinds only: with a kind registered from outside
        there is no coarse level.
    start : str
        Where the sweeps of a step start: ``"velocity"`` (the default), each vertex moved on
        by its velocity (and the share of gravity it took last step); ``"rigid"``, each body
        by its rigid motion alone (:func:`start_rigidly`). What the sweeps do not converge
        stays near the start: from the vertices' velocities a stiff plate's rocking on a soft
        block grew until it was thrown off; from the rigid motion it rests. Not yet the
        default: with it the resting ``pile`` needs the fail-safe more.
    chebyshev : float
        The spectral radius Chebyshev's acceleration assumes, in [0, 1) (0: none).
    penalty_start : float
        A contact row's first stiffness, as a multiple of its vertex's ``m / h^2`` plus its
        elements' stiffness (> 0).
    penalty_ramp : float
        ``beta``, N/m per m of violation: how fast a row's penalty stiffens, once a step (>= 0).
    penalty_max : float
        The stiffest a row gets (N/m).
    rigid_passes : int
        Passes over the rigid bodies' blocks per sweep (:mod:`~deforma.physics.integrators.avbd.rigid`),
        each followed by the dual step of the rows between rigid bodies and colliders and by a
        sweep of the soft vertices with contact rows (so that a soft body resting on a rigid
        one converges with it). A block is three unknowns and its pass visits only its
        vertices with rows: cheap beside a soft body's sweep. Measured on a stack of ten rigid
        boxes at ten sweeps: one pass a sweep sank it into itself and it fell within a second,
        two held it eight seconds, three and four within a millimetre for ten seconds.

    Examples
    --------
    >>> import deforma
    >>> w = deforma.World(dt=1 / 60, integrator="avbd")
    >>> w.integrator_options["iterations"]
    10
    """

    name = "avbd"
    unconditionally_stable = True
    solves_pressure = True  # the gas's energy is in the vertex blocks (avbd.gas)
    solves_rigid = True  # a rigid body is a block of the sweep (avbd.rigid)
    OPTIONS = (Option("iterations", 10, "int", low=1, high=10_000, doc="sweeps per step (the most, with tolerance)"),
               Option("reach", 0.5, "float", low=0.0, high=1e6, closed_low=True,
                      doc="split a step into parts where it moves a vertex into a contact further than this "
                          "many of its shortest edges, or within its body twice as far (0: never)"),
               Option("order", 1, "int", low=1, high=2,
                      doc="1: backward Euler; 2: BDF2 for every vertex outside a contact (keeps vibrations)"),
               Option("tolerance", 0.0, "float", low=0.0, high=math.inf, closed_low=True,
                      doc="stop when no vertex moves faster than this in a sweep (m/s; 0: run every sweep)"),
               Option("cluster_size", 64, "int", low=0, high=1_000_000,
                      doc="vertices per patch of the affine coarse level (0: none)"),
               Option("start", "velocity", "choice", choices=("velocity", "rigid"),
                      doc="where the sweeps start: each vertex moved on by its velocity, or each body by its "
                          "rigid motion alone (for stiff bodies on soft ones)"),
               Option("chebyshev", 0.0, "float", low=0.0, high=1.0, closed_low=True,
                      doc="spectral radius for Chebyshev acceleration (0: none)"),
               Option("penalty_start", 1.0, "float", low=0.0, high=1e12,
                      doc="a contact row's first stiffness, in its vertex's m / h^2 plus its elements' stiffness"),
               Option("penalty_ramp", 1e5, "float", low=0.0, high=1e15, closed_low=True,
                      doc="penalty growth per metre of violation, once a step (N/m^2)"),
               Option("penalty_max", 1e10, "float", low=0.0, high=1e18, doc="the stiffest a contact row gets (N/m)"),
               Option("rigid_passes", 4, "int", low=1, high=1000,
                      doc="passes over the rigid bodies' blocks per sweep, each with their rows' dual step and "
                          "the soft vertices on contacts swept again"),
               Option("mode", "auto", "choice", choices=("auto", "serial", "parallel"), doc=MODE_OPTION_DOC))

    #: the most parts a step is split into where it reaches deep into its contacts
    MAX_PARTS = 16
    #: a body's own deformation splits a step where it moves a vertex this many times
    #: ``reach`` (counted at ``reach``, the README's wobbling springs bunny was split in two
    #: of three steps and ran at half the speed; not counted at all, the 48-body heap ran away)
    STRAIN_SHARE = 2.0
    #: a row's multiplier and penalty carried into the next step: lambda * CARRY, k * SOFTEN
    CARRY = 0.99 * 0.99
    SOFTEN = 0.99
    #: after the sweeps, passes over the bodies with joints until no pin or weld is further
    #: apart than JOINT_TOLERANCE (m), at most JOINT_PASSES
    JOINT_TOLERANCE = 1e-5
    JOINT_PASSES = 200
    #: The fewest sweeps of a step with a joint between two soft bodies (see :meth:`_solve`).
    SOFT_JOINT_SWEEPS = 20

    def __init__(self, **options):
        super().__init__(**options)
        self._topology = (None,)
        self._stiff = None
        self._patches = None
        self._body_memory = None
        self._search = None
        self._bstate = np.empty((0, ROW_COLUMNS))
        self._bidx = np.empty((0, 3), np.int64)
        self._bgeo = np.empty((0, BODY_COLUMNS))
        self._b_entry = np.empty(0, np.int64)
        self._cpairs = np.empty((64, 4), np.int64)  # the corner rows (corner_contacts)
        self._cf = np.empty((64, CORNER_COLUMNS))
        self._cstate = np.empty((64, ROW_COLUMNS))
        self._c_entry = np.empty(128, np.int64)
        self._corner_memory = None
        self._n_corner = 0
        self._gas = None  # (model, GasSet)
        self._rigid = None  # (model, RigidBlocks or None, per-vertex body mass or None)
        self._no_joints = None  # the JointRows of a model without joints
        self._driver = DriverChoice()  # which sweep build runs (option mode)
        self._n = -1
        self._size = None
        self._history = False  # BDF2's: the length of the last step if whole, else False
        self.split = 0
        self.iterations_run = 0
        self.unconverged = 0
        self.residual = 0.0
        self.active_contacts = 0
        self.failsafe = 0
        self._impulses = []  # the last step's rows' impulses, a ContactImpulses per substep
        # the rows' search takes a vertex up to a thickness inside another body as a contact
        # to hold out (narrow_phase.pair_contact): a rigid vertex there, which the contact
        # stage after the solve does not move, was else lost to every later step
        self._behind = np.ones(1)

    def contact_impulses(self, model) -> ContactImpulses:
        """The contact rows of the last step and their impulses, from the multipliers
        (:func:`~deforma.physics.integrators.avbd.rows.row_impulses`; every substep's rows)."""
        return ContactImpulses.concatenate(self._impulses)

    def stats(self) -> dict:
        """``{"iterations", "unconverged", "residual", "contacts", "failsafe", "split"}``: sweeps
        run so far, substeps that stopped at the budget short of a tolerance, the last sweep's
        largest vertex speed change (m/s), the contact rows of the last step, the substeps so
        far in which the contact stage after the solve moved a vertex (it acts on outlines
        closer than :data:`FAILSAFE_SHARE` of their thickness and on vertices in rigid
        bodies: the rows should keep both from happening, and this counts their misses), and
        the substeps split into parts (option ``reach``)."""
        return {"iterations": self.iterations_run, "unconverged": self.unconverged, "residual": self.residual,
                "contacts": self.active_contacts, "failsafe": self.failsafe, "split": self.split}

    def _prepare(self, model):
        """Incidence and colouring, once per Model (its elements never change in place)."""
        if self._topology[0] is model:
            return self._topology
        n = model.n_vertices
        tris = model.triangles.arrays if model.fused else None
        elem = tris.elem if tris is not None else np.zeros((0, 3), np.int32)
        springs = np.stack([model.spring_i, model.spring_j], axis=1)
        t_start, t_item, t_corner = incidence(elem, n)
        s_start, s_item, s_corner = incidence(springs, n)
        # the colouring must see every kind's elements: those not built in add their edges
        extra = [k.vertices for k in model.elements if not k.fused and k.n_elements]
        c_elem, c_start, c_item = model.elem, *incidence(model.elem, n)[:2]
        if extra:
            pairs = [springs] + [np.stack([v[:, a], v[:, b]], axis=1) for v in extra
                                 for a in range(v.shape[1]) for b in range(a + 1, v.shape[1])]
            springs_all = np.concatenate(pairs).astype(np.int64)
            cs_start, cs_item, _ = incidence(springs_all, n)
            order, starts = colour_vertices(n, c_start, c_item, c_elem, cs_start, cs_item, springs_all[:, 0],
                                            springs_all[:, 1])
        else:
            order, starts = colour_vertices(n, c_start, c_item, c_elem, s_start, s_item, model.spring_i,
                                            model.spring_j)
        self._topology = (model, t_start, t_item, t_corner, s_start, s_item, s_corner, order, starts)
        return self._topology

    def _clusters(self, model, x):
        """The coarse level's patches, once per Model and cluster size."""
        size = self._options["cluster_size"]
        if size <= 0 or not model.fused:
            return None
        if self._patches is None or self._patches[0] is not model or self._patches[1] != size:
            cluster, count = make_clusters(x, model.body_vertex_offsets, model.vertex_inv_mass, size)
            v_start, v_list, te_start, te_list = cluster_members(cluster, count, model.elem)
            springs = np.stack([model.spring_i, model.spring_j], axis=1)
            _, _, se_start, se_list = cluster_members(cluster, count, springs)
            self._patches = (model, size, cluster, v_start, v_list, te_start, te_list, se_start, se_list)
        return self._patches[2:]

    def _stiffness(self, model, h):
        """Per vertex, the stiffness of its elements (N/m: the kinds' row sums, damping's
        ``1 / h`` share included): a contact row starts as stiff as the material around its
        vertex, so its multiplier's force is not carried by a gap (a row as soft as the
        inertia, ``m / h^2``, held a resting block's bottom vertices millimetres above the
        floor, and the block hopped). The kinds' rows are summed once per Model version; a
        step split into parts asks for another ``h``."""
        key = (model, model.version)
        if self._stiff is None or self._stiff[0] is not model or self._stiff[1] != key[1]:
            n = model.n_vertices
            elastic = sum((k.stiffness_rows(n) for k in model.elements), np.zeros(n))
            damping = sum((k.damping_rows(n) for k in model.elements), np.zeros(n))
            self._stiff = (*key, elastic, damping)
        return self._stiff[2] + self._stiff[3] / h

    def _scratch(self, n):
        if self._n != n:
            self._x_n = np.empty((n, 2))
            self._y = np.empty((n, 2))
            self._v_last = np.zeros((n, 2))
            self._v_saved = np.zeros((n, 2))
            self._has_last = False
            self._x1 = np.empty((n, 2))
            self._x2 = np.empty((n, 2))
            self._planes = np.empty((n, 7))
            self._touch = np.empty(n, np.int32)
            self._plane_rows = np.empty(n, np.int32)
            self._vertex_row = np.full(n, -1, np.int32)
            self._rows = np.empty((n, ROW_COLUMNS))
            self._memory = np.full((n, MEMORY_COLUMNS), -1.0)
            self._b_start = np.zeros(n + 1, np.int64)
            self._c_start = np.zeros(n + 1, np.int64)
            self._rowed = np.zeros(n, np.bool_)
            self._moves = np.empty(n)  # the sweep's scratch
            self._x_prev = np.empty((n, 2))  # the last step's start, for BDF2
            self._v_prev = np.empty((n, 2))
            self._v_n = np.empty((n, 2))
            self._x_end = np.empty((n, 2))  # where the last step ended: a change since resets BDF2's history
            self._v_end = np.empty((n, 2))
            self._anchor = np.empty((n, 2))
            self._held = np.zeros(n, np.bool_)
            self._held_before = np.zeros(n, np.bool_)
            self._history = False
            self._n = n

    def step(self, model, state_in, state_out, control, contacts, h, *, substeps=1, max_speed=math.inf):
        """Advance by ``substeps`` substeps of ``h`` s. Each is first predicted and collided
        whole; where that motion reaches deeper than ``reach`` shortest edges into a contact,
        or ``STRAIN_SHARE`` times that within a body (:func:`deepest_reach`,
        :func:`deepest_strain_reach`), the prediction is undone and the substep is taken in
        that many equal parts, each collided and solved on its own."""
        n = model.n_vertices
        if self._n != n or self._topology[0] is not model:
            self._memory = None  # vertices renumbered: no warm start
            self._history = False
        self._scratch(n)
        if self._memory is None:
            self._memory = np.full((n, MEMORY_COLUMNS), -1.0)
        topo = self._prepare(model)
        opts = self._options
        x, v = state_out.x, state_out.v
        inv_mass = model.vertex_inv_mass
        gx, gy = (float(c) for c in model.gravity)
        rects, hits, ctopo, scr = control.colliders, contacts.hits, model.contact, contacts.scratch
        vmax2 = float(max_speed) ** 2
        reach = opts["reach"]
        self._impulses = []
        for _ in range(substeps):
            parts, k = 1, 0
            while k < parts:
                hs = float(h) / parts
                keep = 1.0 / (1.0 + hs * model.air_drag)
                mass_h2 = model.vertex_mass * ((1.0 + hs * model.air_drag) / (hs * hs))
                advance_colliders(rects, hs)
                second = opts["order"] == 2
                if second:
                    np.copyto(self._v_n, v)
                np.copyto(self._v_saved, self._v_last)
                had_last = self._has_last
                predict(x, v, self._x_n, self._y, self._v_last, self._has_last, inv_mass, gx, gy, keep,
                        control.force, control.has_force, hs)
                if opts["start"] == "rigid":
                    start_rigidly(x, self._x_n, v, model.vertex_mass, inv_mass, model.body_vertex_offsets, hs * keep)
                blocks, body_mass = self._rigid_blocks(model)
                jr = self._joint_rows(model, blocks)
                if blocks is not None:
                    rigid_targets(x, v, self._x_n, self._y, model.vertex_mass, blocks, gx, gy, keep, control.force,
                                  control.has_force, hs)
                self._has_last = True
                x_n = self._x_n
                # collide once, before the solve: the collider contacts and the body contacts of
                # the predicted motion (each held no closer than its pair began the step)
                count, n_body, found = self._collide(x_n, self._y, rects, ctopo, scr, hs, model.rigid)
                if parts == 1 and reach > 0.0:
                    size = self._edge_size(model)
                    deep = max(deepest_reach(self._y, v, self._planes, self._touch, count, ctopo, found, n_body, size,
                                             hs),
                               deepest_strain_reach(x_n, v, model.vertex_mass, model.body_vertex_offsets, size, hs,
                                                    model.rigid if blocks is not None else None)
                               / self.STRAIN_SHARE)
                    if deep > reach:
                        # an impact: the step in parts, each reaching past its contacts by
                        # less (in one step a soft box met at 5 m/s crushed the one below it)
                        parts = self.MAX_PARTS if deep >= self.MAX_PARTS * reach else math.ceil(deep / reach)
                        np.copyto(x, x_n)
                        np.copyto(self._v_last, self._v_saved)
                        self._has_last = had_last
                        advance_colliders(rects, -hs)
                        self.split += 1
                        continue
                k += 1
                # BDF2 away from the contact rows where the last step was whole and as long
                anchor, hd, free = x_n, hs, 0
                if second and parts == 1 and self._history == hs:
                    np.copyto(self._held_before, self._held)
                    rows_held(self._held, self._touch, count, ctopo, found, n_body, self._cpairs, self._n_corner)
                    n_v = len(self._held)
                    self._held |= jr.v[1:n_v + 1] > jr.v[:n_v]  # a joint's vertices: as a contact's
                    anchor = self._anchor
                    free = second_order_targets(x_n, self._y, self._v_n, self._x_prev, self._v_prev, self._x_end,
                                                self._v_end, anchor, mass_h2, model.vertex_mass, inv_mass, self._held,
                                                self._held_before, gx, gy, model.air_drag, control.force,
                                                control.has_force, hs)
                    if free:
                        hd = 2.0 * hs / 3.0  # the damping's velocity, (x - anchor) / h'
                if blocks is not None:
                    start_joint_rows(x_n, blocks, jr, opts["penalty_start"] / (hs * hs), model.vertex_mass, inv_mass,
                                     self.CARRY, self.SOFTEN, hs)
                k_start = opts["penalty_start"] * (mass_h2 + self._stiffness(model, hd))
                start_rows(self._touch, self._plane_rows, count, self._memory, self._vertex_row, self._rows, k_start,
                           self.CARRY, self.SOFTEN, opts["penalty_max"], self._planes, v, hs)
                rs = self._body_rows(model, ctopo, found, n_body, k_start, v, jr)
                if blocks is not None:
                    rigid_active(blocks, rs.rowed, control.grab_slot)
                    rigid_second_order(blocks, jr, keep, hs)
                    start_rigid_rows(model.rigid, opts["penalty_start"] * body_mass / (hs * hs), v, self._touch,
                                     self._planes, self._rows, count, rs, n_body, self._n_corner, hs)
                self._solve(model, topo, control, x, anchor, mass_h2, inv_mass, count, n_body, rs, hd,
                            opts["tolerance"] * hs, hs)
                if blocks is not None:
                    rigid_rates(blocks, hs)
                    joint_totals(jr, blocks, x, hs)
                close_rows(self._touch, self._plane_rows, count, self._memory, self._vertex_row, self._rows)
                close_body_rows(found, n_body, self._body_memory[0], rs.bstate)
                close_corner_rows(self._cpairs, self._n_corner, self._corner_memory[0], self._cstate)
                self._impulses.append(row_impulses(x, self._touch, self._plane_rows, self._planes, self._rows, count,
                                                   self._bidx, self._bgeo, self._bstate, n_body, self._cpairs,
                                                   self._cf, self._cstate, self._n_corner, hs))
                self.active_contacts = count + n_body + self._n_corner
                solved = x.copy() if free else None
                bad = finish_position_step(x, v, x_n, rects, hits, scr.status["stamp"][0] + 1, hs, vmax2)
                if blocks is not None:
                    rigid_place(x, x_n, v, blocks)
                if bad:
                    self._history = False
                    return StepReport(int(bad), contacts.complete)
                if self._n_corner:
                    # the corner rows' last word, as finish_position_step's projection is the
                    # collider rows': their penalty leaves a corner tens of micrometres through
                    # a loaded edge, put back here on the edges that have a row (the contact
                    # stage below still counts a corner no row held)
                    edges = self._cpairs[:self._n_corner, 2]
                    push_edges_off_corners(x, v, inv_mass, ctopo.ce_a[edges], ctopo.ce_b[edges], ctopo.cv_vertex,
                                           rects, hits)
                collided = x.copy()
                if contact_epilogue(x, v, inv_mass, x_n, self._failsafe_topology(ctopo), scr, contacts.buffer, rects,
                                    hits, hs, True) < 0:
                    self._history = False
                    return StepReport(0, False)
                if blocks is not None:
                    # the contact stage holds a rigid body's vertices (no inverse mass there)
                    # but its fail-safe may put one back where it began: the body stays whole
                    rigid_place(x, x_n, v, blocks)
                self.failsafe += not np.array_equal(x, collided)
                if free:
                    second_order_velocities(x, v, anchor, solved, self._held, inv_mass, hs)
                if second:
                    np.copyto(self._x_prev, x_n)
                    np.copyto(self._v_prev, self._v_n)
                    np.copyto(self._x_end, x)
                    np.copyto(self._v_end, v)
                    self._history = hs if parts == 1 else False
        return StepReport(0, contacts.complete)

    def _rigid_blocks(self, model):
        """``(blocks, body_mass)``: the rigid bodies as blocks of the sweep
        (:func:`~deforma.physics.integrators.avbd.rigid.rigid_blocks`) and per vertex its rigid
        body's mass (kg), or ``(None, None)`` without rigid bodies; once per Model and version
        (a pin holds a rigid body whole)."""
        key = (model, (model.version, model.joints is not None))
        if self._rigid is None or self._rigid[0] is not model or self._rigid[1] != key[1]:
            blocks = body_mass = None
            # joints on soft bodies alone take blocks too (none): their rows read the blocks
            if model.n_vertices and (model.rigid.any() or model.joints is not None):
                blocks = rigid_blocks(model, rigid_set(model))
                body_mass = np.zeros(model.n_vertices)
                for a, b, m in zip(blocks.lo, blocks.hi, blocks.mass):
                    body_mass[a:b] = m
                self._zeros = np.zeros(model.n_vertices)
            self._rigid = (*key, blocks, body_mass)
        return self._rigid[2], self._rigid[3]

    def _joint_rows(self, model, blocks):
        """The Model's joints (``model.joints``), or an empty set of rows for ``blocks`` (None:
        no rigid body) and the model's vertices."""
        jr = model.joints
        if jr is None:
            k = 0 if blocks is None else len(blocks.lo)
            if (self._no_joints is None or len(self._no_joints.j_start) != k + 1
                    or self._no_joints.v[0] != model.n_vertices + 1):
                self._no_joints = no_joint_rows(k, model.n_vertices)
            return self._no_joints
        return jr

    def _edge_size(self, model):
        """Per vertex, its shortest edge in its body's rest shape (m), once per Model (measured
        where a body was first stepped instead, a restart from a heap with corners crushed on
        a wall found edges of 0.08 mm and split every step in 13)."""
        if self._size is None or self._size[0] is not model:
            size = np.full(model.n_vertices, np.inf)
            for body, t in enumerate(model.topologies):
                tri = t.triangles
                e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]], t.springs]).astype(np.int64)
                if len(e):
                    p = t.rest_positions
                    v0 = int(model.body_vertex_offsets[body])
                    length = lengths(p, e[:, 0], e[:, 1])
                    np.minimum.at(size, v0 + e[:, 0], length)
                    np.minimum.at(size, v0 + e[:, 1], length)
            self._size = (model, size)
        return self._size[1]

    @staticmethod
    def _failsafe_topology(ctopo):
        """The contact topology the contact stage after the solve sees: every thickness
        at :data:`FAILSAFE_SHARE` of the rows'. The rows hold a pair at its thickness (to
        their penalty's tolerance); the stage, an inelastic response, takes away every
        approach of a pair it finds within its thickness, and at the rows' own it undid
        their work (two outlines the elements drew together by 5 mm in a step were put
        back where they began, step after step: the resting ``jelly`` stack buzzed)."""
        # made every step (three products of outline-length arrays): the thicknesses change
        # in place when a body's are set
        share = FAILSAFE_SHARE
        return ctopo._replace(thick_other=ctopo.thick_other * share, thick_self=ctopo.thick_self * share,
                              body_thickness=ctopo.body_thickness * share)

    def _collide(self, x_n, y, rects, ctopo, scr, h, rigid):
        """Collide once, before the solve: the collider contacts of the predicted motion
        from ``x_n`` to ``y`` and the body contacts within a margin of it, ``(count, n_body,
        buffer)``.

        Between bodies the margin is how far any vertex is predicted to move: a contact the
        sweeps make (a box landing on another, whose support shifts its prediction by
        millimetres) is then a row from the start, inactive while its gap stays open. Found
        only at the prediction itself, a box at 1/60 s sank through the one below it.
        Contacts of a body with itself keep its contact thickness."""
        count = contact_planes(x_n, y, rects, self._planes, self._touch, self._plane_rows, False, h)
        gather_start(x_n, ctopo, scr)  # for the contact stage after the sweep
        # the rows' own search, in scratch of its own: the widened one left candidate pairs
        # the stage after the sweep then tested (a block sliding at 1.5 m/s was braked by
        # its own outline there)
        margin = float(np.sqrt(((y - x_n) ** 2).sum(axis=1).max())) if len(y) else 0.0
        # (its pairs are listed once: a body's own by how its outline moves relative to
        # itself, not by how far the body goes, with the stage's margin as slack)
        wide = ctopo._replace(thick_other=ctopo.thick_other + margin, body_thickness=ctopo.body_thickness + margin,
                              margin=np.array([ctopo.margin[0] + SPECULATIVE * margin, ctopo.margin[0]]),
                              behind=self._behind)
        if self._search is None or self._search[0] is not ctopo:
            self._search = (ctopo, make_scratch(len(ctopo.cv_vertex), len(ctopo.ce_a), len(ctopo.body_thickness)),
                            make_buffer(64, 64))
        _, mine, found = self._search
        while True:
            gather_start(x_n, ctopo, mine)
            n_body = detect_contacts(y, wide, mine, found)
            if n_body >= 0:
                break
            found = make_buffer(2 * max(mine.status["needed"][0], len(found.vertex)),
                                2 * max(mine.status["pairs_needed"][0], len(found.pair_vertex)))
            mine.status["needed"][0] = 0
            mine.status["pairs_needed"][0] = 0
            self._search = (ctopo, mine, found)
        narrow_targets(ctopo, found, n_body, margin)
        full = found.target[:n_body].copy()
        hold_start_distance(x_n, ctopo, found, n_body)
        ease_apart(ctopo, found, n_body, full, rigid, EASE_SHARE * FAILSAFE_SHARE, EASE_SPEED * h)
        # collider corners an outline edge may meet, within the same margin
        while True:
            n_corner = corner_contacts(x_n, y, rects, ctopo.ce_a, ctopo.ce_b, ctopo.cv_vertex, margin, h,
                                       self._cpairs, self._cf)
            if n_corner >= 0:
                break
            self._cpairs = np.empty((-2 * n_corner, 4), np.int64)
            self._cf = np.empty((-2 * n_corner, CORNER_COLUMNS))
        self._n_corner = n_corner
        return count, n_body, found

    def _body_rows(self, model, ctopo, buf, n_body, k_start, v, jr):
        """The step's body rows, warm-started (:func:`~deforma.physics.integrators.avbd.rows.start_body_rows`),
        with the collider rows and the joints on soft bodies (``jr``) as one
        :class:`~deforma.physics.integrators.avbd.rows.RowSet`."""
        n_cv = len(ctopo.cv_vertex)
        if self._body_memory is None or self._body_memory[1] is not model:
            self._body_memory = (np.full((n_cv, MEMORY_COLUMNS), -1.0), model)
        if len(self._bstate) < n_body:
            self._bstate = np.empty((2 * n_body, ROW_COLUMNS))
            self._bidx = np.empty((2 * n_body, 3), np.int64)
            self._bgeo = np.empty((2 * n_body, BODY_COLUMNS))
            self._b_entry = np.empty(6 * n_body, np.int64)
        opts = self._options
        start_body_rows(ctopo, buf, n_body, self._body_memory[0], self._bstate, self._bidx, self._bgeo, k_start,
                        self.CARRY, self.SOFTEN, opts["penalty_max"], v, model.rigid)
        body_row_incidence(self._bidx, n_body, model.n_vertices, self._b_start, self._b_entry)
        nc = self._n_corner
        n_edges = len(ctopo.ce_a)
        if self._corner_memory is None or self._corner_memory[1] is not model:  # edges renumbered: no warm start
            self._corner_memory = (np.full((n_edges, MEMORY_COLUMNS), -1.0), model)
        if len(self._cstate) < nc:
            self._cstate = np.empty((2 * nc, ROW_COLUMNS))
            self._c_entry = np.empty(4 * nc, np.int64)
        start_corner_rows(self._cpairs, self._cf, nc, self._corner_memory[0], self._cstate, k_start, self.CARRY,
                          self.SOFTEN, opts["penalty_max"], v)
        corner_row_incidence(self._cpairs, nc, model.n_vertices, self._c_start, self._c_entry)
        if self._gas is None or self._gas[0] is not model:
            self._gas = (model, gas_set(model))
        gas = self._gas[1]
        np.multiply(model.body_pressure, model.body_pressure_area, out=gas.load)  # settable live
        mark_rowed(self._vertex_row, self._b_start, self._c_start, gas.start, jr.v, self._rowed)
        return RowSet(self._vertex_row, self._planes, self._rows, self._bidx, self._bgeo, self._bstate, self._b_start,
                      self._b_entry, self._cpairs, self._cf, self._cstate, self._c_start, self._c_entry, gas.start,
                      jr.v, jr.ji, jr.jf, self._rowed)

    def _solve(self, model, topo, control, x, x_n, mass_h2, inv_mass, count, n_body, rs, h, tol, h_rigid):
        """The sweeps of one substep, with the rows' dual steps and Chebyshev's weights
        (``h`` the soft vertices' damping step, ``2/3`` of the substep's ``h_rigid`` for BDF2)."""
        opts = self._options
        blocks = self._rigid[2]
        jr = self._joint_rows(model, blocks)
        coupled = None
        soft_joints = bool(jr.ji[:, SOFT].any())
        if blocks is not None and len(blocks.lo) and model.fused and not model.has_pressure:
            # the soft vertices with contact rows: swept again after each pass over the rigid
            # blocks (one serial colour: they are all rowed). Swept only with the others, a
            # jelly resting on a 24 kg crate buzzed at 5-80 mm/s (the crate, squeezed between
            # the jelly's stiff rows and the floor's, moved in its passes against vertices
            # that stood still until the next sweep); with this it rests as on a fixed box.
            sel = np.flatnonzero(rs.rowed & ~model.rigid & (inv_mass != 0.0)).astype(np.int64)
            coupled = (sel, np.array([0, len(sel)], np.int64))
        rho = opts["chebyshev"]
        _, t_start, t_item, t_corner, s_start, s_item, s_corner, order, starts = topo
        inv_h = 1.0 / h
        y = self._y
        if rho > 0.0:
            np.copyto(self._x1, x)
            np.copyto(self._x2, x)
        omega = 1.0
        if model.fused:
            tris, springs = model.triangles.arrays, model.springs.arrays
        patches = self._clusters(model, x_n)
        most = 0.0
        sweeps = opts["iterations"]
        if soft_joints and ((jr.ji[:, BLOCK:BLOCK + 2] < 0) & (jr.ji[:, FV:FV + 6:3] >= 0)).all(axis=1).any():
            # a joint between two soft bodies couples its two triangles' vertices stiffly,
            # which a vertex sweep relaxes slowly: at 10 sweeps a chain of six soft links
            # hanging still began to swing by itself (0.5 mm/s at 2 s, 13 cm/s at 4.5 s), at
            # 20 it hangs at 0.1 mm/s. (A soft body joined to a rigid one or to the world
            # keeps the budget: the car's tyres on their hubs, a jelly hung from a point.)
            sweeps = max(sweeps, self.SOFT_JOINT_SWEEPS)
        it = 0
        gas = self._gas[1] if model.has_pressure else None
        for it in range(sweeps):
            if gas is not None:
                gas_areas(x, gas)  # the whole-body step and the patches moved vertices too
            if model.fused and gas is None:
                which = self._which_sweep(model.n_vertices)
                kernel = sweep_parallel if which == "parallel" else sweep_serial
                start = time.perf_counter()
                most = kernel(x, x_n, y, mass_h2, inv_mass, order, starts, t_start, t_item, t_corner, tris.elem,
                              tris.b, tris.area, tris.mu, tris.lam, tris.beta, tris.kind, s_start, s_item, s_corner,
                              springs.i, springs.j, springs.rest, springs.ks, springs.kd, control.grab_slot,
                              control.grab_pull, rs, inv_h, self._moves)
                if self._options["mode"] == "auto" and which is not None:
                    self._driver.record(which, time.perf_counter() - start)
            else:
                most = self._sweep_kinds(model, control, x, x_n, mass_h2, inv_mass, order, starts, h, rs,
                                         self._gas[1])
            freeze_bounds(x, x_n, self._touch, self._planes, self._rows, count)
            freeze_body_bounds(x, x_n, rs.bidx, rs.bgeo, rs.bstate, n_body)
            freeze_corner_bounds(x, x_n, rs.cpairs, rs.cf, rs.cstate, self._n_corner)
            if patches is not None:
                cluster_sweep(x, x_n, y, mass_h2, *patches, tris.elem, tris.b, tris.area, tris.mu, tris.lam,
                              tris.beta, tris.kind, springs.i, springs.j, springs.rest, springs.ks, springs.kd,
                              control.grab_slot, control.grab_pull, rs, inv_h)
            rigid_correction(x, x_n, y, mass_h2, inv_mass, model.body_vertex_offsets, control.grab_slot,
                             control.grab_pull, rs)
            if blocks is not None and (coupled is None or not len(coupled[0])):
                most = max(most, rigid_passes(x, x_n, self._zeros, model.rigid, blocks, control.grab_slot,
                                              control.grab_pull, rs, jr, self._touch, self._planes, self._rows, count,
                                              n_body, self._n_corner, h_rigid, opts["penalty_ramp"],
                                              opts["penalty_max"], opts["rigid_passes"], it == sweeps - 1))
            elif blocks is not None:
                # the rigid blocks' passes, each followed by their rows' dual step and by the
                # soft vertices that touch them
                for q in range(opts["rigid_passes"]):
                    last = it == sweeps - 1 and q == opts["rigid_passes"] - 1
                    most = max(most, rigid_pass(x, x_n, self._zeros, model.rigid, blocks, control.grab_slot,
                                                control.grab_pull, rs, jr, self._touch, self._planes, self._rows, count,
                                                n_body, self._n_corner, h_rigid, opts["penalty_ramp"],
                                                opts["penalty_max"], last))
                    sweep_serial(x, x_n, y, mass_h2, inv_mass, coupled[0], coupled[1], t_start, t_item, t_corner,
                                 tris.elem, tris.b, tris.area, tris.mu, tris.lam, tris.beta, tris.kind, s_start,
                                 s_item, s_corner, springs.i, springs.j, springs.rest, springs.ks, springs.kd,
                                 control.grab_slot, control.grab_pull, rs, inv_h, self._moves)
            if soft_joints:
                # the joints with a soft side: their dual step after each sweep (their
                # vertices move in the sweeps and the whole-body steps, not in the passes over
                # the rigid blocks)
                update_joint_rows(jr, blocks, x, opts["penalty_ramp"], opts["penalty_max"], SOFT_JOINTS)
            if rho > 0.0:
                omega = chebyshev_omega(it, rho, omega)
                chebyshev(x, self._x1, self._x2, inv_mass, self._vertex_row, omega)
            if tol > 0.0 and most <= tol * tol:
                break
        if blocks is not None and len(jr.ji):
            # the joints to a tolerance: passes over the jointed bodies alone (cheap beside a
            # sweep). At the budget's passes a weight of 1000 links under a chain of 20 sagged
            # 4.7 % of its length before the rows carried it; with these, 0.5 %. Not where
            # an island has contacts: there the stiff joints won over the contact rows, and
            # the `chain` scene's crate went into the post it swings against
            for _ in range(self.JOINT_PASSES):
                if joint_gap(jr, blocks, x) <= self.JOINT_TOLERANCE:
                    break
                rigid_pass(x, x_n, self._zeros, model.rigid, blocks, control.grab_slot, control.grab_pull, rs, jr,
                           self._touch, self._planes, self._rows, count, n_body, self._n_corner, h_rigid,
                           opts["penalty_ramp"], opts["penalty_max"], False, True)
        # the rows' dual step, once a step: updated after every sweep, the multipliers of a
        # stiff body's contacts chased its unconverged sweeps (a 1e5 Pa block's support jumped
        # between its corners from sweep to sweep and it slid off a slope it should stand on)
        update_rows(x, x_n, self._touch, self._planes, self._rows, count, opts["penalty_ramp"], opts["penalty_max"])
        update_body_rows(x, x_n, rs.bidx, rs.bgeo, rs.bstate, n_body, opts["penalty_ramp"], opts["penalty_max"])
        update_corner_rows(x, x_n, rs.cpairs, rs.cf, rs.cstate, self._n_corner, opts["penalty_ramp"],
                           opts["penalty_max"])
        if blocks is not None:
            update_joint_rows(jr, blocks, x, opts["penalty_ramp"], opts["penalty_max"], RIGID_JOINTS)
        self.iterations_run += it + 1
        self.residual = math.sqrt(most) * inv_h
        if tol > 0.0 and most > tol * tol:
            self.unconverged += 1

    def _which_sweep(self, n):
        """The sweep's build for ``n`` vertices: ``"serial"`` below
        :data:`~deforma.physics.integrators.driver.PARALLEL_MIN_VERTICES` or on one thread,
        else as the option ``mode`` says (``auto``: :class:`~deforma.physics.integrators.driver.DriverChoice`'s
        measure; None then means serial without timing)."""
        mode = self._options["mode"]
        if mode == "serial" or n < PARALLEL_MIN_VERTICES or numba.get_num_threads() < 2:
            return "serial" if mode != "auto" else None
        return "parallel" if mode == "parallel" else self._driver.choose()

    def _sweep_kinds(self, model, control, x, x_n, mass_h2, inv_mass, order, starts, h, rs, gas):
        """One sweep with the elements' share of each colour's blocks from the kinds'
        :meth:`~deforma.physics.elements.kind.ElementKind.vertex_blocks` (every kind, once per
        colour: exact, since a colour's vertices share no element, and slow)."""
        n = model.n_vertices
        g, hb = np.zeros((n, 2)), np.zeros((n, 3))
        most = 0.0
        for c in range(len(starts) - 1):
            g[:] = 0.0
            hb[:] = 0.0
            for kind in model.elements:
                kind.vertex_blocks(x, x_n, h, g, hb)
            most = max(most, sweep_colour_given(x, x_n, self._y, mass_h2, inv_mass, order, starts[c], starts[c + 1],
                                                g, hb, control.grab_slot, control.grab_pull, rs, gas))
        return most


__all__ = ["AVBD"]

"""The contact response (step 3 of :mod:`deforma.physics.contact`): velocities with Coulomb
friction, then positions, split by inverse mass so that linear momentum is kept; and the
position-level projection the stable solvers run inside their sweeps.
"""

from __future__ import annotations

from numba import njit

from ..colliders.geometry import jump_reach, n_colliders, path_hits
from ..colliders.response import collide_point, record_hit
from ..colliders.shapes import RECT_XMAX, RECT_XMIN, RECT_YMAX, RECT_YMIN
from .contacts import note_moved
from .friction import coulomb


@njit(cache=True, inline="always")
def _pair_distance(x, ip, ia, ib, s, nx, ny):
    """How far vertex ``ip`` is in front of the point ``(1 - s) x_ia + s x_ib`` of its
    contact's edge, along the contact's normal ``(nx, ny)`` (m)."""
    ca = 1.0 - s
    return (x[ip, 0] - ca * x[ia, 0] - s * x[ib, 0]) * nx + (x[ip, 1] - ca * x[ia, 1] - s * x[ib, 1]) * ny


@njit(cache=True)
def hold_start_distance(x_start, topo, out, count):
    """Lower each contact's target in ``out[:count]`` to the distance its pair had at the
    start of the substep (``x_start``), if that was closer: a solver that holds contacts
    in its solve then keeps such a pair from closing in but does not push it apart.

    Why: those solvers derive velocities from positions, so a pair that started closer
    than its target (a body placed within another's contact thickness) was pushed out to
    it in one substep and flew apart (a box placed 5 cm into a 10 cm thickness left at 7.8
    m/s under implicit Euler, 7.5 m/s under XPBD). The contact stage after the solve restores
    the distance by positions only, without velocity, as it does under symplectic Euler.

    Examples
    --------
    >>> import numpy as np
    >>> i32 = lambda *v: np.array(v, np.int32)
    >>> from deforma.physics.contact.contacts import empty_topology, make_buffer
    >>> topo = empty_topology()._replace(cv_vertex=i32(0, 1, 2), ce_a=i32(1), ce_b=i32(2))
    >>> out = make_buffer(1, 1)  # vertex 0 above the edge from vertex 1 to vertex 2
    >>> out.vertex[0], out.edge[0], out.s[0], out.target[0], out.normal[0] = 0, 0, 0.5, 0.1, (0.0, 1.0)
    >>> hold_start_distance(np.array([[0.5, 0.04], [1.0, 0.0], [0.0, 0.0]]), topo, out, 1)
    >>> round(float(out.target[0]), 12)  # started 4 cm away: held there
    0.04
    """
    cv, ce_a, ce_b = topo.cv_vertex, topo.ce_a, topo.ce_b
    for c in range(count):
        ip = cv[out.vertex[c]]
        ia = cv[ce_a[out.edge[c]]]
        ib = cv[ce_b[out.edge[c]]]
        d = _pair_distance(x_start, ip, ia, ib, out.s[c], out.normal[c, 0], out.normal[c, 1])
        if d < out.target[c]:
            out.target[c] = max(d, 0.0)


@njit(cache=True)
def project_contacts(x, x_prev, inv_mass, topo, out, count, stick):
    """One Gauss-Seidel pass of position projections over the contacts ``out[:count]``.

    A vertex closer to its edge than the contact's target is pushed out to it, the
    correction split by inverse mass (``w_p``, ``(1 - s) w_a``, ``s w_b``), so that linear
    momentum is kept. Then Coulomb friction at position level (Macklin et al. 2020), as the
    XPBD sweep treats colliders: the pair's relative motion along the edge since the substep
    began (``x_prev``) is undone if it is within ``static friction * push``, the contact
    then sticks for the rest of the substep; otherwise it slides, held back by ``dynamic
    friction * push`` in each pass. ``stick[c]`` holds the decision: -1 before the first
    pass (set it so), then 1 stuck, 0 sliding (as is a pair not touching in the first pass:
    it gets friction from the pass it touches in, from its push there). Positions only: the
    solver derives velocities afterwards.

    Examples
    --------
    A vertex pressed 1 mm into a fixed edge while it slid 0.1 mm along it (static friction
    0.5): pushed back out, and its sliding undone.

    >>> import numpy as np
    >>> i32 = lambda *v: np.array(v, np.int32)
    >>> from deforma.physics.contact.contacts import empty_topology, make_buffer
    >>> topo = empty_topology()._replace(cv_vertex=i32(0, 1, 2), ce_a=i32(1), ce_b=i32(2))
    >>> out = make_buffer(1, 1)  # vertex 0 against the edge from vertex 1 to vertex 2, at its middle
    >>> out.vertex[0], out.edge[0], out.s[0], out.target[0] = 0, 0, 0.5, 0.0
    >>> out.normal[0], out.mu[0] = (0.0, 1.0), (0.3, 0.5)
    >>> x_prev = np.array([[0.5, 0.0], [1.0, 0.0], [0.0, 0.0]])
    >>> x = np.array([[0.5001, -0.001], [1.0, 0.0], [0.0, 0.0]])
    >>> stick = np.array([-1.0])
    >>> project_contacts(x, x_prev, np.array([1.0, 0.0, 0.0]), topo, out, 1, stick)
    >>> x[0].round(12).tolist(), stick.tolist()
    ([0.5, 0.0], [1.0])
    """
    cv, ce_a, ce_b = topo.cv_vertex, topo.ce_a, topo.ce_b
    o_vertex, o_edge, o_s, o_normal, o_target, o_mu = out.vertex, out.edge, out.s, out.normal, out.target, out.mu
    for c in range(count):
        ip = cv[o_vertex[c]]
        ia = cv[ce_a[o_edge[c]]]
        ib = cv[ce_b[o_edge[c]]]
        s = o_s[c]
        ca = 1.0 - s
        nx = o_normal[c, 0]
        ny = o_normal[c, 1]
        wp = inv_mass[ip]
        wa = inv_mass[ia] * ca
        wb = inv_mass[ib] * s
        w = wp + wa * ca + wb * s
        if w <= 0.0:
            continue
        d = _pair_distance(x, ip, ia, ib, s, nx, ny)
        push = o_target[c] - d
        if push > 0.0:
            lam = push / w
            _split(x, ip, ia, ib, wp, wa, wb, lam * nx, lam * ny)
        else:
            push = 0.0
        if stick[c] == 0.0 and push == 0.0:
            continue  # sliding and not touching in this pass: no friction
        # relative motion along the edge since the substep began, t = (-ny, nx)
        rx = (x[ip, 0] - x_prev[ip, 0]) - ca * (x[ia, 0] - x_prev[ia, 0]) - s * (x[ib, 0] - x_prev[ib, 0])
        ry = (x[ip, 1] - x_prev[ip, 1]) - ca * (x[ia, 1] - x_prev[ia, 1]) - s * (x[ib, 1] - x_prev[ib, 1])
        slide = -rx * ny + ry * nx
        if stick[c] < 0.0:
            stick[c] = 1.0 if push > 0.0 and abs(slide) <= o_mu[c, 1] * push else 0.0  # touching only
        if stick[c] == 0.0:
            slide = min(abs(slide), o_mu[c, 0] * push) * (1.0 if slide > 0.0 else -1.0)
        lam = -slide / w
        _split(x, ip, ia, ib, wp, wa, wb, -lam * ny, lam * nx)


# -- response ----------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _keep_out(x, v, i, x0, y0, rects, reach2, h):
    # A vertex that the response moved into a collider, or through a thin one since the start
    # of the substep, meets it there and then: the collider response (infinite mass, its
    # velocity rule and friction), after the same cheap tests as in the integrators' pass.
    px, py = x[i, 0], x[i, 1]
    near = (px - x0) * (px - x0) + (py - y0) * (py - y0) > reach2
    for r in range(n_colliders(rects)):
        if rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX] and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]:
            near = True
    if near:
        x[i, 0], x[i, 1], v[i, 0], v[i, 1], _, _, _, _ = collide_point(x0, y0, px, py, v[i, 0], v[i, 1], rects, h)


@njit(cache=True, inline="always")
def _keep_out_three(x, v, xp, rects, reach2, h, ip, ia, ib, k, a, b):
    _keep_out(x, v, ip, xp[k, 0], xp[k, 1], rects, reach2, h)
    _keep_out(x, v, ia, xp[a, 0], xp[a, 1], rects, reach2, h)
    _keep_out(x, v, ib, xp[b, 0], xp[b, 1], rects, reach2, h)


@njit(cache=True, inline="always")
def _split(a, ip, ia, ib, wp, wa, wb, px, py):
    # a change (px, py) of the pair, shared by the vertex and the edge's ends by inverse mass
    a[ip, 0] += wp * px
    a[ip, 1] += wp * py
    a[ia, 0] -= wa * px
    a[ia, 1] -= wa * py
    a[ib, 0] -= wb * px
    a[ib, 1] -= wb * py


@njit(cache=True)
def solve_contacts(x, v, inv_mass, topo, scr, out, first, last, rects, h, iterations, follow=True):
    """Impulses (once) and position corrections (``iterations`` sweeps) for contacts ``first:last``.

    See the module docstring; linear momentum is kept exactly, since every impulse is split
    between the vertex and the edge's ends by inverse mass. ``follow``: the impulses move the
    vertices too, by ``h`` times their velocity change (see :func:`contact_stage`). A vertex
    the response moves into a collider meets it at once
    (:func:`~deforma.physics.colliders.response.collide_point`), so that the sweeps settle with the
    colliders in place.
    """
    cv, ce_a, ce_b = topo.cv_vertex, topo.ce_a, topo.ce_b
    o_vertex, o_edge, o_s, o_normal, o_target, o_mu = out.vertex, out.edge, out.s, out.normal, out.target, out.mu
    xp = scr.xp
    check_rects = rects.shape[0] > 0
    reach2 = jump_reach(rects)
    status = scr.status
    dirty, dirty_mark, touched, touched_mark = scr.dirty, scr.dirty_mark, scr.touched, scr.touched_mark
    gen, stamp = status.generation[0], status.stamp[0]
    for c in range(first, last):  # the vertices this solve may move
        note_moved(o_vertex[c], dirty, dirty_mark, gen, touched, touched_mark, stamp, status)
        note_moved(ce_a[o_edge[c]], dirty, dirty_mark, gen, touched, touched_mark, stamp, status)
        note_moved(ce_b[o_edge[c]], dirty, dirty_mark, gen, touched, touched_mark, stamp, status)
    inv_h = 1.0 / h
    for sweep in range(iterations):
        for c in range(first, last):
            ip = cv[o_vertex[c]]
            ia = cv[ce_a[o_edge[c]]]
            ib = cv[ce_b[o_edge[c]]]
            s = o_s[c]
            ca = 1.0 - s
            wp = inv_mass[ip]
            wa = inv_mass[ia] * ca
            wb = inv_mass[ib] * s
            w = wp + wa * ca + wb * s
            if w <= 0.0:
                continue  # both sides pinned
            nx = o_normal[c, 0]
            ny = o_normal[c, 1]
            if sweep == 0:
                # Speculative: a pair still farther than its target may approach by what is
                # left of the gap in the next substep, no more; closer pairs may not approach.
                # So a resting pair's support never lapses (it would pop out and back in).
                d = _pair_distance(x, ip, ia, ib, s, nx, ny)
                allowed = -max(d - o_target[c], 0.0) * inv_h
                rvx = v[ip, 0] - ca * v[ia, 0] - s * v[ib, 0]
                rvy = v[ip, 1] - ca * v[ia, 1] - s * v[ib, 1]
                vn = rvx * nx + rvy * ny
                if vn < allowed:
                    jn = allowed - vn
                    vt = ny * rvx - nx * rvy        # along t = (ny, -nx)
                    dvt = coulomb(vt, jn, o_mu[c, 1], o_mu[c, 0]) - vt
                    px = (jn * nx + dvt * ny) / w   # the pair's impulse per unit inverse mass
                    py = (jn * ny - dvt * nx) / w
                    _split(v, ip, ia, ib, wp, wa, wb, px, py)
                    if follow:  # positions follow: no creep
                        _split(x, ip, ia, ib, wp, wa, wb, h * px, h * py)
                    if check_rects:
                        _keep_out_three(x, v, xp, rects, reach2, h, ip, ia, ib, o_vertex[c], ce_a[o_edge[c]],
                                        ce_b[o_edge[c]])
            d = _pair_distance(x, ip, ia, ib, s, nx, ny)
            gap = o_target[c] - d
            if gap > 0.0:
                lam = gap / w
                _split(x, ip, ia, ib, wp, wa, wb, lam * nx, lam * ny)
                if check_rects:
                    _keep_out_three(x, v, xp, rects, reach2, h, ip, ia, ib, o_vertex[c], ce_a[o_edge[c]],
                                    ce_b[o_edge[c]])


@njit(cache=True)
def collider_pass(x, v, topo, scr, rects, hits, h):
    """The collider response (:func:`~deforma.physics.colliders.response.collide_point`) for every vertex
    the stage moved into (or through) a collider; returns how many it moved, which it lists
    as moved for the next check."""
    cv, xp = topo.cv_vertex, scr.xp
    reach2 = jump_reach(rects)
    n_rects = n_colliders(rects)
    status = scr.status
    dirty, dirty_mark, touched, touched_mark = scr.dirty, scr.dirty_mark, scr.touched, scr.touched_mark
    moved = 0
    for m in range(status.touched[0]):
        k = touched[m]
        i = cv[k]
        px, py = x[i, 0], x[i, 1]
        near = (px - xp[k, 0]) * (px - xp[k, 0]) + (py - xp[k, 1]) * (py - xp[k, 1]) > reach2
        for r in range(n_rects):  # the integrators' cheap tests first
            if rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX] and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]:
                near = True
        if near and path_hits(xp[k, 0], xp[k, 1], px, py, rects):
            ux, uy = v[i, 0], v[i, 1]
            x[i, 0], x[i, 1], v[i, 0], v[i, 1], hit, nx, ny, depth = collide_point(
                xp[k, 0], xp[k, 1], px, py, v[i, 0], v[i, 1], rects, h)
            if hit >= 0:  # (path_hits sees rigid outlines too; collide_point leaves them be)
                record_hit(hits, i, status.stamp[0], hit, nx, ny, depth, px, py, ux, uy, x[i, 0], x[i, 1],
                           v[i, 0], v[i, 1])
            note_moved(k, dirty, dirty_mark, status.generation[0], touched, touched_mark, status.stamp[0], status)
            moved += 1
    return moved

"""Broad phase (steps 0 and 1 of :mod:`deforma.physics.contact`): which vertices are tested,
and which outline edges each may meet, through a uniform grid built anew every substep.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .contacts import COLLIDE, SELF_COLLIDE


# -- broad phase -------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def grid_bucket(ix, iy, mask):
    return ((ix * np.int64(73856093)) ^ (iy * np.int64(19349663))) & mask


@njit(cache=True)
def build_grid(x, topo, scr, margin):
    """Hash the swept box of every active outline edge (grown by ``margin`` m) into the grid.

    The swept box spans the edge's ends at the start (``scr.xp``) and now (``x``). Returns
    the number of edges in the grid.
    """
    ce_a, ce_b, ce_body, cv = topo.ce_a, topo.ce_b, topo.ce_body, topo.cv_vertex
    flags = topo.body_flags
    xp, ebox, ecell = scr.xp, scr.ebox, scr.ecell
    n_edges = ce_a.shape[0]
    active = 0
    extent = 0.0
    ox = np.inf
    oy = np.inf
    for j in range(n_edges):
        if flags[ce_body[j]] == 0:
            ebox[j, 0] = np.inf  # never overlaps anything
            continue
        a = ce_a[j]
        b = ce_b[j]
        ia = cv[a]
        ib = cv[b]
        x0 = min(min(xp[a, 0], xp[b, 0]), min(x[ia, 0], x[ib, 0])) - margin
        x1 = max(max(xp[a, 0], xp[b, 0]), max(x[ia, 0], x[ib, 0])) + margin
        y0 = min(min(xp[a, 1], xp[b, 1]), min(x[ia, 1], x[ib, 1])) - margin
        y1 = max(max(xp[a, 1], xp[b, 1]), max(x[ia, 1], x[ib, 1])) + margin
        ebox[j, 0] = x0
        ebox[j, 1] = y0
        ebox[j, 2] = x1
        ebox[j, 3] = y1
        extent += max(x1 - x0, y1 - y0)
        ox = min(ox, x0)
        oy = min(oy, y0)
        active += 1
    if active == 0:
        return 0
    cell = extent / active
    if not cell > 0.0:
        cell = 1.0
    t = scr.cell_fill.shape[0]
    mask = np.int64(t - 1)
    start, fill, items = scr.cell_start, scr.cell_fill, scr.cell_items
    while True:  # a few fast edges can cover many small cells: coarsen until the items fit
        inv = 1.0 / cell
        total = 0
        for j in range(n_edges):
            if ebox[j, 0] == np.inf:
                continue
            ecell[j, 0] = np.int64((ebox[j, 0] - ox) * inv)  # >= 0: truncation is floor
            ecell[j, 1] = np.int64((ebox[j, 1] - oy) * inv)
            ecell[j, 2] = np.int64((ebox[j, 2] - ox) * inv)
            ecell[j, 3] = np.int64((ebox[j, 3] - oy) * inv)
            total += (ecell[j, 2] - ecell[j, 0] + 1) * (ecell[j, 3] - ecell[j, 1] + 1)
        if total <= items.shape[0]:
            break
        cell *= 2.0
    start[:] = 0
    for j in range(n_edges):
        if ebox[j, 0] == np.inf:
            continue
        for ix in range(ecell[j, 0], ecell[j, 2] + 1):
            for iy in range(ecell[j, 1], ecell[j, 3] + 1):
                start[grid_bucket(ix, iy, mask) + 1] += 1
    for k in range(t):
        start[k + 1] += start[k]
        fill[k] = start[k]
    for j in range(n_edges):  # edge by edge: an edge's entries in one bucket are adjacent
        if ebox[j, 0] == np.inf:
            continue
        for ix in range(ecell[j, 0], ecell[j, 2] + 1):
            for iy in range(ecell[j, 1], ecell[j, 3] + 1):
                bk = grid_bucket(ix, iy, mask)
                items[fill[bk]] = j
                fill[bk] += 1
    scr.grid[0] = ox
    scr.grid[1] = oy
    scr.grid[2] = inv
    for m in range(scr.status.active[0]):
        k = scr.active[m]
        scr.xq[k, 0] = x[cv[k], 0]
        scr.xq[k, 1] = x[cv[k], 1]
    return active


@njit(cache=True)
def index_pairs(topo, scr, out, n_pairs):
    """For each collision vertex, the candidate pairs it is part of (as the vertex or an end of
    the edge): a CSR in ``scr.pair_ptr`` / ``out.pair_index``."""
    ptr, fill, index = scr.pair_ptr, scr.pair_fill, out.pair_index
    pv, pe, ce_a, ce_b = out.pair_vertex, out.pair_edge, topo.ce_a, topo.ce_b
    ptr[:] = 0
    for m in range(n_pairs):
        ptr[pv[m] + 1] += 1
        ptr[ce_a[pe[m]] + 1] += 1
        ptr[ce_b[pe[m]] + 1] += 1
    for k in range(ptr.shape[0] - 1):
        ptr[k + 1] += ptr[k]
        fill[k] = ptr[k]
    for m in range(n_pairs):
        for k in (pv[m], ce_a[pe[m]], ce_b[pe[m]]):
            index[fill[k]] = m
            fill[k] += 1


@njit(cache=True)
def colliding_bodies(topo):
    n = 0
    flags = topo.body_flags
    for b in range(flags.shape[0]):
        if flags[b] & COLLIDE:
            n += 1
    return n


@njit(cache=True)
def gather_start(x, topo, scr):
    """Note where the collision vertices are at the start of a substep (``scr.xp``).

    Every outline vertex; the other vertices of colliding bodies too when two or more bodies
    collide (they must not enter another body either, should their body fold), with each
    body's box of them, which :func:`contact_stage` grows to the swept box.
    """
    cv, xp, box = topo.cv_vertex, scr.xp, scr.body_box
    for k in range(topo.body_interior[0]):
        xp[k, 0] = x[cv[k], 0]
        xp[k, 1] = x[cv[k], 1]
    if colliding_bodies(topo) < 2:
        return
    for b in range(topo.body_flags.shape[0]):
        box[b, 0] = np.inf
        box[b, 1] = np.inf
        box[b, 2] = -np.inf
        box[b, 3] = -np.inf
        if (topo.body_flags[b] & COLLIDE) == 0:
            continue
        for lo, hi in ((topo.body_outline[b], topo.body_outline[b + 1]),
                       (topo.body_interior[b], topo.body_interior[b + 1])):
            for k in range(lo, hi):
                px = x[cv[k], 0]
                py = x[cv[k], 1]
                xp[k, 0] = px
                xp[k, 1] = py
                box[b, 0] = min(box[b, 0], px)
                box[b, 1] = min(box[b, 1], py)
                box[b, 2] = max(box[b, 2], px)
                box[b, 3] = max(box[b, 3], py)


@njit(cache=True)
def _activate_inner(x, topo, scr, b, n, near, n_near):
    """Append to ``scr.active`` the off-outline vertices of body ``b`` whose swept box meets
    the box of one of the bodies ``near[:n_near]`` (grown by the margin)."""
    cv, xp, box, active = topo.cv_vertex, scr.xp, scr.body_box, scr.active
    margin = topo.margin[0]
    for k in range(topo.body_interior[b], topo.body_interior[b + 1]):
        x0 = min(xp[k, 0], x[cv[k], 0]) - margin
        x1 = max(xp[k, 0], x[cv[k], 0]) + margin
        y0 = min(xp[k, 1], x[cv[k], 1]) - margin
        y1 = max(xp[k, 1], x[cv[k], 1]) + margin
        for m in range(n_near):
            c = near[m]
            if x0 <= box[c, 2] and box[c, 0] <= x1 and y0 <= box[c, 3] and box[c, 1] <= y1:
                active[n] = k
                n += 1
                break
    return n


@njit(cache=True)
def activate_vertices(x, topo, scr):
    """List the collision vertices to test this substep in ``scr.active``; returns how many.

    None if nothing can touch (no self contact and fewer than two colliding bodies). Else
    every outline vertex of a body with contacts on; and, of a colliding body, the other
    vertices whose swept box meets another colliding body's swept box (grown by the
    margin). Self contact keeps an outline from crossing itself, and a body whose
    triangles all keep their orientation lies inside its outline, so only a folded body
    can carry a vertex that is not on the outline into another; but where a body is folded
    at the end of the stage is not known before it (the response moves outline vertices),
    and a folded flap carries along vertices of triangles that are not turned over. So
    every vertex that may meet another body is tested: sound, and cheap, since a vertex
    off the outline meets another body's edges only where it has entered it.
    """
    cv, flags, box, active = topo.cv_vertex, topo.body_flags, scr.body_box, scr.active
    n = 0
    touching = colliding_bodies(topo) >= 2
    for b in range(flags.shape[0]):
        touching = touching or (flags[b] & SELF_COLLIDE) != 0
    if not touching:  # one colliding body, without self contact: nothing can touch
        scr.status.active[0] = 0
        return 0
    for b in range(flags.shape[0]):
        if flags[b] != 0:
            for k in range(topo.body_outline[b], topo.body_outline[b + 1]):
                active[n] = k
                n += 1
    nb = flags.shape[0]
    if colliding_bodies(topo) >= 2:
        margin = topo.margin[0]
        for b in range(nb):  # the start box (gather_start) grown to the end positions
            if (flags[b] & COLLIDE) == 0:
                continue
            for lo, hi in ((topo.body_outline[b], topo.body_outline[b + 1]),
                           (topo.body_interior[b], topo.body_interior[b + 1])):
                for k in range(lo, hi):
                    box[b, 0] = min(box[b, 0], x[cv[k], 0])
                    box[b, 1] = min(box[b, 1], x[cv[k], 1])
                    box[b, 2] = max(box[b, 2], x[cv[k], 0])
                    box[b, 3] = max(box[b, 3], x[cv[k], 1])
        near = np.empty(nb, np.int64)
        for b in range(nb):
            if (flags[b] & COLLIDE) == 0:
                continue
            n_near = 0
            for c in range(nb):
                if c == b or (flags[c] & COLLIDE) == 0:
                    continue
                if box[b, 0] - margin <= box[c, 2] and box[c, 0] - margin <= box[b, 2] \
                        and box[b, 1] - margin <= box[c, 3] and box[c, 1] - margin <= box[b, 3]:
                    near[n_near] = c
                    n_near += 1
            if n_near:
                n = _activate_inner(x, topo, scr, b, n, near, n_near)
    scr.status.active[0] = n
    return n

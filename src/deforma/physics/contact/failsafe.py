"""The fail-safe of the contact stage (step 4 of :mod:`deforma.physics.contact`): impact zones
(Bridson, Fedkiw and Anderson 2002, translations only) that leave no crossing for sure.
"""

from __future__ import annotations

from numba import njit

from ..colliders.geometry import path_hits
from ..union_find import find_root
from .contacts import note_moved
from .narrow_phase import check_pairs, refresh_pairs


@njit(cache=True)
def impact_zones(x, v, inv_mass, topo, scr, out, first, n_pairs, rects, h):
    """The fail-safe: merge crossing pairs into rigidly translating zones until none is left.

    Checks the pairs of the vertices moved since the last check (``scr.dirty``), and keeps
    its bookkeeping to the zones' members, so that a few crossings in a large heap cost
    little. Returns the number of merge rounds, or ``-(needed)`` if ``out`` is too small
    (then ``scr.status`` says which part).
    """
    cv, ce_a, ce_b, o_vertex, o_edge = topo.cv_vertex, topo.ce_a, topo.ce_b, out.vertex, out.edge
    parent, zone, xp = scr.parent, scr.zone, scr.xp
    zl, zm = scr.zone_list, scr.zone_mark
    status = scr.status
    dirty, dirty_mark, touched, touched_mark = scr.dirty, scr.dirty_mark, scr.touched, scr.touched_mark
    margin = topo.margin[0]
    call = status.generation[0]  # marks this call's zone members
    nz = 0
    for rounds in range(status.active[0] + 1):
        n_pairs, rebuilt = refresh_pairs(x, topo, scr, out, margin, n_pairs)
        if n_pairs < 0:
            status.pairs_needed[0] = -n_pairs
            return n_pairs
        n = check_pairs(x, topo, scr, out, first, n_pairs, rebuilt, True)
        if n < 0:
            status.needed[0] = -n
            return n
        if n == first:
            return rounds
        for c in range(first, n):
            for q in (o_vertex[c], ce_a[o_edge[c]], ce_b[o_edge[c]]):
                if zm[q] != call:
                    zm[q] = call
                    parent[q] = q
                    zl[nz] = q
                    nz += 1
            k = find_root(parent, o_vertex[c])
            for q in (ce_a[o_edge[c]], ce_b[o_edge[c]]):
                r = find_root(parent, q)
                if r != k:
                    parent[r] = k
        # zone sums: m vx, m vy, m, members, still (1: a pinned member, 2: pushed into a collider)
        for m in range(nz):
            zone[zl[m], :] = 0.0
        for m in range(nz):
            k = zl[m]
            r = find_root(parent, k)
            i = cv[k]
            zone[r, 3] += 1.0
            if inv_mass[i] == 0.0:
                zone[r, 4] = 1.0
            else:
                mass = 1.0 / inv_mass[i]
                zone[r, 0] += mass * v[i, 0]
                zone[r, 1] += mass * v[i, 1]
                zone[r, 2] += mass
        gen, stamp = status.generation[0], status.stamp[0]
        frozen = False
        for m in range(nz):
            k = zl[m]
            r = find_root(parent, k)
            i = cv[k]
            vx = 0.0
            vy = 0.0
            if zone[r, 4] == 0.0 and zone[r, 2] > 0.0:
                vx = zone[r, 0] / zone[r, 2]
                vy = zone[r, 1] / zone[r, 2]
            v[i, 0] = vx
            v[i, 1] = vy
            x[i, 0] = xp[k, 0] + h * vx
            x[i, 1] = xp[k, 1] + h * vy
            note_moved(k, dirty, dirty_mark, gen, touched, touched_mark, stamp, status)
            if path_hits(xp[k, 0], xp[k, 1], x[i, 0], x[i, 1], rects):
                zone[r, 4] = 2.0
                frozen = True
        if frozen:  # a zone pushed into a collider stays where it started (outside, like every start)
            for m in range(nz):
                k = zl[m]
                if zone[find_root(parent, k), 4] == 2.0:
                    i = cv[k]
                    v[i, 0] = 0.0
                    v[i, 1] = 0.0
                    x[i, 0] = xp[k, 0]
                    x[i, 1] = xp[k, 1]
    return status.active[0] + 1

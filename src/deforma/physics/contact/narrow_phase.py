"""Narrow phase (step 2 of :mod:`deforma.physics.contact`): a vertex against an outline edge,
by proximity at the end of the substep or by a crossing of the straight-line motion
(continuous collision detection), and the checks the verify step repeats.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .broad_phase import activate_vertices, build_grid, grid_bucket, index_pairs
from .contacts import COLLIDE, CROSSING, PROXIMITY, SELF_COLLIDE, SIDE_MARGIN, SPECULATIVE
from .friction import mix


# -- narrow phase ------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _cross_at(t, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey):
    qx = q0x + t * dqx
    qy = q0y + t * dqy
    ex = e0x + t * dex
    ey = e0y + t * dey
    return qx * ey - qy * ex


@njit(cache=True)
def pair_contact(p0x, p0y, p1x, p1y, a0x, a0y, a1x, a1y, b0x, b0y, b1x, b1y, thickness, behind=0.0):
    """Contact of a point moving ``p0 -> p1`` with an edge moving ``(a0, b0) -> (a1, b1)``.

    The edge's body lies on its left; ``d`` is the point's signed distance from the edge's
    line, positive in front. The side the point starts on is the exact sign of ``d0``.
    Returns ``(kind, s, nx, ny, depth, target)``: ``kind`` is 0 (no contact),
    ``PROXIMITY`` (started in front, ended within ``thickness`` m in front of the segment)
    or ``CROSSING`` (crossed the segment, from either side); ``s`` the foot's position along the edge; ``(nx, ny)`` the unit normal toward
    the side the point must stay on; ``target`` the distance from the line along it that
    the response restores, and ``depth`` how far the point is from it. A point that starts
    behind the line by less than ``behind`` (m), its foot on the edge, is taken as starting in
    front: a vertex a little inside another body, which a solver's rows then hold out (two
    rigid boxes that met at 2.5 m/s ended a step 0.03 mm into each other; seen as behind, the
    pairs were no contacts from then on, and the top box sank in and tipped over).

    Examples
    --------
    The edge runs from (1, 0) to (0, 0), so its body lies below it:

    >>> k, s, nx, ny, depth, target = pair_contact(0.5, 1, 0.5, -0.5, 1, 0, 1, 0, 0, 0, 0, 0, 0.01)
    >>> k == CROSSING, s, (nx, ny), depth, target     # fell through the edge from above
    (True, 0.5, (0.0, 1.0), 0.51, 0.01)
    >>> pair_contact(0.5, 0.1, 0.5, 0.005, 1, 0, 1, 0, 0, 0, 0, 0, 0.01)[0] == PROXIMITY
    True
    >>> k, s, nx, ny, depth, target = pair_contact(0.5, -0.1, 0.5, 0.2, 1, 0, 1, 0, 0, 0, 0, 0, 0.01)
    >>> k == CROSSING, (nx, ny), round(depth, 6)      # from behind: held behind, at its start distance
    (True, (-0.0, -1.0), 0.3)

    A point that stays put at (0.5, 0.5), in front of the edge's line at the start and at the
    end, while the edge swings past it: the line passes it twice, first beyond the edge's
    end (it is then behind, legitimately), then with the segment itself. Held behind:

    >>> k, s, nx, ny, depth, target = pair_contact(0.5, 0.5, 0.5, 0.5, -1, -1, -1, 2, -1, 0, 2, 0, 0.01)
    >>> k == CROSSING, round(s, 3), (round(nx, 3), round(ny, 3))  # the normal out of the back
    (True, 0.634, (0.555, 0.832))
    """
    e0x = b0x - a0x
    e0y = b0y - a0y
    l0 = e0x * e0x + e0y * e0y
    e1x = b1x - a1x
    e1y = b1y - a1y
    l1 = e1x * e1x + e1y * e1y
    if l0 <= 0.0 or l1 <= 0.0:
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0
    q0x = p0x - a0x
    q0y = p0y - a0y
    f0 = q0x * e0y - q0y * e0x          # d0 * |e0|
    front = f0 >= 0.0
    if not front and f0 * f0 < behind * behind * l0:
        s0 = (q0x * e0x + q0y * e0y) / l0
        front = 0.0 <= s0 <= 1.0
    q1x = p1x - a1x
    q1y = p1y - a1y
    f1 = q1x * e1y - q1y * e1x          # d1 * |e1|
    dqx = q1x - q0x
    dqy = q1y - q0y
    dex = e1x - e0x
    dey = e1y - e0y
    # f(t) = (q0 + t dq) x (e0 + t de), |e(t)| times the distance from the moving line, is a
    # quadratic in t: on the same side at both ends, the point may still have crossed the
    # line twice (around an end of the edge, then back through the edge itself: an edge
    # turning fast at a large step). Its extremum tells.
    if (f1 >= 0.0) == front:
        qa = dqx * dey - dqy * dex
        tm = -0.5 * ((q0x * dey - q0y * dex) + (dqx * e0y - dqy * e0x)) / qa if qa != 0.0 else -1.0
        if 0.0 < tm < 1.0 and (_cross_at(tm, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey) >= 0.0) != front:
            # two crossings of the line, at t1 < tm < t2; the first through the segment counts
            t1, s1 = _line_crossing(0.0, tm, front, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey)
            if 0.0 <= s1 <= 1.0:
                return _crossed(front, s1, f0, f1, l0, e1x, e1y, l1, thickness, True)
            t2, s2 = _line_crossing(tm, 1.0, not front, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey)
            if 0.0 <= s2 <= 1.0:  # came back through the segment: the side it held in between
                return _crossed(not front, s2, f0, f1, l0, e1x, e1y, l1, thickness, False)
        if not front:
            return 0, 0.0, 0.0, 0.0, 0.0, 0.0  # stayed behind
        reach = SPECULATIVE * thickness
        if f1 * f1 >= reach * reach * l1:
            return 0, 0.0, 0.0, 0.0, 0.0, 0.0  # clear in front: the common case, no root taken
        s1 = (q1x * e1x + q1y * e1y) / l1
        if 0.0 <= s1 <= 1.0:
            r1 = math.sqrt(l1)
            return PROXIMITY, s1, e1y / r1, -e1x / r1, thickness - f1 / r1, thickness
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0
    # the point changed sides of the line (one root): did it cross the segment itself?
    t, s = _line_crossing(0.0, 1.0, front, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey)
    if s < 0.0 or s > 1.0:
        return 0, 0.0, 0.0, 0.0, 0.0, 0.0  # passed the line beyond the segment's ends
    return _crossed(front, s, f0, f1, l0, e1x, e1y, l1, thickness, True)


@njit(cache=True, inline="always")
def _line_crossing(lo, hi, side, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey):
    """The time in ``[lo, hi]`` at which the point reaches the moving line, leaving ``side``
    (``f(lo)`` on it, ``f(hi)`` not: one sign change, found by bisection), and where along
    the edge it does (``s``; outside [0, 1]: beyond the ends, 2.0 for a vanished edge)."""
    for _ in range(48):
        mid = 0.5 * (lo + hi)
        if (_cross_at(mid, q0x, q0y, dqx, dqy, e0x, e0y, dex, dey) >= 0.0) == side:
            lo = mid
        else:
            hi = mid
    qx = q0x + hi * dqx
    qy = q0y + hi * dqy
    ex = e0x + hi * dex
    ey = e0y + hi * dey
    lt = ex * ex + ey * ey
    if lt <= 0.0:
        return hi, 2.0
    return hi, (qx * ex + qy * ey) / lt


@njit(cache=True, inline="always")
def _crossed(side, s, f0, f1, l0, e1x, e1y, l1, thickness, from_start):
    """A ``CROSSING`` contact for a point that passed through the segment from ``side`` (True:
    the front); the response puts it back on that side."""
    r1 = math.sqrt(l1)
    d1 = f1 / r1
    nx = e1y / r1
    ny = -e1x / r1
    # Back to the distance it started at, at most the thickness, and a hair off the line so
    # that the side is unambiguous: every pair had its start distance at once, so these
    # targets never contradict each other. A point that held the side only between two
    # crossings has no start distance on it: a hair.
    d0 = f0 / math.sqrt(l0) if from_start else 0.0
    if side:
        target = max(min(thickness, d0), SIDE_MARGIN * thickness)
        return CROSSING, s, nx, ny, target - d1, target
    target = max(-d0, SIDE_MARGIN * thickness)
    return CROSSING, s, -nx, -ny, target + d1, target


# The kernels below take the namedtuples once per call and unpack them: a compiled
# helper called per pair with a namedtuple of arrays pays reference counting for every array
# in it (measured: 11 ms instead of 0.4 ms for one narrow phase of a 14-body pile).

@njit(cache=True, inline="always")
def _holds(joined_start, joined, a, b):
    """Whether a joint holds body ``b`` to body ``a``."""
    for p in range(joined_start[a], joined_start[a + 1]):
        if joined[p] == b:
            return True
    return False


@njit(cache=True, inline="always")
def _may_meet(xp, x, cv, k, a, b, reach):
    """Whether collision vertex ``k`` may come within ``reach`` (m) of the edge ``(a, b)`` as
    all three move in a straight line from ``xp`` to ``x`` (rows of ``x``: ``cv``): its start
    distance from the edge, less how far it moves relative to either end, is within
    ``reach``. Exact as a bound: the gap between a point and a point of the edge at a fixed
    place along it changes by at most the larger of the two relative moves. A body in flight
    moves its outline together: its swept boxes overlap everywhere along it, but its own
    pairs do not move apart or together (a donut thrown at 6 m/s had 574,024 candidate pairs
    with itself and 84 contacts; the pairs took 21 ms of its 51 ms step)."""
    ik, ia, ib = cv[k], cv[a], cv[b]
    dkx, dky = x[ik, 0] - xp[k, 0], x[ik, 1] - xp[k, 1]
    rel = max(math.hypot(dkx - (x[ia, 0] - xp[a, 0]), dky - (x[ia, 1] - xp[a, 1])),
              math.hypot(dkx - (x[ib, 0] - xp[b, 0]), dky - (x[ib, 1] - xp[b, 1])))
    ex, ey = xp[b, 0] - xp[a, 0], xp[b, 1] - xp[a, 1]
    qx, qy = xp[k, 0] - xp[a, 0], xp[k, 1] - xp[a, 1]
    ll = ex * ex + ey * ey
    s = min(max((qx * ex + qy * ey) / ll, 0.0), 1.0) if ll > 0.0 else 0.0
    gap = math.hypot(qx - s * ex, qy - s * ey)
    return gap <= reach + rel + 1e-9 * (1.0 + gap)


@njit(cache=True, inline="always")
def _may_vanish(xp, x, cv, a, b):
    """Whether the edge ``(a, b)`` may shrink through zero length as its ends move in a straight
    line from ``xp`` to ``x`` (its body turned inside out in the step): its line then turns
    over past points far from it, which :func:`pair_contact` takes as crossings, so its pairs
    are listed whatever the bounds of :func:`_may_meet` and :func:`_own_frames` say."""
    ex, ey = xp[b, 0] - xp[a, 0], xp[b, 1] - xp[a, 1]
    mx = (x[cv[b], 0] - xp[b, 0]) - (x[cv[a], 0] - xp[a, 0])
    my = (x[cv[b], 1] - xp[b, 1]) - (x[cv[a], 1] - xp[a, 1])
    return mx * mx + my * my >= ex * ex + ey * ey


@njit(cache=True)
def _own_frames(x, topo, scr):
    """Per self-colliding body, its outline's mean move from ``scr.xp`` to ``x`` (B, 2), and
    per outline edge its swept box with that move taken away (Ec, 4: xmin, ymin, xmax,
    ymax): a body's own pairs meet only where these boxes do, however far it goes."""
    cv, xp, flags = topo.cv_vertex, scr.xp, topo.body_flags
    nb = flags.shape[0]
    shift = np.zeros((nb, 2))
    for b in range(nb):
        lo, hi = topo.body_outline[b], topo.body_outline[b + 1]
        if (flags[b] & SELF_COLLIDE) == 0 or hi == lo:
            continue
        for k in range(lo, hi):
            shift[b, 0] += x[cv[k], 0] - xp[k, 0]
            shift[b, 1] += x[cv[k], 1] - xp[k, 1]
        shift[b, 0] /= hi - lo
        shift[b, 1] /= hi - lo
    ce_a, ce_b, ce_body = topo.ce_a, topo.ce_b, topo.ce_body
    rbox = np.empty((ce_a.shape[0], 4))
    for j in range(ce_a.shape[0]):
        a, b, eb = ce_a[j], ce_b[j], ce_body[j]
        ax, ay = x[cv[a], 0] - shift[eb, 0], x[cv[a], 1] - shift[eb, 1]
        bx, by = x[cv[b], 0] - shift[eb, 0], x[cv[b], 1] - shift[eb, 1]
        rbox[j, 0] = min(min(xp[a, 0], xp[b, 0]), min(ax, bx))
        rbox[j, 1] = min(min(xp[a, 1], xp[b, 1]), min(ay, by))
        rbox[j, 2] = max(max(xp[a, 0], xp[b, 0]), max(ax, bx))
        rbox[j, 3] = max(max(xp[a, 1], xp[b, 1]), max(ay, by))
    return shift, rbox


@njit(cache=True)
def narrow_phase(x, topo, scr, out):
    """List the candidate pairs: a collision vertex and an outline edge whose boxes overlap.

    The vertex's swept box is grown by its contact thickness; pairs the flags or the outline
    rule exclude are left out. Where ``topo.margin[1]`` is finite, a body's own pairs are
    listed only where the two may meet as they move relative to each other (the boxes with
    the body's mean move taken away, :func:`_own_frames`, then :func:`_may_meet`), with that
    margin three times as slack, or where the edge may vanish (:func:`_may_vanish`). Writes ``out.pair_vertex`` / ``out.pair_edge``; returns their
    number, or ``-(needed)`` if they did not fit.
    """
    cv, body, flags = topo.cv_vertex, topo.cv_body, topo.body_flags
    ce_a, ce_b, ce_body = topo.ce_a, topo.ce_b, topo.ce_body
    joined_start, joined = topo.joined_start, topo.joined
    thick_other, thick_self = topo.thick_other, topo.thick_self
    xp, ebox, ecell = scr.xp, scr.ebox, scr.ecell
    start, items = scr.cell_start, scr.cell_items
    pair_vertex, pair_edge = out.pair_vertex, out.pair_edge
    ox, oy, inv = scr.grid[0], scr.grid[1], scr.grid[2]
    active = scr.active  # namedtuple fields read once: each read in a loop costs reference counting
    mask = np.int64(scr.cell_fill.shape[0] - 1)
    pcap = pair_vertex.shape[0]
    n_outline = topo.body_interior[0]
    # a body's own pairs: how much further than their reach they may be and still be listed
    # (ContactTopology.margin; inf: every pair whose boxes overlap)
    reach = 3.0 * topo.margin[1]
    sorted_own = reach < np.inf
    if sorted_own:
        shift, rbox = _own_frames(x, topo, scr)
    else:  # (the contact stage: not worth the frames)
        shift, rbox = np.zeros((0, 2)), np.zeros((0, 4))
    n = 0
    for m in range(scr.status.active[0]):
        k = active[m]
        bk = body[k]
        fk = flags[bk]
        if fk == 0:
            continue
        inner = k >= n_outline  # not on the outline: only other bodies' outlines concern it
        i = cv[k]
        grow = SPECULATIVE * max(thick_other[k], thick_self[k])
        bx0 = min(xp[k, 0], x[i, 0]) - grow
        bx1 = max(xp[k, 0], x[i, 0]) + grow
        by0 = min(xp[k, 1], x[i, 1]) - grow
        by1 = max(xp[k, 1], x[i, 1]) + grow
        ix0 = np.int64(math.floor((bx0 - ox) * inv))
        ix1 = np.int64(math.floor((bx1 - ox) * inv))
        iy0 = np.int64(math.floor((by0 - oy) * inv))
        iy1 = np.int64(math.floor((by1 - oy) * inv))
        for ix in range(ix0, ix1 + 1):
            for iy in range(iy0, iy1 + 1):
                bucket = grid_bucket(ix, iy, mask)
                prev = -1
                for it in range(start[bucket], start[bucket + 1]):
                    j = items[it]
                    if j == prev:
                        continue
                    prev = j
                    if ebox[j, 0] > bx1 or ebox[j, 2] < bx0 or ebox[j, 1] > by1 or ebox[j, 3] < by0:
                        continue
                    # take the pair only in the cell of the overlap's low corner
                    if max(ix0, ecell[j, 0]) != ix or max(iy0, ecell[j, 1]) != iy:
                        continue
                    eb = ce_body[j]
                    if eb == bk:
                        if inner or (fk & SELF_COLLIDE) == 0:
                            continue
                        a = ce_a[j]
                        b = ce_b[j]
                        if a == k or b == k:
                            continue
                        if sorted_own and not _may_vanish(xp, x, cv, a, b):
                            g = SPECULATIVE * thick_self[k] + reach
                            px, py = x[i, 0] - shift[bk, 0], x[i, 1] - shift[bk, 1]
                            if (rbox[j, 0] > max(xp[k, 0], px) + g or rbox[j, 2] < min(xp[k, 0], px) - g
                                    or rbox[j, 1] > max(xp[k, 1], py) + g or rbox[j, 3] < min(xp[k, 1], py) - g):
                                continue
                            if not _may_meet(xp, x, cv, k, a, b, g):
                                continue
                    elif (fk & COLLIDE) == 0 or (flags[eb] & COLLIDE) == 0:
                        continue
                    elif _holds(joined_start, joined, bk, eb):
                        continue  # bodies a joint holds together do not collide
                    if n < pcap:
                        pair_vertex[n] = k
                        pair_edge[n] = j
                    n += 1
    return n if n <= pcap else -n


@njit(cache=True)
def collide_outlines(x, topo, scr, out):
    """Steps 0-2 of the module docstring for the motion from ``scr.xp`` to ``x``: the number
    of contacts stored in ``out`` from 0 (-1 if ``out`` was too small; ``scr.status`` says
    which part) and of candidate pairs."""
    status = scr.status
    if topo.cv_vertex.shape[0] == 0 or activate_vertices(x, topo, scr) == 0:
        return 0, 0
    if build_grid(x, topo, scr, topo.margin[0]) == 0:
        return 0, 0
    n_pairs = narrow_phase(x, topo, scr, out)
    if n_pairs < 0:
        status.pairs_needed[0] = -n_pairs
        return -1, 0
    n = check_pairs(x, topo, scr, out, 0, n_pairs, True, False)
    if n < 0:
        status.needed[0] = -n
        return -1, n_pairs
    return n, n_pairs


@njit(cache=True)
def detect_contacts(x, topo, scr, out):
    """Collide only (steps 0-2 of the module docstring): the contacts of the motion from
    ``scr.xp`` to ``x``, stored in ``out`` from 0, nothing moved.

    For solvers that hold contacts inside their solve (:mod:`~deforma.physics.integrators.xpbd`): they
    call it with the predicted end of the substep, use the contacts as constraints, and the
    full stage still runs after them, from the same :func:`gather_start` (this reads
    ``scr.xp`` and only grows the body boxes). Returns the number of contacts, or -1 if
    ``out`` was too small (as :func:`contact_stage`).
    """
    n, _ = collide_outlines(x, topo, scr, out)
    return n


@njit(cache=True)
def check_pairs(x, topo, scr, out, first, n_pairs, every, crossings_only):
    """Test candidate pairs (:func:`pair_contact`) and store their contacts in ``out`` from ``first``.

    Every pair with ``every``; otherwise only the pairs of the vertices the response moved
    since the last check (``scr.dirty``, found through the pair index of
    :func:`index_pairs`), since a pair it left alone keeps its answer. With
    ``crossings_only`` only ``CROSSING`` contacts are kept. Empties the dirty list. Returns
    the index after the last contact stored, or ``-(needed)`` if they did not fit.
    """
    cv, body = topo.cv_vertex, topo.cv_body
    ce_a, ce_b, ce_body = topo.ce_a, topo.ce_b, topo.ce_body
    thick_other, thick_self, body_thick = topo.thick_other, topo.thick_self, topo.body_thickness
    behind = topo.behind[0]
    n_outline = topo.body_interior[0]
    friction = topo.body_friction
    xp = scr.xp
    pair_vertex, pair_edge = out.pair_vertex, out.pair_edge
    o_vertex, o_edge, o_s, o_normal, o_depth, o_target, o_mu, o_kind = \
        out.vertex, out.edge, out.s, out.normal, out.depth, out.target, out.mu, out.kind
    cap = o_vertex.shape[0]
    pair_sel = out.pair_sel
    status = scr.status
    status.generation[0] += 1
    n_sel = n_pairs
    if not every:
        gen = status.generation[0]
        ptr, index, mark, sel, dirty = scr.pair_ptr, out.pair_index, out.pair_mark, out.pair_sel, scr.dirty
        n_sel = 0
        for d in range(status.dirty[0]):
            k = dirty[d]
            for q in range(ptr[k], ptr[k + 1]):
                m = index[q]
                if mark[m] != gen:
                    mark[m] = gen
                    sel[n_sel] = m
                    n_sel += 1
    status.dirty[0] = 0
    n = first
    for q in range(n_sel):
        m = q if every else pair_sel[q]
        k = pair_vertex[m]
        j = pair_edge[m]
        a = ce_a[j]
        b = ce_b[j]
        bk = body[k]
        eb = ce_body[j]
        own = eb == bk
        if own:
            thick = thick_self[k]
        elif k < n_outline:  # two outlines: both sides of the pair agree on the gap
            thick = max(thick_other[k], body_thick[eb])
        else:
            thick = thick_other[k]
        i = cv[k]
        ia = cv[a]
        ib = cv[b]
        kind, s, nx, ny, depth, target = pair_contact(xp[k, 0], xp[k, 1], x[i, 0], x[i, 1], xp[a, 0], xp[a, 1],
                                                      x[ia, 0], x[ia, 1], xp[b, 0], xp[b, 1], x[ib, 0], x[ib, 1],
                                                      thick, 0.0 if own else behind * thick)
        if kind == 0 or (crossings_only and kind != CROSSING):
            continue
        if n < cap:
            o_vertex[n] = k
            o_edge[n] = j
            o_s[n] = s
            o_normal[n, 0] = nx
            o_normal[n, 1] = ny
            o_depth[n] = depth
            o_target[n] = target
            o_mu[n, 0] = mix(friction[bk, 0], friction[eb, 0])
            o_mu[n, 1] = mix(friction[bk, 1], friction[eb, 1])
            o_kind[n] = kind
        n += 1
    return n if n <= cap else -n


@njit(cache=True)
def refresh_pairs(x, topo, scr, out, margin, n_pairs):
    """Rebuild the grid and the candidate pairs if a vertex moved further than ``margin`` since
    the grid was built (only moved vertices can have); returns ``(pairs, rebuilt)`` (pairs
    negative if they did not fit). After a rebuild every pair must be checked again."""
    cv, xq = topo.cv_vertex, scr.xq
    for d in range(scr.status.dirty[0]):
        k = scr.dirty[d]
        if abs(x[cv[k], 0] - xq[k, 0]) > margin or abs(x[cv[k], 1] - xq[k, 1]) > margin:
            build_grid(x, topo, scr, margin)
            n = narrow_phase(x, topo, scr, out)
            if n >= 0:
                index_pairs(topo, scr, out, n)
            return n, True
    return n_pairs, False

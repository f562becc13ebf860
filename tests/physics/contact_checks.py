"""Independent checks of the contact invariants: outline crossings and vertices inside other bodies.

Written apart from deforma.physics.contact on purpose: a sort-and-sweep over segment boxes
and exact orientation signs (deforma.mesh.predicates, Shewchuk's expansions) decide whether
two outline segments cross, and an even-odd ray test decides whether a vertex lies inside
another body.
"""

import numpy as np
from numba import njit

from deforma.mesh.predicates import SCRATCH_SIZE, orient2d_exact


def outline_segments(world):
    """(S, 2) int64 global vertex indices of every outline segment, and (S,) its body."""
    segs, owner = [], []
    for b in world.bodies:
        e = b.topology.boundary_edges
        if len(e):
            segs.append(e.astype(np.int64) + b.vertex_slice.start)
            owner.append(np.full(len(e), b.index))
    if not segs:
        return np.zeros((0, 2), np.int64), np.zeros(0, np.int64)
    return np.concatenate(segs), np.concatenate(owner)


@njit(cache=True)
def _sign(ax, ay, bx, by, cx, cy, w, exact):
    if exact:
        return orient2d_exact(ax, ay, bx, by, cx, cy, w)
    d = (ax - cx) * (by - cy) - (ay - cy) * (bx - cx)
    return 1.0 if d > 0.0 else (-1.0 if d < 0.0 else 0.0)


@njit(cache=True)
def _crossing_pairs(x, seg, exact, out):
    """Pairs of segments without a shared end whose interiors cross properly (each one's ends
    strictly on both sides of the other's line). Sort-and-sweep on the x extent."""
    n = seg.shape[0]
    lo = np.empty(n)
    hi = np.empty(n)
    for s in range(n):
        lo[s] = min(x[seg[s, 0], 0], x[seg[s, 1], 0])
        hi[s] = max(x[seg[s, 0], 0], x[seg[s, 1], 0])
    order = np.argsort(lo)
    w = np.zeros(SCRATCH_SIZE)
    found = 0
    for ii in range(n):
        s = order[ii]
        a, b = seg[s, 0], seg[s, 1]
        ylo = min(x[a, 1], x[b, 1])
        yhi = max(x[a, 1], x[b, 1])
        for jj in range(ii + 1, n):
            t = order[jj]
            if lo[t] > hi[s]:
                break
            c, d = seg[t, 0], seg[t, 1]
            if c == a or c == b or d == a or d == b:
                continue
            if max(x[c, 1], x[d, 1]) < ylo or min(x[c, 1], x[d, 1]) > yhi:
                continue
            o1 = _sign(x[a, 0], x[a, 1], x[b, 0], x[b, 1], x[c, 0], x[c, 1], w, exact)
            o2 = _sign(x[a, 0], x[a, 1], x[b, 0], x[b, 1], x[d, 0], x[d, 1], w, exact)
            if o1 * o2 >= 0.0:
                continue
            o3 = _sign(x[c, 0], x[c, 1], x[d, 0], x[d, 1], x[a, 0], x[a, 1], w, exact)
            o4 = _sign(x[c, 0], x[c, 1], x[d, 0], x[d, 1], x[b, 0], x[b, 1], w, exact)
            if o3 * o4 >= 0.0:
                continue
            if found < out.shape[0]:
                out[found, 0] = s
                out[found, 1] = t
            found += 1
    return found


def crossings(world, *, exact=False):
    """(K, 2) global vertex indices... of crossing outline segments: (K, 2, 2) ends of each pair."""
    seg, _ = outline_segments(world)
    out = np.zeros((64, 2), np.int64)
    n = _crossing_pairs(world.state.x, seg, exact, out)
    return seg[out[:min(n, 64)]], n


@njit(cache=True)
def _inside_counts(x, seg, seg_start, vertex_body, nb):
    """For every vertex, whether it lies inside (even-odd over its outline) any other body.

    ``seg`` is grouped by body: body b's outline is ``seg[seg_start[b]:seg_start[b + 1]]``."""
    n = x.shape[0]
    box = np.empty((nb, 4))
    box[:, :2] = np.inf
    box[:, 2:] = -np.inf
    for i in range(n):
        b = vertex_body[i]
        box[b, 0] = min(box[b, 0], x[i, 0])
        box[b, 1] = min(box[b, 1], x[i, 1])
        box[b, 2] = max(box[b, 2], x[i, 0])
        box[b, 3] = max(box[b, 3], x[i, 1])
    inside = np.zeros(n, np.int64)
    for i in range(n):
        px, py = x[i, 0], x[i, 1]
        for b in range(nb):
            if b == vertex_body[i] or px < box[b, 0] or px > box[b, 2] or py < box[b, 1] or py > box[b, 3]:
                continue
            odd = False
            for s in range(seg_start[b], seg_start[b + 1]):
                ax, ay = x[seg[s, 0], 0], x[seg[s, 0], 1]
                bx, by = x[seg[s, 1], 0], x[seg[s, 1], 1]
                if (ay > py) != (by > py):
                    if px < ax + (py - ay) * (bx - ax) / (by - ay):
                        odd = not odd
            if odd:
                inside[i] = b + 1
    return inside


def vertices_inside_other_bodies(world):
    """Indices of vertices (any vertex, not only outline ones) inside another body's outline."""
    seg, owner = outline_segments(world)
    x = world.state.x
    nb = len(world.bodies)
    vb = np.full(len(x), -1, np.int64)
    for b in world.bodies:
        vb[b.vertex_slice] = b.index
    assert (vb >= 0).all() and (vb < nb).all()
    order = np.argsort(owner, kind="stable")  # already grouped by body; made sure of here
    seg_start = np.searchsorted(owner[order], np.arange(nb + 1))
    return np.flatnonzero(_inside_counts(x, seg[order], seg_start, vb, nb))

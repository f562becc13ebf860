"""Delaunay triangulation by incremental Bowyer-Watson insertion, exact and fast.

The algorithm is the original system's (insert points one at a time, remove every triangle
whose circumcircle holds the new point, fill the hole with a fan from the point), made
robust and fast:

* **Exact convex hull, no super-triangle.** The textbook version encloses the points in a
  big triangle and deletes its corners at the end, which loses hull triangles whose
  circumcircles reach past the big triangle. Here every hull edge carries a *ghost
  triangle* joined to a vertex at infinity; a ghost's "circumcircle" is the open half-plane
  outside its edge plus the open edge itself, so points outside the hull grow the
  triangulation exactly and the result covers the exact convex hull.
* **Exact predicates.** Orientation and in-circle signs come from
  :mod:`deforma.mesh.predicates` (float filter, then exact arithmetic), so cocircular grids,
  collinear runs, duplicates and near-degenerate sets give a valid Delaunay triangulation.
  With exact signs the cavity (triangles whose circle *strictly* contains the point) is
  star-shaped around the point and never yields a zero-area triangle.
* **Fast.** Points are inserted in a biased randomized order sorted along a Hilbert curve
  (:mod:`deforma.mesh.ordering`); each is located by walking from the previous point's
  triangles; the cavity grows over triangle adjacency and its slots are reused. All of it
  is one Numba-compiled loop: no Python runs per point.

The predicates are exact for every finite double, so any finite coordinates work, tiny
and huge mixed in one set included. Coordinates are first scaled by a power of two when
that is exact for every one of them (no coordinate underflows), which keeps typical sets
in the range where the float filter decides; a set that spans too many magnitudes for
that is triangulated as given, with more calls reaching the exact stages.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from .ordering import brio_order
from .predicates import SCRATCH_SIZE, incircle, orient2d

_OK, _TOO_FEW_DISTINCT, _ALL_COLLINEAR, _BROKEN_CAVITY = 0, 1, 2, 3

# (i + 1) % 3 and (i + 2) % 3 without a division in the hot loop
_NEXT = np.array([1, 2, 0], np.int64)
_PREV = np.array([2, 0, 1], np.int64)


# A triangle is one 32-byte record of int32 so that a visit touches one cache line:
# vertices (counter-clockwise), then the neighbours across the edges opposite them, then
# the cavity mark (+stamp: in this insertion's cavity; -stamp: tested, not in conflict).
_N0, _MARK, _REC = 3, 6, 8


@njit(inline="always")
def _in_conflict(T, t, P, px, py, ghost, w):
    """Whether point (px, py) lies strictly inside triangle t's circumcircle.

    For a ghost triangle (one vertex at infinity) the circumcircle degenerates to the open
    half-plane outside its hull edge plus the open edge itself.
    """
    a = T[t, 0]
    b = T[t, 1]
    c = T[t, 2]
    if a == ghost:
        u, v = b, c
    elif b == ghost:
        u, v = c, a
    elif c == ghost:
        u, v = a, b
    else:
        return incircle(P[a, 0], P[a, 1], P[b, 0], P[b, 1], P[c, 0], P[c, 1], px, py, w) > 0.0
    ux = P[u, 0]
    uy = P[u, 1]
    vx = P[v, 0]
    vy = P[v, 1]
    o = orient2d(ux, uy, vx, vy, px, py, w)
    if o != 0.0:
        return o > 0.0
    # collinear with the hull edge: in conflict only strictly between its ends
    # (comparisons of doubles are exact, so this stays exact)
    if ux != vx:
        return min(ux, vx) < px < max(ux, vx)
    return min(uy, vy) < py < max(uy, vy)


@njit(cache=True)
def _bowyer_watson(P, index):
    """Triangulate points ``P`` given in insertion order; ``index[i]`` is point i's input index.

    Returns (triangles as input indices, status). See :func:`delaunay` for the contract.
    """
    n = P.shape[0]
    ghost = n  # the vertex at infinity
    nxt = _NEXT
    prv = _PREV
    w = np.zeros(SCRATCH_SIZE)
    empty = np.empty((0, 3), np.int32)

    # -- the first triangle: two distinct points and a third not on their line -----------
    i0 = 0
    k = 1
    while k < n and P[k, 0] == P[0, 0] and P[k, 1] == P[0, 1]:
        k += 1
    if k == n:
        return empty, _TOO_FEW_DISTINCT
    k1 = k
    i1 = k1
    k += 1
    while k < n and orient2d(P[0, 0], P[0, 1], P[i1, 0], P[i1, 1], P[k, 0], P[k, 1], w) == 0.0:
        k += 1
    if k == n:
        return empty, _ALL_COLLINEAR
    k2 = k
    i2 = k2
    if orient2d(P[i0, 0], P[i0, 1], P[i1, 0], P[i1, 1], P[i2, 0], P[i2, 1], w) < 0.0:
        i1, i2 = i2, i1

    # A triangulation of n points plus the vertex at infinity has 2n - 2 triangles
    # (ghosts included), and each insertion reuses the slots of its cavity.
    cap = 2 * n + 4
    T = np.empty((cap, _REC), np.int32)
    rep = index.astype(np.int32)  # lowest input index among exact duplicates
    link_start = np.empty(n + 1, np.int32)  # new triangle whose cavity-boundary edge starts at v
    link_end = np.empty(n + 1, np.int32)
    # Work lists sized for the worst cavity (every triangle). np.empty only reserves
    # address space: the pages a typical cavity of a few triangles never touches cost no
    # memory. Fixed arrays also keep Numba from reference counting them in the hot loop,
    # which growing them on demand costs (measured: twice the run time).
    cav = np.empty(cap, np.int32)
    bnd_u = np.empty(cap + 2, np.int32)
    bnd_v = np.empty(cap + 2, np.int32)
    bnd_out = np.empty(cap + 2, np.int32)
    bnd_new = np.empty(cap + 2, np.int32)

    T[0, 0], T[0, 1], T[0, 2], T[0, 3], T[0, 4], T[0, 5] = i0, i1, i2, 2, 3, 1
    T[1, 0], T[1, 1], T[1, 2], T[1, 3], T[1, 4], T[1, 5] = i1, i0, ghost, 3, 2, 0  # outside i0-i1
    T[2, 0], T[2, 1], T[2, 2], T[2, 3], T[2, 4], T[2, 5] = i2, i1, ghost, 1, 3, 0  # outside i1-i2
    T[3, 0], T[3, 1], T[3, 2], T[3, 3], T[3, 4], T[3, 5] = i0, i2, ghost, 2, 1, 0  # outside i2-i0
    for t in range(4):
        T[t, _MARK] = 0
    ntri = 4
    last = 0  # a real triangle near the previous point: where the next walk starts
    stamp = 0

    for p in range(1, n):
        if p == k1 or p == k2:
            continue
        px = P[p, 0]
        py = P[p, 1]

        # -- locate: walk toward p across any edge that has p strictly outside ----------
        t = last
        came = -1
        while True:
            a = T[t, 0]
            b = T[t, 1]
            c = T[t, 2]
            if a == ghost or b == ghost or c == ghost:
                break  # p is strictly outside the hull edge we crossed: a conflict
            moved = False
            # any edge order terminates: in a Delaunay triangulation the visibility
            # walk cannot cycle (Edelsbrunner 1990)
            for i in range(3):
                nb = T[t, _N0 + i]
                if nb == came:
                    continue
                u = T[t, nxt[i]]
                v = T[t, prv[i]]
                if orient2d(P[u, 0], P[u, 1], P[v, 0], P[v, 1], px, py, w) < 0.0:
                    came = t
                    t = nb
                    moved = True
                    break
            if not moved:
                break

        a = T[t, 0]
        b = T[t, 1]
        c = T[t, 2]
        if a != ghost and b != ghost and c != ghost:
            dup = -1
            if P[a, 0] == px and P[a, 1] == py:
                dup = a
            elif P[b, 0] == px and P[b, 1] == py:
                dup = b
            elif P[c, 0] == px and P[c, 1] == py:
                dup = c
            if dup >= 0:
                if index[p] < rep[dup]:
                    rep[dup] = index[p]
                continue

        # -- cavity: every triangle whose circumcircle strictly holds p, grown from t ----
        stamp += 1
        T[t, _MARK] = stamp
        cav[0] = t
        ncav = 1
        nbnd = 0
        head = 0
        while head < ncav:
            t = cav[head]
            head += 1
            for i in range(3):
                nb = T[t, _N0 + i]
                m = T[nb, _MARK]
                if m == stamp:
                    continue
                if m != -stamp:
                    if _in_conflict(T, nb, P, px, py, ghost, w):
                        T[nb, _MARK] = stamp
                        cav[ncav] = nb
                        ncav += 1
                        continue
                    T[nb, _MARK] = -stamp
                # the edge of t opposite vertex i bounds the cavity
                bnd_u[nbnd] = T[t, nxt[i]]
                bnd_v[nbnd] = T[t, prv[i]]
                bnd_out[nbnd] = nb
                nbnd += 1

        # -- fill the cavity with a fan of triangles (u, v, p) --------------------------
        # A cavity of c triangles is a disk bounded by c + 2 edges: the fan reuses all c
        # slots and appends two. Exact predicates guarantee the disk; the check costs one
        # comparison and turns a would-be corrupt mesh into an error.
        if nbnd != ncav + 2:
            return empty, _BROKEN_CAVITY
        for e in range(nbnd):
            if e < ncav:
                s = cav[e]
            else:
                s = ntri
                ntri += 1
                T[s, _MARK] = 0
            u = bnd_u[e]
            v = bnd_v[e]
            out = bnd_out[e]
            T[s, 0] = u
            T[s, 1] = v
            T[s, 2] = p
            T[s, _N0 + 2] = out  # across (u, v), opposite p
            # the outside triangle's pointer across (v, u): found by vertex, since ids of
            # freed cavity slots may already be reused by this fan
            for j in range(3):
                if T[out, j] != u and T[out, j] != v:
                    T[out, _N0 + j] = s
                    break
            link_start[u] = s
            link_end[v] = s
            bnd_new[e] = s
            if u != ghost and v != ghost:
                last = s
        for e in range(nbnd):
            s = bnd_new[e]
            T[s, _N0] = link_start[bnd_v[e]]  # across (v, p), opposite u
            T[s, _N0 + 1] = link_end[bnd_u[e]]  # across (p, u), opposite v

    # -- collect the real triangles, as input indices -------------------------------------
    count = 0
    for t in range(ntri):
        if T[t, 0] != ghost and T[t, 1] != ghost and T[t, 2] != ghost:
            count += 1
    result = np.empty((count, 3), np.int32)
    count = 0
    for t in range(ntri):
        if T[t, 0] != ghost and T[t, 1] != ghost and T[t, 2] != ghost:
            result[count, 0] = rep[T[t, 0]]
            result[count, 1] = rep[T[t, 1]]
            result[count, 2] = rep[T[t, 2]]
            count += 1
    return result, _OK


@njit(cache=True)
def _gather(points, order):
    out = np.empty((order.shape[0], 2))
    for i in range(order.shape[0]):
        out[i, 0] = points[order[i], 0]
        out[i, 1] = points[order[i], 1]
    return out


def _exact_power_of_two_scale(pts: np.ndarray) -> np.ndarray:
    """``pts`` times the power of two that brings the largest magnitude to [0.5, 1), or the
    nearest power that is still exact for every coordinate, or ``pts`` itself.

    Scaling by 2**k is exact unless a coordinate underflows (loses low bits below 2**-1074)
    or overflows; a set mixing 1e300 with 1e-300 has no exact scaling to [0.5, 1), and
    scaling it anyway turned its small points into duplicates of 0.
    """
    mags = np.abs(pts[pts != 0.0])
    if mags.size == 0:
        return pts
    top = int(np.frexp(mags.max())[1])
    bottom = int(np.frexp(mags.min())[1])
    # the lowest set bit of a coordinate is at least 2**(frexp exponent - 53)
    k = max(-top, -1074 - (bottom - 53))
    k = min(k, 1023 - top)
    scaled = np.ldexp(pts, k)
    if np.isfinite(scaled).all() and np.array_equal(np.ldexp(scaled, -k), pts):
        return scaled
    return pts


def _as_points(points) -> np.ndarray:
    raw = points if isinstance(points, np.ndarray) else None
    if raw is None:
        try:
            raw = np.asarray(points)
        except (TypeError, ValueError) as err:
            raise ValueError(f"points must be an (N, 2) array of real numbers: {err}") from None
    if raw.dtype.kind == "c" or (raw.dtype == object and any(isinstance(v, complex) for v in raw.ravel())):
        raise ValueError("points must be real numbers: got complex values")
    if raw.dtype.kind not in "biufO":
        raise ValueError(f"points must be an (N, 2) array of real numbers, got dtype {raw.dtype}")
    try:
        pts = np.ascontiguousarray(raw, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as err:
        raise ValueError(f"points must be an (N, 2) array of real numbers: {err}") from None
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"points must be an (N, 2) array, got shape {pts.shape}")
    if pts.shape[0] < 3:
        raise ValueError(f"need at least 3 points to triangulate, got {pts.shape[0]}")
    if pts.shape[0] >= 2**30:
        raise ValueError(f"at most 2**30 points can be triangulated, got {pts.shape[0]}")
    if not np.isfinite(pts).all():
        bad = pts[~np.isfinite(pts)][0]
        raise ValueError(
            f"points must be finite doubles (magnitude at most {np.finfo(np.float64).max:.6g}): found {bad}"
        )
    return pts


def delaunay(points: ArrayLike) -> np.ndarray:
    """Delaunay triangulation of 2D points (incremental Bowyer-Watson, exact predicates).

    Parameters
    ----------
    points : (N, 2) array_like of real numbers
        Point coordinates, any units; N >= 3. Converted to float64; every finite double
        works, from subnormals (5e-324) to 1.8e308, mixed in one set: the predicates are
        exact over the whole range.

    Returns
    -------
    (M, 3) int32 ndarray
        Indices into ``points``, one row per triangle, counter-clockwise (positive area).
        The triangles cover the convex hull of the points exactly, and no point lies
        strictly inside any triangle's circumcircle. Where four or more points are
        cocircular (a regular grid), one of the valid triangulations is returned,
        always the same one for the same input.

    Raises
    ------
    ValueError
        If ``points`` is not an (N, 2) array of finite real numbers (complex values,
        strings, NaN, inf or a value beyond the largest double are refused), or has fewer
        than three distinct points, or all its points are collinear.

    Notes
    -----
    Exact duplicates are ignored: of several points with identical coordinates only the
    one with the lowest index appears in the triangles; the others are unreferenced.
    Points on the hull between two hull corners are vertices of the triangulation (no
    triangle has zero area).

    Examples
    --------
    >>> import numpy as np, deforma
    >>> square = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]])
    >>> deforma.delaunay(square).shape
    (4, 3)
    """
    pts = _as_points(points)
    scaled = _exact_power_of_two_scale(pts)
    order = brio_order(scaled)
    # renumber the points in insertion order: neighbours in space become neighbours in memory
    tris, status = _bowyer_watson(_gather(scaled, order), order)
    if status == _TOO_FEW_DISTINCT:
        raise ValueError("need at least 3 distinct points to triangulate; all points coincide")
    if status == _ALL_COLLINEAR:
        raise ValueError("points are all collinear: a triangulation needs 3 points not on one line")
    if status == _BROKEN_CAVITY:  # unreachable with exact predicates; never return garbage
        raise RuntimeError("internal error in deforma.delaunay: a cavity was not a disk")
    return tris

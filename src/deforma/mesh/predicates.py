"""Exact geometric predicates: orientation and in-circle tests with the exact sign.

Floating-point evaluation of these determinants gets the sign wrong near zero, and a
Delaunay kernel fed wrong signs on exact grids (where every four neighbours are cocircular)
loops or corrupts its mesh. Each predicate here runs in up to three stages, after
Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
Predicates" (1997):

1. a plain float evaluation with a forward error bound: its sign is returned when the
   value clears the bound (almost every call on random input);
2. the same evaluation with every rounding checked by an error-free transformation: when no
   operation rounded, the float value is the exact value (integer grids and most
   coordinates with few significant bits end here, at a few dozen flops);
3. the determinant expanded into a sum of products of the coordinates' exact differences,
   each product formed without rounding (two-product, scale-expansion) and summed into a
   nonoverlapping expansion, whose largest component carries the exact sign.

The inputs must not overflow when squared twice: callers scale coordinates by a power of
two first (exact), as :func:`deforma.delaunay` does.

All functions are Numba ``njit`` kernels; stage 3 works in a caller-supplied scratch
array so that no call allocates (see :data:`SCRATCH_SIZE`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_EPS = 2.0**-53  # half an ulp of 1.0: the unit roundoff of float64
_SPLITTER = 134217729.0  # 2**27 + 1, splits a double into two 26-bit halves
ORIENT_ERRBOUND = (3.0 + 16.0 * _EPS) * _EPS
INCIRCLE_ERRBOUND = (10.0 + 96.0 * _EPS) * _EPS

#: Length of the scratch array the exact stages need: ``w[0:16]`` for one product,
#: ``w[16:-16]`` for the running sum, ``w[-16:]`` for the coordinate differences.
SCRATCH_SIZE = 4096


@njit(inline="always")
def _two_sum(a, b):
    x = a + b
    bv = x - a
    av = x - bv
    return x, (a - av) + (b - bv)


@njit(inline="always")
def _two_diff(a, b):
    x = a - b
    bv = a - x
    av = x + bv
    return x, (a - av) + (bv - b)


@njit(inline="always")
def _split(a):
    c = _SPLITTER * a
    hi = c - (c - a)
    return hi, a - hi


@njit(inline="always")
def _two_product(a, b):
    x = a * b
    ahi, alo = _split(a)
    bhi, blo = _split(b)
    err = x - ahi * bhi
    err -= alo * bhi
    err -= ahi * blo
    return x, alo * blo - err


@njit(inline="always")
def _grow(e, elen, b):
    """Add the double ``b`` to the expansion ``e[:elen]`` in place; return the new length.

    In place is safe: component ``h`` is written at an index never past the one just read.
    """
    q = b
    h = 0
    for i in range(elen):
        q, t = _two_sum(q, e[i])
        if t != 0.0:
            e[h] = t
            h += 1
    if q != 0.0 or h == 0:
        e[h] = q
        h += 1
    return h


@njit(inline="always")
def _scale(e, elen, b, h, off):
    """Write ``e[:elen] * b`` exactly into ``h[off:]``; return the new length (no zeros)."""
    n = 0
    q, t = _two_product(e[0], b)
    if t != 0.0:
        h[off + n] = t
        n += 1
    for i in range(1, elen):
        p1, p0 = _two_product(e[i], b)
        s, t = _two_sum(q, p0)
        if t != 0.0:
            h[off + n] = t
            n += 1
        q, t = _two_sum(p1, s)
        if t != 0.0:
            h[off + n] = t
            n += 1
    if q != 0.0 or n == 0:
        h[off + n] = q
        n += 1
    return n


@njit(inline="always")
def _add_product(w, acc_len, a, b, c, d):
    """Add the exact product ``a*b*c*d`` to the expansion held in ``w[16:16+acc_len]``.

    ``w[0:16]`` is the working space for the product's own expansion (at most 8 terms).
    Returns the new accumulator length.
    """
    if a == 0.0 or b == 0.0 or c == 0.0 or d == 0.0:
        return acc_len
    # largest factors first: ((a b) c) d then never passes below the smallest double on the
    # way to a product that is in range (two tiny factors first would underflow)
    if abs(a) < abs(b):
        a, b = b, a
    if abs(c) < abs(d):
        c, d = d, c
    if abs(a) < abs(c):
        a, c = c, a
    if abs(b) < abs(d):
        b, d = d, b
    if abs(b) < abs(c):
        b, c = c, b
    x, y = _two_product(a, b)
    if y != 0.0:
        w[0] = y
        w[1] = x
        n = 2
    else:
        w[0] = x
        n = 1
    n = _scale(w, n, c, w, 8)  # reads w[0:2], writes at most w[8:12]
    n = _scale(w[8:], n, d, w, 0)  # reads w[8:12], writes at most w[0:8]
    acc = w[16:]
    for i in range(n):
        acc_len = _grow(acc, acc_len, w[i])
    return acc_len


@njit(inline="always")
def _add_product2(w, acc_len, a, b):
    """Add the exact product ``a*b`` to the accumulator ``w[16:16+acc_len]``."""
    x, y = _two_product(a, b)
    acc = w[16:]
    if y != 0.0:
        acc_len = _grow(acc, acc_len, y)
    return _grow(acc, acc_len, x)


@njit(inline="always")
def _sign_of(w, acc_len):
    if acc_len == 0:
        return 0.0
    top = w[16 + acc_len - 1]
    return 1.0 if top > 0.0 else (-1.0 if top < 0.0 else 0.0)


@njit(inline="always")
def _upscale(m, target):
    """A power of two that brings the largest input magnitude ``m`` up to about ``2**target``.

    Expansion arithmetic is exact only while no product underflows: with inputs of
    magnitude 1 and 1e-260 (a lattice point nudged by a tiny offset), the product of two
    tiny ones is below the smallest double, and a determinant whose large terms cancel
    exactly came out 0 instead of its true, tiny sign. Multiplying every input by the same
    power of two is exact and keeps the sign; bringing the largest to ``2**target`` (500 for
    the degree-2 orientation, 250 for the degree-4 in-circle test) keeps the largest
    products below overflow and lifts the smallest into range. Only upward: the callers
    scale their points to magnitude <= 1 first (see :func:`deforma.delaunay`).
    """
    if m == 0.0:
        return 1.0
    e = math.frexp(m)[1]
    return math.ldexp(1.0, target - e) if e < target else 1.0


@njit(cache=True)
def orient2d_exact(ax, ay, bx, by, cx, cy, w):
    """Sign (+1, -1, 0) of the orientation determinant, always exact (stages 2 and 3)."""
    k = _upscale(max(max(abs(ax), abs(ay)), max(max(abs(bx), abs(by)), max(abs(cx), abs(cy)))), 500)
    ax, ay, bx, by, cx, cy = ax * k, ay * k, bx * k, by * k, cx * k, cy * k
    acx, e1 = _two_diff(ax, cx)
    bcx, e2 = _two_diff(bx, cx)
    acy, e3 = _two_diff(ay, cy)
    bcy, e4 = _two_diff(by, cy)
    if e1 == 0.0 and e2 == 0.0 and e3 == 0.0 and e4 == 0.0:
        left, el = _two_product(acx, bcy)
        right, er = _two_product(acy, bcx)
        det, es = _two_diff(left, right)
        if el == 0.0 and er == 0.0 and es == 0.0:
            return 1.0 if det > 0.0 else (-1.0 if det < 0.0 else 0.0)
    # det = ax*by - ax*cy - ay*bx + ay*cx + bx*cy - by*cx, six exact products
    n = 0
    n = _add_product2(w, n, ax, by)
    n = _add_product2(w, n, -ax, cy)
    n = _add_product2(w, n, -ay, bx)
    n = _add_product2(w, n, ay, cx)
    n = _add_product2(w, n, bx, cy)
    n = _add_product2(w, n, -by, cx)
    return _sign_of(w, n)


@njit(inline="always")
def orient2d(ax, ay, bx, by, cx, cy, w):
    """Orientation of the triangle (a, b, c), exact in sign.

    Returns a value that is positive when a, b, c turn counter-clockwise, negative when
    clockwise and zero when collinear (only the sign is meaningful). ``w`` is a float64
    scratch array of :data:`SCRATCH_SIZE`.
    """
    detleft = (ax - cx) * (by - cy)
    detright = (ay - cy) * (bx - cx)
    det = detleft - detright
    bound = ORIENT_ERRBOUND * (abs(detleft) + abs(detright))
    if det > bound or -det > bound:
        return det
    return orient2d_exact(ax, ay, bx, by, cx, cy, w)


@njit(inline="always")
def _ops_exact_incircle(adx, ady, bdx, bdy, cdx, cdy):
    """Stage 2: the float determinant and whether no operation in it rounded."""
    al, e0 = _two_product(adx, adx)
    al2, e1 = _two_product(ady, ady)
    alift, e2 = _two_sum(al, al2)
    bl, e3 = _two_product(bdx, bdx)
    bl2, e4 = _two_product(bdy, bdy)
    blift, e5 = _two_sum(bl, bl2)
    cl, e6 = _two_product(cdx, cdx)
    cl2, e7 = _two_product(cdy, cdy)
    clift, e8 = _two_sum(cl, cl2)
    p1, f1 = _two_product(bdx, cdy)
    p2, f2 = _two_product(cdx, bdy)
    bc, f3 = _two_diff(p1, p2)
    p3, f4 = _two_product(cdx, ady)
    p4, f5 = _two_product(adx, cdy)
    ca, f6 = _two_diff(p3, p4)
    p5, f7 = _two_product(adx, bdy)
    p6, f8 = _two_product(bdx, ady)
    ab, f9 = _two_diff(p5, p6)
    ta, g1 = _two_product(alift, bc)
    tb, g2 = _two_product(blift, ca)
    tc, g3 = _two_product(clift, ab)
    s, g4 = _two_sum(ta, tb)
    det, g5 = _two_sum(s, tc)
    err = (
        abs(e0) + abs(e1) + abs(e2) + abs(e3) + abs(e4) + abs(e5) + abs(e6) + abs(e7) + abs(e8)
        + abs(f1) + abs(f2) + abs(f3) + abs(f4) + abs(f5) + abs(f6) + abs(f7) + abs(f8) + abs(f9)
        + abs(g1) + abs(g2) + abs(g3) + abs(g4) + abs(g5)
    )
    return det, err == 0.0


@njit(cache=True)
def incircle_exact(ax, ay, bx, by, cx, cy, dx, dy, w):
    """Sign (+1, -1, 0) of the in-circle determinant, always exact (stages 2 and 3)."""
    k = _upscale(max(max(max(abs(ax), abs(ay)), max(abs(bx), abs(by))),
                     max(max(abs(cx), abs(cy)), max(abs(dx), abs(dy)))), 250)
    ax, ay, bx, by, cx, cy, dx, dy = ax * k, ay * k, bx * k, by * k, cx * k, cy * k, dx * k, dy * k
    adx, adxt = _two_diff(ax, dx)
    ady, adyt = _two_diff(ay, dy)
    bdx, bdxt = _two_diff(bx, dx)
    bdy, bdyt = _two_diff(by, dy)
    cdx, cdxt = _two_diff(cx, dx)
    cdy, cdyt = _two_diff(cy, dy)
    if adxt == 0.0 and adyt == 0.0 and bdxt == 0.0 and bdyt == 0.0 and cdxt == 0.0 and cdyt == 0.0:
        det, exact = _ops_exact_incircle(adx, ady, bdx, bdy, cdx, cdy)
        if exact:
            return 1.0 if det > 0.0 else (-1.0 if det < 0.0 else 0.0)
    # Stage 3. Each difference is exactly hi + lo; the determinant
    #   |a|^2 (b x c) + |b|^2 (c x a) + |c|^2 (a x b)   (vectors relative to d)
    # is a sum of products of four such components, each added exactly.
    # comp[2*row + 0] is the high part of a difference, comp[2*row + 1] its rounding error;
    # rows: adx ady bdx bdy cdx cdy.
    comp = w[w.shape[0] - 16 : w.shape[0] - 4]
    comp[0] = adx
    comp[1] = adxt
    comp[2] = ady
    comp[3] = adyt
    comp[4] = bdx
    comp[5] = bdxt
    comp[6] = bdy
    comp[7] = bdyt
    comp[8] = cdx
    comp[9] = cdxt
    comp[10] = cdy
    comp[11] = cdyt
    n = 0
    for k in range(3):
        # the lift of point k times the cross product of the next two, in cyclic order
        px = 2 * k  # row of point k's x difference; +1 is its y
        qx = 2 * ((k + 1) % 3)
        rx = 2 * ((k + 2) % 3)
        for axis in range(2):  # x^2, then y^2 of the lifted point
            row = px + axis
            for i in range(2):
                u = comp[2 * row + i]
                for j in range(2):
                    v = comp[2 * row + j]
                    for s in range(2):
                        for t in range(2):
                            # + q_x r_y
                            n = _add_product(w, n, u, v, comp[2 * qx + s], comp[2 * (rx + 1) + t])
                            # - r_x q_y
                            n = _add_product(w, n, -u, v, comp[2 * rx + s], comp[2 * (qx + 1) + t])
    return _sign_of(w, n)


@njit(inline="always")
def incircle(ax, ay, bx, by, cx, cy, dx, dy, w):
    """In-circle test, exact in sign.

    Positive when d lies strictly inside the circle through a, b, c (given counter-
    clockwise), negative when strictly outside, zero when the four points are cocircular.
    ``w`` is a float64 scratch array of :data:`SCRATCH_SIZE`.
    """
    adx = ax - dx
    bdx = bx - dx
    cdx = cx - dx
    ady = ay - dy
    bdy = by - dy
    cdy = cy - dy
    bdxcdy = bdx * cdy
    cdxbdy = cdx * bdy
    alift = adx * adx + ady * ady
    cdxady = cdx * ady
    adxcdy = adx * cdy
    blift = bdx * bdx + bdy * bdy
    adxbdy = adx * bdy
    bdxady = bdx * ady
    clift = cdx * cdx + cdy * cdy
    det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady)
    permanent = (
        (abs(bdxcdy) + abs(cdxbdy)) * alift
        + (abs(cdxady) + abs(adxcdy)) * blift
        + (abs(adxbdy) + abs(bdxady)) * clift
    )
    bound = INCIRCLE_ERRBOUND * permanent
    if det > bound or -det > bound:
        return det
    return incircle_exact(ax, ay, bx, by, cx, cy, dx, dy, w)


def orient2d_py(a, b, c) -> float:
    """Exact orientation sign of three points; a convenience wrapper for tests and tools."""
    w = np.zeros(SCRATCH_SIZE)
    return float(np.sign(orient2d(a[0], a[1], b[0], b[1], c[0], c[1], w)))


def incircle_py(a, b, c, d) -> float:
    """Exact in-circle sign of d against the counter-clockwise triangle a, b, c."""
    w = np.zeros(SCRATCH_SIZE)
    return float(np.sign(incircle(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1], w)))

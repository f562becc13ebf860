"""Exact geometric predicates: orientation and in-circle tests with the exact sign.

Floating-point evaluation of these determinants gets the sign wrong near zero, and a
Delaunay kernel fed wrong signs on exact grids (where every four neighbours are cocircular)
loops or corrupts its mesh. Each predicate here runs in up to three stages, after
Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
Predicates" (1997):

1. a plain float evaluation with a forward error bound: its sign is returned when the
   value clears the bound (almost every call on random input). The bound has an absolute
   term for products that fall below the smallest normal double (where the relative bound
   does not hold), and an overflow makes the value or the bound inf or NaN, which never
   clears it;
2. the same evaluation, on inputs scaled by a power of two into a safe exponent range,
   with every rounding checked by an error-free transformation: when no operation rounded,
   the float value is the exact value (integer grids and most coordinates with few
   significant bits end here, at a few dozen flops). Skipped when the inputs' magnitudes
   span more than that range holds (no single power of two then avoids both overflow and
   underflow);
3. the determinant expanded into monomials of the raw coordinates, each a product of
   doubles ``m * 2**e`` (``m`` a 53-bit integer), summed exactly as a fixed-point integer
   of 16-bit limbs wide enough for every finite double (about 8,700 bits for the in-circle
   test). Its sign is the exact sign.

So the signs are exact for every finite double input: no range to respect, no scaling by
the caller. A few thousand integer operations make stage 3 slower than a float
evaluation, and it is rare: only inputs within a few ulps of degenerate, or whose
magnitudes span more than about 2**400, reach it.

All functions are Numba ``njit`` kernels; stage 3 works in a caller-supplied scratch
array so that no call allocates (see :data:`SCRATCH_SIZE`).
"""

from __future__ import annotations

import math
from itertools import permutations

import numpy as np
from numba import njit

_EPS = 2.0**-53  # half an ulp of 1.0: the unit roundoff of float64
_SPLITTER = 134217729.0  # 2**27 + 1, splits a double into two 26-bit halves
# Shewchuk's bounds with a doubled second-order term: room for the absolute underflow
# term below when adding it rounds (see _UNDERFLOW)
ORIENT_ERRBOUND = (3.0 + 32.0 * _EPS) * _EPS
INCIRCLE_ERRBOUND = (10.0 + 192.0 * _EPS) * _EPS
# A product below 2**-1022 (subnormal) has an absolute error up to 2**-1075 instead of a
# relative one. The filters add this much (times the size of what multiplies such an
# error) to their bound: 2**13 times the worst such error, so it holds after rounding.
_UNDERFLOW = 2.0**-1060

#: Length of the float64 scratch array the exact stage needs (it is used as int64 limbs).
SCRATCH_SIZE = 4096

# -- stage 3: exact fixed-point integer sums of products of doubles -----------------------
_LIMB_BITS = 16
_LIMB_MASK = 0xFFFF
# A nonzero double is m * 2**e with 2**52 <= m < 2**53 and e >= -1126 (2**-1074 = 2**52 *
# 2**-1126), so a product of four is an integer multiple of 2**(4 * -1126): bit 0 of the
# accumulator. The largest, four times 2**1024, ends below bit 4 * (1024 + 1126) = 8600.
_ACC_EXP0 = 4 * -1126
_ACC_LIMBS = 560  # 8960 bits: the largest product, its 212 mantissa bits and the carries
_PROD = _ACC_LIMBS  # iw[_PROD:_PROD + 20]: the mantissa product being formed
_TMP = _ACC_LIMBS + 20  # iw[_TMP:_TMP + 20]: the factor before it
_TWO53 = 9007199254740992.0

# The in-circle determinant | x y x^2+y^2 1 | over the rows a, b, c, d as 24 signed
# permutations (row for x, row for y, row for the lift); the 1 takes the remaining row.
_PERMS = np.array(
    [
        (p[0], p[1], p[2], (-1) ** sum(p[i] > p[j] for i in range(4) for j in range(i + 1, 4)))
        for p in permutations(range(4))
    ],
    np.int64,
)


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
def _acc_add(iw, negative, x1, x2, x3, x4):
    """Add the exact product ``x1 x2 x3 x4`` (negated if ``negative``) to the accumulator.

    ``iw`` is the scratch array viewed as int64: ``iw[:_ACC_LIMBS]`` holds the sum as
    16-bit limbs that may run over or go negative until :func:`_acc_sign` carries them. A
    factor of exactly 1.0 is left out, so a product of two is ``x1, x2, 1.0, 1.0``.
    """
    if x1 == 0.0 or x2 == 0.0 or x3 == 0.0 or x4 == 0.0:
        return
    prod = iw[_PROD : _PROD + 20]
    tmp = iw[_TMP : _TMP + 20]
    prod[0] = 1
    n = 1
    e = 0  # the product is prod * 2**e
    for k in range(4):
        x = x1 if k == 0 else (x2 if k == 1 else (x3 if k == 2 else x4))
        if x < 0.0:
            negative = not negative
            x = -x
        if x == 1.0:
            continue
        f, ex = math.frexp(x)
        m = np.int64(f * _TWO53)  # exact: f has at most 53 significant bits
        e += ex - 53
        m0 = m & _LIMB_MASK
        m1 = (m >> 16) & _LIMB_MASK
        m2 = (m >> 32) & _LIMB_MASK
        m3 = m >> 48
        for i in range(n + 4):
            tmp[i] = 0
        for i in range(n):  # limb products < 2**32, at most four per limb: no overflow
            p = prod[i]
            tmp[i] += p * m0
            tmp[i + 1] += p * m1
            tmp[i + 2] += p * m2
            tmp[i + 3] += p * m3
        carry = 0
        for i in range(n + 4):
            v = tmp[i] + carry
            prod[i] = v & _LIMB_MASK
            carry = v >> _LIMB_BITS
        n += 4
    s = e - _ACC_EXP0  # >= 0: bit position of prod's lowest bit in the accumulator
    q = s >> 4
    r = s & 15
    for i in range(n):
        v = prod[i] << r
        if negative:
            iw[q + i] -= v & _LIMB_MASK
            iw[q + i + 1] -= v >> _LIMB_BITS
        else:
            iw[q + i] += v & _LIMB_MASK
            iw[q + i + 1] += v >> _LIMB_BITS


@njit(inline="always")
def _acc_sign(iw):
    """Sign (+1, -1, 0) of the accumulated sum; carries the limbs from the lowest up."""
    carry = 0
    nonzero = False
    for i in range(_ACC_LIMBS):
        v = iw[i] + carry
        if (v & _LIMB_MASK) != 0:
            nonzero = True
        carry = v >> _LIMB_BITS  # arithmetic shift: floor division, also when negative
    # sum = (limbs in [0, 2**16) below) + carry * 2**(16 * _ACC_LIMBS)
    if carry < 0:
        return -1.0
    if carry > 0 or nonzero:
        return 1.0
    return 0.0


@njit(inline="always")
def _min_nonzero(m, v):
    v = abs(v)
    return v if v != 0.0 and v < m else m


@njit(inline="always")
def _safe_shift(hi, lo, target, floor):
    """The power of two ``k`` that puts magnitudes ``hi`` (largest) and ``lo`` (smallest
    nonzero) in the range where stage 2 neither overflows nor underflows: the largest to
    about ``2**target``, and the lowest set bit of the smallest, at least
    ``2**(frexp(lo)[1] - 53)``, to at least ``2**floor``. Returns 4096 when the inputs span
    more than that range.
    """
    k = target - math.frexp(hi)[1]
    if math.frexp(lo)[1] - 53 + k < floor:
        return 4096
    return k


@njit(cache=True)
def orient2d_exact(ax, ay, bx, by, cx, cy, w):
    """Sign (+1, -1, 0) of the orientation determinant, always exact (stages 2 and 3)."""
    hi = max(max(abs(ax), abs(ay)), max(max(abs(bx), abs(by)), max(abs(cx), abs(cy))))
    if hi == 0.0:
        return 0.0
    lo = _min_nonzero(_min_nonzero(_min_nonzero(hi, ax), ay), bx)
    lo = _min_nonzero(_min_nonzero(_min_nonzero(lo, by), cx), cy)
    # differences below 2**481, products below 2**962; products of the lowest bits >= 2**-1022
    k = _safe_shift(hi, lo, 480, -511)
    if k != 4096:
        sx, sy = math.ldexp(ax, k), math.ldexp(ay, k)  # exact: no overflow, no underflow
        tx, ty = math.ldexp(bx, k), math.ldexp(by, k)
        ux, uy = math.ldexp(cx, k), math.ldexp(cy, k)
        acx, e1 = _two_diff(sx, ux)
        bcx, e2 = _two_diff(tx, ux)
        acy, e3 = _two_diff(sy, uy)
        bcy, e4 = _two_diff(ty, uy)
        if e1 == 0.0 and e2 == 0.0 and e3 == 0.0 and e4 == 0.0:
            left, el = _two_product(acx, bcy)
            right, er = _two_product(acy, bcx)
            det, es = _two_diff(left, right)
            if el == 0.0 and er == 0.0 and es == 0.0:
                return 1.0 if det > 0.0 else (-1.0 if det < 0.0 else 0.0)
    # stage 3: det = ax*by - ax*cy - ay*bx + ay*cx + bx*cy - by*cx, on the raw inputs
    iw = w.view(np.int64)
    iw[:_ACC_LIMBS] = 0
    _acc_add(iw, False, ax, by, 1.0, 1.0)
    _acc_add(iw, True, ax, cy, 1.0, 1.0)
    _acc_add(iw, True, ay, bx, 1.0, 1.0)
    _acc_add(iw, False, ay, cx, 1.0, 1.0)
    _acc_add(iw, False, bx, cy, 1.0, 1.0)
    _acc_add(iw, True, by, cx, 1.0, 1.0)
    return _acc_sign(iw)


@njit(inline="always")
def orient2d(ax, ay, bx, by, cx, cy, w):
    """Orientation of the triangle (a, b, c), exact in sign for any finite doubles.

    Returns a value that is positive when a, b, c turn counter-clockwise, negative when
    clockwise and zero when collinear (only the sign is meaningful). ``w`` is a float64
    scratch array of :data:`SCRATCH_SIZE`.
    """
    detleft = (ax - cx) * (by - cy)
    detright = (ay - cy) * (bx - cx)
    det = detleft - detright
    bound = ORIENT_ERRBOUND * (abs(detleft) + abs(detright)) + _UNDERFLOW
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
    hi = max(max(max(abs(ax), abs(ay)), max(abs(bx), abs(by))),
             max(max(abs(cx), abs(cy)), max(abs(dx), abs(dy))))
    if hi == 0.0:
        return 0.0
    lo = _min_nonzero(_min_nonzero(_min_nonzero(_min_nonzero(hi, ax), ay), bx), by)
    lo = _min_nonzero(_min_nonzero(_min_nonzero(_min_nonzero(lo, cx), cy), dx), dy)
    # differences below 2**241, lifts below 2**483, products below 2**966; products of
    # four lowest bits >= 2**-1020
    k = _safe_shift(hi, lo, 240, -255)
    if k != 4096:
        sx, sy = math.ldexp(ax, k), math.ldexp(ay, k)
        tx, ty = math.ldexp(bx, k), math.ldexp(by, k)
        ux, uy = math.ldexp(cx, k), math.ldexp(cy, k)
        vx, vy = math.ldexp(dx, k), math.ldexp(dy, k)
        adx, adxt = _two_diff(sx, vx)
        ady, adyt = _two_diff(sy, vy)
        bdx, bdxt = _two_diff(tx, vx)
        bdy, bdyt = _two_diff(ty, vy)
        cdx, cdxt = _two_diff(ux, vx)
        cdy, cdyt = _two_diff(uy, vy)
        if adxt == 0.0 and adyt == 0.0 and bdxt == 0.0 and bdyt == 0.0 and cdxt == 0.0 and cdyt == 0.0:
            det, exact = _ops_exact_incircle(adx, ady, bdx, bdy, cdx, cdy)
            if exact:
                return 1.0 if det > 0.0 else (-1.0 if det < 0.0 else 0.0)
    # stage 3: | x y x^2+y^2 1 | over the rows a, b, c, d, expanded into 48 monomials of
    # the raw inputs (positive when d is inside the circle through counter-clockwise a, b, c)
    xs = (ax, bx, cx, dx)
    ys = (ay, by, cy, dy)
    iw = w.view(np.int64)
    iw[:_ACC_LIMBS] = 0
    for i in range(_PERMS.shape[0]):
        px = xs[_PERMS[i, 0]]
        qy = ys[_PERMS[i, 1]]
        r = _PERMS[i, 2]
        negative = _PERMS[i, 3] < 0
        _acc_add(iw, negative, px, qy, xs[r], xs[r])
        _acc_add(iw, negative, px, qy, ys[r], ys[r])
    return _acc_sign(iw)


@njit(inline="always")
def incircle(ax, ay, bx, by, cx, cy, dx, dy, w):
    """In-circle test, exact in sign for any finite doubles.

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
    bc = bdxcdy - cdxbdy
    ca = cdxady - adxcdy
    ab = adxbdy - bdxady
    det = alift * bc + blift * ca + clift * ab
    permanent = (
        (abs(bdxcdy) + abs(cdxbdy)) * alift
        + (abs(cdxady) + abs(adxcdy)) * blift
        + (abs(adxbdy) + abs(bdxady)) * clift
    )
    # an underflowed product's absolute error is multiplied by a lift or a cross term
    tiny = _UNDERFLOW * (1.0 + alift + blift + clift + abs(bc) + abs(ca) + abs(ab))
    bound = INCIRCLE_ERRBOUND * permanent + tiny
    if det > bound or -det > bound:
        return det
    return incircle_exact(ax, ay, bx, by, cx, cy, dx, dy, w)


# Called from Python, an ``inline="always"`` function is compiled in every process (it has no
# cache): ``mesh.box`` calling incircle cost 0.5 s of every ``deforma run``. These cached
# wrappers inline it once and load from the cache afterwards.
@njit(cache=True)
def _orient2d_cached(ax, ay, bx, by, cx, cy, w):
    return orient2d(ax, ay, bx, by, cx, cy, w)


@njit(cache=True)
def _incircle_cached(ax, ay, bx, by, cx, cy, dx, dy, w):
    return incircle(ax, ay, bx, by, cx, cy, dx, dy, w)


@njit(cache=True)
def incircle_signs(a, b, c, d) -> np.ndarray:
    """Exact in-circle signs of ``d[k]`` against the counter-clockwise triangles ``a[k], b[k], c[k]``.

    Parameters
    ----------
    a, b, c, d : (K, 2) float64 ndarray
        The points of ``K`` tests.

    Returns
    -------
    (K,) float64 ndarray
        +1 inside, -1 outside, 0 on the circle. One compiled loop: :func:`incircle_py` per
        cell of a box's grid was a Python call each, seconds for a million cells.
    """
    w = np.zeros(SCRATCH_SIZE)
    out = np.empty(len(a))
    for k in range(len(a)):
        out[k] = np.sign(incircle(a[k, 0], a[k, 1], b[k, 0], b[k, 1], c[k, 0], c[k, 1], d[k, 0], d[k, 1], w))
    return out


def orient2d_py(a, b, c) -> float:
    """Exact orientation sign of three points; a convenience wrapper for tests and tools."""
    w = np.zeros(SCRATCH_SIZE)
    return float(np.sign(_orient2d_cached(float(a[0]), float(a[1]), float(b[0]), float(b[1]),
                                          float(c[0]), float(c[1]), w)))


def incircle_py(a, b, c, d) -> float:
    """Exact in-circle sign of d against the counter-clockwise triangle a, b, c."""
    w = np.zeros(SCRATCH_SIZE)
    return float(np.sign(_incircle_cached(float(a[0]), float(a[1]), float(b[0]), float(b[1]), float(c[0]),
                                          float(c[1]), float(d[0]), float(d[1]), w)))

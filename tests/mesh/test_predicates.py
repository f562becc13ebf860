"""The exact predicates against Python's exact rationals, stage by stage."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from deforma.mesh.predicates import (
    SCRATCH_SIZE,
    incircle,
    incircle_exact,
    orient2d,
    orient2d_exact,
)
from delaunay_checks import incircle_exact as incircle_fraction
from delaunay_checks import orient_exact as orient_fraction

W = np.zeros(SCRATCH_SIZE)


def sign(v: float) -> int:
    return int(np.sign(v))


# magnitudes from 2**-100 to 2**100 and exact small integers: products of four stay finite
values = st.one_of(
    st.floats(min_value=-(2.0**100), max_value=2.0**100, allow_nan=False, allow_infinity=False).filter(
        lambda v: v == 0 or abs(v) > 2.0**-100
    ),
    st.integers(-8, 8).map(float),
)
point = st.tuples(values, values)


@settings(max_examples=400, deadline=None)
@given(point, point, point)
def test_orient_signs_exact(a, b, c):
    want = orient_fraction(a, b, c)
    assert sign(orient2d(*a, *b, *c, W)) == want
    assert sign(orient2d_exact(*a, *b, *c, W)) == want


@settings(max_examples=400, deadline=None)
@given(point, point, point, point)
def test_incircle_signs_exact(a, b, c, d):
    if orient_fraction(a, b, c) == 0:
        return
    if orient_fraction(a, b, c) < 0:
        b, c = c, b
    want = incircle_fraction(a, b, c, d)
    assert sign(incircle(*a, *b, *c, *d, W)) == want
    assert sign(incircle_exact(*a, *b, *c, *d, W)) == want


def test_near_degenerate_cases_need_the_exact_stages():
    rng = np.random.default_rng(5)
    hits = 0
    for _ in range(300):
        # nearly cocircular: points on a circle, rounded, the fourth nudged by an ulp or so
        t = rng.random(4) * 2 * np.pi
        p = 0.3 + 0.1 * np.c_[np.cos(t), np.sin(t)]
        p[3] += rng.integers(-2, 3, 2) * np.spacing(p[3])
        a, b, c, d = map(tuple, p)
        if orient_fraction(a, b, c) < 0:
            b, c = c, b
        want = incircle_fraction(a, b, c, d)
        assert sign(incircle(*a, *b, *c, *d, W)) == want
        # nearly collinear: the middle of a segment, nudged by an ulp
        q = p[0] + 0.5 * (p[1] - p[0]) + rng.integers(-1, 2, 2) * np.spacing(p[0])
        want = orient_fraction(tuple(p[0]), tuple(p[1]), tuple(q))
        assert sign(orient2d(*p[0], *p[1], *q, W)) == want
        hits += want == 0
    assert hits > 0  # some cases were exactly degenerate


def test_float_filter_would_get_these_wrong():
    # A classic: float evaluation of orient2d gives inconsistent signs on a near-line
    # (Kettner et al., "Classroom examples of robustness problems in geometric computations").
    a = (0.5, 0.5)
    b = (12.0, 12.0)
    c = (24.0, 24.0)
    wrong = 0
    for i in range(64):
        for j in range(64):
            p = (a[0] + i * np.spacing(a[0]), a[1] + j * np.spacing(a[1]))
            want = orient_fraction(p, b, c)
            got = sign(orient2d(*p, *b, *c, W))
            assert got == want
            naive = (p[0] - c[0]) * (b[1] - c[1]) - (p[1] - c[1]) * (b[0] - c[0])
            wrong += sign(naive) != want
    assert wrong > 0  # the naive formula does fail here, so the test means something


def test_signs_survive_products_below_the_smallest_double():
    # Lattice points nudged by 7.6e-261 (found by the Delaunay property test): the large
    # terms cancel exactly and the sign rests on eps**2 ~ 6e-521, below the smallest double.
    eps = 7.616969426672526e-261
    a, b, c = (eps, -2.0), (-1.0, eps), (-2.0, 2.0)  # collinear but for the nudges
    assert orient_fraction(a, b, c) == 1
    assert sign(orient2d_exact(*a, *b, *c, W)) == sign(orient2d(*a, *b, *c, W)) == 1
    p, q, r, d = (-2.0, 2.0), (-2.0, -2.0), (-6.0, eps), (-1.0, eps)  # cocircular but for the nudges
    if orient_fraction(p, q, r) < 0:
        q, r = r, q
    want = incircle_fraction(p, q, r, d)
    assert want != 0
    assert sign(incircle_exact(*p, *q, *r, *d, W)) == sign(incircle(*p, *q, *r, *d, W)) == want


# every finite double: subnormals, normals and values near the largest double, with either sign
any_double = st.one_of(
    st.floats(allow_nan=False, allow_infinity=False),
    st.floats(min_value=-(2.0**-1000), max_value=2.0**-1000, allow_nan=False),
    st.integers(-(2**52), 2**52).map(lambda m: m * 2.0**-1074),  # subnormals, exactly
    st.sampled_from([0.0, 1.0, -1.0, 2.0**1023, -(2.0**1023), 1.7976931348623157e308, 5e-324]),
)
any_point = st.tuples(any_double, any_double)


@settings(max_examples=150, deadline=None)
@given(any_point, any_point, any_point, st.sampled_from(["free", "repeat", "mirror"]))
def test_orient_exact_over_the_whole_double_range(a, b, c, kind):
    if kind == "repeat":  # collinear or nearly: a coordinate shared, the sign rests on the rest
        c = (a[0], c[1])
    elif kind == "mirror":
        c = (-a[0], -a[1])
    want = orient_fraction(a, b, c)
    assert sign(orient2d(*a, *b, *c, W)) == want
    assert sign(orient2d_exact(*a, *b, *c, W)) == want


@settings(max_examples=150, deadline=None)
@given(any_point, any_point, any_point, any_point)
def test_incircle_exact_over_the_whole_double_range(a, b, c, d):
    o = orient_fraction(a, b, c)
    if o == 0:
        return
    if o < 0:
        b, c = c, b
    want = incircle_fraction(a, b, c, d)
    assert sign(incircle(*a, *b, *c, *d, W)) == want
    assert sign(incircle_exact(*a, *b, *c, *d, W)) == want


@pytest.mark.parametrize("big, small", [(1e300, 1e-300), (2.0**1000, 2.0**-1000), (1.7e308, 5e-324)])
def test_signs_with_magnitudes_mixed_in_one_call(big, small):
    # the large terms cancel exactly; the sign rests on products of the small ones, far
    # below the smallest double (and the large products far above the largest)
    a, b, c = (big, big), (2 * small, small), (small, 0.0)
    assert orient_fraction(a, b, c) != 0
    assert sign(orient2d(*a, *b, *c, W)) == orient_fraction(a, b, c)
    for p, q, r, d in [
        ((-big, 0.0), (big, 0.0), (0.0, big), (0.0, -big + small)),  # just inside
        ((-big, 0.0), (big, 0.0), (0.0, big), (small, -big)),  # on the circle, by a hair off
        ((0.0, 0.0), (small, 0.0), (0.0, small), (big, big)),  # tiny circle, far point
        ((small, small), (big, -big), (big, big), (2 * small, 0.0)),
    ]:
        if orient_fraction(p, q, r) == 0:
            continue
        if orient_fraction(p, q, r) < 0:
            q, r = r, q
        assert sign(incircle(*p, *q, *r, *d, W)) == incircle_fraction(p, q, r, d)


def test_filters_do_not_trust_products_below_the_smallest_normal_double():
    # Differences around 1e-160: products fall to subnormals, where rounding is absolute,
    # not relative. The points are nearly collinear / cocircular at that scale.
    s = 1e-160
    rng = np.random.default_rng(8)
    for _ in range(200):
        a = tuple(rng.integers(-50, 50, 2) * s)
        b = tuple(rng.integers(-50, 50, 2) * s)
        t = rng.random()
        c = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
        assert sign(orient2d(*a, *b, *c, W)) == orient_fraction(a, b, c)
        ang = rng.random(4) * 2 * np.pi
        p = [(s * 40 * np.cos(u), s * 40 * np.sin(u)) for u in ang]
        if orient_fraction(p[0], p[1], p[2]) == 0:
            continue
        if orient_fraction(p[0], p[1], p[2]) < 0:
            p[1], p[2] = p[2], p[1]
        assert sign(incircle(*p[0], *p[1], *p[2], *p[3], W)) == incircle_fraction(*p)

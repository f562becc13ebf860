"""deforma.delaunay against SciPy on random points and against exact properties on
degenerate ones (grids, cocircular and collinear sets, duplicates, extreme scales)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull
from scipy.spatial import Delaunay as ScipyDelaunay

import deforma
from delaunay_checks import canonical, check_delaunay, orient_exact

HYP = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@pytest.mark.parametrize("n, seed", [(3, 0), (4, 1), (10, 2), (100, 3), (2000, 4), (50_000, 5)])
def test_same_triangles_as_scipy_on_random_points(n, seed):
    pts = np.random.default_rng(seed).random((n, 2))
    ours = deforma.delaunay(pts)
    assert canonical(ours) == canonical(ScipyDelaunay(pts).simplices)
    if n <= 2000:
        check_delaunay(pts, ours)


def test_same_triangles_as_scipy_on_gaussian_points_with_offset():
    pts = np.random.default_rng(7).normal(size=(5000, 2)) * 3.0 + (1e4, -2e4)
    assert canonical(deforma.delaunay(pts)) == canonical(ScipyDelaunay(pts).simplices)


def test_public_names():
    pts = np.random.default_rng(0).random((20, 2))
    assert np.array_equal(deforma.delaunay(pts), deforma.mesh.delaunay(pts))


def test_unit_square_with_centre():
    pts = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]])
    tris = deforma.delaunay(pts)
    assert tris.shape == (4, 3)
    assert all(4 in t for t in tris)
    check_delaunay(pts, tris)


@pytest.mark.parametrize("w, h", [(2, 2), (3, 2), (7, 5), (30, 30)])
def test_integer_grid_every_four_points_cocircular(w, h):
    pts = np.stack(np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float)), -1).reshape(-1, 2)
    tris = deforma.delaunay(pts)
    assert len(tris) == 2 * (w - 1) * (h - 1)  # every cell split in two, no slivers
    check_delaunay(pts, tris)


def test_grid_with_non_representable_spacing():
    # 0.1 is not a double: spacing and differences round, so the exact stages must work
    pts = np.stack(np.meshgrid(np.arange(12) * 0.1, np.arange(9) * 0.1), -1).reshape(-1, 2)
    check_delaunay(pts, deforma.delaunay(pts))


def test_points_on_one_circle_with_exact_coordinates():
    # all integer points on the circle x^2 + y^2 = 5^4: every four of them cocircular
    r2 = 625
    pts = [(x, y) for x in range(-25, 26) for y in range(-25, 26) if x * x + y * y == r2]
    pts = np.array(pts, float)
    assert len(pts) >= 12
    tris = deforma.delaunay(pts)
    assert len(tris) == len(pts) - 2
    check_delaunay(pts, tris)


def test_collinear_points_on_the_hull_are_vertices():
    line = np.c_[np.linspace(0, 1, 11), np.zeros(11)]
    pts = np.vstack([line, [[0.5, 1.0]]])
    tris = deforma.delaunay(pts)
    assert len(tris) == 10
    check_delaunay(pts, tris)


def test_duplicates_reference_the_lowest_index():
    rng = np.random.default_rng(3)
    base = rng.random((40, 2))
    pts = np.vstack([base, base[::3], base[:5]])
    tris = deforma.delaunay(pts)
    assert tris.max() < 40
    assert canonical(tris) == canonical(deforma.delaunay(base))
    # the lowest index wins even when a duplicate comes first in the input
    swapped = np.vstack([base[:1], base])
    assert 1 not in set(deforma.delaunay(swapped).ravel().tolist())


@pytest.mark.parametrize("scale", [2.0**-1000, 1e-300, 1e-150, 1e150, 1e300, 2.0**1000])
def test_extreme_scales(scale):
    rng = np.random.default_rng(11)
    pts = rng.random((300, 2))
    grid = np.stack(np.meshgrid(np.arange(6.0), np.arange(6.0)), -1).reshape(-1, 2)
    for p in (pts, grid):
        scaled = p * scale
        tris = deforma.delaunay(scaled)
        check_delaunay(scaled, tris, brute_force=False)
        if np.log2(scale).is_integer():  # power-of-two scaling is exact: same result
            assert np.array_equal(tris, deforma.delaunay(p))


def test_deterministic():
    pts = np.stack(np.meshgrid(np.arange(20.0), np.arange(20.0)), -1).reshape(-1, 2)
    assert np.array_equal(deforma.delaunay(pts), deforma.delaunay(pts))


@pytest.mark.parametrize(
    "points, message",
    [
        ([[0, 0], [1, 1]], "at least 3 points"),
        ([[0, 0], [0, 0], [0, 0]], "3 distinct points"),
        ([[0, 0], [1, 1], [2, 2], [3, 3]], "collinear"),
        ([[0, 0], [1, 0], [np.nan, 1]], "finite"),
        ([[0, 0], [1, 0], [np.inf, 1]], "finite"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], r"\(N, 2\)"),
        ([0, 1, 2], r"\(N, 2\)"),
        ([["a", "b"], ["c", "d"], ["e", "f"]], "real numbers"),
        ([[0, 0], [1, 0], [0, 1j]], "complex"),
        (np.array([[0, 0], [1, 0], [0, 1]], complex), "complex"),
        ([[0, 0], [1, 0], [0, 10**400]], "real numbers"),
        ([[0, 0], [1, 0], [0, 2**1024]], "real numbers"),  # an int beyond the largest double
    ],
)
def test_bad_input_raises_one_line_value_error(points, message):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning or overflow warning on the way
        with pytest.raises(ValueError, match=message) as info:
            deforma.delaunay(points)
    assert "\n" not in str(info.value)


# -- property-based: degenerate sets ------------------------------------------------------


def _exactly_degenerate(pts: np.ndarray) -> bool:
    """Fewer than 3 distinct points, or all on one line, decided in exact arithmetic.

    (A float rank test is no oracle here: rounding makes "collinear" lattice points, once
    scaled and offset, slightly non-collinear, and those the triangulation must accept.)
    """
    u = np.unique(pts, axis=0)
    if len(u) < 3:
        return True
    from fractions import Fraction

    def dist(i):  # exact: float differences of huge coordinates overflow
        return sum(abs(Fraction(float(u[i][k])) - Fraction(float(u[0][k]))) for k in range(2))

    far = max(range(1, len(u)), key=dist)
    return all(orient_exact(u[0], u[far], q) == 0 for q in u)

coords = st.integers(min_value=-6, max_value=6)
small_int_points = st.lists(st.tuples(coords, coords), min_size=3, max_size=40)


@HYP
@given(small_int_points, st.sampled_from([1.0, 0.1, 2.0**-30, 3.0e7]), st.floats(-1e3, 1e3))
def test_property_integer_lattice_sets(raw, scale, offset):
    """Few distinct values per axis: many duplicates, collinear runs and cocircular sets."""
    pts = np.array(raw, float) * scale + offset
    if _exactly_degenerate(pts):
        with pytest.raises(ValueError):
            deforma.delaunay(pts)
        return
    check_delaunay(pts, deforma.delaunay(pts))


@HYP
@given(
    st.integers(3, 30),
    st.integers(0, 2**32 - 1),
    st.sampled_from(["circle", "line+1", "two-lines", "cluster"]),
)
def test_property_structured_degenerate_sets(n, seed, kind):
    rng = np.random.default_rng(seed)
    if kind == "circle":  # points on a circle (rounded: nearly cocircular) plus its centre
        t = rng.random(n) * 2 * np.pi
        pts = np.vstack([np.c_[np.cos(t), np.sin(t)], [[0.0, 0.0]]])
    elif kind == "line+1":  # a collinear run and one point off it
        s = rng.random(n)
        pts = np.vstack([np.c_[s, 2 * s + 1], [[0.3, -5.0]]])
    elif kind == "two-lines":
        s = rng.integers(0, 8, n).astype(float)
        pts = np.vstack([np.c_[s, np.zeros(n)], np.c_[s, np.ones(n)]])
    else:  # a tight cluster far from the origin: differences round
        pts = 1e6 + rng.random((n, 2)) * 1e-9
    if _exactly_degenerate(pts):
        with pytest.raises(ValueError):
            deforma.delaunay(pts)
        return
    check_delaunay(pts, deforma.delaunay(pts))


def test_regression_box_points_reusing_cavity_slots():
    # Crashed an early version of the kernel: a fan reused a freed cavity slot whose id
    # the outside triangle still held, and the adjacency was patched in the wrong place.
    m = deforma.mesh.box(((0.1, 0.3), (2.7, 0.1), (2.3, 1.9), (0.3, 1.3)), detail=7, edges=True)
    check_delaunay(m.vertices, deforma.delaunay(m.vertices))


def test_nearly_collinear_after_rounding_is_triangulated():
    # Lattice points on one line, scaled and offset: rounding moves them off the line by an
    # ulp, so they are not collinear any more and must be triangulated (without slivers of
    # negative area), not rejected.
    raw = np.array([[11, 6], [-13, -18], [11, 6], [-16, -21], [-4, -9]], float)
    pts = raw * 3.0e7 + 29.777640542740528
    assert not _exactly_degenerate(pts)
    check_delaunay(pts, deforma.delaunay(pts))


# -- magnitudes mixed in one set: the whole double range -----------------------------------


def _check_covers_hull(pts: np.ndarray, tris: np.ndarray) -> None:
    """Every distinct point a vertex, exact Delaunay (check_delaunay), and the triangles'
    area equal to SciPy's hull area on a copy scaled to magnitude 1 (when that hull exists)."""
    check_delaunay(pts, tris, brute_force=len(pts) <= 40)
    used = set(np.unique(tris).tolist())
    assert len(used) == len(np.unique(pts, axis=0))
    unit = pts / np.abs(pts).max()  # small points may flush to 0 here: area unaffected
    try:
        hull = ConvexHull(unit)
    except Exception:  # all large points on one line in the scaled copy: nothing to compare
        return
    a, b, c = unit[tris[:, 0]], unit[tris[:, 1]], unit[tris[:, 2]]
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])).sum()
    # rounding of the scaled copy: up to ~1e-16 of the unit box per triangle
    assert area == pytest.approx(hull.volume, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("big, small", [(1e300, 1e-300), (2.0**1000, 2.0**-1000), (1.7e308, 5e-324), (1.0, 1e-310)])
def test_magnitudes_mixed_in_one_set_keep_every_point(big, small):
    # issue 17: half the distinct points were dropped (the tiny ones flushed to 0 when the
    # set was scaled down) and the triangles no longer covered the hull
    rng = np.random.default_rng(17)
    pts = np.vstack([(rng.random((20, 2)) - 0.5) * big, (rng.random((20, 2)) - 0.5) * small])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tris = deforma.delaunay(pts)
    _check_covers_hull(pts, tris)


@pytest.mark.parametrize("scale", [5e-324, 1e-320, 5.6e-309, 2.0**-1060])
def test_subnormal_coordinates_are_points_not_coincident(scale):
    # issue 17: below ~5.6e-309 the scaling factor overflowed and every point "coincided"
    grid = np.stack(np.meshgrid(np.arange(5.0), np.arange(4.0)), -1).reshape(-1, 2)
    pts = grid * scale
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tris = deforma.delaunay(pts)
    _check_covers_hull(pts, tris)
    assert len(tris) == 2 * 4 * 3


magnitude = st.sampled_from([5e-324, 2.0**-1074 * 3, 1e-310, 2.0**-1000, 1e-300, 1e-150, 1.0, 3.0e7, 1e150,
                             1e300, 2.0**1000, 2.0**1020])


@HYP
@given(
    st.lists(
        st.tuples(st.integers(-4, 4), st.integers(-4, 4), magnitude, st.floats(-1, 1)),
        min_size=3,
        max_size=25,
    )
)
def test_property_sets_mixing_magnitudes(raw):
    """Small lattices (collinear runs, cocircular quads) and random points, each at its own
    magnitude from the smallest subnormal to 2**1022, in one set."""
    pts = np.array([(x * m, y * m) if abs(r) < 0.5 else (x * m * r, y * m * (1 - r)) for x, y, m, r in raw])
    if _exactly_degenerate(pts):
        with pytest.raises(ValueError):
            deforma.delaunay(pts)
        return
    _check_covers_hull(pts, deforma.delaunay(pts))

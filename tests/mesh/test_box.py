"""Box meshes: point counts, exact area, no slivers on the sides, clear errors for bad quads."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import deforma
from deforma.mesh import box
from delaunay_checks import check_delaunay


def shoelace(c):
    c = np.asarray(c, float)
    x, y = c[:, 0], c[:, 1]
    return 0.5 * (np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


RECT = ((0, 0), (2, 0), (2, 1), (0, 1))


@pytest.mark.parametrize("n", [0, 1, 2, 3, 8, 15])
@pytest.mark.parametrize("edges", [False, True])
def test_point_count_area_and_topology(n, edges):
    m = box(RECT, detail=n, edges=edges)
    expected = n * n + 4 + (4 * n if edges else 0)
    assert len(m.vertices) == expected
    assert m.area == pytest.approx(2.0, rel=1e-12)
    assert (m.triangle_areas > 0).all()
    assert len(m.boundary) == 1
    assert m.euler_characteristic == 1
    # every point is used by some triangle
    assert np.array_equal(np.unique(m.triangles), np.arange(expected))


def test_interior_points_are_bilinear_grid():
    m = box(RECT, detail=3, edges=False)
    assert np.allclose(m.vertices[:4], RECT)
    xs = np.unique(m.vertices[4:, 0].round(12))
    ys = np.unique(m.vertices[4:, 1].round(12))
    assert np.allclose(xs, [0.5, 1.0, 1.5])
    assert np.allclose(ys, [0.25, 0.5, 0.75])


def test_edges_put_points_on_sides_at_grid_spacing():
    m = box(RECT, detail=4, edges=True)
    b = m.vertices[m.boundary[0]]
    # boundary runs through all 4 + 4*4 outline points, spaced 2/5 along x and 1/5 along y
    assert len(b) == 20
    steps = np.hypot(*np.diff(np.vstack([b, b[:1]]), axis=0).T)
    assert np.allclose(np.sort(np.unique(steps.round(12))), [0.2, 0.4])
    # with sides subdivided, the mesh is a grid of right triangles with legs 0.4 and 0.2
    assert m.min_angle == pytest.approx(math.degrees(math.atan(0.5)), abs=1e-9)


def test_edges_give_better_triangles_than_bare_sides():
    bare = box(RECT, detail=8, edges=False)
    sided = box(RECT, detail=8, edges=True)
    assert sided.min_angle > 4 * bare.min_angle
    assert sided.max_aspect_ratio < bare.max_aspect_ratio


def test_clockwise_corners_and_uv():
    m = box(RECT[::-1], detail=2, edges=True)
    assert m.area == pytest.approx(2.0, rel=1e-12)
    assert (m.triangle_areas > 0).all()
    assert m.uv.min() == 0.0 and m.uv.max() == 1.0
    # uv (u, v) maps back to the position through the bilinear map of the given corners
    c = np.asarray(RECT[::-1], float)
    u, v = m.uv[:, :1], m.uv[:, 1:]
    back = c[0] + u * (c[1] - c[0]) + v * (c[3] - c[0]) + u * v * (c[0] - c[1] + c[2] - c[3])
    assert np.allclose(back, m.vertices)


def test_tilted_sides_have_no_slivers():
    # sides at awkward angles put rounded points a hair off their line: no sliver may survive
    corners = ((0.1, 0.3), (2.7, 0.1), (2.3, 1.9), (0.3, 1.3))
    for n in range(1, 30):
        m = box(corners, detail=n, edges=True)
        assert m.area == pytest.approx(shoelace(corners), rel=1e-12)
        assert m.min_angle > 5.0
        assert len(m.boundary[0]) == 4 + 4 * n


convex_quads = st.tuples(
    st.floats(-100, 100), st.floats(-100, 100),  # centre
    st.floats(0.01, 50),  # radius
    st.lists(st.floats(0, 2 * math.pi), min_size=4, max_size=4, unique=True),
    st.lists(st.floats(0.5, 1.0), min_size=4, max_size=4),
)


def make_quad(cx, cy, r, angles, radii):
    angles = sorted(angles)
    return np.array([[cx + r * f * math.cos(a), cy + r * f * math.sin(a)] for a, f in zip(angles, radii)])


def turns(q):
    e = np.roll(q, -1, axis=0) - q
    f = np.roll(e, -1, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = (e[:, 0] * f[:, 1] - e[:, 1] * f[:, 0]) / (np.hypot(*e.T) * np.hypot(*f.T))
    if np.hypot(*e.T).min() < 1e-6 * np.ptp(q, axis=0).max():
        return np.zeros(4)  # corners too close to tell apart: not a clear quad
    return np.nan_to_num(s)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(convex_quads, st.integers(0, 6), st.booleans())
def test_random_convex_quads(quad, n, edges):
    q = make_quad(*quad)
    s = turns(q)
    assume((s > 1e-3).all())  # clearly convex
    m = box(q, detail=n, edges=edges)
    # far from the origin, coordinates of size |q| carry rounding of eps |q| |quad size|
    # into each area, so the tolerance grows with |q|
    assert m.area == pytest.approx(shoelace(q - q.mean(axis=0)), rel=1e-9, abs=1e-13 * np.abs(q).max() ** 2)
    assert (m.triangle_areas > 0).all()
    assert len(m.vertices) == n * n + 4 + (4 * n if edges else 0)
    assert m.euler_characteristic == 1 and len(m.boundary) == 1


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(convex_quads, st.integers(0, 3), st.floats(0.05, 0.95))
def test_collinear_corner_is_rejected(quad, k, f):
    q = make_quad(*quad)
    assume((turns(q) > 1e-3).all())
    # put corner k+1 on the segment from corner k to corner k+2
    q[(k + 1) % 4] = q[k] + f * (q[(k + 2) % 4] - q[k])
    with pytest.raises(ValueError, match="line"):
        box(q, detail=2)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(convex_quads, st.integers(0, 3))
def test_crossed_quad_is_rejected(quad, k):
    q = make_quad(*quad)
    assume((turns(q) > 1e-3).all())
    q[[k, (k + 1) % 4]] = q[[(k + 1) % 4, k]]  # swapping neighbours makes a bow tie
    with pytest.raises(ValueError, match="self-intersecting"):
        box(q, detail=2)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(convex_quads, st.integers(0, 3))
def test_coinciding_corners_are_rejected(quad, k):
    q = make_quad(*quad)
    assume((turns(q) > 1e-3).all())
    q[(k + 1) % 4] = q[k]
    with pytest.raises(ValueError, match="coincide"):
        box(q, detail=2)


@pytest.mark.parametrize(
    "corners, message",
    [
        (((0, 0), (2, 0), (0.5, 0.5), (0, 2)), "concave"),
        (((1, 1),) * 4, "same point"),
        (((0, 0), (1, 0), (1, 1)), r"shape \(4, 2\)"),
        (((0, 0), (1, 0), (1, float("nan")), (0, 1)), "finite"),
        ("abcd", "pairs"),
    ],
)
def test_bad_corners(corners, message):
    with pytest.raises(ValueError, match=message):
        box(corners, detail=2)


@pytest.mark.parametrize("detail", [-1, 2.5, "3", True])
def test_bad_detail(detail):
    with pytest.raises(ValueError, match=r"detail must be an integer >= 0"):
        box(RECT, detail=detail)


def test_bad_edges_flag():
    with pytest.raises(ValueError, match="edges must be True or False"):
        box(RECT, detail=2, edges="yes")


def test_public_name():
    m = deforma.mesh.box(RECT, detail=1)
    assert isinstance(m, deforma.mesh.Mesh)


def mirrored_edges(m, axis):
    """The mesh's edge set, and the same set with every vertex replaced by its mirror image
    across the box's centre line (x -> -x for axis 0)."""
    x = m.vertices
    flip = x.copy()
    flip[:, axis] *= -1
    key = {tuple(np.round(p, 9) + 0.0): k for k, p in enumerate(x)}
    mirror = np.array([key[tuple(np.round(p, 9) + 0.0)] for p in flip])
    edges = set(map(tuple, np.sort(m.edges, axis=1).tolist()))
    return edges, set(map(tuple, np.sort(mirror[np.array(sorted(edges))], axis=1).tolist()))


@pytest.mark.parametrize("n", [1, 3, 9])
def test_rectangle_with_even_cell_count_is_mirror_symmetric_and_still_delaunay(n):
    m = box(((-0.75, -0.5), (0.75, -0.5), (0.75, 0.5), (-0.75, 0.5)), detail=n, edges=True)
    for axis in (0, 1):
        edges, mirrored = mirrored_edges(m, axis)
        assert edges == mirrored  # no lattice direction is preferred: dropped flat, it lands flat
    check_delaunay(m.vertices, m.triangles)


def test_odd_cell_count_has_no_preferred_shear_direction():
    m = box(((-0.75, -0.5), (0.75, -0.5), (0.75, 0.5), (-0.75, 0.5)), detail=8, edges=True)
    x, t = m.vertices, m.triangles
    # diagonals of the cells: rising (/) and falling (\) in equal numbers, up to the middle column
    d = np.array([[a, b] for tri in t for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0]))])
    v = x[d[:, 1]] - x[d[:, 0]]
    diagonal = (np.abs(v[:, 0]) > 1e-9) & (np.abs(v[:, 1]) > 1e-9)
    rising = np.sign(v[diagonal, 0] * v[diagonal, 1])
    assert abs(rising.sum()) / 2 <= 9  # each diagonal appears twice (once per triangle); one way: 81
    check_delaunay(x, t)


def test_edges_default_is_the_same_in_the_api_the_cli_and_scene_files():
    # issue 18: one default (on), so a box looks the same however it is asked for
    import inspect
    from dataclasses import fields

    from deforma.cli import _parser
    from deforma.scene import schema

    api = inspect.signature(box).parameters["edges"].default
    scene = next(f.default for f in fields(schema.BoxBody) if f.name == "edges")
    cli = _parser().parse_args(["mesh", "box", "-o", "m.png"]).edges
    assert api is scene is cli is True
    m = box(RECT, detail=3)
    assert len(m.vertices) == 3 * 3 + 4 + 4 * 3

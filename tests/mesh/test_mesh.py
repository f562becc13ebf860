"""The Mesh type: validation, edges, boundary loops, quality figures."""

import math

import numpy as np
import pytest

from deforma.mesh import Mesh
from deforma.mesh import quality

SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]


def annulus(n=12, r0=1.0, r1=2.0):
    """A ring of 2n vertices and 2n triangles: one hole."""
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    v = np.concatenate([np.c_[r0 * np.cos(a), r0 * np.sin(a)], np.c_[r1 * np.cos(a), r1 * np.sin(a)]])
    t = []
    for i in range(n):
        j = (i + 1) % n
        t += [[i, n + i, n + j], [i, n + j, j]]
    return v, np.array(t)


def test_square_known_answers():
    m = Mesh(SQUARE, [[0, 1, 2], [0, 2, 3]])
    assert m.vertices.dtype == np.float64 and m.triangles.dtype == np.int32
    assert m.edges.dtype == np.int32
    assert m.edges.tolist() == [[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]]
    assert m.area == 1.0
    assert m.triangle_areas.tolist() == [0.5, 0.5]
    assert m.min_angle == pytest.approx(45.0)
    # right isosceles triangle: R = sqrt(2)/2, r = (2 - sqrt(2))/2
    assert m.aspect_ratios == pytest.approx(np.full(2, (math.sqrt(2) / 2) / (2 - math.sqrt(2))))
    assert m.euler_characteristic == 1
    assert len(m.boundary) == 1 and sorted(m.boundary[0].tolist()) == [0, 1, 2, 3]
    assert m.uv.tolist() == SQUARE


def test_clockwise_triangles_are_reversed():
    m = Mesh(SQUARE, [[0, 2, 1], [0, 3, 2]])
    assert (m.triangle_areas > 0).all()
    assert m.area == 1.0


def test_boundary_loops_of_an_annulus():
    v, t = annulus()
    m = Mesh(v, t)
    assert m.euler_characteristic == 0
    assert len(m.boundary) == 2
    outer, hole = m.boundary
    assert sorted(outer.tolist()) == list(range(12, 24))
    assert sorted(hole.tolist()) == list(range(12))

    def signed(loop):
        x, y = v[loop, 0], v[loop, 1]
        return 0.5 * (np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))

    assert signed(outer) > 0 > signed(hole)  # outline counter-clockwise, hole clockwise
    # consecutive loop vertices are joined by boundary edges
    b = {tuple(e) for e in m.boundary_edges.tolist()}
    assert all((int(outer[i]), int(outer[(i + 1) % 12])) in b for i in range(12))


def test_equilateral_quality():
    v = [[0, 0], [1, 0], [0.5, math.sqrt(3) / 2]]
    m = Mesh(v, [[0, 1, 2]])
    assert m.min_angle == pytest.approx(60.0)
    assert m.max_aspect_ratio == pytest.approx(1.0)
    assert quality.triangle_angles(v, [[0, 1, 2]]).sum() == pytest.approx(180.0)


def test_quality_worsens_as_a_triangle_flattens():
    ratios = [Mesh([[0, 0], [1, 0], [0.5, h]], [[0, 1, 2]]).max_aspect_ratio for h in (0.8, 0.2, 0.05, 0.01)]
    assert ratios == sorted(ratios) and ratios[-1] > 100


def test_collinear_triangle_is_rejected():
    with pytest.raises(ValueError, match="degenerate"):
        Mesh([[0, 0], [1, 0], [2, 0], [0, 1]], [[0, 1, 3], [0, 1, 2]])
    with pytest.raises(ValueError, match="degenerate"):
        Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 1]])


def test_nearly_collinear_rounding_sliver_is_rejected():
    # a point a rounding error off the line through the other two
    with pytest.raises(ValueError, match="degenerate"):
        Mesh([[0, 0], [0.3, 0.1 + 1e-17], [0.9, 0.3]], [[0, 1, 2]])
    assert quality.degenerate_triangles([[0, 0], [0.3, 0.1], [0.9, 0.3 + 1e-6]], [[0, 1, 2]]).tolist() == [False]


@pytest.mark.parametrize(
    "vertices, triangles, message",
    [
        ([[0, 0], [1, 0]], [[0, 1, 0]], r"vertices must be an \(N, 2\)"),
        ([[0, 0], [1, 0], [0, np.nan]], [[0, 1, 2]], "finite"),
        (SQUARE, [[0, 1]], r"triangles must be an \(M, 3\)"),
        (SQUARE, np.zeros((0, 3), int), r"M >= 1"),
        (SQUARE, [[0.0, 1.0, 2.0]], "integers"),
        (SQUARE, [[0, 1, 4]], r"indices must lie in \[0, 3\]"),
        (SQUARE, [[0, 1, 2], [2, 0, 1]], "same triangle twice"),
        ([[0, 0], [1, 0], [0, 1], [0, -1], [0.5, 2]], [[0, 1, 2], [0, 1, 3], [1, 0, 4]], "at most 2"),
    ],
)
def test_bad_input(vertices, triangles, message):
    with pytest.raises(ValueError, match=message):
        Mesh(vertices, triangles)


def test_uv_and_texture_checks():
    m = Mesh(SQUARE, [[0, 1, 2]], uv=np.full((4, 2), 0.5), texture=np.zeros((2, 3, 4), np.uint8))
    assert m.texture.shape == (2, 3, 4)
    with pytest.raises(ValueError, match="uv must have"):
        Mesh(SQUARE, [[0, 1, 2]], uv=[[0, 0]])
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        Mesh(SQUARE, [[0, 1, 2]], uv=np.full((4, 2), 1.5))
    with pytest.raises(ValueError, match="RGBA"):
        Mesh(SQUARE, [[0, 1, 2]], texture=np.zeros((2, 3), np.uint8))


def test_input_arrays_are_copied():
    v = np.array(SQUARE, float)
    m = Mesh(v, [[0, 1, 2]])
    v[0] = 9
    assert m.vertices[0].tolist() == [0, 0]


@pytest.mark.parametrize("n", [10, 3_000_000])
def test_row_keys_order_rows_lexicographically(n):
    from deforma.mesh.mesh import _row_keys

    rng = np.random.default_rng(0)
    rows = rng.integers(0, min(n, 7), size=(200, 3))
    keys = _row_keys(rows, n)
    order = np.lexsort(rows.T[::-1])
    assert (np.diff(keys[order]) >= 0).all()  # lexicographic order is key order
    same = (rows[:, None, :] == rows[None, :, :]).all(axis=2)
    assert np.array_equal(same, keys[:, None] == keys[None, :])  # equal rows <=> equal keys


def test_texture_coordinates_are_given_by_keyword():
    with pytest.raises(TypeError):
        Mesh(SQUARE, [[0, 1, 2]], np.full((4, 2), 0.5))  # noqa: the positional uv is refused
    assert Mesh(SQUARE, [[0, 1, 2]], uv=np.full((4, 2), 0.5)).uv.shape == (4, 2)

"""Outlines of pictures: ``deforma.mesh.outline`` (simple polygons with holes, in metres).

Known answers: a rectangle is four corners of its size; areas are pixel counts times
scale^2; a ring is one outer loop and one hole, an island in the hole a second region; the
outline lies on the mesh of the same picture; every loop is simple, outer loops run
counter-clockwise and holes clockwise, inside their outer loop, whatever the picture.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import ndimage

import deforma
from deforma.mesh import outline
from deforma.mesh.outline import simplify_loop


def area(loop):
    """Signed shoelace area: > 0 counter-clockwise (y up)."""
    x, y = loop[:, 0], loop[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def region_area(outer, holes):
    return area(outer) + sum(area(h) for h in holes)  # holes are clockwise: negative


def cross(o, p, q):
    return (p[..., 0] - o[..., 0]) * (q[..., 1] - o[..., 1]) - (p[..., 1] - o[..., 1]) * (q[..., 0] - o[..., 0])


def crossings(loops):
    """Pairs of segments (of all loops together) that cross or touch, other than a loop's
    neighbouring segments at their shared corner. Brute force, O(n^2)."""
    a = np.concatenate(loops)
    b = np.concatenate([np.roll(x, -1, axis=0) for x in loops])
    loop = np.repeat(np.arange(len(loops)), [len(x) for x in loops])
    pos = np.concatenate([np.arange(len(x)) for x in loops])
    size = np.array([len(x) for x in loops])[loop]
    i, j = np.triu_indices(len(a), 1)
    gap = np.abs(pos[i] - pos[j])
    neighbours = (loop[i] == loop[j]) & ((gap == 1) | (gap == size[i] - 1))
    d1, d2 = cross(a[i], b[i], a[j]), cross(a[i], b[i], b[j])
    d3, d4 = cross(a[j], b[j], a[i]), cross(a[j], b[j], b[i])
    proper = (d1 * d2 < 0) & (d3 * d4 < 0)

    def on(p, q, r):  # r on segment pq, given collinear
        return np.all((np.minimum(p, q) <= r) & (r <= np.maximum(p, q)), axis=1)

    touch = ((d1 == 0) & on(a[i], b[i], a[j])) | ((d2 == 0) & on(a[i], b[i], b[j]))
    touch |= ((d3 == 0) & on(a[j], b[j], a[i])) | ((d4 == 0) & on(a[j], b[j], b[i]))
    # neighbours may only meet at their shared corner: collinear and folding back is a spike
    spike = np.zeros(len(i), bool)
    if neighbours.any():
        shared = np.where(np.all(b[i] == a[j], axis=1)[:, None], b[i], a[i])
        other_i = np.where(np.all(shared == a[i], axis=1)[:, None], b[i], a[i])
        other_j = np.where(np.all(shared == a[j], axis=1)[:, None], b[j], a[j])
        spike = (cross(shared, other_i, other_j) == 0) & (np.sum((other_i - shared) * (other_j - shared), axis=1) > 0)
    bad = np.where(neighbours, spike, proper | touch)
    return np.c_[i[bad], j[bad]]


def inside(points, loop):
    """Even-odd point in polygon (points not on the boundary)."""
    x, y = points[:, 0:1], points[:, 1:2]
    ax, ay = loop[:, 0], loop[:, 1]
    bx, by = np.roll(ax, -1), np.roll(ay, -1)
    straddle = (ay > y) != (by > y)
    xcross = ax + (y - ay) * (bx - ax) / np.where(by != ay, by - ay, 1.0)
    return (np.sum(straddle & (x < xcross), axis=1) % 2) == 1


def check_polygons(regions):
    """Every loop simple and non-degenerate, outer CCW, holes CW and inside their outer."""
    loops = []
    for outer, holes in regions:
        assert outer.dtype == np.float64 and outer.ndim == 2 and outer.shape[1] == 2 and len(outer) >= 3
        assert not np.array_equal(outer[0], outer[-1])  # not closed
        assert area(outer) > 0
        for h in holes:
            assert len(h) >= 3 and area(h) < 0
            assert inside(h, outer).all()
        loops += [outer, *holes]
    assert len(crossings(loops)) == 0


def square_picture():
    pic = np.zeros((40, 60), np.uint8)
    pic[10:30, 10:50] = 255  # 40 x 20 px
    return pic


def ring_mask(size=120, r_out=50, r_in=25):
    yy, xx = np.mgrid[0:size, 0:size] + 0.5
    d2 = (xx - size / 2) ** 2 + (yy - size / 2) ** 2
    return (d2 < r_out**2) & (d2 >= r_in**2)


def test_square_is_four_corners_ccw_of_its_size():
    [(outer, holes)] = outline(square_picture(), scale=0.01)
    assert holes == []
    assert outer.shape == (4, 2) and area(outer) > 0
    # 40 x 20 px at 1 cm, centred on the origin, corners exact
    assert sorted(map(tuple, outer.round(12).tolist())) == [(-0.2, -0.1), (-0.2, 0.1), (0.2, -0.1), (0.2, 0.1)]
    check_polygons([(outer, holes)])


def test_ring_is_outer_ccw_and_hole_cw_with_the_pixel_area():
    mask = ring_mask()
    scale = 0.02
    regions = outline(mask, scale=scale)
    assert len(regions) == 1
    outer, holes = regions[0]
    assert len(holes) == 1 and area(outer) > 0 and area(holes[0]) < 0
    assert region_area(outer, holes) == pytest.approx(mask.sum() * scale**2, rel=0.03)
    check_polygons(regions)


def test_tolerance_zero_keeps_the_staircase_exactly():
    mask = ring_mask()
    regions = outline(mask, scale=1.0, tolerance=0)
    outer, holes = regions[0]
    assert region_area(outer, holes) == mask.sum()  # pixel borders: exact area
    for loop in (outer, *holes):
        step = np.roll(loop, -1, axis=0) - loop
        assert np.all((step[:, 0] == 0) | (step[:, 1] == 0))  # axis-aligned, no diagonals
        assert np.all(np.abs(step).sum(axis=1) > 0)
        # only corners: no point in the middle of a straight run
        turn = cross(np.roll(loop, 1, axis=0), loop, np.roll(loop, -1, axis=0))
        assert np.all(turn != 0)
    check_polygons(regions)


def test_larger_tolerance_gives_fewer_points_and_stays_simple():
    counts = []
    for tolerance in (0.0, 0.5, 1.0, 2.0, 4.0, 8.0):
        regions = outline("armadillo", tolerance=tolerance)
        check_polygons(regions)
        counts.append(sum(len(o) + sum(len(h) for h in hs) for o, hs in regions))
    assert counts == sorted(counts, reverse=True) and counts[-1] < counts[0] / 10


def test_simplified_outline_stays_within_tolerance_of_the_staircase():
    exact = outline("bunny", scale=1.0, tolerance=0)[0][0]
    simple = outline("bunny", scale=1.0, tolerance=2.0)[0][0]
    # every staircase corner within 2 px of some segment of the simplified loop
    a, b = simple, np.roll(simple, -1, axis=0)
    ab = b - a
    t = np.clip(np.einsum("pkd,kd->pk", exact[:, None] - a[None], ab) / np.einsum("kd,kd->k", ab, ab), 0, 1)
    d = np.hypot(*(exact[:, None] - a[None] - t[..., None] * ab[None]).transpose(2, 0, 1)).min(axis=1)
    assert d.max() <= 2.0 + 1e-9


def test_two_blobs_are_two_regions():
    pic = np.zeros((40, 80), np.uint8)
    pic[5:35, 5:35] = 200
    pic[10:30, 50:75] = 200
    regions = outline(pic, scale=0.01)
    assert len(regions) == 2
    assert sorted(round(region_area(o, h) / 1e-4) for o, h in regions) == [500, 900]
    check_polygons(regions)


def test_island_in_a_hole_is_a_region_of_its_own():
    mask = ring_mask()
    yy, xx = np.mgrid[0:120, 0:120] + 0.5
    mask |= (xx - 60) ** 2 + (yy - 60) ** 2 < 10**2
    regions = outline(mask, scale=0.01)
    assert len(regions) == 2
    assert sorted(len(h) for _, h in regions) == [0, 1]  # three loops
    ring, island = sorted(regions, key=lambda r: -len(r[1]))
    assert inside(island[0], ring[1][0]).all()  # the island sits in the ring's hole
    check_polygons(regions)


def test_builtin_donut_keeps_its_hole():
    regions = outline("donut")
    assert len(regions) == 1 and len(regions[0][1]) == 1
    check_polygons(regions)


@pytest.mark.parametrize("source", ["bunny", "donut", "ellipse and square"])
def test_outline_lies_on_the_mesh_of_the_same_picture(source):
    scale = 0.01
    if source == "ellipse and square":
        yy, xx = np.mgrid[0:100, 0:120] + 0.5
        source = np.zeros((100, 120, 3), np.uint8)
        source[(xx - 50) ** 2 / 900 + (yy - 40) ** 2 / 400 < 1] = (200, 80, 40)
        source[70:90, 90:110] = (200, 80, 40)
    mesh = deforma.mesh.from_image(source, scale=scale, resolution=8, edge_step=4)
    regions = outline(source, scale=scale)
    points = np.concatenate([o for o, _ in regions])
    assert np.abs(points.min(axis=0) - mesh.vertices.min(axis=0)).max() <= scale
    assert np.abs(points.max(axis=0) - mesh.vertices.max(axis=0)).max() <= scale
    area_outline = sum(region_area(o, h) for o, h in regions)
    assert area_outline == pytest.approx(mesh.area, rel=0.02)


def test_white_background_and_transparency():
    black = outline(square_picture())
    white = np.full((40, 60, 3), 255, np.uint8)
    white[10:30, 10:50] = (30, 20, 60)
    [(outer, _)] = outline(white, background="white")
    np.testing.assert_allclose(np.sort(outer, axis=0), np.sort(black[0][0], axis=0))
    rgba = np.zeros((40, 60, 4), np.uint8)  # white everywhere, alpha decides
    rgba[..., :3] = 255
    rgba[10:30, 10:50, 3] = 255
    [(outer, _)] = outline(rgba, background="white")
    np.testing.assert_allclose(np.sort(outer, axis=0), np.sort(black[0][0], axis=0))


def test_min_area_drops_small_loops():
    mask = np.zeros((40, 60), bool)
    mask[5:35, 5:35] = True
    mask[18:22, 18:22] = False  # a 16 px hole
    mask[10:14, 45:50] = True  # a 20 px blob
    assert [len(h) for _, h in outline(mask)] == [1, 0]
    assert [len(h) for _, h in outline(mask, min_area=18)] == [0, 0]
    assert [len(h) for _, h in outline(mask, min_area=25)] == [0]


def test_a_crossing_simplification_is_undone():
    # a comb: narrow gaps between long teeth; a coarse tolerance would join the teeth tips
    # across the gaps and the base corners, crossing the loop
    mask = np.zeros((60, 80), bool)
    mask[45:55, 5:75] = True
    for c in range(5, 75, 6):
        mask[5:45, c : c + 4] = True
    for tolerance in (3.0, 10.0, 40.0):
        regions = outline(mask, scale=1.0, tolerance=tolerance)
        assert len(regions) == 1
        check_polygons(regions)
    assert region_area(*outline(mask, scale=1.0, tolerance=0)[0]) == mask.sum()


def test_simplify_loop_on_a_circle():
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    circle = np.c_[np.cos(t), np.sin(t)] * 100
    kept = simplify_loop(circle, 1.0)
    assert 10 < len(kept) < 40
    assert len(simplify_loop(circle, 0.0)) == 400  # no three points in line


def one_line_value_error(match, *args, **kwargs):
    with pytest.raises(ValueError, match=match) as info:
        outline(*args, **kwargs)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"tolerance": -1.0}, r"tolerance must be >= 0 px"),
        ({"tolerance": float("nan")}, r"tolerance must be finite"),
        ({"tolerance": float("inf")}, r"tolerance must be finite"),
        ({"tolerance": "one"}, r"tolerance must be a number"),
        ({"scale": 0.0}, r"scale must be > 0 m per pixel"),
        ({"scale": -0.01}, r"scale must be > 0"),
        ({"min_area": -1}, r"min_area must be >= 0 square px"),
        ({"background": "pink"}, r"background must be"),
        ({"threshold": 1.5}, r"threshold must be a number in \[0, 1\)"),
    ],
)
def test_bad_parameters(kwargs, match):
    one_line_value_error(match, square_picture(), **kwargs)


def test_bad_pictures():
    one_line_value_error(r"has no foreground", np.zeros((20, 20), np.uint8))
    one_line_value_error(r"whole picture is foreground", np.full((20, 20), 255, np.uint8))
    one_line_value_error(r"only specks", np.eye(20, dtype=np.uint8) * 255)
    one_line_value_error(r"source must be", object())
    one_line_value_error(r"no foreground", np.zeros((20, 20, 4), np.uint8))  # all transparent


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.integers(0, 2**32 - 1),
    st.integers(2, 8),
    st.floats(0.1, 0.7),
    st.sampled_from([0.0, 0.5, 1.0, 2.5, 6.0]),
)
def test_random_block_pictures_give_simple_nested_polygons(seed, blocks, fill, tolerance):
    rng = np.random.default_rng(seed)
    cells = rng.random((blocks, blocks)) < fill
    mask = np.kron(cells, np.ones((3, 3), bool))  # 3 x 3 px blocks: 9 px, never specks
    mask = np.pad(mask, 2)
    if not mask.any():
        one_line_value_error(r"no foreground", mask)
        return
    regions = outline(mask, scale=1.0, tolerance=tolerance, min_area=0)
    check_polygons(regions)
    # one region per side-connected piece, as the mesher sees them
    _, pieces = ndimage.label(mask)
    assert len(regions) == pieces
    if tolerance == 0:
        assert sum(region_area(o, h) for o, h in regions) == pytest.approx(mask.sum(), abs=0.25 * blocks**2)

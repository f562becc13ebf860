"""Every collider shape drawn where it is: filled, bordered, holes open, moving ones followed."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import deforma
from deforma.mesh import picture
from deforma.render import Camera, Renderer
from deforma.render.fill import fill_triangles

RED = (1.0, 0.0, 0.0)
CUP = np.array([(-0.6, -0.3), (0.6, -0.3), (0.6, 0.3), (0.5, 0.3), (0.5, -0.2), (-0.5, -0.2), (-0.5, 0.3),
                (-0.6, 0.3)])


def star_with_hole():
    t = np.linspace(0, 2 * np.pi, 120, endpoint=False)
    r = 3 + np.sin(7 * t)
    hole = 0.5 * np.c_[np.cos(t[::4]), np.sin(t[::4])]
    return [np.c_[r * np.cos(t), r * np.sin(t)], hole[::-1]]


@pytest.mark.parametrize("loops", [
    [[(0, 0), (3, 0), (3, 3), (0, 3)], [(1, 1), (2, 1), (2, 2), (1, 2)]],            # a square ring
    [CUP],                                                                             # concave
    [[(0, 0), (10, 0), (10, 3)] + [p for k in range(9, 0, -1)                          # a comb
                                   for p in ((k + 0.5, 3), (k + 0.5, 1), (k, 1), (k, 3))] + [(0, 3)]],
    [[(0, 0), (10, 0), (10, 10), (0, 10)]]                                             # 16 holes
    + [[(x + 0.2, y + 0.2), (x + 0.2, y + 0.8), (x + 0.8, y + 0.8), (x + 0.8, y + 0.2)]
       for x in range(1, 9, 2) for y in range(1, 9, 2)],
    [[(0, 0), (10, 0), (10, 10), (0, 10)]]                                             # holes in a row
    + [[(x + 0.2, 1.2), (x + 0.5, 1.8), (x + 0.8, 1.2)] for x in range(1, 9)],
    star_with_hole(),
])
def test_fill_triangles_cover_the_polygon_exactly(loops):
    poly = deforma.Polygon(loops[0], holes=loops[1:])
    tris = fill_triangles(loops)
    corners = np.concatenate([np.asarray(p, float) for p in loops])[tris]
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    assert (area > 0).all()                                   # counter-clockwise, none flat
    # even-odd: a loop inside an odd number of others is a hole, else it bounds solid (an island)
    rings = [deforma.Polygon(p) for p in loops]
    depth = [sum(bool(r.contains([p[0]])[0]) for j, r in enumerate(rings) if j != k) for k, p in enumerate(loops)]
    solid = sum(r.area * (-1) ** d for r, d in zip(rings, depth))
    assert area.sum() == pytest.approx(solid, rel=1e-9)       # no gap, no overlap
    assert poly.contains(corners.mean(axis=1)).all()          # none in a hole or a notch


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(0.3, 3.0), min_size=3, max_size=40), st.booleans())
def test_fill_triangles_of_random_star_polygons(radii, hole):
    # star-shaped about the origin: simple whatever the radii; a hole inside the inner radius
    t = np.linspace(0, 2 * np.pi, len(radii), endpoint=False)
    outer = np.c_[np.cos(t), np.sin(t)] * np.array(radii)[:, None]
    loops = [outer] + ([0.2 * np.c_[np.cos(-t[:6]), np.sin(-t[:6])]] if hole and len(radii) >= 6 else [])
    try:
        poly = deforma.Polygon(loops[0], holes=loops[1:])
    except ValueError:  # collinear or crossing after rounding: not a polygon to fill
        return
    tris = fill_triangles(loops)
    corners = np.concatenate(loops)[tris]
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    assert (area > 0).all() and area.sum() == pytest.approx(poly.area, rel=1e-9)


def every_shape():
    """One collider of each shape (two polygons: a concave cup and a square ring)."""
    return [
        deforma.Rect((-3.0, 1.0), (2.0, 0.4), 20.0),
        deforma.Circle((0.0, 1.2), 0.5),
        deforma.Polygon(CUP * 2 + (2.8, 1.0)),
        deforma.Polygon([(-3.8, -1.8), (-1.8, -1.8), (-1.8, 0.2), (-3.8, 0.2)],
                        holes=[[(-3.3, -1.3), (-2.3, -1.3), (-2.3, -0.3), (-3.3, -0.3)]]),
        deforma.Segment((0.0, -1.0), (2.0, -0.5), radius=0.2),
        deforma.Segment((0.0, -1.7), (3.0, -1.5)),     # a wire
    ]


@pytest.fixture
def renderer(gl_ctx):
    # 400 x 200 pixels showing x in [-4, 4], y in [-2, 2]: 50 pixels per metre
    r = Renderer(gl_ctx, (400, 200), samples=0, camera=Camera((0, 0), (8, 4)))
    yield r
    r.release()


def is_red(img):
    """The fill (1, 0, 0) times its shading, 0.92 to 1."""
    return (img[..., 0] > 225) & (img[..., 1] < 10) & (img[..., 2] < 10)


def pixel(renderer, point):
    c, r = renderer.camera.world_to_pixel(point, renderer.size)
    return int(r), int(c)


def test_every_shape_is_drawn_filled_with_its_holes_open(renderer):
    renderer.render()
    empty = renderer.read().astype(int)
    colliders = every_shape()
    renderer.render(colliders=colliders, collider_colors=[RED] * len(colliders))
    img = renderer.read().astype(int)
    red = is_red(img)
    changed = np.abs(img - empty).sum(-1) > 30
    inside = [(-3.0, 1.0), (-2.4, 1.2), (0.0, 1.4), (0.3, 1.0), (2.8, 0.5), (1.7, 1.2), (3.9, 1.3),
              (-3.6, -1.0), (-2.05, -1.0), (-3.0, -1.6), (1.0, -0.75), (0.05, -1.0)]
    for p in inside:
        assert red[pixel(renderer, p)], p
    # background in the ring's hole and in the cup's notch, and beside everything
    for p in [(-2.8, -0.8), (-3.1, -0.5), (2.8, 1.2), (2.0, 1.4), (3.5, 1.2), (0.0, 0.5), (1.0, 0.0)]:
        assert not changed[pixel(renderer, p)], p
    # the wire has no inside but is a line of a few pixels
    mid = pixel(renderer, (1.5, -1.6))
    column = changed[mid[0] - 6: mid[0] + 7, mid[1]]
    assert 2 <= column.sum() <= 6
    # the drawn area of the square ring is its area: (4 - 1) m^2 * 2500 px/m^2
    r0, c0 = pixel(renderer, (-3.9, 0.3))
    r1, c1 = pixel(renderer, (-1.7, -1.9))
    assert abs(changed[r0:r1, c0:c1].sum() - 3 * 2500) < 200
    # a dark border inside the boundary: the ring's left side, 1 px in
    r, c = pixel(renderer, (-3.8 + 0.01, -1.0))
    assert img[r, c].sum() < 250 and not red[r, c]


def test_a_moving_collider_is_drawn_at_its_new_pose(renderer):
    world = deforma.World(gravity=(0, 0))
    # a body far out of view: a world without bodies does not step its colliders (yet)
    world.add_body(deforma.mesh.box(((0, 0), (0.2, 0), (0.2, 0.2), (0, 0.2)), detail=0), position=(0, 50))
    slab = world.add_collider(deforma.Rect((-2.5, 0.0), (1.0, 0.4), velocity=(4.0, 0.0)))
    arm = world.add_collider(deforma.Segment((1.5, 0.0), (3.5, 0.0), radius=0.1, angular_velocity=180.0))
    uploads = []
    original = renderer._upload_colliders
    renderer._upload_colliders = lambda *a: (uploads.append(1), original(*a))

    def red_at(point):
        renderer.render(colliders=world.colliders, collider_colors=[RED, RED])
        return bool(is_red(renderer.read().astype(int))[pixel(renderer, point)])

    assert red_at((-2.5, 0.0)) and red_at((3.2, 0.0)) and not red_at((2.5, 0.8))
    assert len(uploads) == 1                  # nothing changed: the buffer was not written again
    for _ in range(round(0.5 / world.dt)):    # half a second: 2 m to the right, a quarter turn
        world.step()
    assert slab.center[0] == pytest.approx(-0.5) and arm.angle == pytest.approx(90.0)
    assert red_at((-0.5, 0.0)) and not red_at((-2.5, 0.0))
    assert red_at((2.5, 0.8)) and not red_at((3.2, 0.0))
    assert len(uploads) == 2


def test_a_collider_changed_in_place_is_redrawn(renderer):
    c = deforma.Circle((0.0, 0.0), 0.3)

    def red_at(point):
        renderer.render(colliders=[c], collider_colors=[RED])
        return bool(is_red(renderer.read().astype(int))[pixel(renderer, point)])

    assert not red_at((0.0, 0.6))
    c.radius = 0.8
    assert red_at((0.0, 0.6))


def test_world_picture_shows_a_circle_and_a_polygon_with_a_hole():
    world = deforma.World()
    world.add_collider(deforma.Circle((3.0, 0.0), 1.0))
    world.add_collider(deforma.Polygon([(-2, -2), (2, -2), (2, 2), (-2, 2)],
                                       holes=[[(-1, -1), (1, -1), (1, 1), (-1, 1)]]))
    lo, hi = picture.content_bounds(world)
    np.testing.assert_allclose(lo, [-2, -2], atol=1e-9)
    np.testing.assert_allclose(hi, [4, 2], atol=1e-9)
    img = np.asarray(picture.world_picture(world, size=300)).astype(int)
    h, w = img.shape[:2]

    def at(x, y):  # metres to the picture's pixels (the content fills it, 4% margin)
        pad = 0.04 * 300
        scale = (300 - 2 * pad) / 6.0
        return img[int(round(pad + (2 - y) * scale)), int(round(pad + (x + 2) * scale))]

    def near(rgb, colour, tol=12):
        return np.abs(rgb - colour).max() <= tol

    assert (h, w) == (208, 300)
    for p in [(3.0, 0.0), (3.5, 0.5), (-1.5, 0.0), (0.0, 1.5), (1.6, -1.6)]:
        assert near(at(*p), picture.COLLIDER_FILL), p
    for p in [(0.0, 0.0), (0.5, -0.5), (3.9, 1.8), (2.3, 1.5)]:     # the hole, and beside the circle
        assert near(at(*p), picture.BACKGROUND), p

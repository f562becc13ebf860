"""Colliders of every shape, fixed and moving, under all three integrators.

The known answers: a box on a conveyor with enough static friction moves at the conveyor's
speed (frictionless, it stays); a block on a tilted capsule slides at ``g (sin a - mu cos a)``;
bodies dropped on a circle, into a concave cup and onto a wire rest on them with no vertex
inside at any step; a paddle turning at 180 degrees per second throws what it hits at about
its tip speed; a ring picture's polygons keep the ring's area and hole.
"""

import math

import numpy as np
import pytest

import deforma
from physics_meshes import grid_mesh

INTEGRATORS = ["symplectic-euler", "implicit-euler", "xpbd"]


def world(name, **kw):
    dt = 1 / 600 if name == "symplectic-euler" else 1 / 120
    return deforma.World(dt=dt, integrator=name, stiffness=2000.0, damping=1.0, **kw)


def assert_never_inside(w, steps, *, every=1):
    for k in range(steps):
        w.step()
        if k % every == 0:
            for c in w.colliders:
                for b in w.bodies:
                    inside = c.contains(b.positions)
                    assert not inside.any(), (k, c, np.flatnonzero(inside)[:5].tolist())


@pytest.mark.parametrize("name", INTEGRATORS)
@pytest.mark.parametrize("mu", [0.8, 0.0])
def test_a_conveyor_carries_a_box_that_grips_it_and_not_one_that_does_not(name, mu):
    w = world(name)
    belt = w.add_collider(deforma.Rect((0, -0.25), (40, 0.5), 0.0, velocity=(0.5, 0.0), friction=mu,
                                       static_friction=mu))
    box = w.add_body(grid_mesh(0.4, 0.2, 5, 3), position=(0, 0.1001))
    for _ in range(int(0.5 / w.dt)):  # settle on the belt first: it picks the box up
        w.step()
    x0, t0 = box.center_of_mass[0], w.time
    for _ in range(int(2.0 / w.dt)):
        w.step()
    speed = (box.center_of_mass[0] - x0) / (w.time - t0)
    if mu:
        assert abs(speed - 0.5) < 0.025, speed  # within 5% of the belt's speed
    else:
        assert abs(speed) < 0.01, speed
    assert not belt.contains(box.positions).any()
    assert belt.center[0] == pytest.approx(0.5 * w.time)  # the belt itself moved on


@pytest.mark.parametrize("name", INTEGRATORS)
def test_a_block_on_a_tilted_capsule_slides_at_the_coulomb_rate(name):
    angle = 30.0
    mu = 0.3
    w = world(name, friction=mu, static_friction=0.4)
    t = math.radians(angle)
    down = np.array([math.cos(t), math.sin(t)])
    ramp = w.add_collider(deforma.Segment(-10 * down, 10 * down, radius=0.1))
    body = w.add_body(grid_mesh(0.3, 0.1, 4, 2))
    # put it on the capsule's top face, turned with it
    p = body.positions - body.positions.mean(axis=0)
    rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    normal = np.array([-math.sin(t), math.cos(t)])
    body.positions = p @ rot.T + (0.1 + 0.05 + 1e-4) * normal
    for _ in range(int(0.3 / w.dt)):
        w.step()
    v0, t0 = body.velocities.mean(axis=0) @ down, w.time
    for _ in range(int(0.5 / w.dt)):
        w.step()
    accel = (body.velocities.mean(axis=0) @ down - v0) / (w.time - t0)
    exact = -9.81 * (math.sin(t) - mu * math.cos(t))  # down the slope is -down
    assert accel == pytest.approx(exact, rel=0.03)
    assert not ramp.contains(body.positions).any()


@pytest.mark.parametrize("name", INTEGRATORS)
def test_a_body_drapes_over_a_circle_and_never_enters_it(name):
    w = world(name)
    w.add_collider(deforma.Circle((0, 0), 0.4))
    body = w.add_body(grid_mesh(1.2, 0.1, 13, 2), position=(0.0, 0.8))
    assert_never_inside(w, int(1.5 / w.dt))
    p = body.positions
    assert p[:, 1].min() < 0.3  # its ends hang down
    assert 0.399 < np.hypot(*p.T).min() < 0.42  # and it lies on the circle


@pytest.mark.parametrize("name", INTEGRATORS)
def test_a_concave_cup_holds_a_body(name):
    w = world(name)
    w.add_collider(deforma.Polygon([[-1, 0], [1, 0], [1, 1], [0.8, 1], [0.8, 0.2], [-0.8, 0.2], [-0.8, 1],
                                          [-1, 1]]))
    body = w.add_body(grid_mesh(0.5, 0.3, 6, 4), position=(0.1, 1.2))
    body.velocities = (0.5, 0.0)
    assert_never_inside(w, int(2.0 / w.dt))
    c = body.center_of_mass
    assert -0.8 < c[0] < 0.8 and 0.2 < c[1] < 0.5  # in the cup, on its floor


@pytest.mark.parametrize("name", INTEGRATORS)
def test_a_body_rests_on_a_wire(name):
    w = world(name)
    wire = w.add_collider(deforma.Segment((-1, 0), (1, 0)))  # radius 0: no inside, but not to be crossed
    body = w.add_body(grid_mesh(0.4, 0.2, 5, 3), position=(0, 0.5))
    for _ in range(int(1.5 / w.dt)):
        w.step()
        assert body.positions[:, 1].min() > -1e-6
    assert abs(body.center_of_mass[1] - 0.1) < 0.03
    assert np.abs(body.velocities).max() < 0.1  # resting (sliding slowly, as on a floor: 0.05 m/s)
    assert wire.length == 2.0


@pytest.mark.parametrize("name", INTEGRATORS)
def test_a_turning_paddle_throws_what_it_hits(name):
    w = world(name, gravity=(0.0, 0.0))
    paddle = w.add_collider(deforma.Segment((-0.6, 0), (0.6, 0), radius=0.05, angular_velocity=180.0))
    body = w.add_body(grid_mesh(0.2, 0.2, 3, 3), position=(0.45, 0.3))
    assert_never_inside(w, int(0.6 / w.dt))
    tip = math.radians(180.0) * 0.6  # 1.9 m/s
    speed = np.hypot(*body.velocities.mean(axis=0))
    assert 0.4 * tip < speed < 2.0 * tip, speed
    assert paddle.angle == pytest.approx(180.0 * w.time)


def test_colliders_from_a_ring_picture_keep_its_area_and_hole():
    yy, xx = np.mgrid[:200, :200]
    r = np.hypot(xx - 99.5, yy - 99.5)
    picture = ((r < 80) & (r > 40)).astype(np.uint8) * 255
    (ring,) = deforma.colliders_from_image(picture, scale=0.01)
    assert len(ring.holes) == 1
    assert ring.area == pytest.approx(picture.astype(bool).sum() * 1e-4, rel=0.03)
    assert ring.contains([[0.6, 0.0]])[0] and not ring.contains([[0.0, 0.0]])[0]  # material; the hole
    w = deforma.World(dt=1 / 600)
    w.add_collider(ring)
    body = w.add_body(grid_mesh(0.3, 0.3, 4, 4), position=(0.0, 0.0))  # dropped inside the hole
    assert_never_inside(w, 300, every=5)
    assert body.positions[:, 1].min() > -0.41  # held by the hole's rim (radius 0.4 m)


def test_a_moving_collider_that_traps_a_body_is_reported_and_everything_is_put_back():
    w = deforma.World(dt=1 / 600)
    w.add_collider(deforma.Rect((0, -0.5), (4, 1.0), 0.0))
    body = w.add_body(grid_mesh(0.4, 0.2, 5, 3), position=(0, 0.1001))
    lid = w.add_collider(deforma.Rect((0, 0.3), (4, 0.1), 0.0, velocity=(0.0, -3.0)))  # a press
    with pytest.raises(deforma.SimulationUnstable, match="trapped inside collider 1"):
        for _ in range(200):  # it reaches the floor after 0.083 s (50 steps)
            before, center = body.positions.copy(), lid.center
            w.step()
    assert np.array_equal(body.positions, before) and lid.center == center
    assert 0.0 < center[1] < 0.3


def test_moving_colliders_move_in_a_world_without_bodies():
    w = deforma.World(dt=0.01)
    c = w.add_collider(deforma.Circle((0, 0), 1.0, velocity=(1.0, 0.0), angular_velocity=90.0))
    for _ in range(100):
        w.step()
    assert c.center == pytest.approx((1.0, 0.0)) and c.angle == pytest.approx(90.0)


def test_colliders_refuse_bad_input_in_one_line():
    bad = [
        lambda: deforma.Circle((0, 0), 0.0),
        lambda: deforma.Circle((0, 0), -1.0),
        lambda: deforma.Polygon([[0, 0], [1, 0]]),
        lambda: deforma.Polygon([[0, 0], [1, 1], [1, 0], [0, 1]]),  # a bow tie
        lambda: deforma.Polygon([[0, 0], [1, 0], [2, 0]]),  # no area
        lambda: deforma.Polygon([[0, 0], [1, 0], [0, 1]], holes=[[[5, 5], [6, 5], [5, 6]]]),
        lambda: deforma.Polygon([[0, 0], [9, 0], [9, 9], [0, 9]],  # an island in a hole
                                holes=[[[1, 1], [8, 1], [8, 8], [1, 8]], [[2, 2], [7, 2], [7, 7], [2, 7]]]),
        lambda: deforma.Segment((1, 1), (1, 1)),
        lambda: deforma.Segment((0, 0), (1, 0), radius=-0.1),
        lambda: deforma.Rect((0, 0), (1, 1), velocity=(np.nan, 0)),
        lambda: deforma.Rect((0, 0), (1, 1), angular_velocity=np.inf),
        lambda: deforma.colliders_from_image(np.zeros((20, 20), np.uint8), scale=0.01),
    ]
    for f in bad:
        with pytest.raises(ValueError) as info:
            f()
        assert "\n" not in str(info.value)
    assert deforma.Segment((1, 1), (1, 1), radius=0.2).contains([[1.1, 1.0]])[0]  # a disc
    r = deforma.Rect((0, 0), (1, 1))
    with pytest.raises(ValueError, match="velocity"):
        r.velocity = (0, float("inf"))
    assert r.velocity == (0.0, 0.0)

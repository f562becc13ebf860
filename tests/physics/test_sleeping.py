"""Sleeping (World(sleep=True), the default; deforma.physics.sleeping): islands at rest stop being stepped,
and wake when disturbed, moving exactly as they would have without sleep."""

import copy

import numpy as np
import pytest

import deforma
from deforma.physics.sleeping import SLEEP_TIME

WOOD = deforma.Material("rigid", density=600.0)


def _box(size=0.3, detail=2):
    return deforma.mesh.box(((0, 0), (size, 0), (size, size), (0, size)), detail=detail, edges=True)


def _stack(n=5, sleep=True, material=WOOD):
    w = deforma.World(sleep=sleep)
    w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0.0))
    for k in range(n):
        w.add_body(_box(), position=(0.02 * (k % 2), 0.151 + 0.301 * k), material=material)
    return w


def _run(w, seconds):
    for _ in range(round(seconds / w.dt)):
        w.step()


def test_a_stack_of_ten_rigid_boxes_falls_asleep_where_it_settled_and_costs_no_integration():
    w = _stack(10)
    _run(w, 3.0)
    settled = [b.center_of_mass.copy() for b in w.bodies]
    assert all(b.sleeping for b in w.bodies)
    assert all(np.abs(b.velocities).max() == 0.0 for b in w.bodies)
    sweeps = w.integrator_stats["iterations"]
    _run(w, 10.0)
    assert w.integrator_stats["iterations"] == sweeps  # asleep: not one sweep
    assert all(b.sleeping for b in w.bodies)
    assert max(np.abs(b.center_of_mass - c).max() for b, c in zip(w.bodies, settled)) == 0.0


def test_a_woken_island_moves_exactly_as_without_sleep():
    w = _stack(5)
    _run(w, 2.0)
    assert all(b.sleeping for b in w.bodies)
    twin = copy.deepcopy(w)
    twin.sleep = False
    for world in (w, twin):
        top = world.bodies[4]
        top.apply_impulse((0.8 * top.vertex_masses.sum(), 0.0))  # 0.8 m/s sideways: it slides off
    assert not any(b.sleeping for b in w.bodies)  # the whole island woke
    for step in range(60):
        w.step()
        twin.step()
        if any(b.sleeping for b in w.bodies):
            break
        np.testing.assert_allclose(w.state.x, twin.state.x, rtol=0, atol=1e-12)
        np.testing.assert_allclose(w.state.v, twin.state.v, rtol=0, atol=1e-12)
    assert step == 59  # it moved the whole second


def test_a_copy_of_a_sleeping_world_sleeps_on_as_it_does():
    w = _stack(3)
    _run(w, 2.0)
    twin = copy.deepcopy(w)
    _run(w, 1.0)
    _run(twin, 1.0)
    assert all(b.sleeping for b in w.bodies) and all(b.sleeping for b in twin.bodies)
    assert np.array_equal(w.state.x, twin.state.x)


def test_a_body_landing_on_a_sleeping_stack_wakes_it_and_all_sleep_again():
    w = _stack(3)
    _run(w, 2.0)
    assert all(b.sleeping for b in w.bodies)
    falling = w.add_body(_box(0.2), position=(0.05, 3.0), material=WOOD)
    _run(w, 0.6)  # adding a body wakes every island; they sleep again while it falls
    assert [b.sleeping for b in w.bodies] == [True, True, True, False]
    woke = False
    for _ in range(120):
        w.step()
        woke |= not w.bodies[2].sleeping
    top = w.bodies[2].positions[:, 1].max()
    assert woke and falling.center_of_mass[1] == pytest.approx(top + 0.1, abs=2e-3)
    _run(w, 5.0)  # the stack rocks at up to 5 cm/s for about 4 s after the 2 m drop
    assert all(b.sleeping for b in w.bodies)


def test_what_wakes_a_sleeping_body():
    w = _stack(2)
    floor = w.colliders[0]
    _run(w, 2.0)
    low, top = w.bodies

    def asleep():
        _run(w, 1.0)
        return low.sleeping and top.sleeping

    assert asleep()
    top.apply_force((0.0, 10.0))
    assert not low.sleeping and not top.sleeping  # the island wakes
    assert asleep()
    low.sleeping = False
    assert not top.sleeping
    assert asleep()
    w.gravity = (0.0, -9.0)
    w.step()
    assert not top.sleeping or top._still < SLEEP_TIME
    assert asleep()
    g = w.grab(top.center_of_mass)
    assert not top.sleeping
    _run(w, 1.0)
    assert not top.sleeping  # held by the mouse: kept awake
    w.release(g)
    assert asleep()
    floor.center = (0.0, -0.5)  # a still collider set: every island wakes
    w.step()
    assert not low.sleeping or low._still < SLEEP_TIME
    top.sleeping = True  # put to sleep now, with its island
    assert low.sleeping and top.sleeping and np.abs(w.state.v).max() == 0.0


def test_a_body_on_a_moving_collider_stays_awake():
    w = deforma.World(sleep=True)
    belt = w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0.0, velocity=(0.0, 0.0)))
    box = w.add_body(_box(), position=(0, 0.151), material=WOOD)
    _run(w, 1.5)
    assert box.sleeping
    belt.velocity = (0.0, 1e-3)  # rising 1 mm/s: slower than the sleep speed, still it moves
    _run(w, 2.0)
    assert not box.sleeping and box.center_of_mass[1] == pytest.approx(0.150 + 2e-3, abs=1e-5)


def test_sleep_on_by_default_and_from_scene_files(tmp_path):
    assert deforma.World().sleep
    with pytest.raises(ValueError, match="sleep"):
        deforma.World(sleep="yes")
    path = tmp_path / "s.toml"
    for sleep in (True, False):
        deforma.save_scene(_stack(2, sleep=sleep), path)
        assert deforma.load_scene(path).sleep is sleep
    path.write_text('[[body]]\nshape = "box"\ncorners = [[0, 0], [1, 0], [1, 1], [0, 1]]\n')
    assert deforma.load_scene(path).sleep  # a scene that does not say sleeps


def test_a_default_world_puts_a_jelly_on_the_floor_to_sleep():
    w = deforma.World()
    w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0.0))
    body = w.add_body(_box(0.4, 4), position=(0.0, 0.25), material=deforma.Material.preset("jelly"))
    _run(w, 4.0)
    assert body.sleeping
    assert np.all(body.velocities == 0.0)


def test_a_body_drifting_slowly_through_space_keeps_its_momentum():
    # nothing holds it (no collider, pin or joint to the world): it never sleeps, where a
    # slow island would stop under Box2D's rule
    w = deforma.World(gravity=(0.0, 0.0))
    body = w.add_body(_box(), position=(0.0, 0.0), material=WOOD)
    body.velocities = np.tile([2e-3, -1e-3], (body.n_vertices, 1))  # 2.2 mm/s, below the sleep speed
    _run(w, 2.0)
    assert not body.sleeping
    np.testing.assert_allclose(body.velocities.mean(axis=0), [2e-3, -1e-3], rtol=1e-9)
    # pinned, a body at rest falls asleep even in space
    still = w.add_body(_box(), position=(2.0, 0.0), material=WOOD)
    still.pin([0])
    _run(w, 1.0)
    assert still.sleeping and not body.sleeping


def _step_until_touching(w, a, b, steps, failure):
    """Step ``w`` until ``a`` and ``b`` (bodies or a collider) touch; fail with ``failure`` if
    they do not within ``steps`` steps."""
    for _ in range(steps):
        w.step()
        if w.contacts_between(a, b) is not None:
            return
    pytest.fail(failure)


def test_a_sleeping_body_is_awake_for_the_step_a_thrown_body_reaches_it():
    # woken only after the step of the impact (by its contact pairs), the sleeping box met
    # the thrown one held, as a wall: the cards scene's wheel bounced off the house of cards
    w = _stack(1)
    _run(w, 1.0)
    low = w.bodies[0]
    top = w.add_body(_box(), position=(0.0, 1.0), material=WOOD)
    w.step()  # (a body added wakes every island at the next step)
    low.sleeping = True
    top.velocities = np.tile([0.0, -8.0], (top.n_vertices, 1))  # 13 cm a step: past any contact margin
    _step_until_touching(w, low, top, 120, "the thrown box never reached the one below")
    # it moved in the step of the impact: held (asleep), its velocities would stay exactly 0
    assert np.abs(low.velocities).max() > 0.0


def test_a_sleeping_body_is_awake_for_the_step_a_moving_collider_reaches_it():
    w = _stack(1)
    box = w.bodies[0]
    paddle = w.add_collider(deforma.Rect((-1.0, 0.15), (0.2, 0.1), 0.0))
    _run(w, 1.0)
    assert box.sleeping
    paddle.velocity = (6.0, 0.0)  # 10 cm a step, towards the box 0.85 m away
    w.step()  # (a collider's change of motion wakes every island at the next step)
    box.sleeping = True
    _step_until_touching(w, box, paddle, 60, "the paddle never reached the box")
    assert np.abs(box.velocities).max() > 0.0  # held (asleep), they would stay exactly 0

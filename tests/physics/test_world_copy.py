"""copy.deepcopy(world): an independent world that steps bit for bit as the original would."""

import copy
import math

import numpy as np
import pytest

import deforma

INTEGRATORS = ["symplectic-euler", "implicit-euler", "xpbd"]


def busy_world(integrator):
    """Two soft bodies (springs, and a Neo-Hookean one on top) on a tilted floor, a moving
    collider, a pinned vertex and a held grab: every kind of state a step carries."""
    w = deforma.World(dt=1 / 600, substeps=2, integrator=integrator, friction=0.4, static_friction=0.6)
    w.add_collider(deforma.Rect(center=(0, 0), size=(10, 0.4), angle=5.0))
    w.add_collider(deforma.Rect(center=(3.5, 2.0), size=(0.5, 0.5), angle=0.0, velocity=(-0.4, 0.0),
                                angular_velocity=30.0))
    sheet = deforma.mesh.box(((0, 0), (1, 0), (1, 0.5), (0, 0.5)), detail=2)
    w.add_body(sheet, position=(0.0, 0.56))
    rubber = deforma.Material("neo-hookean", youngs_modulus=1e3, poisson_ratio=0.3, density=1.0, damping=0.01)
    top = w.add_body(sheet, position=(0.2, 1.1), material=rubber)
    w.substeps = max(2, math.ceil(1.2 * w.dt / w.stable_dt(explicit=True)))  # symplectic Euler's limit
    top.pin([0])
    w.drag(w.grab((0.2, 1.2), strength=20.0), (0.5, 1.4))
    return w


def snapshot(w):
    return ([b.positions.copy() for b in w.bodies] + [b.velocities.copy() for b in w.bodies]
            + [np.array([*c.center, c.angle]) for c in w.colliders])


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_copy_steps_exactly_as_the_original(integrator):
    w = busy_world(integrator)
    for _ in range(150):  # into contact with the floor and each other
        w.step()
    if integrator == "implicit-euler":
        assert w._integrator._factor is not None  # the factor that cannot be copied exists
    twin = copy.deepcopy(w)
    assert twin.time == w.time and twin.step_count == w.step_count
    for _ in range(150):
        w.step()
        twin.step()
    assert twin.time == w.time
    for a, b in zip(snapshot(w), snapshot(twin)):
        np.testing.assert_array_equal(a, b)  # bit for bit
    if integrator == "implicit-euler":
        assert twin.integrator_stats == w.integrator_stats


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_copy_is_independent(integrator):
    w = busy_world(integrator)
    for _ in range(20):
        w.step()
    before, t = snapshot(w), w.time
    twin = copy.deepcopy(w)
    assert twin.bodies[0] is not w.bodies[0] and twin.colliders[1] is not w.colliders[1]
    assert twin.bodies[0].mesh is not w.bodies[0].mesh
    for _ in range(30):
        twin.step()
    twin.explode(3.0)
    twin.bodies[0].velocities += 1.0
    twin.colliders[0].angle = 10.0
    assert w.time == t
    for a, b in zip(before, snapshot(w)):
        np.testing.assert_array_equal(a, b)
    assert twin.time > t


def test_a_copy_of_a_copy_before_its_first_solve_still_matches():
    w = busy_world("implicit-euler")
    for _ in range(100):
        w.step()
    twin = copy.deepcopy(copy.deepcopy(w))  # the stand-in factor is copied too
    for _ in range(50):
        w.step()
        twin.step()
    for a, b in zip(snapshot(w), snapshot(twin)):
        np.testing.assert_array_equal(a, b)

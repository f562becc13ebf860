"""Placing a body turned, moving and spinning; reading its velocity, spin and angle; the blast."""

import math

import numpy as np
import pytest

import deforma
from deforma.physics.rigid_motion import fit_angle, linear_and_angular_velocity, rotate

BOX = ((0, 0), (1, 0), (1, 0.5), (0, 0.5))


def test_angle_turns_the_mesh_about_its_box_centre():
    w = deforma.World(gravity=(0, 0))
    m = deforma.mesh.box(BOX, detail=3)
    b = w.add_body(m, position=(2, 3), angle=30)
    expect = rotate(m.vertices - [0.5, 0.25] + [2, 3], math.radians(30), (2.0, 3.0))
    assert np.allclose(b.positions, expect, atol=1e-12)
    assert b.angle == pytest.approx(30.0, abs=1e-9)


def test_velocity_and_spin_set_every_vertex_rigidly():
    w = deforma.World(gravity=(0, 0))
    b = w.add_body(deforma.mesh.box(BOX, detail=3), position=(0, 0), velocity=(1.5, -2), angular_velocity=-90)
    m = b.vertex_masses
    c = b.center_of_mass
    r = b.positions - c
    omega = math.radians(-90)
    expect = np.column_stack([1.5 - omega * r[:, 1], -2 + omega * r[:, 0]])
    assert np.allclose(b.velocities, expect, atol=1e-12)
    vel, spin = linear_and_angular_velocity(b.positions, b.velocities, m)
    assert np.allclose(vel, (1.5, -2)) and spin == pytest.approx(omega)
    assert np.allclose(b.velocity, (1.5, -2)) and b.angular_velocity == pytest.approx(-90)


@pytest.mark.parametrize("integrator", ["symplectic-euler", "implicit-euler", "implicit-bdf2", "xpbd"])
def test_a_thrown_body_keeps_its_momentum_without_gravity(integrator):
    w = deforma.World(gravity=(0, 0), dt=1 / 60, integrator=integrator,
                      material=deforma.Material.preset("rubber"))
    b = w.add_body(deforma.mesh.box(BOX, detail=4), position=(0, 0), velocity=(2, 1), angular_velocity=45)
    p0 = b.vertex_masses @ b.velocities
    for _ in range(30):
        w.step()
    assert np.allclose(b.vertex_masses @ b.velocities, p0, rtol=1e-9, atol=1e-12)
    assert np.allclose(b.center_of_mass, (0.5 * 2, 0.5 * 1), atol=1e-9)


def test_a_spinning_stiff_body_turns_at_its_spin_under_symplectic_euler():
    # a rigid rotor: after 0.5 s at 180 deg/s it has turned 90 degrees (the body stays
    # nearly rigid: rubber at this spin stretches by ~1e-4)
    w = deforma.World(integrator="symplectic-euler", gravity=(0, 0), dt=1 / 60,
                      material=deforma.Material.preset("rubber"))
    b = w.add_body(deforma.mesh.box(BOX, detail=4), position=(0, 0), angle=10, angular_velocity=180)
    for _ in range(30):
        w.step()
    assert b.angle == pytest.approx(100.0, abs=0.5)
    assert b.angular_velocity == pytest.approx(180.0, rel=0.01)


def test_velocity_and_spin_setters_keep_the_rest_of_the_motion():
    w = deforma.World(gravity=(0, 0))
    b = w.add_body(deforma.mesh.box(BOX, detail=3), velocity=(1, 0), angular_velocity=30)
    b.velocity = (0, 2)
    assert np.allclose(b.velocity, (0, 2)) and b.angular_velocity == pytest.approx(30)
    b.angular_velocity = -60
    assert np.allclose(b.velocity, (0, 2)) and b.angular_velocity == pytest.approx(-60)


def test_fit_angle_is_the_rotation_of_a_rigid_motion():
    rng = np.random.default_rng(3)
    rest = rng.normal(size=(20, 2))
    m = rng.uniform(0.5, 2, 20)
    for a in (-3.0, -1.0, 0.0, 0.5, 3.1):
        x = rotate(rest, a, (0.3, -0.2)) + (4, 5)
        assert fit_angle(rest, x, m) == pytest.approx(a, abs=1e-12)


def test_a_blast_with_a_radius_fades_and_stops_at_it():
    w = deforma.World(gravity=(0, 0))
    near = w.add_body(deforma.mesh.box(BOX, detail=2), position=(1, 0))
    far = w.add_body(deforma.mesh.box(BOX, detail=2), position=(6, 0))
    w.explode(3.0, center=(0, 0), radius=3.0)
    d = np.linalg.norm(near.positions, axis=1)
    speed = np.linalg.norm(near.velocities, axis=1)
    assert np.allclose(speed, 3.0 * (1 - d / 3.0))
    # each pushed straight away from the centre
    x, v = near.positions, near.velocities
    assert np.allclose(x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0], 0) and ((x * v).sum(axis=1) > 0).all()
    assert not far.velocities.any()


@pytest.mark.parametrize("kwargs, message", [
    (dict(angle=float("nan")), "angle must be finite"),
    (dict(angle=1e7), "angle must be within"),
    (dict(velocity=(1e9, 0)), "velocity must lie within"),
    (dict(velocity=(1, 2, 3)), "velocity must be a pair"),
    (dict(angular_velocity=1e12), "angular_velocity must be within"),
])
def test_bad_placement_is_refused_in_one_line(kwargs, message):
    w = deforma.World()
    with pytest.raises(ValueError, match=message):
        w.add_body(deforma.mesh.box(BOX, detail=2), **kwargs)
    assert not w.bodies


def test_a_blast_radius_needs_a_centre_and_must_be_positive():
    w = deforma.World()
    w.add_body(deforma.mesh.box(BOX, detail=2))
    with pytest.raises(ValueError, match="radius needs a center"):
        w.explode(1.0, radius=2.0)
    with pytest.raises(ValueError, match="radius must be"):
        w.explode(1.0, center=(0, 0), radius=0.0)


def test_scene_keys_place_the_body(tmp_path):
    p = tmp_path / "spin.toml"
    p.write_text("""
[physics]
gravity = [0, 0]
[[body]]
shape = "box"
corners = [[0, 0], [1, 0], [1, 0.5], [0, 0.5]]
detail = 3
position = [0, 2]
angle = 45
velocity = [1, 2]
angular_velocity = 90
""")
    w = deforma.load_scene(p)
    b = w.bodies[0]
    assert b.angle == pytest.approx(45) and np.allclose(b.velocity, (1, 2))
    assert b.angular_velocity == pytest.approx(90)
    p.write_text(p.read_text().replace("angle = 45", "angle = 1e9"))
    with pytest.raises(deforma.scene.SceneError, match=r"body\[0\]\.angle"):
        deforma.load_scene(p)

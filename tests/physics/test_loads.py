"""Applied forces and impulses (body.apply_force, body.apply_impulse): known answers under
every integrator, and one clear line for every bad value."""

import numpy as np
import pytest

import deforma

INTEGRATORS = ["symplectic-euler", "implicit-euler", "xpbd"]


def free_box(integrator, **kw):
    w = deforma.World(gravity=(0.0, 0.0), dt=1 / 60, integrator=integrator, stiffness=200.0, mass=2.0, **kw)
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=3, edges=True), position=(0, 0))
    if integrator == "symplectic-euler":
        w.substeps = int(np.ceil(w.dt / (0.5 * w.stable_dt())))
    return w, b


def momentum(b):
    return (b.vertex_masses[:, None] * b.velocities).sum(axis=0)


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_force_for_one_step_gives_its_impulse_and_then_stops(integrator):
    w, b = free_box(integrator)
    b.apply_force((3.0, -1.0))  # N, for one step of 1/60 s
    w.step()
    np.testing.assert_allclose(momentum(b), np.array([3.0, -1.0]) / 60, rtol=1e-9, atol=1e-12)
    w.step()  # forgotten after the step that used it
    np.testing.assert_allclose(momentum(b), np.array([3.0, -1.0]) / 60, rtol=1e-9, atol=1e-12)
    # a total force spread by mass accelerates every vertex alike: the body does not deform
    assert np.ptp(b.velocities[:, 0]) < 1e-9


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_forces_on_listed_vertices_add_up_and_turn_the_body(integrator):
    w, b = free_box(integrator)
    x = b.positions
    left, right = int(np.argmin(x[:, 0] + x[:, 1])), int(np.argmax(x[:, 0] + x[:, 1]))
    b.apply_force([[0.0, -2.0], [0.0, 2.0]], indices=[left, right])  # a couple: no net force
    b.apply_force([[0.0, -2.0], [0.0, 2.0]], indices=[left, right])  # calls before a step add up
    w.step()
    np.testing.assert_allclose(momentum(b), 0.0, atol=1e-12)
    c = b.center_of_mass
    r = b.positions - c
    spin = float(np.sum(b.vertex_masses * (r[:, 0] * b.velocities[:, 1] - r[:, 1] * b.velocities[:, 0])))
    assert spin > 0.0  # counter-clockwise


def test_an_impulse_changes_velocities_at_once_and_spares_pins():
    w, b = free_box("implicit-euler")
    b.pin([0])
    b.apply_impulse((0.0, 2.0))  # N s on 2 kg: 1 m/s for every free vertex
    assert b.velocities[0].tolist() == [0.0, 0.0]
    np.testing.assert_allclose(b.velocities[1:, 1], 1.0)
    b.apply_impulse([[0.5, 0.0]], indices=[3])
    assert b.velocities[3, 0] == pytest.approx(0.5 / b.vertex_masses[3])


@pytest.mark.parametrize("call, value, kw, message", [
    ("apply_force", (1.0, 2.0, 3.0), {}, r"force must be a total \(2,\) or one row per vertex"),
    ("apply_force", "up", {}, "force must be numbers in N"),
    ("apply_force", (np.nan, 0.0), {}, "force must be finite"),
    ("apply_force", (1e13, 0.0), {}, r"within \+-1e\+12 N"),
    ("apply_force", [[1.0, 0.0]], {"indices": [0, 1]}, r"\(2, 2\)"),
    ("apply_force", (1.0, 0.0), {"indices": [99]}, "vertex index 99 is out of range"),
    ("apply_impulse", (np.inf, 0.0), {}, "impulse must be finite"),
    ("apply_impulse", (1.0, 0.0), {"indices": [1.5]}, "must be integers"),
])
def test_a_bad_load_is_refused_in_one_line_and_changes_nothing(call, value, kw, message):
    w, b = free_box("implicit-euler")
    twin, tb = free_box("implicit-euler")
    with pytest.raises(ValueError, match=message) as e:
        getattr(b, call)(value, **kw)
    assert "\n" not in str(e.value)
    w.step()
    twin.step()
    # no force was kept: the step is the step of a world that was never asked
    np.testing.assert_array_equal(b.velocities, tb.velocities)
    np.testing.assert_array_equal(b.positions, tb.positions)

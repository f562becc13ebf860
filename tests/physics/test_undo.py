"""A step that fails leaves the World exactly as it was before that step: positions,
velocities, the rest shape plasticity moved, the torn mesh, collider poses, grabs."""

import copy

import numpy as np
import pytest

import deforma
from deforma.physics import stepper

INTEGRATORS = ["symplectic-euler", "implicit-euler", "xpbd"]


def torn_sheet_world(integrator):
    """A plastic, tearing corotated strip pinned at its left end and pulled at its right by a
    grab moving right, beside a collider that moves and turns: it yields, then tears."""
    w = deforma.World(dt=1 / 240, substeps=8, integrator=integrator)
    mat = deforma.Material("corotated", youngs_modulus=2e3, poisson_ratio=0.3, density=1.0, yield_strain=0.05,
                           tear_strain=0.3)
    body = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 0.4), (0, 0.4)), detail=6, edges=True), material=mat,
                      position=(0, 1))
    x = body.positions
    body.pin(np.flatnonzero(x[:, 0] < x[:, 0].min() + 1e-9))
    w.add_collider(deforma.Rect((3.0, 3.0), (0.5, 0.2), 0.0, velocity=(0.1, 0.0), angular_velocity=30.0))
    right = np.flatnonzero(x[:, 0] > x[:, 0].max() - 1e-9)
    grab = w.grab(tuple(x[right].mean(axis=0)), strength=200.0, radius=0.25)
    return w, grab


def snapshot(w):
    """What a step may change, as arrays (the Model's rest shape read from the Model itself:
    it is what plasticity moves, and no public attribute shows it whole)."""
    m = w.model
    out = [np.array([w.time, w.step_count, len(w.bodies)])]
    for b in w.bodies:
        out += [b.positions, b.velocities, b.triangles, b.springs, b.pinned]
    out += [m.spring_rest_length, m.elem_b, m.elem_area, np.array([m.version])]
    for c in w.colliders:
        out += [np.array([*c.center, c.angle])]
    return [np.array(a, copy=True) for a in out]


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_step_failing_after_plastic_flow_a_tear_and_a_moving_collider_puts_everything_back(monkeypatch,
                                                                                              integrator):
    armed = []
    real = stepper.lost_shape

    def lost_shape(world, model, state, lost, step):  # the last check of a step, after plasticity and tearing
        if armed:
            return deforma.SimulationUnstable("made to fail", body=world.bodies[0], step=step, hint="none")
        return real(world, model, state, lost, step)

    monkeypatch.setattr(stepper, "lost_shape", lost_shape)
    monkeypatch.setattr(stepper, "SHAPE_CHECK_EVERY", 1)  # the check runs every step
    w, grab = torn_sheet_world(integrator)
    start = np.array(grab.target)
    for k in range(400):
        w.drag(grab, tuple(start + [0.002 * k, 0.0]))
        probe = copy.deepcopy(w)
        probe.step()
        if probe.bodies[0].n_vertices > w.bodies[0].n_vertices:  # this step tears
            break
        w.step()
    else:
        pytest.fail("the strip never tore")
    # the step also moves the rest shape (plasticity) and the collider
    rest_before, rest_after = w.model.rest_shape(0)[1], probe.model.rest_shape(0)[1]
    assert rest_before is not None and not np.array_equal(rest_before[0], rest_after[0])
    assert probe.colliders[0].center != w.colliders[0].center
    before, model, topology = snapshot(w), w.model, w.bodies[0].topology
    twin, twin_grab = copy.deepcopy((w, grab))  # one memo: the twin's own grab
    armed.append(True)
    with pytest.raises(deforma.SimulationUnstable, match="made to fail"):
        w.step()
    for a, b in zip(snapshot(w), before, strict=True):
        np.testing.assert_array_equal(a, b)  # bit for bit
    assert w.model is model and w.bodies[0].topology is topology
    assert grab.active and grab.target == twin_grab.target and np.array_equal(grab.vertices, twin_grab.vertices)
    # and it goes on as if the failed step never was
    armed.clear()
    for _ in range(3):
        w.drag(grab, tuple(start + [0.002 * k, 0.0]))
        twin.drag(twin_grab, tuple(start + [0.002 * k, 0.0]))
        w.step()
        twin.step()
    assert w.bodies[0].n_vertices == twin.bodies[0].n_vertices >= probe.bodies[0].n_vertices  # both tore
    if integrator == "implicit-euler":  # its factor was corrected in the failed step: rounding apart
        np.testing.assert_allclose(w.bodies[0].positions, twin.bodies[0].positions, rtol=0, atol=1e-12)
    else:
        np.testing.assert_array_equal(w.bodies[0].positions, twin.bodies[0].positions)


def test_a_runaway_step_puts_back_the_gas_kick_and_the_collider_poses():
    w = deforma.World(dt=1 / 600, stiffness=500.0, max_speed=50.0)
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=3, edges=True), pressure=50.0)
    w.add_collider(deforma.Circle((5.0, 0.0), 0.5, velocity=(1.0, 0.0), angular_velocity=90.0))
    for _ in range(5):
        w.step()
    before = snapshot(w)
    b.velocities[0] = (60.0, 0.0)  # faster than max_speed: the step must fail
    v0 = b.velocities.copy()
    with pytest.raises(deforma.SimulationUnstable, match="faster than max_speed"):
        w.step()
    assert np.array_equal(b.velocities, v0)  # not kicked by the gas
    after = snapshot(w)
    for k, (a, c) in enumerate(zip(after, before, strict=True)):
        if k == 2:  # the velocities: only the one set by hand differs
            continue
        np.testing.assert_array_equal(a, c)


def test_a_step_interrupted_by_ctrl_c_after_the_integrator_leaves_no_half_made_step(monkeypatch):
    w, grab = torn_sheet_world("implicit-euler")
    for _ in range(5):
        w.step()
    before = snapshot(w)

    def interrupt(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(stepper.behaviours, "limit_and_yield", interrupt)  # after the integrator moved everything
    with pytest.raises(KeyboardInterrupt):
        w.step()
    for a, b in zip(snapshot(w), before, strict=True):
        np.testing.assert_array_equal(a, b)

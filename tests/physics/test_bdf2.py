"""implicit-bdf2 against known answers at display steps: a bar's ring and its decay, a
rotor's spin, free fall, momentum, and the hanging column.

BDF2's own figures come from its characteristic equation for a mode ``x' = lambda x``:
``(1 - (2/3) h lambda) z^2 - (4/3) z + 1/3 = 0``, the amplitude kept per step is the larger
root's modulus and the phase per step its argument.
"""

import copy
import math

import numpy as np
import pytest

import deforma
from deforma.physics import SimulationUnstable
from test_converged_implicit import angular_momentum, momentum, spinning_box
from test_fem_validation import EXPECTED, L, RHO, E, column, hang

H = 1 / 60


def bdf2_root(h_lambda: complex) -> complex:
    roots = np.roots([1 - 2 / 3 * h_lambda, -4 / 3, 1 / 3])
    return roots[np.argmax(np.abs(roots))]


def ring(per_period, periods, damping=0.0, integrator="implicit-bdf2", options=None):
    """The column of test_fem_validation (0.2 x 2 m, 1e5 Pa, 100 kg/m^2) clamped at its top,
    set ringing in its first longitudinal mode without gravity, at ``per_period`` steps per
    period of c / 4L: (frequency / (c / 4L), amplitude of the last period / of the first)."""
    f = math.sqrt(E / RHO) / (4 * L)
    # (sleep off: the ring decays below its 5 mm/s, and the decay is what is measured)
    w = deforma.World(gravity=(0.0, 0.0), dt=1 / (f * per_period), integrator=integrator, integrator_options=options,
                      sleep=False)
    m = column(4)
    b = w.add_body(m, material=deforma.Material("corotated", youngs_modulus=E, poisson_ratio=0.3, density=RHO,
                                                damping=damping), position=None)
    b.pin(np.flatnonzero(np.isclose(m.vertices[:, 1], 0.0)))
    depth = -m.vertices[:, 1]  # from the clamp
    v = b.velocities
    v[:, 1] = 0.05 * np.sin(math.pi * depth / (2 * L))  # the first mode's shape, 5 cm/s at the tip
    b.velocities = v
    tip = np.isclose(m.vertices[:, 1], -L)
    s = []
    for _ in range(per_period * periods):
        w.step()
        s.append(b.positions[tip, 1].mean() + L)
    s = np.array(s)
    up = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    crossings = (up + 1 - s[up] / (s[up + 1] - s[up])) * w.dt
    assert w.integrator_stats["unconverged"] == 0
    return 1 / np.diff(crossings).mean() / f, np.abs(s[-per_period:]).max() / np.abs(s[:per_period]).max()


def test_a_bar_rings_at_its_frequency_and_keeps_bdf2s_share_of_its_amplitude():
    # h = T/20: BDF2's phase makes 0.971 of the frequency and keeps 0.676 of the amplitude
    # after 10 periods (backward Euler: 0.969 and 8e-5)
    freq, kept = ring(20, 10)
    z = bdf2_root(2j * math.pi / 20)
    assert freq == pytest.approx(1.0, abs=0.03)
    assert freq == pytest.approx(np.angle(z) / (2 * math.pi / 20), rel=0.01)
    assert kept >= 0.6
    assert kept == pytest.approx(abs(z) ** 200, rel=0.05)


def test_material_damping_decays_a_ring_by_the_materials_rate_and_the_schemes_share():
    # damping ratio 1 % for the first mode (stiffness-proportional: zeta = damping omega / 2)
    omega = 2 * math.pi * math.sqrt(E / RHO) / (4 * L)
    zeta = 0.01
    _, free = ring(20, 10)
    _, damped = ring(20, 10, damping=2 * zeta / omega)
    h = 2 * math.pi / omega / 20
    decay = -zeta * omega + 1j * omega * math.sqrt(1 - zeta ** 2)
    expected = (abs(bdf2_root(h * decay)) / abs(bdf2_root(1j * omega * h))) ** 200  # 0.562; continuous 0.533
    assert damped / free == pytest.approx(expected, rel=0.10)


def test_a_spinning_box_keeps_its_spin_to_one_percent():
    # the box of test_converged_implicit (1e4 Pa, 5 rad/s, 1/60 s, 60 steps); backward Euler
    # keeps 0.75 of the spin there
    w, b = spinning_box(integrator="implicit-bdf2")
    start, p0 = angular_momentum(b), momentum(b)
    for _ in range(60):
        w.step()
    assert angular_momentum(b) / start == pytest.approx(1.0, abs=0.01)
    assert np.abs(momentum(b) - p0).max() < 1e-9 * 100 * 3.5


def test_free_fall_within_bdf2s_second_order_error():
    w = deforma.World(dt=H, gravity=(0.0, -9.81), integrator="implicit-bdf2")
    b = w.add_body(deforma.mesh.box(((0, 0), (0.3, 0), (0.3, 0.2), (0, 0.2)), detail=2, edges=True),
                   position=(0.0, 10.0))
    b.velocities[:] = (0.5, 2.0)
    start = b.center_of_mass
    for _ in range(60):
        w.step()
    t = 1.0
    com = b.center_of_mass
    # the first step starts from a past of constant velocity: an O(h^2) error, which BDF2's
    # second root (1/3) does not let grow
    assert com[1] == pytest.approx(start[1] + 2.0 * t - 9.81 * t * t / 2, abs=9.81 * H * H)
    assert com[0] == pytest.approx(start[0] + 0.5 * t, abs=1e-9)
    assert b.velocities[:, 1].mean() == pytest.approx(2.0 - 9.81 * t, abs=9.81 * H)


def test_an_impulse_between_steps_is_kept_exactly_not_read_as_an_acceleration():
    w, b = spinning_box(integrator="implicit-bdf2", omega=0.0)
    for _ in range(3):
        w.step()
    b.apply_impulse((0.0, 50.0))  # N s on 100 kg
    for _ in range(5):
        w.step()
    np.testing.assert_allclose(momentum(b), [0.0, 50.0], atol=1e-9)
    assert np.ptp(b.velocities[:, 1]) < 1e-9  # all of it moves alike: nothing rings


@pytest.mark.parametrize("model", ["corotated", "neo-hookean"])
def test_hanging_column_at_a_display_step(model):
    elongation, _ = hang(model, 4, "implicit-bdf2")
    assert abs(elongation / EXPECTED - 1) < 0.03


def test_a_force_for_one_step_gives_its_whole_impulse_spread_as_bdf2_spreads_it():
    # BDF2 takes 2/3 of a one-step force's impulse at once, then a third of the rest at each
    # step after (its second root, 1/3): the whole of it within rounding after 40 steps
    w, b = spinning_box(integrator="implicit-bdf2", omega=0.0)
    w.step()
    b.apply_force((3.0, -1.0))  # N, for one step of 1/60 s
    w.step()
    np.testing.assert_allclose(momentum(b), np.array([2.0, -2.0 / 3.0]) / 60, rtol=1e-9, atol=1e-12)
    for _ in range(40):
        w.step()
    np.testing.assert_allclose(momentum(b), np.array([3.0, -1.0]) / 60, rtol=1e-9, atol=1e-12)


def test_a_step_undone_and_run_again_starts_from_the_same_history():
    w, b = spinning_box(integrator="implicit-bdf2")
    for _ in range(3):
        w.step()
    twin = copy.deepcopy(w)
    w.max_speed = 1.0  # the rim moves at 3.5 m/s: the step fails and is undone
    with pytest.raises(SimulationUnstable):
        w.step()
    w.max_speed = twin.max_speed
    for _ in range(3):
        w.step()
        twin.step()
    assert np.array_equal(b.positions, twin.bodies[0].positions)
    assert np.array_equal(b.velocities, twin.bodies[0].velocities)


@pytest.mark.parametrize("integrator", ["implicit-bdf2", "implicit-euler"])
def test_a_box_sliding_on_a_frictionless_floor_keeps_its_speed(integrator):
    # a 40 x 20 cm box resting on a frictionless floor, given 2 m/s along it: nothing acts
    # along the floor, so every vertex keeps 2 m/s (BDF2 gave the vertices on the floor
    # backward Euler's velocity, and the box settled at 1.864 m/s)
    w = deforma.World(dt=H, integrator=integrator, friction=0.0, static_friction=0.0, sleep=False)
    w.add_collider(deforma.Rect((0, -0.5), (400, 1), 0.0))
    mat = deforma.Material("corotated", youngs_modulus=1e5, poisson_ratio=0.3, density=100.0)
    b = w.add_body(deforma.mesh.box(((0, 0), (0.4, 0), (0.4, 0.2), (0, 0.2)), detail=4), position=(0, 0.1005),
                   material=mat)
    for _ in range(60):
        w.step()
    b.velocity = (2.0, 0.0)
    for _ in range(120):
        w.step()
    assert np.abs(b.velocities[:, 0] - 2.0).max() < 1e-3

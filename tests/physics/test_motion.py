"""Known answers of the free dynamics: free fall, a spring's period, conservation laws."""

import math

import numpy as np
import pytest

import deforma
from physics_meshes import Chain, grid_mesh


def test_free_fall_matches_discrete_and_continuous_answers():
    h, n, g = 1 / 1000, 500, 9.81
    w = deforma.World(dt=h, gravity=(0.0, -g))
    b = w.add_body(grid_mesh(0.3, 0.2, 4, 3), position=(1.0, 10.0))
    b.velocities[:] = (0.5, 2.0)
    for _ in range(n):
        w.step()
    t = n * h
    com = b.center_of_mass
    # symplectic Euler: v_k = v0 - g h k, y_n = y0 + h sum_k v_k = y0 + v0 t - g h^2 n (n + 1) / 2
    assert com[1] == pytest.approx(10.0 + 2.0 * t - g * h * h * n * (n + 1) / 2, abs=1e-9)
    assert com[1] == pytest.approx(10.0 + 2.0 * t - g * t * t / 2, abs=g * h * t)  # O(h) from the exact
    assert com[0] == pytest.approx(1.0 + 0.5 * t, abs=1e-9)
    assert w.time == pytest.approx(t) and w.step_count == n


def test_two_masses_on_one_spring_oscillate_with_period_2pi_sqrt_mu_over_k():
    k, total_mass = 150.0, 3.0  # two vertices of 1.5 kg: reduced mass mu = 0.75 kg
    w = deforma.World(dt=1e-4, gravity=(0, 0), mass=total_mass, stiffness=k, damping=0.0)
    b = w.add_body(Chain([[0, 0], [1, 0]], [[0, 1]]), position=None)
    b.positions[1, 0] = 1.1  # stretched by 10 cm
    lengths = []
    for _ in range(20000):  # 2 s
        w.step()
        lengths.append(b.positions[1, 0] - b.positions[0, 0] - 1.0)
    s = np.array(lengths)
    up = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    # interpolate the crossing times for sub-step precision
    tc = (up + 1 + (-s[up]) / (s[up + 1] - s[up])) * 1e-4
    period = np.diff(tc).mean()
    assert len(tc) >= 4
    assert period == pytest.approx(2 * math.pi * math.sqrt(0.75 / k), rel=2e-3)


def _random_body(world, seed):
    rng = np.random.default_rng(seed)
    b = world.add_body(grid_mesh(1.0, 0.6, 7, 5), position=(0, 0))
    b.positions[:] += rng.normal(scale=0.03, size=b.positions.shape)
    b.velocities[:] = rng.normal(scale=0.5, size=b.velocities.shape)
    return b


def test_momentum_and_angular_momentum_kept_without_gravity_or_colliders():
    w = deforma.World(dt=1 / 2000, gravity=(0, 0), stiffness=400.0, damping=0.3)
    b = _random_body(w, 1)
    m = b.mass / b.n_vertices

    def momenta():
        x, v = b.positions, b.velocities
        return m * v.sum(axis=0), m * float(np.sum(x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0]))

    p0, l0 = momenta()
    for _ in range(1000):
        w.step()
    p1, l1 = momenta()
    assert np.abs(p1 - p0).max() < 1e-12
    # symplectic Euler keeps angular momentum exactly for central forces (up to rounding)
    assert l1 == pytest.approx(l0, abs=1e-12)


def test_energy_stays_bounded_without_damping():
    w = deforma.World(dt=1 / 2000, gravity=(0, -9.81), stiffness=400.0, damping=0.0)
    _random_body(w, 2)
    totals = []
    for _ in range(4000):
        w.step()
        totals.append(w.energy().total)
    e = np.array(totals)
    e0 = w.energy()
    scale = max(e0.kinetic + e0.spring, 1e-9)
    assert np.ptp(e) < 0.05 * scale  # oscillates by a few percent, O(h)
    half = len(e) // 2
    assert abs(e[:half].mean() - e[half:].mean()) < 0.01 * scale  # and does not drift


def test_damping_removes_energy():
    w = deforma.World(dt=1 / 2000, gravity=(0, 0), stiffness=400.0, damping=0.5)
    _random_body(w, 3)
    e0 = w.energy().total
    for _ in range(2000):
        w.step()
    assert w.energy().total < 0.5 * e0

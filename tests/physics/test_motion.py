"""Known answers of the free dynamics under symplectic Euler: a spring's period at a small step,
bounded energy, damping (free fall and momentum under every integrator: test_integrators.py)."""

import math

import numpy as np
import pytest

import deforma
from physics_meshes import Chain, random_body


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


def test_energy_stays_bounded_without_damping():
    w = deforma.World(integrator="symplectic-euler", dt=1 / 2000, gravity=(0, -9.81), stiffness=400.0, damping=0.0)
    random_body(w, 2, self_collision=False)  # its outline folds onto itself now and then: inelastic
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
    random_body(w, 3)
    e0 = w.energy().total
    for _ in range(2000):
        w.step()
    assert w.energy().total < 0.5 * e0

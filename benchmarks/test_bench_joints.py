"""bench_joints.py builds the same bodies and pins in deforma and pymunk, measures both, and
skips the peer in one line without pymunk.

Run with ``pytest benchmarks/test_bench_joints.py`` (the project's testpaths cover tests/ only,
so the default run does not need pymunk). About 10 s warm: one short measure of each case,
whose quality windows (5 s of the chains, 8 s of the pendulum) are simulated whole.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_joints

NO_PYMUNK = "pymunk not installed: bench_joints' peer (pip install pymunk)"


@pytest.mark.parametrize("case, n", [("chain", 21), ("heavy chain", 21), ("pendulum", 1)])
def test_both_engines_get_the_same_bodies_and_pins(case, n):
    pytest.importorskip("pymunk", reason=NO_PYMUNK)
    engines = bench_joints.engines(case)
    assert list(engines) == ["deforma avbd", "pymunk"]
    d, p = engines.values()
    assert len(d.masses) == n and len(d.pins) == (1 if case == "pendulum" else 21)
    np.testing.assert_allclose(p.masses, d.masses, rtol=1e-12)  # 100 kg/m^2, the same boxes
    np.testing.assert_allclose(p.centres(), d.centres(), atol=1e-12)
    np.testing.assert_allclose(p.pins, d.pins, atol=1e-12)  # pinned at the same points
    assert p.sample() == pytest.approx(d.sample(), abs=1e-9)  # the weight's height; the swing
    assert p.speed() == d.speed() == 0.0
    if case == "heavy chain":
        assert d.masses[-1] == pytest.approx(1000 * d.masses[0])


def test_pymunk_keeps_its_defaults_and_its_joined_pairs_do_not_collide():
    pytest.importorskip("pymunk", reason=NO_PYMUNK)
    space, bodies, weight = bench_joints.pymunk_chain(3, 1.0)
    assert space.iterations == 10 and space.damping == 1.0 and math.isinf(space.sleep_time_threshold)
    assert len(space.constraints) == 4 and not any(c.collide_bodies for c in space.constraints)
    assert bodies[-1] is weight and tuple(space.gravity) == (0.0, -bench_joints.G)


def test_swing_period_of_a_sampled_cosine():
    t = np.arange(1, 481) * bench_joints.H
    assert bench_joints.swing_period(30 * np.cos(2 * np.pi * t / 1.7)) == pytest.approx(1.7, rel=1e-3)
    assert math.isnan(bench_joints.swing_period(np.ones(10)))


@pytest.fixture(scope="module")
def measured():
    pytest.importorskip("pymunk", reason=NO_PYMUNK)
    return {case: bench_joints.measure(case, rounds=2, steps=15) for case in bench_joints.CASES}


def test_a_short_measure_gives_both_rows_of_every_case(measured):
    import pymunk

    for case, m in measured.items():
        assert set(m) == {"deforma avbd", "pymunk"}
        for r in m.values():
            assert r["steps_per_s"] > 0 and r["timed_steps"] == 30
        rows = bench_joints.case_rows(case, m, pymunk.version)
        assert [r.topic for r in rows] == ["joints", "joints"] and all(r.unit == "steps/s" for r in rows)
        assert "deforma avbd" in rows[0].case and rows[0].ratio.startswith("pymunk ")
        assert f"pymunk {pymunk.version}" in rows[1].case


def test_deformas_chains_stretch_under_one_percent(measured):
    for case in ("chain", "heavy chain"):
        r = measured[case]["deforma avbd"]
        assert r["stretch"] < 0.01, case
        assert r["end_speed"] < 0.1, case  # it hangs (the heavy weight buzzes at about 1 cm/s)


def test_both_pendulums_swing_at_the_analytic_period_and_deformas_keeps_its_swing(measured):
    d, p = measured["pendulum"]["deforma avbd"], measured["pendulum"]["pymunk"]
    assert abs(d["period_error"]) < 0.02 and abs(p["period_error"]) < 0.02  # the same bar and hinge
    assert d["kept"] > 0.98


def test_without_pymunk_the_rows_are_skipped_in_one_line(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "pymunk", None)  # import pymunk raises ImportError
    assert bench_joints.run(quick=True) == []
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pymunk not installed" in err[0] and "pip install pymunk" in err[0]

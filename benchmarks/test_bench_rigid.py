"""bench_rigid.py builds the same boxes in deforma and pymunk, measures both, and skips the
peer in one line without pymunk.

Run with ``pytest benchmarks/test_bench_rigid.py`` (the project's testpaths cover tests/ only,
so the default run does not need pymunk).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_rigid


@pytest.mark.parametrize("case, n", [("stack", 10), ("pyramid", 210)])
def test_both_engines_get_the_same_boxes(case, n):
    pytest.importorskip("pymunk")
    engines = bench_rigid.engines(case)
    assert len(engines) == 3
    (_, centres, speeds, masses), *peers = engines.values()
    assert len(masses) == n
    for _, peer_centres, peer_speeds, peer_masses in peers:
        np.testing.assert_allclose(peer_masses, masses, rtol=1e-12)  # 100 kg/m^2, the same boxes
        np.testing.assert_allclose(peer_centres(), centres(), atol=1e-12)
        assert peer_speeds().max() == speeds().max() == 0.0


def test_pymunk_pairs_meet_with_friction_half():
    pymunk = pytest.importorskip("pymunk")
    space, _ = bench_rigid.pymunk_space(bench_rigid.stack_boxes(2))
    assert space.iterations == 10 and space.collision_slop == pytest.approx(bench_rigid.SLOP)
    seen = []
    space.on_collision(post_solve=lambda arbiter, space, data: seen.append(arbiter.friction))
    for _ in range(30):
        space.step(bench_rigid.H)
    assert seen and np.allclose(seen, bench_rigid.FRICTION)  # box on floor and box on box
    assert bench_rigid.pymunk_space(bench_rigid.stack_boxes(2), slop=None)[0].collision_slop == \
        pytest.approx(pymunk.Space().collision_slop)


def test_a_short_measure_of_the_stack():
    pytest.importorskip("pymunk")
    m = bench_rigid.measure("stack", rounds=2, steps=10)
    assert set(m) == {"deforma avbd", "pymunk, slop 5 mm", "pymunk defaults, slop 0.1"}
    for r in m.values():
        assert r["boxes"] == 10 and r["steps_per_s"] > 0 and np.isfinite(r["drift"])
        assert r["drift"] < 0.2 and r["end_speed"] < 1.0  # the stack stands in every engine
    assert m["deforma avbd"]["drift"] < 1e-3


def test_without_pymunk_the_rows_are_skipped_in_one_line(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "pymunk", None)  # import pymunk raises ImportError
    assert bench_rigid.run(quick=True) == []
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pymunk not installed" in err[0] and "pip install pymunk" in err[0]

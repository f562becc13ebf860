"""bench_sleep.py builds its heap, settles a small one and the stack until they sleep, and
makes its rows; no timing is asserted (the figures are the benchmark's, not a test's).

Run with ``pytest benchmarks/test_bench_sleep.py`` (the project's testpaths cover tests/ only).
About 5 s warm: a heap of 10 bodies in 2 rows and the 10-box stack, each settled and measured
briefly.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_sleep
from common import format_row


def test_the_heap_is_rigid_boxes_and_every_fourth_a_soft_one_in_its_container():
    w = bench_sleep.heap_world(20, rows=2)
    assert w.sleep and w.dt == pytest.approx(1 / 60) and len(w.colliders) == 3
    soft = [not b.material.is_rigid for b in w.bodies]
    assert len(soft) == 20 and sum(soft) == 5 and soft[3] and not soft[0]
    assert {b.n_vertices for b, s in zip(w.bodies, soft) if s} == {36}
    assert {b.n_vertices for b, s in zip(w.bodies, soft) if not s} == {16}
    floor, left, right = w.colliders
    xs = [x for b in w.bodies for x in b.positions[:, 0]]
    assert left.center[0] + left.size[0] / 2 < min(xs) and max(xs) < right.center[0] - right.size[0] / 2
    assert floor.center[1] + floor.size[1] / 2 == pytest.approx(0.0)  # the floor's top at y = 0
    assert min(y for b in w.bodies for y in b.positions[:, 1]) > 0.0


@pytest.mark.parametrize("case", ["heap", "stack"])
def test_a_short_measure_sleeps_and_prints_its_rows(case, capsys):
    m = bench_sleep.measure(case, rounds=2, steps=5, bodies=10, rows=2, cap=10.0)
    s = m["settle"]
    # asleep on its own, or put to sleep by hand at the cap; either way every body sleeps
    assert (s["asleep_at"] is not None) == (m["put_to_sleep"] == 0) and m["still_asleep"]
    if case == "stack":  # the stack lands at once: asleep after its 0.5 s of rest
        assert s["asleep_at"] == pytest.approx(0.5, abs=0.1)
    assert m["asleep_sps"] > 0 and m["awake_sps"] > 0
    assert m["ratio"] == pytest.approx(m["asleep_sps"] / m["awake_sps"])
    rows = bench_sleep.case_rows(case, m)
    assert [r.topic for r in rows] == ["sleep"] * 3 and [r.unit for r in rows] == ["steps/s", "steps/s", "s"]
    assert "cheaper a step than awake" in rows[0].ratio and rows[0].value == m["asleep_sps"]
    assert rows[2].met is (s["asleep_at"] is not None) and rows[2].value == pytest.approx(s["steps"] / 60)
    for r in rows:
        print(format_row(r))
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 3 and all(line.startswith("| sleep |") for line in out)


def test_bodies_still_awake_at_the_cap_are_put_to_sleep_and_the_rows_say_so():
    m = bench_sleep.measure("heap", rounds=1, steps=2, bodies=10, rows=2, cap=0.1)  # too short to fall asleep
    assert m["settle"]["asleep_at"] is None and m["put_to_sleep"] == 10 and m["still_asleep"]
    rows = bench_sleep.case_rows("heap", m)
    assert "10 of 10 still awake after 0.1 s were put to sleep by hand" in rows[0].case
    assert rows[2].met is False and "never all asleep" in rows[2].ratio

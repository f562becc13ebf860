"""bench_car.py drives the car scene and makes its row; no timing is asserted (the figure is
the benchmark's, not a test's).

Run with ``pytest benchmarks/test_bench_car.py`` (the project's testpaths cover tests/ only).
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_car
from common import format_row


def test_the_car_row_is_against_the_clock():
    m = bench_car.measure(1, 10)
    assert len(m["speed"]) == 1 and m["speed"][0] > 0 and m["seconds"] > 0.6
    (row,) = bench_car.run(quick=True)
    assert row.topic == "car" and row.unit == "x real time" and row.met == (row.value >= 1.0)
    assert "car scene" in format_row(row)

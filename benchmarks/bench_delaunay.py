"""Delaunay benchmark: deforma.delaunay against Triangle and SciPy, in the same run.

Goals (issue 2): on 1e6 uniform random points faster than Shewchuk's Triangle (the
``triangle`` package, as called from Python) and at least 10x faster than
``scipy.spatial.Delaunay``; peak extra memory below Triangle's; an exact 1000 x 1000
integer grid in at most 3x the random-case time.

Times are medians of wall time; each method gets one warm-up call (Numba's compiled code
comes from its cache). Memory is the peak resident set during one call minus the
resident set just before it, each method in a fresh subprocess (Linux ``VmHWM`` after
resetting it through ``/proc/self/clear_refs``).
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Row, median_seconds  # noqa: E402

import deforma  # noqa: E402


def _triangle(points):
    import triangle

    return triangle.triangulate({"vertices": points}, "Q")["triangles"]


def _scipy(points):
    from scipy.spatial import Delaunay

    return Delaunay(points).simplices


METHODS = {"deforma": deforma.delaunay, "triangle": _triangle, "scipy": _scipy}

_MEMORY_PROBE = textwrap.dedent(
    """
    import json, sys
    import numpy as np
    sys.path.insert(0, {here!r})
    from bench_delaunay import METHODS, random_points
    fn = METHODS[{method!r}]
    pts = random_points({n})
    fn(pts[:1000])  # warm up: imports, compiled code
    def status(key):
        for line in open("/proc/self/status"):
            if line.startswith(key):
                return int(line.split()[1]) * 1024
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")  # reset the peak resident set (VmHWM)
    before = status("VmRSS:")
    tris = fn(pts)
    print(json.dumps({{"extra": status("VmHWM:") - before, "triangles": len(tris)}}))
    """
)


def random_points(n: int, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).random((n, 2))


def grid_points(side: int) -> np.ndarray:
    g = np.arange(side, dtype=np.float64)
    return np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)


def peak_extra_memory(method: str, n: int) -> int:
    """Peak extra resident memory in bytes of one call on n random points (fresh process)."""
    code = _MEMORY_PROBE.format(here=str(Path(__file__).resolve().parent), method=method, n=n)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])["extra"]


def run(quick: bool = False) -> list[Row]:
    n = 100_000 if quick else 1_000_000
    side = 316 if quick else 1000
    repeat = 3 if quick else 5
    label = f"{n:.0e} random"
    pts = random_points(n)
    grid = grid_points(side)

    t = {m: median_seconds(lambda m=m: METHODS[m](pts), repeat=repeat if m != "scipy" else 3) for m in METHODS}
    t_grid = {m: median_seconds(lambda m=m: METHODS[m](grid), repeat=repeat) for m in ("deforma", "triangle")}
    mem = {m: peak_extra_memory(m, n) for m in ("deforma", "triangle")}

    vs_tri = t["triangle"] / t["deforma"]
    vs_scipy = t["scipy"] / t["deforma"]
    grid_ratio = t_grid["deforma"] / t["deforma"]
    mem_ratio = mem["deforma"] / mem["triangle"]
    return [
        Row("delaunay", f"{label}: deforma", t["deforma"], "s"),
        Row("delaunay", f"{label}: triangle", t["triangle"], "s", f"deforma {vs_tri:.2f}x faster",
            "faster than Triangle", vs_tri > 1.0),
        Row("delaunay", f"{label}: scipy", t["scipy"], "s", f"deforma {vs_scipy:.1f}x faster",
            ">= 10x faster than SciPy", vs_scipy >= 10.0),
        Row("delaunay", f"{side}x{side} grid: deforma", t_grid["deforma"], "s",
            f"{grid_ratio:.2f}x the random case", "grid <= 3x random", grid_ratio <= 3.0),
        Row("delaunay", f"{side}x{side} grid: triangle", t_grid["triangle"], "s",
            f"deforma {t_grid['triangle'] / t_grid['deforma']:.2f}x faster"),
        Row("delaunay", f"{label}: peak extra memory, deforma", mem["deforma"] / 2**20, "MiB"),
        Row("delaunay", f"{label}: peak extra memory, triangle", mem["triangle"] / 2**20, "MiB",
            f"deforma uses {mem_ratio:.2f}x", "below Triangle's", mem_ratio < 1.0),
    ]


if __name__ == "__main__":
    from common import format_table

    print(format_table(run(quick="--quick" in sys.argv)))

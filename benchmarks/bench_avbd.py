"""avbd benchmark: the README's bunny on a floor at one step a frame, against the former default.

The body is the README's: ``deforma.mesh.from_image("bunny", resolution=4, detect_edges=True,
edge_step=2, scale=0.01)`` (4557 vertices, the World's springs) dropped 20 cm onto a floor.
Two worlds run side by side, one step of each in turn (so that the shared machine's load falls
on both alike), after one simulated second each (landing, Numba compilation):

- ``avbd`` at ``dt = 1/60 s``, one step a frame, its default options (ten sweeps);
- the default before avbd: symplectic Euler at ``dt = 1/600 s`` with ``substeps="auto"``.

Figures are medians of timed steps; the cost per simulated second is the step time over
``dt``. The goal (issue 48): avbd at real time or better, at least 60 steps/s of 1/60 s.
``--quick`` takes the bunny at resolution 8 (1,391 vertices) and fewer steps.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Row  # noqa: E402

import deforma  # noqa: E402


def bunny_world(resolution: int, integrator: str | None):
    """The README bunny 20 cm above a floor, under ``integrator`` at 1/60 s (None: symplectic Euler at
    1/600 s with automatic substeps, the default before avbd)."""
    mesh = deforma.mesh.from_image("bunny", resolution=resolution, detect_edges=True, edge_step=2, scale=0.01)
    w = deforma.World(sleep=False, dt=1 / 600, integrator="symplectic-euler") if integrator is None else \
        deforma.World(sleep=False, dt=1 / 60, substeps=1, integrator=integrator)
    w.add_collider(deforma.Rect((0.0, -0.25), (8.0, 0.5), 0.0))
    w.add_body(mesh, position=(0.0, np.ptp(mesh.vertices[:, 1]) / 2 + 0.2))
    return w


def run(quick: bool) -> list[Row]:
    resolution = 8 if quick else 4
    worlds = {"avbd": bunny_world(resolution, "avbd"), "default": bunny_world(resolution, None)}
    for w in worlds.values():
        while w.time < 1.0:
            w.step()
    times = {name: [] for name in worlds}
    repeat = 10 if quick else 30
    for _ in range(repeat):
        for name, w in worlds.items():
            t0 = time.perf_counter()
            w.step()
            times[name].append(time.perf_counter() - t0)
    step = {name: statistics.median(t) for name, t in times.items()}
    cost = {name: step[name] / worlds[name].dt for name in worlds}
    n = len(worlds["avbd"].bodies[0].positions)
    default = worlds["default"]
    rows = [Row("avbd", f"README bunny ({n} vertices) on a floor, avbd, 1/60 s x 1: steps per s",
                1.0 / step["avbd"], "1/s", f"{cost['default'] / cost['avbd']:.3g}x cheaper per simulated s "
                f"than the former default", ">= 60 steps/s (real time)", None if quick else 1.0 / step["avbd"] >= 60.0),
            Row("avbd", f"README bunny ({n} vertices), the former default: symplectic, dt {default.dt:.3g} s x "
                        f"{default.substeps} substeps: s per simulated s", cost["default"], "s",
                f"step {step['default'] * 1e3:.3g} ms")]
    return rows


if __name__ == "__main__":
    from common import format_table

    print(format_table(run(quick="--quick" in sys.argv)))

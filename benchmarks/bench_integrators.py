"""Integrator benchmark: cost per simulated second of the three integrators on one body.

The body is ``bench_physics``'s: a 1 m square of n x n vertices (stiffness 2000 N/m per
spring, damping 0.5 N*s/m, 1 kg) standing on a floor, with the two other colliders beside
it. Each integrator runs at settings that show the body as stiff as it is:

- ``symplectic-euler`` at half its stable step (``0.5 * world.stable_dt()``), as in
  ``bench_physics``: the reference, it integrates the stiffness as given;
- ``implicit-euler`` and ``xpbd`` at ``dt = 1/60 s`` with the substeps that keep the body's
  height within 0.5% of its 1 m after 1/6 s on the floor at 1e4 vertices (found by
  ``python benchmarks/bench_integrators.py --sag``: implicit 1, since the floor is inside
  its solve; XPBD 64: one Gauss-Seidel sweep per substep carries the floor's support about
  one row up, so fewer let the body sink into itself; see docs/integrators.md). The rows
  give the height at the end of the timed steps (the body still rings a little) and use the
  same substeps at 1e5 vertices.

``python benchmarks/bench_integrators.py --xpbd-sag`` prints XPBD's sag at 1/60 s against
its estimate ``g H h^2 / l^2`` (``World.xpbd_substeps``; docs/integrators.md).

Figures are medians of timed ``world.step()`` calls after warm-up steps (which include
Numba compilation and, for implicit Euler, the one factorization). The cost per simulated
second is the step time divided by ``dt``. A separate row times one implicit Euler step of
one substep at ``dt = 1/60 s`` on 1e5 vertices, the issue's goal (<= 0.1 s).

The converged rows (:func:`converged_rows`) time implicit Euler solved to ``tolerance =
1e-3`` m/s and ``implicit-bdf2`` (the same tolerance, its default) against implicit Euler's
three fixed iterations on the same body, one step of each in turn (alternating, so that the
shared machine's load falls on all three alike), and the spinning box of
``tests/physics/test_converged_implicit.py`` (1e4 Pa) likewise.
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_physics import grid_mesh  # noqa: E402
from common import Row  # noqa: E402

import deforma  # noqa: E402

SUBSTEPS = {"implicit-euler": 1, "xpbd": 64}


def make_world(n: int, integrator: str, *, substeps: int = 1):
    """The bench_physics body (n*n vertices, touching the floor) under ``integrator``."""
    w = deforma.World(sleep=False, dt=1 / 600, stiffness=2000.0, damping=0.5, mass=1.0, integrator=integrator)
    w.add_collider(deforma.Rect((0.0, -0.25), (4.0, 0.5), 0.0))
    w.add_collider(deforma.Rect((-1.2, 0.5), (0.8, 0.1), 30.0))
    w.add_collider(deforma.Rect((1.0, 0.1), (0.2, 0.2), 10.0))
    body = w.add_body(grid_mesh(n), position=(0.0, 0.5 + 1e-6))
    if integrator == "symplectic-euler":
        w.dt = 0.5 * w.stable_dt()
    else:
        w.dt, w.substeps = 1 / 60, substeps
    return w, body


def timed_steps(w, *, warmup: int, repeat: int) -> float:
    """Median seconds per ``world.step()`` over ``repeat`` steps after ``warmup`` steps."""
    for _ in range(warmup):
        w.step()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        w.step()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def run(quick: bool) -> list[Row]:
    """Rows for the table: cost per simulated second per integrator and size, and the goal."""
    rows = []
    sizes = (100,) if quick else (100, 317)
    for n in sizes:
        nv = n * n
        label = f"{nv:.0e}".replace("+0", "") + " vertices"
        costs, made = {}, {}
        for name in ("symplectic-euler", "implicit-euler", "xpbd"):
            w, body = make_world(n, name, substeps=SUBSTEPS.get(name, 1))
            if name == "symplectic-euler":
                w.integrator_options = {"mode": "serial"}  # both cores fight other processes; serial is steady
                step = timed_steps(w, warmup=20, repeat=50)
                settings = f"dt {w.dt * 1e6:.3g} us"
                height = ""
            else:
                warm = 10  # 1/6 s on the floor: also the settle for the height figure
                step = timed_steps(w, warmup=warm, repeat=3 if nv > 50_000 else 5)
                settings = f"dt 1/60 s x {w.substeps}"
                height = f", height {np.ptp(body.positions[:, 1]):.4f} m after {w.time:.2f} s"
            costs[name] = step / w.dt
            made[name] = Row("integrators", f"{name}, {label}, {settings}: s per simulated s{height}",
                             costs[name], "s", f"step {step * 1e3:.3g} ms")
            rows.append(made[name])
        for name in ("implicit-euler", "xpbd"):
            made[name].ratio += f"; {costs['symplectic-euler'] / costs[name]:.2g}x faster than symplectic"
    # the goal: one implicit Euler step (one substep) at dt = 1/60 s on 1e5 vertices
    n = 100 if quick else 317
    w, body = make_world(n, "implicit-euler", substeps=1)
    step = timed_steps(w, warmup=3, repeat=5 if quick else 7)
    rows.append(Row("integrators", f"implicit-euler, {n * n:.0e} vertices, one step of 1/60 s "
                                   f"({w.integrator_options['iterations']} local/global iterations)".replace("+0", ""),
                    step, "s", "", "<= 0.1 s per step at 1e5 vertices", None if quick else step <= 0.1))
    rows += converged_rows(quick)
    return rows


SOLVES = (("implicit-euler", {}, "3 iterations"), ("implicit-euler", {"tolerance": 1e-3}, "tolerance 1e-3 m/s"),
          ("implicit-bdf2", {}, "tolerance 1e-3 m/s"))


def spinning_box(integrator: str):
    """The spinning box of the converged-solve tests: 1 m, corotated 1e4 Pa, 5 rad/s, no gravity."""
    w = deforma.World(sleep=False, gravity=(0.0, 0.0), dt=1 / 60, integrator=integrator)
    m = deforma.Material("corotated", youngs_modulus=1e4, poisson_ratio=0.3, density=100.0)
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=8, edges=True), position=(0, 0),
                   material=m)
    r = b.positions - b.center_of_mass
    b.velocities = 5.0 * np.stack([-r[:, 1], r[:, 0]], axis=1)
    return w, b


def alternating(worlds, *, warmup: int, repeat: int) -> list[float]:
    """Median seconds per step of each world, stepping them in turn."""
    for w in worlds:
        for _ in range(warmup):
            w.step()
    times = [[] for _ in worlds]
    for _ in range(repeat):
        for w, t in zip(worlds, times):
            t0 = time.perf_counter()
            w.step()
            t.append(time.perf_counter() - t0)
    return [statistics.median(t) for t in times]


def converged_rows(quick: bool) -> list[Row]:
    """Implicit Euler to a tolerance and BDF2 against three fixed iterations: the standing
    body (1e4 vertices; 1e5 too unless quick) and the spinning box, alternating."""
    rows = []
    cases = [("standing body, 1e4 vertices", lambda i: make_world(100, i)[0], 10, 7)]
    if not quick:
        cases.append(("standing body, 1e5 vertices", lambda i: make_world(317, i)[0], 3, 3))
    cases.append(("spinning box, 1e4 Pa, 1/60 s", lambda i: spinning_box(i)[0], 5, 25))
    for label, make, warmup, repeat in cases:
        worlds = []
        for integrator, options, _ in SOLVES:
            w = make(integrator)
            w.integrator_options = options
            worlds.append(w)
        steps = alternating(worlds, warmup=warmup, repeat=repeat)
        for (integrator, options, how), w, step in zip(SOLVES, worlds, steps):
            st = w.integrator_stats
            per = st["iterations"] / max(1, (w.step_count * w.substeps))
            goal, met = "", None
            if options and label.endswith("1e5 vertices") and integrator == "implicit-euler":
                goal, met = "converged 1e5-vertex step <= 2x the fixed one", step <= 2 * steps[0]
            rows.append(Row("integrators", f"{integrator}, {how}, {label}: one step of 1/60 s", step, "s",
                            f"{step / steps[0]:.2g}x the 3-iteration step; {per:.0f} iterations per substep, "
                            f"{st['unconverged']} unconverged", goal, met))
    return rows


def sag(n: int = 100) -> None:
    """Print the body's height after 1/6 s for several substep counts (how SUBSTEPS was chosen)."""
    for name, counts in (("implicit-euler", (1, 2, 4)), ("xpbd", (16, 32, 64))):
        for s in counts:
            w, body = make_world(n, name, substeps=s)
            try:
                for _ in range(10):
                    w.step()
                print(f"{name} x {s}: height {np.ptp(body.positions[:, 1]):.4f} m")
            except deforma.SimulationUnstable as e:
                print(f"{name} x {s}: unstable ({e})")


def _height_lost(w, body, seconds: float = 2.0) -> float:
    """Fraction of its rest height a body has lost after ``seconds`` (averaged over the last 1/2 s)."""
    rest = np.ptp(body.topology.rest_positions[:, 1])
    steps = int(round(seconds / w.dt))
    heights = []
    for k in range(steps):
        w.step()
        if k >= steps - int(round(0.5 / w.dt)):
            heights.append(np.ptp(body.positions[:, 1]))
    return 1.0 - float(np.mean(heights)) / rest


def xpbd_sag() -> None:
    """XPBD's sag at 1/60 s against its estimate g H h^2 / l^2 (docs/integrators.md,
    "How many substeps XPBD needs"): the pile's bunny and two spring grids on a floor."""
    g = 9.81

    def estimate(w, body):
        x, e = body.topology.rest_positions, body.topology.springs
        spacing = np.median(np.hypot(*(x[e[:, 1]] - x[e[:, 0]]).T))
        h = w.dt / w.substeps
        return g * np.ptp(x[:, 1]) * h * h / spacing**2

    bunny = deforma.mesh.from_image("bunny", resolution=22, edge_step=16, scale=0.0022)
    for s in (2, 4, 8, 16):
        mat = deforma.Material("corotated", youngs_modulus=2000.0, poisson_ratio=0.3, density=5.5)
        w = deforma.World(sleep=False, dt=1 / 60, substeps=s, integrator="xpbd", material=mat, friction=0.4,
                          static_friction=0.6, air_drag=0.6)
        w.add_collider(deforma.Rect((0.0, -0.2), (4.4, 0.4), 0.0))
        body = w.add_body(bunny, position=(0.0, 0.45))
        est = estimate(w, body)
        print(f"bunny x {s}: estimate {est:.4f}, height lost {_height_lost(w, body):.4f}")
    for n, counts in ((30, (1, 2, 4, 8, 22)), (100, (16, 32, 64))):
        for s in counts:
            w, body = make_world(n, "xpbd", substeps=s)
            est = estimate(w, body)
            print(f"{n} x {n} springs x {s}: estimate {est:.4f}, height lost {_height_lost(w, body):.4f}")


if __name__ == "__main__":
    from common import format_table

    if "--sag" in sys.argv:
        sag()
    elif "--xpbd-sag" in sys.argv:
        xpbd_sag()
    else:
        print(format_table(run(quick="--quick" in sys.argv)))

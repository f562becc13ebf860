"""Sweeps: runs per minute of ``deforma sweep`` with 1 and 2 workers, and the overhead per run.

The sweep is 16 runs of the built-in ``sample`` scene, 4 simulated seconds each (a 4 x 4 grid
of ``physics.youngs_modulus`` and ``physics.static_friction``, every run stable). Issue 16's
goals: 2 workers at least 1.7x the runs per minute of one, and the overhead per run (everything
but the simulation) below 10 % of a 4 s ``sample`` run.

- *Runs per minute* time :func:`deforma.sweep` once its local Ray cluster is up and every
  worker has run a warm-up run (Numba kernels loaded), so neither Ray's start-up (reported on
  its own row) nor compiling is in them. Each round starts a fresh cluster of 1, then of 2
  CPUs; the medians are over the rounds.
- *The simulation* is the same 16 scenes run one after the other in one Ray task on the same
  1-CPU cluster, just before and just after the timed sweep (the mean of the two), by what
  ``deforma run sample`` does without outputs: build the world, step it frame by frame. So it
  runs in the same kind of process, with the same single Numba thread, at nearly the same
  moment of a shared machine's load. *Overhead per run* = (1-worker sweep time - that time) /
  16, as a fraction of the simulation of one run: Ray's scheduling and transfers per run, the
  per-frame metrics, checking the sweep file and writing the table.

The machine may be shared: the load average is printed (stderr) at the start of each round,
and after each 2-worker sweep two plain halves of the 16 runs are run at once on its two
workers, their CPU time over their wall time giving the cores the machine actually gave two
workers (2.0 on an idle machine). With fewer, the 2-worker figure measures the other work,
not the sweep.

Usage: ``python benchmarks/run.py --only sweep`` (or ``python benchmarks/bench_sweep.py``);
needs the sweep extra (``pip install '.[sweep]'``).
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import Row, format_table  # noqa: E402

RUNS = 16
SECONDS = 4.0
SPEC = f"""
scene = "sample"
seconds = {SECONDS}

[parameters]
"physics.youngs_modulus" = [1000.0, 1500.0, 2000.0, 2500.0]
"physics.static_friction" = [0.3, 0.5, 0.7, 0.9]
"""
# two short runs per CPU, each worker's first: Numba's cache is loaded there, not in the timed sweep
WARM_UP = """
scene = "sample"
seconds = 0.2

[parameters]
"physics.youngs_modulus" = [1100.0, 1200.0, 1300.0, 1400.0]
"""


def _simulate_plainly(scenes) -> tuple[float, float]:
    """(wall, CPU) seconds to build and step every scene frame by frame in this process
    (``deforma run`` without outputs)."""
    from deforma.scene import Script

    t0, c0 = time.perf_counter(), time.process_time()
    for scene in scenes:
        world = scene.build()
        script = Script(scene, world)
        fps = scene.run.fps
        for k in range(max(1, int(round(scene.run.seconds * fps))) + 1):
            script.advance(k / fps)
    return time.perf_counter() - t0, time.process_time() - c0


def _timed_sweep(spec: Path, workers: int, folder: Path, tag: str, scenes) -> tuple[float, float, float]:
    """Start-up of a local cluster of ``workers`` CPUs, seconds of the timed 16-run sweep on it and:
    with one worker, seconds of the plain simulation of ``scenes`` on that worker; with two, the
    cores the two workers got (CPU over wall time of two plain halves of ``scenes`` at once)."""
    import ray

    import deforma.sweeps as sweeps

    if __name__ != "__main__":  # the worker cannot import this file: send the function itself
        ray.cloudpickle.register_pickle_by_value(sys.modules[__name__])
    t0 = time.perf_counter()
    sweeps.connect(workers=workers)
    startup = time.perf_counter() - t0
    try:
        warm = folder / "warm_up.toml"
        warm.write_text(WARM_UP)
        sweeps.sweep(warm, folder / f"warm-{tag}")
        plainly = ray.remote(num_cpus=1)(_simulate_plainly)
        plain = []
        if workers == 1:
            plain.append(ray.get(plainly.remote(scenes))[0])
        t0 = time.perf_counter()
        result = sweeps.sweep(spec, folder / f"out-{tag}")
        elapsed = time.perf_counter() - t0
        if (result.ran, result.ok) != (RUNS, RUNS):
            raise RuntimeError(f"the benchmark sweep did not run {RUNS} ok runs: {result}")
        if workers == 1:
            plain.append(ray.get(plainly.remote(scenes))[0])
            return startup, elapsed, statistics.mean(plain)
        # what the machine gave two workers: on a shared machine less than 2 cores, and then
        # no sweep can be 2x faster with 2 workers than with one
        halves = ray.get([plainly.remote(scenes[:RUNS // 2]), plainly.remote(scenes[RUNS // 2:])])
        return startup, elapsed, sum(cpu for _, cpu in halves) / max(wall for wall, _ in halves)
    finally:
        ray.shutdown()


def run(quick: bool) -> list[Row]:
    import importlib.util

    import deforma.sweeps as sweeps

    missing = [m for m in ("ray", "pyarrow") if importlib.util.find_spec(m) is None]
    if missing:  # the rest of `benchmarks/run.py` must not need the sweep extra
        print(f"sweep: skipped, {' and '.join(missing)} not installed (pip install '.[sweep]')", file=sys.stderr)
        return []

    rounds = 1 if quick else 3
    folder = Path(tempfile.mkdtemp(prefix="deforma-bench-sweep-"))
    spec = folder / "bench.toml"
    spec.write_text(SPEC)
    scenes = [sweeps.scene_for(sweeps.load_spec(spec), r.parameters, source="bench")
              for r in sweeps.plan(sweeps.load_spec(spec))]
    plain, cores, startups, per = [], [], [], {1: [], 2: []}
    for k in range(rounds):
        print(f"sweep: round {k + 1}/{rounds}, load average {os.getloadavg()[0]:.2f}", file=sys.stderr)
        for workers in (1, 2):
            startup, elapsed, extra = _timed_sweep(spec, workers, folder, f"{k}-{workers}", scenes)
            startups.append(startup)
            per[workers].append(elapsed)
            (plain if workers == 1 else cores).append(extra)
            print(f"sweep: {workers} worker{'s' if workers > 1 else ''}: start-up {startup:.1f} s, {RUNS} runs in "
                  f"{elapsed:.2f} s" + (f", plainly simulated in {extra:.2f} s" if workers == 1 else
                                        f", the two workers got {extra:.2f} cores")
                  + f"; load average {os.getloadavg()[0]:.2f}", file=sys.stderr)
    print(f"sweep: done, load average {os.getloadavg()[0]:.2f}", file=sys.stderr)

    simulation = statistics.median(plain) / RUNS
    one, two = statistics.median(per[1]), statistics.median(per[2])
    speedup = one / two
    # per round: each timed sweep against the simulation measured around it, then the median
    overheads = [(s - p) / p for s, p in zip(per[1], plain)]
    overhead = statistics.median(overheads)
    return [
        Row("sweep", "Ray local cluster start-up (not in the figures below)", statistics.median(startups), "s",
            goal="informational"),
        Row("sweep", f"one {SECONDS:g} s `sample` run simulated plainly on a worker", simulation, "s",
            goal="informational (the simulation)"),
        Row("sweep", f"{RUNS} runs of `sample` {SECONDS:g} s, 1 worker", 60 * RUNS / one, "runs/min",
            goal="informational"),
        Row("sweep", f"{RUNS} runs of `sample` {SECONDS:g} s, 2 workers", 60 * RUNS / two, "runs/min",
            ratio=f"{speedup:.2f}x 1 worker", goal=">= 1.7x 1 worker", met=speedup >= 1.7),
        Row("sweep", "cores the 2 workers got (CPU / wall time of 2 plain tasks at once)", statistics.median(cores),
            "cores", goal="informational: below 2, the machine is shared"),
        Row("sweep", "overhead per run, 1 worker (all but the simulation)", 100 * overhead,
            f"% of a {SECONDS:g} s `sample` run", ratio=f"{overhead * simulation * 1000:.0f} ms/run",
            goal="< 10 %", met=overhead < 0.10),
    ]


if __name__ == "__main__":
    print(format_table(run(quick="--quick" in sys.argv)))

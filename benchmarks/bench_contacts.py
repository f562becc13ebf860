"""Contact benchmark: what the body contact stage costs, in a heap and for one big body.

*Heaps.* 10 to 200 bodies of about 500 vertices (bunnies, donuts, armadillos at resolution
13 and boxes of detail 20, each ~0.7 m across, 1 kg, 5000 N/m springs) are dropped in five
rows into a container as wide as the heap needs, at dt = 1/600 s with the substeps
``stable_dt()`` asks for, and stepped for 1.5 s, so that they lie on each other in a heap.
Every heap is five rows high, so that a body has about as many neighbours in each; a
deeper heap costs more per body, since the stage's work follows the contacts per body. From that state, K steps with contacts on and K steps with every body's
``collide`` and ``self_collision`` off are timed in turns (the state put back before each
batch, so both run from the same heap), 9 rounds, medians compared. The stage's cost is the
difference; its share is that over the full step. Linear growth means the stage's time per
body stays about the same from 10 to 200 bodies.

*One big body.* The bench_physics body (a 1 m square of 316 x 316 vertices on the floor, at
half its stable step) with its self contact on (the default: the stage tests its 1,260
outline vertices every substep) and off, timed the same way.

*The demo's bunny.* The ``demo`` scene's first 4 s with the bunny's self contact on and
off: a small body (~1,000 vertices) that flexes and touches itself most substeps, where the
stage's fixed cost per substep shows.

Command: ``python benchmarks/run.py --only contacts`` (``--quick`` stops at 50 bodies and a
100 x 100 body).
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from pathlib import Path


sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_physics import grid_mesh  # noqa: E402
from common import Row  # noqa: E402

import deforma  # noqa: E402

SIZE = 0.7  # m, each body's extent


def body_meshes():
    half = SIZE / 2
    return [deforma.mesh.from_image(name, resolution=13, detect_edges=True, edge_step=9, scale=SIZE / 560)
            for name in ("bunny", "donut", "armadillo")] + \
        [deforma.mesh.box(((-half, -half), (half, -half), (half, half), (-half, half)), detail=20, edges=True)]


ROWS = 5  # every heap is as high: wider for more bodies, so each body has as many neighbours


def heap_world(n_bodies: int):
    """``n_bodies`` bodies poured in ``ROWS`` rows into a container, settled for 1.5 s."""
    per_row = math.ceil(n_bodies / ROWS)
    width = per_row * (SIZE + 0.15)
    w = deforma.World(sleep=False, dt=1 / 600, integrator="symplectic-euler", stiffness=5000.0, damping=0.5,
                      friction=0.4, static_friction=0.6, air_drag=0.5)
    w.add_collider(deforma.Rect((0.0, -0.25), (width + 1.0, 0.5), 0.0))
    for side in (-1, 1):
        w.add_collider(deforma.Rect((side * (width / 2 + 0.3), 10.0), (0.4, 20.0), 0.0))
    meshes = body_meshes()
    for k in range(n_bodies):
        row, col = divmod(k, per_row)
        x = -width / 2 + (col + 0.5) * (SIZE + 0.15)
        w.add_body(meshes[(k + row) % len(meshes)], position=(x, 0.5 + row * (SIZE + 0.1)))
    w.substeps = math.ceil(w.dt / w.stable_dt())  # within the stable step, as a careful user would
    for _ in range(int(1.5 / w.dt)):
        w.step()
    return w


def _set_contacts(w, on: bool):
    for b in w.bodies:
        b.collide = on
        b.self_collision = on


def on_off(w, *, steps: int, rounds: int) -> tuple[float, float]:
    """Median seconds per step with contacts on and off, timed in turns from one state."""
    x, v, t = w._state.x.copy(), w._state.v.copy(), w.time
    times = {True: [], False: []}
    for _ in range(rounds):
        for on in (True, False):
            w._state.x[...] = x  # the heap first: switching contacts on checks for overlaps
            w._state.v[...] = v
            _set_contacts(w, on)
            w.step()  # one untimed step after switching
            t0 = time.perf_counter()
            for _ in range(steps):
                w.step()
            times[on].append((time.perf_counter() - t0) / steps)
    w._state.x[...] = x
    w._state.v[...] = v
    _set_contacts(w, True)
    w.time = t
    return statistics.median(times[True]), statistics.median(times[False])


def run(quick: bool = False) -> list[Row]:
    rows = []
    counts = (10, 25, 50) if quick else (10, 25, 50, 100, 200)
    per_body = []
    for n in counts:
        w = heap_world(n)
        on, off = on_off(w, steps=3 if n > 50 else 10, rounds=5 if quick else 9)
        stage = on - off
        per_body.append(stage / n)
        w.step()
        contacts = len(w.contacts)
        rows.append(Row("contacts", f"heap of {n} bodies, {w._model.n_vertices} vertices: step with contacts",
                        on, "s", f"{contacts / n:.0f} contacts per body; the stage {stage * 1e3:.3g} ms = "
                                 f"{stage / on:.0%} of the step ({stage / n * 1e6:.3g} us per body)"))
        rows.append(Row("contacts", f"heap of {n} bodies: same step, contacts off", off, "s"))
    growth = per_body[-1] / per_body[0]
    rows.append(Row("contacts", f"stage time per body, {counts[-1]} vs {counts[0]} bodies", growth, "x",
                    "", "about linear growth: per body within 2x", growth < 2.0))
    n = 100 if quick else 316
    w = deforma.World(sleep=False, dt=1 / 600, integrator="symplectic-euler", stiffness=2000.0, damping=0.5, mass=1.0)
    w.add_collider(deforma.Rect((0.0, -0.25), (4.0, 0.5), 0.0))
    w.add_collider(deforma.Rect((-1.2, 0.5), (0.8, 0.1), 30.0))
    w.add_collider(deforma.Rect((1.0, 0.1), (0.2, 0.2), 10.0))
    body = w.add_body(grid_mesh(n), position=(0.0, 0.5 + 1e-6))
    w.dt = 0.5 * w.stable_dt()
    for _ in range(200):
        w.step()
    x, v = w._state.x.copy(), w._state.v.copy()
    times = {True: [], False: []}
    for _ in range(5 if quick else 11):
        for on in (True, False):
            w._state.x[...] = x
            w._state.v[...] = v
            body.self_collision = on
            w.step()
            t0 = time.perf_counter()
            for _ in range(20):
                w.step()
            times[on].append((time.perf_counter() - t0) / 20)
    on, off = statistics.median(times[True]), statistics.median(times[False])
    rows.append(Row("contacts", f"one body, {body.n_vertices} vertices: step with self contact", on, "s",
                    f"{on / off:.2f}x the step without it", "<= 1.3x (with the stage on)", on / off <= 1.3))
    rows.append(Row("contacts", f"one body, {body.n_vertices} vertices: step, self contact off", off, "s"))
    rows += demo_rows(rounds=3 if quick else 7)
    return rows


def demo_rows(*, rounds: int) -> list[Row]:
    """The ``demo`` scene's first 4 s (the bunny lands, flexes and rolls: self contacts most
    substeps), with its self contact on and off, in turns from a fresh load."""
    from deforma.scene.build import load_scene

    times = {True: [], False: []}
    for _ in range(rounds):
        for on in (True, False):
            w = load_scene("demo")
            w.bodies[0].self_collision = on
            n = round(4.0 / w.dt)
            w.step()
            t0 = time.perf_counter()
            for _ in range(n):
                w.step()
            times[on].append(time.perf_counter() - t0)
    on, off = statistics.median(times[True]), statistics.median(times[False])
    return [Row("contacts", "demo scene, 4 s: physics with self contact", on, "s",
                f"{on / off:.2f}x the same without it"),
            Row("contacts", "demo scene, 4 s: physics, self contact off", off, "s")]


if __name__ == "__main__":
    from common import format_table

    print(format_table(run(quick="--quick" in sys.argv)))

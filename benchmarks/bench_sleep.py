"""Sleeping: what a step costs when every body sleeps, against the same world awake.

``deforma.World(sleep=True)`` lets islands of bodies at rest fall asleep
(:mod:`deforma.physics.sleeping`: every vertex slower than 5 mm/s for 0.5 s); when every body
sleeps, ``world.step()`` integrates nothing. The issue asks that a 200-body heap cost at least
10x less a step asleep than awake. deforma runs ``avbd``, its default, at ``dt = 1/60 s``, one
step a frame, gravity 9.81 m/s^2, friction 0.5 (``friction`` and ``static_friction``).

Cases:

- *heap*: 200 bodies poured in 5 rows of 40 into a container (a floor whose top is y = 0 and
  two walls 5 cm beyond the outer columns): every fourth one a soft box (0.16 m,
  ``corotated``, E = 2e4 Pa, nu = 0.3, 100 kg/m^2, damping 0.05 s; 36 vertices), the others
  rigid boxes (0.2 m, 100 kg/m^2; 16 vertices), tilted by -10, 0 or 10 degrees (the soft ones
  15) so that they tumble as they land, every other row 4 cm to the side. Five rows high, as
  ``bench_contacts.py``'s heaps. ``tools/heap.py``'s heap (48 soft bodies of 169 vertices at
  1/60 s) is another workload and is not reused;
- *heap of 50*: the same in 5 rows of 10, the one heap of those tried that falls asleep on
  its own (after 3.6 s): heaps of 10, 25, 40, 100 and 200 bodies in 5 rows were not all
  asleep after 30 s, nor 75 after 20 s. In them a few bodies (in the 200: 5 to 15, most in a
  cluster against a wall) keep moving at 5-40 mm/s, and as a heap is one island, or a few,
  they keep the rest awake or wake it again;
- *stack*: ``bench_rigid.py``'s stack, 10 rigid boxes of 0.4 x 0.2 m on its floor (its
  ``deforma_world``, with ``sleep`` switched on).

Each world is stepped with ``sleep=True`` until every body sleeps, at most ``SETTLE_CAP``
simulated seconds (30 s for the heaps, 10 s for the stack); the simulated time that took is a
row, whose goal is that it happens within the cap. Bodies still awake at the cap are put to
sleep by hand (``body.sleeping = True``, their island with them, velocities zeroed), so that
the asleep step is measured anyway; the row says so. Then a ``copy.deepcopy`` of the settled
world with ``twin.sleep = False`` is the same world awake. The two take turns, after 5
untimed steps each: rounds of ``steps`` steps of the awake twin (7 x 30 for the 200-body
heap, 7 x 60 for the others; ``--quick``: only the heap of 50 and the stack, 3 x 15 and
3 x 30) and of ``ASLEEP_BATCH`` times as many steps of the sleeping world, whose steps take
microseconds; each round is timed as a whole (``perf_counter``), the speed is the median over
the rounds of the steps per second, and the ratio is the sleeping world's speed over the
awake twin's (the awake cost of a step over the asleep cost). The sleeping world's row also
gives the CPU time over the wall time of its timed steps (avbd may use both cores of the VM)
and says if any body woke while timed.

Command: ``python benchmarks/run.py --only sleep`` (or ``python benchmarks/bench_sleep.py
[--quick]``); under 2 minutes on the 2-core VM, most of it the 200-body heap's 30 s.
"""

from __future__ import annotations

import copy
import gc
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_rigid  # the stack and its floor
from common import Row

import deforma

H = 1 / 60
G = 9.81
RHO = 100.0  # kg/m^2
FRICTION = 0.5
RIGID = deforma.Material("rigid", density=RHO)
SOFT = deforma.Material("corotated", youngs_modulus=2e4, poisson_ratio=0.3, density=RHO, damping=0.05)
RIGID_SIZE, SOFT_SIZE = 0.2, 0.16  # m, box sides
PITCH = RIGID_SIZE + 0.08  # m between columns
ROW_GAP = RIGID_SIZE + 0.1  # m between rows
HEAP_BODIES, HEAP_ROWS = 200, 5
SMALL_HEAP = 50  # 5 rows of 10: the one heap tried that falls asleep on its own
SOFT_EVERY = 4  # every fourth body is soft
SETTLE_CAP = {"heap": 30.0, "stack": 10.0}  # simulated s at most to fall asleep
ASLEEP_BATCH = 10  # the sleeping world steps this many times the awake twin's steps a round
WARMUP_STEPS = 5
GOAL = 10.0  # the heap costs at least 10x less a step asleep than awake


def _square(side: float, detail: int):
    h = side / 2
    return deforma.mesh.box(((-h, -h), (h, -h), (h, h), (-h, h)), detail=detail)


def heap_world(n_bodies: int = HEAP_BODIES, rows: int = HEAP_ROWS) -> deforma.World:
    """``n_bodies`` boxes in ``rows`` rows above a container, not yet stepped (``sleep=True``):
    every ``SOFT_EVERY``-th one soft, the others rigid (module docstring)."""
    cols = -(-n_bodies // rows)
    width = cols * PITCH
    w = deforma.World(dt=H, gravity=(0.0, -G), friction=FRICTION, static_friction=FRICTION, sleep=True)
    w.add_collider(deforma.Rect((0.0, -0.25), (width + 1.0, 0.5), 0.0))  # floor, top at y = 0
    for side in (-1, 1):  # walls, inner faces 5 cm beyond the outermost columns' reach
        w.add_collider(deforma.Rect((side * (width / 2 + 0.25), 2.5), (0.4, 5.0), 0.0))
    rigid_box, soft_box = _square(RIGID_SIZE, 2), _square(SOFT_SIZE, 4)
    for k in range(n_bodies):
        row, col = divmod(k, cols)
        x = -width / 2 + (col + 0.5) * PITCH + 0.04 * (row % 2 - 0.5)
        y = 0.3 + row * ROW_GAP
        if k % SOFT_EVERY == SOFT_EVERY - 1:
            w.add_body(soft_box, position=(x, y), angle=15.0, material=SOFT)
        else:
            w.add_body(rigid_box, position=(x, y), angle=10.0 * (k % 3 - 1), material=RIGID)
    return w


def stack_world() -> deforma.World:
    """``bench_rigid.py``'s 10-box stack on its floor, with ``sleep=True``."""
    w, _ = bench_rigid.deforma_world(bench_rigid.stack_boxes())
    w.sleep = True
    return w


def all_asleep(w) -> bool:
    return all(b.sleeping for b in w.bodies)


def settle(w, cap: float) -> dict:
    """Step ``w`` until every body sleeps or ``cap`` simulated s have passed.

    Returns {"asleep_at": simulated s when every body slept (None if not within the cap),
    "wall": s of wall time it took, "asleep": bodies asleep at the end, "steps": steps taken,
    "cap": ``cap``}.
    """
    t0 = time.perf_counter()
    steps = 0
    while not all_asleep(w) and steps * w.dt < cap - 1e-9:
        w.step()
        steps += 1
    done = all_asleep(w)
    return {"asleep_at": steps * w.dt if done else None, "wall": time.perf_counter() - t0,
            "asleep": sum(b.sleeping for b in w.bodies), "steps": steps, "cap": cap}


def timed_rates(worlds: dict, rounds: int, steps: dict) -> dict:
    """{name: (median steps/s over the rounds, CPU time / wall time)}: the worlds take turns,
    ``steps[name]`` steps each a round, each round timed as a whole; ``WARMUP_STEPS`` untimed
    steps each first."""
    for w in worlds.values():
        for _ in range(WARMUP_STEPS):
            w.step()
    rates = {name: [] for name in worlds}
    wall = dict.fromkeys(worlds, 0.0)
    cpu = dict.fromkeys(worlds, 0.0)
    for _ in range(rounds):
        for name, w in worlds.items():
            n = steps[name]
            gc.collect()
            c0, t0 = time.process_time(), time.perf_counter()
            for _ in range(n):
                w.step()
            t1, c1 = time.perf_counter(), time.process_time()
            rates[name].append(n / (t1 - t0))
            wall[name] += t1 - t0
            cpu[name] += c1 - c0
    return {name: (statistics.median(rates[name]), cpu[name] / wall[name]) for name in worlds}


def measure(case: str, rounds: int, steps: int, *, bodies: int = HEAP_BODIES, rows: int = HEAP_ROWS,
            cap: float | None = None) -> dict:
    """Settle ``case`` ("heap" of ``bodies`` bodies in ``rows`` rows, or "stack") with sleep on, then time it
    asleep against a deepcopy of it awake (module docstring). If some bodies are still awake
    at the cap, their islands are put to sleep by hand (``body.sleeping = True``, which also
    zeroes their velocities) before the copy, so that the asleep step is measured anyway.

    Returns {"bodies", "soft", "vertices", "settle" (``settle``'s dict), "put_to_sleep"
    (bodies put to sleep by hand), "asleep_sps", "awake_sps", "asleep_cpu", "awake_cpu",
    "ratio" (asleep steps/s over awake steps/s), "still_asleep" (every body of the sleeping
    world asleep after the timed rounds), "timed_steps" (the awake twin's; the sleeping
    world's are ASLEEP_BATCH times as many)}.
    """
    w = heap_world(bodies, rows) if case == "heap" else stack_world()
    s = settle(w, SETTLE_CAP[case] if cap is None else cap)
    awake = [b for b in w.bodies if not b.sleeping]
    for b in awake:
        if not b.sleeping:  # an earlier one's island may have taken it along
            b.sleeping = True
    twin = copy.deepcopy(w)
    twin.sleep = False
    r = timed_rates({"asleep": w, "awake": twin}, rounds, {"asleep": steps * ASLEEP_BATCH, "awake": steps})
    return {"bodies": len(w.bodies), "soft": sum(not b.material.is_rigid for b in w.bodies),
            "vertices": sum(b.n_vertices for b in w.bodies), "settle": s, "put_to_sleep": len(awake),
            "asleep_sps": r["asleep"][0], "awake_sps": r["awake"][0],
            "asleep_cpu": r["asleep"][1], "awake_cpu": r["awake"][1],
            "ratio": r["asleep"][0] / r["awake"][0], "still_asleep": all_asleep(w), "timed_steps": rounds * steps}


def case_rows(case: str, m: dict) -> list[Row]:
    """The rows of one case's ``measure``: asleep (with the ratio), awake, the time to fall asleep."""
    s = m["settle"]
    cap = s["cap"]
    if case == "heap":
        what = (f"heap of {m['bodies']} bodies ({m['bodies'] - m['soft']} rigid, {m['soft']} soft; "
                f"{m['vertices']} vertices)")
        goal, met = f">= {GOAL:g}x cheaper a step asleep than awake", m["ratio"] >= GOAL
        if m["bodies"] != HEAP_BODIES:
            goal, met = "", None  # the goal is the 200-body heap's
    else:
        what = f"stack of {m['bodies']} rigid boxes ({m['vertices']} vertices)"
        goal, met = "", None
    slept = ("every body fell asleep" if not m["put_to_sleep"] else
             f"{m['put_to_sleep']} of {m['bodies']} still awake after {cap:g} s were put to sleep by hand")
    if not m["still_asleep"]:
        slept += "; some woke while timed"
    return [
        Row("sleep", f"{what}, 1/60 s, settled, asleep ({slept})", m["asleep_sps"], "steps/s",
            f"{m['ratio']:.3g}x cheaper a step than awake; CPU/wall {m['asleep_cpu']:.2f}", goal, met),
        Row("sleep", f"  same world awake (deepcopy, sleep off), {m['timed_steps']} timed steps", m["awake_sps"],
            "steps/s", f"CPU/wall {m['awake_cpu']:.2f}"),
        Row("sleep", f"  {case} of {m['bodies']}: simulated time until every body slept", s["steps"] * H, "s",
            (f"{s['wall']:.1f} s of wall time" if s["asleep_at"] is not None else
             f"never all asleep: {s['asleep']} of {m['bodies']} at the cap; {s['wall']:.1f} s of wall time"),
            f"every body asleep within {cap:g} s", s["asleep_at"] is not None),
    ]


def run(quick: bool) -> list[Row]:
    rows: list[Row] = []
    plan = [("heap", 50, 3, 15), ("stack", 0, 3, 30)] if quick else \
        [("heap", HEAP_BODIES, 7, 30), ("heap", SMALL_HEAP, 7, 60), ("stack", 0, 7, 60)]
    for case, bodies, rounds, steps in plan:  # bodies: the heap's (the stack has its 10)
        rows += case_rows(case, measure(case, rounds, steps, bodies=bodies))
    return rows


if __name__ == "__main__":
    from common import format_table

    print(format_table(run(quick="--quick" in sys.argv)))

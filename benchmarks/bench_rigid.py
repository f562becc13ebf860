"""Rigid-body stacking: deforma's default integrator against pymunk (issue 49).

deforma runs ``avbd``, its default, which solves each rigid body (``Material("rigid")``) as one
block of its sweep, with its default options. The peer is pymunk (Chipmunk 2), the usual 2D
rigid-body engine for Python. Both get the same boxes, the same floor and the same step:

- gravity 9.81 m/s^2, ``dt = 1/60 s``, one step a frame (deforma: ``substeps=1``);
- boxes of density 100 kg/m^2 (the same masses; pymunk's moments are a solid box's, as
  deforma's rigid bodies take theirs from the mesh);
- a fixed floor: a 10 x 1 m box whose top face is y = 0 (deforma's ``Rect`` collider, in pymunk
  a static ``Poly`` of the same corners);
- friction 0.5: pymunk has one coefficient, so deforma gets ``friction=0.5`` and
  ``static_friction=0.5``. pymunk takes the product of the two shapes' coefficients, so every
  pymunk shape gets sqrt(0.5) and every pair, box on box or box on floor, 0.5.

pymunk runs twice, with its default 10 solver iterations and no sleeping (its default) both
times: once with ``collision_slop`` (the overlap it leaves uncorrected) set to 5 mm, Box2D's
slop for a world in metres, and once with every default, whose slop of 0.1 (meant for pixels)
is half a box's height here. Boxes are ``pymunk.Poly.create_box``, radius 0.

Two cases:

- *stack*: 10 boxes of 0.4 x 0.2 m, each 1 mm above the one below and 1 cm to the side of it
  every other box (x = 0.01 (i mod 2), y = 0.1 + 0.201 i);
- *pyramid*: 20 rows of 0.2 m boxes (210 boxes), row r holding 20 - r boxes at
  x = (c - (20 - r - 1) / 2) 0.202, y = 0.1 + 0.201 r.

Each engine first runs one simulated second (60 steps, untimed: deforma compiles its kernels
and the boxes land), and each box's centre there is its reference. Then the engines take turns,
rounds of a fixed number of steps each (stack 10 x 60, pyramid 10 x 60; ``--quick``:
4 x 30 and 4 x 15); only the ``step()`` calls are timed. The speed is the median over the rounds
of the steps per second; the accuracy is the largest distance of any box centre from its
reference at any step of those rounds (``drift``) and the fastest box centre at the end; the
rows also give the largest distance of a box centre at the end from where it was placed (an
engine that closed the 1 mm gaps exactly would move the stack's top box 9 mm down, the
pyramid's 19 mm; deforma's contacts keep them), which shows what the first second did: pymunk
lets boxes in contact overlap by up to its slop, and its pyramid sinks into itself then.
pymunk runs on one thread; deforma's row gives its CPU time over its wall time while timed
(about 1 for one thread; avbd may use both cores of the VM for its vertex sweeps).

``pymunk`` is not a dependency of deforma: without it this module prints one line and gives
no rows (``pip install pymunk``).
"""

from __future__ import annotations

import gc
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Row

import deforma

H = 1 / 60
G = 9.81
RHO = 100.0  # kg/m^2
FRICTION = 0.5  # both engines; pymunk multiplies the two shapes' coefficients
SLOP = 0.005  # m, pymunk's collision_slop for a world in metres (Box2D's linear slop)
FLOOR_CENTRE, FLOOR_SIZE = (0.0, -0.5), (10.0, 1.0)  # top face at y = 0
SETTLE_STEPS = 60  # one simulated second before the reference positions
PYRAMID_GOAL = 3.0  # deforma's pyramid within 3x pymunk's steps/s


def stack_boxes(n: int = 10) -> list[tuple[float, float, float, float]]:
    """The stack as (x, y, width, height) of each box's centre and size, bottom first."""
    return [(0.01 * (i % 2), 0.1 + 0.201 * i, 0.4, 0.2) for i in range(n)]


def pyramid_boxes(rows: int = 20) -> list[tuple[float, float, float, float]]:
    """The pyramid as (x, y, width, height): row r holds rows - r boxes of 0.2 m."""
    return [((c - (rows - r - 1) / 2) * 0.202, 0.1 + r * 0.201, 0.2, 0.2)
            for r in range(rows) for c in range(rows - r)]


CASES = {"stack": stack_boxes, "pyramid": pyramid_boxes}


def deforma_world(boxes):
    """A World holding ``boxes`` as rigid bodies on the floor; returns (world, bodies)."""
    w = deforma.World(sleep=False, dt=H, substeps=1, gravity=(0.0, -G), friction=FRICTION, static_friction=FRICTION)
    w.add_collider(deforma.Rect(FLOOR_CENTRE, FLOOR_SIZE, 0.0))
    rigid = deforma.Material("rigid", density=RHO)
    bodies = [w.add_body(deforma.mesh.box(((0, 0), (bw, 0), (bw, bh), (0, bh)), detail=2),
                         position=(x, y), material=rigid) for x, y, bw, bh in boxes]
    return w, bodies


def pymunk_space(boxes, *, slop: float | None = SLOP):
    """A pymunk Space holding ``boxes`` on the floor; returns (space, bodies). ``slop=None``
    keeps pymunk's default collision_slop. Raises ImportError without pymunk."""
    import pymunk

    space = pymunk.Space()  # iterations 10, no sleeping: pymunk's defaults
    space.gravity = (0.0, -G)
    if slop is not None:
        space.collision_slop = slop
    mu = math.sqrt(FRICTION)  # pymunk's pair friction is the product of the two shapes'
    (cx, cy), (fw, fh) = FLOOR_CENTRE, FLOOR_SIZE
    floor = pymunk.Poly(space.static_body, [(cx - fw / 2, cy - fh / 2), (cx + fw / 2, cy - fh / 2),
                                             (cx + fw / 2, cy + fh / 2), (cx - fw / 2, cy + fh / 2)])
    floor.friction = mu
    space.add(floor)
    bodies = []
    for x, y, bw, bh in boxes:
        body = pymunk.Body()
        shape = pymunk.Poly.create_box(body, (bw, bh))
        shape.density = RHO
        shape.friction = mu
        body.position = (x, y)
        space.add(body, shape)
        bodies.append(body)
    return space, bodies


def engines(case: str, *, with_pymunk: bool = True) -> dict:
    """{name: (step, centres, speeds, masses)} for ``case``: ``centres()`` (n, 2) m,
    ``speeds()`` (n,) m/s of the box centres, ``masses`` (n,) kg."""
    boxes = CASES[case]()
    out = {}
    w, bodies = deforma_world(boxes)
    out["deforma avbd"] = (w.step,
                           lambda bodies=bodies: np.array([b.center_of_mass for b in bodies]),
                           lambda bodies=bodies: np.array([math.hypot(*b.velocity) for b in bodies]),
                           np.array([b.mass for b in bodies]))
    if with_pymunk:
        for name, slop in ((f"pymunk, slop {SLOP * 1000:g} mm", SLOP), ("pymunk defaults, slop 0.1", None)):
            space, pbodies = pymunk_space(boxes, slop=slop)
            out[name] = (lambda space=space: space.step(H),
                         lambda pb=pbodies: np.array([tuple(b.position) for b in pb]),
                         lambda pb=pbodies: np.array([b.velocity.length for b in pb]),
                         np.array([b.mass for b in pbodies]))
    return out


def measure(case: str, rounds: int, steps: int, *, with_pymunk: bool = True) -> dict:
    """Each engine's figures for ``case``: one simulated second untimed, then ``rounds`` turns of
    ``steps`` steps each, engine after engine.

    Returns {name: {"steps_per_s", "cpu_share", "drift", "end_speed", "off_placement",
    "boxes"}}: the median over the rounds of steps per second (wall time of the ``step()`` calls
    alone), their CPU time over their wall time, the largest distance (m) of any box centre at
    any step from where it was after the first second, the fastest box centre (m/s) at the end,
    and the largest distance (m) of any box centre at the end from where it was placed.
    """
    eng = engines(case, with_pymunk=with_pymunk)
    placed = {name: centres() for name, (_, centres, _, _) in eng.items()}
    ref, drift, wall, cpu, rates = {}, {}, {}, {}, {}
    for name, (step, centres, _, _) in eng.items():
        for _ in range(SETTLE_STEPS):
            step()
        ref[name] = centres()
        drift[name], wall[name], cpu[name], rates[name] = 0.0, 0.0, 0.0, []
    for _ in range(rounds):
        for name, (step, centres, _, _) in eng.items():
            gc.collect()
            spent = 0.0
            for _ in range(steps):
                c0, t0 = time.process_time(), time.perf_counter()
                step()
                t1, c1 = time.perf_counter(), time.process_time()
                spent += t1 - t0
                cpu[name] += c1 - c0
                drift[name] = max(drift[name], float(np.hypot(*(centres() - ref[name]).T).max()))
            wall[name] += spent
            rates[name].append(steps / spent)
    return {name: {"steps_per_s": statistics.median(rates[name]), "cpu_share": cpu[name] / wall[name],
                   "drift": drift[name], "end_speed": float(speeds().max()), "boxes": len(masses),
                   "off_placement": float(np.hypot(*(centres() - placed[name]).T).max())}
            for name, (_, centres, speeds, masses) in eng.items()}


def run(quick: bool) -> list[Row]:
    try:
        import pymunk
    except ImportError as err:
        print(f"rigid: pymunk not installed ({err}); rows skipped (pip install pymunk)", file=sys.stderr)
        return []
    plan = {"stack": (4, 30) if quick else (10, 60), "pyramid": (4, 15) if quick else (10, 60)}
    rows: list[Row] = []
    for case, (rounds, steps) in plan.items():
        m = measure(case, rounds, steps)
        d = m.pop("deforma avbd")
        main = m[f"pymunk, slop {SLOP * 1000:g} mm"]
        ratio = main["steps_per_s"] / d["steps_per_s"]

        def accuracy(r: dict) -> str:
            return (f"drift {r['drift'] * 1000:.3g} mm, end speed {r['end_speed'] * 1000:.2g} mm/s, "
                    f"{r['off_placement'] * 1000:.3g} mm off placement")

        title = (f"{case} ({d['boxes']} boxes), 1/60 s x 1, drift over {rounds * steps} steps after 1 s, "
                 f"deforma avbd")
        goal, met = ("", None) if case != "pyramid" else (f"within {PYRAMID_GOAL:g}x pymunk's steps/s",
                                                        ratio <= PYRAMID_GOAL)
        rows.append(Row("rigid", title, d["steps_per_s"], "steps/s",
                        f"pymunk {ratio:.3g}x its steps/s; {accuracy(d)}; CPU/wall {d['cpu_share']:.2f}", goal, met))
        for name, r in m.items():
            rows.append(Row("rigid", f"  same, {name} (pymunk {pymunk.version}, 10 iterations)", r["steps_per_s"],
                            "steps/s", accuracy(r)))
    return rows


if __name__ == "__main__":
    from common import format_table

    print(format_table(run(quick="--quick" in sys.argv)))

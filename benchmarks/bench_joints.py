"""Joints: deforma's default integrator against pymunk, the peer of ``bench_rigid.py``.

deforma runs ``avbd``, its default, with every default but sleep (``deforma.World(sleep=False,
dt=1/60)``: the peers do not sleep): its pins are rows of the rigid blocks' sweep. The peer is pymunk (Chipmunk 2), the usual 2D rigid-body
engine for Python, with its defaults: 10 solver iterations, no sleeping, no damping. Both get
the same bodies, the same joints and the same step:

- gravity 9.81 m/s^2 down, ``dt = 1/60 s``, one step a frame (deforma's ``substeps`` left
  at its default, which is 1 under avbd);
- rigid boxes of density 100 kg/m^2 (the same masses; pymunk's moments are a solid box's, as
  deforma's rigid bodies take theirs from the mesh), ``pymunk.Poly.create_box`` of radius 0;
- pins (deforma's ``World.join``, pymunk's ``PivotJoint`` made from one world point) at the
  same points; deforma's joined bodies do not collide with each other, so every pymunk joint
  gets ``collide_bodies = False`` (the pairs it joins, and only those, do not collide).

Three cases:

- *chain*: 20 links of 0.02 x 0.098 m (0.196 kg) hanging from the world, each pinned 1 mm
  below its top to the one above (the first to the world at (0, -2 mm)), 2 mm apart, and a
  square weight of one link's mass pinned under the last (the helper ``chain`` below is the
  one of ``tests/physics/test_joints.py``);
- *heavy chain*: the same with a weight of 1000 links (196 kg, a 1.4 m square), the mass ratio
  an iterative solver finds hardest;
- *pendulum*: a 1 x 0.05 m bar hinged at the middle of one end to the world, let go at 60
  degrees from hanging (``tests/physics/test_joints.py``'s compound pendulum).

Each engine first runs one simulated second untimed (deforma loads or compiles its kernels).
Then the engines take turns, rounds of a fixed number of steps each (7 x 120; ``--quick``
3 x 60); only the ``step()`` calls are timed and the speed is the median over the rounds of
the steps per second. If the rounds end before the quality window (5 s for the chains, 8 s
for the pendulum) the engines run on untimed to its end. Quality, from t = 0:

- chains: the *stretch*, the largest distance the weight's centre moved up or down from where
  it was placed over the first 5 s, over the chain's 2 m, and the weight's speed at 5 s;
- pendulum: the period (the mean time between upward passes through hanging, interpolated
  between steps, over the first 8 s) against the analytic period of the compound pendulum at
  60 degrees (``scipy.special.ellipk``), and the swing kept: the largest swing over the last
  2 s of the 8 s over the 60 degrees it was let go at.

pymunk runs on one thread; deforma's row gives its CPU time over its wall time while timed.

``pymunk`` is not a dependency of deforma: without it this module prints one line and gives
no rows (``pip install pymunk``).
"""

from __future__ import annotations

import gc
import math
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "physics"))
from common import Row
from physics_meshes import chain  # the tests' chain, built the same here

import deforma

H = 1 / 60
G = 9.81
RHO = 100.0  # kg/m^2
RIGID = deforma.Material("rigid", density=RHO)
LINKS, LINK_LENGTH = 20, 0.1  # the chain: 2 m
WEIGHT_RATIO = {"chain": 1.0, "heavy chain": 1000.0}  # the weight, in links' masses
BAR = (1.0, 0.05)  # the pendulum's length and width (m)
AMPLITUDE = 60.0  # degrees from hanging
WINDOW = {"chain": 5.0, "heavy chain": 5.0, "pendulum": 8.0}  # s of simulation the quality covers
KEPT_OVER = 2.0  # s at the end of the pendulum's window whose largest swing is the swing kept
WARMUP_STEPS = 60  # one simulated second, untimed
CASES = ("chain", "heavy chain", "pendulum")


def pymunk_chain(links, weight_ratio, length=0.1, width=0.02, gap=0.002):
    """``chain``'s bodies and pins in a pymunk Space; returns (space, bodies, weight), bodies
    the links then the weight. Raises ImportError without pymunk."""
    import pymunk

    space = pymunk.Space()  # iterations 10, no sleeping, no damping: pymunk's defaults
    space.gravity = (0.0, -G)

    def box(w, h, centre):
        body = pymunk.Body()
        shape = pymunk.Poly.create_box(body, (w, h))
        shape.density = RHO
        body.position = centre
        space.add(body, shape)
        return body

    bodies = [box(width, length - gap, (0.0, -length / 2 - i * length)) for i in range(links)]
    side = math.sqrt(weight_ratio * bodies[0].mass / RHO)
    weight = box(side, side, (0.0, -links * length - side / 2 - gap))
    pins = [pymunk.PivotJoint(bodies[0], space.static_body, (0.0, -gap))]
    pins += [pymunk.PivotJoint(bodies[i], bodies[i - 1], (0.0, -i * length - gap)) for i in range(1, links)]
    pins.append(pymunk.PivotJoint(weight, bodies[-1], (0.0, -links * length - 1.5 * gap)))
    for pin in pins:
        pin.collide_bodies = False  # as deforma's joined bodies
    space.add(*pins)
    return space, bodies + [weight], weight


def _release(amplitude):
    """The bar's angle (degrees) and centre when let go ``amplitude`` degrees from hanging."""
    start = -90.0 + amplitude
    c, s = math.cos(math.radians(start)), math.sin(math.radians(start))
    return start, (BAR[0] / 2 * c, BAR[0] / 2 * s)


def deforma_pendulum(w, amplitude=AMPLITUDE):
    """The bar of ``tests/physics/test_joints.py``, hinged at (0, 0); returns (bar, hinge)."""
    length, width = BAR
    start, centre = _release(amplitude)
    m = deforma.mesh.box(((0, -width / 2), (length, -width / 2), (length, width / 2), (0, width / 2)), detail=2)
    body = w.add_body(m, position=centre, angle=start, material=RIGID)
    return body, w.join(body, None, at=(0.0, 0.0))


def pymunk_pendulum(amplitude=AMPLITUDE):
    """The same bar and hinge in a pymunk Space; returns (space, bar)."""
    import pymunk

    space = pymunk.Space()
    space.gravity = (0.0, -G)
    start, centre = _release(amplitude)
    body = pymunk.Body()
    shape = pymunk.Poly.create_box(body, BAR)
    shape.density = RHO
    body.position, body.angle = centre, math.radians(start)
    hinge = pymunk.PivotJoint(body, space.static_body, (0.0, 0.0))
    hinge.collide_bodies = False
    space.add(body, shape, hinge)
    return space, body


def pendulum_period(length, width, amplitude_deg):
    """A bar hinged at the middle of an end: the compound pendulum's period at this amplitude."""
    from scipy.special import ellipk

    inertia = (length ** 2 + width ** 2) / 12 + (length / 2) ** 2  # per unit mass, about the hinge
    t0 = 2 * math.pi * math.sqrt(inertia / (G * length / 2))
    return t0 * 2 / math.pi * ellipk(math.sin(math.radians(amplitude_deg) / 2) ** 2)


def swing_period(swing: np.ndarray) -> float:
    """The mean period (s) of a swing (degrees from hanging after each step, ``H`` apart) from
    its upward passes through hanging, interpolated between steps; nan with fewer than two."""
    t, a = np.arange(1, len(swing) + 1) * H, np.asarray(swing)
    up = np.flatnonzero((a[:-1] < 0) & (a[1:] >= 0))
    if len(up) < 2:
        return math.nan
    cross = t[up] + (t[up + 1] - t[up]) * (-a[up]) / (a[up + 1] - a[up])
    return float(np.mean(np.diff(cross)))


@dataclass
class Engine:
    """One engine's world for a case: ``step()``; ``sample()`` the figure followed (the
    weight's centre height (m) on a chain, the swing in degrees from hanging on the
    pendulum); ``speed()`` the weight's or bar's speed (m/s); ``masses`` (kg) and
    ``centres()`` (n, 2) m of its bodies; ``pins`` the world points its joints were made at."""

    step: Callable[[], object]
    sample: Callable[[], float]
    speed: Callable[[], float]
    masses: np.ndarray
    centres: Callable[[], np.ndarray]
    pins: np.ndarray


def engines(case: str, *, with_pymunk: bool = True) -> dict[str, Engine]:
    """{"deforma avbd": Engine, "pymunk": Engine} for ``case`` (one of ``CASES``)."""
    out = {}
    w = deforma.World(sleep=False, dt=H)  # avbd, every default but sleep
    if case == "pendulum":
        body, _ = deforma_pendulum(w)
        follow = body
        sample = lambda body=body: body.angle + 90.0  # noqa: E731
    else:
        follow, _ = chain(w, LINKS, WEIGHT_RATIO[case], RIGID, length=LINK_LENGTH)
        sample = lambda body=follow: float(body.center_of_mass[1])  # noqa: E731
    bodies = w.bodies
    out["deforma avbd"] = Engine(w.step, sample, lambda b=follow: float(np.hypot(*b.velocity)),
                                 np.array([b.mass for b in bodies]),
                                 lambda bodies=bodies: np.array([b.center_of_mass for b in bodies]),
                                 np.array([j.anchor for j in w.joints], float))
    if with_pymunk:
        if case == "pendulum":
            space, body = pymunk_pendulum()
            pbodies, follow = [body], body
            sample = lambda body=body: math.degrees(body.angle) + 90.0  # noqa: E731
        else:
            space, pbodies, follow = pymunk_chain(LINKS, WEIGHT_RATIO[case], length=LINK_LENGTH)
            sample = lambda body=follow: body.position.y  # noqa: E731
        out["pymunk"] = Engine(lambda space=space: space.step(H), sample, lambda b=follow: b.velocity.length,
                               np.array([b.mass for b in pbodies]),
                               lambda pb=pbodies: np.array([tuple(b.position) for b in pb]),
                               np.array([tuple(c.a.local_to_world(c.anchor_a)) for c in space.constraints]))
    return out


def quality(case: str, placed: float, samples: np.ndarray, speeds: np.ndarray) -> dict:
    """A case's quality figures from its window's samples and speeds after each step
    (``placed``: the sample before the first step)."""
    if case == "pendulum":
        kept = np.abs(samples[-round(KEPT_OVER / H):]).max() / AMPLITUDE
        period = swing_period(samples)
        return {"period_error": period / pendulum_period(*BAR, AMPLITUDE) - 1.0, "kept": float(kept),
                "period": period}
    return {"stretch": float(np.abs(placed - samples).max()) / (LINKS * LINK_LENGTH),
            "end_speed": float(speeds[-1])}


def measure(case: str, rounds: int, steps: int, *, warmup: int = WARMUP_STEPS, with_pymunk: bool = True) -> dict:
    """Each engine's figures for ``case``: ``warmup`` steps untimed, then ``rounds`` turns of
    ``steps`` steps each, engine after engine, then untimed steps to the end of the case's
    quality window if the rounds ended before it.

    Returns {name: {"steps_per_s", "cpu_share", "bodies", "timed_steps", **quality}}: the
    median over the rounds of steps per second (wall time of the ``step()`` calls alone), their
    CPU time over their wall time, and ``quality``'s figures over the first ``WINDOW[case]`` s.
    """
    eng = engines(case, with_pymunk=with_pymunk)
    window = round(WINDOW[case] / H)
    placed = {name: e.sample() for name, e in eng.items()}
    samples = {name: [] for name in eng}
    speeds = {name: [] for name in eng}
    wall = dict.fromkeys(eng, 0.0)
    cpu = dict.fromkeys(eng, 0.0)
    rates = {name: [] for name in eng}

    def record(name, e):
        samples[name].append(e.sample())
        speeds[name].append(e.speed())

    for name, e in eng.items():
        for _ in range(warmup):
            e.step()
            record(name, e)
    for _ in range(rounds):
        for name, e in eng.items():
            gc.collect()
            spent = 0.0
            for _ in range(steps):
                c0, t0 = time.process_time(), time.perf_counter()
                e.step()
                t1, c1 = time.perf_counter(), time.process_time()
                spent += t1 - t0
                cpu[name] += c1 - c0
                record(name, e)
            wall[name] += spent
            rates[name].append(steps / spent)
    for name, e in eng.items():
        while len(samples[name]) < window:
            e.step()
            record(name, e)
    return {name: {"steps_per_s": statistics.median(rates[name]), "cpu_share": cpu[name] / wall[name],
                   "bodies": len(e.masses), "timed_steps": rounds * steps,
                   **quality(case, placed[name], np.array(samples[name][:window]),
                             np.array(speeds[name][:window]))}
            for name, e in eng.items()}


def describe(case: str, r: dict) -> str:
    """A row's quality figures in words."""
    if case == "pendulum":
        return (f"period {r['period_error'] * 100:+.2g} % off the analytic {pendulum_period(*BAR, AMPLITUDE):.3f} s, "
                f"{r['kept'] * 100:.1f} % of the {AMPLITUDE:g} degree swing kept at {WINDOW[case]:g} s")
    return (f"stretch {r['stretch'] * 100:.3g} % over {WINDOW[case]:g} s, "
            f"weight speed at {WINDOW[case]:g} s {r['end_speed'] * 1000:.3g} mm/s")


def case_rows(case: str, m: dict, pymunk_version: str) -> list[Row]:
    """The rows of one case's ``measure``: deforma's, then pymunk's."""
    d, p = m["deforma avbd"], m["pymunk"]
    ratio = p["steps_per_s"] / d["steps_per_s"]
    what = ("compound pendulum (1 x 0.05 m bar, 60 degrees)" if case == "pendulum" else
            f"{case} ({LINKS} links, weight of {WEIGHT_RATIO[case]:g} link{'' if WEIGHT_RATIO[case] == 1 else 's'})")
    title = f"{what}, 1/60 s, {d['timed_steps']} timed steps, deforma avbd"
    return [Row("joints", title, d["steps_per_s"], "steps/s",
                f"pymunk {ratio:.3g}x its steps/s; {describe(case, d)}; CPU/wall {d['cpu_share']:.2f}"),
            Row("joints", f"  same, pymunk {pymunk_version} (10 iterations)", p["steps_per_s"], "steps/s",
                describe(case, p))]


def run(quick: bool) -> list[Row]:
    try:
        import pymunk
    except ImportError as err:
        print(f"joints: pymunk not installed ({err}); rows skipped (pip install pymunk)", file=sys.stderr)
        return []
    rounds, steps = (3, 60) if quick else (7, 120)
    rows: list[Row] = []
    for case in CASES:
        rows += case_rows(case, measure(case, rounds, steps), pymunk.version)
    return rows


if __name__ == "__main__":
    from common import format_table

    print(format_table(run(quick="--quick" in sys.argv)))

"""Integrators: one scene under every integrator, side by side in a video, and a plot of energy vs time.

Usage::

    python -m deforma.examples integrators                       # jelly scene at its own dt
    python -m deforma.examples integrators --dt 0.0166667 --substeps 4 \
        --video jelly_60hz.gif --plot jelly_60hz.png

(``python examples/compare_integrators.py`` from the repository root runs the same.)

By default it writes ``integrators.gif`` and ``integrators.png`` in the current folder; the
pictures in docs/ are made by naming them (docs/integrators.md, "Commands").

Each panel is the same scene (same bodies, stiffness, damping, friction) stepped by one
integrator: one panel, and one line in each plot, per registered integrator
(``deforma.physics.available_integrators()``; five today: symplectic-euler, implicit-euler,
xpbd, implicit-bdf2, avbd), so an integrator registered later is compared too. A panel
whose integrator becomes unstable freezes on the last good state and says so (the world
raises :class:`deforma.SimulationUnstable` with a hint; nothing NaN is drawn). The plot has
the total energy of each run over time and, as a reference for accuracy, the energy of a box
vibrating freely without damping (what each integrator adds or removes by itself) and the
period error of two masses on one spring against the step.

Needs the ``render`` extra (moderngl, imageio) and matplotlib.
"""

from __future__ import annotations

import argparse
import math
import time
import warnings
from pathlib import Path

import numpy as np

import deforma
from deforma.checks import StepBeyondStableWarning
from deforma.physics import SimulationUnstable, available_integrators

#: every registered integrator, in the registry's order (the original's symplectic Euler first)
INTEGRATORS = tuple(available_integrators())


def two_mass_period_error(integrator: str, h: float) -> float:
    """Relative error of the measured period of two 1.5 kg masses on a 150 N/m spring at step ``h``.

    Examples
    --------
    >>> abs(two_mass_period_error("symplectic-euler", 1e-3)) < 1e-4
    True
    """
    k = 150.0
    w = deforma.World(dt=h, gravity=(0, 0), mass=3.0, stiffness=k, damping=0.0, integrator=integrator)

    class Chain:
        vertices = np.array([[0.0, 0.0], [1.0, 0.0]])
        edges = np.array([[0, 1]])

    b = w.add_body(Chain(), position=None)
    b.positions[1, 0] = 1.1
    exact = 2 * math.pi * math.sqrt(0.75 / k)
    s = []
    for _ in range(int(round(4 * exact / h)) + 2):
        w.step()
        s.append(b.positions[1, 0] - b.positions[0, 0] - 1.0)
    s = np.array(s)
    up = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    tc = (up + 1 + (-s[up]) / (s[up + 1] - s[up])) * h
    return float(np.diff(tc).mean() / exact - 1)


def free_vibration_energy(integrator: str, dt: float, substeps: int, *, seconds: float = 2.0):
    """Energy over time (J, relative to the start) of a 1 m box (7 x 7 inside, 1500 N/m, 1 kg,
    no damping) stretched 10% sideways and let go, without gravity or colliders: what the
    integrator itself adds or removes.

    Returns ``(t, E / E0)`` arrays, or arrays cut at the step that became unstable.
    """
    w = deforma.World(dt=dt, substeps=substeps, gravity=(0, 0), mass=1.0, stiffness=1500.0, damping=0.0,
                      integrator=integrator)
    with warnings.catch_warnings():
        # an explicit integrator beyond its stable step is part of the comparison: the run
        # stops where it blows up and the plot labels it "(unstable)", so add_body's early
        # warning would only repeat that
        warnings.simplefilter("ignore", StepBeyondStableWarning)
        b = w.add_body(deforma.mesh.box(((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)), detail=7,
                                        edges=True), position=(0, 0))
    b.positions[:, 0] *= 1.1
    e0 = w.energy().total
    t, e = [0.0], [1.0]
    try:
        while w.time < seconds:
            w.step()
            t.append(w.time)
            e.append(w.energy().total / e0)
    except SimulationUnstable:
        pass
    return np.array(t), np.array(e)


def run(args) -> dict:
    """Step the scene under each integrator; write the video; return the energy traces."""
    from PIL import Image, ImageDraw

    from deforma.render import Renderer, WorldView, open_writer

    worlds, views, status, energy, cost = {}, {}, {}, {}, {}
    pw, ph = args.panel
    # one renderer (one GL context) draws every panel: each view draws its own meshes
    renderer = Renderer.headless((pw, ph)) if args.video else None
    for name in INTEGRATORS:
        w = deforma.load_scene(args.scene)
        w.integrator = name
        if args.dt is not None:
            w.dt = args.dt
        if args.substeps is not None:
            w.substeps = args.substeps
        worlds[name] = w
        if renderer is not None:
            views[name] = WorldView(renderer, w)
        status[name] = f"{name}  dt {w.dt * 1e3:.3g} ms x {w.substeps}"
        energy[name] = [(0.0, w.energy().total)]
        cost[name] = 0.0
    w0 = worlds[INTEGRATORS[0]]
    seconds = args.seconds
    fps = args.fps
    steps_per_frame = max(1, round(1 / (fps * w0.dt)))
    frames = int(seconds * fps)
    writer = open_writer(args.video, fps=fps) if args.video else None
    try:
        for _ in range(frames):
            panels = []
            for name in INTEGRATORS:
                w = worlds[name]
                if not status[name].endswith("UNSTABLE"):
                    t0 = time.perf_counter()
                    try:
                        for _ in range(steps_per_frame):
                            w.step()
                    except SimulationUnstable as e:
                        status[name] += " UNSTABLE"
                        print(f"{name}: {e}")
                    cost[name] += time.perf_counter() - t0
                    energy[name].append((w.time, w.energy().total))
                if writer is not None:
                    img = Image.fromarray(views[name].draw())
                    d = ImageDraw.Draw(img)
                    red = status[name].endswith("UNSTABLE")
                    d.text((8, 6), status[name], fill=(200, 30, 30) if red else (20, 20, 20))
                    d.text((8, 20), f"t = {w.time:5.2f} s", fill=(20, 20, 20))
                    panels.append(np.asarray(img))
            if writer is not None:
                writer.write(np.concatenate(panels, axis=1))
    finally:
        if writer is not None:
            writer.close()
        if renderer is not None:
            renderer.release()  # a live standalone context would hinder a window opened later
    for name in INTEGRATORS:
        print(f"{name:17s} cost {cost[name]:.2f} s for {worlds[name].time:.2f} simulated s; "
              f"energy {energy[name][0][1]:.3f} J -> {energy[name][-1][1]:.3f} J")
    return energy


def plot(energy: dict, args) -> None:
    """Energy vs time of the runs and the two-mass period error vs step, into one PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, c, b) = plt.subplots(1, 3, figsize=(15, 4.2))
    colors = {"symplectic-euler": "#e07a5f", "implicit-euler": "#3d9970", "xpbd": "#5b8def",
              "implicit-bdf2": "#9b5de5", "avbd": "#444444"}
    # an integrator registered later gets a colour of matplotlib's cycle that none of these uses
    spare = (col for col in plt.rcParams["axes.prop_cycle"].by_key()["color"] if col not in colors.values())
    for name in INTEGRATORS:
        colors.setdefault(name, next(spare, "#888888"))
    for name, trace in energy.items():
        t, e = np.array(trace).T
        a.plot(t, e, label=name, color=colors[name])
    a.set_xlabel("time (s)")
    a.set_ylabel("total energy (J)")
    dt = args.dt or deforma.load_scene(args.scene).dt
    a.set_title(f"scene '{args.scene}', dt = {dt * 1e3:.3g} ms")
    a.legend()
    scene_world = deforma.load_scene(args.scene)
    substeps = args.substeps or scene_world.substeps
    for name in INTEGRATORS:
        t, e = free_vibration_energy(name, dt, substeps)
        c.plot(t, e, label=name + ("" if t[-1] >= 2.0 - 1e-9 else " (unstable)"), color=colors[name])
        print(f"free vibration {name:17s}: E/E0 after {t[-1]:.2f} s = {e[-1]:.4f}")
    c.set_xlabel("time (s)")
    c.set_ylabel("energy / initial energy")
    c.set_title(f"free vibration, no damping, dt = {dt * 1e3:.3g} ms x {substeps}")
    c.set_ylim(0, 1.1)
    c.legend()
    steps = np.array([3e-4, 1e-3, 3e-3, 1e-2, 3e-2])
    for name in INTEGRATORS:
        err = []
        for h in steps:
            try:
                err.append(abs(two_mass_period_error(name, h)))
            except SimulationUnstable:
                err.append(np.nan)
        b.loglog(steps, err, "o-", label=name, color=colors[name])
    b.set_xlabel("step h (s)")
    b.set_ylabel("|period error| (relative)")
    # one spring: xpbd and avbd (order 1) solve backward Euler exactly, so their lines lie on
    # implicit-euler's; implicit-bdf2 leaves it only at the largest steps
    b.set_title("two masses, one spring\n(implicit-euler = xpbd = avbd here)")
    b.legend()
    fig.tight_layout()
    fig.savefig(args.plot, dpi=110)
    print(f"wrote {args.plot}")


def main(argv: list[str] | None = None) -> int:
    """Step the scene under every integrator; write the video and the plot."""
    p = argparse.ArgumentParser(prog="python -m deforma.examples integrators", description=__doc__.split("\n")[0])
    p.add_argument("--scene", default="jelly", help="built-in scene name or .toml path (default jelly)")
    p.add_argument("--seconds", type=float, default=4.0, help="simulated seconds (default 4)")
    p.add_argument("--dt", type=float, default=None, help="step in s for every integrator (default the scene's)")
    p.add_argument("--substeps", type=int, default=None, help="substeps for every integrator (default the scene's)")
    p.add_argument("--fps", type=float, default=30.0, help="video frames per second (default 30)")
    p.add_argument("--panel", type=int, nargs=2, default=(320, 180), metavar=("W", "H"),
                   help="size of each integrator's panel in px (default 320 180)")
    # the defaults go to the current folder: running the example must not overwrite the
    # pictures tracked in docs/ (name them to refresh those)
    p.add_argument("--video", default="integrators.gif", help="output .mp4/.gif ('' for none; default integrators.gif)")
    p.add_argument("--plot", default="integrators.png", help="output PNG of energy vs time (default integrators.png)")
    args = p.parse_args(argv)
    if args.plot:
        import importlib.util

        if importlib.util.find_spec("matplotlib") is None:  # say so before a minute of simulating
            p.error("the energy plot needs matplotlib: pip install 'deforma[examples]' "
                    "(or matplotlib), or pass --plot '' for the video only")
    for out in (args.video, args.plot):
        if out:
            Path(out).parent.mkdir(parents=True, exist_ok=True)
    energy = run(args)
    if args.plot:
        plot(energy, args)
    return 0

"""Record, or compare with a record, the states of every built-in scene under every integrator.

A refactor of the physics that keeps its maths must give the same states. This runs each
built-in scene (its own dt, its scripted explosions and pulls) for ``--steps`` steps under
each integrator and saves every body's positions and velocities at every ``--every``-th step
(``record``), or compares them with a saved record (``compare``: prints the largest
difference per scene and integrator, and exits 1 if any passes ``--tolerance``).

Usage::

    python tools/same_states.py record /tmp/before.npz
    ... change the code ...
    python tools/same_states.py compare /tmp/before.npz

Besides each integrator at the scene's own ``substeps``, ``symplectic-euler@stable`` runs
symplectic Euler with as many substeps as its stable step needs (at most 64), since most
scenes are set up for a stable integrator and stop at once under it otherwise.

Run both sides with the same NUMBA_NUM_THREADS (the symplectic step chunks its springs by
thread count): the default here pins one thread, so the serial driver runs in both.
A scene that stops with ``SimulationUnstable`` under an integrator is recorded up to
where it stopped, with its message; the comparison checks that it stops at the same step.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402


def run(scene_name: str, integrator: str, steps: int, every: int) -> tuple[list[np.ndarray], str]:
    from deforma import scene as scenes

    scene = scenes.load(scene_name)
    world = scene.build()
    world.integrator = integrator.split("@")[0]
    if integrator.endswith("@stable"):  # as many substeps as the explicit step needs (at most 64)
        world.substeps = max(1, min(64, math.ceil(world.dt / world.stable_dt() - 1e-9)))
    script = scenes.Script(scene, world)
    frames, failure = [], ""
    for k in range(steps):
        if k % every == 0:
            frames.append(np.concatenate([np.concatenate([b.positions, b.velocities], axis=1)
                                          for b in world.bodies] or [np.zeros((0, 4))]))
        script.apply()
        try:
            world.step()
        except Exception as e:  # noqa: BLE001 - an error is part of what is compared (its step and message)
            failure = f"step {k}: {type(e).__name__}: {e}"
            break
    frames.append(np.concatenate([np.concatenate([b.positions, b.velocities], axis=1)
                                  for b in world.bodies] or [np.zeros((0, 4))]))
    return frames, failure


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("action", choices=["record", "compare"])
    p.add_argument("path")
    p.add_argument("--steps", type=int, default=600)
    p.add_argument("--every", type=int, default=50)
    p.add_argument("--tolerance", type=float, default=1e-12)
    p.add_argument("--scenes", default="", help="comma-separated built-in scenes (default: all)")
    p.add_argument("--integrators", default="", help="comma-separated (default: all)")
    a = p.parse_args(argv)
    from deforma.physics import available_integrators
    from deforma.scene import builtin_scenes

    names = a.scenes.split(",") if a.scenes else sorted(builtin_scenes())
    integrators = a.integrators.split(",") if a.integrators else [*available_integrators(), "symplectic-euler@stable"]
    saved = dict(np.load(a.path, allow_pickle=False)) if a.action == "compare" else {}
    out, worst = {}, 0.0
    for name in names:
        for integ in integrators:
            t0 = time.perf_counter()
            frames, failure = run(name, integ, a.steps, a.every)
            key = f"{name}/{integ}"
            took = time.perf_counter() - t0
            if a.action == "record":
                for k, f in enumerate(frames):
                    out[f"{key}/{k}"] = f
                out[f"{key}/failure"] = np.array(failure)
                print(f"{key:32s} {len(frames):3d} frames {took:6.1f} s {failure[:60]}", flush=True)
                continue
            old_failure = str(saved.get(f"{key}/failure", "<missing>"))
            diff = 0.0
            shapes_ok = True
            for k, f in enumerate(frames):
                ref = saved.get(f"{key}/{k}")
                if ref is None or ref.shape != f.shape:
                    shapes_ok = False
                    break
                with np.errstate(invalid="ignore"):
                    d = np.abs(f - ref)
                scale = max(1.0, float(np.abs(ref[np.isfinite(ref)]).max(initial=0.0)))
                diff = max(diff, float(np.nanmax(d, initial=0.0)) / scale)
            same_end = old_failure == failure and len(frames) == sum(1 for k in saved if k.startswith(key + "/")) - 1
            verdict = "same" if shapes_ok and same_end and diff <= a.tolerance else "DIFFERENT"
            if verdict != "same":
                worst = max(worst, np.inf if not (shapes_ok and same_end) else diff)
            print(f"{key:32s} max rel diff {diff:.3g} {verdict} {took:6.1f} s"
                  + ("" if same_end else f"  (failure was {old_failure[:50]!r}, now {failure[:50]!r})"), flush=True)
    if a.action == "record":
        np.savez_compressed(a.path, **out)
        return 0
    return 1 if worst > a.tolerance else 0


if __name__ == "__main__":
    sys.exit(main())

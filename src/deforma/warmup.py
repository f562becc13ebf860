"""Compiling every built-in scene's kernels once: the warm-up (issue 50).

deforma's kernels compile on first use and are cached (:mod:`deforma.kernel_cache`). A first
``deforma run demo`` compiles only what ``demo`` calls; measured on a cold cache (2-core VM),
``demo`` took 100 s, and the scenes after it compiled 70 s more between them (``sample``
18 s: symplectic Euler; ``chain`` 28 s: rigid bodies and joints; ``crates`` 14 s: implicit
Euler; ``tear`` 6 s; ``balloon`` 4 s).

So the first command that compiles starts this warm-up in a second process, on the core
the compiler leaves idle (compiling is single-threaded): it builds every built-in
scene and steps it a few times, with a grab and an explosion, the scenes whose kernels the
running one shares least first, so that what the two compile overlaps little (a kernel the
other process has already written to the cache is loaded, not compiled again). When the
command ends, it waits for a warm-up still running, and says so. ``deforma warmup`` runs the
same in the foreground, with a progress bar: for an image or a CI cache built ahead.

Chosen over the alternatives measured in the issue's notes: fewer ``inline="always"``
kernels compiled 22 % faster but stepped 70 % slower; a lower LLVM optimisation level saved
3 %. A marker file in the cache folder (``warmup.done``) says the warm-up has run for these
sources; a folder whose sources change (an upgrade) is a new folder, and warms up again.
``DEFORMA_WARMUP=0`` turns the background warm-up off.

Measured on a cold cache, the 2-core VM at a load of 3: ``deforma run demo -o demo.mp4``
compiled for 150 s and ended at 169 s; the warm-up ended at 215 s, and the run waited for it.
After that, 1 s of ``jelly``, ``chain``, ``tear``, ``crates`` or ``sample`` took 1.2-3.3 s, none
compiling (they had compiled 3-28 s each), and 8 s of every built-in scene compiled nothing.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Callable, Sequence

__all__ = ["ORDER", "Background", "start_background", "warm_up"]

#: Scenes first in the warm-up: those whose kernels ``demo`` (the README's first command)
#: shares least. Symplectic Euler's and implicit Euler's first, then ``chain``'s rigid bodies
#: and joints, which also call avbd's sweep: by then the run has mostly compiled and cached it.
ORDER = ("sample", "crates", "tear", "chain", "balloon")

#: Set in the warm-up's own process (it must not start another).
WORKER_ENV = "DEFORMA_WARMUP_WORKER"


def _scene_order(last: str | None) -> list[str]:
    from .scene.assets import builtin_scenes

    names = list(builtin_scenes())
    order = [n for n in ORDER if n in names] + [n for n in names if n not in ORDER]
    if last in order:  # the scene the calling command is compiling: by then mostly cached
        order.remove(last)
        order.append(last)
    return order


def _exercise(name: str, steps: int) -> None:
    """Build the built-in scene ``name`` and step it as a run and the viewer would: plain
    steps, then a grab dragged for a step, then an explosion; a body that can tear is torn."""
    import numpy as np

    from . import scene as scenes

    world = scenes.load(name).build()
    for _ in range(steps):
        world.step()
    soft = [b for b in world.bodies if not b.material.is_rigid] or world.bodies
    if soft:
        centre = np.asarray(soft[0].positions, dtype=float).mean(axis=0)
        try:
            g = world.grab(centre)
        except ValueError:  # nothing under the point (a ring's hole): no grab kernels from it
            g = None
        if g is not None:
            world.drag(g, centre + (0.01, 0.01))
            world.step()
            world.release(g)
        world.explode(1.0, center=centre)
        world.step()
    for body in world.bodies:
        if body.material.tear_strain is not None:
            _tear(world, body)
            break


def _tear(world, body, steps: int = 60) -> None:
    """Pull ``body`` apart by two grabs at its far ends until it tears (its vertex count
    changes) or ``steps`` steps pass: the tearing kernels run only once a tear happens."""
    import numpy as np

    x = np.asarray(body.positions, dtype=float)
    n = len(x)
    ends = x[np.argmin(x[:, 0])], x[np.argmax(x[:, 0])]
    width = float(ends[1][0] - ends[0][0]) or 1.0
    grabs = [world.grab(p, strength=1e4 * body.mass, radius=0.2 * width) for p in ends]
    for k in range(1, steps + 1):
        for g, p, sign in zip(grabs, ends, (-1.0, 1.0)):
            world.drag(g, p + (sign * 0.05 * width * k, 0.0))
        world.step()
        if len(body.positions) != n:
            break
    for g in grabs:
        world.release(g)


def warm_up(names: Sequence[str] | None = None, *, last: str | None = None, steps: int = 3,
            progress: Callable[[str], None] | None = None) -> float:
    """Compile the kernels of the built-in scenes ``names`` (default: every one) by building
    and stepping each (see the module docstring); returns the wall time (s).

    ``last``: a scene to take last (another process is compiling it). ``progress`` is
    called with each scene's name once it has stepped.

    Examples
    --------
    >>> warm_up(["slope"], steps=1) >= 0.0
    True
    """
    import warnings

    t0 = time.perf_counter()
    order = list(names) if names is not None else _scene_order(last)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a scene's own advice is not the warm-up's business
        for name in order:
            _exercise(name, steps)
            if progress is not None:
                progress(name)
    return time.perf_counter() - t0


class Background:
    """A warm-up running in a second process (:func:`start_background`)."""

    def __init__(self, process: subprocess.Popen, started: float):
        self.process = process
        self.started = started

    def running(self) -> bool:
        return self.process.poll() is None

    def wait(self, say: Callable[[str], None]) -> None:
        """Wait for the warm-up to end, saying so first if it is still running."""
        if self.running():
            say(f"deforma: compiling the other built-in scenes' kernels (once; started "
                f"{time.perf_counter() - self.started:.0f} s ago, in a second process)...")
        try:
            self.process.wait()
        except BaseException:  # Ctrl-C or a signal while waiting: no warm-up left behind
            self.stop()
            raise

    def stop(self) -> None:
        """End the warm-up now (the next command that compiles starts it again)."""
        if self.running():
            self.process.terminate()
        self.process.wait()


def start_background(running: str | None = None) -> Background | None:
    """Start :func:`warm_up` in a second process, unless it is not wanted:
    ``DEFORMA_WARMUP=0``, a single core (it would slow the command it is meant to help),
    inside a warm-up, where the cache folder is unknown, or where a warm-up has run
    (``warmup.done``) or runs (``warmup.pid`` of a live process) for this folder.
    ``running``: the built-in scene the calling command is running (taken last)."""
    if os.environ.get("DEFORMA_WARMUP", "1") == "0" or os.environ.get(WORKER_ENV):
        return None
    if (os.cpu_count() or 1) < 2:
        return None
    from .kernel_cache import kernel_folder

    folder = kernel_folder()
    if folder is None or (folder / "warmup.done").exists() or _alive(folder / "warmup.pid"):
        return None
    args = [sys.executable, "-m", "deforma.warmup", "--folder", str(folder)]
    if running:
        args += ["--last", running]
    env = dict(os.environ, **{WORKER_ENV: "1", "NUMBA_CACHE_DIR": str(folder)})
    try:
        p = subprocess.Popen(args, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    except OSError:
        return None
    return Background(p, time.perf_counter())


def _alive(pidfile: Path) -> bool:
    try:
        pid = int(pidfile.read_text())
        os.kill(pid, 0)
    except (OSError, ValueError):
        return False
    return True


def _worker(argv: Sequence[str]) -> int:
    """The second process: ``python -m deforma.warmup --folder F [--last SCENE]``. Writes
    ``warmup.pid`` while it runs, ``warmup.done`` when every scene stepped, and what failed to
    ``warmup.log``."""
    import argparse
    import traceback

    p = argparse.ArgumentParser(prog="python -m deforma.warmup")
    p.add_argument("--folder", required=True)
    p.add_argument("--last")
    a = p.parse_args(argv)
    folder = Path(a.folder)
    pidfile = folder / "warmup.pid"
    try:
        pidfile.write_text(str(os.getpid()))
        seconds = warm_up(last=a.last)
        (folder / "warmup.done").write_text(f"{seconds:.1f} s\n")
        (folder / "warmup.log").unlink(missing_ok=True)
        return 0
    except Exception:  # noqa: BLE001 - kept for whoever looks; the next command tries again
        try:
            (folder / "warmup.log").write_text(traceback.format_exc())
        except OSError:
            pass
        return 1
    finally:
        pidfile.unlink(missing_ok=True)


if __name__ == "__main__":  # pragma: no cover - the second process
    sys.exit(_worker(sys.argv[1:]))

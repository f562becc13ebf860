"""Headless video against real time: ``deforma run SCENE -o OUT`` in simulated seconds per wall second.

The issue (50) asks that, warm, ``deforma run demo -o demo.mp4 --size 1280x720`` run at least
2x real time and a GIF (``-o demo.gif``) at least 1x. Each case runs the whole command in a
fresh Python process (``deforma.cli.main``: importing deforma, building the scene, simulating,
drawing, reading back, encoding, writing the file) and times it from inside that process, so
the interpreter's own start-up is left out and nothing else is. The same scene without
``-o`` (the physics alone) is timed in the same rounds: it is the ceiling a video run can
reach, and the ratio video / physics says how much of the run the pictures cost.

The cases run in turns (physics, MP4, GIF, physics, MP4, ...) so a shared machine's load
weighs on all alike; the figure per case is the median over the rounds. One untimed run first
loads (or, after an edit of the physics, compiles) the kernels. The load average is printed
with the figures: llvmpipe and ffmpeg's threads slow down a lot when other processes hold
the cores.

Command: ``python benchmarks/run.py --only video`` (or ``python benchmarks/bench_video.py
[--quick] [--scene demo]``); ``--quick`` runs 1 s of the scene in 3 rounds (about a minute),
the full run the scene's own length (10 s for demo) in 5 rounds.
"""

from __future__ import annotations

import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Row  # noqa: E402

#: Goals of the issue, in simulated seconds per wall second.
GOALS = {"mp4": 2.0, "gif": 1.0}

# the command, timed from inside its process: the interpreter's start-up left out. With
# BENCH_ONE_AT_A_TIME=1 each frame is drawn, read back and encoded before the next is simulated,
# as before issue 50 (one off-screen buffer, the writer's work in the caller's thread).
_TIMED = ("import os, sys, time\n"
          "t = time.perf_counter()\n"
          "from deforma.cli import main\n"
          "if os.environ.get('BENCH_ONE_AT_A_TIME') == '1':\n"
          "    sys.path.insert(0, os.environ['BENCH_DIR'])\n"
          "    import bench_video\n"
          "    bench_video.one_frame_at_a_time()\n"
          "code = main(sys.argv[1:])\n"
          "print(f'BENCH_WALL {time.perf_counter() - t:.6f}', file=sys.stderr)\n"
          "sys.exit(code)\n")


def one_frame_at_a_time() -> None:
    """Make this process's video runs draw, read and encode each frame before the next is
    simulated (the pipeline before issue 50), for the comparison in the same run."""
    import numpy as np

    from deforma.render import recorder, video

    init = recorder.FrameRecorder.__init__

    def init_one(self, view, writer, *, in_flight=None):
        init(self, view, writer, in_flight=1)

    def write_now(self, frame):
        if self._closed:
            raise ValueError(f"{self.path}: writer is closed")
        f = np.ascontiguousarray(self._check(frame))
        if self.frames_written == 0:
            self._start(f)  # what the writer's thread needs first (an MP4's ffmpeg), as write() does
        self._write(f)
        self.frames_written += 1

    recorder.FrameRecorder.__init__ = init_one
    video.FrameWriter.write = write_now

_SIMULATED = re.compile(r"(\d+(?:\.\d+)?) s simulated")
_WALL = re.compile(r"BENCH_WALL (\d+(?:\.\d+)?)")


def parse_run(stderr: str) -> tuple[float, float]:
    """(simulated seconds, wall seconds) from a timed ``deforma run``'s output.

    Examples
    --------
    >>> parse_run("demo: 300 frames, 9.97 s simulated in 5.1 s wall (...)\\nBENCH_WALL 4.2\\n")
    (9.97, 4.2)
    """
    sim, wall = _SIMULATED.search(stderr), _WALL.search(stderr)
    if sim is None or wall is None:
        raise RuntimeError(f"not a finished deforma run: {stderr.strip()[-400:]}")
    return float(sim.group(1)), float(wall.group(1))


def run_once(scene: str, output: str | None, *, seconds: float | None, size=(1280, 720), cwd=None,
             one_at_a_time: bool = False) -> float:
    """Simulated seconds per wall second of one ``deforma run`` in a fresh process."""
    args = ["run", scene, "--quiet", "--size", f"{size[0]}x{size[1]}"]
    if seconds is not None:
        args += ["--seconds", f"{seconds:g}"]
    if output is not None:
        args += ["-o", output]
    env = dict(os.environ, BENCH_ONE_AT_A_TIME="1" if one_at_a_time else "0",
               BENCH_DIR=str(Path(__file__).resolve().parent))
    r = subprocess.run([sys.executable, "-c", _TIMED, *args], capture_output=True, text=True, cwd=cwd,
                       timeout=900, env=env)
    if r.returncode != 0:
        raise RuntimeError(f"deforma {' '.join(args)} failed ({r.returncode}): {r.stderr.strip()[-400:]}")
    sim, wall = parse_run(r.stdout + r.stderr)  # the summary line is on stdout
    return sim / wall


#: The cases, timed in turns: the physics alone, then each format as it runs now and as it ran
#: before issue 50 (one frame at a time).
CASES = ("physics", "mp4", "gif", "mp4 one at a time", "gif one at a time")


def measure(scene: str, *, rounds: int, seconds: float | None, cases=CASES) -> dict:
    """Real-time ratios per case, ``{case: [per round]}``, the cases timed in turns."""
    speeds = {k: [] for k in cases}
    with tempfile.TemporaryDirectory() as d:
        run_once(scene, None, seconds=0.1, cwd=d)  # kernels loaded (or compiled) once, untimed
        for _ in range(rounds):
            for k in cases:
                kind = k.split()[0]
                out = None if kind == "physics" else os.path.join(d, f"{scene}.{kind}")
                speeds[k].append(run_once(scene, out, seconds=seconds, cwd=d, one_at_a_time=k.endswith("time")))
    return speeds


def run(quick: bool, scene: str = "demo") -> list[Row]:
    rounds, seconds = (3, 1.0) if quick else (5, None)
    print(f"video: load average at start {os.getloadavg()[0]:.2f}", file=sys.stderr)
    speeds = measure(scene, rounds=rounds, seconds=seconds)
    med = {k: statistics.median(v) for k, v in speeds.items()}
    print(f"video: load average at end {os.getloadavg()[0]:.2f}; per round "
          + "; ".join(f"{k} " + ", ".join(f"{x:.2f}" for x in v) for k, v in speeds.items()), file=sys.stderr)
    length = f"{seconds:g} s" if seconds is not None else "the scene's length"
    rows = [Row("video", f"{scene}, physics alone (no -o), {length}", med["physics"], "x real time",
                goal="informational: the ceiling of a video run")]
    for kind, name in (("mp4", "MP4"), ("gif", "GIF")):
        x, before = med[kind], med[f"{kind} one at a time"]
        rows.append(Row("video", f"{scene} -o {scene}.{kind}, 1280x720 {name}, {length}", x, "x real time",
                        ratio=f"{x / before:.2f}x one frame at a time ({before:.2f}x real time); "
                              f"{x / med['physics']:.2f}x the physics alone",
                        goal=f">= {GOALS[kind]:g}x real time", met=x >= GOALS[kind]))
    return rows


if __name__ == "__main__":
    import argparse

    from common import format_table

    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="1 s of the scene, 3 rounds")
    p.add_argument("--scene", default="demo", help="built-in scene or .toml (default demo)")
    a = p.parse_args()
    print(format_table(run(a.quick, a.scene)))

"""Start-up of ``deforma run``: seconds from the command to the first frame written, cold and warm.

Usage: ``python benchmarks/startup.py [SCENE] [--runs N] [--warm-only] [--src DIR ...]``

"Cold" runs the command with ``NUMBA_CACHE_DIR`` pointing at an empty folder, as on a fresh
install (every kernel compiles); "warm" runs it again with that folder filled. Frames go to
a PNG folder, whose writer saves each ``frame_*.png`` as it is drawn (into a hidden staging
folder inside it, moved into place at the end), so the first file's appearance anywhere
under the folder is the moment the first frame was written. Not one of run.py's topics: a
cold run takes minutes.

``--src DIR`` (repeatable) times the ``src/`` folder of another checkout instead of the
installed package (``git archive COMMIT src | tar -x -C DIR`` gives one), each with its own
cache; with two or more, the warm runs take turns, so a machine whose load changes during the
measurement weighs on every tree alike. ``--warm-only`` skips the cold run and uses the kernel
cache the package already has (run any ``deforma run`` once first to fill it); that shared
cache keeps the three most recent source versions, so other checkouts on the machine can evict it.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def time_run(scene: str, cache_dir: str | None, out: Path, src: str | None = None) -> tuple[float, float, str, str]:
    """(seconds to the first frame file, seconds to exit, stdout, stderr) of one ``deforma run``.

    ``cache_dir``: the ``NUMBA_CACHE_DIR`` to use (None: the package's own choice); ``src``: a
    ``src/`` folder put first on ``PYTHONPATH`` (None: the installed package).
    """
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    exe = os.path.join(os.path.dirname(sys.executable), "deforma")
    env = dict(os.environ)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    if src is not None:
        env["PYTHONPATH"] = os.pathsep.join(p for p in (os.path.abspath(src), env.get("PYTHONPATH")) if p)
    t0 = time.perf_counter()
    p = subprocess.Popen([exe, "run", scene, "-o", f"{out}/", "--quiet"], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = None
    while p.poll() is None:
        if first is None and any(out.rglob("frame_*.png")):
            first = time.perf_counter() - t0
        time.sleep(0.005)
    total = time.perf_counter() - t0
    stdout, stderr = p.communicate()
    if p.returncode != 0:
        raise RuntimeError(f"deforma run {scene} failed: {stderr}")
    return (first if first is not None else total), total, stdout.strip(), stderr.strip()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", nargs="?", default="sample")
    ap.add_argument("--runs", type=int, default=3, help="warm runs per tree (the median is reported)")
    ap.add_argument("--warm-only", action="store_true",
                    help="no cold run: time warm runs on the kernel cache the package already uses")
    ap.add_argument("--src", action="append", metavar="DIR",
                    help="time this src/ folder instead of the installed package (repeatable)")
    a = ap.parse_args(argv)
    trees = a.src or [None]
    names = {t: ("installed package" if t is None else t) for t in trees}
    rows, warm = [], {t: [] for t in trees}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "frames"
        caches = {}
        for k, t in enumerate(trees):
            if a.warm_only:
                caches[t] = None
                continue
            caches[t] = os.path.join(tmp, f"numba-cache-{k}")
            os.mkdir(caches[t])
            rows.append((f"{names[t]}: cold (empty NUMBA_CACHE_DIR)", *time_run(a.scene, caches[t], out, t)))
        for i in range(a.runs):
            for t in (trees if i % 2 == 0 else trees[::-1]):  # take turns, first place alternating
                warm[t].append(time_run(a.scene, caches[t], out, t))
        loads = os.getloadavg() if hasattr(os, "getloadavg") else None
    for t in trees:
        runs = sorted(warm[t], key=lambda r: r[0])
        rows.append((f"{names[t]}: warm (median of {a.runs})", *runs[len(runs) // 2]))
    print(f"| `deforma run {a.scene} -o frames/` | first frame written | command done |")
    print("| --- | ---: | ---: |")
    for name, first, total, _, _ in rows:
        print(f"| {name} | {first:.2f} s | {total:.2f} s |")
    for t in trees:
        print(f"\n{names[t]}: warm first frame, every run (s, sorted): "
              + ", ".join(f"{r[0]:.2f}" for r in sorted(warm[t], key=lambda r: r[0])))
    if loads is not None:
        print(f"load average at the end: {loads[0]:.2f}, {loads[1]:.2f}, {loads[2]:.2f}")
    for name, _, _, stdout, stderr in rows:
        print(f"\n{name}:\n  stderr: {stderr or '(nothing)'}\n  stdout: {stdout}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

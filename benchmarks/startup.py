"""Start-up of ``deforma run``: seconds from the command to the first frame written, cold and warm.

Usage: ``python benchmarks/startup.py [SCENE] [--runs N] [--warm-only]``

"Cold" runs the command with ``NUMBA_CACHE_DIR`` pointing at an empty folder, as on a fresh
install (every kernel compiles); "warm" runs it again with that folder filled. Frames go to
a PNG folder, whose writer saves each ``frame_*.png`` as it is drawn (into a hidden staging
folder inside it, moved into place at the end), so the first file's appearance anywhere
under the folder is the moment the first frame was written. Not one of run.py's
topics: a cold run takes a minute. ``--warm-only`` skips the cold run and uses the kernel
cache this install already has (run any ``deforma run`` once first to fill it).
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


def time_run(scene: str, cache_dir: str | None, out: Path) -> tuple[float, float, str, str]:
    """(seconds to the first frame file, seconds to exit, stdout, stderr) of one ``deforma run``."""
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    exe = os.path.join(os.path.dirname(sys.executable), "deforma")
    env = dict(os.environ) if cache_dir is None else dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
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
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("scene", nargs="?", default="sample")
    ap.add_argument("--runs", type=int, default=3, help="warm runs (the median is reported)")
    ap.add_argument("--warm-only", action="store_true",
                    help="no cold run: time warm runs on the kernel cache this install already uses")
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "frames"
        if a.warm_only:
            cache, rows = None, []
        else:
            cache = os.path.join(tmp, "numba-cache")
            os.mkdir(cache)
            rows = [("cold (empty NUMBA_CACHE_DIR)", *time_run(a.scene, cache, out))]
        warm = sorted((time_run(a.scene, cache, out) for _ in range(a.runs)), key=lambda r: r[0])
        rows.append((f"warm (median of {a.runs})", *warm[len(warm) // 2]))
    print(f"| `deforma run {a.scene} -o frames/` | first frame written | command done |")
    print("| --- | ---: | ---: |")
    for name, first, total, _, _ in rows:
        print(f"| {name} | {first:.2f} s | {total:.2f} s |")
    if len(warm) > 1:
        firsts = ", ".join(f"{r[0]:.2f}" for r in warm)
        print(f"\nwarm first frame, every run (s, sorted): {firsts}")
    for name, _, _, stdout, stderr in rows:
        print(f"\n{name}:\n  stderr: {stderr or '(nothing)'}\n  stdout: {stdout}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Start-up of ``deforma run``: seconds from the command to the first frame written, cold and warm.

Usage: ``python benchmarks/startup.py [SCENE] [--runs N]``

"Cold" runs the command with ``NUMBA_CACHE_DIR`` pointing at an empty folder, as on a fresh
install (every kernel compiles); "warm" runs it again with that folder filled. Frames go to
a PNG folder, whose writer renames each ``frame_*.png`` into place as it is drawn, so the
first file's appearance is the moment the first frame was written. Not one of run.py's
topics: a cold run takes a minute.
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


def time_run(scene: str, cache_dir: str, out: Path) -> tuple[float, float, str, str]:
    """(seconds to the first frame file, seconds to exit, stdout, stderr) of one ``deforma run``."""
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    exe = os.path.join(os.path.dirname(sys.executable), "deforma")
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    t0 = time.perf_counter()
    p = subprocess.Popen([exe, "run", scene, "-o", f"{out}/", "--quiet"], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = None
    while p.poll() is None:
        if first is None and any(out.glob("frame_*.png")):
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
    a = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        cache, out = os.path.join(tmp, "numba-cache"), Path(tmp) / "frames"
        os.mkdir(cache)
        rows = [("cold (empty NUMBA_CACHE_DIR)", *time_run(a.scene, cache, out))]
        warm = sorted((time_run(a.scene, cache, out) for _ in range(a.runs)), key=lambda r: r[0])
        rows.append((f"warm (median of {a.runs})", *warm[len(warm) // 2]))
    print(f"| `deforma run {a.scene} -o frames/` | first frame written | command done |")
    print("| --- | ---: | ---: |")
    for name, first, total, _, _ in rows:
        print(f"| {name} | {first:.2f} s | {total:.2f} s |")
    for name, _, _, stdout, stderr in rows:
        print(f"\n{name}:\n  stderr: {stderr or '(nothing)'}\n  stdout: {stdout}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

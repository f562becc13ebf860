"""Rendering: a deforming, textured 20k-triangle body at 1280x720, headless, readback included.

The issue's goal is >= 60 frames/s on this machine's software OpenGL (Mesa llvmpipe via
EGL). Each timed frame uploads new vertex positions, draws background, grid, colliders and
the body, and reads the picture back to a NumPy array, which is what ``deforma run`` does.

Usage: ``python benchmarks/run.py --only render`` (or ``python benchmarks/bench_render.py``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import Row, format_table, median_seconds  # noqa: E402


def grid_body(n: int):
    """An n x n vertex grid over 6 m x 3 m: 2 (n-1)^2 triangles (n = 101 gives 20,000)."""
    xs, ys = np.meshgrid(np.linspace(-3, 3, n), np.linspace(0, 3, n))
    pts = np.c_[xs.ravel(), ys.ravel()]
    i = np.arange(n * n).reshape(n, n)
    a, b, c, d = i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(), i[1:, :-1].ravel()
    tris = np.r_[np.c_[a, b, c], np.c_[a, c, d]].astype(np.int32)
    uv = (pts - pts.min(0)) / np.ptp(pts, axis=0)
    return pts, tris, uv


def run(quick: bool) -> list[Row]:
    import os

    from deforma.render import Camera, Renderer

    # the machine may be shared: llvmpipe's threads slow down a lot when other processes hold
    # the cores, so the load is printed beside the figures
    print(f"render: load average at start {os.getloadavg()[0]:.2f}", file=sys.stderr)
    pts, tris, uv = grid_body(101)
    rng = np.random.default_rng(0)
    tex = rng.integers(0, 256, (512, 512, 4), dtype=np.uint8)
    tex[..., 3] = 255
    colliders = [((0, -0.4), (7, 0.3), 3.0), ((-2.5, 2.0), (1.5, 0.2), -20.0), ((2.5, 2.0), (1.5, 0.2), 20.0)]
    repeat = 15 if quick else 60
    rows = []
    for samples, label in ((0, "no MSAA"), (4, "4x MSAA")):
        r = Renderer.headless((1280, 720), samples=samples, camera=Camera((0, 1.3), (8, 4.5)))
        h = r.add_mesh(tris, uv, texture=tex)
        k = [0]

        def frame():
            k[0] += 1
            # a new deformation each frame, as in a simulation
            p = pts + 0.02 * np.sin(k[0] * 0.1 + pts[:, ::-1])
            r.render([(h, p)], colliders)
            r.read()

        t = median_seconds(frame, repeat=repeat, warmup=3)
        fps = 1.0 / t
        goal = samples == 0
        rows.append(Row("render", f"20k textured tris 1280x720 + readback, {label}", fps, "frames/s",
                        goal=">= 60 frames/s" if goal else "informational (default of `deforma run`)",
                        met=(fps >= 60) if goal else None))
        r.release()
    return rows


if __name__ == "__main__":
    print(format_table(run(quick="--quick" in sys.argv)))

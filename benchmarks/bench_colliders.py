"""Colliders of mixed shapes against rectangles only: the cost of a step among 100 pegs.

A peg board: 100 fixed colliders on a 10 x 10 lattice, 0.6 m apart, and soft boxes falling
through it. Once with 100 rotated rectangles; once with 25 each of rectangles, circles,
concave polygons (an L of 6 corners) and capsules, of about the same size. The goal (the
collider-shapes issue): a step among mixed shapes costs at most 1.5x a step among
rectangles. Both worlds are stepped in turns, so the machine's load weighs on both alike.

Usage: ``python benchmarks/bench_colliders.py [--quick]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import deforma  # noqa: E402
from common import Row, interleaved_medians  # noqa: E402


def peg(kind: str, center) -> deforma.physics.Collider:
    x, y = center
    if kind == "rect":
        return deforma.Rect(center, (0.3, 0.3), 45.0)
    if kind == "circle":
        return deforma.Circle(center, 0.17)
    if kind == "polygon":
        ell = np.array([[0, 0], [0.3, 0], [0.3, 0.1], [0.1, 0.1], [0.1, 0.3], [0, 0.3]]) - 0.15
        return deforma.Polygon(ell + (x, y))
    return deforma.Segment((x - 0.15, y - 0.05), (x + 0.15, y + 0.05), radius=0.05)


def board(mixed: bool, bodies: int) -> deforma.World:
    """The peg board with ``bodies`` soft boxes (11 x 11 vertices each) dropped into it."""
    w = deforma.World(sleep=False, dt=1 / 600, substeps=4, stiffness=3000.0, damping=1.0, integrator="symplectic-euler")
    kinds = ["rect", "circle", "polygon", "segment"]
    for k in range(100):
        i, j = divmod(k, 10)
        center = (0.6 * j - 2.7 + 0.3 * (i % 2), 0.6 * i)
        w.add_collider(peg(kinds[k % 4] if mixed else "rect", center))
    w.add_collider(deforma.Rect((0, -0.6), (8, 0.4), 0.0))
    box = deforma.mesh.box([[-0.15, -0.15], [0.15, -0.15], [0.15, 0.15], [-0.15, 0.15]], detail=9)
    for b in range(bodies):
        w.add_body(box, position=(-2.4 + 4.8 * b / max(bodies - 1, 1), 6.4))
    for _ in range(300):  # 0.5 s: the boxes are among the top pegs
        w.step()
    return w


def run(quick: bool) -> list[Row]:
    bodies = 4 if quick else 8
    rects, mixed = board(False, bodies), board(True, bodies)
    n = sum(b.n_vertices for b in rects.bodies)
    t = interleaved_medians({"rect": rects.step, "mixed": mixed.step}, 100 if quick else 400)
    ratio = t["mixed"] / t["rect"]
    return [
        Row("colliders", f"step among 100 rectangles, {bodies} boxes ({n} vertices)", t["rect"] * 1e3, "ms"),
        Row("colliders", "  same among 25 rects, 25 circles, 25 L-polygons, 25 capsules", t["mixed"] * 1e3, "ms",
            ratio=f"{ratio:.2f}x the rectangles", goal="<= 1.5x", met=ratio <= 1.5),
    ]


if __name__ == "__main__":
    from common import format_table

    print(format_table(run(quick="--quick" in sys.argv)))

"""Write the ``pyramid`` scene: 20 rows of rigid boxes (210) standing on a floor.

The layout is ``benchmarks/bench_rigid.py``'s ``pyramid_boxes()``: 0.2 m boxes (detail 2, as
the benchmark meshes them) of density 100 kg/m^2, 2 mm apart in a row, each row 1 mm above
the one below (row r holds 20 - r boxes centred at x = (c - (20 - r - 1) / 2) 0.202,
y = 0.1 + 0.201 r), on a floor whose top is y = 0, with friction 0.5 and static friction 0.5.
Nothing else happens: the scene shows stacking at 1/60 s under the default integrator (avbd).
The rows alternate two colours so that each row reads on its own.

Run from the repository root::

    python tools/make_pyramid.py     # writes src/deforma/assets/scenes/pyramid.toml
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from bench_rigid import pyramid_boxes  # noqa: E402 - the benchmark's layout: the scene is what it measures

OUT = Path(__file__).resolve().parents[1] / "src" / "deforma" / "assets" / "scenes" / "pyramid.toml"
ROWS = 20
SIZE = 0.2          # m, each box's side
GAP = 0.002         # m, between neighbours in a row
LIFT = 0.001        # m, between a row and the one below
DENSITY = 100.0     # kg/m^2 (4 kg a box)
COLORS = ("#d9822b", "#f2d091")   # the rows alternate: burnt orange, sand


def boxes(rows: int = ROWS) -> list[tuple[int, float, float]]:
    """(row, x, y) of each box's centre, bottom row first: ``pyramid_boxes()`` of the benchmark
    (row r holds rows - r boxes), with its row."""
    row = [r for r in range(rows) for _ in range(rows - r)]
    return [(r, x, y) for r, (x, y, _, _) in zip(row, pyramid_boxes(rows), strict=True)]


def scene() -> str:
    out = [f'''# Stacking: a pyramid of {ROWS} rows of rigid boxes ({len(boxes())}) stands on a floor at 1/60 s.
# The layout of benchmarks/bench_rigid.py's pyramid. Written by tools/make_pyramid.py.
[scene]
name = "pyramid"
description = "A pyramid of {ROWS} rows of rigid boxes ({len(boxes())} boxes, 0.2 m, 2 mm apart) stands on a floor at 1/60 s: nothing sags, slides or jitters, and it falls asleep."

[run]
seconds = 5.0
fps = 30

[camera]
center = [0.0, 2.05]
size = [8.2, 4.6]

[physics]
friction = 0.5
static_friction = 0.5

# 0.2 m boxes of {DENSITY:g} kg/m^2 ({DENSITY * SIZE * SIZE:g} kg), {GAP * 1000:g} mm apart in a row, each row {LIFT * 1000:g} mm above the one below
''']
    row = -1
    for r, x, y in boxes():
        if r != row:
            n = ROWS - r
            out.append(f"# row {r}: {n} box{'es' if n > 1 else ''}")
            row = r
        out.append(f'''[[body]]
corners = [[0, 0], [{SIZE:g}, 0], [{SIZE:g}, {SIZE:g}], [0, {SIZE:g}]]
detail = 2
position = [{x:.4f}, {y:.4f}]
material = "rigid"
density = {DENSITY:.1f}
color = "{COLORS[r % 2]}"
''')
    out.append('''# the floor: its top face at y = 0
[[collider]]
center = [0.0, -0.5]
size = [10.0, 1.0]
''')
    return "\n".join(out)


def main() -> None:
    OUT.write_text(scene())


if __name__ == "__main__":
    main()

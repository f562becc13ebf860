"""Write the ``car`` scene and its level: a JellyCar-like car on a bumpy level.

The car is a rigid chassis on two wheels. Each wheel is a rigid hub, driven by a motor pin
to the chassis, inside a soft rubber tyre held on it by eight pins around its rim (a weld
holds a turn, which a soft body has only as a whole; the pins hold the tyre as a rim does).
The tyres and hubs are rings and discs of concentric circles of points, triangulated by
deforma's Delaunay and written as ``shape = "mesh"`` bodies. The level is a picture (white
ground on black) the scene traces as an image collider.

Run from the repository root::

    python tools/make_car.py     # writes src/deforma/assets/levels/bumps.png
                                 # and src/deforma/assets/scenes/car.toml
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from deforma.mesh import Mesh, delaunay

ROOT = Path(__file__).resolve().parents[1] / "src" / "deforma" / "assets"
SCALE = 0.01                # m per pixel of the level
GROUND = 40                 # px: the flat ground's height in the picture
LENGTH = 1000               # px: the level's length (10 m)
R_TYRE, R_RIM, R_HUB = 0.25, 0.10, 0.12   # m
PINS = 8                    # pins holding each tyre on its hub, at radius R_PIN
R_PIN = 0.11


def ring(outer: float, inner: float, rings: int) -> Mesh:
    """A ring (``inner`` > 0) or a disc (``inner`` = 0) of radius ``outer`` (m): ``rings``
    concentric circles of points, staggered, triangulated by Delaunay (the hole's
    triangles dropped)."""
    pts = [] if inner > 0 else [(0.0, 0.0)]
    radii = np.linspace(inner, outer, rings + 1) if inner > 0 else np.linspace(0.0, outer, rings + 1)[1:]
    spacing = (outer - inner) / rings
    for k, rad in enumerate(radii):
        n = max(6, int(round(2 * math.pi * rad / spacing)))
        for i in range(n):
            a = 2 * math.pi * (i + 0.5 * (k % 2)) / n
            pts.append((rad * math.cos(a), rad * math.sin(a)))
    pts = np.round(np.array(pts), 9)
    tris = delaunay(pts)
    c = pts[tris].mean(axis=1)
    return Mesh(pts, tris[np.hypot(c[:, 0], c[:, 1]) > inner])


def level() -> tuple[Image.Image, float]:
    """The level's picture and its top's height in pixels: flat ground, humps, a ramp up to a
    plateau, a drop, and a row of small bumps."""
    x = np.arange(LENGTH)
    top = np.full(LENGTH, float(GROUND))
    for c, w, h in ((220, 60, 14), (330, 80, 22), (440, 50, 12)):    # humps
        top += h * np.exp(-0.5 * ((x - c) / (w / 2.5)) ** 2)
    ramp = (x >= 520) & (x < 640)
    top[ramp] += 30 * (x[ramp] - 520) / 120
    top[(x >= 640) & (x < 740)] += 30                                  # a plateau, then a drop
    for c in range(800, 940, 45):                                      # small bumps
        top += 6 * np.exp(-0.5 * ((x - c) / 8.0) ** 2)
    top[x >= 975] += 100                                               # a wall at the end
    height = int(top.max()) + 10
    img = Image.new("RGB", (LENGTH, height), "black")
    draw = ImageDraw.Draw(img)
    draw.polygon([(0, height)] + [(int(i), height - float(t)) for i, t in zip(x, top)] + [(LENGTH - 1, height)],
                 fill="white")
    return img, float(top.max())


def fmt(a) -> str:
    return "[" + ", ".join("[" + ", ".join(f"{v:.6g}" for v in row) + "]" for row in np.asarray(a).tolist()) + "]"


#: The tyres' rubber.
TYRE = """material = "corotated"
youngs_modulus = 150000.0
poisson_ratio = 0.4
density = 400.0
material_damping = 0.01"""


def mesh_body(mesh: Mesh, at, material: str, color: str) -> str:
    """A ``[[body]]`` table of ``mesh`` (``shape = "mesh"``) placed at ``at``, of ``material``
    (its keys' lines)."""
    return (f'[[body]]\nshape = "mesh"\nvertices = {fmt(mesh.vertices)}\ntriangles = {fmt(mesh.triangles)}\n'
            f'position = [{at[0]:.4f}, {at[1]:.4f}]\n{material}\ncolor = "{color}"\n')


def scene(top_px: float) -> str:
    tyre, hub = ring(R_TYRE, R_RIM, 4), ring(R_HUB, 0.0, 3)
    x0 = -LENGTH * SCALE / 2 + 1.0           # the car starts 1 m from the level's left end
    y = R_TYRE + 0.01                        # wheel centres (the flat ground at y = 0)
    out = ['''# Joints and soft bodies together: a JellyCar-like car. Its two soft rubber tyres, each held on a
# rigid hub by eight pins, are driven by motor pins to a rigid chassis over a bumpy level
# (a picture traced as an image collider). Written by tools/make_car.py.
[scene]
name = "car"
description = "A car with two soft rubber tyres on motor-driven rigid hubs drives over a bumpy level drawn as a picture; its tyres squash where they touch."

[run]
seconds = 8.0
fps = 30

[camera]
# the chassis (body 0) in the middle, as a side-scroller keeps its car
center = [-3.35, 0.64]
size = [4.8, 2.7]
follow = 0

[physics]
friction = 0.9
static_friction = 1.0
''']
    out.append(f'''# the chassis
[[body]]
corners = [[0, 0], [1.3, 0], [1.3, 0.2], [0, 0.2]]
detail = 3
position = [{x0:.4f}, {y + 0.38:.4f}]
material = "rigid"
density = 200.0
color = "#2e86de"
''')
    for k, dx in enumerate((-0.45, 0.45)):
        out.append(f"# wheel {k}: its hub (rigid) and its tyre (soft rubber)\n"
                   + mesh_body(hub, (x0 + dx, y), 'material = "rigid"\ndensity = 400.0', "#dfe4ea") + "\n"
                   + mesh_body(tyre, (x0 + dx, y), TYRE, "#2f3542"))
    height_m = (top_px + 10) * SCALE
    out.append(f'''# the level: white ground on black, its flat top at y = 0
[[collider]]
shape = "image"
source = "bumps"
scale = {SCALE}
position = [0.0, {-GROUND * SCALE + height_m / 2 - 10 * SCALE:.4f}]
''')
    for k, dx in enumerate((-0.45, 0.45)):
        hub_i, tyre_i = 1 + 2 * k, 2 + 2 * k
        cx = x0 + dx
        out.append(f'''# wheel {k}: the motor (hub to chassis, clockwise: forward), and the tyre on its hub
[[joint]]
a = {hub_i}
b = 0
at = [{cx:.4f}, {y:.4f}]
motor_speed = -300.0
max_torque = 60.0
''')
        for p in range(PINS):
            a = 2 * math.pi * p / PINS
            out.append(f'''[[joint]]
a = {tyre_i}
b = {hub_i}
at = [{cx + R_PIN * math.cos(a):.5f}, {y + R_PIN * math.sin(a):.5f}]
''')
    return "\n".join(out)


def main() -> None:
    img, top_px = level()
    img.save(ROOT / "levels" / "bumps.png", optimize=True)
    (ROOT / "scenes" / "car.toml").write_text(scene(top_px))


if __name__ == "__main__":
    main()

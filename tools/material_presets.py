"""Measure every material preset on a 0.5 m block (docs/physics.md, "Material presets").

Run ``python tools/material_presets.py`` for the table, ``--picture`` for docs/presets.png
(the six side by side: landing at 0.4 s, at 0.55 s, at rest at 3 s). Per preset, a 0.5 m square (``mesh.box``, detail 8)
on a floor under ``deforma.World(dt=1 / 600, integrator="symplectic-euler")`` (``substeps="auto"``;
``wood`` under ``implicit-bdf2``, since its stable step would need hundreds of substeps):

- sag: how much shorter it stands at rest than its rest shape (``world.solve_static()``), %;
- bounce: dropped from 0.5 m (its bottom 0.5 m above the floor), how high its centre rises
  after the first impact, as a share of the drop, %;
- squash: the least height during the first impact, as a share of the standing height lost, %;
- settle: from the first impact, how long until its height stays within 0.5 % of the block's
  size of its standing height (bounces and wobble), s.
"""

import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

import deforma

SIZE, DROP, SECONDS = 0.5, 0.5, 3.0


def world(name: str, drop: float) -> tuple:
    material = deforma.Material.preset(name)
    integrator = "implicit-bdf2" if name == "wood" else "symplectic-euler"
    w = deforma.World(dt=1 / 600, material=material, integrator=integrator)
    w.add_collider(deforma.Rect((0.0, -0.25), (4.0, 0.5), 0.0))
    half = SIZE / 2
    body = w.add_body(deforma.mesh.box(((-half, -half), (half, -half), (half, half), (-half, half)), detail=8),
                      position=(0.0, half + drop + 1e-6))
    return w, body


def measure(name: str) -> dict:
    w, body = world(name, 0.0)
    if name == "wood":  # solve_static's relaxation converges too slowly at 1e9 Pa: let it stand 1 s
        for _ in range(round(1.0 / w.dt)):
            w.step()
    else:
        w.solve_static()
    standing = float(np.ptp(body.positions[:, 1]))
    centre = float(body.positions[:, 1].mean())
    w, body = world(name, DROP)
    heights, centres, times = [], [], []
    for _ in range(round(SECONDS / w.dt)):
        w.step()
        heights.append(np.ptp(body.positions[:, 1]))
        centres.append(body.positions[:, 1].mean())
        times.append(w.time)
    heights, centres, times = np.array(heights), np.array(centres), np.array(times)
    touch = int(np.argmax(centres - centre < 0.02 * SIZE))  # the first impact: the centre near where it rests
    after = slice(touch, None)
    low = int(touch + np.argmin(heights[touch:touch + round(0.3 / w.dt)]))
    rise = float(np.max(centres[low:]) - centre)
    swinging = np.flatnonzero(np.abs(heights[after] - standing) > 0.005 * SIZE)
    return {"sag %": 100 * (1 - standing / SIZE), "bounce %": 100 * rise / DROP,
            "squash %": 100 * (1 - heights[low] / standing),
            "settle s": float(times[touch + swinging[-1]] - times[touch]) if len(swinging) else 0.0,
            "substeps": w.substeps}


def picture(out: Path) -> None:
    """docs/presets.png: the six presets dropped side by side (implicit-bdf2 at 1/120 s, so
    that wood needs no hundreds of substeps and jelly still wobbles), three moments stacked."""
    from PIL import Image, ImageDraw

    names = list(deforma.physics.material.PRESETS)
    colours = ["#e07a5f", "#f2cc8f", "#3d405b", "#81b29a", "#a0522d", "#5b8def"]
    toml = ("[physics]\ndt = 0.008333333333333333\nintegrator = \"implicit-bdf2\"\n"
            "[camera]\ncenter = [0.0, 0.9]\nsize = [6.4, 3.6]\n"
            "[[collider]]\ncenter = [0.0, -0.25]\nsize = [8.0, 0.5]\n")
    half = SIZE / 2
    for i, (name, colour) in enumerate(zip(names, colours)):
        toml += (f"[[body]]\nshape = \"box\"\ndetail = 8\ncorners = [[{-half}, {-half}], [{half}, {-half}], "
                 f"[{half}, {half}], [{-half}, {half}]]\nposition = [{-2.5 + i}, {half + DROP + 1e-6}]\n"
                 f"material = \"{name}\"\ncolor = \"{colour}\"\n")
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "materials.toml").write_text(toml)
        gif = deforma.show(Path(tmp) / "materials.toml", seconds=SECONDS, fps=20, size=1280, format="gif").save(Path(tmp) / "m.gif")
        frames = Image.open(gif)
        rows = []
        for t in (0.4, 0.55, SECONDS):
            frames.seek(min(round(t * 20) - 1, frames.n_frames - 1))
            f = frames.convert("RGB")
            rows.append(f.crop((0, int(f.height * 0.35), f.width, int(f.height * 0.85))))
    sheet = Image.new("RGB", (rows[0].width, sum(r.height for r in rows)))
    for k, r in enumerate(rows):
        sheet.paste(r, (0, k * r.height))
    draw = ImageDraw.Draw(sheet)
    for i, name in enumerate(names):  # each block's name over its column, and each row's time
        draw.text(((-2.5 + i + 3.2) / 6.4 * sheet.width, 12), name, fill=(40, 44, 52), anchor="mt",
                  font_size=28)
    for k, t in enumerate(("0.4 s", "0.55 s", f"{SECONDS:g} s")):
        draw.text((12, k * rows[0].height + 12), t, fill=(40, 44, 52), font_size=24)
    sheet.resize((sheet.width // 2, sheet.height // 2), Image.LANCZOS).save(out)


def main() -> None:
    warnings.simplefilter("ignore")
    if sys.argv[1:] == ["--picture"]:
        picture(Path(__file__).resolve().parents[1] / "docs" / "presets.png")
        return
    names = sys.argv[1:] or list(deforma.physics.material.PRESETS)
    print("| preset | sag | bounce | squash | settle | substeps |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for name in names:
        m = measure(name)
        print(f"| {name} | {m['sag %']:.2g}% | {m['bounce %']:.2g}% | {m['squash %']:.2g}% | {m['settle s']:.2f} s | "
              f"{m['substeps']} |", flush=True)


if __name__ == "__main__":
    main()

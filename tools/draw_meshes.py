"""Draw docs/meshes.png: the bunny, donut, armadillo and box meshes, wireframe over texture.

Pure Pillow (no matplotlib, no GL): each image mesh is drawn in its picture's pixel frame
through its ``uv`` coordinates, so the wireframe lands exactly where the mesher put it; the
box is filled with a colour per triangle from its ``uv``.

Run from the repository root::

    python tools/draw_meshes.py                 # writes docs/meshes.png
    python tools/draw_meshes.py --out /tmp/meshes.png --resolution 6 --edge-step 3
    python tools/draw_meshes.py --table         # prints the figures in docs/mesh.md
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

import deforma

PANEL = 400  # pixels per panel side
ZOOM = 2  # drawn at ZOOM x and scaled down, for smooth lines
OUT = Path(__file__).resolve().parents[1] / "docs" / "meshes.png"
BACKGROUND = (40, 44, 52, 255)


def _font(size):
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1 has a single bitmap size
        return ImageFont.load_default()


def _checker(size, cell):
    yy, xx = np.mgrid[0:size, 0:size] // cell
    shade = np.where((xx + yy) % 2 == 0, 52, 60).astype(np.uint8)
    return Image.fromarray(np.dstack([shade, shade + 2, shade + 8, np.full_like(shade, 255)]), "RGBA")


def _wire(draw, pts, mesh, colour, width, boundary_colour):
    for a, b in mesh.edges:
        draw.line([tuple(pts[a]), tuple(pts[b])], fill=colour, width=width)
    for loop in mesh.boundary:
        ring = [tuple(p) for p in pts[np.r_[loop, loop[:1]]]]
        draw.line(ring, fill=boundary_colour, width=width + 1)


def image_panel(name, resolution, edge_step):
    mesh = deforma.mesh.from_image(name, resolution=resolution, detect_edges=True, edge_step=edge_step, scale=0.01)
    tex = Image.fromarray(mesh.texture, "RGBA")
    size = PANEL * ZOOM
    k = size / max(tex.size)
    canvas = _checker(size, 16 * ZOOM)
    scaled = tex.resize((round(tex.width * k), round(tex.height * k)), Image.LANCZOS)
    x0, y0 = (size - scaled.width) // 2, (size - scaled.height) // 2
    canvas.alpha_composite(scaled, (x0, y0))
    pts = np.c_[x0 + mesh.uv[:, 0] * scaled.width, y0 + (1 - mesh.uv[:, 1]) * scaled.height]
    overlay = Image.new("RGBA", canvas.size, (0, 0, 0, 0))
    _wire(ImageDraw.Draw(overlay), pts, mesh, (20, 30, 60, 150), ZOOM, (255, 255, 255, 230))
    canvas.alpha_composite(overlay)
    label = f"{name}: {len(mesh.vertices)} vertices, min angle {mesh.min_angle:.0f}°"
    return canvas.resize((PANEL, PANEL), Image.LANCZOS), label


def box_panel(detail):
    corners = ((0.2, 0.0), (2.0, 0.3), (1.8, 1.7), (0.0, 1.3))
    mesh = deforma.mesh.box(corners, detail=detail, edges=True)
    size = PANEL * ZOOM
    canvas = _checker(size, 16 * ZOOM)
    v = mesh.vertices
    lo, hi = v.min(axis=0), v.max(axis=0)
    k = 0.85 * size / (hi - lo).max()
    pts = np.c_[(v[:, 0] - 0.5 * (lo[0] + hi[0])) * k + size / 2, size / 2 - (v[:, 1] - 0.5 * (lo[1] + hi[1])) * k]
    draw = ImageDraw.Draw(canvas)
    for tri in mesh.triangles:
        u, w = mesh.uv[tri].mean(axis=0)
        colour = (int(90 + 150 * u), int(120 + 100 * w), int(230 - 120 * u * w), 255)
        draw.polygon([tuple(pts[i]) for i in tri], fill=colour)
    overlay = Image.new("RGBA", canvas.size, (0, 0, 0, 0))
    _wire(ImageDraw.Draw(overlay), pts, mesh, (20, 30, 60, 170), ZOOM, (255, 255, 255, 230))
    canvas.alpha_composite(overlay)
    label = f"box: detail {detail}, edges=True, {len(mesh.vertices)} vertices"
    return canvas.resize((PANEL, PANEL), Image.LANCZOS), label


def table():
    """Print a Markdown table of mesh figures for the built-ins at a few settings."""
    import time

    from deforma.mesh.image import foreground_mask

    print("| picture | resolution | edge_step | detect_edges | vertices | triangles | area / foreground | "
          "boundary loops | V-E+F | min angle | max R/2r | time |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name in ("bunny", "donut", "armadillo"):
        fg = int(foreground_mask(name).sum())
        for r, e, d in ((2, 1, True), (4, 2, True), (8, 4, True), (6, 2, False)):
            deforma.mesh.from_image(name, resolution=r, edge_step=e, detect_edges=d)  # warm-up (JIT)
            t = time.perf_counter()
            m = deforma.mesh.from_image(name, resolution=r, edge_step=e, detect_edges=d, scale=1.0)
            dt = time.perf_counter() - t
            print(f"| {name} | {r} | {e if d else '-'} | {d} | {len(m.vertices)} | {len(m.triangles)} | "
                  f"{m.area / fg:.4f} | {len(m.boundary)} | {m.euler_characteristic} | {m.min_angle:.1f}° | "
                  f"{m.max_aspect_ratio:.1f} | {dt * 1000:.0f} ms |")
    for n, e in ((8, False), (8, True), (30, True)):
        m = deforma.mesh.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=n, edges=e)
        print(f"| box 2x1 | detail {n} | - | edges={e} | {len(m.vertices)} | {len(m.triangles)} | "
              f"{m.area / 2:.15f} | {len(m.boundary)} | {m.euler_characteristic} | {m.min_angle:.1f}° | "
              f"{m.max_aspect_ratio:.1f} | |")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT)
    parser.add_argument("--resolution", type=int, default=8)
    parser.add_argument("--edge-step", type=int, default=4)
    parser.add_argument("--detail", type=int, default=8)
    parser.add_argument("--table", action="store_true", help="print mesh figures instead of drawing")
    args = parser.parse_args(argv)
    if args.table:
        table()
        return
    panels = [image_panel(n, args.resolution, args.edge_step) for n in ("bunny", "donut", "armadillo")]
    panels.append(box_panel(args.detail))
    caption = 28
    sheet = Image.new("RGBA", (PANEL * len(panels), PANEL + caption), BACKGROUND)
    draw = ImageDraw.Draw(sheet)
    font = _font(15)
    for i, (img, label) in enumerate(panels):
        sheet.paste(img, (i * PANEL, 0))
        draw.text((i * PANEL + 10, PANEL + 6), label, fill=(230, 230, 230, 255), font=font)
    sheet.convert("RGB").save(args.out, optimize=True)
    print(f"wrote {args.out} (resolution={args.resolution}, edge_step={args.edge_step}, detail={args.detail})")


if __name__ == "__main__":
    main()

"""Meshes: a box and the three built-in pictures made into triangle meshes, with their quality.

``deforma.mesh.box`` spreads ``detail`` x ``detail`` points inside four corners (``edges=True``
adds points on the sides); ``deforma.mesh.from_image`` follows a picture's outline, holes
included, sampling every ``resolution``-th pixel inside. Both end in ``deforma.delaunay``.
"""

from __future__ import annotations

import deforma

from ._common import PICTURE_SIZE, parser, save_picture

#: The built-in pictures and the metres per pixel that make each about a metre across.
PICTURES = {"bunny": 0.004, "donut": 0.004, "armadillo": 0.004}


def main(argv: list[str] | None = None) -> int:
    """Mesh a box and every built-in picture; print their figures; optionally draw them in a row."""
    args = parser("meshes", __doc__).parse_args(argv)
    meshes = {"box": deforma.mesh.box(((0, 0), (1, 0), (1, 0.7), (0, 0.7)), detail=8, edges=True)}
    for name, scale in PICTURES.items():
        meshes[name] = deforma.mesh.from_image(name, resolution=8, detect_edges=True, edge_step=4, scale=scale)
    print(f"{'mesh':10s} {'vertices':>8s} {'triangles':>9s} {'loops':>5s} {'area m2':>8s} {'min angle':>9s}")
    for name, m in meshes.items():
        print(f"{name:10s} {len(m.vertices):8d} {len(m.triangles):9d} {len(m.boundary):5d} "
              f"{m.area:8.3f} {m.min_angle:8.1f}°")
    if args.output:
        from PIL import Image

        from ..mesh.picture import mesh_picture

        # one picture a mesh, side by side at the same height
        tiles = [mesh_picture(m, size=PICTURE_SIZE // 2) for m in meshes.values()]
        height = max(t.height for t in tiles)
        tiles = [t.resize((round(t.width * height / t.height), height)) for t in tiles]
        row = Image.new("RGB", (sum(t.width for t in tiles), height), "white")
        x = 0
        for t in tiles:
            row.paste(t, (x, 0))
            x += t.width
        row.thumbnail((PICTURE_SIZE, PICTURE_SIZE))
        save_picture(row, args.output)
    return 0

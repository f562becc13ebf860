"""Materials: the same block in four materials (springs and three presets) dropped on a floor.

Every block is 0.4 m square; after they land the example prints how far each sags under its
own weight against the estimate ``density g H / (2 E)`` of a finite-element material (the
seed's springs have no Young's modulus: their sag follows ``stiffness`` and ``mass``).
"""

from __future__ import annotations

import deforma

from ._common import parser, save_world, step_for

SIDE = 0.4  # m
#: label -> material (None: the world's springs, the original's model)
MATERIALS = {
    "springs": None,
    "jelly": deforma.Material.preset("jelly"),
    "foam": deforma.Material.preset("foam"),
    "rubber": deforma.Material.preset("rubber"),
}


def main(argv: list[str] | None = None) -> int:
    """Drop one block per material; print each one's sag at rest."""
    args = parser("materials", __doc__).parse_args(argv)
    world = deforma.World(mass=2.0, stiffness=3000.0)  # the springs block's: soft enough to see it sag
    world.add_collider(deforma.Rect(center=(1.05, -0.1), size=(3.0, 0.2), angle=0.0))
    square = deforma.mesh.box(((0, 0), (SIDE, 0), (SIDE, SIDE), (0, SIDE)), detail=6, edges=True)
    bodies = {label: world.add_body(square, position=(0.7 * k, 0.5), material=mat)
              for k, (label, mat) in enumerate(MATERIALS.items())}
    step_for(world, 2.0)
    g = -world.gravity[1]
    print(f"{'material':8s} {'height m':>9s} {'sag':>7s} {'estimate':>9s}")
    for label, body in bodies.items():
        height = float(body.positions[:, 1].max() - body.positions[:, 1].min())
        mat = MATERIALS[label]
        estimate = f"{mat.density * g * SIDE / (2 * mat.youngs_modulus):9.2%}" if mat else f"{'-':>9s}"
        print(f"{label:8s} {height:9.4f} {1 - height / SIDE:7.2%} {estimate}")
    save_world(world, args.output)
    return 0

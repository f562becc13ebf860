"""Tearing: a sheet held on its left side is pulled on its right until it tears in two.

A material with ``tear_strain`` cuts every mesh edge stretched beyond it (the crack starts at
the outline and runs inward an edge a step); ``body.pieces`` labels the connected pieces.
Mass and momentum are kept through the cut.
"""

from __future__ import annotations

import numpy as np

import deforma

from ._common import parser, save_world


def main(argv: list[str] | None = None) -> int:
    """Pull a pinned sheet apart; print when it tears and into how many pieces."""
    args = parser("tearing", __doc__).parse_args(argv)
    sheet = deforma.mesh.box(((0, 0), (1, 0), (1, 0.5), (0, 0.5)), detail=8, edges=True)
    mat = deforma.Material("corotated", youngs_modulus=2e4, poisson_ratio=0.3, density=2.0, tear_strain=0.3)
    world = deforma.World(gravity=(0, 0), integrator="implicit-euler", material=mat)
    body = world.add_body(sheet, position=None)
    body.pin(np.flatnonzero(body.positions[:, 0] < 1e-9))  # the left side held
    mass = body.mass
    grab = world.grab((0.99, 0.25), radius=0.15, strength=500.0)
    torn_at = None
    for k in range(300):
        world.drag(grab, (1.0 + 0.003 * k, 0.25))  # pulled to the right, 0.18 m/s
        world.step()
        if torn_at is None and body.pieces.max() > 0:
            torn_at = world.time
    world.release(grab)
    pieces = int(body.pieces.max()) + 1
    when = f"first cut through at t = {torn_at:.2f} s" if torn_at is not None else "never cut through"
    print(f"{pieces} pieces ({when}); {len(sheet.vertices)} -> {len(body.positions)} vertices; "
          f"mass {mass:.4f} -> {body.mass:.4f} kg")
    save_world(world, args.output)
    return 0

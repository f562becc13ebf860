"""Colliders: every shape (rectangle, circle, segment, polygon, a picture's outline), fixed and moving.

Soft rings roll through a course of colliders: a ramp (a rectangle), a spinning roller (a
circle with an angular velocity: a moving collider), a wire (a segment with a radius), a cup
(a concave polygon) and the donut picture traced into polygons by
``deforma.colliders_from_image``. Each collider may override the world's friction.
"""

from __future__ import annotations

import deforma

from ._common import parser, save_world, step_for


def main(argv: list[str] | None = None) -> int:
    """Drop soft rings onto a course of every collider shape; print where each ends up."""
    args = parser("colliders", __doc__).parse_args(argv)
    world = deforma.World(material=deforma.Material.preset("jelly"))
    world.add_collider(deforma.Rect((-1.3, 1.6), (2.0, 0.1), -15.0))                         # a ramp
    world.add_collider(deforma.Circle((0.0, 0.9), 0.25, angular_velocity=-180.0, friction=0.8))  # a roller
    world.add_collider(deforma.Segment((0.4, 0.6), (1.6, 0.2), radius=0.03))                # a wire
    world.add_collider(deforma.Polygon([[1.8, -0.5], [3.8, -0.5], [3.8, 0.2], [3.7, 0.2], [3.7, -0.4],
                                        [1.9, -0.4], [1.9, 0.2], [1.8, 0.2]]))              # a cup
    for piece in deforma.colliders_from_image("donut", scale=0.002, position=(-1.9, 0.2), tolerance=4.0):  # a picture
        world.add_collider(piece)
    world.add_collider(deforma.Rect((0.5, -0.6), (6.0, 0.2), 0.0))                          # the floor
    ball = deforma.mesh.from_image("donut", resolution=24, edge_step=6, scale=0.0008)
    balls = [world.add_body(ball, position=(-2.0 + 0.3 * k, 2.3 + 0.3 * k)) for k in range(3)]
    step_for(world, 3.0)
    for k, b in enumerate(balls):
        x, y = b.positions.mean(axis=0)
        print(f"ring {k}: at ({x:5.2f}, {y:5.2f}) m, speed {float(abs(b.velocity).max()):.2f} m/s")
    save_world(world, args.output)
    return 0

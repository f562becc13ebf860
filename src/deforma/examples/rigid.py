"""Rigid bodies and joints: a chain of rigid links hinged to the world swings and knocks a crate.

``Material("rigid", density=...)`` makes any mesh a rigid body; ``world.join`` pins two bodies
(or a body and the world) at a point, and ``joint.force`` is the force that held them over
the last step. A pin with ``motor_speed`` turns a paddle at that speed.
"""

from __future__ import annotations

import deforma

from ._common import parser, save_world, step_for


def main(argv: list[str] | None = None) -> int:
    """Swing a four-link chain into a crate and drive a paddle; print the hinge's force and what moved."""
    args = parser("rigid", __doc__).parse_args(argv)
    world = deforma.World()
    world.add_collider(deforma.Rect((0.5, -0.1), (5.0, 0.2), 0.0))
    rigid = deforma.Material("rigid", density=100.0)
    link = deforma.mesh.box(((0, -0.03), (0.3, -0.03), (0.3, 0.03), (0, 0.03)), detail=2)
    top = (-1.0, 1.3)
    links = [world.add_body(link, position=(top[0] + 0.15 + 0.31 * k, top[1]), material=rigid) for k in range(4)]
    hinge = world.join(links[0], None, at=top)  # the chain's top, hinged to the world
    for k in range(1, 4):
        world.join(links[k], links[k - 1], at=(top[0] + 0.31 * k, top[1]))  # each link's end on the one before
    crate = world.add_body(deforma.mesh.box(((0, 0), (0.3, 0), (0.3, 0.3), (0, 0.3)), detail=2),
                           position=(-1.3, 0.15), material=rigid)  # where the chain's tip sweeps by
    paddle = world.add_body(deforma.mesh.box(((0, 0), (0.8, 0), (0.8, 0.08), (0, 0.08)), detail=2),
                            position=(1.0, 0.8), material=rigid)
    motor = world.join(paddle, None, at=(1.0, 0.8), motor_speed=90.0)  # degrees/s, counter-clockwise
    step_for(world, 2.0)
    fx, fy = hinge.force
    print(f"hinge force ({fx:.1f}, {fy:.1f}) N on a chain of {sum(b.mass for b in links):.1f} kg, still swinging")
    print(f"crate: knocked {crate.positions[:, 0].mean() + 1.3:+.2f} m sideways, turned {crate.angle:.0f} degrees")
    print(f"paddle: turned {paddle.angle:.0f} degrees in {world.time:.1f} s, spinning at "
          f"{paddle.angular_velocity:.0f} degrees/s (motor speed {motor.motor_speed:.0f})")
    save_world(world, args.output)
    return 0

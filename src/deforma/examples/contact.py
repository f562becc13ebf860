"""Contact: soft boxes stacked on a floor, with the contact forces between them and begin/end events.

Bodies touch each other and the floor through the same contact rows; ``world.contact_pairs()``
sums the last step's contacts of each touching pair (impulse, points) and ``world.on_contact``
reports pairs that begin or end touching.
"""

from __future__ import annotations

import deforma

from ._common import parser, save_world, step_for


def main(argv: list[str] | None = None) -> int:
    """Drop three boxes onto each other; print each pair's contact force at rest and the events."""
    args = parser("contact", __doc__).parse_args(argv)
    world = deforma.World(material=deforma.Material.preset("gummy"), friction=0.6, static_friction=0.8)
    floor = world.add_collider(deforma.Rect(center=(0, -0.1), size=(3.0, 0.2), angle=0.0))
    boxes, bottom = [], 0.02
    for side in (0.6, 0.45, 0.3):  # largest at the bottom, each 2 cm above the one below
        square = deforma.mesh.box(((0, 0), (side, 0), (side, side), (0, side)), detail=5, edges=True)
        boxes.append(world.add_body(square, position=(0.0, bottom + side / 2)))
        bottom += side + 0.02
    events = []
    world.on_contact(lambda e: events.append((round(e.step * world.dt, 2), e.kind, name(e.a), name(e.b))))

    def name(thing) -> str:
        return "floor" if thing is floor else f"box {boxes.index(thing)}"

    step_for(world, 2.5)
    for t, kind, a, b in events:
        print(f"t = {t:4.2f} s  {kind:5s} {a} - {b}")
    print("at rest (force = impulse / dt, against the weight resting on it):")
    masses = [b.mass for b in boxes]
    for pair in world.contact_pairs():
        k = boxes.index(pair.a)
        above = sum(masses[k:]) if pair.b is floor else sum(masses[boxes.index(pair.b):])
        print(f"  {name(pair.a)} - {name(pair.b)}: {pair.normal_impulse / world.dt:7.1f} N "
              f"(weight above: {above * -world.gravity[1]:7.1f} N)")
    save_world(world, args.output)
    return 0

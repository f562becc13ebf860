"""Physics: soft bodies of springs or finite elements, colliders of any shape with Coulomb friction.

``World`` ties together the constant ``Model`` (springs, rest lengths, masses), the
``State`` (positions, velocities), the force kernels, an integrator chosen by name and the
collider leaf. See ``docs/physics.md`` for the model and the friction scheme.
"""

from .colliders.shapes import (
           Circle,
           Collider,
           Polygon,
           Rect,
           Segment,
           colliders_from_image,
)
from .integrators import available_integrators, register_integrator
from .material import Material
from .world import Body, Energy, Grab, SimulationUnstable, World

__all__ = ["Body", "Circle", "Collider", "Energy", "Grab", "Material", "Polygon", "Rect", "Segment",
           "SimulationUnstable", "World", "available_integrators", "colliders_from_image", "register_integrator"]

"""Time integrators, one module each, registered by name (``World(integrator=...)``).

- :mod:`~deforma.physics.integrators.base`: the registry, the seam every integrator
  implements, and the tail the position-based ones share;
- :mod:`~deforma.physics.integrators.symplectic`: ``"symplectic-euler"``, the original's;
- :mod:`~deforma.physics.integrators.implicit`: ``"implicit-euler"`` and, second order,
  ``"implicit-bdf2"``;
- :mod:`~deforma.physics.integrators.xpbd`: ``"xpbd"``;
- :mod:`~deforma.physics.integrators.avbd`: ``"avbd"``, Augmented Vertex Block Descent (the
  default).

Importing this package registers the five, in the order they were written.
"""

# isort: skip_file
from .base import available_integrators, make_integrator, register_integrator
from . import symplectic, implicit, xpbd  # noqa: F401  (each registers its integrator)
from .implicit import bdf2  # noqa: F401  (after xpbd: the first three keep their order)
from . import avbd  # noqa: F401

__all__ = ["available_integrators", "make_integrator", "register_integrator"]

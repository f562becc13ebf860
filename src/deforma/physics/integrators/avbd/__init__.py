"""``"avbd"``: Augmented Vertex Block Descent, backward Euler by Gauss-Seidel over per-vertex
blocks with contacts as augmented-Lagrangian rows.

- :mod:`~deforma.physics.integrators.avbd.blocks`: a vertex's 2 x 2 block from each element kind;
- :mod:`~deforma.physics.integrators.avbd.colouring`: vertices coloured so a colour shares no element;
- :mod:`~deforma.physics.integrators.avbd.rows`: contact rows with Coulomb friction, warm-started;
- :mod:`~deforma.physics.integrators.avbd.solver`: the step, registered as ``"avbd"``.
"""

from .solver import AVBD

__all__ = ["AVBD"]

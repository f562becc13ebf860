"""``"avbd"``: Augmented Vertex Block Descent, backward Euler by Gauss-Seidel over per-vertex
blocks with contacts as augmented-Lagrangian rows.

- :mod:`~deforma.physics.integrators.avbd.blocks`: a vertex's 2 x 2 block from each element kind;
- :mod:`~deforma.physics.integrators.avbd.colouring`: vertices coloured so a colour shares no element;
- :mod:`~deforma.physics.integrators.avbd.rows`: contact rows with Coulomb friction, warm-started
  (collider faces and corners, other bodies' and a body's own outline);
- :mod:`~deforma.physics.integrators.avbd.gas`: a body's gas pressure as energy in its vertices' blocks;
- :mod:`~deforma.physics.integrators.avbd.clusters`: the coarse level of affine patches;
- :mod:`~deforma.physics.integrators.avbd.solver`: the step, registered as ``"avbd"``.
"""

from .solver import AVBD

__all__ = ["AVBD"]

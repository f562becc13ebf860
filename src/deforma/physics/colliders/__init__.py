"""Colliders: the shapes a user places, and how vertices meet them.

- :mod:`~deforma.physics.colliders.shapes`: the Python objects (``Rect``, ``Circle``,
  ``Polygon``, ``Segment``, levels from pictures) and their packing into one array;
- :mod:`~deforma.physics.colliders.geometry`: the packed shapes as compiled tests (inside,
  exit face, swept paths) and their motion: a leaf that knows shapes and points only;
- :mod:`~deforma.physics.colliders.response`: the per-vertex collision and Coulomb
  friction response, corners against outlines, and the contact planes the stable solvers
  hold inside their solve.
"""

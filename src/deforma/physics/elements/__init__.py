"""Element kinds: what holds a body together and the kernels each integrator runs over it.

- :mod:`~deforma.physics.elements.springs`: the original's springs along mesh edges;
- :mod:`~deforma.physics.elements.triangles`: triangle finite elements (geometry and the
  passes every integrator runs over them), whose energy density comes from
  :mod:`~deforma.physics.elements.corotated` or :mod:`~deforma.physics.elements.neo_hookean`.
"""

"""Implicit (backward) Euler, ``"implicit-euler"``: the solver, the matrix assembly and the
factor kept across small changes.

- :mod:`~deforma.physics.integrators.implicit.solver`: the integrator and its kernels
  (right-hand sides, contact local steps);
- :mod:`~deforma.physics.integrators.implicit.assembly`: the constant global matrix and
  the contacts' entries merged into it;
- :mod:`~deforma.physics.integrators.implicit.updated_factor`: the sparse factorisation
  corrected by low-rank updates.
"""

from .solver import ImplicitEuler

__all__ = ["ImplicitEuler"]

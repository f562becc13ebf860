"""Implicit integration, ``"implicit-euler"`` (backward Euler) and ``"implicit-bdf2"`` (BDF2,
second order): the solver, its acceleration, the matrix assembly and the factor kept across
small changes.

- :mod:`~deforma.physics.integrators.implicit.solver`: the integrator and its kernels
  (right-hand sides, contact local steps);
- :mod:`~deforma.physics.integrators.implicit.bdf2`: BDF2 as backward Euler steps of 2h/3
  from the two last states (registered by the integrators package, after xpbd);
- :mod:`~deforma.physics.integrators.implicit.anderson`: Anderson acceleration of the
  converged solve;
- :mod:`~deforma.physics.integrators.implicit.assembly`: the constant global matrix and
  the contacts' entries merged into it;
- :mod:`~deforma.physics.integrators.implicit.updated_factor`: the sparse factorisation
  corrected by low-rank updates.
"""

from .solver import ImplicitEuler

__all__ = ["ImplicitEuler"]

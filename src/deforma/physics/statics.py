"""Static equilibrium: where the bodies come to rest under pins, gravity, applied forces and
contacts, without the motion that leads there.

:func:`solve_static` relaxes the world by backward Euler steps of the longest step the World
takes (0.1 s), each solved to a tolerance, with every velocity set to zero before each step
(implicit pseudo-time stepping, or dynamic relaxation with an implicit integrator). A step
from rest moves each mode of angular frequency ``omega`` the fraction
``(h omega)^2 / (1 + (h omega)^2)`` of its way to equilibrium, so stiff modes arrive in one
step and soft ones (a sway on a contact, a long soft body) in a few; the answer is the
minimum of the bodies' potential (elastic energy minus the work of gravity and the forces)
under the pins and contacts, whatever the path. It stops when the vertices are estimated to
be within ``tolerance`` of where they settle: the last step's largest move, times ``r / (1 -
r)`` where the moves shrink by ``r > 1/2`` per step.

What it refuses, in one line and changing nothing: bodies that nothing holds (no pinned
vertex and no collider in the world) under gravity or a force, materials whose rest shape depends on
the path (tearing, plasticity), and a world that does not settle within ``max_iterations``
relaxation steps (the World is put back as it was).

Units: m, s.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..checks import number
from .integrators import make_integrator

if TYPE_CHECKING:
    from .world import World

#: The relaxation step: the longest ``dt`` a World takes (s).
RELAX_STEP = 0.1
#: The velocity tolerance of each relaxation step's solve (m/s).
SOLVE_TOLERANCE = 1e-6


def solve_static(world: "World", *, tolerance: float = 1e-6, max_iterations: int = 1000) -> int:
    """Move every body to its static equilibrium (see the module docstring); returns the
    relaxation steps it took. ``world.time`` and ``world.step_count`` stay; velocities end at
    zero; the forces applied with ``body.apply_force`` act throughout and are then forgotten,
    as after a step."""
    tol = number(tolerance, "tolerance")
    if not tol > 0.0:
        raise ValueError(f"tolerance must be a distance > 0 m, got {tolerance!r}")
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, (int, np.integer)) \
            or not 1 <= max_iterations <= 100_000:
        raise ValueError(f"max_iterations must be an integer in [1, 100000], got {max_iterations!r}")
    bodies = world.bodies
    if not bodies:
        return 0
    for i, b in enumerate(bodies):
        m = b.material
        if m is not None and (m.tear_strain is not None or m.yield_strain is not None):
            raise ValueError(f"solve_static needs elastic bodies: body {i} "
                             f"{'tears' if m.tear_strain is not None else 'yields'}, so where it rests depends "
                             f"on how it got there (step the world instead)")
    if not world.colliders and not any(b.pinned.any() for b in bodies) and (any(world.gravity) or world._forces):
        raise ValueError("solve_static: nothing holds the bodies (no pinned vertex, no collider), so they would "
                         "fall for ever: pin a vertex, or add a collider under them")
    # what the relaxation borrows, and what a failure puts back (tearing and plasticity are
    # refused above, so the topology and rest shapes stay; moving colliders hold still)
    x0, v0, lost = world._state.x.copy(), world._state.v.copy(), dict(world._lost_shape)
    forces = list(world._forces)
    borrowed = (world._integrator, world._dt, world._substeps, world._auto, world.time, world.step_count)
    motions = [(c, c.velocity, c.angular_velocity) for c in world.colliders]
    for c, _, _ in motions:
        c.velocity, c.angular_velocity = (0.0, 0.0), 0.0
    world._integrator = make_integrator("implicit-euler", {"tolerance": SOLVE_TOLERANCE, "max_iterations": 2000})
    world._dt, world._substeps, world._auto = RELAX_STEP, 1, False
    done, settled, moved = 0, False, math.inf
    try:
        for done in range(1, max_iterations + 1):
            before = world._state.x.copy()
            world._state.v[:] = 0.0
            world._forces[:] = forces
            world.step()
            moved, last = float(np.abs(world._state.x - before).max(initial=0.0)), moved
            # the steps shrink geometrically near the answer, by r each: what is left to go is
            # about moved r / (1 - r), more than the last step where r > 1/2 (soft modes)
            r = moved / last if last > 0.0 else 0.0
            if moved == 0.0 or (r < 1.0 and moved * max(1.0, r / (1.0 - r)) <= tol):
                settled = True
                break
        if not settled:
            raise ValueError(f"solve_static did not settle within max_iterations = {max_iterations} relaxation "
                             f"steps (the last moved a vertex {moved:.3g} m; tolerance {tol:g} m): raise "
                             f"max_iterations, or support the bodies better")
    except BaseException:
        world._state.x[...] = x0  # the shapes are the same: the arrays are too
        world._state.v[...] = v0
        world._lost_shape = lost
        world._forces[:] = forces
        raise
    finally:
        (world._integrator, world._dt, world._substeps, world._auto, world.time, world.step_count) = borrowed
        for c, velocity, spin in motions:
            c.velocity, c.angular_velocity = velocity, spin
        world._packed_colliders = None  # their velocities changed twice: pack them again
    world._state.v[:] = 0.0
    world._forces.clear()
    return done


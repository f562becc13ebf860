"""Time integrators behind a small registry, keyed by name (``World(integrator=...)``).

An integrator advances a :class:`~deforma.physics.model.Model` and its
:class:`~deforma.physics.state.State` by ``substeps`` substeps of length ``h``, including
the collision response (:func:`~deforma.physics.colliders.collide_point`, which needs the
position before and after each substep), and reports how many vertices ended non-finite or
faster than ``max_speed``. It also saves the state at the start of the step into
``state.x_start`` / ``state.v_start`` so the world can undo a failed step.

Only ``"symplectic-euler"`` exists now; an implicit Euler or XPBD integrator is a class
with the same ``advance`` signature registered with :func:`register_integrator`.

Semi-implicit (symplectic) Euler, per substep::

    v += h * F(x, v) / m
    x += h * v
    x, v = collide(x_before, x, v)

It is fused into two passes over memory per substep: springs once per spring, then one
per-vertex pass that gathers spring forces and adds gravity and the grab pull, integrates,
collides and checks the result. Both passes run on all cores for bodies big enough to pay
for the thread start-up (``PARALLEL_MIN_VERTICES``, measured in ``benchmarks/``).
"""

from __future__ import annotations

from typing import Callable, Protocol

import numpy as np
from numba import njit, prange

from .colliders import RECT_XMAX, RECT_XMIN, RECT_YMAX, RECT_YMIN, collide_point
from .forces import spring_force, spring_forces_serial

# Below this many vertices one thread is faster than two (thread wake-up ~ a few us).
PARALLEL_MIN_VERTICES = 512


class StepInputs(Protocol):
    """What a world hands an integrator each step (duck-typed; see ``World``)."""

    gravity: tuple[float, float]
    rects: np.ndarray          # (R, RECT_COLUMNS) packed colliders
    grab_slot: np.ndarray      # (N,) int32, grab entry per vertex or -1
    grab_pull: np.ndarray      # (K, 3) float64, (S, S*tx, S*ty) per entry
    max_speed: float           # m/s; faster counts as runaway


class Integrator(Protocol):
    """The seam: one object per world, free to keep scratch arrays between steps."""

    name: str

    def advance(self, model, state, inputs: StepInputs, h: float, substeps: int) -> int:
        """Advance ``substeps`` substeps of ``h`` seconds; return the count of bad vertices."""


_REGISTRY: dict[str, Callable[[], Integrator]] = {}


def register_integrator(name: str):
    """Class decorator: make an integrator available as ``World(integrator=name)``.

    Examples
    --------
    >>> @register_integrator("noop")
    ... class Noop:
    ...     name = "noop"
    ...     def advance(self, model, state, inputs, h, substeps):
    ...         return 0
    >>> "noop" in available_integrators()
    True
    >>> _ = _REGISTRY.pop("noop")
    """
    def deco(cls):
        if name in _REGISTRY:
            raise ValueError(f"an integrator named {name!r} is already registered")
        _REGISTRY[name] = cls
        return cls
    return deco


def available_integrators() -> list[str]:
    """Names accepted by ``World(integrator=...)``."""
    return sorted(_REGISTRY)


def make_integrator(name: str) -> Integrator:
    """A new integrator instance by name; ``ValueError`` naming the choices if unknown."""
    try:
        factory = _REGISTRY[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown integrator {name!r}; available: {', '.join(available_integrators())}") from None
    return factory()


@njit(cache=True, inline="always")
def _semi_implicit_euler(x0, y0, vx, vy, fx, fy, inv_mass, gx, gy, h):
    vx += h * (fx * inv_mass + gx)
    vy += h * (fy * inv_mass + gy)
    return x0 + h * vx, y0 + h * vy, vx, vy


@njit(cache=True, inline="always")
def _is_bad(px, py, vx, vy, vmax2):
    # written so that NaN fails the test too; p - p is NaN for inf and NaN
    if vx * vx + vy * vy <= vmax2 and (px - px) == 0.0 and (py - py) == 0.0:
        return 0
    return 1


# The per-vertex loop bodies below are spelled out in both drivers on purpose, helpers that
# take arrays included: every array passed to a compiled helper per vertex costs atomic
# reference-count updates that Numba does not always prune (a helper taking the dozen
# arrays made the step 10x slower). Scalar-only helpers are free.

@njit(cache=True)
def symplectic_euler_serial(x, v, x_start, v_start, fe, spring_i, spring_j, rest, ks, kd,
                            adj_ptr, adj_spring, adj_sign, inv_mass, gx, gy, grab_slot, grab_pull,
                            rects, h, substeps, vmax2):
    """``substeps`` symplectic Euler substeps of ``h`` s with collisions, one thread.

    Saves the start state into ``x_start`` / ``v_start``; stops early and returns the
    number of vertices that ended non-finite or faster than ``sqrt(vmax2)`` m/s.
    """
    n_rects = rects.shape[0]
    for sub in range(substeps):
        spring_forces_serial(x, v, spring_i, spring_j, rest, ks, kd, fe)
        save = sub == 0
        bad = 0
        for i in range(x.shape[0]):
            x0, y0, vx, vy = x[i, 0], x[i, 1], v[i, 0], v[i, 1]
            if save:
                x_start[i, 0], x_start[i, 1], v_start[i, 0], v_start[i, 1] = x0, y0, vx, vy
            fx = 0.0
            fy = 0.0
            for k in range(adj_ptr[i], adj_ptr[i + 1]):  # forces.gather_spring_force
                e = adj_spring[k]
                fx += adj_sign[k] * fe[e, 0]
                fy += adj_sign[k] * fe[e, 1]
            g = grab_slot[i]
            if g >= 0:  # forces.grab_force
                fx += grab_pull[g, 1] - grab_pull[g, 0] * x0
                fy += grab_pull[g, 2] - grab_pull[g, 0] * y0
            px, py, vx, vy = _semi_implicit_euler(x0, y0, vx, vy, fx, fy, inv_mass[i], gx, gy, h)
            near = False
            for r in range(n_rects):  # broad phase: bounding boxes
                if rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX] and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]:
                    near = True
            if near:
                px, py, vx, vy = collide_point(x0, y0, px, py, vx, vy, rects, h)
            x[i, 0], x[i, 1], v[i, 0], v[i, 1] = px, py, vx, vy
            bad += _is_bad(px, py, vx, vy, vmax2)
        if bad:
            return bad
    return 0


@njit(cache=True, parallel=True)
def symplectic_euler_parallel(x, v, x_start, v_start, fe, spring_i, spring_j, rest, ks, kd,
                              adj_ptr, adj_spring, adj_sign, inv_mass, gx, gy, grab_slot, grab_pull,
                              rects, h, substeps, vmax2):
    """:func:`symplectic_euler_serial` on all cores (same arguments, same result)."""
    n_rects = rects.shape[0]
    for sub in range(substeps):
        for e in prange(spring_i.shape[0]):
            a = spring_i[e]
            b = spring_j[e]
            fe[e, 0], fe[e, 1] = spring_force(x[a, 0], x[a, 1], x[b, 0], x[b, 1], v[a, 0], v[a, 1],
                                              v[b, 0], v[b, 1], rest[e], ks[e], kd[e])
        save = sub == 0
        bad = 0
        for i in prange(x.shape[0]):
            x0, y0, vx, vy = x[i, 0], x[i, 1], v[i, 0], v[i, 1]
            if save:
                x_start[i, 0], x_start[i, 1], v_start[i, 0], v_start[i, 1] = x0, y0, vx, vy
            fx = 0.0
            fy = 0.0
            for k in range(adj_ptr[i], adj_ptr[i + 1]):  # forces.gather_spring_force
                e = adj_spring[k]
                fx += adj_sign[k] * fe[e, 0]
                fy += adj_sign[k] * fe[e, 1]
            g = grab_slot[i]
            if g >= 0:  # forces.grab_force
                fx += grab_pull[g, 1] - grab_pull[g, 0] * x0
                fy += grab_pull[g, 2] - grab_pull[g, 0] * y0
            px, py, vx, vy = _semi_implicit_euler(x0, y0, vx, vy, fx, fy, inv_mass[i], gx, gy, h)
            near = False
            for r in range(n_rects):  # broad phase: bounding boxes
                if rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX] and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]:
                    near = True
            if near:
                px, py, vx, vy = collide_point(x0, y0, px, py, vx, vy, rects, h)
            x[i, 0], x[i, 1], v[i, 0], v[i, 1] = px, py, vx, vy
            bad += _is_bad(px, py, vx, vy, vmax2)
        if bad:
            return bad
    return 0


@register_integrator("symplectic-euler")
class SymplecticEuler:
    """Semi-implicit Euler (the original's): ``v += h F/m; x += h v``, then collisions.

    Stable for ``h`` below roughly ``2 / omega_max`` (see ``World.stable_dt``); energy
    stays bounded without damping.

    Examples
    --------
    >>> make_integrator("symplectic-euler").name
    'symplectic-euler'
    """

    name = "symplectic-euler"

    def __init__(self):
        self._fe = np.zeros((0, 2))

    def advance(self, model, state, inputs, h, substeps):
        if self._fe.shape[0] != model.n_springs:
            self._fe = np.zeros((model.n_springs, 2))
        kernel = symplectic_euler_parallel if model.n_vertices >= PARALLEL_MIN_VERTICES else symplectic_euler_serial
        gx, gy = inputs.gravity
        return kernel(state.x, state.v, state.x_start, state.v_start, self._fe,
                      model.spring_i, model.spring_j, model.spring_rest_length, model.spring_stiffness,
                      model.spring_damping, model.adj_ptr, model.adj_spring, model.adj_sign,
                      model.vertex_inv_mass, float(gx), float(gy), inputs.grab_slot, inputs.grab_pull,
                      inputs.rects, float(h), int(substeps), float(inputs.max_speed) ** 2)

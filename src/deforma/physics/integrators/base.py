"""What every integrator shares: the registry by name, the seam, the position step's tail.

An integrator advances a :class:`~deforma.physics.model.Model` and its
:class:`~deforma.physics.state.State` by ``substeps`` substeps of length ``h``, including
the collision response (:func:`~deforma.physics.colliders.response.collide_point`, which
needs the position before and after each substep), and reports how many vertices ended
non-finite or faster than ``max_speed``. It also saves the state at the start of the step
into ``state.x_start`` / ``state.v_start`` so the world can undo a failed step.

Three are registered, one module each, by :mod:`deforma.physics.integrators`:
``"symplectic-euler"`` (:mod:`~deforma.physics.integrators.symplectic`, the default),
``"implicit-euler"`` (:mod:`~deforma.physics.integrators.implicit`) and ``"xpbd"``
(:mod:`~deforma.physics.integrators.xpbd`); another is a class with the same ``advance``
signature registered with :func:`register_integrator`. An integrator class may set
``unconditionally_stable = True``; ``World.stable_dt`` then reports no explicit step limit
for it.

The position-based integrators (XPBD, implicit Euler) end each substep alike: velocities from
positions, then the collider response (:func:`finish_position_step`).
"""

from __future__ import annotations

from typing import Callable, Protocol

import numpy as np
from numba import njit

from ..colliders.geometry import jump_reach, n_colliders
from ..colliders.response import collide_point, record_hit
from ..colliders.shapes import RECT_XMAX, RECT_XMIN, RECT_YMAX, RECT_YMIN


@njit(cache=True, inline="always")
def is_bad(px, py, vx, vy, vmax2):
    """1 if the vertex state is non-finite or faster than ``sqrt(vmax2)`` m/s, else 0."""
    # written so that NaN fails the test too; p - p is NaN for inf and NaN
    if vx * vx + vy * vy <= vmax2 and (px - px) == 0.0 and (py - py) == 0.0:
        return 0
    return 1


@njit(cache=True)
def finish_position_step(x, v, x_prev, rects, hits, stamp, h, vmax2):
    """End a substep of a position-based integrator: velocities, contacts, the bad-vertex count.

    Implicit Euler and XPBD both produce new positions; the velocity is then
    ``(x - x_prev) / h`` and contacts with friction act as in symplectic Euler.

    Parameters
    ----------
    x, v : (N, 2) float64
        Solved positions (m), updated in place with the collided positions; velocities
        (m/s), output.
    x_prev : (N, 2) float64
        Positions at the start of the substep (m).
    rects : (R, RECT_COLUMNS) float64
        From :func:`~deforma.physics.colliders.shapes.pack_colliders`.
    hits : ColliderHits
        Where each vertex that touches a collider is noted, with ``stamp``.
    h : float
        Substep (s).
    vmax2 : float
        Squared runaway speed (m^2/s^2).

    Returns
    -------
    int
        Vertices that ended non-finite or faster than ``sqrt(vmax2)``.
    """
    # serial on purpose: a few percent of a step (the solves dominate), and a parallel loop
    # waits out other processes' time slices at its barrier when the cores are busy (the
    # 4 s jelly comparison once took 27.6 s instead of 1.7 s while the other core was busy)
    inv_h = 1.0 / h
    reach2 = jump_reach(rects)
    n_rects = n_colliders(rects)
    bad = 0
    for i in range(x.shape[0]):
        x0, y0 = x_prev[i, 0], x_prev[i, 1]
        px, py = x[i, 0], x[i, 1]
        vx = (px - x0) * inv_h
        vy = (py - y0) * inv_h
        near = False
        for r in range(n_rects):  # broad phase: bounding boxes
            if rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX] and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]:
                near = True
        if near or (px - x0) ** 2 + (py - y0) ** 2 > reach2:
            px, py, vx, vy, hit, nx, ny, depth = collide_point(x0, y0, px, py, vx, vy, rects, h)
            if hit >= 0:
                record_hit(hits, i, stamp, hit, nx, ny, depth)
        x[i, 0], x[i, 1], v[i, 0], v[i, 1] = px, py, vx, vy
        bad += is_bad(px, py, vx, vy, vmax2)
    return bad

class StepInputs(Protocol):
    """What a world hands an integrator each step (duck-typed; see ``World``)."""

    gravity: tuple[float, float]
    air_drag: float            # 1/s: every velocity decays as dv/dt = -air_drag v
    rects: np.ndarray          # (R, RECT_COLUMNS) packed colliders
    hits: tuple                # colliders.ColliderHits: who touched which collider, per vertex
    contact_scratch: tuple     # contacts.ContactScratch
    contacts: tuple            # contacts.ContactBuffer
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
    """Names accepted by ``World(integrator=...)``, in registration order (the default first).

    Examples
    --------
    >>> available_integrators()[:3]
    ['symplectic-euler', 'implicit-euler', 'xpbd']
    """
    return list(_REGISTRY)


def make_integrator(name: str) -> Integrator:
    """A new integrator instance by name; ``ValueError`` naming the choices if unknown."""
    try:
        factory = _REGISTRY[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown integrator {name!r}; available: {', '.join(available_integrators())}") from None
    return factory()

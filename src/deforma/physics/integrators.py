"""Time integrators behind a small registry, keyed by name (``World(integrator=...)``).

An integrator advances a :class:`~deforma.physics.model.Model` and its
:class:`~deforma.physics.state.State` by ``substeps`` substeps of length ``h``, including
the collision response (:func:`~deforma.physics.colliders.collide_point`, which needs the
position before and after each substep), and reports how many vertices ended non-finite or
faster than ``max_speed``. It also saves the state at the start of the step into
``state.x_start`` / ``state.v_start`` so the world can undo a failed step.

Three are registered, one module each, when ``deforma.physics`` is imported:
``"symplectic-euler"`` (:mod:`~deforma.physics.symplectic`, the default), ``"implicit-euler"``
(:mod:`~deforma.physics.implicit`) and ``"xpbd"`` (:mod:`~deforma.physics.xpbd`); another is
a class with the same ``advance`` signature registered with :func:`register_integrator`.
This module imports none of them (they import it), so there is no import cycle.
An integrator class may set ``unconditionally_stable = True``; ``World.stable_dt`` then
reports no explicit step limit for it.
"""

from __future__ import annotations

from typing import Callable, Protocol

import numpy as np

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

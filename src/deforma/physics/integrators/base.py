"""What every integrator shares: the seam, its options, the registry by name, and the
contact stages every substep runs before and after the integrator's own work.

An integrator is an object (one per world, free to keep scratch arrays between steps) with

    report = integrator.step(model, state_in, state_out, control, contacts, h,
                             substeps=1, max_speed=inf)

which advances ``state_out`` by ``substeps`` substeps of ``h`` seconds and returns a
:class:`StepReport`. ``state_in`` is the state the step started from: the integrator never
writes it, so a failed step is undone by keeping it. ``state_out`` arrives holding what the
integrator advances: ``state_in``, or what an earlier stage of the step made of it (the gas
pressure's kick on the velocities). ``control`` (:class:`~deforma.physics.control.Control`)
says what acts on the bodies, ``contacts`` (:class:`~deforma.physics.contact.contacts.Contacts`)
is the contact data the substeps fill.

Every substep of every integrator has the same frame: colliders moved to the substep's end;
the integrator's own work; the collider response per vertex; then :func:`contact_epilogue`
(collider corners against outlines, and the body contact stage of
:mod:`deforma.physics.contact`). The integrators that hold contacts inside their solve or
sweep (XPBD, implicit Euler) also list them first, for the predicted motion
(:func:`held_contacts`), and end with velocities from positions (:func:`finish_position_step`).

Five are registered, one module each, by :mod:`deforma.physics.integrators`:
``"symplectic-euler"`` (:mod:`~deforma.physics.integrators.symplectic`, the default),
``"implicit-euler"`` and ``"implicit-bdf2"`` (:mod:`~deforma.physics.integrators.implicit`),
``"xpbd"`` (:mod:`~deforma.physics.integrators.xpbd`) and ``"avbd"``
(:mod:`~deforma.physics.integrators.avbd`). Another is a subclass of :class:`Integrator`
registered with :func:`register_integrator`; its :attr:`Integrator.OPTIONS` are its settings
(``World(integrator_options=...)``, ``world.integrator_options``, the scene key
``[physics.integrator_options]``).
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Mapping, NamedTuple, TypeVar

import numpy as np
from numba import njit

from ..colliders.geometry import jump_reach, n_colliders
from ..colliders.response import collide_dynamic, collide_point, contact_planes, push_edges_off_corners, record_hit
from ..colliders.shapes import RECT_XMAX, RECT_XMIN, RECT_YMAX, RECT_YMIN
from ..contact.broad_phase import gather_start
from ..contact.narrow_phase import detect_contacts
from ..contact.response import hold_start_distance
from ..contact.stage import contact_stage

if TYPE_CHECKING:
    from ..contact.contacts import Contacts
    from ..contact.pairs import ContactImpulses
    from ..control import Control
    from ..model import Model
    from ..state import State


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
            qx, qy, ux, uy = px, py, vx, vy
            px, py, vx, vy, hit, nx, ny, depth = collide_point(x0, y0, px, py, vx, vy, rects, h)
            if hit >= 0:
                record_hit(hits, i, stamp, hit, nx, ny, depth, qx, qy, ux, uy, px, py, vx, vy)
        x[i, 0], x[i, 1], v[i, 0], v[i, 1] = px, py, vx, vy
        bad += is_bad(px, py, vx, vy, vmax2)
    return bad


@njit(cache=True)
def held_contacts(x_prev, y, rects, planes, touch, rows, dynamic, h, topo, scr, buf):
    """The contacts a stable solver holds inside its solve or sweep, for the motion from
    ``x_prev`` to the prediction ``y``: the collider contact planes
    (:func:`~deforma.physics.colliders.response.contact_planes`, into ``planes`` and
    ``touch``) and the body contacts (:func:`~deforma.physics.contact.narrow_phase.detect_contacts`,
    into ``buf``, each held no closer than its pair started:
    :func:`~deforma.physics.contact.response.hold_start_distance`). Also notes the start of
    the substep for the contact stage (:func:`~deforma.physics.contact.broad_phase.gather_start`).
    ``rows``, ``dynamic``: see ``contact_planes``.

    Returns ``(count, n_body)``: how many collider and body contacts; ``n_body`` is -1 when
    the buffer was too small (the World grows it and runs the step again).
    """
    count = contact_planes(x_prev, y, rects, planes, touch, rows, dynamic, h)
    gather_start(x_prev, topo, scr)
    n_body = detect_contacts(y, topo, scr, buf)  # of the predicted motion
    if n_body >= 0:
        hold_start_distance(x_prev, topo, buf, n_body)
    return count, n_body


@njit(cache=True)
def contact_epilogue(x, v, inv_mass, x_start, topo, scr, buf, rects, hits, h, follow):
    """The end of every substep, after the collider response: points in rigid bodies put out
    of them (:func:`~deforma.physics.colliders.response.collide_dynamic`, from ``x_start``, where the
    vertices began the substep), collider corners pushed off
    body outlines (:func:`~deforma.physics.colliders.response.push_edges_off_corners`), then
    the body contact stage (:func:`~deforma.physics.contact.stage.contact_stage`; ``follow``:
    whether its velocity impulses move positions too). Returns the stage's result: -1 when
    the buffer was too small (the World grows it and runs the step again)."""
    collide_dynamic(x, v, inv_mass, x_start, rects, hits, scr.status.stamp[0] + 1, h)
    push_edges_off_corners(x, v, inv_mass, topo.ce_a, topo.ce_b, topo.cv_vertex, rects, hits)
    return contact_stage(x, v, inv_mass, topo, scr, buf, rects, hits, h, follow)


class StepReport(NamedTuple):
    """What :meth:`Integrator.step` says of the step it ran (a named tuple: made every step).

    Attributes
    ----------
    bad_vertices : int
        Vertices that ended a substep non-finite or faster than ``max_speed``; the step
        stopped there (``state_out`` is garbage: keep ``state_in``).
    complete : bool
        False when the contact buffer was too small: ``contacts.needed`` says how large it
        must be; grow it and run the step again from ``state_in``.
    unconverged : int
        Substeps of an iterative solve that stopped at its iteration limit short of its
        tolerance (the step stands; the World counts them as a warning).
    """

    bad_vertices: int = 0
    complete: bool = True
    unconverged: int = 0


@dataclass(frozen=True)
class Option:
    """One setting of an integrator: its name, default and what values it takes.

    ``kind`` is ``"int"`` (an integer in ``[low, high]``), ``"float"`` (a number in the open
    interval ``(low, high)``, or ``[low, high)`` with ``closed_low``) or ``"choice"`` (one of
    ``choices``).

    Examples
    --------
    >>> Option("iterations", 3, "int", low=1, high=10_000, doc="sweeps").check(5, "xpbd")
    5
    """

    name: str
    default: Any
    kind: str
    low: float = -math.inf
    high: float = math.inf
    choices: tuple = ()
    doc: str = ""
    closed_low: bool = False

    def allowed(self) -> str:
        """What the option takes, in words."""
        if self.kind == "int":
            return f"an integer in [{self.low:g}, {self.high:g}]"
        if self.kind == "float":
            return f"a number in {'[' if self.closed_low else '('}{self.low:g}, {self.high:g})"
        return "one of " + ", ".join(repr(c) for c in self.choices)

    def check(self, value: Any, integrator: str) -> Any:
        """``value`` as the option keeps it; ``ValueError`` saying what is allowed if it is not."""
        bad = ValueError(f"{integrator} option {self.name} must be {self.allowed()}, got {value!r}")
        if self.kind == "int":
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) \
                    or not self.low <= value <= self.high:
                raise bad
            return int(value)
        if self.kind == "float":
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                    or not (self.low <= float(value) if self.closed_low else self.low < float(value)) \
                    or not float(value) < self.high:
                raise bad
            return float(value)
        if value not in self.choices:
            raise bad
        return value


class Integrator:
    """The seam every integrator implements: :meth:`step`, and its options by name.

    A subclass sets :attr:`name`, its :attr:`OPTIONS` and :meth:`step`; it is made available
    as ``World(integrator=name)`` by :func:`register_integrator`. Its options are read as
    ``self.options[name]``. ``unconditionally_stable = True`` tells ``World.stable_dt`` that
    it has no explicit step limit. ``solves_pressure = True`` says that its step holds the
    bodies' gas itself (else the stepper kicks the velocities by the gas force first,
    :mod:`deforma.physics.behaviours.pressure`). ``solves_rigid = True`` says that it moves
    the rigid bodies as blocks of its own solve (else the rigid stage does after each
    substep, :mod:`deforma.physics.rigid`). :meth:`stats` gives counters a user may want
    to see (``world.integrator_stats``).

    Examples
    --------
    >>> make_integrator("xpbd").options
    {'iterations': 1}
    """

    name: str = ""
    OPTIONS: tuple[Option, ...] = ()
    unconditionally_stable = False
    solves_pressure = False
    solves_rigid = False

    def __init__(self, **options: Any) -> None:
        self._options = {o.name: o.default for o in self.OPTIONS}
        self.configure(options)

    @property
    def options(self) -> dict:
        """The integrator's settings by name (a copy: set them with :meth:`configure`)."""
        return dict(self._options)

    def configure(self, options: Mapping[str, Any]) -> None:
        """Set the options named in the mapping ``options``; the others go back to their
        defaults. Checks every value first: a bad one raises ``ValueError`` and changes nothing."""
        if not hasattr(options, "items"):
            raise ValueError(f"{self.name} options must be a table of name = value, got {options!r}")
        mine = {o.name: o for o in self.OPTIONS}
        new = {o.name: o.default for o in self.OPTIONS}
        for key, value in options.items():
            if key not in mine:
                raise ValueError(unknown_option(key, self.name))
            new[key] = mine[key].check(value, self.name)
        self._options = new
        self._options_changed()

    def _options_changed(self) -> None:
        """Called after the options changed (a subclass drops what depended on them)."""

    def stats(self) -> dict:
        """Counters of the work done so far (per integrator; empty by default)."""
        return {}

    def contact_impulses(self, model: Model) -> ContactImpulses | None:
        """The last step's contact rows with their impulses
        (:class:`~deforma.physics.contact.pairs.ContactImpulses`), or None where the integrator
        keeps no contact force (the World then lists its contacts without impulses)."""
        return None

    def step(self, model: Model, state_in: State, state_out: State, control: Control, contacts: Contacts, h: float,
             *, substeps: int = 1,
             max_speed: float = math.inf) -> StepReport:
        """Advance ``state_out`` by ``substeps`` substeps of ``h`` seconds (see the module docstring)."""
        raise NotImplementedError


def unknown_option(key: Any, integrator: str) -> str:
    """The message for an option ``key`` that ``integrator`` does not take: which integrator
    does take it, or the nearest of its own names."""
    others = [n for n, cls in _REGISTRY.items() if n != integrator and any(o.name == key for o in cls.OPTIONS)]
    mine = [o.name for o in _REGISTRY[integrator].OPTIONS] if integrator in _REGISTRY else []
    takes = f"{integrator} takes " + (", ".join(mine) if mine else "no options")
    if others:
        named = others[0] if len(others) == 1 else ", ".join(others[:-1]) + " and " + others[-1]
        return f"{key!r} is an option of {named}, not of {integrator} ({takes})"
    near = difflib.get_close_matches(str(key), mine, n=1)
    hint = f" (did you mean {near[0]!r}?)" if near else ""
    return f"unknown {integrator} option {key!r}{hint}; {takes}"


_REGISTRY: dict[str, type[Integrator]] = {}

_I = TypeVar("_I", bound=type[Integrator])


def register_integrator(name: str) -> Callable[[_I], _I]:
    """Class decorator: make an :class:`Integrator` subclass available as ``World(integrator=name)``.

    Examples
    --------
    >>> @register_integrator("noop")
    ... class Noop(Integrator):
    ...     name = "noop"
    ...     def step(self, model, state_in, state_out, control, contacts, h, *, substeps=1, max_speed=math.inf):
    ...         return StepReport()
    >>> "noop" in available_integrators()
    True
    >>> _ = _REGISTRY.pop("noop")
    """
    def deco(cls: _I) -> _I:
        if name in _REGISTRY:
            raise ValueError(f"an integrator named {name!r} is already registered")
        if not (isinstance(cls, type) and issubclass(cls, Integrator)):
            raise ValueError(f"integrator {name!r} must be a subclass of deforma.physics.integrators.Integrator")
        _REGISTRY[name] = cls
        return cls
    return deco


def available_integrators() -> list[str]:
    """Names accepted by ``World(integrator=...)``, in registration order (``"avbd"``, the
    default, last).

    Examples
    --------
    >>> available_integrators()[:3]
    ['symplectic-euler', 'implicit-euler', 'xpbd']
    """
    return list(_REGISTRY)


def make_integrator(name: str, options: Mapping[str, Any] | None = None) -> Integrator:
    """A new integrator instance by name with ``options`` (a mapping; defaults for the rest);
    ``ValueError`` naming the choices if the name is unknown, or saying what is wrong with an option."""
    try:
        factory = _REGISTRY[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown integrator {name!r}; available: {', '.join(available_integrators())}") from None
    integrator = factory()
    if options:
        integrator.configure(options)
    return integrator

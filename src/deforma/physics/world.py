"""The World: soft bodies, colliders, gravity and friction, stepped in time.

A world keeps the handles (bodies, grabs, colliders) and the parameters, and the data a step
passes along: one :class:`~deforma.physics.model.Model` (constant arrays of all bodies), the
:class:`~deforma.physics.state.State` (positions and velocities of all bodies) and the one
the step started from, a :class:`~deforma.physics.control.Control` (grabs, applied forces,
packed colliders) and the :class:`~deforma.physics.contact.contacts.Contacts`. The step
itself is :mod:`deforma.physics.stepper`; the stable step, energies, checks and hints are
:mod:`deforma.physics.diagnostics`. Bodies and grabs are thin handles
(:mod:`deforma.physics.body`) whose ``positions`` / ``velocities`` are views into the
world's arrays.

Units are SI (m, kg, s, N); y points up; angles are degrees.
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING, Any, Callable, Mapping

import numpy as np
from numpy.typing import ArrayLike

from ..checks import MAX_COORDINATE, MAX_GRAVITY, MAX_SUBSTEPS, MIN_SUBSTEP, check_option_numbers
from ..checks import non_negative as _non_negative
from ..checks import number as _finite
from ..checks import pair as _pair
from ..checks import positive as _positive
from ..checks import switch as _switch
from . import diagnostics, rigid_motion, stepper
from .body import Body, Grab, _fem_mesh_check, _material, _pressure, _spin
from .colliders.shapes import INV_INERTIA, INV_MASS, SHAPES, Collider, pack_colliders
from .contact.clearance import outlines_overlap
from .contact.contacts import ContactPoints, Contacts
from .contact.pairs import ContactPair, group_pairs, impulses_from_points
from .control import Control
from ..checks import IgnoredSettingWarning, StepBeyondStableWarning
from .diagnostics import Energy, SimulationUnstable
from .sleeping import SLEEP_TIME, body_boxes, fastest_vertex, islands, sleep_changes, touching_boxes
from .events import ContactEvent, Events
from . import joint as _joint
from .joint import Joint
from .integrators import make_integrator
from .material import Material
from .model import Model
from .rigid.stage import RIGID_SUBSTEP, rigid_set
from .state import State
from .topology import BodyTopology, triangles_under

if TYPE_CHECKING:
    from ..mesh.mesh import Mesh

__all__ = ["Body", "Energy", "Grab", "SimulationUnstable", "World"]

MAX_ANGLE = 1e6  # degrees: a placement angle beyond this is a mistake, not a turn

# Automatic contact thickness: this fraction of a body's median boundary edge (see World).
AUTO_THICKNESS = 0.05


class World:
    """Soft bodies, colliders of any shape (fixed or moving), gravity and Coulomb friction.

    Parameters
    ----------
    gravity : (float, float), optional
        Acceleration of gravity in m/s^2.
    dt : float, optional
        Time advanced by one :meth:`step`, seconds (> 0; default 1/60 s, one step a frame).
    substeps : int or "auto", optional
        Integration substeps per step (>= 1); each is ``dt / substeps`` long. ``"auto"`` (the
        default): as many as the explicit integrator's stable step asks (``ceil(dt /
        stable_dt())``, chosen again whenever the bodies, their parameters, the grabs or ``dt``
        change; 1 under the unconditionally stable integrators); past 1000 ``add_body`` warns
        and the step is refused in one line.
    mass : float, optional
        Default total mass of a body in kg (> 0); each vertex weighs ``mass / N``.
    stiffness : float, optional
        Default spring constant in N/m (>= 0).
    damping : float, optional
        Default spring damping in N*s/m (>= 0).
    air_drag : float, optional
        In 1/s (>= 0): every vertex's velocity decays as ``dv/dt = -air_drag v``, so a body
        falls no faster than ``g / air_drag``. Spring damping acts on stretching only and is
        proportional to stiffness, so it barely slows the slow sway of a tall stack or a
        heap; a little air drag lets them come to rest (Box2D's ``linearDamping``, Matter.js's
        ``frictionAir``). Default 0.
    friction, static_friction : float, optional
        Default dynamic and static Coulomb coefficients of colliders (>= 0).
    grab_strength : float, optional
        Default mouse pull in N/m per held vertex (> 0).
    max_speed : float, optional
        A vertex faster than this (m/s) means the simulation ran away (> 0; ``inf`` to
        check only for NaN/inf).
    integrator : str, optional
        Time integrator by name (default ``"avbd"``, stable and at rest at 1/60 s; see
        ``deforma.physics.available_integrators()`` and ``docs/integrators.md``).
    integrator_options : dict, optional
        The integrator's settings by name (see ``docs/integrators.md``; e.g.
        ``{"iterations": 5}`` for ``"implicit-euler"``); the others keep their defaults.
    contact_thickness : float or None, optional
        How far apart touching bodies stay, metres (> 0, below every colliding body's
        shortest boundary edge). ``None`` (default): each body uses 5% of its median
        boundary edge (``body.contact_thickness``), which keeps bodies of any size visibly
        touching. Contacts are explained in ``docs/physics.md``.
    sleep : bool, optional
        Whether bodies at rest fall asleep (default True): an island of bodies touching or
        joined, every vertex slower than 5 mm/s for 0.5 s, is no longer stepped until
        something disturbs it (:attr:`sleep`, ``docs/physics.md``, Sleeping).

    Every parameter is also a settable attribute, validated the same way, and takes effect
    at the next step (bodies and colliders that do not override it follow the world).

    ``copy.deepcopy(world)`` makes an independent world (its own bodies, colliders, grabs and
    integrator) that steps exactly as this one would, bit for bit, whichever the integrator:
    run one ahead to look into the future without changing the other. Body and grab handles
    taken from this world keep pointing into this world; the copy's are in ``copy.bodies``.

    Examples
    --------
    >>> import deforma
    >>> w = deforma.World(dt=1 / 600, stiffness=500.0)
    >>> m = deforma.mesh.Mesh([[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 1, 2], [0, 2, 3]])
    >>> body = w.add_body(m, position=(0, 1))
    >>> _ = w.add_collider(deforma.Rect((0, -0.25), (10, 0.5), 0.0))
    >>> for _ in range(600):
    ...     w.step()
    >>> bool(abs(body.center_of_mass[1] - 0.5) < 0.01)  # resting on the ground
    True
    """

    def __init__(self, *, gravity: ArrayLike = (0.0, -9.81), dt: float = 1 / 60, substeps: int | str = "auto",
                 mass: float = 1.0, stiffness: float = 1000.0, damping: float = 0.5, friction: float = 0.3,
                 static_friction: float = 0.5, grab_strength: float = 50.0, max_speed: float = 1e3,
                 integrator: str = "avbd", contact_thickness: float | None = None, air_drag: float = 0.0,
                 material: Material | None = None, integrator_options: Mapping[str, Any] | None = None,
                 sleep: bool = True) -> None:
        self._bodies: list[Body] = []
        self._colliders: list[Collider] = []
        self._packed_colliders: tuple | None = None  # what was packed: (id, version) per collider
        self._grabs: list[Grab] = []
        self._grabs_dirty = True
        self._lost_shape: dict[int, int] = {}  # id(body) -> checks in a row at which it had lost its shape
        self._forces: list[tuple[Body, np.ndarray, np.ndarray]] = []  # (body, body-local vertices, forces): applied during the next step
        self._joints: list[Joint] = []
        self._events = Events()  # on_contact, on_joint_break
        self._contact_record = None  # (model, its bodies, ContactImpulses or None) of the last step
        self._pair_cache = None  # (contact record, its pairs by key)
        self._island = np.zeros(0, np.int64)  # each body's island after the last step (physics.sleeping)
        self._sleep_key = None  # what a change of wakes every island (_world_key)
        self._gravity, self._air_drag = (0.0, -9.81), 0.0
        self._model = Model([], masses=[], stiffness=[], damping=[])
        self._model_bodies: list[Body] = []
        self._state = State.empty()
        self._start = State.empty()  # the state the step started from: what a failed step keeps
        self._sub_start = State.empty()  # with rigid bodies: where each substep started
        self._control = Control(0)
        self._contacts = Contacts.for_topology(self._model.contact, n_vertices=0)
        self._contact_thickness: float | None = None
        self._material: Material | None = None
        self.time = 0.0
        self.step_count = 0
        self._said_ignored: set[str] = set()  # the spring parameters already said to reach no FEM body
        self._auto = False  # substeps = "auto"
        self._auto_key = None  # what the automatic substeps were chosen for
        self.gravity = gravity
        self.dt = dt
        # "auto" asks the integrator, set below: until then one substep
        self.substeps = 1 if isinstance(substeps, str) and substeps == "auto" else substeps
        self.mass = mass
        self.stiffness = stiffness
        self.damping = damping
        self.friction = friction
        self.static_friction = static_friction
        self.grab_strength = grab_strength
        self.max_speed = max_speed
        self.integrator = integrator
        self.sleep = sleep
        if integrator_options is not None:
            self.integrator_options = integrator_options
        if isinstance(substeps, str) and substeps == "auto":
            self.substeps = "auto"
        self.contact_thickness = contact_thickness
        self.air_drag = air_drag
        self.material = material

    def __deepcopy__(self, memo):
        # everything is copied as usual (implicit Euler's factor is factored again at the
        # copy's first solve, see UpdatedFactor.__deepcopy__); what is keyed by id() is
        # re-keyed to the copies, or the copy would repack its colliders a step earlier than
        # this world (rounding apart) and forget which bodies had lost their shape
        import copy

        new = type(self).__new__(type(self))
        memo[id(self)] = new
        for name, value in self.__dict__.items():
            new.__dict__[name] = copy.deepcopy(value, memo)
        ids = {id(o): id(memo[id(o)]) for o in (*self._bodies, *self._colliders)}
        new._lost_shape = {ids[k]: n for k, n in self._lost_shape.items() if k in ids}
        if self._packed_colliders is not None:
            new._packed_colliders = tuple((ids.get(k, k), version) for k, version in self._packed_colliders)
        new._events.touching = {(id(p.a), id(p.b)): p for p in new._events.touching.values()}
        new._pair_cache = None
        if self._sleep_key is not None and self._sleep_key == self._world_key():
            new._sleep_key = new._world_key()  # of the copies' ids: nothing changed, nothing wakes
        return new

    # -- sleeping ---------------------------------------------------------------------------
    @property
    def sleep(self) -> bool:
        """Whether bodies at rest fall asleep (:mod:`deforma.physics.sleeping`): an island of
        bodies touching or joined, all slower than ``SLEEP_SPEED`` (5 mm/s) for ``SLEEP_TIME``
        (0.5 s), stops being stepped, held as pinned, until something disturbs it (see
        :attr:`Body.sleeping`). On by default; setting it off wakes every body."""
        return self._sleep

    @sleep.setter
    def sleep(self, value: bool) -> None:
        self._sleep = _switch(value, "sleep")
        if not self._sleep:
            self._wake(self._bodies)

    def _world_key(self) -> tuple:
        """What, changed, wakes every island: the world's parameters, integrator, bodies,
        joints and still colliders (a moving one wakes only the bodies it touches)."""
        return (self._gravity, self._air_drag, self._contact_thickness, self._max_speed, self._grab_strength,
                self.mass, self.stiffness, self.damping, self.friction, self.static_friction, id(self._material),
                id(self._integrator), id(self._model), tuple(id(j) for j in self._joints),
                tuple((id(c), c._version) for c in self._colliders if not c.moving))

    def _island_of(self, body) -> list:
        """The bodies in ``body``'s island after the last step (itself alone if unknown)."""
        i = body._index
        if len(self._island) != len(self._bodies):
            return [body]
        return [b for b, label in zip(self._bodies, self._island) if label == self._island[i]]

    def _hold(self, bodies) -> None:
        """Hold the vertices of ``bodies`` as their pins and sleep say (Model.pinned)."""
        for b in bodies:
            self._model.set_pinned(b._index, b._pinned | b._asleep)

    def _wake(self, bodies) -> None:
        woken = [b for b in bodies if b._asleep]
        for b in woken:
            b._asleep = False
            b._still = 0.0
        self._hold(woken)

    def _wake_approached(self) -> None:
        """Before a step: wake the islands an awake body or a moving collider may reach in it.
        Woken after the step (by its contact pairs), a sleeping island met the step's impact
        held, as a wall: the ``cards`` scene's wheel bounced off the sleeping house instead of
        knocking it down."""
        bodies = self._bodies
        asleep = np.array([b._asleep for b in bodies], bool)
        if not asleep.any():
            return
        offsets = self._model.body_vertex_offsets
        lo, hi = body_boxes(self._state.x, offsets)
        dt = self.dt
        # how far each awake body may get this step: its fastest vertex, and gravity's pull
        # from rest, plus both sides' contact thickness
        thick = self._model.contact.body_thickness  # (the Model's: no median of edges each step)
        reach = fastest_vertex(self._state.v, offsets) * dt + math.hypot(*self._gravity) * dt * dt + thick
        lo_a, hi_a = lo[~asleep] - reach[~asleep, None], hi[~asleep] + reach[~asleep, None]
        moving = [c for c in self._colliders if c.moving]
        if moving:  # and each moving collider: its speed, the turn's at its box's corners
            box = np.array([c.bounds() for c in moving]).reshape(-1, 4)
            half = 0.5 * np.hypot(box[:, 2] - box[:, 0], box[:, 3] - box[:, 1])
            speed = np.array([math.hypot(*c.velocity) for c in moving]) + half * np.abs(
                np.radians([c.angular_velocity for c in moving]))
            r = (speed * dt)[:, None]
            lo_a, hi_a = np.vstack([lo_a, box[:, :2] - r]), np.vstack([hi_a, box[:, 2:] + r])
        if not len(lo_a):
            return
        hit = touching_boxes(lo_a, hi_a, lo[asleep] - thick[asleep, None], hi[asleep] + thick[asleep, None])
        for k in np.flatnonzero(asleep)[hit]:
            if bodies[k]._asleep:
                self._wake(self._island_of(bodies[k]))

    def _fall_asleep(self, bodies) -> None:
        for b in bodies:
            b._asleep = True
            b._still = SLEEP_TIME
            self._state.v[b.vertex_slice] = 0.0
        self._hold(bodies)

    def _disturb(self, body) -> None:
        """Something acts on ``body``: it wakes, with its island."""
        if any(b is body for b in self._bodies):
            self._wake(self._island_of(body))

    def _update_sleep(self, kept_awake) -> None:
        """After a step: which islands fall asleep and which wake (:func:`~deforma.physics.sleeping.sleep_changes`);
        ``kept_awake``: ids of bodies grabbed or pushed this step."""
        bodies = self._bodies
        index = {id(b): k for k, b in enumerate(bodies)}
        links = []
        kept = np.array([id(b) in kept_awake for b in bodies], bool)
        # held by the world: pinned, joined to it, or touching a collider
        held = np.array([bool(b._pinned.any()) for b in bodies], bool)
        for j in self._joints:
            if j.b is None and id(j.a) in index:
                held[index[id(j.a)]] = True
        for p in self._pairs().values():
            if id(p.b) in index:
                links.append((index[id(p.a)], index[id(p.b)]))
            else:
                held[index[id(p.a)]] = True
                if getattr(p.b, "moving", False):
                    kept[index[id(p.a)]] = True  # on a moving collider
        links += self._joined_pairs()
        self._island = islands(len(bodies), np.array(links, np.int64).reshape(-1, 2))
        asleep = np.array([b._asleep for b in bodies], bool)
        speed = fastest_vertex(self._state.v, self._model.body_vertex_offsets)
        fall, wake, still = sleep_changes(asleep, np.array([b._still for b in bodies]), speed, self._island, kept,
                                          self.dt, held)
        for b, t in zip(bodies, still):
            b._still = float(t)
        self._wake([b for b, w in zip(bodies, wake) if w])
        self._fall_asleep([b for b, f in zip(bodies, fall) if f])

    # -- parameters -------------------------------------------------------------------------
    @property
    def gravity(self) -> tuple[float, float]:
        """Acceleration of gravity (m/s^2) as (x, y)."""
        return self._gravity

    @gravity.setter
    def gravity(self, value: ArrayLike) -> None:
        self._gravity = self._model.gravity = _pair(value, "gravity", limit=MAX_GRAVITY)

    @property
    def dt(self) -> float:
        """Seconds advanced per :meth:`step`."""
        return self._dt

    @dt.setter
    def dt(self, value: float) -> None:
        dt = _positive(value, "dt", "s")
        self._check_substep(dt, getattr(self, "_substeps", 1))
        self._dt = dt

    @property
    def substeps(self) -> int:
        """Substeps per step: the number in force (with ``"auto"``, the one chosen for the
        bodies as they are now; :attr:`auto_substeps` says whether it follows them).

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(dt=1 / 60, stiffness=2000.0, integrator="symplectic-euler")
        >>> _ = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=4))
        >>> w.substeps = "auto"
        >>> w.substeps, w.auto_substeps  # ceil(dt / stable_dt())
        (11, True)
        >>> w.integrator = "implicit-euler"; w.substeps  # stable at any step
        1
        """
        if self._auto:
            try:
                self._substeps = self._auto_substeps()
            except ValueError:  # more than allowed: the next step says so
                pass
        return self._substeps

    @substeps.setter
    def substeps(self, value: int | str) -> None:
        if isinstance(value, str) and value == "auto":
            self._auto_key = None
            self._substeps = self._auto_substeps()  # StepTooLong past MAX_SUBSTEPS: nothing changed
            self._auto = True
            return
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= value <= MAX_SUBSTEPS:
            raise ValueError(f"substeps must be an integer in [1, {MAX_SUBSTEPS}] (one step must stay short "
                             f"enough to interrupt) or \"auto\", got {value!r}")
        self._check_substep(self._dt, int(value))
        self._substeps = int(value)
        self._auto = False

    @property
    def auto_substeps(self) -> bool:
        """Whether ``substeps`` is ``"auto"``: chosen from the stable step before every step
        in which the bodies, their parameters, the grabs, ``dt`` or the integrator changed."""
        return self._auto

    def _auto_substeps(self):
        """The substeps ``"auto"`` asks now: ``ceil(dt / stable_dt())``; past ``MAX_SUBSTEPS``
        raises :class:`~deforma.physics.diagnostics.StepTooLong` (a ``SimulationUnstable`` and a
        ``ValueError``, one line), whoever asks: the setter and a step alike."""
        if self._grabs_dirty:
            self._rebuild_grabs()
        model, control = self._model, self._control
        key = (model, model.version, self._dt, self._integrator.name, control.grab_slot.tobytes(),
               control.grab_pull[:, 0].tobytes())
        if self._auto_key is not None and self._auto_key[0] is model and self._auto_key[1:] == key[1:]:
            return self._substeps
        stable = self.stable_dt()
        need = 1 if not math.isfinite(stable) else max(1, math.ceil(self._dt / stable * (1.0 + 1e-9)))
        if model.n_vertices and model.rigid.any() and not self._rigid_in_solve():
            # a soft body meets a rigid one between substeps (its outline stands still within
            # one): at one 1/60 s implicit step a jelly ball went 5 cm into a crate before it
            # was put out, and bounced off with 22 % more energy than it came with; none at 1/120 s
            need = max(need, math.ceil(self._dt / RIGID_SUBSTEP * (1.0 - 1e-9)))
        if need > MAX_SUBSTEPS:
            raise diagnostics.step_too_long(self, model, control, need, stable)
        self._auto_key = key
        return need

    @staticmethod
    def _check_substep(dt, substeps):
        if dt / substeps < MIN_SUBSTEP:
            raise ValueError(f"dt / substeps must be >= {MIN_SUBSTEP:g} s, got {dt:g} / {substeps} = "
                             f"{dt / substeps:.3g} s")

    @staticmethod  # callable in the class body (Python >= 3.10)
    def _world_param(name: str, unit: str, check: Callable[[Any, str, str], float]) -> property:
        def get(self):
            return getattr(self, "_" + name)

        def set_(self, value):
            setattr(self, "_" + name, check(value, name, unit))
            for b in range(len(self._bodies)):  # bodies that follow the world (friction: body contacts)
                self._apply_body_parameters(b)
            if name in ("mass", "stiffness", "damping"):
                self._say_ignored(name)
            if name in ("friction", "static_friction"):
                self._packed_colliders = None  # colliders that follow the world's
        return property(get, set_, doc=f"World default {name} ({unit}).")

    def _say_ignored(self, name: str) -> None:
        """Warn once per parameter when the spring ``name`` just set reaches no finite-element body."""
        fem = [b for b in self._bodies if b.is_fem]
        if not fem or name in self._said_ignored:
            return
        self._said_ignored.add(name)
        which = ", ".join(f"body {b.index} ({b.material.model})" for b in fem[:3]) + (" ..." if len(fem) > 3 else "")
        share = "no body" if len(fem) == len(self._bodies) else "only the bodies made of springs"
        instead = {"mass": "density", "stiffness": "youngs_modulus", "damping": "the material's damping"}[name]
        warnings.warn(f"world.{name} changes {share}: {which} {'is' if len(fem) == 1 else 'are'} made of finite "
                      f"elements, whose {name} is set by {instead} (world.material or body.material)",
                      IgnoredSettingWarning, stacklevel=3)

    mass = _world_param("mass", "kg", _positive)
    stiffness = _world_param("stiffness", "N/m", _non_negative)
    damping = _world_param("damping", "N*s/m", _non_negative)
    friction = _world_param("friction", "(dimensionless)", _non_negative)
    static_friction = _world_param("static_friction", "(dimensionless)", _non_negative)
    del _world_param

    @property
    def grab_strength(self) -> float:
        """Default mouse pull in N/m per held vertex."""
        return self._grab_strength

    @grab_strength.setter
    def grab_strength(self, value: float) -> None:
        self._grab_strength = _positive(value, "grab_strength", "N/m")

    @property
    def max_speed(self) -> float:
        """Speed (m/s) above which a vertex counts as runaway."""
        return self._max_speed

    @max_speed.setter
    def max_speed(self, value: float) -> None:
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"max_speed must be a number of m/s, got {value!r}") from None
        if v != math.inf:  # inf: no speed check; else a number whose square is finite
            v = _positive(value, "max_speed", "m/s (or inf)")
        self._max_speed = v

    @property
    def air_drag(self) -> float:
        """Air drag in 1/s: every velocity decays as ``dv/dt = -air_drag v``."""
        return self._air_drag

    @air_drag.setter
    def air_drag(self, value: float) -> None:
        self._air_drag = self._model.air_drag = _non_negative(value, "air_drag", "1/s")

    @property
    def contact_thickness(self) -> float | None:
        """Contact thickness in metres, or ``None`` for each body's automatic value."""
        return self._contact_thickness

    @contact_thickness.setter
    def contact_thickness(self, value: float | None) -> None:
        if value is None:
            self._contact_thickness = None
        else:
            t = _positive(value, "contact_thickness", "m")
            for body in self._bodies:
                self._check_thickness(body, t)
            self._contact_thickness = t
        for b in range(len(self._bodies)):
            self._apply_body_parameters(b)

    def _check_thickness(self, body, t) -> None:
        lengths = body.topology.boundary_edge_lengths
        if not len(lengths) or not (body._overrides["collide"] or body._overrides["self_collision"]):
            return
        shortest = float(lengths.min())
        if t >= shortest:
            which = f"body {body._index}" if body._world is self and body in self._bodies else "the new body"
            raise ValueError(
                f"contact_thickness {t:g} m is not below the shortest boundary edge of {which} ({shortest:.3g} m): "
                f"touching bodies would hover apart by more than their own mesh spacing; use a value below "
                f"{shortest:.3g} m (it is in metres) or None for 5% of each body's median boundary edge")

    def _body_thickness(self, body) -> float:
        if self._contact_thickness is not None:
            return self._contact_thickness
        lengths = body.topology.boundary_edge_lengths
        if not len(lengths):
            return 0.0
        return float(min(AUTO_THICKNESS * np.median(lengths), 0.5 * lengths.min()))

    @property
    def material(self) -> Material | None:
        """Default material of bodies that have none of their own; ``None``: the seed's springs."""
        return self._material

    @material.setter
    def material(self, value: Material | None) -> None:
        value = _material(value)
        if value is not None and value.is_fem:
            for body in self._bodies:
                if body._overrides["material"] is None:
                    _fem_mesh_check(body.topology)
        if value is None or not value.is_rigid:
            self._check_joined_stay_rigid([b for b in self._bodies if b._overrides["material"] is None])
        self._material = value
        self._material_changed()

    def _check_joined_stay_rigid(self, softened) -> None:
        """Refuse to make a body a joint holds soft where the joint cannot hold a soft body
        (a weld, a motor, or an integrator other than avbd: :meth:`_check_soft_joint`)."""
        for j in self._joints:
            for body in (j.a, j.b):
                if body is not None and any(body is s for s in softened):
                    try:
                        self._check_soft_joint(j.kind, j.motor_speed, f"body {body._index}")
                    except ValueError as e:
                        raise ValueError(f"body {body._index} is held by a joint ({j!r}) that cannot hold it soft: "
                                         f"{e}; remove the joint first (world.remove_joint)") from None

    def _material_changed(self) -> None:
        # springs and elements are different arrays: rebuild the Model, keep the state
        if self._bodies:
            self._rebuild(self._state.x.copy(), self._state.v.copy())

    @property
    def integrator(self) -> str:
        """Name of the time integrator; setting one gives it its default options."""
        return self._integrator.name

    @integrator.setter
    def integrator(self, name: str) -> None:
        made = make_integrator(name)
        if not made.solves_rigid:
            for j in self._joints:
                soft = [body for body in (j.a, j.b) if body is not None and not body.material.is_rigid]
                if soft:
                    raise ValueError(f"body {soft[0]._index} is soft and held by a joint ({j!r}): joints on soft "
                                     f"bodies are solved by integrator='avbd'; remove the joint first "
                                     f"(world.remove_joint) to use {name!r}")
        self._integrator = made
        self._rigid_solve_changed()

    def _rigid_in_solve(self) -> bool:
        """Whether the integrator solves the rigid bodies in its own sweep (avbd's blocks,
        :mod:`deforma.physics.integrators.avbd.rigid`, and their joints as rows): else the rigid
        stage after each substep moves them and others meet their outlines as colliders'
        (:mod:`deforma.physics.rigid`)."""
        return self._integrator.solves_rigid

    def _joined_pairs(self) -> list[tuple[int, int]]:
        """The pairs of body indices the joints hold together (not the world's joints)."""
        return [(j.a._index, j.b._index) for j in self._joints if j.b is not None]

    def _rigid_solve_changed(self) -> None:
        """Who moves the rigid bodies may have changed (the integrator, or the joints): the
        joined pairs' contact switch (soft bodies' too), the rigid bodies' contact switches,
        and their outlines packed again or no more."""
        model = getattr(self, "_model", None)
        if model is None or not model.n_vertices:
            return
        model.set_joined(self._joined_pairs())
        if not model.rigid.any():
            return
        for body in self._bodies:
            if body.material.is_rigid:
                model.set_contact_parameters(body._index, **self._contact_parameters(body))
        self._packed_colliders = None
        self._auto_key = None

    @property
    def integrator_options(self) -> dict:
        """The integrator's settings by name (a new dict; ``docs/integrators.md`` lists them).

        Setting a dict sets the options it names and puts the others back to their defaults;
        a name the integrator does not take, or a value out of its range, raises
        ``ValueError`` and changes nothing.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(integrator="implicit-euler", integrator_options={"tolerance": 1e-4})
        >>> w.integrator_options
        {'iterations': 3, 'tolerance': 0.0001, 'max_iterations': 500, 'contact_weight': 10.0}
        >>> w.integrator_options = {"contact_weight": 20.0}
        >>> w.integrator_options
        {'iterations': 3, 'tolerance': 0.0, 'max_iterations': 500, 'contact_weight': 20.0}
        """
        return self._integrator.options

    @integrator_options.setter
    def integrator_options(self, options: Mapping[str, Any]) -> None:
        check_option_numbers(options, self._integrator)  # 10**400: one line, not an OverflowError
        self._integrator.configure(options)

    @property
    def integrator_stats(self) -> dict:
        """Counters of the integrator's work so far, by name (a new dict; implicit Euler counts
        ``factorizations`` and ``updates`` of its matrix, the others nothing)."""
        return self._integrator.stats()

    # -- bodies -----------------------------------------------------------------------------
    @property
    def bodies(self) -> list[Body]:
        """The bodies, in the order added (a new list; use add_body / remove_body to change)."""
        return list(self._bodies)

    def add_body(self, mesh: Mesh | Any, *, position: ArrayLike | None = None, material: Material | None = None,
                 mass: float | None = None, stiffness: float | None = None, damping: float | None = None,
                 collide: bool = True, self_collision: bool = True, friction: float | None = None,
                 static_friction: float | None = None, pressure: float | None = None, angle: float = 0.0,
                 velocity: ArrayLike = (0.0, 0.0), angular_velocity: float = 0.0) -> Body:
        """Make a soft body from a mesh: springs on its edges, or finite elements on its triangles.

        Parameters
        ----------
        mesh : deforma.mesh.Mesh
            Or any object with ``vertices`` (N, 2) and ``edges`` (E, 2) (and optionally
            ``triangles``), e.g. a chain of springs. Rest lengths come from the vertices.
        position : (float, float), optional
            Where the mesh's bounding-box centre goes, metres; ``None`` keeps its coordinates.
        material : deforma.Material, optional
            What the body is made of; ``None`` follows the world's ``material`` (whose default
            ``None`` is the seed's springs). A finite-element material (``"corotated"``,
            ``"neo-hookean"``) makes every triangle an element and takes the mass from its
            density, so it cannot be combined with ``mass``, ``stiffness`` or ``damping``.
        mass, stiffness, damping : float, optional
            Springs only: total mass (kg), spring constant (N/m) and damping (N*s/m); ``None``
            follows the world.
        collide : bool, optional
            Touch other bodies (default). Off, the body passes through every other body; in
            a heap that saves most of the step (the contact stage is 80-90% of it there).
        self_collision : bool, optional
            Touch itself (default): its outline cannot fold through itself. The cost follows
            the outline, not the body: a 1e5-vertex body at rest measured 1.3x a bare step
            without it (which is only ~2 ms); a small body that flexes and touches itself
            most substeps pays about 2x (the ``demo`` scene's bunny; ``docs/benchmarks.md``).
        friction, static_friction : float, optional
            Coulomb coefficients against other bodies and itself (>= 0); ``None`` follows the
            world's. Two bodies use ``sqrt(a * b)`` of theirs; colliders use their own.
        pressure : float, optional
            A gas inside the body's outer outline, N/m at the rest area (>= 0), pushing
            with ``pressure * A0 / A`` (:mod:`deforma.physics.behaviours.pressure`); the body needs a
            closed outline (triangles, or springs forming closed loops). ``None`` (default):
            no gas.
        angle : float, optional
            Turn the mesh by this many degrees (counter-clockwise) about its bounding-box
            centre before it is placed; it rests in that shape (``body.angle`` starts here).
        velocity : (float, float), optional
            Initial velocity of its centre of mass, m/s.
        angular_velocity : float, optional
            Initial spin about its centre of mass, deg/s (counter-clockwise).

        Returns
        -------
        Body

        Raises
        ------
        ValueError
            Bad values, or a colliding body placed where it overlaps another colliding body
            (their outlines cross or one lies inside the other): bodies must start apart.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> b = w.add_body(deforma.mesh.Mesh([[0, 0], [2, 0], [0, 2]], [[0, 1, 2]]), position=(5, 5))
        >>> b.positions.min(axis=0).tolist(), b.positions.max(axis=0).tolist()
        ([4.0, 4.0], [6.0, 6.0])

        A box turned 30 degrees, thrown up and to the right, spinning at a turn per second:

        >>> box = deforma.mesh.box(((0, 0), (1, 0), (1, 0.5), (0, 0.5)), detail=2)
        >>> b = w.add_body(box, position=(0, 2), angle=30, velocity=(2, 3), angular_velocity=360)
        >>> round(b.angle, 9), b.velocity.round(9).tolist(), round(b.angular_velocity, 9)
        (30.0, [2.0, 3.0], 360.0)
        """
        turn = _finite(angle, "angle")
        if not abs(turn) <= MAX_ANGLE:
            raise ValueError(f"angle must be within +-{MAX_ANGLE:g} degrees, got {angle!r}")
        vel = _pair(velocity, "velocity", limit=self.max_speed)
        spin = _spin(angular_velocity, self.max_speed)
        try:
            vertices, edges = mesh.vertices, mesh.edges
        except AttributeError:
            raise ValueError(f"mesh must be a deforma.mesh.Mesh (or have .vertices and .edges), "
                             f"got {type(mesh).__name__}") from None
        x = np.array(vertices, dtype=np.float64)
        if x.ndim == 2 and x.shape[1] == 2 and len(x) and position is not None:
            x += np.asarray(_pair(position, "position")) - (x.min(axis=0) + x.max(axis=0)) / 2
        if x.ndim == 2 and x.shape[1] == 2 and len(x) and turn and np.all(np.isfinite(x)):
            x = rigid_motion.rotate(x, math.radians(turn), (x.min(axis=0) + x.max(axis=0)) / 2)
        if x.ndim == 2 and x.size and np.all(np.isfinite(x)) and np.abs(x).max() > MAX_COORDINATE:
            raise ValueError(f"a body's vertices must lie within +-{MAX_COORDINATE:g} m, got {np.abs(x).max():g}")
        topo = BodyTopology.from_arrays(x, edges, getattr(mesh, "triangles", None))
        material = _material(material)
        effective = material if material is not None else self._material
        if effective is not None and effective.is_fem:
            given = [k for k, v in (("mass", mass), ("stiffness", stiffness), ("damping", damping)) if v is not None]
            if given:
                raise ValueError(f"the {effective.model!r} material sets the body's mass (density * area) and "
                                 f"elasticity (youngs_modulus, poisson_ratio); do not pass {', '.join(given)} too")
            _fem_mesh_check(topo)
        overrides = {
            "material": material,
            "mass": None if mass is None else _positive(mass, "mass", "kg"),
            "stiffness": None if stiffness is None else _non_negative(stiffness, "stiffness", "N/m"),
            "damping": None if damping is None else _non_negative(damping, "damping", "N*s/m"),
            "friction": None if friction is None else _non_negative(friction, "friction", "(dimensionless)"),
            "static_friction": None if static_friction is None
            else _non_negative(static_friction, "static_friction", "(dimensionless)"),
            "collide": _switch(collide, "collide"),
            "self_collision": _switch(self_collision, "self_collision"),
            "pressure": _pressure(pressure, topo),
        }
        body = Body(self, len(self._bodies), mesh, topo, overrides)
        body._angle0 = math.radians(turn)
        if self._contact_thickness is not None:
            self._check_thickness(body, self._contact_thickness)
        if overrides["collide"]:
            self._check_no_overlap(body, topo.rest_positions)
        xs = [self._state.x, topo.rest_positions]
        vs = [self._state.v, np.zeros_like(topo.rest_positions)]
        self._bodies.append(body)
        self._rebuild(np.concatenate(xs), np.concatenate(vs))
        if vel != (0.0, 0.0) or spin:
            body.velocities[...] = rigid_motion.rigid_velocities(body.positions, body.vertex_masses, vel, spin)
        if self._auto and not self._integrator.unconditionally_stable:
            try:  # say so now, not at the first step
                self._substeps = self._auto_substeps()
            except ValueError as e:
                warnings.warn(str(e), StepBeyondStableWarning, stacklevel=2)
        elif not self._integrator.unconditionally_stable:
            stable = self.stable_dt()
            if self._dt / self._substeps > stable:
                # say so now, not at the step that blows up
                need = math.ceil(self._dt / stable)
                h = self._dt / self._substeps
                warnings.warn(f"under {self.integrator} this world's step, dt/substeps = {h:.3g} s, exceeds the "
                              f"stable estimate {stable:.3g} s with this body: set substeps = {need} (or "
                              f"\"auto\"), lower dt, or use integrator=\"implicit-euler\"",
                              StepBeyondStableWarning, stacklevel=2)
        return body

    def remove_body(self, body: Body) -> None:
        """Take a body out of the world (its grabs are released).

        Raises
        ------
        ValueError
            If ``body`` is not a body of this world.
        """
        b = self._own_body(body)
        keep = np.ones(self._model.n_vertices, bool)
        keep[body.vertex_slice] = False
        x, v = self._state.x[keep], self._state.v[keep]
        for g in self._grabs:
            if g.body is body:
                g.active = False
        self._grabs = [g for g in self._grabs if g.active]
        self._forces = [f for f in self._forces if f[0] is not body]  # its loads go with it
        self._joints = [j for j in self._joints if body not in (j.a, j.b)]  # and its joints
        del self._bodies[b]
        body._world = None
        for k, other in enumerate(self._bodies):
            other._index = k
        self._rebuild(x, v)

    def _own_body(self, body) -> int:
        if not isinstance(body, Body) or body._world is not self:
            raise ValueError(f"unknown body {body!r}: pass one returned by this world's add_body")
        return body._index

    def _rebuild(self, x, v):
        # the rest shapes plasticity moved live in the Model's arrays: take them over, body by
        # body (a torn body's vertices through the tear's source), so dents survive a rebuild
        old = self._model
        for b in self._bodies:  # a body added, removed, torn or remade: every island wakes
            b._asleep, b._still = False, 0.0
        shapes, torn = {}, {}
        if old is not None:
            for i, body in enumerate(self._model_bodies):
                was_fem = old.materials[i] is not None and old.materials[i].is_fem
                if body._world is self and was_fem == body.is_fem:  # springs and elements do not convert
                    if was_fem and not isinstance(body._tear_source, slice):  # torn: its elements and all
                        torn[body._index] = (old, i)
                        continue
                    shape = old.rest_shape(i)
                    if any(part is not None for part in shape):
                        shapes[body] = shape
        tops = [b.topology for b in self._bodies]
        self._model = Model(tops, masses=[b._param("mass") for b in self._bodies],
                            stiffness=[b.stiffness for b in self._bodies],
                            damping=[b.damping for b in self._bodies],
                            materials=[b.material for b in self._bodies],
                            pinned=[b._pinned for b in self._bodies],
                            contact=[self._contact_parameters(b) for b in self._bodies],
                            pressure=[b._overrides["pressure"] for b in self._bodies], torn=torn,
                            gravity=self._gravity, air_drag=self._air_drag)
        for body, shape in shapes.items():
            src = body._tear_source
            self._model.take_rest_shape(body._index, shape, None if isinstance(src, slice) else src)
        if self._joints:
            self._model.set_joined(self._joined_pairs())
        self._model_bodies = list(self._bodies)
        self._state = State(x, v)
        packed = self._control.colliders
        self._control = Control(self._model.n_vertices)
        self._control.colliders = packed  # where the colliders are: a tear rebuilds mid-step
        self._grabs_dirty = True
        # keep what an earlier step grew the buffer to (a torn body rebuilds the Model while
        # its contacts go on; a small buffer would make the next step run twice)
        self._contacts = Contacts.for_topology(self._model.contact, n_vertices=self._model.n_vertices,
                                               keep=self._contacts)

    def _contact_parameters(self, body) -> dict:
        o = body._overrides
        if body.material.is_rigid and not self._rigid_in_solve():
            # others meet its outline as a collider's (deforma.physics.rigid); in avbd's
            # sweep it is a block whose outline meets others as any body's does
            return dict(collide=False, self_collision=False, friction=body.friction,
                        static_friction=body.static_friction, thickness=self._body_thickness(body))
        return dict(collide=o["collide"], self_collision=o["self_collision"], friction=body.friction,
                    static_friction=body.static_friction, thickness=self._body_thickness(body))

    def _apply_body_parameters(self, b: int) -> None:
        body = self._bodies[b]
        self._model.set_body_parameters(b, mass=body._param("mass"), stiffness=body.stiffness, damping=body.damping)
        self._model.set_contact_parameters(b, **self._contact_parameters(body))

    def _check_no_overlap(self, body, x=None) -> None:
        """Refuse a colliding body that overlaps another colliding body (bodies must start
        apart); a body a joint holds to it may overlap it (joined bodies do not collide: the
        links of a chain overlap at their pins)."""
        topo = body.topology
        if not len(topo.boundary_edges):
            return
        if x is None:
            x = body.positions
        joined = {id(j.b if j.a is body else j.a) for j in self._joints if body is j.a or body is j.b}
        for other in self._bodies:
            if (other is body or id(other) in joined or not other._overrides["collide"]
                    or not len(other.topology.boundary_edges)):
                continue
            if outlines_overlap(x, topo.boundary_edges, other.positions, other.topology.boundary_edges):
                which = f"body {body._index}" if body in self._bodies else f"the new body ({len(self._bodies)})"
                raise ValueError(
                    f"{which} would overlap body {other._index} (their outlines cross or one lies inside the "
                    f"other): colliding bodies must start apart; move it, or give it collide=False")

    @property
    def contacts(self) -> ContactPoints:
        """The contacts of the last substep: with colliders, other bodies and itself.

        A struct of arrays (see :class:`~deforma.physics.contact.contacts.ContactPoints`); collider
        contacts have ``collider >= 0``, contacts with a rigid body's outline ``rigid_body >= 0``,
        body contacts ``collider == -1`` and an ``edge``.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> _ = w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0.0))
        >>> box = deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2, edges=True)
        >>> a = w.add_body(box, position=(0, 0.52))
        >>> b = w.add_body(box, position=(0, 1.6))
        >>> for _ in range(600):
        ...     w.step()
        >>> c = w.contacts
        >>> sorted(set(c.collider.tolist())), bool((c.normal[c.collider == -1, 1] > 0.99).any())
        ([-1, 0], True)
        """
        if self._colliders_changed():
            self._pack_colliders()
        m = self._model
        rigid = rigid_set(m).bodies if m.n_vertices and m.rigid.any() else np.zeros(0, np.int64)
        return self._contacts.points(m.contact, self._control.colliders, len(self._colliders), rigid)

    def _pairs(self) -> dict:
        """The last step's touching pairs by ``(id(a), id(b))`` (:func:`~deforma.physics.contact.pairs.group_pairs`),
        worked out once per step: from the integrator's contact rows where it keeps their
        forces (avbd), else from :attr:`contacts` (no impulses). None once a body was added or
        removed since (their vertices no longer number as the step's did): empty."""
        record = self._contact_record
        if record is None:
            return {}
        model, bodies, imp = record
        if model is not self._model:
            return {}
        if self._pair_cache is not None and self._pair_cache[0] is record:
            return self._pair_cache[1]
        offsets = model.body_vertex_offsets
        vertex_body = np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))
        rigid_of = None
        if imp is None:
            imp, rigid_of = impulses_from_points(self.contacts, self._state.x)
        pairs = group_pairs(imp, vertex_body, bodies, self._colliders, rigid_of)
        self._pair_cache = (record, pairs)
        return pairs

    def contact_pairs(self) -> list[ContactPair]:
        """Every body touching another body or a collider after the last step, as
        :class:`~deforma.physics.contact.pairs.ContactPair` (``a`` a body; ``b`` a body of
        higher index or a collider): the impulses between them over the step (N s, from the
        contact rows' multipliers under avbd; NaN under the other integrators, which keep no
        contact force) and the contact points. A body's contacts with itself are not listed;
        after a body is added or removed, nothing is until the next step.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> floor = w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0.0))
        >>> box = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2, edges=True),
        ...                  position=(0, 0.6), material=deforma.Material("rigid", density=10.0))
        >>> for _ in range(60):
        ...     w.step()
        >>> (p,) = w.contact_pairs()
        >>> p.a is box, p.b is floor, round(p.normal_impulse / w.dt, 1)  # its weight, N
        (True, True, 98.1)
        """
        return list(self._pairs().values())

    def contacts_between(self, a: Body | Collider, b: Body | Collider) -> ContactPair | None:
        """The contact of ``a`` and ``b`` (bodies or colliders, either order) over the last
        step, seen from ``a`` (its ``impulse`` acts on ``a``), or None if they do not touch
        (see :meth:`contact_pairs`)."""
        pairs = self._pairs()
        if (id(a), id(b)) in pairs:
            return pairs[(id(a), id(b))]
        if (id(b), id(a)) in pairs:
            return pairs[(id(b), id(a))].flipped()
        return None

    def on_contact(self, callback: Callable[[ContactEvent], Any]) -> Callable[[ContactEvent], Any]:
        """Call ``callback(event)`` after each step with a
        :class:`~deforma.physics.events.ContactEvent` per pair that began (``event.kind ==
        "begin"``) or ended (``"end"``) touching in it (pairs as :meth:`contact_pairs`); pairs
        already touching when it is registered begin at the next step. Returns ``callback``,
        so it can decorate. A callback that raises is reported once (a ``CallbackWarning``
        naming it) and the step completes; :meth:`remove_listener` stops it.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> floor = w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0.0))
        >>> _ = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2), position=(0, 1))
        >>> seen = []
        >>> @w.on_contact
        ... def landed(event):
        ...     seen.append((event.kind, event.b is floor, event.step))
        >>> for _ in range(60):
        ...     w.step()
        >>> seen  # the seed's springs bounce once
        [('begin', True, 19), ('end', True, 23), ('begin', True, 28)]
        """
        self._events.contact.append(Events.checked(callback, "on_contact"))
        return callback

    def on_joint_break(self, callback: Callable[[Joint], Any]) -> Callable[[Joint], Any]:
        """Call ``callback(joint)`` after the step in which a joint's force exceeded its
        ``break_force`` (the joint is then out of the world, ``joint.broken`` True). Returns
        ``callback``; errors as :meth:`on_contact`'s."""
        self._events.joint_break.append(Events.checked(callback, "on_joint_break"))
        return callback

    def remove_listener(self, callback: Callable[..., Any]) -> None:
        """Stop calling a callback registered with :meth:`on_contact` or :meth:`on_joint_break`.

        Raises
        ------
        ValueError
            If it is not registered.
        """
        self._events.remove(callback)

    # -- colliders --------------------------------------------------------------------------
    @property
    def colliders(self) -> tuple:
        """The colliders, in the order added (a read-only view: use add_collider /
        remove_collider; a collider's own pose, motion and friction can be set directly)."""
        return tuple(self._colliders)

    def add_collider(self, collider: Collider) -> Collider:
        """Add a collider (a :class:`~deforma.Rect`, :class:`~deforma.Circle`,
        :class:`~deforma.Polygon` or :class:`~deforma.Segment`); returns it.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> w.add_collider(deforma.Rect((0, 0), (10, 0.5), 15.0)).angle
        15.0
        >>> paddle = w.add_collider(deforma.Segment((-1, 2), (1, 2), radius=0.05, angular_velocity=90.0))
        >>> len(w.colliders)
        2
        """
        if not isinstance(collider, SHAPES):
            raise ValueError(f"collider must be a deforma.Rect, Circle, Polygon or Segment, "
                             f"got {type(collider).__name__}")
        if any(c is collider for c in self._colliders):
            raise ValueError("this collider is in the world already")
        self._colliders.append(collider)
        return collider

    def remove_collider(self, collider: Collider) -> None:
        """Take a collider out of the world.

        Raises
        ------
        ValueError
            If ``collider`` is not a collider of this world.
        """
        for k, c in enumerate(self._colliders):
            if c is collider:
                del self._colliders[k]
                return
        raise ValueError("that collider is not in this world (see world.colliders)")

    def _collider_key(self) -> tuple:
        return tuple((id(c), c._version) for c in self._colliders)

    def _colliders_changed(self) -> bool:
        return self._packed_colliders != self._collider_key()

    def _pack_colliders(self):
        shapes = list(self._colliders)
        model = self._model
        rigid = model is not None and model.rigid.any() and not self._rigid_in_solve()
        if rigid:  # the rigid bodies' outlines follow, where the state has them now
            rs = rigid_set(model)
            shapes += rs.outlines(*rs.poses(model, self._state.x, self._state.v), self._bodies)
        packed = pack_colliders(shapes, friction=self.friction, static_friction=self.static_friction)
        if rigid:
            packed[len(self._colliders):len(shapes), INV_MASS], packed[len(self._colliders):len(shapes),
                                                                      INV_INERTIA] = rs.inverse_masses(model)
        self._control.colliders = packed
        self._packed_colliders = None if rigid else self._collider_key()

    # -- the step's data ---------------------------------------------------------------------
    @property
    def model(self) -> Model:
        """The bodies' constant arrays as the integrators read them (:class:`~deforma.physics.model.Model`):
        for reading (change parameters through the World and its bodies, which keep it
        consistent). A new Model replaces it when bodies are added, removed or torn.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> _ = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=1))
        >>> w.model.n_vertices, float(w.model.vertex_mass.sum())
        (9, 1.0)
        """
        return self._model

    @property
    def state(self) -> State:
        """Every vertex's position and velocity, ``state.x`` and ``state.v`` ((N, 2), m and
        m/s; :class:`~deforma.physics.state.State`), bodies one after another as in
        :attr:`model`: for reading (a body's own are ``body.positions``, ``body.velocities``)."""
        return self._state

    @property
    def control(self) -> Control:
        """The step's grabs, applied forces and packed colliders
        (:class:`~deforma.physics.control.Control`): for reading."""
        return self._control

    # -- joints -----------------------------------------------------------------------------
    @property
    def joints(self) -> list[Joint]:
        """The joints, in the order they were made (a new list)."""
        return list(self._joints)

    def join(self, a: Body, b: Body | None = None, at: ArrayLike | None = None, *, kind: str = "pin",
             stiffness: float | None = None, damping: float | None = None, motor_speed: float | None = None,
             max_torque: float | None = None, break_force: float | None = None) -> Joint:
        """Join body ``a`` to body ``b`` (None: to the world) at the point ``at``.

        Parameters
        ----------
        a, b : Body, Body or None
            Bodies of this world, ``b`` None for the world. A rigid body (``Material("rigid",
            ...)``) holds the point as it moves and turns; a soft body holds it by the
            triangle under it, whose three vertices share the joint's force by their
            barycentric weights (a hinge tears no hole). Joints on soft bodies are solved by
            ``integrator="avbd"`` (the default).
        at : (float, float)
            The point both hold (m): on ``a`` or ``b`` now, and on every soft body it joins.
        kind : {"pin", "weld", "spring"}
            A hinge (the bodies turn freely about the point), a weld (they do not turn
            either; rigid bodies), or a zero-length spring and damper between the two points.
            Several pins hold a soft body as a weld would (as a tyre on its rim).
        stiffness, damping : float, optional
            A spring's N/m (needed) and N s/m (default 0). Solved implicitly: any stiffness
            is stable.
        motor_speed : float, optional
            A pin's motor between rigid bodies (or one and the world): drives ``a``'s spin
            relative to ``b`` towards this many degrees/s (counter-clockwise), with at most
            ``max_torque`` N m (default: as much as it takes).
        break_force : float, optional
            N: a step whose :attr:`Joint.force` exceeds it breaks the joint (it leaves
            :attr:`joints` and :attr:`Joint.broken` turns True). Default: it never breaks.

        Returns
        -------
        Joint
            Its ``force`` (N, on ``a``) and ``torque`` are the last step's.

        Examples
        --------
        A 1 m bar hinged to the world at its end swings as a compound pendulum:

        >>> import deforma
        >>> w = deforma.World(dt=1 / 60)
        >>> bar = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 0.05), (0, 0.05)), detail=2),
        ...                  position=(0.5, 0.0), material=deforma.Material("rigid", density=100.0))
        >>> hinge = w.join(bar, None, at=(0.0, 0.0))
        >>> for _ in range(30):
        ...     w.step()
        >>> round(float(bar.center_of_mass[1]), 2)  # a quarter swing (0.48 s) later: hanging down
        -0.5

        A jelly block hung from the world by a pin at its top edge stays there:

        >>> w = deforma.World(dt=1 / 60)
        >>> jelly = w.add_body(deforma.mesh.box(((0, 0), (0.2, 0), (0.2, 0.2), (0, 0.2)), detail=3),
        ...                    position=(0.0, 0.0), material=deforma.Material.preset("jelly"))
        >>> top = w.join(jelly, None, at=(0.0, 0.1))
        >>> for _ in range(60):
        ...     w.step()
        >>> bool(abs(top.point - (0.0, 0.1)).max() < 1e-3)
        True
        """
        if not isinstance(kind, str) or kind not in _joint.KINDS:
            raise ValueError(f"kind must be one of {', '.join(_joint.KINDS)}, got {kind!r}")
        for name, body in (("a", a), ("b", b)):
            if body is None and name == "b":
                continue
            self._own_body(body)
        if a is b:
            raise ValueError(f"a joint between body {a._index} and itself holds nothing: join it to another body "
                             f"or to the world (b=None)")
        if at is None:
            raise ValueError("at must be the point (x, y) in metres both bodies hold")
        point = _joint.anchor(at)
        stiffness, damping = _joint.spring(kind, stiffness, damping)
        motor_speed, max_torque = _joint.motor(kind, motor_speed, max_torque)
        break_force = None if break_force is None else _positive(break_force, "break_force", "N")
        under = {id(body): triangles_under(body.positions, body.topology.triangles, point, tolerance=1e-9).any()
                 for body in (a, b) if body is not None}
        if not any(under.values()):
            where = "body " + str(a._index) + ("" if b is None else f" or body {b._index}")
            raise ValueError(f"at = {point} is not on {where}: a joint point must lie on a body it joins")
        for name, body in (("a", a), ("b", b)):
            if body is not None and not body.material.is_rigid:
                self._check_soft_joint(kind, motor_speed, f"{name} (body {body._index})")
                if not under[id(body)]:
                    raise ValueError(f"at = {point} is not on {name} (body {body._index}), a soft body: it holds a "
                                     f"joint by the triangle under the point; put at on it")
        model = self._model
        rs = rigid_set(model)
        center, angle, _, _ = rs.poses(model, self._state.x, self._state.v)
        local, turn = [], 0.0
        for side, body in enumerate((a, b)):
            if body is None:
                local.append(point)
                continue
            if not body.material.is_rigid:
                local.append(point)  # (the rigid stage's frame: a soft side is avbd's alone)
                continue
            k = int(np.flatnonzero(rs.bodies == body._index)[0])
            c, s_ = math.cos(angle[k]), math.sin(angle[k])
            dx, dy = point[0] - center[k, 0], point[1] - center[k, 1]
            local.append((c * dx + s_ * dy, -s_ * dx + c * dy))  # turned back to the body frame
            turn += angle[k] if side == 0 else -angle[k]
        # each side's point as a rigid body carries it (a frame of two vertices) and as a soft
        # body does (the triangle under it): a body's material may change while joined
        frames: list[Any] = [None, None]
        tris: list[Any] = [None, None]
        weights: list[Any] = [None, None]
        ref = 0.0
        for side, body in enumerate((a, b)):
            if body is None:
                continue
            i0, i1, alpha, beta, theta = _joint.frame(body.positions, point)
            frames[side] = (i0, i1, alpha, beta)
            ref += theta if side == 0 else -theta
            tris[side], weights[side] = _joint.triangle_weights(body.positions, body.topology.triangles, point)
        j = Joint(self, a, b, kind, point, np.concatenate(local), turn, stiffness, damping, motor_speed, max_torque,
                  frame=(frames, tris, weights, ref), break_force=break_force)
        self._joints.append(j)
        self._rigid_solve_changed()
        return j

    def _check_soft_joint(self, kind: str, motor_speed, which: str) -> None:
        """Refuse a joint this world cannot hold on the soft body ``which``: a weld or a
        motor (they hold a turn, which a soft body has only as a whole), or any joint under
        an integrator that does not solve joints on soft bodies (all but avbd)."""
        if kind == "weld" or motor_speed is not None:
            what = "a weld" if kind == "weld" else "a motor"
            raise ValueError(f"{what} holds a rigid body's turn, and {which} is soft: join a soft body with pins or "
                             f"springs (several pins hold it as a weld), or pin it to a rigid hub that has the "
                             f"{'weld' if kind == 'weld' else 'motor'}")
        if not self._rigid_in_solve():
            raise ValueError(f"{which} is soft, and joints on soft bodies are solved by integrator='avbd' (the "
                             f"default); this world uses {self._integrator.name!r}")

    def _break_joints(self) -> None:
        """Take out the joints whose force over the last step exceeded their ``break_force``."""
        broken = [j for j in self._joints if j.break_force is not None and np.hypot(*j._force[:2]) > j.break_force]
        for j in broken:
            j._broken = True
            self.remove_joint(j)
        if broken:
            self._events.joints_broken(broken)

    def remove_joint(self, joint: Joint) -> None:
        """Take a joint out of the world.

        Raises
        ------
        ValueError
            If ``joint`` is not one of this world's joints.
        """
        if not any(joint is j for j in self._joints):
            raise ValueError(f"unknown joint {joint!r}: pass one returned by this world's join")
        self._joints = [j for j in self._joints if j is not joint]
        self._rigid_solve_changed()

    # -- interaction ------------------------------------------------------------------------
    def explode(self, strength: float, *, center: ArrayLike | None = None, radius: float | None = None) -> None:
        """A kick to every vertex: ``strength`` m/s upward (the original's space key), or a
        blast away from ``center``.

        Parameters
        ----------
        strength : float
            Speed added, m/s (negative pushes down / inward).
        center : (float, float), optional
            If given, push radially away from this point instead, ``strength`` m/s each
            (a vertex exactly on the centre is not pushed).
        radius : float, optional
            With ``center``: a blast that reaches this far (m), ``strength`` at the centre
            fading linearly to nothing at ``radius``; vertices beyond it are untouched.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> b = w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]))
        >>> w.explode(5.0)
        >>> b.velocities[:, 1].tolist()
        [5.0, 5.0, 5.0]
        >>> w.explode(4.0, center=(0, -1), radius=2.0)  # 1 m from the centre: half of 4 m/s, upward
        >>> b.velocities[:, 1].round(12).tolist()
        [7.0, 5.828427124746, 5.0]
        """
        s = _finite(strength, "strength")
        if radius is not None:
            if center is None:
                raise ValueError("radius needs a center: explode(strength, center=(x, y), radius=r)")
            reach = _positive(radius, "radius", "m")
        self._wake(self._bodies)
        v, x = self._state.v, self._state.x
        if center is None:
            v[:, 1] += s
            return
        d = x - np.asarray(_pair(center, "center"))
        n = np.linalg.norm(d, axis=1)
        ok = n > 0
        if radius is not None:
            ok &= n < reach
        scale = np.full(len(n), s)
        if radius is not None:
            scale *= 1.0 - n / reach
        v[ok] += (scale[ok] / n[ok])[:, None] * d[ok]

    def grab(self, point: ArrayLike, *, strength: float | None = None, radius: float | None = None) -> Grab:
        """Take hold of the body under ``point`` (the mouse press).

        Picks the vertices of the triangle under the point, plus, with ``radius``, every
        vertex of that body within ``radius`` metres. The topmost (last added) body wins.
        A point off every body gives an empty grab that does nothing. A body without
        triangles (a spring chain) is picked by ``radius`` alone. Each held vertex keeps its
        offset from the grabbed point: it is pulled toward ``target + offset``, so dragging
        moves the held patch without squeezing it into one point.

        Parameters
        ----------
        point : (float, float)
            Metres.
        strength : float, optional
            Pull in N/m per held vertex: force ``strength * (target + offset - x)``;
            default ``world.grab_strength``.
        radius : float, optional
            Metres (> 0).

        Returns
        -------
        Grab
            Pass it to :meth:`drag` and :meth:`release`. The target starts at ``point``.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> b = w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]))
        >>> len(w.grab((0.2, 0.2)).vertices), len(w.grab((5.0, 5.0)).vertices)
        (3, 0)
        """
        p = np.asarray(_pair(point, "point"))
        s = self.grab_strength if strength is None else _positive(strength, "strength", "N/m")
        r = None if radius is None else _positive(radius, "radius", "m")
        for body in reversed(self._bodies):
            x = body.positions
            picked = np.zeros(0, np.int64)
            t = body.triangles
            if len(t):
                hit = np.flatnonzero(triangles_under(x, t, p))
                if len(hit):
                    picked = t[hit[0]].astype(np.int64)
            if r is not None and (len(picked) or not len(t)):
                near = np.flatnonzero(np.linalg.norm(x - p, axis=1) <= r)
                picked = np.union1d(picked, near)
            if len(picked):
                picked = np.unique(picked)
                g = Grab(self, body, picked, (float(p[0]), float(p[1])), s, offsets=x[picked] - p)
                break
        else:
            g = Grab(self, None, [], (float(p[0]), float(p[1])), s)
        if g.body is not None:
            self._disturb(g.body)
        self._grabs.append(g)
        self._grabs_dirty = True
        return g

    def _own_grab(self, g) -> None:
        if not isinstance(g, Grab) or g._world is not self:
            raise ValueError(f"unknown grab {g!r}: pass one returned by this world's grab()")

    def drag(self, g: Grab, target: ArrayLike) -> None:
        """Move the pull target of an active grab to ``target`` (metres)."""
        self._own_grab(g)
        if not g.active:
            raise ValueError("this grab was released; grab again")
        g.target = _pair(target, "target")
        self._grabs_dirty = True

    def release(self, g: Grab) -> None:
        """Let go (the mouse release); releasing twice is harmless."""
        self._own_grab(g)
        if g.active:
            g.active = False
            self._grabs.remove(g)
            self._grabs_dirty = True

    def _rebuild_grabs(self):
        self._control.hold([(g.body.vertex_slice.start + g.vertices, g.strength, np.asarray(g.target) + g.offsets)
                            for g in self._grabs if len(g.vertices)])
        self._grabs_dirty = False

    # -- stepping ---------------------------------------------------------------------------
    def step(self) -> None:
        """Advance the world by ``dt`` seconds (``substeps`` substeps; the stages are
        :mod:`deforma.physics.stepper`'s).

        Raises
        ------
        SimulationUnstable
            If a vertex ends non-finite or faster than ``max_speed``, is trapped between
            colliders, or a body lost its shape; the world is then put back exactly as it was
            before this step (positions, velocities, rest shapes, torn meshes, collider poses).
        """
        stepper.step(self)

    def solve_static(self, *, tolerance: float = 1e-6, max_iterations: int = 1000, max_seconds: float = 60.0,
                     progress: Callable[..., Any] | bool | None = None) -> int:
        """Move every body to its static equilibrium under its pins, gravity, the forces
        applied with ``body.apply_force`` and its contacts (:mod:`deforma.physics.statics`:
        backward Euler relaxation from rest, whatever the world's integrator).

        Parameters
        ----------
        tolerance : float, optional
            m (> 0): done when no vertex is estimated farther than this from where it settles.
        max_iterations : int, optional
            Relaxation steps at most (in [1, 100000]); each is one converged implicit solve.
        max_seconds : float, optional
            Wall-time budget, s (> 0, ``inf`` for none; Numba's one-time compiling is not
            counted), checked after each relaxation step. Default 60.
        progress : None, False or callable, optional
            ``None``: a bar on stderr when it is a terminal, once the solve has taken a second;
            ``False``: nothing; a callable is given a
            :class:`~deforma.physics.statics.StaticProgress` (``iteration``, ``moved``,
            ``remaining``, ``tolerance``, ``elapsed``, ``max_seconds``) after every step, and
            an exception it raises stops the solve (the World is put back).

        Returns
        -------
        int
            The relaxation steps taken. ``time`` and ``step_count`` stay; velocities end at
            zero; applied forces are used and forgotten, as by a step.

        Raises
        ------
        ValueError
            One line each, and the World is put back as it was. Before any step: a bad
            argument; bodies nothing holds (no pinned vertex, no collider); a material that
            tears or yields; a ``tolerance`` below what float64 resolves at the bodies'
            coordinates. Once seen: a body that fell past every collider (slid or rolled off);
            a relaxation that stopped getting closer for 100 steps (naming the body: one that
            slides freely on frictionless colliders, one that jitters, a tolerance below the
            solve's noise); no rest within ``max_iterations`` or ``max_seconds``.

        Examples
        --------
        >>> import deforma, numpy as np
        >>> w = deforma.World(gravity=(0.0, -9.81), mass=2.0, stiffness=100.0)
        >>> class Chain:  # one spring, a 1 kg mass hanging from a pinned one
        ...     vertices, edges = np.array([[0.0, 0.0], [0.0, -1.0]]), np.array([[0, 1]])
        >>> b = w.add_body(Chain())
        >>> b.pin([0])
        >>> steps = w.solve_static()
        >>> round(float(-b.positions[1, 1] - 1.0), 5)  # m g / k, to the tolerance of 1e-6 m
        0.0981
        """
        from .statics import solve_static

        return solve_static(self, tolerance=tolerance, max_iterations=max_iterations, max_seconds=max_seconds,
                            progress=progress)

    # -- diagnostics ------------------------------------------------------------------------
    def stable_dt(self, *, explicit: bool = False) -> float:
        """Estimate of the largest stable explicit (sub)step in seconds for the current bodies.

        For an unconditionally stable integrator (``"implicit-euler"``, ``"xpbd"``) this is
        ``inf`` unless ``explicit=True``, which always gives the semi-implicit Euler limit
        below (e.g. to say how far beyond it a stiff setup is).

        Bounds the fastest spring mode by Gershgorin's theorem, ``omega^2 <= max_i
        2 sum(ks)_i / m_i`` and ``gamma <= max_i 2 sum(kd)_i / m_i`` over the springs (and
        grabs) at each vertex; a finite element adds its stiffness matrix's row sum,
        ``A k sum_w |D_i . D_w|`` with ``k = 2 (mu + max(lambda, 0))`` its stiffness at rest
        (:func:`~deforma.physics.elements.triangles.max_stiffness`), and ``damping`` times that to
        ``gamma``. Then it returns the step at which semi-implicit Euler on
        ``x'' = -omega^2 x - gamma x'`` turns unstable, ``(sqrt(gamma^2 + 4 omega^2) - gamma)
        / omega^2`` (``2 / omega`` without damping). Compare it with ``dt / substeps``.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(mass=2.0, stiffness=100.0, damping=0.0, integrator="symplectic-euler")
        >>> _ = w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]))
        >>> round(w.stable_dt(), 4)  # 2 / sqrt(2 * 200 / (2 / 3))
        0.0816
        """
        if not explicit and self._integrator.unconditionally_stable:
            return math.inf
        if self._grabs_dirty:
            self._rebuild_grabs()
        return diagnostics.stable_dt(self._model, self._control)

    def xpbd_substeps(self, strain: float = 0.01) -> int:
        """Substeps per ``dt`` at which XPBD holds the bodies up under their own weight.

        XPBD's Gauss-Seidel sweep carries a correction only about one row of the mesh per
        sweep, so within a substep the support of the floor (or of pins) does not reach the
        whole body, and a stiff body standing or hanging sags far more than its material
        says. A column of ``N = H / l`` rows (height ``H`` along gravity, mesh spacing ``l``,
        the median edge) whose every spring is corrected once per sweep comes to rest
        shortened by ``g H h^2 / (l^2 iterations)`` of its height; a pinned body's ``H`` is
        the distance from its pins to its farthest vertex in any direction, since a
        horizontal cantilever bends under the same lag (a 1 m one 0.1 m thick: its height
        asked for 3 substeps at 1/60 s, under which its tip hung 69% lower than at rest in
        equilibrium; its length asks for 30, 12%); measured on finite-element
        and spring bodies the sag is up to twice that (and a lattice of springs beyond about
        10% folds flat; docs/integrators.md, "How many substeps XPBD needs"). This returns
        the smallest number of substeps for which twice that estimate is at most ``strain``
        for every body, with the XPBD integrator's ``iterations`` (one sweep per substep
        under any other integrator). It does not include the material's own sag, which every
        integrator shows.

        Parameters
        ----------
        strain : float
            Shortening allowed, as a fraction of each body's height, in (0, 1); default 1%.

        Returns
        -------
        int
            At least 1 (also without gravity or bodies).

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(dt=1 / 60, integrator="xpbd")
        >>> _ = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=98))
        >>> w.xpbd_substeps()  # a 1 m body with 1 cm spacing at a display step
        74
        """
        if isinstance(strain, bool) or not isinstance(strain, (int, float, np.number)) \
                or not 0.0 < float(strain) < 1.0:
            raise ValueError(f"strain must be a number in (0, 1), got {strain!r}")
        sweeps = self._integrator.options["iterations"] if self.integrator == "xpbd" else 1
        return diagnostics.xpbd_substeps(self._bodies, self.gravity, self._dt, sweeps, float(strain))

    def energy(self, body: Body | None = None) -> Energy:
        """Kinetic, spring, gravitational and elastic (finite-element) energy in joules, of one body or all.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(mass=3.0)
        >>> b = w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]), position=None)
        >>> b.velocities[:] = (2.0, 0.0)
        >>> w.energy().kinetic  # 3 kg at 2 m/s
        6.0
        """
        m = self._model
        if body is None:
            return diagnostics.energy(m, self._state, self.gravity)
        b = self._own_body(body)
        return diagnostics.energy(m, self._state, self.gravity, body.vertex_slice,
                                  slice(int(m.body_spring_offsets[b]), int(m.body_spring_offsets[b + 1])),
                                  slice(int(m.body_elem_offsets[b]), int(m.body_elem_offsets[b + 1])))

    def _repr_png_(self) -> bytes:
        """A picture of the world as it is now (PNG bytes, 400 px on the longer side): what a
        notebook shows for a World. Bodies are filled triangles in their picture's colours,
        colliders grey; drawn with Pillow by :func:`deforma.mesh.picture.world_picture`."""
        from ..mesh.picture import png_bytes, world_picture

        return png_bytes(world_picture(self))

    def __repr__(self) -> str:
        return (f"World({len(self._bodies)} bodies, {self._model.n_vertices} vertices, "
                f"{len(self._colliders)} colliders, t={self.time:.4g} s)")

"""What the World says about a run: the stable explicit step, energies, whether a step went
wrong (a runaway vertex, a body that lost its shape, one trapped between colliders) and what
to change then.

Everything here reads a World's data and raises or returns; nothing changes it. The checks
raise :class:`SimulationUnstable`, which the step pipeline (:mod:`deforma.physics.stepper`)
catches to put the World back as it was before the step.

Units are SI (m, kg, s, N).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np

from ..checks import LIMITS, MAX_SUBSTEPS
from .behaviours.strain import spring_strains
from .elements.triangles import element_energy, signed_areas

# A body has lost its shape when a spring is this many times its rest length, or its area
# falls below this share of its rest area; checked every SHAPE_CHECK_EVERY steps.
LOST_STRETCH = 10.0
LOST_AREA = 0.1
SHAPE_CHECK_EVERY = 16


class SimulationUnstable(RuntimeError):
    """This world cannot step at this ``dt``: a step produced a non-finite or runaway state
    (the world was put back as before it), or, before any step, the step it asks for is beyond
    what the integrator can hold (:class:`StepTooLong`, also a ``ValueError``).

    Attributes
    ----------
    body : Body
        The first body with a bad vertex.
    step : int
        Index of the failed step (``world.step_count`` when it started).
    hint : str
        What to change, e.g. "dt/substeps 0.01 s exceeds the stable estimate 0.002 s: ...".
    """

    def __init__(self, message: str, *, body, step: int, hint: str):
        super().__init__(message)
        self.body = body
        self.step = step
        self.hint = hint


class StepTooLong(SimulationUnstable, ValueError):
    """``substeps = "auto"`` would need more than ``MAX_SUBSTEPS`` substeps of ``dt`` to stay
    within the stable explicit step: raised where it is asked (setting ``substeps = "auto"``,
    or at the next :meth:`World.step` after the bodies, grabs or ``dt`` changed), before anything
    is changed. The one error for "this world cannot step at this dt" is
    :class:`SimulationUnstable`, and this is one; it is also a ``ValueError``, as a setting the
    world refuses is everywhere else (and as this was before), so ``except ValueError`` and
    ``except SimulationUnstable`` both catch it.

    Attributes (besides :class:`SimulationUnstable`'s; ``body`` is the one whose vertex sets the
    stable step)
    ----------
    needed : int
        The substeps ``"auto"`` would take.
    stable : float
        The stable explicit (sub)step, s.
    largest_dt : float
        The largest ``dt`` (s) that ``MAX_SUBSTEPS`` substeps hold, rounded down to 3 digits;
        0 where that is below the shortest ``dt`` a World takes (1e-6 s).
    """

    def __init__(self, message: str, *, body, step: int, hint: str, needed: int, stable: float, largest_dt: float):
        super().__init__(message, body=body, step=step, hint=hint)
        self.needed = needed
        self.stable = stable
        self.largest_dt = largest_dt


def _round_down(value: float, digits: int = 3) -> float:
    """``value`` (> 0) rounded down to ``digits`` significant digits."""
    unit = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.floor(value / unit * (1.0 + 1e-12)) * unit


def step_too_long(world, model, control, need: int, stable: float) -> StepTooLong:
    """The :class:`StepTooLong` for ``world`` whose ``substeps = "auto"`` would need ``need``
    substeps of its ``dt`` at the stable step ``stable`` (s): names the body that sets it and
    the options that fit (the largest ``dt``, softer bodies, a weaker grab, an unconditionally
    stable integrator)."""
    body = world.bodies[0] if world.bodies else None
    if model.n_vertices:
        w2, gamma = vertex_rates(model, control)
        first = int(np.argmax(np.hypot(gamma, 2.0 * np.sqrt(w2)) + gamma))  # the shortest 4 / (...)
        b = int(np.searchsorted(model.body_vertex_offsets, first, side="right") - 1)
        if 0 <= b < len(world.bodies):
            body = world.bodies[b]
    largest = _round_down(MAX_SUBSTEPS * stable) if math.isfinite(stable) and stable > 0 else 0.0
    shortest = LIMITS["dt"][0]
    why = f"{damping_note(model, control, stable)}{grab_note(model, control, stable)}"
    if largest >= shortest:
        fits = f"lower dt to {largest:.3g} s or less ({MAX_SUBSTEPS} substeps of it hold)"
    else:  # no dt the World takes: only the bodies or the integrator can change
        largest = 0.0
        fits = f"no dt of at least {shortest:g} s fits in {MAX_SUBSTEPS} substeps"
    fits += ", lower the grab strength" if grab_note(model, control, stable) else ", soften the bodies"
    hint = f"{fits}, or use integrator=\"implicit-euler\" (stable at any step)"
    count = f"{need}" if need < 10**6 else f"about {need:.3g}"  # no count of 80 digits
    message = (f"substeps = \"auto\" would need {count} substeps of dt = {world.dt:g} s (stable step {stable:.3g} s"
               f"{why}), more than {MAX_SUBSTEPS}: {hint}")
    return StepTooLong(message, body=body, step=world.step_count, hint=hint, needed=need, stable=stable,
                       largest_dt=largest)


@dataclass(frozen=True)
class Energy:
    """Energies in joules: kinetic ``sum m v^2 / 2``, spring ``sum ks (L - l)^2 / 2``,
    gravitational ``-sum m g . x`` (zero at the origin) and the elastic energy of the
    finite elements ``sum A psi(F)``."""

    kinetic: float
    spring: float
    gravitational: float
    elastic: float = 0.0

    @property
    def total(self) -> float:
        """Sum of the four, in joules."""
        return self.kinetic + self.spring + self.gravitational + self.elastic


def energy(model, state, gravity, vertices=slice(None), springs=slice(None), elements=slice(None)) -> Energy:
    """The :class:`Energy` of the vertices, springs and triangle elements in the given slices
    (all by default); ``elastic`` also holds the registered element kinds' energy of those
    vertices."""
    x, v, mass = state.x[vertices], state.v[vertices], model.vertex_mass[vertices]
    kinetic = 0.5 * float(np.sum(mass * np.einsum("ij,ij->i", v, v)))
    si, sj = model.spring_i[springs], model.spring_j[springs]
    stretch = np.linalg.norm(state.x[sj] - state.x[si], axis=1) - model.spring_rest_length[springs]
    spring = 0.5 * float(np.sum(model.spring_stiffness[springs] * stretch * stretch))
    gravitational = -float(np.sum(mass * (x @ np.asarray(gravity))))
    ts = elements
    elastic = float(np.sum(element_energy(state.x, model.elem[ts], model.elem_b[ts], model.elem_area[ts],
                                          model.elem_mu[ts], model.elem_lambda[ts], model.elem_kind[ts])))
    lo, hi = (0, model.n_vertices) if vertices == slice(None) else (vertices.start, vertices.stop)
    for kind in model.elements:  # the registered kinds' elements of these vertices
        if kind is model.springs or kind is model.triangles:  # counted above
            continue
        mine = (kind.vertices[:, 0] >= lo) & (kind.vertices[:, 0] < hi)
        elastic += float(np.sum(kind.energy(state.x)[mine]))
    return Energy(kinetic, spring, gravitational, elastic)


def vertex_rates(model, control) -> tuple[np.ndarray, np.ndarray]:
    """Per vertex, ``(omega^2, gamma)`` (N,) (1/s^2, 1/s): its stiffness and damping rates,
    from every element kind's row sums and ``control``'s grabs."""
    n = model.n_vertices
    ks, kd = np.zeros(n), np.zeros(n)
    for kind in model.elements:
        ks += kind.stiffness_rows(n)
        kd += kind.damping_rows(n)
    held = control.grab_slot >= 0
    ks[held] += control.grab_pull[control.grab_slot[held], 0]
    return 2 * ks * model.vertex_inv_mass, 2 * kd * model.vertex_inv_mass


def explicit_rates(model, control) -> tuple[float, float]:
    """``(omega^2, gamma)`` of :func:`stable_dt`: the largest stiffness and damping rates over
    the vertices (1/s^2, 1/s), :func:`vertex_rates`."""
    w2, gamma = vertex_rates(model, control)
    return float(np.max(w2)), float(np.max(gamma))


def stable_dt(model, control) -> float:
    """The semi-implicit Euler step limit (s) of ``model`` with ``control``'s grabs (see
    :meth:`deforma.World.stable_dt`)."""
    if model.n_vertices == 0:
        return math.inf
    w2, gamma = explicit_rates(model, control)
    if w2 == 0:
        return math.inf if gamma == 0 else 2 / gamma
    # (sqrt(gamma^2 + 4 w2) - gamma) / w2, written without the difference of two close
    # numbers (heavy damping made it 0, and a hint then divided by it)
    return 4.0 / (math.hypot(gamma, 2.0 * math.sqrt(w2)) + gamma)


def damping_note(model, control, stable: float) -> str:
    """`` (set by damping: ...)`` when damping, not stiffness, makes the explicit step
    ``stable`` (s) more than 10x shorter: a material's damping (stiffness-proportional,
    ``material_damping``) easily does, and the hint should name it."""
    w2, _ = explicit_rates(model, control)
    undamped = math.inf if w2 == 0 else 2.0 / math.sqrt(w2)
    if not stable < 0.1 * undamped:
        return ""
    return f" (set by the damping: {undamped:.3g} s without it; lower material_damping or damping)"


def grab_note(model, control, stable: float) -> str:
    """`` (set by the grabs: ...)`` when the grabs, not the bodies, make the explicit step
    ``stable`` (s) less than half as long: a runaway under a strong grab was told to "lower the
    stiffness or damping, raise the mass", which changes nothing a grab of 1e12 N/m does."""
    held = control.grab_slot >= 0
    if not held.any():
        return ""
    free = copy.copy(control)
    free.grab_slot = np.full_like(control.grab_slot, -1)
    ungrabbed = stable_dt(model, free)
    if not stable < 0.5 * ungrabbed:
        return ""
    strongest = float(np.max(control.grab_pull[control.grab_slot[held], 0]))
    return (f" (set by the grabs, up to {strongest:.3g} N/m on a vertex: {ungrabbed:.3g} s without them; "
            f"lower the grab strength)")


def support_reach(x, pinned, down) -> float:
    """How far (m) the support of a body at rest positions ``x`` (N, 2) must travel through
    it: from its pinned vertices to the farthest vertex, in any direction (a cantilever held
    at one end bends under a load that its pins carry along its length); without pins, its
    height along ``down`` (a floor holds it from below).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 0.1]])
    >>> support_reach(x, np.array([True, False, False, False]), np.array([0.0, -1.0]))  # along its length
    2.0024984394500787
    >>> support_reach(x, np.zeros(4, bool), np.array([0.0, -1.0]))  # standing: its height
    0.1
    """
    if not pinned.any():
        return float(np.ptp(x @ down))
    from scipy.spatial import cKDTree

    return float(cKDTree(x[pinned]).query(x)[0].max())


def xpbd_substeps(bodies, gravity, dt: float, sweeps: int, strain: float) -> int:
    """Substeps per ``dt`` at which XPBD with ``sweeps`` sweeps per substep holds ``bodies``
    up under ``gravity`` to ``strain`` (see :meth:`deforma.World.xpbd_substeps`)."""
    g = math.hypot(*gravity)
    if g == 0.0 or not bodies:
        return 1
    down = np.asarray(gravity, dtype=np.float64) / g
    need = 1
    for body in bodies:
        t = body.topology
        x, e = t.rest_positions, t.springs
        if len(e) == 0:
            continue
        spacing = float(np.median(np.hypot(*(x[e[:, 1]] - x[e[:, 0]]).T)))
        reach = support_reach(x, body.pinned, down)
        if spacing <= 0.0 or reach <= 0.0:
            continue
        h = spacing * math.sqrt(strain * sweeps / (2.0 * g * reach))
        need = max(need, math.ceil(dt / h - 1e-9))
    return need


def xpbd_advice(world) -> str:
    """What to do when ``world`` runs XPBD with fewer substeps than :meth:`World.xpbd_substeps`
    asks for, in one clause; ``""`` otherwise (or under another integrator). The viewer,
    ``deforma run`` and the lost-shape hint all say it in these words.

    Examples
    --------
    >>> import deforma
    >>> w = deforma.World(dt=1 / 60, integrator="xpbd")
    >>> _ = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=28))
    >>> xpbd_advice(w)
    'under xpbd with substeps = 1 the bodies sag under their own weight (a sweep carries the support one mesh row): raise substeps to 22 (world.xpbd_substeps()) or use implicit-euler'
    """
    if world.integrator != "xpbd":
        return ""
    need = world.xpbd_substeps()
    if world.substeps >= need:
        return ""
    return (f"under xpbd with substeps = {world.substeps} the bodies sag under their own weight (a sweep carries "
            f"the support one mesh row): raise substeps to {need} (world.xpbd_substeps()) or use implicit-euler")


def runaway(world, model, state, start, control, step: int, *, unconditionally_stable: bool) -> SimulationUnstable:
    """The error for a step whose integrator left vertices non-finite or faster than
    ``world.max_speed``: which body, and what to change (from the stable step estimate, the
    velocities at the step's ``start`` and whether the integrator has a step limit)."""
    x, v = state.x, state.v
    speed = np.hypot(v[:, 0], v[:, 1])
    bad = ~(np.isfinite(x).all(axis=1) & (speed <= world.max_speed))
    first = int(np.argmax(bad))
    b = int(np.searchsorted(model.body_vertex_offsets, first, side="right") - 1)
    finite = bool(np.isfinite(speed[first]) and np.isfinite(x[first]).all())
    what = f"a vertex faster than max_speed {world.max_speed:g} m/s" if finite \
        else "non-finite positions or velocities"
    h = world.dt / world.substeps
    stable = world.stable_dt()
    given = float(np.max(np.hypot(start.v[:, 0], start.v[:, 1]), initial=0.0))
    if given > world.max_speed:
        hint = (f"a velocity given before the step is already {given:.3g} m/s, beyond max_speed "
                f"{world.max_speed:g} m/s (explode strength, body.velocities): give less, or raise max_speed")
    elif math.isinf(stable) and unconditionally_stable:
        hint = (f"the {world.integrator} integrator has no step limit, so a large force ran away "
                f"(grab strength, explosion): lower it, or raise max_speed if such speeds are intended")
    elif h > stable and world.dt / stable <= MAX_SUBSTEPS:
        need = math.ceil(world.dt / stable)
        hint = (f"dt/substeps {h:.3g} s exceeds the stable estimate {stable:.3g} s"
                f"{damping_note(model, control, stable)}{grab_note(model, control, stable)}: lower dt or raise "
                f"substeps to at least {need}")
    elif h > stable:
        hint = (f"dt/substeps {h:.3g} s exceeds the stable estimate {stable:.3g} s"
                f"{damping_note(model, control, stable)}{grab_note(model, control, stable)} by more than "
                f"{MAX_SUBSTEPS} substeps can make up: lower "
                f"the stiffness or damping, raise the mass, or use an unconditionally stable integrator "
                f"(implicit-euler, xpbd)")
    else:
        hint = (f"dt/substeps {h:.3g} s is within the stable estimate {stable:.3g} s, so a large "
                f"force ran away (grab strength, explosion, stiffness): lower it, raise damping "
                f"or substeps, or raise max_speed if such speeds are intended")
    return SimulationUnstable(f"body {b} became unstable at step {step} ({what}); {hint}",
                              body=world.bodies[b], step=step, hint=hint)


def lost_shape(world, model, state, lost: dict, step: int) -> SimulationUnstable | None:
    """The error for a body that has lost its shape at two checks in a row, else ``None``.

    Lost: a spring stretched ``LOST_STRETCH`` times its rest length, or a finite-element
    body's triangles turned inside out over most of it (its area below ``LOST_AREA`` of its
    rest area). A hard impact may crush a body for a moment, so only a shape still lost at
    the next check is garbage; ``lost`` (body id -> checks in a row) is updated. No stable
    step keeps either; a run that did is garbage however finite its numbers (a step too long
    for the stiffness, a body started inside a collider).
    """
    m, x = model, state.x
    for b, body in enumerate(world.bodies):
        tear = body.material.tear_strain
        limit = LOST_STRETCH if tear is None else max(LOST_STRETCH, 2.0 * (1.0 + tear))
        s0, s1 = m.body_spring_offsets[b], m.body_spring_offsets[b + 1]
        what = None
        if s1 > s0:
            ratio = 1.0 + float(np.max(spring_strains(x, m.spring_i[s0:s1], m.spring_j[s0:s1],
                                                      m.spring_rest_length[s0:s1])))
            if ratio > limit:
                what = f"a spring is {ratio:.3g} times its rest length"
        t0, t1 = m.body_elem_offsets[b], m.body_elem_offsets[b + 1]
        # only finite elements are held to their area: a springs body (no elements in the
        # Model) folded flat keeps every spring's length, a state of that model
        if what is None and t1 > t0:
            area = signed_areas(x, m.elem[t0:t1])
            rest = m.elem_area[t0:t1]
            if area.sum() < LOST_AREA * rest.sum():
                what = (f"its area fell to {area.sum() / rest.sum():.0%} of its rest area "
                        f"({np.mean(area < 0):.0%} of its triangles inside out)")
        seen = lost.get(id(body), 0) + 1 if what is not None else 0
        lost[id(body)] = seen
        if seen < 2:
            continue
        hint = ("shorten dt or raise substeps (or use implicit-euler), and start bodies outside colliders; "
                "a stiffer or denser body keeps its shape better")
        advice = xpbd_advice(world)
        if advice:
            hint = f"{advice}, and start bodies outside colliders"
        return SimulationUnstable(f"body {b} lost its shape at step {step}: {what}; {hint}",
                                  body=body, step=step, hint=hint)
    return None


def trapped(world, model, state, step: int) -> SimulationUnstable | None:
    """The error for a vertex left inside a collider (after colliders moved or changed), else ``None``.

    The response pushes a vertex out of a collider that moved onto it; only one with no
    room left, squeezed between colliders closer than the body can fit, stays inside.
    """
    x = state.x
    for c, collider in enumerate(world.colliders):
        x0, y0, x1, y1 = collider.bounds()
        # a rigid body's vertices are the rigid stage's (it may rest a hair inside a collider)
        near = np.flatnonzero((x[:, 0] > x0) & (x[:, 0] < x1) & (x[:, 1] > y0) & (x[:, 1] < y1) & ~model.rigid)
        inside = near[collider.contains(x[near])] if len(near) else near
        if len(inside):
            b = int(np.searchsorted(model.body_vertex_offsets, inside[0], side="right") - 1)
            hint = ("move the colliders apart (or the body out from between them): the gap left "
                    "is narrower than the body can be squeezed")
            return SimulationUnstable(
                f"body {b} is trapped inside collider {c} at step {step} "
                f"({len(inside)} vertices, squeezed between colliders); {hint}",
                body=world.bodies[b], step=step, hint=hint)
    return None

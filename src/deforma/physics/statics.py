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

How long it may take (issue 51: the built-in ``crates``, ``balloon``, ``pile`` and
``playground`` ran for minutes, silently): at most ``max_iterations`` relaxation steps and
``max_seconds`` of wall time (default 60 s; Numba's one-time compiling of the kernels is not
counted), whichever comes first; and it gives up early, naming the body, when the relaxation
stops getting closer: when the median move of the last :data:`STALL_WINDOW` steps is more
than :data:`STALL_RATIO` of the median of the ones before (a converging relaxation shrinks
it by ``r^100``, 0.37 for the slow ``r = 0.99`` of a mode with a 6 s period). Progress is
shown on a terminal (a bar on stderr after a second) or given to a ``progress`` callable.

What it refuses, in one line and changing nothing: bodies that nothing holds (no pinned
vertex and no collider in the world) under gravity or a force, materials whose rest shape
depends on the path (tearing, plasticity), a ``tolerance`` below what float64 resolves at the
bodies' coordinates (checked first, before any step); and, once seen, a body that fell past
every collider (it slid or rolled off its support), a relaxation that stopped getting closer
(a body that slides without end on frictionless colliders, one that jitters on a contact the
implicit solve cannot resolve, a tolerance below the solve's noise), and a world that does not
settle within ``max_iterations`` steps or ``max_seconds`` (the World is put back as it was).

Units: m, s.
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Callable

import numpy as np

from ..checks import number
from .integrators import make_integrator

if TYPE_CHECKING:
    from .world import World

#: The relaxation step: the longest ``dt`` a World takes (s).
RELAX_STEP = 0.1
#: The velocity tolerance of each relaxation step's solve (m/s).
SOLVE_TOLERANCE = 1e-6
#: The default wall-time budget of one call (s).
MAX_SECONDS = 60.0
#: Relaxation steps per window of the stall test, and the share of the previous window's median
#: move above which the last window's median counts as no closer.
STALL_WINDOW = 100
STALL_RATIO = 0.9
#: The smallest tolerance, in doubles' spacing at the largest coordinate: below it the moves
#: that decide the end cannot be told apart from rounding.
RESOLVABLE_ULPS = 16


@dataclass(frozen=True)
class StaticProgress:
    """What :func:`solve_static` tells a ``progress`` callable after each relaxation step.

    Attributes
    ----------
    iteration : int
        Relaxation steps done (1, 2, ...); ``max_iterations`` at most.
    moved : float
        The largest distance a vertex moved in the last step (m).
    remaining : float
        Estimated distance still to go (m): ``moved * max(1, r / (1 - r))``, ``inf`` while the
        moves do not shrink; done when it is within ``tolerance``.
    tolerance : float
        The tolerance asked for (m).
    elapsed, max_seconds : float
        Seconds used so far (Numba's compiling not counted) and the budget (s).
    """

    iteration: int
    moved: float
    remaining: float
    tolerance: float
    elapsed: float
    max_seconds: float


def _check_arguments(tolerance, max_iterations, max_seconds, progress) -> tuple[float, float]:
    tol = number(tolerance, "tolerance")
    if not tol > 0.0:
        raise ValueError(f"tolerance must be a distance > 0 m, got {tolerance!r}")
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, (int, np.integer)) \
            or not 1 <= max_iterations <= 100_000:
        raise ValueError(f"max_iterations must be an integer in [1, 100000], got {max_iterations!r}")
    if isinstance(max_seconds, (bool, np.bool_)) or isinstance(max_seconds, complex):
        raise ValueError(f"max_seconds must be a number of seconds > 0 (inf: no limit), got {max_seconds!r}")
    try:
        budget = float(max_seconds)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"max_seconds must be a number of seconds > 0 (inf: no limit), got {max_seconds!r}") \
            from None
    if not budget > 0.0:  # NaN too
        raise ValueError(f"max_seconds must be a number of seconds > 0 (inf: no limit), got {max_seconds!r}")
    if progress is not None and progress is not False and not callable(progress):
        raise ValueError(f"progress must be None (a bar on a terminal), False or a callable taking a "
                         f"StaticProgress, got {progress!r}")
    return tol, budget


def _held(world) -> np.ndarray:
    """Per body: whether a pin or a joint holds it (not only its contacts)."""
    held = np.array([bool(b.pinned.any()) for b in world.bodies])
    index = {id(b): i for i, b in enumerate(world.bodies)}
    for j in world.joints:
        for side in (j.a, j.b):
            if side is not None and id(side) in index:
                held[index[id(side)]] = True
    return held


def _frictionless(world) -> bool:
    """Whether every collider's surface is frictionless (its own coefficients, else the world's)."""
    def coefficient(own, default):
        return default if own is None else own
    return bool(world.colliders) and all(
        coefficient(c.friction, world.friction) == 0.0 and coefficient(c.static_friction, world.static_friction) == 0.0
        for c in world.colliders)


def _bar(total: int):
    """A tqdm bar on stderr, only on a terminal, shown once the solve has taken a second."""
    if not bool(getattr(sys.stderr, "isatty", lambda: False)()):
        return None
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency
        return None
    return tqdm(total=total, desc="solve_static", unit="step", delay=1.0, leave=False, dynamic_ncols=True,
                file=sys.stderr)


def solve_static(world: "World", *, tolerance: float = 1e-6, max_iterations: int = 1000,
                 max_seconds: float = MAX_SECONDS, progress: Callable[[StaticProgress], object] | bool | None = None
                 ) -> int:
    """Move every body to its static equilibrium (see the module docstring); returns the
    relaxation steps it took. ``world.time`` and ``world.step_count`` stay; velocities end at
    zero; the forces applied with ``body.apply_force`` act throughout and are then forgotten,
    as after a step. ``progress``: ``None`` draws a bar on a terminal, ``False`` nothing, a
    callable is given a :class:`StaticProgress` after every step (an exception it raises
    stops the solve, and the World is put back)."""
    tol, budget = _check_arguments(tolerance, max_iterations, max_seconds, progress)
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
    scale = float(np.abs(world._state.x).max(initial=0.0))
    finest = RESOLVABLE_ULPS * float(np.spacing(max(scale, 1.0)))
    if tol < finest:
        raise ValueError(f"solve_static: tolerance {tol:g} m is below what float64 resolves at these coordinates "
                         f"(up to {scale:.3g} m from the origin, where doubles are {np.spacing(max(scale, 1.0)):.3g} "
                         f"m apart): give tolerance >= {finest:.2g} m")
    held = _held(world)
    g = np.asarray(world.gravity, dtype=np.float64)
    up = -g / math.hypot(*g) if g.any() else None
    floor = None
    if up is not None and world.colliders:
        # the lowest point of any collider along "up": a free body wholly below it has left them all
        floor = min(float((np.array([[x0, y0], [x1, y0], [x0, y1], [x1, y1]]) @ up).min())
                    for x0, y0, x1, y1 in (c.bounds() for c in world.colliders))
    offsets = np.asarray(world._model.body_vertex_offsets)

    # what the relaxation borrows, and what a failure puts back (tearing and plasticity are
    # refused above, so the topology and rest shapes stay; moving colliders hold still)
    x0, v0, lost = world._state.x.copy(), world._state.v.copy(), dict(world._lost_shape)
    forces = list(world._forces)
    borrowed = (world._integrator, world._dt, world._substeps, world._auto, world.time, world.step_count)
    motions = [(c, c.velocity, c.angular_velocity) for c in world.colliders]
    for c, _, _ in motions:
        c.velocity, c.angular_velocity = (0.0, 0.0), 0.0
    # sleeping is the motion's: with every velocity zeroed, a body still on its way would fall
    # asleep after SLEEP_TIME and be held there, a false rest; every body relaxes awake
    sleep, dozing = world._sleep, [(b, b._asleep, b._still) for b in bodies]
    world._sleep = False
    world._wake(bodies)
    integrator = make_integrator("implicit-euler", {"tolerance": SOLVE_TOLERANCE, "max_iterations": 2000})
    world._integrator = integrator
    world._dt, world._substeps, world._auto = RELAX_STEP, 1, False
    done, settled, moved = 0, False, math.inf
    moves: list[float] = []
    centres = deque(maxlen=STALL_WINDOW + 1)  # each body's centre after the last steps
    body_moves = deque(maxlen=STALL_WINDOW)  # each body's largest vertex move in the last steps
    bar = _bar(max_iterations) if progress is None else None
    from ..startup import CompileWatch

    started = time.perf_counter()
    try:
        with CompileWatch() as watch, warnings.catch_warnings():
            # "the implicit solve stopped at max_iterations short of its tolerance": counted, and
            # said in the error if the relaxation fails, not once per call in the world's words
            warnings.filterwarnings("ignore", message="the implicit solve stopped", category=RuntimeWarning)
            for done in range(1, max_iterations + 1):
                before = world._state.x.copy()
                world._state.v[:] = 0.0
                world._forces[:] = forces
                world.step()
                x = world._state.x
                step_moves = np.abs(x - before).max(axis=1)
                moved, last = float(step_moves.max(initial=0.0)), moved
                moves.append(moved)
                body_moves.append(np.maximum.reduceat(step_moves, offsets[:-1]) if len(step_moves) else step_moves)
                centres.append(np.add.reduceat(x, offsets[:-1]) / np.diff(offsets)[:, None])
                # the steps shrink geometrically near the answer, by r each: what is left to go is
                # about moved r / (1 - r), more than the last step where r > 1/2 (soft modes)
                r = moved / last if last > 0.0 else 0.0
                remaining = 0.0 if moved == 0.0 else (moved * max(1.0, r / (1.0 - r)) if r < 1.0 else math.inf)
                elapsed = time.perf_counter() - started - watch.seconds
                if bar is not None:
                    bar.set_postfix_str(f"to go ~{remaining:.2g} m (tolerance {tol:g} m)", refresh=False)
                    bar.update(1)
                elif callable(progress):
                    progress(StaticProgress(done, moved, remaining, tol, elapsed, budget))
                if remaining <= tol:
                    settled = True
                    break
                _check_fallen(x, offsets, body_moves[-1], held, up, floor, math.hypot(*g), done)
                if len(moves) >= 2 * STALL_WINDOW:
                    _check_stalled(world, moves, body_moves, centres, held, tol, integrator, done)
                if elapsed > budget and done < max_iterations:
                    raise ValueError(f"solve_static did not settle within max_seconds = {budget:g} s ({done} "
                                     f"relaxation steps{_short(integrator, done)}; the last moved a vertex "
                                     f"{moved:.3g} m, tolerance {tol:g} m): raise max_seconds, or support the "
                                     f"bodies better")
        if not settled:
            raise ValueError(f"solve_static did not settle within max_iterations = {max_iterations} relaxation "
                             f"steps (the last moved a vertex {moved:.3g} m; tolerance {tol:g} m"
                             f"{_short(integrator, done)}): raise max_iterations, or support the bodies better")
    except BaseException:
        world._state.x[...] = x0  # the shapes are the same: the arrays are too
        world._state.v[...] = v0
        world._lost_shape = lost
        world._forces[:] = forces
        for b, asleep, still in dozing:
            b._asleep, b._still = asleep, still
        world._hold(bodies)
        raise
    finally:
        if bar is not None:
            bar.close()
        world._sleep = sleep
        (world._integrator, world._dt, world._substeps, world._auto, world.time, world.step_count) = borrowed
        for c, velocity, spin in motions:
            c.velocity, c.angular_velocity = velocity, spin
        world._packed_colliders = None  # their velocities changed twice: pack them again
    world._state.v[:] = 0.0
    world._forces.clear()
    return done


def _short(integrator, done: int) -> str:
    """``; the implicit solve stopped short of its tolerance in K of them``, or ``""``."""
    short = int(integrator.stats().get("unconverged", 0))
    if not short:
        return ""
    return (f"; the implicit solve stopped short of its tolerance in {short} of {done} (contacts it cannot "
            f"resolve at {RELAX_STEP:g} s steps)")


def _check_fallen(x, offsets, body_moves, held, up, floor, gravity: float, done: int) -> None:
    """Refuse a body that no pin or joint holds, wholly below every collider and still falling
    (it moved half a free fall's ``g h^2`` in the last step)."""
    if floor is None:
        return
    height = x @ up
    for b in np.flatnonzero(~held & (body_moves >= 0.5 * gravity * RELAX_STEP ** 2)):
        top = float(height[offsets[b]:offsets[b + 1]].max(initial=-math.inf))
        if top < floor:
            c = x[offsets[b]:offsets[b + 1]].mean(axis=0)
            raise ValueError(f"solve_static: body {b} fell past every collider at relaxation step {done} (now at "
                             f"({c[0]:.3g}, {c[1]:.3g}) m): it slid or rolled off its support, so it would fall for "
                             f"ever; support it (a wall, a wider floor, friction), or pin a vertex")


def _check_stalled(world, moves, body_moves, centres, held, tol: float, integrator, done: int) -> None:
    """Refuse a relaxation whose moves stopped shrinking (see the module docstring), naming the
    body that moves most and, from how its centre went, why."""
    w = STALL_WINDOW
    now, before = float(np.median(moves[-w:])), float(np.median(moves[-2 * w:-w]))
    if not now > STALL_RATIO * before:
        return
    per_body = np.median(np.asarray(body_moves), axis=0)
    b = int(np.argmax(per_body))
    path = np.asarray(centres)[:, b]
    net = path[-1] - path[0]
    travelled = float(np.hypot(*np.diff(path, axis=0).T).sum())
    distance = float(np.hypot(*net))
    head = f"solve_static stopped getting closer after {done} relaxation steps"
    if distance > 0.5 * travelled and distance > 10.0 * tol:
        d = net / distance
        went = (f"body {b} keeps moving one way (its centre went {distance:.3g} m along ({d[0]:.2f}, {d[1]:.2f}) in "
                f"the last {w} steps)")
        if not held[b] and _frictionless(world):
            raise ValueError(f"{head}: {went}: it slides freely, as the colliders are frictionless and no wall "
                             f"stops it that way; give them friction or static_friction, add a wall, or pin a "
                             f"vertex")
        raise ValueError(f"{head}: {went}: it slides or rolls (friction stops a slide, not a roll) and nothing "
                         f"stops it; add a wall or a flatter support, or pin a vertex")
    body = world.bodies[b]
    size = float(np.hypot(*np.ptp(body.positions, axis=0)))
    if now < 1e-3 * size:  # a hair's breadth: the solve's noise, not the bodies
        raise ValueError(f"{head}: the moves stay about {now:.3g} m a step (body {b} moves most, back and forth; "
                         f"tolerance {tol:g} m{_short(integrator, done)}): give a tolerance above {2 * now:.2g} m "
                         f"if that is close enough, or support the bodies better")
    gas = (" (its gas pushes as a kick from each relaxation step's start, outside the implicit solve)"
           if body.pressure else "")
    raise ValueError(f"{head}: body {b} jitters about {now:.3g} m a step, back and forth{gas}"
                     f"{_short(integrator, done)}: support it better (a wider, flatter support, friction, a pin), "
                     f"or step the world until it rests instead")

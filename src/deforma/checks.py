"""Checks at the boundary: every number a user gives is tested against the range in which
the formulas that read it mean something, and refused in one line that names the value and
the range.

The ranges (``LIMITS``, SI units) are wide - no realistic scene comes near them - but finite,
so that no product, square or sum downstream overflows, no step count runs away and every
hint stays true. ``docs/cli.md`` lists them.

Examples
--------
>>> positive(0.01, "dt", "s")
0.01
>>> positive(1e-300, "dt", "s")
Traceback (most recent call last):
...
ValueError: dt must be in [1e-06, 0.1] s, got 1e-300
"""

from __future__ import annotations

import math
import sys

import numpy as np

#: name -> (smallest, largest) allowed value; names not listed are only checked for sign.
LIMITS = {
    "dt": (1e-6, 0.1),                  # s: below, a second of simulation is 1e6 steps
    "mass": (1e-9, 1e9),                # kg
    "stiffness": (0.0, 1e12),           # N/m
    "damping": (0.0, 1e9),              # N*s/m
    "friction": (0.0, 100.0),           # Coulomb coefficients
    "static_friction": (0.0, 100.0),
    "grab_strength": (1e-9, 1e12),      # N/m per vertex
    "strength": (1e-9, 1e12),           # a grab's strength, N/m
    "radius": (1e-9, 1e6),              # m
    "air_drag": (0.0, 1e4),             # 1/s
    "contact_thickness": (1e-9, 1e3),   # m
    "pressure": (0.0, 1e12),            # N/m
    "max_speed": (1e-9, 1e100),         # m/s (inf allowed: no speed check)
    "scale": (1e-9, 1e3),               # m per pixel of a picture (its side is capped in pixels)
}
#: Largest coordinate or size of anything placed in a world (m), and of gravity (m/s^2).
MAX_COORDINATE = 1e9
MAX_GRAVITY = 1e7
#: Largest component of a force (N) or impulse (N s) applied to a body (body.apply_force).
MAX_LOAD = 1e12
#: Largest number of substeps in one step: a step must stay short enough to interrupt.
MAX_SUBSTEPS = 1000
#: Smallest substep (s): dt / substeps below this is refused.
MIN_SUBSTEP = 1e-7
#: Most points one body's mesh may have: ``mesh.box``, ``mesh.from_image``, scene files,
#: ``deforma run`` and ``deforma mesh`` refuse more, counted before any triangulation (a box's
#: from its detail, a picture's from its foreground pixels per resolution**2 and its outline).
#: Measured on the project's 2-core machine (shared), a box resting on a floor under avbd at the
#: default dt = 1/60 s, kernels compiled; meshing, then a step:
#:   2e4 points  0.3 s, 0.2-0.3 s       5e4  0.9 s, 0.5-0.8 s      1e5  1.6 s, 1.5-1.7 s
#:   2.5e5       4.9 s, 4-6 s           5e5  7.2 s, 9-14 s         1e6  27 s,  29 s
#: (a picture's 1.1e5 points: 4.4 s to mesh, 0.7-1.1 s a step). A step costs about linear time
#: in the points, so 1e5 is where a scene's default 5 s (300 steps) still runs in minutes
#: (about 8) and meshing in seconds (no progress bar needed); a million took over two hours for
#: those 5 s and 29 s before the first frame, with nothing shown. The built-in scenes' bodies
#: have at most 1346 points; 1e5 is far beyond what a step at 60 Hz carries.
MAX_BODY_POINTS = 100_000
#: Largest box ``detail`` whose points can fit in MAX_BODY_POINTS: detail**2 + 4 points without
#: edges (316); with edges (the default) the box has (detail + 2)**2 points, so 314.
MAX_DETAIL = math.isqrt(MAX_BODY_POINTS - 4)


def number(value, name: str) -> float:
    """``value`` as a finite float, or one ValueError line."""
    if isinstance(value, (bool, np.bool_)) or isinstance(value, complex):
        raise ValueError(f"{name} must be a real number, got {value!r}")
    try:
        v = float(value)
    except OverflowError:  # a number beyond any float: an integer like 10**400, or a Fraction of one
        got = f"an integer of {digit_count(value)} digits" if isinstance(value, int) else "a number"
        raise ValueError(f"{name} must be finite, got {got}, too large for a float") from None
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v


def digit_count(value: int) -> str:
    """How many digits ``value`` has, said without str() failing on one past Python's limit."""
    try:
        return str(len(str(abs(value))))
    except ValueError:  # beyond sys.get_int_max_str_digits() (4300 by default): str() refuses it
        return f"more than {sys.get_int_max_str_digits()}"


def check_option_numbers(options, integrator) -> None:
    """Refuse, in one line naming the option and what it takes, an integer in ``options`` (a
    mapping of an integrator's option names to values) too long to be shown or to become a
    float: ``float(10**400)`` overflows, and a message would print every digit. Other values
    are the integrator's own check (:meth:`~deforma.physics.integrators.base.Option.check`).

    Examples
    --------
    >>> from deforma.physics.integrators import make_integrator
    >>> check_option_numbers({"tolerance": 10**400}, make_integrator("avbd"))
    Traceback (most recent call last):
    ...
    ValueError: avbd option tolerance must be a number in [0, inf), got an integer of 401 digits
    """
    if not hasattr(options, "items"):
        return  # the integrator says what a table of options is
    known = {o.name: o for o in type(integrator).OPTIONS}
    for key, value in options.items():
        if key in known and isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**40:
            raise ValueError(f"{integrator.name} option {key} must be {known[key].allowed()}, got an integer of "
                             f"{digit_count(value)} digits")


def _limited(v: float, value, name: str, unit: str, lo: float, lo_open: bool) -> float:
    if v < lo or (lo_open and v == lo):  # the sign first: the usual mistake, said as before
        raise ValueError(f"{name} must be {'>' if lo_open else '>='} {lo:g} {unit}, got {value!r}")
    low, high = LIMITS.get(name, (lo, math.inf))
    if v < low or v > high:
        raise ValueError(f"{name} must be in [{low:g}, {high:g}] {unit}, got {value!r}")
    return v


def positive(value, name: str, unit: str) -> float:
    """A finite number > 0 within ``LIMITS[name]`` (when listed)."""
    return _limited(number(value, name), value, name, unit, 0.0, True)


def non_negative(value, name: str, unit: str) -> float:
    """A finite number >= 0 within ``LIMITS[name]`` (when listed)."""
    return _limited(number(value, name), value, name, unit, 0.0, False)


def pair(value, name: str, *, positive: bool = False, limit: float = MAX_COORDINATE) -> tuple[float, float]:
    """A pair of finite numbers of magnitude at most ``limit`` (both > 0 with ``positive``)."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except OverflowError:  # an integer beyond any float (10**400)
        raise ValueError(f"{name} must be a pair of finite numbers, got a number too large for a float") from None
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a pair of numbers, got {value!r}") from None
    if a.shape != (2,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be a pair of finite numbers, got {value!r}")
    if positive and np.any(a <= 0):
        raise ValueError(f"{name} must be positive in both directions, got {value!r}")
    if np.any(np.abs(a) > limit):
        raise ValueError(f"{name} must lie within +-{limit:g}, got {value!r}")
    return float(a[0]), float(a[1])


def box_point_count(detail: int, edges: bool) -> int:
    """How many points ``mesh.box(corners, detail=detail, edges=edges)`` has, before it is built.

    >>> box_point_count(8, True), box_point_count(8, False), box_point_count(0, True)
    (100, 68, 4)
    """
    return (detail + 2) ** 2 if edges and detail > 0 else detail * detail + 4


def check_box_points(detail: int, edges: bool, name: str = "detail") -> None:
    """Refuse, in one line, a box whose points would pass ``MAX_BODY_POINTS``; ``name`` is how
    the caller spells the option (``"detail"``, ``"--detail"``).

    >>> check_box_points(1000, True)
    Traceback (most recent call last):
    ...
    ValueError: detail=1000 gives a box of 1004004 points (with edges), more than the 100000 one body may have (MAX_BODY_POINTS): give detail=314 or less
    """
    count = box_point_count(detail, edges)
    if count <= MAX_BODY_POINTS:
        return
    fit = math.isqrt(MAX_BODY_POINTS) - 2 if edges else MAX_DETAIL
    if detail > 10**9:  # and str() of an integer past 4300 digits would fail
        raise ValueError(f"{name} must be at most {fit}: a body may have {MAX_BODY_POINTS} points (MAX_BODY_POINTS), "
                         f"got an integer of {digit_count(detail)} digits")
    raise ValueError(f"{name}={detail} gives a box of {count} points"
                     f"{' (with edges)' if edges else ''}, more than the {MAX_BODY_POINTS} one body may have "
                     f"(MAX_BODY_POINTS): give {name}={fit} or less")


def switch(value, name: str) -> bool:
    """``True`` or ``False`` (numpy's too), nothing else."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def coefficient(value, name: str):
    """A friction coefficient override: ``None``, or a number in ``LIMITS[name]``."""
    if value is None:
        return None
    return non_negative(value, name, "(dimensionless)")


class IgnoredSettingWarning(UserWarning):
    """A world parameter set that some bodies do not read: ``world.stiffness`` (``mass``,
    ``damping``) on bodies made of finite elements, whose stiffness is their material's. Said
    once per world and parameter, naming the bodies and their model."""


class StepBeyondStableWarning(RuntimeWarning):
    """``World.add_body`` under an explicit integrator: the world's step is beyond the stable
    estimate with the new body, so a step will likely blow up (the message says what to set).
    Here, with the other checks at the boundary, so that the command line can filter it
    without importing the physics."""


class CallbackWarning(RuntimeWarning):
    """A listener registered with ``world.on_contact`` or ``world.on_joint_break`` raised: said
    once per listener, with its name and error; the step it was called after stands."""

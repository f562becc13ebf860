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
#: Largest box ``detail`` (mesh.box, scene files, ``deforma mesh --detail``): (detail + 2)**2
#: points, about a million, is as far as a mass-spring body is still useful and stays well
#: inside memory.
MAX_DETAIL = 1000


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

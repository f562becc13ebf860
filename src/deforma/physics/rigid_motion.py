"""A set of vertices seen as one moving thing: its centre of mass, velocity, spin and angle.

Pure functions over arrays (positions ``x`` (N, 2) in m, velocities ``v`` (N, 2) in m/s,
masses ``m`` (N,) in kg). A soft body's ``velocity``, ``angular_velocity`` and ``angle``
are these of its vertices; a rigid body's vertices move exactly so. Angles here are
radians and angular velocities rad/s (the API converts to degrees).
"""

from __future__ import annotations

import math

import numpy as np


def center_of_mass(x: np.ndarray, m: np.ndarray) -> np.ndarray:
    """(2,) the mass-weighted mean of ``x`` (m).

    Examples
    --------
    >>> import numpy as np
    >>> center_of_mass(np.array([[0.0, 0.0], [3.0, 0.0]]), np.array([2.0, 1.0])).tolist()
    [1.0, 0.0]
    """
    return (m @ x) / m.sum()


def linear_and_angular_velocity(x: np.ndarray, v: np.ndarray, m: np.ndarray) -> tuple[np.ndarray, float]:
    """The velocity of the centre of mass (m/s) and the spin about it (rad/s, counter-clockwise).

    The spin is the angular momentum about the centre of mass over the moment of inertia of
    the vertices there, ``sum m (r x v) / sum m |r|^2``: exact for a rigid motion, and for a
    deforming body the rotation that carries its angular momentum (0 for a single point).

    Examples
    --------
    A rod of two equal masses turning at 2 rad/s about its middle, which moves at (1, 0):

    >>> import numpy as np
    >>> x = np.array([[-1.0, 0.0], [1.0, 0.0]])
    >>> v = np.array([[1.0, -2.0], [1.0, 2.0]])
    >>> vel, omega = linear_and_angular_velocity(x, v, np.ones(2))
    >>> vel.tolist(), omega
    ([1.0, 0.0], 2.0)
    """
    total = m.sum()
    c = (m @ x) / total
    vel = (m @ v) / total
    r = x - c
    u = v - vel
    inertia = float(m @ (r * r).sum(axis=1))
    if inertia <= 0.0:
        return vel, 0.0
    momentum = float(m @ (r[:, 0] * u[:, 1] - r[:, 1] * u[:, 0]))
    return vel, momentum / inertia


def rigid_velocities(x: np.ndarray, m: np.ndarray, velocity, omega: float) -> np.ndarray:
    """(N, 2) the velocities of ``x`` moving rigidly: ``velocity`` at the centre of mass and a
    spin ``omega`` (rad/s) about it, ``velocity + omega x (x - c)``.

    Examples
    --------
    >>> import numpy as np
    >>> rigid_velocities(np.array([[-1.0, 0.0], [1.0, 0.0]]), np.ones(2), (1.0, 0.0), 2.0).tolist()
    [[1.0, -2.0], [1.0, 2.0]]
    """
    r = x - center_of_mass(x, m)
    out = np.empty_like(x)
    out[:, 0] = velocity[0] - omega * r[:, 1]
    out[:, 1] = velocity[1] + omega * r[:, 0]
    return out


def fit_angle(rest: np.ndarray, x: np.ndarray, m: np.ndarray) -> float:
    """The rotation (rad, in (-pi, pi]) of the rigid motion that carries ``rest`` closest to
    ``x`` in the mass-weighted least-squares sense (the rotation of the polar decomposition
    of the 2D shape-matching matrix).

    Examples
    --------
    >>> import numpy as np
    >>> rest = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    >>> c, s = np.cos(0.3), np.sin(0.3)
    >>> x = rest @ np.array([[c, s], [-s, c]]) + [5.0, 2.0]
    >>> round(fit_angle(rest, x, np.ones(3)), 12)
    0.3
    """
    r0 = rest - center_of_mass(rest, m)
    r = x - center_of_mass(x, m)
    dot = float(m @ (r0 * r).sum(axis=1))
    cross = float(m @ (r0[:, 0] * r[:, 1] - r0[:, 1] * r[:, 0]))
    return math.atan2(cross, dot)


def rotate(x: np.ndarray, angle: float, about) -> np.ndarray:
    """``x`` turned by ``angle`` rad counter-clockwise about the point ``about``.

    Examples
    --------
    >>> import numpy as np
    >>> rotate(np.array([[1.0, 0.0]]), np.pi / 2, (0.0, 0.0)).round(12).tolist()
    [[0.0, 1.0]]
    """
    c, s = math.cos(angle), math.sin(angle)
    d = x - np.asarray(about, dtype=np.float64)
    out = np.empty_like(x)
    out[:, 0] = about[0] + c * d[:, 0] - s * d[:, 1]
    out[:, 1] = about[1] + s * d[:, 0] + c * d[:, 1]
    return out

"""The one Coulomb friction rule that every contact uses (colliders, other bodies, self).

A contact removes an inward relative normal velocity ``vn < 0`` in one substep; ``jn = -vn``
is then the normal impulse per unit (effective) mass of that substep, ``h N / m``. Friction
acts on the relative tangential velocity ``vt`` with the same effective mass, so the test is
the same for a vertex on a collider (the other side has infinite mass) and for a vertex on
another body's edge:

- **stick**: if ``|vt| <= static_friction * jn`` the tangential velocity is cancelled;
- **slip**: otherwise ``friction * jn`` is taken off ``|vt|``, never reversing it.

Two bodies' coefficients combine as their geometric mean, ``sqrt(mu_a * mu_b)`` (Box2D's
``b2MixFriction``): a frictionless body is frictionless against anything, and a body meets
itself with its own coefficient. A collider's coefficients describe its surface against any
body (the original inspector's Physics Settings), so collider contacts use them unmixed.

Units: m/s.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, inline="always")
def coulomb(vt, jn, static_friction, friction):
    """Tangential relative velocity (m/s) after friction, given the normal impulse ``jn`` (m/s).

    Parameters
    ----------
    vt : float
        Relative tangential velocity before friction (m/s, signed).
    jn : float
        Inward normal velocity removed this substep (m/s, >= 0).
    static_friction, friction : float
        Coulomb coefficients (dimensionless, >= 0).

    Examples
    --------
    >>> coulomb(0.4, 1.0, 0.5, 0.3)  # within the static cone: sticks
    0.0
    >>> round(coulomb(0.8, 1.0, 0.5, 0.3), 12)  # slips, slowed by 0.3 * 1.0
    0.5
    """
    if jn <= 0.0:
        return vt
    if abs(vt) <= static_friction * jn:
        return 0.0
    slow = friction * jn
    if abs(vt) <= slow:
        return 0.0
    return vt - slow if vt > 0.0 else vt + slow


@njit(cache=True, inline="always")
def mix(a, b):
    """Coefficient of a contact between two bodies with coefficients ``a`` and ``b``.

    Examples
    --------
    >>> mix(0.5, 0.5), mix(0.0, 1.0), round(mix(0.2, 0.8), 6)
    (0.5, 0.0, 0.4)
    """
    return math.sqrt(a * b)

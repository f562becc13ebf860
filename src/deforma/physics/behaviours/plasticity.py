"""Plasticity: strain beyond the yield point moves the rest shape, so dents stay.

A material with ``yield_strain = y`` (``deforma.Material(..., yield_strain=0.05,
plastic_rate=1.0)``) is elastic while every stretch stays within ``[1 - y, 1 + y]`` of its
rest shape. After each step, whatever lies beyond becomes permanent (at the share
``plastic_rate`` of it per step; 1 is perfectly plastic):

* a spring of length ``L`` outside ``[(1 - y) r, (1 + y) r]`` gets the rest length ``r``
  that puts it on the nearer bound;
* a triangle's principal stretches ``s_i`` (:mod:`deforma.physics.behaviours.strain`) outside the
  bounds are split ``F = F_e F_p`` into an elastic part on the bound and a plastic part
  ``F_p = V diag(p) V^T`` (``p_i = s_i / clamp(s_i)``, ``V`` the principal directions in the
  rest shape); the rest shape becomes ``F_p`` applied to the old one: ``B <- B F_p^-1``,
  rest area ``<- area p_1 p_2``. The mass does not change (it is kept per vertex).

The rest shape never degenerates: relative to the original, no rest length or principal
rest stretch may leave ``[1 / limit, limit]`` (``REST_LIMIT`` = 4); an update that would is
not made (the material hardens there and stays elastic). An inverted triangle does not
flow (its stretch has no meaning to make permanent); the elastic forces push it back out.
"""

from __future__ import annotations

import math

from numba import njit

from ..elements.triangles import corners, deformation_gradient
from .strain import principal_stretches

REST_LIMIT = 4.0


@njit(cache=True)
def yield_springs(x, spring_i, spring_j, rest, rest0, yield_strain, rate):
    """Move the rest lengths of springs stretched or squashed beyond ``yield_strain``.

    Returns how many changed.

    Examples
    --------
    >>> import numpy as np
    >>> rest = np.ones(1)
    >>> yield_springs(np.array([[0.0, 0.0], [1.5, 0.0]]), np.array([0]), np.array([1]), rest, np.ones(1), 0.1,
    ...               1.0)
    1
    >>> round(float(rest[0]), 6)  # 1.5 is now 10% beyond the new rest length
    1.363636
    """
    changed = 0
    for e in range(spring_i.shape[0]):
        i, j = spring_i[e], spring_j[e]
        dx = x[j, 0] - x[i, 0]
        dy = x[j, 1] - x[i, 1]
        length = (dx * dx + dy * dy) ** 0.5
        r = rest[e]
        if length > (1.0 + yield_strain) * r:
            target = length / (1.0 + yield_strain)
        elif yield_strain < 1.0 and length < (1.0 - yield_strain) * r:
            target = length / (1.0 - yield_strain)
        else:
            continue
        new = r * (target / r) ** rate
        if not (rest0[e] / REST_LIMIT <= new <= REST_LIMIT * rest0[e]):
            continue
        rest[e] = new
        changed += 1
    return changed


@njit(cache=True)
def yield_elements(x, elem, b, area, b0, area0, yield_strain, rate):
    """Move the rest shapes (``b``, ``area``, in place) of triangles strained beyond yield.

    ``b0`` / ``area0`` are the original rest shapes (the bound's reference). Returns how many
    changed.

    Examples
    --------
    >>> import numpy as np
    >>> from deforma.physics.elements.triangles import rest_geometry
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    >>> bb, a = rest_geometry(x, [[0, 1, 2]])
    >>> x[1, 0] = 1.5  # 50% longer along x; yield at 10%
    >>> yield_elements(x, np.array([[0, 1, 2]], np.int32), bb, a, bb.copy(), a.copy(), 0.1, 1.0)
    1
    >>> round(1.0 / float(bb[0, 0]), 6), round(float(a[0]), 6)  # rest edge 1.5 / 1.1; area grew as much
    (1.363636, 0.681818)
    """
    lo = max(1.0 - yield_strain, 1e-3)
    hi = 1.0 + yield_strain
    changed = 0
    for e in range(elem.shape[0]):
        i, j, k, b00, b01, b10, b11 = corners(elem, b, e)
        f00, f01, f10, f11 = deformation_gradient(x, i, j, k, b00, b01, b10, b11)
        s1, s2, vx, vy, _, _ = principal_stretches(f00, f01, f10, f11)
        if s2 <= 0.0 or (lo <= s2 and s1 <= hi):
            continue  # inverted (no flow) or elastic
        p1 = (s1 / min(max(s1, lo), hi)) ** rate
        p2 = (s2 / min(max(s2, lo), hi)) ** rate
        # F_p^-1 = V diag(1/p) V^T with V = [v, perp v]
        q1 = 1.0 / p1
        q2 = 1.0 / p2
        m00 = q1 * vx * vx + q2 * vy * vy
        m01 = (q1 - q2) * vx * vy
        m11 = q1 * vy * vy + q2 * vx * vx
        n00 = b00 * m00 + b01 * m01  # B F_p^-1
        n01 = b00 * m01 + b01 * m11
        n10 = b10 * m00 + b11 * m01
        n11 = b10 * m01 + b11 * m11
        # the accumulated plastic deformation B0 B'^-1... its stretches must stay within the limit:
        # G = (B')^-1 B0 maps the original rest shape to the new one
        det = n00 * n11 - n01 * n10
        if not (det > 0.0 and det < math.inf):
            # a triangle pressed flat (its smallest stretch ~1e-17): its flow is singular to
            # rounding and would make the rest shape so; no flow (the shape checks report a
            # body that stays flattened)
            continue
        g00 = (n11 * b0[e, 0] - n01 * b0[e, 2]) / det
        g01 = (n11 * b0[e, 1] - n01 * b0[e, 3]) / det
        g10 = (-n10 * b0[e, 0] + n00 * b0[e, 2]) / det
        g11 = (-n10 * b0[e, 1] + n00 * b0[e, 3]) / det
        t1, t2, _, _, _, _ = principal_stretches(g00, g01, g10, g11)
        if not (1.0 / REST_LIMIT <= t2 and t1 <= REST_LIMIT):
            continue
        b[e, 0], b[e, 1], b[e, 2], b[e, 3] = n00, n01, n10, n11
        area[e] = area[e] * p1 * p2
        changed += 1
    return changed

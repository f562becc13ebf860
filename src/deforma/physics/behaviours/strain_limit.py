"""Strain limiting: no spring or triangle ends a step stretched beyond ``max_stretch``.

A material with ``max_stretch = s`` (``deforma.Material(..., max_stretch=1.05)``) is
projected after every step (any integrator): each spring longer than ``s`` times its rest
length, and each triangle with a principal stretch (:mod:`deforma.physics.behaviours.strain`) above
``s``, is shortened to exactly ``s`` by moving its vertices along the constraint's gradient
weighted by their inverse masses (Provot 1995 for springs; the stretch of an element is
limited in its principal directions, as in Thomaszewski et al. 2009). Sweeps repeat, in
Gauss-Seidel order, until no constraint exceeds its limit by more than ``tolerance`` (1e-4
of strain) or ``max_sweeps`` ran out.

No energy is injected. A correction moves a constraint's vertices with zero mass-weighted
sum (the centre of mass, hence gravity's energy, stays), shortens an over-stretched spring
or element (lowering its elastic energy), and the velocity that kept stretching it is
removed by an inelastic impulse along the same gradient (momentum kept, kinetic energy
lowered): a body pulled hard becomes inextensible in that direction, as a cloth's yarn.
Pinned vertices (inverse mass 0) do not move.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..elements.triangles import (
    corners,
    deformation_gradient,
    vertex_gradients,
    weighted_dot,
)
from .strain import principal_stretches

#: A constraint within this (strain) of its limit is active: the velocity that stretches it
#: further is removed even when its position needs no correction.
ACTIVE = 1e-3


@njit(cache=True)
def limit_springs(x, v, inv_mass, spring_i, spring_j, rest, max_stretch, tolerance, max_sweeps, move=True,
                  stop=True):
    """Shorten springs longer than ``max_stretch * rest`` (``move``) and remove the velocity
    that stretches a spring at its limit further (``stop``), in place on ``x``, ``v``.

    Returns the number of sweeps run, the largest excess strain left (0 when none) and how
    many springs the first sweep found active (within ``ACTIVE`` of their limit or beyond).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [2.0, 0.0]]); v = np.array([[0.0, 0.0], [1.0, 0.0]])
    >>> limit_springs(x, v, np.ones(2), np.array([0], np.int32), np.array([1], np.int32), np.ones(1), 1.1,
    ...               1e-4, 50)
    (2, 0.0, 1)
    >>> x[:, 0].round(12).tolist(), v[:, 0].tolist()  # 1.1 long, centred; no more separating speed
    ([0.45, 1.55], [0.5, 0.5])
    """
    worst = 0.0
    sweeps = 0
    active = 0
    for sweeps in range(1, max_sweeps + 1):
        worst = 0.0
        m = spring_i.shape[0]
        for n in range(m):
            e = n if sweeps % 2 == 1 else m - 1 - n  # alternating, as for the elements below
            i, j = spring_i[e], spring_j[e]
            wi, wj = inv_mass[i], inv_mass[j]
            w = wi + wj
            dx = x[j, 0] - x[i, 0]
            dy = x[j, 1] - x[i, 1]
            length = (dx * dx + dy * dy) ** 0.5
            c = length - max_stretch * rest[e]
            if c <= -ACTIVE * rest[e] or w == 0.0:
                continue
            if sweeps == 1:
                active += 1
            nx = dx / length
            ny = dy / length
            if move and c > 0.0:
                excess = c / rest[e]
                if excess > worst:
                    worst = excess
                x[i, 0] += wi / w * c * nx
                x[i, 1] += wi / w * c * ny
                x[j, 0] -= wj / w * c * nx
                x[j, 1] -= wj / w * c * ny
            rate = (v[j, 0] - v[i, 0]) * nx + (v[j, 1] - v[i, 1]) * ny
            if stop and rate > 0.0:  # still stretching it: an inelastic impulse along the spring stops that
                v[i, 0] += wi / w * rate * nx
                v[i, 1] += wi / w * rate * ny
                v[j, 0] -= wj / w * rate * nx
                v[j, 1] -= wj / w * rate * ny
        if worst <= tolerance:
            break
    return sweeps, worst if worst > tolerance else 0.0, active


@njit(cache=True, inline="always")
def _along(a, i, j, k, wi, wj, wk, g, step):
    """``a += step * W g`` over a triangle's three vertices (``g`` their 6 gradient entries)."""
    a[i, 0] += wi * g[0] * step
    a[i, 1] += wi * g[1] * step
    a[j, 0] += wj * g[2] * step
    a[j, 1] += wj * g[3] * step
    a[k, 0] += wk * g[4] * step
    a[k, 1] += wk * g[5] * step


@njit(cache=True)
def limit_elements(x, v, inv_mass, elem, b, max_stretch, tolerance, max_sweeps, move=True, stop=True):
    """Bring every principal stretch of the triangles ``elem`` down to ``max_stretch``
    (``move``) and remove the velocity that stretches one at its limit further (``stop``).

    ``C = s_i - max_stretch`` for each principal stretch above the limit, gradient ``R v_i
    v_i^T`` in ``F`` (:mod:`deforma.physics.behaviours.strain`). Returns the sweeps run, the largest
    excess stretch left (0 when none) and how many constraints the first sweep found active.

    Examples
    --------
    >>> import numpy as np
    >>> from deforma.physics.elements.triangles import rest_geometry
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    >>> bb, _ = rest_geometry(x, [[0, 1, 2]])
    >>> x[1, 0] = 2.0  # twice as long along x
    >>> limit_elements(x, np.zeros((3, 2)), np.ones(3), np.array([[0, 1, 2]], np.int32), bb, 1.2, 1e-4, 50)[1]
    0.0
    >>> from deforma.physics.behaviours.strain import stretch_field
    >>> bool(stretch_field(x, [[0, 1, 2]], bb)[0].max() <= 1.2 + 1e-4)
    True
    """
    worst = 0.0
    sweeps = 0
    active = 0
    for sweeps in range(1, max_sweeps + 1):
        worst = 0.0
        m = elem.shape[0]
        for n in range(m):
            # sweeps alternate direction: a correction then travels the length of the body in
            # one sweep either way (a chain pulled at one end converged ~10x faster)
            e = n if sweeps % 2 == 1 else m - 1 - n
            i, j, k, b0, b1, b2, b3 = corners(elem, b, e)
            wi, wj, wk = inv_mass[i], inv_mass[j], inv_mass[k]
            for which in range(2):
                f00, f01, f10, f11 = deformation_gradient(x, i, j, k, b0, b1, b2, b3)
                s1, s2, v1x, v1y, c, s = principal_stretches(f00, f01, f10, f11)
                if which == 0:
                    cons = s1 - max_stretch
                    vx, vy = v1x, v1y
                else:
                    cons = s2 - max_stretch
                    vx, vy = -v1y, v1x
                if cons <= -ACTIVE:
                    continue
                ux = c * vx - s * vy  # u = R v, gradient u v^T
                uy = s * vx + c * vy
                g = vertex_gradients(ux * vx, ux * vy, uy * vx, uy * vy, b0, b1, b2, b3)
                norm = weighted_dot(wi, wj, wk, g, g)
                if norm == 0.0:
                    continue
                if sweeps == 1:
                    active += 1
                if move and cons > 0.0:
                    if cons > worst:
                        worst = cons
                    _along(x, i, j, k, wi, wj, wk, g, -cons / norm)
                rate = g[0] * v[i, 0] + g[1] * v[i, 1] + g[2] * v[j, 0] + g[3] * v[j, 1] + g[4] * v[k, 0] \
                    + g[5] * v[k, 1]
                if stop and rate > 0.0:  # still stretching: remove that velocity (an inelastic impulse)
                    _along(v, i, j, k, wi, wj, wk, g, -rate / norm)
        if worst <= tolerance:
            break
    return sweeps, worst if worst > tolerance else 0.0, active


def attachments(rest, edges, pinned):
    """Long-range attachments of a body with pinned vertices: for every vertex, the nearest
    pinned vertex along the mesh's edges and that path's rest length (``inf`` and -1 where
    none is reachable); NumPy/SciPy.

    Examples
    --------
    >>> import numpy as np
    >>> rest = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    >>> anchor, reach = attachments(rest, np.array([[0, 1], [1, 2]]), np.array([True, False, False]))
    >>> anchor.tolist(), reach.tolist()
    ([0, 0, 0], [0.0, 1.0, 2.0])
    """
    import scipy.sparse as sp
    from scipy.sparse.csgraph import dijkstra

    rest = np.asarray(rest, dtype=np.float64)
    e = np.asarray(edges).reshape(-1, 2)
    n = len(rest)
    pins = np.flatnonzero(pinned)
    if not len(pins):
        return np.full(n, -1, np.int64), np.full(n, np.inf)
    length = np.linalg.norm(rest[e[:, 1]] - rest[e[:, 0]], axis=1)
    g = sp.coo_matrix((length, (e[:, 0], e[:, 1])), shape=(n, n)).tocsr()
    reach, _, source = dijkstra(g, directed=False, indices=pins, min_only=True, return_predecessors=True)
    return np.where(np.isfinite(reach), source, -1).astype(np.int64), reach


@njit(cache=True)
def limit_attachments(x, anchor, reach, max_stretch):
    """Pull every vertex back within ``max_stretch`` times its path length of its pinned
    anchor (Kim, Chentanez and Mueller 2012, "Long range attachments"): the stretch of a
    whole chain of constraints undone in one pass, as no path can be longer than its edges
    allow. Returns how many moved."""
    moved = 0
    for i in range(x.shape[0]):
        a = anchor[i]
        if a < 0 or a == i:
            continue
        dx = x[i, 0] - x[a, 0]
        dy = x[i, 1] - x[a, 1]
        d = (dx * dx + dy * dy) ** 0.5
        far = max_stretch * reach[i]
        if d > far:
            x[i, 0] = x[a, 0] + dx * far / d
            x[i, 1] = x[a, 1] + dy * far / d
            moved += 1
    return moved


def project_stretch(x, v, x_start, inv_mass, spring_i, spring_j, rest, elem, b, max_stretch, dt, *, anchors=None,
                    tolerance=1e-4, sweeps=200):
    """Bring every spring and element of one body within ``max_stretch`` (in place).

    Gauss-Seidel sweeps (:func:`limit_springs`, :func:`limit_elements`) move a correction
    one constraint at a time, so a long body pulled at one end needs sweeps in proportion to
    the square of its length (1000 sweeps for a 20-element strip let go 30% stretched).
    Where the body has pinned vertices, the long-range attachments
    (:func:`limit_attachments`, ``anchors = (anchor, reach)`` from :func:`attachments`)
    first undo the stretch of every path from a pin at once; the sweeps then start close to
    the answer. The sweeps also remove, constraint by constraint, the velocity that still
    stretches an active one (inelastic impulses: kinetic energy can only fall).

    The velocity that made the overshoot goes with it: a vertex's velocity changes by its
    correction over the step ``dt`` (s), as in position-based dynamics, so that a body held
    taut by its limit does not keep the speed the step gave it (which the next step would
    turn into a larger overshoot); but only as far as the correction takes back the step's
    own motion from ``x_start``, so that a body that starts a step beyond its limit (set so,
    or given the limit live) is put back without being thrown.

    Returns the largest excess left (0 within ``tolerance``).
    """
    before = x.copy()
    moved = 0
    if anchors is not None:
        moved = limit_attachments(x, anchors[0], anchors[1], max_stretch)
    worst = 0.0
    for stage in range(2):  # positions, then (after the velocity update) what still stretches
        move, stop = stage == 0, stage == 1
        active = 0
        if len(spring_i):
            _, r, n = limit_springs(x, v, inv_mass, spring_i, spring_j, rest, max_stretch, tolerance,
                                    sweeps if move else 4, move, stop)
            worst, active = max(worst, r if move else 0.0), active + n
        if len(elem):
            _, r, n = limit_elements(x, v, inv_mass, elem, b, max_stretch, tolerance, sweeps if move else 4, move,
                                     stop)
            worst, active = max(worst, r if move else 0.0), active + n
        if move and not active and not moved:
            # nothing within ACTIVE of its limit and nothing moved: the velocity update and the
            # stop stage would change nothing (the common step, a third of the check's cost)
            return 0.0
        if move:
            c = x - before
            size = np.linalg.norm(c, axis=1)
            unit = c / np.where(size > 0, size, 1.0)[:, None]
            undone = np.clip(-np.einsum("ij,ij->i", before - x_start, unit), 0.0, size)
            v += unit * (undone / dt)[:, None]
    return worst

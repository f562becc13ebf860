"""Contact pairs and their events: which bodies touch which bodies and colliders, and how hard.

An integrator that holds its contacts as rows of its solve (avbd) knows each row's force: its
multiplier at the end of the sweeps. It hands the last step's rows over as
:class:`ContactImpulses`, one row per contact row and substep, in world vertex indices:

- a vertex pushed by a collider (``collider >= 0``, ``edge == -1``),
- a vertex pushed by an outline edge of a body (``edge >= 0``, ``collider == -1``; the edge
  takes the opposite force, shared by its ends),
- an outline edge pushed by a collider's corner (``vertex == -1``, ``edge >= 0``,
  ``collider >= 0``).

``normal`` is the unit direction of the normal force on the pushed side (out of the other
side), ``normal_impulse`` its size over the row's substep (N s, >= 0) and
``friction_impulse`` the friction's, signed along the tangent ``(-n_y, n_x)``.

:func:`group_pairs` sums the rows by pair of body and body or collider (a body's contacts
with itself are left out) into :class:`ContactPair`; a pair *touches* while the summed normal
impulse of its rows is positive (rows the solve held open have none).
:func:`contact_events` compares the pairs touching after two steps.

Units: m, N s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class ContactImpulses:
    """A step's contact rows and their impulses, struct of arrays (see the module docstring).

    Attributes
    ----------
    vertex : (K,) int64
        The pushed vertex (world index), or -1 where the pushed side is ``edge``.
    edge : (K, 2) int64
        The outline edge's two vertices, or -1 for a vertex against a collider.
    collider : (K,) int64
        Index into ``world.colliders``, or -1 for a vertex against an edge.
    point : (K, 2) float64
        Where the row acts at the end of its substep (m): the vertex, or the collider's corner.
    normal : (K, 2) float64
        Unit direction of the normal force on the pushed side.
    normal_impulse, friction_impulse : (K,) float64
        N s over the row's substep; friction along ``(-normal_y, normal_x)``. NaN where the
        integrator does not measure them.
    """

    vertex: np.ndarray
    edge: np.ndarray
    collider: np.ndarray
    point: np.ndarray
    normal: np.ndarray
    normal_impulse: np.ndarray
    friction_impulse: np.ndarray

    def __len__(self) -> int:
        return len(self.collider)

    @staticmethod
    def empty() -> "ContactImpulses":
        """No rows."""
        z = np.zeros(0)
        return ContactImpulses(np.zeros(0, np.int64), np.zeros((0, 2), np.int64), np.zeros(0, np.int64),
                               np.zeros((0, 2)), np.zeros((0, 2)), z, z)

    @staticmethod
    def concatenate(parts) -> "ContactImpulses":
        """One record of the rows of several (a step's substeps, in order)."""
        parts = list(parts)
        if not parts:
            return ContactImpulses.empty()
        if len(parts) == 1:
            return parts[0]
        return ContactImpulses(*(np.concatenate([getattr(p, f) for p in parts])
                                 for f in ("vertex", "edge", "collider", "point", "normal", "normal_impulse",
                                           "friction_impulse")))


def impulses_from_points(points, x) -> tuple[ContactImpulses, np.ndarray]:
    """The rows of a :class:`~deforma.physics.contact.contacts.ContactPoints`, for an
    integrator that finds contacts but keeps no force for them (the impulses are NaN), at
    positions ``x`` (N, 2) m; and per row the rigid body whose outline the vertex met (an index
    into ``world.bodies``), or -1 (:func:`group_pairs`' ``rigid_of``)."""
    n = len(points.vertex)
    nan = np.full(n, np.nan)
    imp = ContactImpulses(points.vertex.astype(np.int64), points.edge.copy(), points.collider.copy(),
                          x[points.vertex].copy(), points.normal.copy(), nan, nan.copy())
    return imp, points.rigid_body.copy()


@dataclass(frozen=True)
class ContactPair:
    """Two things in contact over the last step, seen from ``a``.

    Attributes
    ----------
    a : Body
        One body.
    b : Body or Collider
        What it touches: another body or a collider.
    normal_impulse : float
        Sum of the normal impulses between them over the step (N s); NaN where the world's
        integrator does not measure contact forces (only avbd does).
    friction_impulse : float
        Size of the summed friction impulse over the step (N s); NaN likewise.
    impulse : (2,) float64
        Total impulse on ``a`` from ``b`` over the step, normal and friction (N s); ``b``
        takes the opposite.
    normal : (2,) float64
        Unit direction of the summed normal impulse on ``a`` (out of ``b``), or of the
        contact normals where impulses are not measured.
    points : (K, 2) float64
        The contact points (m): where each row acted.
    """

    a: Any
    b: Any
    normal_impulse: float
    friction_impulse: float
    impulse: np.ndarray
    normal: np.ndarray
    points: np.ndarray

    def flipped(self) -> "ContactPair":
        """The same pair seen from ``b``."""
        return ContactPair(self.b, self.a, self.normal_impulse, self.friction_impulse, -self.impulse, -self.normal,
                           self.points)


def _row_bodies(imp: ContactImpulses, vertex_body: np.ndarray, rigid_of=None):
    """Per row: the pushed side's body and the other side's (a body index, or -1 with a
    collider), and whether the two sides were swapped so that a body-body pair reads low index
    first (its force then acts on the other side: sign -1)."""
    pushed_vertex = np.where(imp.vertex >= 0, imp.vertex, imp.edge[:, 0])
    a = vertex_body[pushed_vertex]
    other = np.where((imp.vertex >= 0) & (imp.edge[:, 0] >= 0), vertex_body[np.maximum(imp.edge[:, 0], 0)], -1)
    if rigid_of is not None:
        other = np.where(rigid_of >= 0, rigid_of, other)
    swap = (other >= 0) & (other < a)
    lo = np.where(swap, other, a)
    hi = np.where(swap, a, other)
    return lo, hi, np.where(swap, -1.0, 1.0)


def group_pairs(imp: ContactImpulses, vertex_body: np.ndarray, bodies, colliders, rigid_of=None) -> dict:
    """The touching pairs of a step's rows: ``{(id(a), id(b)): ContactPair}`` with ``a`` the
    lower-indexed body of a body-body pair, or the body of a body-collider pair.

    Parameters
    ----------
    imp : ContactImpulses
        The step's rows.
    vertex_body : (N,) int64
        Each world vertex's index in ``bodies``.
    bodies, colliders : sequence
        The world's bodies and colliders, by index.
    rigid_of : (K,) int64, optional
        Per row, a rigid body on the other side where ``imp`` names it by index only
        (:func:`impulses_from_points`), else -1.

    Examples
    --------
    >>> import numpy as np
    >>> imp = ContactImpulses(np.array([0, 1]), np.full((2, 2), -1), np.array([0, 0]),
    ...                       np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[0.0, 1.0], [0.0, 1.0]]),
    ...                       np.array([0.5, 0.25]), np.array([0.0, 0.1]))
    >>> (p,) = group_pairs(imp, np.array([0, 0]), ["body"], ["floor"]).values()
    >>> p.a, p.b, p.normal_impulse, p.impulse.round(3).tolist()
    ('body', 'floor', 0.75, [-0.1, 0.75])
    """
    if not len(imp):
        return {}
    lo, hi, sign = _row_bodies(imp, vertex_body, rigid_of)
    keep = lo != hi  # a body's contacts with itself are not pairs
    measured = not np.isnan(imp.normal_impulse).all()
    if measured:
        keep &= imp.normal_impulse > 0.0
    rows = np.flatnonzero(keep)
    if not len(rows):
        return {}
    # the other side: a body (>= 0) or a collider (encoded -1 - index)
    other = np.where(hi[rows] >= 0, hi[rows], -1 - imp.collider[rows]).astype(np.int64)
    # one integer per (lo, other), in the same order: np.unique(axis=0) compares rows as
    # structured arrays, and NumPy turns a Ctrl-C that lands in that comparison into a
    # TypeError ("Cannot compare structured arrays"), which escaped a run as a traceback
    first = int(other.min())
    width = int(other.max()) - first + 1
    codes, which = np.unique(lo[rows].astype(np.int64) * width + (other - first), return_inverse=True)
    uniq = np.stack([codes // width, codes % width + first], axis=1)
    which = which.reshape(-1)
    n = imp.normal[rows] * sign[rows, None]
    t = np.stack([-n[:, 1], n[:, 0]], axis=1)
    jn = imp.normal_impulse[rows] if measured else np.ones(len(rows))
    jt = imp.friction_impulse[rows] if measured else np.zeros(len(rows))
    normal_part = np.zeros((len(uniq), 2))
    friction_part = np.zeros((len(uniq), 2))
    np.add.at(normal_part, which, n * jn[:, None])
    np.add.at(friction_part, which, t * jt[:, None])
    total_n = np.bincount(which, jn, len(uniq))
    pairs = {}
    for u, (ia, ib) in enumerate(uniq):
        a = bodies[ia]
        b = bodies[ib] if ib >= 0 else colliders[-1 - ib]
        size = float(np.hypot(*normal_part[u]))
        pairs[(id(a), id(b))] = ContactPair(
            a, b,
            float(total_n[u]) if measured else float("nan"),
            float(np.hypot(*friction_part[u])) if measured else float("nan"),
            (normal_part[u] + friction_part[u]) if measured else np.full(2, np.nan),
            normal_part[u] / size if size > 0.0 else np.zeros(2),
            imp.point[rows[which == u]])
    return pairs


def contact_events(before: dict, now: dict):
    """The pairs that began touching (in ``now``, not ``before``) and those that ended (the
    reverse), as ``(begun, ended)`` lists of pairs (``before``'s for the ended ones)."""
    begun = [p for k, p in now.items() if k not in before]
    ended = [p for k, p in before.items() if k not in now]
    return begun, ended

"""The rigid bodies of a Model as arrays (:class:`RigidSet`), their poses read from the
State, and their outlines as the moving polygons soft bodies collide with (:class:`RigidOutline`).

Units: m, kg, s; angles in radians, spins in rad/s.
"""

from __future__ import annotations

import math

import numpy as np

from ..behaviours.pressure import _loops
from ..colliders.shapes import POLYGON, _polygon_reach
from ..rigid_motion import center_of_mass, fit_angle, linear_and_angular_velocity


def triangle_inertia(x: np.ndarray, triangles: np.ndarray, density: float) -> tuple[float, np.ndarray, float]:
    """Mass (kg), centre of mass (m) and moment of inertia about it (kg m^2) of the solid
    triangles ``triangles`` of ``x`` at areal density ``density``.

    Examples
    --------
    A 2 x 1 rectangle of density 3 (two triangles): m = 6, I = m (a^2 + b^2) / 12 = 2.5.

    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])
    >>> m, c, i = triangle_inertia(x, np.array([[0, 1, 2], [0, 2, 3]]), 3.0)
    >>> m, c.tolist(), round(i, 12)
    (6.0, [1.0, 0.5], 2.5)
    """
    a, b, c = x[triangles[:, 0]], x[triangles[:, 1]], x[triangles[:, 2]]
    area = 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))
    mass = density * area.sum()
    center = (area @ ((a + b + c) / 3.0)) / area.sum()
    a, b, c = a - center, b - center, c - center
    # a triangle's second moment about a point (its corners relative to it): A/6 (|a|^2 + |b|^2
    # + |c|^2 + a.b + b.c + c.a)
    dot = lambda p, q: (p * q).sum(axis=1)  # noqa: E731
    inertia = density * float(area @ (dot(a, a) + dot(b, b) + dot(c, c) + dot(a, b) + dot(b, c) + dot(c, a))) / 6.0
    return float(mass), center, inertia


class RigidOutline:
    """A rigid body's outline as the packed collider soft bodies meet: a polygon (holes
    included) at the body's pose, moving with its velocity and spin. Read by
    :func:`~deforma.physics.colliders.shapes.pack_colliders` like a Polygon; not a user collider."""

    kind = POLYGON

    def __init__(self, loops, center, angle, velocity, omega, reach, friction, static_friction):
        self.loops = loops
        self.center = (float(center[0]), float(center[1]))
        self.angle = math.degrees(angle)
        self.velocity = (float(velocity[0]), float(velocity[1]))
        self.angular_velocity = math.degrees(omega)
        self._reach = reach
        self.friction = friction
        self.static_friction = static_friction


class RigidSet:
    """The rigid bodies of a :class:`~deforma.physics.model.Model`, as arrays.

    Attributes
    ----------
    bodies : (K,) int64
        Their body indices in the Model.
    mass, inertia : (K,) float64
        kg, kg m^2 about the centre of mass (of the triangles at the density).
    rest_center : (K, 2) float64
        Centre of mass of the rest shape (m).
    outline_ptr : (K + 1,) int64
        Rigid body ``k``'s outline vertices are ``outline_local[outline_ptr[k]:outline_ptr[k + 1]]``.
    outline_local : (No, 2) float64
        Their rest positions relative to ``rest_center`` (the body frame, angle 0).
    outline_vertex : (No,) int64
        Their rows in the State.
    loops_local : list of list of (k, 2) arrays
        Per rigid body, its outline loops in the body frame (outer counter-clockwise, holes clockwise).
    reach : (K,) float64
        Half the thinnest part of each outline (m; a vertex moving less per substep cannot jump it).
    """

    def __init__(self, model):
        mats = model.materials
        self.bodies = np.array([b for b, m in enumerate(mats) if m is not None and m.is_rigid], np.int64)
        k = len(self.bodies)
        self.mass = np.zeros(k)
        self.inertia = np.zeros(k)
        self.rest_center = np.zeros((k, 2))
        self.loops_local = []
        self.reach = np.zeros(k)
        local, vertex, ptr = [], [], [0]
        off = model.body_vertex_offsets
        for j, b in enumerate(self.bodies):
            t = model.topologies[b]
            m, c, inertia = triangle_inertia(t.rest_positions, t.triangles, mats[b].density)
            self.mass[j], self.rest_center[j], self.inertia[j] = m, c, inertia
            outline = t.boundary_vertices
            local.append(t.rest_positions[outline] - c)
            vertex.append(outline + off[b])
            ptr.append(ptr[-1] + len(outline))
            # boundary edges run with the body on their left: outer loops counter-clockwise,
            # holes clockwise, as a Polygon collider packs them
            loops = [t.rest_positions[lp[:, 0]] - c for lp in _loops(t.boundary_edges)]
            self.loops_local.append(loops)
            self.reach[j] = _polygon_reach(loops)
        self.outline_ptr = np.array(ptr, np.int64)
        self.outline_local = np.concatenate(local) if local else np.zeros((0, 2))
        self.outline_vertex = np.concatenate(vertex).astype(np.int64) if vertex else np.zeros(0, np.int64)
        # warm starts: the normal and friction impulse each outline vertex's contact took last
        # substep, and against which packed row (-1: none)
        self.cache_row = np.full(len(self.outline_vertex), -1, np.int64)
        self.cache_impulse = np.zeros((len(self.outline_vertex), 2))
        self.edges = None  # (edge_ptr, edges in the body frames), from the first packing (stage.outline_edges)

    def __len__(self) -> int:
        return len(self.bodies)

    def inverse_masses(self, model) -> tuple[np.ndarray, np.ndarray]:
        """``(1/mass (K,), 1/inertia (K,))``, 0 for a body with a pinned vertex: a rigid body
        held anywhere is held everywhere (it stands as a collider would)."""
        off = model.body_vertex_offsets
        held = np.array([model.pinned[off[b]:off[b + 1]].any() for b in self.bodies], bool)
        return np.where(held, 0.0, 1.0 / self.mass), np.where(held, 0.0, 1.0 / self.inertia)

    def poses(self, model, x, v) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(center (K, 2), angle (K,), velocity (K, 2), omega (K,))`` read from the State's
        ``x``, ``v``: the centre of mass, the rotation from the rest shape, the velocity of
        the centre and the spin (exact for vertices that move rigidly)."""
        k = len(self.bodies)
        center, angle, vel, omega = np.zeros((k, 2)), np.zeros(k), np.zeros((k, 2)), np.zeros(k)
        off = model.body_vertex_offsets
        for j, b in enumerate(self.bodies):
            sl = slice(off[b], off[b + 1])
            m = model.vertex_mass[sl]
            xb = x[sl]
            center[j] = center_of_mass(xb, m)
            angle[j] = fit_angle(model.topologies[b].rest_positions, xb, m)
            vel[j], omega[j] = linear_and_angular_velocity(xb, v[sl], m)
        return center, angle, vel, omega

    def outlines(self, center, angle, vel, omega, bodies) -> list[RigidOutline]:
        """The outlines to pack as colliders at these poses; ``bodies`` are the World's body
        handles (their friction coefficients apply to what touches them)."""
        out = []
        for j, b in enumerate(self.bodies):
            cs, sn = math.cos(angle[j]), math.sin(angle[j])
            rot = np.array([[cs, sn], [-sn, cs]])  # row vectors: p @ rot turns p by +angle
            loops = [lp @ rot + center[j] for lp in self.loops_local[j]]
            body = bodies[b]
            out.append(RigidOutline(loops, center[j], angle[j], vel[j], omega[j], self.reach[j], body.friction,
                                    body.static_friction))
        return out

    def place(self, model, x, v, center, angle, vel, omega) -> None:
        """Write every rigid body's vertices into ``x``, ``v`` at these poses (in place)."""
        off = model.body_vertex_offsets
        for j, b in enumerate(self.bodies):
            sl = slice(off[b], off[b + 1])
            r = model.topologies[b].rest_positions - self.rest_center[j]
            cs, sn = math.cos(angle[j]), math.sin(angle[j])
            px = cs * r[:, 0] - sn * r[:, 1]
            py = sn * r[:, 0] + cs * r[:, 1]
            x[sl, 0] = center[j, 0] + px
            x[sl, 1] = center[j, 1] + py
            v[sl, 0] = vel[j, 0] - omega[j] * py
            v[sl, 1] = vel[j, 1] + omega[j] * px

"""Handles onto a world's bodies and grabs: what :meth:`World.add_body` and
:meth:`World.grab` return.

A :class:`Body` owns nothing but its topology, mesh and overrides; its ``positions`` and
``velocities`` are views into the world's state, and its setters write through the world
(which validates and updates the Model). A :class:`Grab` is the mouse: vertices of one body
pulled toward a target while held.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..checks import MAX_LOAD
from ..checks import number as _number
from ..checks import pair as _pair
from ..checks import non_negative as _non_negative
from ..checks import positive as _positive
from ..checks import switch as _switch
from .behaviours import tearing as _tearing
from . import rigid_motion
from .behaviours.pressure import outline_loops
from .material import Material
from .rigid.stage import rigid_set
from .topology import BodyTopology, element_geometry

if TYPE_CHECKING:  # the World imports this module
    from ..mesh.mesh import Mesh
    from .world import World


SPRINGS = Material("springs")  # the seed's springs, what a body without a material is (immutable: shared)


def _material(value):
    if value is None or isinstance(value, Material):
        return value
    raise ValueError(f"material must be a deforma.Material (or None for the world's / the seed's springs), "
                     f"got {type(value).__name__}: e.g. deforma.Material('neo-hookean', youngs_modulus=1e5, "
                     f"poisson_ratio=0.3, density=100.0)")


def _spin(value, max_speed: float) -> float:
    """An angular velocity given in deg/s, checked against ``max_speed`` (read as rad/s);
    returned in rad/s."""
    spin = math.radians(_number(value, "angular_velocity"))
    if not abs(spin) <= max_speed:
        raise ValueError(f"angular_velocity must be within +-{math.degrees(max_speed):g} deg/s "
                         f"(world.max_speed in rad/s), got {value!r}")
    return spin


def _fem_mesh_check(topology) -> None:
    """Refuse a mesh that cannot be made of finite elements (before anything changes)."""
    element_geometry(topology)  # raises with the reason


def _pressure(value, topology) -> float | None:
    """Validate a body's gas pressure (N/m) and that the body can hold a gas."""
    if value is None:
        return None
    p = _non_negative(value, "pressure", "N/m")
    outline_loops(topology.rest_positions, topology.boundary_edges, topology.springs, topology.triangles)
    return p


class Body:
    """A soft body in a world: a handle onto its slice of the world's arrays.

    Made by :meth:`World.add_body`, not directly. ``material``, the springs' ``mass`` (kg,
    total), ``stiffness`` (N/m per spring) and ``damping`` (N*s/m per spring), and the
    body-contact ``friction`` / ``static_friction`` can be set live; setting ``None`` makes
    the body follow the world's value again. A body of a finite-element material takes its
    mass from the material's density and has no springs to set. ``collide`` and
    ``self_collision`` switch its contacts with other bodies and with itself; :meth:`pin`
    holds vertices in place.

    Examples
    --------
    >>> import deforma
    >>> w = deforma.World()
    >>> b = w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]), position=(0, 2))
    >>> b.positions.shape, b.mass, b.n_springs
    ((3, 2), 1.0, 3)
    """

    def __init__(self, world: World, index: int, mesh: Any, topology: BodyTopology, overrides: dict[str, Any]) -> None:
        self._world: World | None = world
        self._index = index
        self.mesh = mesh
        self.topology = topology
        self._overrides = overrides
        self._pinned = np.zeros(topology.n_vertices, bool)
        self._asleep = False  # held still by the world's sleeping (physics.sleeping)
        self._still = 0.0  # s it has been slower than sleeping.SLEEP_SPEED
        self._tear_topology: tuple[BodyTopology, Any] | None = None  # (topology, tearing.TearTopology) cached for the tear check
        self._tear_source = slice(None)  # after a tear: which old vertex each new one copies
        self._tear_fresh = np.zeros(0, np.int64)  # and the vertices whose springs, elements or mass it changed
        self._cracks: tuple[BodyTopology, Any] | None = None  # (topology, tips of the cracks that ran in its last step: Tear.tips)
        self._angle0 = 0.0  # rad: the angle it was placed at (its rest shape is turned so)

    def _tear_view(self):
        """The tear check's view (:class:`~deforma.physics.behaviours.tearing.TearTopology`) of the current
        topology: kept from the last tear, or built once for a topology it has not seen."""
        t = self.topology
        if self._tear_topology is None or self._tear_topology[0] is not t:
            self._tear_topology = (t, _tearing.TearTopology.of(t.rest_positions, t.triangles))
        return self._tear_topology[1]

    def _crack_tips(self):
        """Tips of the cracks that ran in the last step (none once they stopped, or for a
        topology set since)."""
        c = self._cracks
        return c[1] if c is not None and c[0] is self.topology else ()

    def _apply_tear(self, cut) -> None:
        """Take the torn mesh ``cut`` (a :class:`~deforma.physics.behaviours.tearing.Tear`) as the body's."""
        from ..mesh import Mesh

        t, src = self.topology, cut.source
        self.topology, tt = _tearing.torn_topologies(t, self._tear_view(), cut)
        self._tear_topology = (self.topology, tt)  # the tear check's view of the torn mesh, kept
        uv = getattr(self.mesh, "uv", None)
        if uv is not None and len(uv) == t.n_vertices:
            torn = self.topology  # the mesh's own copies of its rest positions and triangles
            self.mesh = Mesh._trusted(torn.rest_positions.copy(), torn.triangles.copy(), np.take(uv, src, axis=0),
                                      getattr(self.mesh, "texture", None))
        self._pinned = self._pinned[src]
        self._tear_source = src
        self._cracks = (self.topology, cut.tips)
        self._overrides["pressure"] = None  # the gas escapes through the tear

    def _tear_state(self) -> tuple:
        """Everything a tear changes on this handle (what a failed step puts back)."""
        return (self.topology, self._tear_topology, self.mesh, self._pinned, self._tear_source, self._tear_fresh,
                self._cracks, self._overrides["pressure"])

    def _set_tear_state(self, state: tuple) -> None:
        (self.topology, self._tear_topology, self.mesh, self._pinned, self._tear_source, self._tear_fresh,
         self._cracks, self._overrides["pressure"]) = state

    def _check(self) -> "World":
        if self._world is None:
            raise ValueError("this body was removed from its world")
        return self._world

    @property
    def world(self) -> "World":
        """The world the body lives in."""
        return self._check()

    @property
    def index(self) -> int:
        """Position of the body in ``world.bodies``."""
        self._check()
        return self._index

    @property
    def vertex_slice(self) -> slice:
        """Rows of the world's state arrays that belong to this body."""
        off = self._check()._model.body_vertex_offsets
        return slice(int(off[self._index]), int(off[self._index + 1]))

    @property
    def positions(self) -> np.ndarray:
        """(N, 2) vertex positions in metres: a view into the world's state, writable.

        Setting it refuses positions where a colliding body would overlap another (contacts
        keep bodies apart from a start where they are apart; writing into the view in place
        skips that check, so keep such edits clear of other bodies).
        """
        return self._check()._state.x[self.vertex_slice]

    @positions.setter
    def positions(self, value: ArrayLike) -> None:
        x = self._checked_array(value, "positions", shapes=((self.n_vertices, 2),))
        world = self._check()
        if self._overrides["collide"]:
            world._check_no_overlap(self, x)
        world._disturb(self)
        self.positions[...] = x

    @property
    def velocities(self) -> np.ndarray:
        """(N, 2) vertex velocities in m/s: a view into the world's state, writable."""
        return self._check()._state.v[self.vertex_slice]

    @velocities.setter
    def velocities(self, value: ArrayLike) -> None:
        # a single (vx, vy) sets every vertex: the usual way to launch a body
        v = self._checked_array(value, "velocities", shapes=((self.n_vertices, 2), (2,)))
        self._check()._disturb(self)
        self.velocities[...] = v

    def _checked_array(self, value, name, *, shapes):
        try:
            a = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be an array of numbers, got {type(value).__name__}") from None
        if a.shape not in shapes or not np.all(np.isfinite(a)):
            allowed = " or ".join(str(s) for s in shapes)
            raise ValueError(f"{name} must be finite with shape {allowed}, got shape {a.shape}")
        return a

    @property
    def n_vertices(self) -> int:
        """Number of vertices (masses)."""
        return self.topology.n_vertices

    @property
    def n_springs(self) -> int:
        """Number of springs (unique mesh edges)."""
        return self.topology.n_springs

    @property
    def triangles(self) -> np.ndarray:
        """(M, 3) int32 triangles in body-local vertex indices (may be empty)."""
        return self.topology.triangles

    @property
    def springs(self) -> np.ndarray:
        """(E, 2) int32 spring vertex pairs in body-local indices."""
        return self.topology.springs

    def to_mesh(self) -> Mesh:
        """The body's current shape as a :class:`~deforma.mesh.Mesh`: its positions (m), its
        triangles (a torn body's as torn), its texture coordinates and picture.

        A triangle the motion has turned over stays as it is (it is not re-ordered), so the
        mesh shows the body exactly; ``deforma.mesh.write_meshes`` writes it as OBJ, JSON or
        SVG.

        Raises
        ------
        ValueError
            A body without triangles (a chain of springs): no mesh to give.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2), position=(0, 2))
        >>> w.step()
        >>> m = b.to_mesh()
        >>> bool((m.vertices == b.positions).all()), bool((m.triangles == b.triangles).all()), m.uv.shape
        (True, True, (16, 2))
        """
        from ..mesh import Mesh

        if len(self.triangles) == 0:
            raise ValueError(f"body {self._index} has no triangles (a chain of springs): it has no mesh to give")
        uv = getattr(self.mesh, "uv", None)
        if uv is None or len(uv) != self.n_vertices:
            x = self.topology.rest_positions
            lo, hi = x.min(axis=0), x.max(axis=0)
            uv = (x - lo) / np.where(hi > lo, hi - lo, 1.0)
        return Mesh._trusted(self.positions.copy(), self.triangles.copy(), np.array(uv, dtype=np.float64, copy=True),
                             getattr(self.mesh, "texture", None))

    @property
    def vertex_masses(self) -> np.ndarray:
        """(N,) mass of each vertex in kg (a copy): equal for springs, ``density`` times the
        lumped area for finite elements."""
        return self._check()._model.vertex_mass[self.vertex_slice].copy()

    @property
    def center_of_mass(self) -> np.ndarray:
        """(2,) centre of mass in metres (vertices weighted by their masses)."""
        m = self._check()._model.vertex_mass[self.vertex_slice]
        return rigid_motion.center_of_mass(self.positions, m)

    @property
    def velocity(self) -> np.ndarray:
        """(2,) velocity of the centre of mass, m/s (a copy).

        Setting it shifts every vertex's velocity by the same amount: the body's spin and
        wobble stay as they are.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(gravity=(0, 0))
        >>> b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2))
        >>> b.velocity = (1.0, 2.0)
        >>> b.velocity.tolist(), b.velocities[0].tolist()
        ([1.0, 2.0], [1.0, 2.0])
        """
        m = self._check()._model.vertex_mass[self.vertex_slice]
        return rigid_motion.center_of_mass(self.velocities, m)  # the momentum over the mass

    @velocity.setter
    def velocity(self, value: ArrayLike) -> None:
        world = self._check()
        vel = _pair(value, "velocity", limit=world.max_speed)
        self.velocities[...] += np.asarray(vel) - self.velocity

    @property
    def angular_velocity(self) -> float:
        """Spin about the centre of mass, deg/s, counter-clockwise: the vertices' angular
        momentum about it over their moment of inertia (exact for a rigid motion).

        Setting it replaces that spin and keeps the rest of the motion.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(gravity=(0, 0))
        >>> b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2))
        >>> b.angular_velocity = 90.0
        >>> round(b.angular_velocity, 9), bool(abs(b.velocity).max() < 1e-12)
        (90.0, True)
        """
        m = self._check()._model.vertex_mass[self.vertex_slice]
        _, omega = rigid_motion.linear_and_angular_velocity(self.positions, self.velocities, m)
        return math.degrees(omega)

    @angular_velocity.setter
    def angular_velocity(self, value: float) -> None:
        world = self._check()
        spin = _spin(value, world.max_speed)
        m = world._model.vertex_mass[self.vertex_slice]
        x = self.positions
        _, omega = rigid_motion.linear_and_angular_velocity(x, self.velocities, m)
        self.velocities[...] += rigid_motion.rigid_velocities(x, m, (0.0, 0.0), spin - omega)

    @property
    def angle(self) -> float:
        """How far the body has turned, degrees counter-clockwise: the angle it was placed at
        (``add_body(angle=...)``) plus the rotation of the rigid motion that best carries its
        rest shape onto its vertices (mass-weighted least squares). Within +-180 of the
        placement angle: a body that spins through half a turn wraps around.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(gravity=(0, 0), dt=1 / 600, integrator="symplectic-euler")
        >>> b = w.add_body(deforma.mesh.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=2), angle=10)
        >>> b.angular_velocity = 90.0
        >>> for _ in range(60):  # a tenth of a second at 90 deg/s
        ...     w.step()
        >>> round(b.angle, 1)
        19.0
        """
        m = self._check()._model.vertex_mass[self.vertex_slice]
        turn = rigid_motion.fit_angle(self.topology.rest_positions, self.positions, m)
        return math.degrees(self._angle0 + turn)

    @property
    def material(self) -> Material:
        """The body's material (its own, or the world's; ``Material("springs")`` if neither is set).

        Setting it (or ``None``: follow the world) switches the model live; the body keeps its
        positions and velocities.
        """
        m = self._overrides["material"]
        if m is None:
            m = self._check().material
        return SPRINGS if m is None else m

    @material.setter
    def material(self, value: Material | None) -> None:
        world = self._check()
        value = _material(value)
        if value is not None and value.is_fem:
            _fem_mesh_check(self.topology)
        made = value if value is not None else (world.material or SPRINGS)
        world._check_joined_stay_rigid([self] if not made.is_rigid else [])
        self._overrides["material"] = value
        world._disturb(self)
        world._material_changed()

    @property
    def is_fem(self) -> bool:
        """True if the body is made of finite elements (its material is not ``"springs"``)."""
        return self.material.is_fem

    def _param(self, name):
        v = self._overrides[name]
        return getattr(self._check(), name) if v is None else v

    def _set_param(self, name, value, check):
        if value is not None and name in ("mass", "stiffness", "damping") and self.is_fem:
            raise ValueError(f"body {self._index} is made of {self.material.model!r} elements, which have no "
                             f"spring {name}: change its material (youngs_modulus, density, damping) instead")
        self._overrides[name] = None if value is None else check(value)
        world = self._check()
        world._disturb(self)
        world._apply_body_parameters(self._index)

    def _mass(self):
        if self.is_fem:
            return float(self._check()._model.vertex_mass[self.vertex_slice].sum())
        return self._param("mass")

    mass = property(_mass,
                    lambda self, v: self._set_param("mass", v, lambda x: _positive(x, "mass", "kg")),
                    doc="Total mass in kg: for springs spread evenly over the vertices (the original's "
                        "mass / N); for finite elements ``density * area`` (read-only).")
    stiffness = property(lambda self: self._param("stiffness"),
                         lambda self, v: self._set_param("stiffness", v,
                                                         lambda x: _non_negative(x, "stiffness", "N/m")),
                         doc="Spring constant ks of every spring, N/m (springs bodies).")
    damping = property(lambda self: self._param("damping"),
                       lambda self, v: self._set_param("damping", v,
                                                       lambda x: _non_negative(x, "damping", "N*s/m")),
                       doc="Spring damping kd of every spring, N*s/m (springs bodies).")

    @property
    def sleeping(self) -> bool:
        """Whether the body sleeps (``World(sleep=True)``, :mod:`deforma.physics.sleeping`): at
        rest with its island, not stepped, held as a pinned body is. Setting ``False`` wakes it
        and its island; ``True`` puts its island to sleep now. Pushing, pulling, dragging,
        pinning or setting its positions, velocities or parameters through their setters wakes
        it too (writing into the ``positions`` or ``velocities`` views in place does not).

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(sleep=True)
        >>> _ = w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0.0))
        >>> b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2), position=(0, 0.5),
        ...                material=deforma.Material("rigid", density=10.0))
        >>> for _ in range(60):
        ...     w.step()
        >>> b.sleeping
        True
        >>> b.apply_impulse((0.0, 5.0))
        >>> b.sleeping, b.velocity.round(3).tolist()
        (False, [0.0, 0.5])
        """
        self._check()
        return self._asleep

    @sleeping.setter
    def sleeping(self, value: bool) -> None:
        world = self._check()
        if _switch(value, "sleeping"):
            world._fall_asleep(world._island_of(self))
        else:
            world._disturb(self)

    @property
    def pinned(self) -> np.ndarray:
        """(N,) bool: which vertices are pinned (a copy; use :meth:`pin` / :meth:`unpin`)."""
        self._check()
        return self._pinned.copy()

    def _indices(self, indices, name):
        try:
            a = np.asarray(indices)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be vertex indices (integers), got {indices!r}") from None
        if a.dtype == bool and a.shape == (self.n_vertices,):
            return np.flatnonzero(a)
        a = a.reshape(-1)
        if a.size and a.dtype == object and all(isinstance(v, int) for v in a.tolist()):
            # Python integers too large for int64: certainly out of range, said as such
            bad = next(v for v in a.tolist() if not 0 <= v < self.n_vertices)
            raise ValueError(f"{name}: vertex index {bad} is out of range; body {self._index} has vertices "
                             f"0..{self.n_vertices - 1}")
        if a.size and not np.issubdtype(a.dtype, np.integer):
            raise ValueError(f"{name} must be integers (or a bool mask of {self.n_vertices}), got dtype {a.dtype}")
        if a.size and (a.min() < 0 or a.max() >= self.n_vertices):
            bad = int(a[(a < 0) | (a >= self.n_vertices)][0])
            raise ValueError(f"{name}: vertex index {bad} is out of range; body {self._index} has vertices "
                             f"0..{self.n_vertices - 1}")
        return a.astype(np.int64)

    def _loads(self, value, indices, name: str, unit: str):
        """``(vertices, per-vertex values)`` of a force or impulse: a (2,) total spread over the
        listed vertices by their mass, or one (2,) row per listed vertex."""
        world = self._check()
        idx = np.arange(self.n_vertices) if indices is None else self._indices(indices, f"{name} indices")
        try:
            a = np.array(value, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be numbers in {unit}, got {value!r}") from None
        if not (a.shape == (2,) or a.shape == (len(idx), 2)):
            raise ValueError(f"{name} must be a total (2,) or one row per vertex ({len(idx)}, 2), in {unit}; "
                             f"got shape {a.shape}")
        if not np.isfinite(a).all() or np.abs(a).max(initial=0.0) > MAX_LOAD:
            raise ValueError(f"{name} must be finite and within +-{MAX_LOAD:g} {unit}, got {value!r}")
        if a.shape == (2,):
            m = world._model.vertex_mass[self.vertex_slice][idx]
            a = a[None, :] * (m / m.sum())[:, None] if len(idx) else np.zeros((0, 2))
        return idx, a

    def apply_force(self, force: ArrayLike, indices: ArrayLike | None = None) -> None:
        """Push the body with ``force`` (N) during the next step (every substep of it).

        Parameters
        ----------
        force : (2,) or (K, 2) array_like of float
            A total force, spread over the vertices by their mass (so it accelerates them
            alike: ``force / mass``), or one force per vertex listed in ``indices``.
        indices : array_like of int or bool mask, optional
            Body-local vertices (default: all). A pinned vertex takes its share and stays.

        Calls before a step add up; the step uses them and forgets them.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(gravity=(0, 0), dt=0.01, mass=2.0)
        >>> b = w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]))
        >>> b.apply_force((4.0, 0.0))  # 4 N on 2 kg for 0.01 s
        >>> w.step()
        >>> b.velocities[:, 0].round(12).tolist()
        [0.02, 0.02, 0.02]
        """
        idx, f = self._loads(force, indices, "force", "N")
        world = self._check()
        world._disturb(self)
        world._forces.append((self, idx, f))

    def apply_impulse(self, impulse: ArrayLike, indices: ArrayLike | None = None) -> None:
        """Change the body's velocities now by ``impulse`` (N s): ``impulse / mass`` per vertex.

        Parameters
        ----------
        impulse : (2,) or (K, 2) array_like of float
            A total impulse, spread over the vertices by their mass (each then changes its
            velocity by ``impulse / mass``), or one impulse per vertex listed in ``indices``.
        indices : array_like of int or bool mask, optional
            Body-local vertices (default: all). A pinned vertex takes its share and stays.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World(mass=3.0)
        >>> b = w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]))
        >>> b.apply_impulse((0.0, 6.0))  # 6 N s on 3 kg
        >>> b.velocities[:, 1].tolist()
        [2.0, 2.0, 2.0]
        """
        idx, j = self._loads(impulse, indices, "impulse", "N*s")
        world = self._check()
        world._disturb(self)  # before reading its masses: asleep, its vertices are held (no inverse mass)
        if self.material.is_rigid:  # the whole body takes it: its centre and its spin
            x, m = self.positions, self.vertex_masses
            r = x[idx] - rigid_motion.center_of_mass(x, m)
            rs = rigid_set(world._model)
            k = int(np.flatnonzero(rs.bodies == self._index)[0])
            total = j.sum(axis=0)
            turn = float((r[:, 0] * j[:, 1] - r[:, 1] * j[:, 0]).sum())
            inv_mass, inv_inertia = rs.inverse_masses(world._model)
            self.velocities[...] += rigid_motion.rigid_velocities(x, m, total * inv_mass[k], turn * inv_inertia[k])
            return
        rows = self.vertex_slice.start + idx
        free = ~self._pinned[idx]
        np.add.at(world._state.v, rows[free], j[free] * world._model.vertex_inv_mass[rows[free], None])

    def pin(self, indices: ArrayLike) -> None:
        """Hold vertices ``indices`` (body-local, or a bool mask) where they are: infinite mass,
        zero velocity, under every integrator, until :meth:`unpin`. A rigid body held at any
        vertex is held whole: it stops and stands as a collider would.

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> b = w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]), position=(0, 2))
        >>> b.pin([0, 1])
        >>> for _ in range(60):
        ...     w.step()
        >>> b.pinned.tolist(), b.positions[0].tolist()
        ([True, True, False], [-0.5, 1.5])
        """
        world = self._check()
        idx = self._indices(indices, "pin indices")
        world._disturb(self)
        self._pinned[idx] = True
        self.velocities[slice(None) if self.material.is_rigid and idx.size else idx] = 0.0
        world._hold([self])

    def unpin(self, indices: ArrayLike | None = None) -> None:
        """Free vertices ``indices`` (default: all of them)."""
        world = self._check()
        world._disturb(self)
        if indices is None:
            self._pinned[:] = False
        else:
            self._pinned[self._indices(indices, "unpin indices")] = False
        world._hold([self])
    friction = property(lambda self: self._param("friction"),
                        lambda self, v: self._set_param("friction", v,
                                                        lambda x: _non_negative(x, "friction", "(dimensionless)")),
                        doc="Dynamic Coulomb coefficient against other bodies and itself; two bodies "
                            "mix theirs as sqrt(a * b). Colliders use their own.")
    static_friction = property(lambda self: self._param("static_friction"),
                               lambda self, v: self._set_param(
                                   "static_friction", v, lambda x: _non_negative(x, "static_friction",
                                                                                 "(dimensionless)")),
                               doc="Static Coulomb coefficient against other bodies and itself, mixed "
                                   "as sqrt(a * b).")

    @property
    def collide(self) -> bool:
        """Whether the body touches other bodies (both must have it on)."""
        return self._overrides["collide"]

    @collide.setter
    def collide(self, value: bool) -> None:
        self._set_switch("collide", value)

    @property
    def self_collision(self) -> bool:
        """Whether the body touches itself (a fold of its outline against another part of it)."""
        return self._overrides["self_collision"]

    @self_collision.setter
    def self_collision(self, value: bool) -> None:
        self._set_switch("self_collision", value)

    def _set_switch(self, name, value):
        value = _switch(value, name)
        world = self._check()
        world._disturb(self)
        if value and name == "collide":
            world._check_no_overlap(self)
        self._overrides[name] = value
        world._apply_body_parameters(self._index)

    @property
    def contact_thickness(self) -> float:
        """The contact thickness this body uses, metres (the world's, or its automatic value)."""
        return self._check()._body_thickness(self)

    @property
    def pressure(self) -> float | None:
        """Gas pressure at the rest area, N/m (``None``: no gas); settable. See
        :mod:`deforma.physics.behaviours.pressure`. A body that tears lets its gas out (``None``)."""
        self._check()
        return self._overrides["pressure"]

    @pressure.setter
    def pressure(self, value: float | None) -> None:
        world = self._check()
        self._overrides["pressure"] = _pressure(value, self.topology)
        world._rebuild(world._state.x, world._state.v)

    @property
    def pieces(self) -> np.ndarray:
        """(N,) int: the connected piece each vertex belongs to (all 0 until the body tears).

        Examples
        --------
        >>> import deforma
        >>> w = deforma.World()
        >>> b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2))
        >>> int(b.pieces.max()) + 1
        1
        """
        self._check()
        t = self.topology
        return _tearing.pieces(t.n_vertices, t.springs if not len(t.triangles) else [], t.triangles)

    def __repr__(self) -> str:
        if self._world is None:
            return "Body(removed)"
        if self.is_fem:
            return (f"Body({self.n_vertices} vertices, {len(self.triangles)} {self.material.model} elements, "
                    f"mass {self.mass:.4g} kg)")
        return f"Body({self.n_vertices} vertices, {self.n_springs} springs, mass {self.mass} kg)"


class Grab:
    """A mouse grab: vertices of one body pulled along with ``target`` until released.

    Made by :meth:`World.grab`. ``vertices`` are body-local indices (empty when the point
    was off every body, then the grab does nothing). ``offsets`` (k, 2), metres: where each
    held vertex was relative to the grabbed point; vertex ``vertices[i]`` is pulled toward
    ``target + offsets[i]``, so the held patch moves as a hand would move it, keeping its
    shape, rather than being squeezed into the one point ``target`` (which crumpled the
    triangles under a wide grab, and inverted the grabbed triangle under a strong one).
    """

    def __init__(self, world: World, body: Body | None, vertices: ArrayLike, target: tuple[float, float], strength: float,
                 offsets: ArrayLike | None = None) -> None:
        self._world = world
        self.body = body
        self.vertices = np.asarray(vertices, dtype=np.int64)
        self.target = target
        self.strength = strength
        self.offsets = np.zeros((len(self.vertices), 2)) if offsets is None else np.asarray(offsets, np.float64)
        self.active = True

    def __repr__(self) -> str:
        state = "active" if self.active else "released"
        return f"Grab({len(self.vertices)} vertices, target={self.target}, strength={self.strength} N/m, {state})"

"""The constant part of a world: every body's springs, triangle elements, masses, pins, gas and
contact topology, concatenated into the arrays the kernels read (:class:`Model`).
"""

from __future__ import annotations

import uuid

import numpy as np

from .contact.contacts import COLLIDE, SELF_COLLIDE, SIDE_MARGIN, SPECULATIVE, ContactTopology
from .elements.kind import BodyElements, element_kind
from .elements.springs import SpringKind
from .elements.triangles import TriangleKind, rest_geometry
from .material import KIND_CODES
from .topology import element_geometry, lumped_areas, off_outline


class Model:
    """All bodies' constant arrays, concatenated, as the kernels read them.

    Attributes
    ----------
    vertex_mass, vertex_inv_mass : (N,) float64
        Mass of each vertex in kg (a body's total mass / its vertex count) and its inverse.
    spring_i, spring_j : (E,) int32
        Global vertex indices of each spring's ends.
    spring_rest_length : (E,) float64
        Rest lengths in metres.
    spring_stiffness : (E,) float64
        Spring constants ``ks`` in N/m.
    spring_damping : (E,) float64
        Damping constants ``kd`` in N*s/m (acting on the relative velocity along the spring).
    body_vertex_offsets, body_spring_offsets, body_elem_offsets : (B + 1,) int64
        Where each body's vertices, springs and elements start. A body of a finite-element
        material has elements and no springs; a springs body has springs and no elements.
    elem : (T, 3) int32
        Triangle elements (global vertex indices, counter-clockwise at rest), each body's
        sorted by their lowest vertex (so a run of elements touches a narrow band of
        vertices); a torn body's keep the order they had (a few renumbered corners aside,
        the same band). ``elem_source`` (T,) int64: each element's row in its body's
        ``topology.triangles``.
    elem_b : (T, 4) float64
        Rest-shape inverses ``B`` (row-major, 1/m); see :mod:`deforma.physics.elements.triangles`.
    elem_area : (T,) float64
        Rest areas (m^2).
    elem_mu, elem_lambda, elem_damping : (T,) float64
        Plane-stress Lamé parameters (Pa) and damping (s) of each element's material.
    elem_kind : (T,) int32
        ``material.KIND_COROTATED`` or ``KIND_NEO_HOOKEAN``.
    vertex_area : (N,) float64
        Lumped rest area per vertex of finite-element bodies (a third of each triangle
        around it, m^2; 0 for springs bodies): its mass is ``density * vertex_area``.
    pinned : (N,) bool
        Pinned vertices: they keep their position (``vertex_inv_mass`` 0, infinite mass).
    spring_rest_length0, elem_b0, elem_area0 : arrays
        The rest shape as built: plasticity (:mod:`deforma.physics.behaviours.plasticity`) moves
        ``spring_rest_length``, ``elem_b`` and ``elem_area`` and bounds them against these.
    version : int
        Incremented by every change of a parameter or rest shape made in place (the
        ``set_*`` methods, plasticity): a solver that keeps something built from the
        Model (a factored matrix) compares it instead of the arrays.
    serial : int
        A number no other Model has (a random 128-bit identifier; a copy made by
        ``copy.deepcopy`` or a pickle keeps it).
    torn_from : (int, (N,) int64, (N,) bool, int) or None
        Set by the world when a tear rebuilt this Model from another: that Model's
        ``serial``; for each vertex the vertex of that Model it comes from (a copy or
        itself); the vertices whose springs or elements the tear changed (the corners of
        the triangles it renumbered, the ends of the springs it snapped: every other vertex
        has the same ones, in the same order); and this Model's ``version`` then. A solver
        that keeps something built for the old Model (implicit Euler's factor and matrix)
        carries it over instead of starting again.
    pressure_a, pressure_b : (P,) int32
        Directed outline edges (global vertex indices, gas on the left) of the bodies that
        hold a gas (:mod:`deforma.physics.behaviours.pressure`); ``body_pressure_offsets`` (B + 1,) says
        where each body's start.
    body_pressure, body_pressure_area : (B,) float64
        Each body's gas pressure at rest (N/m; 0 without gas) and the enclosed area at rest
        (m^2); ``has_pressure`` whether any body holds a gas.
    gravity : (float, float)
        Acceleration of gravity (m/s^2), and ``air_drag`` (1/s): the World's, which it sets
        in place when they change (the Model is not rebuilt for them).
    elements : list of ElementKind
        The element kinds (:mod:`deforma.physics.elements.kind`): the springs, the triangle
        elements, then one entry per registered kind a body's material uses. ``fused`` says
        whether the integrators' compiled drivers can run them all.
    contact : ContactTopology
        Every body as the contact stage reads it (outline and other vertices, outline edges,
        triangles, per-vertex contact thickness, per-body flags, thickness and friction);
        see :mod:`deforma.physics.contact`.
    joints : JointRows or None
        The world's joints as rows of avbd's sweep
        (:class:`~deforma.physics.integrators.avbd.joints.JointRows`), set by the World before
        each step while avbd moves its rigid bodies; None otherwise.

    The constructor takes the bodies' topologies and parameters (lists, one entry per body);
    ``torn``, a dict from a finite-element body to ``(Model before, its index there)`` when a
    tear made the body's topology from that one's, builds that body's elements from the
    Model before (the same elements in the same order, with the rest shape plasticity
    moved) instead of from its topology.

    Examples
    --------
    >>> from deforma.physics.topology import BodyTopology
    >>> t = BodyTopology.from_arrays([[0, 0], [1, 0], [0, 1]], [[0, 1], [1, 2], [0, 2]])
    >>> m = Model([t], masses=[3.0], stiffness=[100.0], damping=[0.0])
    >>> m.vertex_mass.tolist(), m.spring_i.tolist(), m.spring_j.tolist()
    ([1.0, 1.0, 1.0], [0, 0, 1], [1, 2, 2])
    """

    def __init__(self, topologies, *, masses, stiffness, damping, materials=None, pinned=None, contact=None,
                 pressure=None, torn=None, gravity=(0.0, 0.0), air_drag=0.0):
        self.topologies = list(topologies)
        self.gravity = gravity
        self.air_drag = air_drag
        self.version = 0
        self.serial = uuid.uuid4().int  # unique across processes too (a pickled world's Models)
        self.torn_from = None
        self._attachments = {}  # body -> its long-range attachments, until the pins change
        nb = len(self.topologies)
        materials = [None] * nb if materials is None else list(materials)
        # a finite-element body (or one of a registered element kind) weighs density * area and
        # has no springs; only the corotated and Neo-Hookean ones have triangle elements here
        fem = [m is not None and m.is_fem for m in materials]
        has_tri = [m is not None and m.model in KIND_CODES for m in materials]
        nv = [t.n_vertices for t in self.topologies]
        ne = [0 if f else t.n_springs for t, f in zip(self.topologies, fem)]
        nt = [len(t.triangles) if f else 0 for t, f in zip(self.topologies, has_tri)]
        self.body_vertex_offsets = np.zeros(nb + 1, np.int64)
        self.body_spring_offsets = np.zeros(nb + 1, np.int64)
        self.body_elem_offsets = np.zeros(nb + 1, np.int64)
        np.cumsum(nv, out=self.body_vertex_offsets[1:])
        np.cumsum(ne, out=self.body_spring_offsets[1:])
        np.cumsum(nt, out=self.body_elem_offsets[1:])
        n, e, ntot = int(self.body_vertex_offsets[-1]), int(self.body_spring_offsets[-1]), int(self.body_elem_offsets[-1])

        self.spring_i = np.empty(e, np.int32)
        self.spring_j = np.empty(e, np.int32)
        self.spring_rest_length = np.empty(e, np.float64)
        self.elem = np.empty((ntot, 3), np.int32)
        self.elem_b = np.empty((ntot, 4), np.float64)
        self.elem_area = np.empty(ntot, np.float64)
        self.elem_source = np.empty(ntot, np.int64)
        self.vertex_area = np.zeros(n, np.float64)
        self.elem_b0 = np.empty((ntot, 4), np.float64)
        self.elem_area0 = np.empty(ntot, np.float64)
        torn = torn or {}
        for b, t in enumerate(self.topologies):
            s0, s1 = self.body_spring_offsets[b], self.body_spring_offsets[b + 1]
            v0 = self.body_vertex_offsets[b]
            if not fem[b]:
                self.spring_i[s0:s1] = t.springs[:, 0] + v0
                self.spring_j[s0:s1] = t.springs[:, 1] + v0
                self.spring_rest_length[s0:s1] = t.spring_rest_length
                continue
            if not has_tri[b]:  # another element kind's body: its mass comes from its area
                self.vertex_area[v0:v0 + t.n_vertices] = element_geometry(t)[3]
                continue
            t0, t1 = self.body_elem_offsets[b], self.body_elem_offsets[b + 1]
            if b in torn:
                self._torn_elements(b, *torn[b])
                continue
            tri, bmat, area, lumped, order = element_geometry(t)
            self.elem_source[t0:t1] = order
            self.elem[t0:t1] = tri
            if v0:
                self.elem[t0:t1] += int(v0)
            self.elem_b[t0:t1] = self.elem_b0[t0:t1] = bmat
            self.elem_area[t0:t1] = self.elem_area0[t0:t1] = area
            self.vertex_area[v0:v0 + t.n_vertices] = lumped
        # every element is a finite-element body's: set_body_material below fills them all
        self.elem_mu = np.empty(ntot, np.float64)
        self.elem_lambda = np.empty(ntot, np.float64)
        self.elem_damping = np.empty(ntot, np.float64)
        self.elem_kind = np.empty(ntot, np.int32)
        self.vertex_mass = np.empty(n, np.float64)
        self.vertex_inv_mass = np.empty(n, np.float64)
        self.pinned = np.zeros(n, bool)
        if pinned is not None:
            for b, mask in enumerate(pinned):
                self.pinned[self.body_vertex_offsets[b]:self.body_vertex_offsets[b + 1]] = mask
        # a rigid body's vertices: the soft integrators hold them (infinite mass there) and
        # the rigid stage moves them (deforma.physics.rigid)
        self.rigid = np.zeros(n, bool)
        self.joints = None
        for b, m in enumerate(materials):
            if m is not None and m.is_rigid:
                self.rigid[self.body_vertex_offsets[b]:self.body_vertex_offsets[b + 1]] = True
        self.spring_stiffness = np.empty(e, np.float64)
        self.spring_damping = np.empty(e, np.float64)
        self.materials = materials
        for b in range(nb):
            if fem[b]:
                self.set_body_material(b, materials[b])
            else:
                self.set_body_parameters(b, mass=masses[b], stiffness=stiffness[b], damping=damping[b])

        self.spring_rest_length0 = self.spring_rest_length.copy()
        self._pressure(pressure if pressure is not None else [None] * nb)

        # The contact stage's view: the collision vertices are every body's outline vertices,
        # body by body, then the other vertices of each body with triangles, body by body.
        nb = len(self.topologies)
        outline = [t.boundary_vertices for t in self.topologies]
        inner = [off_outline(t) for t in self.topologies]
        body_outline = np.zeros(nb + 1, np.int64)
        np.cumsum([len(o) for o in outline], out=body_outline[1:])
        body_interior = np.full(nb + 1, body_outline[-1], np.int64)
        np.cumsum([len(i) for i in inner], out=body_interior[1:])
        body_interior[1:] += body_outline[-1]
        cv, cb, ea, eb, ebody = [np.zeros(0, np.int32)], [np.zeros(0, np.int32)], [np.zeros(0, np.int32)], \
            [np.zeros(0, np.int32)], [np.zeros(0, np.int32)]
        for b, t in enumerate(self.topologies):
            local = np.full(t.n_vertices, -1, np.int64)
            local[outline[b]] = np.arange(len(outline[b])) + body_outline[b]
            cv.append(outline[b] + self.body_vertex_offsets[b])
            cb.append(np.full(len(outline[b]), b))
            ea.append(local[t.boundary_edges[:, 0]])
            eb.append(local[t.boundary_edges[:, 1]])
            ebody.append(np.full(len(t.boundary_edges), b))
        for b in range(nb):
            cv.append(inner[b] + self.body_vertex_offsets[b])
            cb.append(np.full(len(inner[b]), b))
        v = int(body_interior[-1])
        body_tri = np.zeros(nb + 1, np.int64)
        np.cumsum([len(t.triangles) for t in self.topologies], out=body_tri[1:])
        tri = np.empty((body_tri[-1], 3), np.int32)
        for b, t in enumerate(self.topologies):
            tri[body_tri[b]:body_tri[b + 1]] = t.triangles
            if self.body_vertex_offsets[b]:
                tri[body_tri[b]:body_tri[b + 1]] += int(self.body_vertex_offsets[b])

        def i32(parts):
            return np.ascontiguousarray(np.concatenate(parts), dtype=np.int32)
        vertex_cv = np.full(n, -1, np.int32)
        vertex_cv[i32(cv)] = np.arange(v, dtype=np.int32)
        self.contact = ContactTopology(i32(cv), i32(cb), vertex_cv, body_outline, body_interior, tri, body_tri,
                                       i32(ea), i32(eb), i32(ebody),
                                       np.zeros(v), np.zeros(v), np.zeros(nb, np.int32), np.zeros(nb),
                                       np.zeros((nb, 2)), np.array([0.0, np.inf]), np.zeros(nb + 1, np.int64),
                                       np.zeros(0, np.int32), np.zeros(1))
        for b in range(nb):
            if contact is not None:
                self.set_contact_parameters(b, **contact[b])
        # the built-in kinds by name (the compiled drivers and the matrix assembly run them from
        # the arrays above), then the registered kinds' elements
        self.springs = SpringKind(self)
        self.triangles = TriangleKind(self)
        self.elements = [self.springs, self.triangles]
        custom = {}
        for b, m in enumerate(materials):
            kind = element_kind(m.model) if fem[b] and not has_tri[b] else None
            if kind is not None:
                custom.setdefault(kind, []).append(
                    BodyElements(b, self.topologies[b], m, int(self.body_vertex_offsets[b])))
        self.elements += [kind.build(bodies) for kind, bodies in custom.items()]
        # whether the integrators' compiled drivers run every kind (the built-in pair)
        self.fused = all(k.fused for k in self.elements)

    def _torn_elements(self, body: int, old: "Model", old_body: int) -> None:
        """Fill body ``body``'s elements from body ``old_body`` of Model ``old``, which a tear
        turned into this one: it keeps the triangles, in order, with corners at the same rest
        positions (some renumbered onto copies), so the elements keep their order, rest shape
        (as built and where plasticity moved it) and parameters; only their corners are
        read again. Copying them costs a fraction of sorting and gathering them anew."""
        t0, t1 = self.body_elem_offsets[body], self.body_elem_offsets[body + 1]
        o0, o1 = old.body_elem_offsets[old_body], old.body_elem_offsets[old_body + 1]
        v0, v1 = self.body_vertex_offsets[body], self.body_vertex_offsets[body + 1]
        t = self.topologies[body]
        if t1 - t0 != o1 - o0:
            raise ValueError("a torn body keeps its triangles: the Model before has another number of them")
        order = old.elem_source[o0:o1]
        self.elem_source[t0:t1] = order
        np.take(t.triangles, order, axis=0, out=self.elem[t0:t1])
        if v0:
            self.elem[t0:t1] += int(v0)
        for name in ("elem_b", "elem_area", "elem_b0", "elem_area0"):
            getattr(self, name)[t0:t1] = getattr(old, name)[o0:o1]
        area = t.geometry[1] if t.geometry is not None else rest_geometry(t.rest_positions, t.triangles)[1]
        lumped_areas(t.triangles, np.ascontiguousarray(area), self.vertex_area[v0:v1])  # as element_geometry sums them

    def rest_shape(self, body: int):
        """Body ``body``'s rest shape where plasticity moved it, in its topology's order:
        ``(springs (E, 2), rest lengths (E,))`` and ``(B (M, 4), rest areas (M,))`` (``None``
        for a part still as built, or a body without it). A rebuilt Model starts from the
        mesh's rest shape; :meth:`take_rest_shape` gives it this one back, so that dents
        survive a tear, a new body or a new material."""
        s0, s1 = self.body_spring_offsets[body], self.body_spring_offsets[body + 1]
        t0, t1 = self.body_elem_offsets[body], self.body_elem_offsets[body + 1]
        springs = elements = None
        if not np.array_equal(self.spring_rest_length[s0:s1], self.spring_rest_length0[s0:s1]):
            springs = (self.topologies[body].springs, self.spring_rest_length[s0:s1].copy())
        if not (np.array_equal(self.elem_b[t0:t1], self.elem_b0[t0:t1])
                and np.array_equal(self.elem_area[t0:t1], self.elem_area0[t0:t1])):
            order = self.elem_source[t0:t1]
            b = np.empty((t1 - t0, 4))
            area = np.empty(t1 - t0)
            b[order], area[order] = self.elem_b[t0:t1], self.elem_area[t0:t1]
            elements = (b, area)
        return springs, elements

    def take_rest_shape(self, body: int, shape, source=None) -> None:
        """Give body ``body`` the rest shape ``shape`` (:meth:`rest_shape` of the Model before,
        for the same body), where its vertex ``i`` is the old vertex ``source[i]`` (a tear's
        copies: ``None`` for the same vertices). A spring takes the rest length of the old
        spring between its ends' sources; the elements, those of the old triangles in the
        same rows (a tear keeps them in order). Bumps :attr:`version`."""
        springs, elements = shape
        topo = self.topologies[body]
        s0, s1 = self.body_spring_offsets[body], self.body_spring_offsets[body + 1]
        t0, t1 = self.body_elem_offsets[body], self.body_elem_offsets[body + 1]
        if springs is not None and s1 > s0:
            old, rest = springs
            src = np.arange(topo.n_vertices) if source is None else np.asarray(source)
            n_old = int(max(old.max(initial=0), src.max(initial=0))) + 1
            lo, hi = np.sort(src[topo.springs], axis=1).T
            key = lo.astype(np.int64) * n_old + hi
            old_key = old[:, 0].astype(np.int64) * n_old + old[:, 1]  # sorted, as a topology keeps its springs
            at = np.minimum(np.searchsorted(old_key, key), len(old_key) - 1)
            found = old_key[at] == key
            self.spring_rest_length[s0:s1][found] = rest[at[found]]
        if elements is not None and t1 - t0 == len(elements[1]):
            order = self.elem_source[t0:t1]
            self.elem_b[t0:t1] = elements[0][order]
            self.elem_area[t0:t1] = elements[1][order]
        self.version += 1

    def _pressure(self, pressure) -> None:
        from .behaviours.pressure import enclosed_area, outline_loops

        nb = len(self.topologies)
        loops = [np.zeros((0, 2), np.int32)] * nb
        self.body_pressure = np.zeros(nb)
        self.body_pressure_area = np.zeros(nb)
        for b, (t, p) in enumerate(zip(self.topologies, pressure)):
            if p is None:
                continue
            loops[b] = outline_loops(t.rest_positions, t.boundary_edges, t.springs, t.triangles)
            self.body_pressure_area[b] = enclosed_area(t.rest_positions, loops[b][:, 0], loops[b][:, 1])
            self.body_pressure[b] = p
            loops[b] = loops[b] + self.body_vertex_offsets[b]
        self.has_pressure = bool(self.body_pressure.any())  # read every step
        self.body_pressure_offsets = np.zeros(nb + 1, np.int64)
        np.cumsum([len(lp) for lp in loops], out=self.body_pressure_offsets[1:])
        edges = np.concatenate([np.zeros((0, 2), np.int32)] + loops).astype(np.int32)
        self.pressure_a = np.ascontiguousarray(edges[:, 0])
        self.pressure_b = np.ascontiguousarray(edges[:, 1])

    @property
    def n_vertices(self) -> int:
        """Total number of vertices over all bodies."""
        return len(self.vertex_mass)

    @property
    def n_springs(self) -> int:
        """Total number of springs over all bodies."""
        return len(self.spring_i)

    @property
    def n_elements(self) -> int:
        """Total number of triangle elements over all bodies."""
        return len(self.elem)

    def set_body_parameters(self, body: int, *, mass: float, stiffness: float, damping: float) -> None:
        """Write springs body ``body``'s total mass (kg), stiffness (N/m) and damping (N*s/m) into the arrays.

        The caller validates the values; this only spreads them over vertices and springs.
        A finite-element body ignores them (its material sets its masses).
        """
        if self.materials[body] is not None and self.materials[body].is_fem:
            return
        v0, v1 = self.body_vertex_offsets[body], self.body_vertex_offsets[body + 1]
        s0, s1 = self.body_spring_offsets[body], self.body_spring_offsets[body + 1]
        share = self.topologies[body].mass_share
        self.vertex_mass[v0:v1] = mass / (v1 - v0) if share is None else mass * share
        self._inverse_masses(v0, v1)
        self.spring_stiffness[s0:s1] = stiffness
        self.spring_damping[s0:s1] = damping

    def set_body_material(self, body: int, material) -> None:
        """Write finite-element body ``body``'s material: element parameters and vertex masses
        (``density`` times each vertex's lumped area). The body must have been built with a
        finite-element material (switching between springs and elements rebuilds the Model)."""
        if material is None or not material.is_fem or self.materials[body] is None \
                or not self.materials[body].is_fem:
            raise ValueError("set_body_material needs a finite-element body and material; rebuild the Model to "
                             "switch between springs and elements")
        self.materials[body] = material
        t0, t1 = self.body_elem_offsets[body], self.body_elem_offsets[body + 1]
        if t1 > t0:
            mu, lam = material.lame()
            self.elem_mu[t0:t1] = mu
            self.elem_lambda[t0:t1] = lam
            self.elem_damping[t0:t1] = material.damping
            self.elem_kind[t0:t1] = material.kind
        v0, v1 = self.body_vertex_offsets[body], self.body_vertex_offsets[body + 1]
        self.vertex_mass[v0:v1] = material.density * self.vertex_area[v0:v1]
        self._inverse_masses(v0, v1)

    def set_pinned(self, body: int, mask) -> None:
        """Pin (``True``) or free the vertices of body ``body`` (mask over its vertices)."""
        v0, v1 = self.body_vertex_offsets[body], self.body_vertex_offsets[body + 1]
        self.pinned[v0:v1] = mask
        self._inverse_masses(v0, v1)
        self._attachments = {}

    def attachments(self, body: int):
        """Body ``body``'s long-range attachments to its pins (body-local anchor index and path
        length, m; see :func:`deforma.physics.behaviours.strain_limit.attachments`), cached until the pins
        change."""
        cache = self._attachments
        if body not in cache:
            from .behaviours.strain_limit import attachments

            t = self.topologies[body]
            v0, v1 = self.body_vertex_offsets[body], self.body_vertex_offsets[body + 1]
            edges = t.springs if not len(t.triangles) else np.concatenate(
                [t.triangles[:, [0, 1]], t.triangles[:, [1, 2]], t.triangles[:, [2, 0]]])
            cache[body] = attachments(t.rest_positions, edges, self.pinned[v0:v1])
        return cache[body]

    def _inverse_masses(self, v0, v1):
        self.version += 1  # every set_* that changes masses, springs or elements comes here
        # a pinned vertex has infinite mass: no force, impulse or projection moves it
        # (so has a rigid body's, as the soft integrators see it: the rigid stage moves it)
        self.vertex_inv_mass[v0:v1] = np.where(self.pinned[v0:v1] | self.rigid[v0:v1], 0.0,
                                               1.0 / self.vertex_mass[v0:v1])

    def set_joined(self, pairs) -> None:
        """The pairs of bodies ``(a, b)`` a joint holds together: they do not collide with
        each other (``contact.joined_start``, ``contact.joined``)."""
        nb = len(self.contact.body_flags)
        lists = [set() for _ in range(nb)]
        for a, b in pairs:
            lists[a].add(b)
            lists[b].add(a)
        start = np.zeros(nb + 1, np.int64)
        start[1:] = np.cumsum([len(x) for x in lists])
        joined = np.array([b for x in lists for b in sorted(x)], np.int32)
        self.contact = self.contact._replace(joined_start=start, joined=joined)

    def set_contact_parameters(self, body: int, *, collide: bool, self_collision: bool, friction: float,
                               static_friction: float, thickness: float) -> None:
        """Write body ``body``'s contact switches, friction coefficients and thickness (m).

        The self-contact thickness of each boundary vertex is capped at half its rest
        clearance in front of its own outline, so that no body touches itself at rest. The
        caller validates the values.
        """
        c = self.contact
        c.body_flags[body] = (COLLIDE if collide else 0) | (SELF_COLLIDE if self_collision else 0)
        c.body_thickness[body] = thickness
        c.body_friction[body, 0] = friction
        c.body_friction[body, 1] = static_friction
        k0, k1 = c.body_outline[body], c.body_outline[body + 1]
        clear = self.topologies[body].boundary_clearance
        c.thick_other[k0:k1] = thickness
        c.thick_self[k0:k1] = np.minimum(thickness, 0.5 * clear)
        # vertices off the outline only must not cross other bodies' outlines (should their body
        # fold): a hair of thickness, so that their contacts are crossings, put back just in front
        i0, i1 = c.body_interior[body], c.body_interior[body + 1]
        c.thick_other[i0:i1] = SIDE_MARGIN * thickness
        c.margin[0] = SPECULATIVE * float(c.thick_other.max()) if len(c.thick_other) else 0.0

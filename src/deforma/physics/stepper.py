"""One ``World.step``, stage by stage (``docs/architecture.md`` draws it):

1. **inputs**: pack the colliders if they changed, set the grabs and applied forces in the
   :class:`~deforma.physics.control.Control`, copy the State into the step's start; with
   ``world.sleep``, wake every island if the world changed, and integrate nothing when every
   body sleeps (:mod:`~deforma.physics.sleeping`);
2. **gas**: the pressure kick (:func:`~deforma.physics.behaviours.apply_pressure`), unless the
   integrator holds the gas in its solve (``solves_pressure``: avbd);
3. **integrate**: ``integrator.step(model, start, state, control, contacts, h)``, run again
   from the start with a larger contact buffer if it ran out of room; with rigid bodies,
   one substep at a time, each followed by the rigid stage
   (:func:`~deforma.physics.rigid.stage.step_rigid_bodies`: the rigid bodies and joints);
4. **colliders**: the collider objects follow their motion; nothing may be left inside one;
5. **behaviours**: stretch limit and plasticity, then tearing (a torn body gets a new Model);
6. **checks**: every ``SHAPE_CHECK_EVERY`` steps, no body may have lost its shape;
7. **after**: the step stands; the contacts it ended with are kept for
   ``world.contact_pairs()``, islands fall asleep or wake, the contact listeners hear of pairs
   that began or ended touching (:mod:`~deforma.physics.events`), and joints past their
   ``break_force`` break.

A stage that finds the step gone wrong raises :class:`~deforma.physics.diagnostics.SimulationUnstable`;
the World is then put back exactly as it was before the step (:class:`Undo`): positions,
velocities, plastic rest shapes, torn topology, collider poses, grabs. So it is after any
other error or an interrupt (Ctrl-C) during a step: no half-made step stays.
"""

from __future__ import annotations

import warnings

import numpy as np

from . import behaviours
from .behaviours import tearing
from .colliders.response import clear_impulses
from .joint import pack_rows, read_rows
from .rigid.stage import begin_joint_forces, end_joint_forces, rigid_set, step_rigid_bodies
from .diagnostics import SHAPE_CHECK_EVERY, lost_shape, runaway, trapped
from .topology import BodyTopology

REPACK_EVERY = 64  # steps: moving colliders are packed again from their objects this often


class Undo:
    """What a step may change, kept at its start so that a failed step leaves the World as it
    was: the State (``start``, which the integrator reads and never writes), the Model and
    the plastic rest shape (copied only when a check after plasticity can fail this step),
    the tearing bodies' topology, the moving colliders' poses and the lost-shape counts."""

    def __init__(self, world, poses, *, late_check: bool):
        self.state = world._state
        self.model = world._model
        self.model_bodies = world._model_bodies
        self.control = world._control
        self.contacts = world._contacts
        self.lost_shape = dict(world._lost_shape)
        self.poses = poses  # (collider, center, angle) of the moving ones
        m = self.model
        self.bodies = [(b, b._tear_state()) for b, mat in zip(world._bodies, m.materials)
                       if mat is not None and mat.tear_strain is not None]
        self.rest_shape = None
        if late_check and any(mat is not None and mat.yield_strain is not None for mat in m.materials):
            self.rest_shape = (m.spring_rest_length.copy(), m.elem_b.copy(), m.elem_area.copy(), m.version)

    def restore(self, world, start) -> None:
        """Put ``world`` back as it was when this was made; ``start`` holds its State."""
        world._model = self.model
        world._model_bodies = self.model_bodies
        world._control = self.control
        world._contacts = self.contacts
        world._state = self.state
        world._state.assign(start)
        world._lost_shape = self.lost_shape
        world._grabs_dirty = True
        if self.rest_shape is not None:
            m = self.model
            rest, b, area, version = self.rest_shape
            m.spring_rest_length[...] = rest
            m.elem_b[...] = b
            m.elem_area[...] = area
            m.version = version
        for body, state in self.bodies:
            body._set_tear_state(state)
        for c, center, angle in self.poses:
            c._set_pose(center, angle)


def step(world) -> None:
    """Advance ``world`` by ``world.dt`` (the stages of the module docstring)."""
    w = world
    poses = [(c, c.center, c.angle) for c in w._colliders if c.moving]
    # the rigid stage after each substep, unless the integrator solves the rigid bodies itself
    rigid = bool(w._model.n_vertices) and w._model.rigid.any() and not w._rigid_in_solve()
    # the joints as rows of the integrator's sweep, where it moves the rigid bodies
    rows = None if rigid or not w._joints else pack_rows(w._joints, w._model, rigid_set(w._model).bodies)
    w._model.joints = rows
    moving = bool(poses) or rigid  # the rigid bodies' outlines move as colliders
    moved = w._colliders_changed() or rigid
    if moved:
        w._pack_colliders()
    if moving:
        # the kernels move the packed copies: until the objects follow (at the end of a
        # step that succeeds), the packed array is not theirs
        w._packed_colliders = None
    if w._sleep:
        key = w._world_key()
        if key != w._sleep_key:  # a parameter, the bodies, the joints or a still collider changed
            w._wake(w._bodies)
            w._sleep_key = key
        w._wake_approached()
    # no body, or every body asleep and no collider moving: nothing to integrate
    idle = not w._model.n_vertices or (w._sleep and not poses and all(b._asleep for b in w._bodies))
    if idle:  # moving colliders still move
        for c in w._colliders:
            c.advance(w.dt)
        w._forces.clear()
        w.time += w.dt
        w.step_count += 1
        return
    if w._grabs_dirty:
        w._rebuild_grabs()
    if w._auto:  # substeps = "auto": chosen again when what the stable step depends on changed
        w._substeps = w._auto_substeps()  # StepTooLong (a SimulationUnstable) past the limit
    control = w._control
    control.step = w.step_count
    if control.has_force:
        control.clear_force()
    for body, vertices, forces in w._forces:  # body-local vertices: a rebuild since kept them
        control.add_force(body.vertex_slice.start + vertices, forces)
    start = w._start
    start.assign(w._state)
    undo = Undo(w, poses, late_check=w.step_count % SHAPE_CHECK_EVERY == 0)
    try:
        if rigid:
            # the rigid bodies take the soft bodies' impulses after every soft substep, not
            # once a step: a soft body held by an outline that stands still for a whole step
            # stores the push as elastic energy and the rigid body gets the momentum besides
            # (measured: a jelly ball into a crate at 1/60 s gained 11 % energy; substep by
            # substep, none)
            sub, h = w._sub_start, w.dt / w._substeps
            begin_joint_forces(w)
            for _ in range(w._substeps):
                sub.assign(w._state)
                _integrate(w, sub, moving, 1)
                step_rigid_bodies(w, sub, w._state, control, w._contacts.hits, w._control.colliders,
                                  len(w._colliders), h)
            end_joint_forces(w, w.dt)
        else:
            _integrate(w, start, moving, w._substeps)
        # the contacts as the integrator left them, in the numbering of the Model it stepped
        # (a tear below may renumber the vertices)
        record = (w._model, w._model_bodies, w._integrator.contact_impulses(w._model))
        for c, _, _ in poses:  # the kernels moved the packed copies; now the objects
            c.advance(w.dt)
        if moved or poses:
            error = trapped(w, w._model, w._state, w.step_count)
            if error is not None:
                raise error
        if poses and not rigid and w.step_count % REPACK_EVERY:
            # the packed copies are where the objects now are (up to rounding, which a
            # repack every REPACK_EVERY steps clears): no repack next step
            w._packed_colliders = w._collider_key()
        behaviours.limit_and_yield(w._model, start, w._state, w.dt)
        tear_bodies(w)
        if w.step_count % SHAPE_CHECK_EVERY == 0:
            error = lost_shape(w, w._model, w._state, w._lost_shape, w.step_count)
            if error is not None:
                raise error
    except BaseException:  # SimulationUnstable, and any error or interrupt: no half-made step stays
        undo.restore(w, start)
        if moving:
            w._packed_colliders = None
        raise
    if rows is not None:
        read_rows(w._joints, rows, w.dt)
    kept_awake = {id(g.body) for g in w._grabs if g.body is not None} | {id(b) for b, _, _ in w._forces}
    w._forces.clear()
    w.time += w.dt
    w.step_count += 1
    w._contact_record = record
    if w._sleep:
        w._update_sleep(kept_awake)
    if w._events.listening:
        w._events.contacts(w._pairs(), w.step_count, w.time)
    if w._joints:
        w._break_joints()


def _integrate(w, start, moving: bool, substeps: int) -> None:
    """Stages 2 and 3 over ``substeps`` of the step's substeps: the gas kick and the
    integrator, again from ``start`` with a larger contact buffer while it runs out of room."""
    integrator, contacts, state = w._integrator, w._contacts, w._state
    h = w.dt / w._substeps  # the count in force (the public getter would check "auto" again)
    rects = w._control.colliders.copy() if moving else None  # where the packed colliders start
    while True:
        if w._model.has_pressure and not integrator.solves_pressure:
            behaviours.apply_pressure(w._model, state, h * substeps)
        contacts.clear_needed()
        if w._model.rigid.any():  # the impulses the rigid bodies take are this run's alone
            clear_impulses(contacts.hits)
        report = integrator.step(w._model, start, state, w._control, contacts, h, substeps=substeps,
                                 max_speed=w.max_speed)
        if report.complete:
            break
        # the contact buffer was too small: grow it and run the step again from its start
        state.assign(start)
        if moving:  # the kernels moved the packed colliders: back to the start
            w._control.colliders[...] = rects
        contacts.grow()
    if report.unconverged:
        # the step stands (it is as good as the iterations made it), so a warning, not an
        # error; one text, so Python shows it once where it is not filtered otherwise
        warnings.warn("the implicit solve stopped at max_iterations short of its tolerance in some "
                      "substeps (world.integrator_stats counts them): raise max_iterations or tolerance, "
                      "or take more substeps", RuntimeWarning, stacklevel=3)
    if report.bad_vertices:
        raise runaway(w, w._model, state, start, w._control, w.step_count,
                      unconditionally_stable=integrator.unconditionally_stable)


def tear_bodies(world) -> None:
    """Split the meshes of bodies stretched beyond their ``tear_strain`` (see
    :mod:`deforma.physics.behaviours.tearing`); rebuilds the Model when any tore, telling it
    which vertices each new one copies (``Model.torn_from``), so that a solver can carry over
    what it built for the old one."""
    w = world
    torn = False
    for body, material in zip(w._bodies, w._model.materials):  # the Model's: body.material makes one
        limit = None if material is None else material.tear_strain
        if limit is None:
            continue
        topo = body.topology
        x = w._state.x[body.vertex_slice]
        if not len(topo.triangles):
            keep = tearing.snap_springs(x, topo.springs, topo.spring_rest_length, limit)
            if not keep.all():
                body.topology = BodyTopology.from_arrays(topo.rest_positions, topo.springs[keep],
                                                         mass_share=topo.mass_share)
                body._tear_fresh = np.unique(topo.springs[~keep])
                torn = True
            continue
        cut = tearing.tear_mesh(body._tear_view(), x, limit, tips=body._crack_tips())
        if cut is None:
            body._cracks = None  # every crack stopped: a new one may start
            continue
        body._tear_fresh = np.union1d(cut.triangles[cut.changed], topo.triangles[cut.changed])  # old, new corners
        body._apply_tear(cut)
        torn = True
    if not torn:
        return
    old = w._model
    off = old.body_vertex_offsets
    source = np.concatenate([np.arange(off[i], off[i + 1])[b._tear_source] for i, b in enumerate(w._bodies)])
    # np.take: NumPy's fancy indexing gathers (N, 2) rows 15x slower (0.23 against 0.016 ms at 1e4)
    w._rebuild(np.take(w._state.x, source, axis=0), np.take(w._state.v, source, axis=0))
    new_off = w._model.body_vertex_offsets
    fresh = np.zeros(w._model.n_vertices, bool)
    for i, body in enumerate(w._bodies):
        fresh[new_off[i] + body._tear_fresh] = True
        body._tear_source = slice(None)
        body._tear_fresh = np.zeros(0, np.int64)
    w._model.torn_from = (old.serial, source, fresh, w._model.version)

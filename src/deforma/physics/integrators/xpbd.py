"""XPBD: extended position-based dynamics (Macklin et al. 2016) with small substeps
(Macklin et al. 2019, "Small Steps in Physics Simulation").

Per substep ``h``::

    x_prev = x;  v = (v + h g) / (1 + h air_drag);  x += h v      # predict
    list the collider and body contacts of the predicted motion
    repeat iterations times (Gauss-Seidel):
        project the collider contacts (out of the collider, with friction)
        project the body contacts (split by inverse mass)
        for each spring in order:
            C = |x_ij| - l,   d = x_ij / |x_ij|
            dlam = -(ks h^2 C + lam + kd h d . (dx_j - dx_i)) / ((ks h^2 + kd h)(w_i + w_j) + 1)
            lam += dlam;  x_j += w_j d dlam;  x_i -= w_i d dlam
    v = (x - x_prev) / h
    x, v = collide(x_prev, x, v);  contact stage

with ``w = 1/m`` and ``dx = x - x_prev``. This is Macklin's update with compliance
``alpha = 1 / ks`` and damping ``beta = kd`` (``alpha~ = alpha / h^2``, ``gamma = alpha~
beta~ / h = kd / (ks h)``), multiplied through by ``ks h^2`` so that ``ks = 0`` (no spring)
needs no special case. When the iteration converges, ``lam / h^2`` is the spring force
``-ks C - kd dC/dt`` of the symplectic path evaluated at the end of the substep: XPBD then
solves the same backward Euler equations as ``"implicit-euler"`` (without the geometric
stiffness term), so the same ``stiffness`` and ``damping`` mean the same material.

The mouse pull ``S (target - x)`` is a zero-length spring to the target with compliance
``1/S``, solved per held vertex before the springs (exactly, as it involves one vertex),
so a strong pull cannot blow up either. Gravity enters the prediction.

Contacts are in the sweep (Macklin et al. 2020, "Detailed Rigid Body Simulation with
Extended Position Based Dynamics"), so the floor's support and a neighbour's push travel
through the body within it. A collider contact sticks or slides as decided once per substep
from its predicted push (the collider rule's impulse): stuck, its tangential motion since the
substep began is undone in every sweep; sliding, each sweep holds it back by ``friction``
times that sweep's push. Body contacts are found for the predicted motion by the contact
stage's own broad and narrow phase (:func:`~deforma.physics.contact.narrow_phase.detect_contacts`) and
projected as the stage projects them, with the same position-level friction as colliders
(stick or slide decided by the first sweep; :func:`~deforma.physics.contact.response.project_contacts`).
That friction matters where the sweep itself separates a pair (a thick contact, a fast hit):
the contact stage after the sweep then sees no approach and gives no friction impulse.
Resting pairs are held by the stage's speculative contacts, which carry friction. A pair
that starts the substep closer than its target is held there, not pushed apart (velocities
come from positions: :func:`~deforma.physics.contact.response.hold_start_distance`). The full
collider response and contact stage still run after the sweep.

One Gauss-Seidel sweep per substep (``iterations = 1``, the "small steps" choice) carries
a correction across about one spring per substep against the sweep order (and across the
whole body along it), so a large stiff body behaves softer than ``ks`` unless the substeps
are many; ``docs/integrators.md`` gives measured figures. The sweep is serial and goes
colour by colour (:func:`sweep_order`: no two springs, or elements, of a colour share a
vertex), the elements' colours in an order drawn afresh for each step from the step's index
(``control.step``, :func:`colour_sequence`), so results are deterministic, and a step
repeated (after a failure, or after the contact buffer grew) draws the same order.

Units: m, m/s, kg, N/m, N*s/m, s.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..colliders.geometry import advance_colliders
from ..contact.response import project_contacts
from ..elements.kind import COLOURS, colour_sequence, sweep_order
from ..elements.springs import project_springs
from ..elements.triangles import project_elements
from .base import (Integrator, Option, StepReport, contact_epilogue, finish_position_step, held_contacts,
                   register_integrator)


@njit(cache=True)
def predict(x, v, x_prev, inv_mass, gx, gy, keep, force, has_force, grab_slot, grab_pull, h):
    """Start an XPBD substep: ``x_prev = x``, the velocity kicked by gravity and the applied
    ``force`` (if ``has_force``) and damped by air drag (``keep = 1 / (1 + h air_drag)``),
    ``x`` moved to its prediction ``x + h v``, and a held vertex pulled to its grab target
    exactly (a zero-length spring of compliance ``1 / S``). A pinned vertex stays.

    ``inv_mass`` is the constraints' inverse mass, ``keep`` times the vertex's (air drag's
    heavier mass, :meth:`XPBD.step`): the force's share is divided by ``keep`` again."""
    h2 = h * h
    for i in range(x.shape[0]):
        x_prev[i, 0] = x[i, 0]
        x_prev[i, 1] = x[i, 1]
        if inv_mass[i] == 0.0:  # pinned: it stays
            v[i, 0] = 0.0
            v[i, 1] = 0.0
            continue
        if has_force:
            v[i, 0] = (v[i, 0] + h * (gx + force[i, 0] * inv_mass[i] / keep)) * keep
            v[i, 1] = (v[i, 1] + h * (gy + force[i, 1] * inv_mass[i] / keep)) * keep
        else:
            v[i, 0] = (v[i, 0] + h * gx) * keep
            v[i, 1] = (v[i, 1] + h * gy) * keep
        px = x[i, 0] + h * v[i, 0]
        py = x[i, 1] + h * v[i, 1]
        g = grab_slot[i]
        if g >= 0:
            # zero-length spring to the target with compliance 1/S, solved exactly:
            # x = (x* + h^2 w S t) / (1 + h^2 w S)
            a = h2 * inv_mass[i]
            den = 1.0 + a * grab_pull[g, 0]
            px = (px + a * grab_pull[g, 1]) / den
            py = (py + a * grab_pull[g, 2]) / den
        x[i, 0] = px
        x[i, 1] = py


@njit(cache=True)
def project_collider_contacts(x, x_prev, inv_mass, planes, touch, count):
    """One sweep over the collider contacts ``planes[:count]`` (vertices ``touch``): each
    vertex put back on the outside of its plane, with Coulomb friction at position level.

    Stick or slide is decided once, by the first sweep (``planes[k, 7]`` -1: not yet; the
    predicted motion's push is the substep's normal impulse, as in the collider rule): a stuck
    vertex has its tangential motion since the substep began undone in every sweep, a sliding
    one is held back by the dynamic coefficient times each sweep's push (relative to the
    collider's surface, which moved by ``planes[k, 5:7]``).
    """
    for k in range(count):
        i = touch[k]
        nx, ny = planes[k, 0], planes[k, 1]
        gap = x[i, 0] * nx + x[i, 1] * ny - planes[k, 2]
        if inv_mass[i] == 0.0:
            continue
        push = -gap if gap < 0.0 else 0.0
        # tangential motion since the substep began (t = (-ny, nx))
        slide = (x_prev[i, 0] + planes[k, 5] - x[i, 0]) * -ny + (x_prev[i, 1] + planes[k, 6] - x[i, 1]) * nx
        if planes[k, 7] < 0.0:
            planes[k, 7] = 1.0 if abs(slide) <= planes[k, 3] * push else 0.0
        if planes[k, 7] == 0.0:
            slide = min(abs(slide), planes[k, 4] * push) * (1.0 if slide > 0.0 else -1.0)
        x[i, 0] += push * nx - slide * ny
        x[i, 1] += push * ny + slide * nx


@njit(cache=True)
def xpbd_substeps(x, v, x_prev, lam, planes, touch, inv_mass, springs, spring_order, tris, elem_order, elem_starts,
                  seed, elem_lam_acc, gx, gy, keep, force, has_force, grab_slot, grab_pull, rects, hits, ctopo, cscr,
                  cbuf, h, substeps, iterations, vmax2):
    """``substeps`` XPBD substeps of ``h`` s with ``iterations`` Gauss-Seidel sweeps each,
    over the built-in element kinds (springs and triangles): the compiled driver for them.

    Parameters
    ----------
    x, v : (N, 2) float64
        Positions (m) and velocities (m/s), advanced in place.
    x_prev : (N, 2) float64
        Scratch: positions at the start of the current substep.
    lam : (E,) float64
        Scratch: accumulated multipliers (N s^2).
    planes, touch : (N, 8) float64, (N,) int32
        Scratch: the collider contacts of the substep
        (:func:`~deforma.physics.colliders.response.contact_planes`; column 7: 1 stuck, 0 sliding).
    inv_mass : (N,) float64
        1/kg.
    springs : SpringArrays
        The springs (:class:`~deforma.physics.elements.springs.SpringArrays`: ends, rest
        lengths m, stiffness N/m, damping N*s/m).
    spring_order : (E,) int64
        The springs by colour (:func:`sweep_order`), the order of every sweep.
    tris : TriangleArrays
        Triangle elements (:class:`~deforma.physics.elements.triangles.TriangleArrays`).
    elem_order, elem_starts : (T,) int64, (COLOURS + 1,) int64
        The elements by colour and where each colour starts.
    seed : int
        Picks the order of the elements' colours in this call's sweeps
        (:func:`colour_sequence`).
    elem_lam_acc : (T, 3) float64
        Scratch: the elements' accumulated multipliers.
    gx, gy : float
        Gravity (m/s^2).
    keep : float
        ``1 / (1 + h air_drag)``: the part of each velocity air drag leaves per substep.
    force : (N, 2) float64
        Applied forces (N), read if ``has_force``.
    grab_slot : (N,) int32
        Grab entry per vertex or -1.
    grab_pull : (K, 3) float64
        ``(S, S tx, S ty)`` per grab entry (N/m, N).
    rects : (R, RECT_COLUMNS) float64
        Packed colliders.
    hits : ColliderHits
        Collider contacts, per vertex.
    ctopo, cscr, cbuf : namedtuples
        The contact stage's topology, scratch and buffer (:mod:`deforma.physics.contact`).
    h : float
        Substep (s).
    substeps, iterations : int
        Counts.
    vmax2 : float
        Squared runaway speed (m^2/s^2).

    Returns
    -------
    int
        Vertices that ended non-finite or faster than ``sqrt(vmax2)`` (0 if all is well;
        stops after the first bad substep).

    Examples
    --------
    >>> import numpy as np
    >>> from deforma.physics.contact.contacts import empty_topology, make_buffer, make_scratch
    >>> from deforma.physics.colliders.response import make_hits
    >>> from deforma.physics.elements.springs import SpringArrays
    >>> from deforma.physics.elements.triangles import TriangleArrays
    >>> x, v = np.array([[0.0, 0.0], [1.5, 0.0]]), np.zeros((2, 2))
    >>> ends = np.array([0], np.int32), np.array([1], np.int32)
    >>> spring = SpringArrays(*ends, np.ones(1), np.full(1, 1e9), np.zeros(1))
    >>> none = TriangleArrays.empty()
    >>> bad = xpbd_substeps(x, v, x.copy(), np.zeros(1), np.zeros((2, 8)), np.zeros(2, np.int32), np.ones(2),
    ...                     spring, sweep_order(np.array([[0, 1]], np.int32), 2)[0], none,
    ...                     *sweep_order(none.elem, 2), 0, np.zeros((0, 3)), 0.0, 0.0, 1.0, np.zeros((0, 2)), False,
    ...                     np.full(2, -1, np.int32), np.zeros((0, 3)), np.zeros((0, 21)), make_hits(2),
    ...                     empty_topology(), make_scratch(0, 0), make_buffer(0, 0), 0.01, 1, 1, 1e6)
    >>> round(float(x[1, 0] - x[0, 0]), 4)  # a very stiff spring snaps to its rest length
    1.0
    """
    sequence = np.empty(COLOURS, np.int64)
    plane_rows = np.empty(touch.shape[0], np.int32)  # (rigid outlines are met after the sweep)
    for sub in range(substeps):
        advance_colliders(rects, h)  # moving colliders to where they are at the end of the substep
        predict(x, v, x_prev, inv_mass, gx, gy, keep, force, has_force, grab_slot, grab_pull, h)
        for e in range(springs.i.shape[0]):
            lam[e] = 0.0
        for e in range(tris.elem.shape[0]):
            elem_lam_acc[e, 0] = 0.0
            elem_lam_acc[e, 1] = 0.0
            elem_lam_acc[e, 2] = 0.0
        count, n_body = held_contacts(x_prev, x, rects, planes, touch, plane_rows, False, h, ctopo, cscr, cbuf)
        for k in range(count):
            planes[k, 7] = -1.0  # stick or slide: not decided yet
        if n_body < 0:
            return 0  # the contact buffer is too small; the world grows it and repeats the step
        stick = np.full(n_body, -1.0)  # the body contacts' stick or slide: not decided yet
        for it in range(iterations):
            if sub == 0 and it == 0:
                colour_sequence(seed, sequence)
            # collider contacts first, so that the springs carry their support through the sweep
            project_collider_contacts(x, x_prev, inv_mass, planes, touch, count)
            project_contacts(x, x_prev, inv_mass, ctopo, cbuf, n_body, stick)
            project_springs(x, x_prev, inv_mass, springs.i, springs.j, springs.rest, springs.ks, springs.kd,
                            spring_order, lam, h)
            project_elements(x, x_prev, inv_mass, tris.elem, tris.b, tris.area, tris.mu, tris.lam, tris.beta, tris.kind,
                             elem_order, elem_starts, sequence, elem_lam_acc, h)
        bad = finish_position_step(x, v, x_prev, rects, hits, cscr.status.stamp[0] + 1, h, vmax2)
        if bad:
            return bad
        # cscr.xp still holds x_prev (detect_contacts only read it): no second gather_start
        if contact_epilogue(x, v, inv_mass, x_prev, ctopo, cscr, cbuf, rects, hits, h, True) < 0:
            return 0  # the contact buffer is too small; the world grows it and repeats the step
    return 0


@register_integrator("xpbd")
class XPBD(Integrator):
    """XPBD with substeps: compliance ``1 / stiffness``, damping ``kd`` along each spring.

    Unconditionally stable (a constraint projection cannot overshoot); a large stiff body
    needs many substeps to look as stiff as ``stiffness`` says (``world.substeps``).

    Options
    -------
    iterations : int
        Gauss-Seidel sweeps over the springs and elements per substep (in [1, 10000];
        default 1, as in "Small Steps": more substeps beat more iterations).

    Examples
    --------
    >>> from deforma.physics.integrators import make_integrator
    >>> make_integrator("xpbd").options["iterations"]
    1
    """

    name = "xpbd"
    unconditionally_stable = True
    OPTIONS = (Option("iterations", 1, "int", low=1, high=10_000,
                      doc="Gauss-Seidel sweeps per substep (more substeps beat more sweeps)"),)

    def __init__(self, **options):
        super().__init__(**options)
        self._n = (-1, -1, -1)
        self._orders = (None,)  # (model, spring order, element order, where each colour starts)
        self._heavy = None  # (model, version, keep, the constraints' inverse masses)

    def step(self, model, state_in, state_out, control, contacts, h, *, substeps=1, max_speed=math.inf):
        shape = (model.n_vertices, model.n_springs, model.n_elements)
        if self._n != shape:  # scratch kept between steps
            self._x_prev = np.empty((shape[0], 2))
            self._lam = np.empty(shape[1])
            self._elem_lam = np.empty((shape[2], 3))
            self._planes = np.empty((shape[0], 8))
            self._touch = np.empty(shape[0], np.int32)
            self._plane_rows = np.empty(shape[0], np.int32)
            self._n = shape
        if self._orders[0] is not model:  # a Model's springs and elements never change in place
            self._orders = (model, sweep_order(np.stack([model.spring_i, model.spring_j], axis=1), shape[0])[0],
                            *sweep_order(model.elem, shape[0]))
        gx, gy = model.gravity
        keep = 1.0 / (1.0 + float(h) * model.air_drag)
        inv_mass = self._heavier(model, keep)
        if not model.fused:
            bad = self._step_kinds(model, state_out, control, contacts, h, substeps, max_speed, inv_mass)
            return StepReport(int(bad), contacts.complete)
        # the colours' order is drawn from the step's index: a step repeated (after the
        # contact buffer grew) draws the same
        bad = xpbd_substeps(state_out.x, state_out.v, self._x_prev, self._lam, self._planes, self._touch,
                            inv_mass, model.springs.arrays, self._orders[1], model.triangles.arrays,
                            self._orders[2], self._orders[3], int(control.step), self._elem_lam,
                            float(gx), float(gy), keep, control.force,
                            control.has_force, control.grab_slot, control.grab_pull, control.colliders, contacts.hits,
                            model.contact, contacts.scratch, contacts.buffer, float(h), int(substeps),
                            int(self._options["iterations"]), float(max_speed) ** 2)
        return StepReport(int(bad), contacts.complete)

    def _heavier(self, model, keep):
        """The constraints' inverse masses: ``keep`` times the vertices' (air drag's heavier
        mass, ``M (1 + h air_drag)``, as in implicit Euler). Air drag -c v joins backward
        Euler as ``(1 + h c) M (x - y) / h^2 = f(x)`` with the prediction ``y`` damped by
        ``keep``: with the plain mass, the springs and elements balanced ``keep`` times
        gravity, and a hanging body at 1/60 s with ``air_drag = 5`` rested 8% short of its
        stretch. Made once per Model, ``h`` and air drag."""
        if keep == 1.0:
            return model.vertex_inv_mass
        key = (model, model.version, keep)
        if self._heavy is None or self._heavy[0] is not model or self._heavy[1:3] != key[1:]:
            self._heavy = (*key, model.vertex_inv_mass * keep)
        return self._heavy[3]

    def _step_kinds(self, model, state, control, contacts, h, substeps, max_speed, inv_mass) -> int:
        """:func:`xpbd_substeps` with the loop over the element kinds in Python: each kind
        projects its own constraints (``ElementKind.project``) where the compiled driver
        projects the springs and triangles. The same arithmetic, in the same order."""
        x, v = state.x, state.v
        gx, gy = model.gravity
        keep = 1.0 / (1.0 + float(h) * model.air_drag)
        rects, topo, scr, buf = control.colliders, model.contact, contacts.scratch, contacts.buffer
        sequence = np.empty(COLOURS, np.int64)
        colour_sequence(int(control.step), sequence)
        vmax2 = float(max_speed) ** 2
        for _ in range(substeps):
            advance_colliders(rects, h)
            predict(x, v, self._x_prev, inv_mass, float(gx), float(gy), keep, control.force,
                    control.has_force, control.grab_slot, control.grab_pull, h)
            for kind in model.elements:
                kind.begin_substep()
            count, n_body = held_contacts(self._x_prev, x, rects, self._planes, self._touch, self._plane_rows, False, h,
                                          topo, scr, buf)
            self._planes[:count, 7] = -1.0  # stick or slide: not decided yet
            if n_body < 0:
                return 0  # the contact buffer is too small; the world grows it and repeats the step
            stick = np.full(n_body, -1.0)
            for _ in range(self._options["iterations"]):
                project_collider_contacts(x, self._x_prev, inv_mass, self._planes, self._touch, count)
                project_contacts(x, self._x_prev, inv_mass, topo, buf, n_body, stick)
                for kind in model.elements:
                    kind.project(x, self._x_prev, inv_mass, h, sequence)
            bad = finish_position_step(x, v, self._x_prev, rects, contacts.hits, scr.status["stamp"][0] + 1, h,
                                       vmax2)
            if bad:
                return bad
            if contact_epilogue(x, v, inv_mass, self._x_prev, topo, scr, buf, rects, contacts.hits, h, True) < 0:
                return 0
        return 0

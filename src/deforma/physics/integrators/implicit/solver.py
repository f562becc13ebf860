"""Implicit (backward) Euler for the mass-spring system, solved by prefactored local/global steps.

Backward Euler (Baraff & Witkin 1998) asks for the end-of-substep state, per substep ``h``::

    M (x - x_n - h v_n) / h^2 = f_spring(x, v) + f_grab(x) + M g,   v = (x - x_n) / h

Following Liu et al. 2013 ("Fast Simulation of Mass-Spring Systems"), this is the minimum of

    1/2 |x - y|_M^2 + h^2 sum_e ks_e/2 |x_ij - l_e d_e|^2 + h kd_e/2 |x_ij - p_e|^2
                   + h^2 sum_grab S/2 |x - target|^2,          y = x_n + h v_n + h^2 g

over ``x`` and over the auxiliary spring directions ``d_e`` (unit vectors) and damping
targets ``p_e``. With ``d_e`` and ``p_e`` fixed this is quadratic in ``x`` with the constant
matrix ``A = M + L_w + h^2 S_grab`` (``L_w`` the graph Laplacian with spring weights
``w_e = h^2 ks_e + h kd_e``); with ``x`` fixed the best ``d_e`` is the spring's current
direction. Alternating the two (the *local* step per spring, the *global* solve with
``A``) lowers the objective every iteration, and ``A`` is factored once (SuperLU,
symmetric mode with a minimum-degree ordering) and reused until the mass, stiffness,
damping or ``h`` change (small changes are corrected, not refactored: see below).

Damping. The spring damping force ``kd ((v_j - v_i) . d) d`` of the symplectic path is
kept exactly: backward Euler's damping term ``h kd/2 ((x_ij - x_ij^n) . d)^2`` equals
``h kd/2 |x_ij - p_e|^2`` with ``p_e = x_ij - ((x_ij - x_ij^n) . d) d``, the projection of
``x_ij`` onto the line of zero relative velocity along the spring, so it fits the same
local/global scheme and the same constant matrix. It damps only the stretch rate, never
rigid rotation (a spinning body keeps spinning).

The mouse pull is in the matrix (it changes ``A``'s diagonal, so a new grab or release
changes the factor; moving a held grab changes only the right-hand side). Gravity is in ``y``.

Every element kind takes part the same way (:mod:`deforma.physics.elements.kind`): its
``matrix_weights`` and ``matrix_entries`` give its part of ``A`` (the springs' ``L_w``, the
triangles' ``sum_e w_e D D^T``), its ``rhs`` its local step at the current iterate
(:func:`inertia_rhs` gives ``M y`` and the grabs'). The built-in kinds' part of ``A`` is
assembled in one compiled pass (:func:`~deforma.physics.integrators.implicit.assembly.system_matrix`);
another kind's entries are merged into it.

Contacts are inside the solve (the projective-dynamics way). The vertices whose
prediction ``y`` lies inside a collider are listed with the plane of the face they would
leave by (:func:`~deforma.physics.colliders.response.contact_planes`); each gets the term
``k_c/2 |x - P(x)|^2``, ``k_c = contact_weight * A_ii``, whose local step
(:func:`contact_rhs`) projects onto the outside of the plane with Coulomb friction at
position level (the prediction in the first iteration, then where a Jacobi step of the
contact-free system would move the iterate: :func:`free_estimate`), and whose weight joins
``A``'s diagonal. A vertex already outside projects to itself, so an inactive contact
exerts no force at convergence. A new
contact set changes the factor; a resting or sliding body keeps its set, and its factor, for
many steps (docs/integrators.md says why this and not an iterative solve). After the solve the
shared collider response (:func:`~deforma.physics.integrators.base.finish_position_step`) and the
body contact stage run as in the symplectic path, so nothing ends inside a collider or
across an outline; the stage's impulses change velocities only, not positions
(:func:`~deforma.physics.contact.stage.contact_stage` says why).

A rigid body's outline (:mod:`deforma.physics.rigid`) gives planes too, moving with the
velocity the body will have once the vertices headed into it stick to it
(:func:`recoil_planes`: a wall moving at the body's own velocity made a light crate take a
heavy jelly's whole stop, and fly off with more energy than the jelly brought); after the
solve each of its planes' forces goes back to the body (:func:`rigid_plane_impulses`), and
points still inside it are met between two masses
(:func:`~deforma.physics.colliders.response.collide_dynamic`). Met only after the solve, a
rubber donut thrown into crates at 5 m/s folded over them and ran away.

Body contacts are in the solve too: the contacts of the predicted motion
(:func:`~deforma.physics.contact.narrow_phase.detect_contacts`) each add a spring between the vertex and
the edge point, ``k_c/2 |D x - q|^2`` with ``D x = x_p - (1 - s) x_a - s x_b``, whose
coefficients sum to zero (linear momentum kept exactly); :func:`body_contact_rhs` is its
local step. A pair closer than its target at the start of the substep is held there rather
than pushed apart (:func:`~deforma.physics.contact.response.hold_start_distance`). Its entries join
the matrix, so a new set of pairs changes the factor; a pair keeps the ``s`` it had when the matrix
was built, also when other pairs come or go. The contact-free matrix is assembled once per Model
(:func:`system_matrix`) and a new contact set merges the contacts' entries into it
(:func:`with_entries`), each in one compiled pass: with SciPy's sparse sums this took 1.5
ms per refactor of the ``pile`` (2458 vertices), now 0.56 ms. A new contact set, a grab or
a tear is then taken into the factor by a low-rank correction while it is small
(:mod:`~deforma.physics.integrators.implicit.updated_factor`), and the matrix is factored again once the
changes add up.

Solved to a tolerance (``tolerance > 0``; ``implicit-bdf2``'s default). The local/global
iteration is a fixed-point map whose fixed point is the backward Euler step; it converges
linearly, and slowly where the constant matrix misses the motion: a stiff body's rotation
is not in ``A`` (the local step lags one iteration), so three fixed iterations kept 6 % of a
spinning box's angular momentum after one second at 1/60 s, where backward Euler keeps 75 %.
Each substep therefore iterates until the objective's gradient, taken as a force on each vertex's own mass for the substep,
would change no velocity by more than ``tolerance`` (m/s), at least ``iterations`` and at
most ``max_iterations`` times, Anderson-accelerated
(:mod:`~deforma.physics.integrators.implicit.anderson`); the contacts' local steps then
project the iterate itself, so that the fixed point is the minimum of the objective with the
contact terms. A substep that reaches ``max_iterations`` first stands as it is and is counted
(``StepReport.unconverged``; the World warns). With ``tolerance = 0`` (implicit Euler's
default for now: converged at 1e-3 m/s, a ``pile`` test took 115 s instead of 2.3 s, since
contacts converge slowly; ``docs/benchmarks.md``) a fixed ``iterations`` run per substep,
approximate where springs turn, exact along a spring after one iteration.

Backward Euler is unconditionally stable and dissipates: a mode of angular frequency
``omega`` loses the factor ``1 / (1 + (h omega)^2)`` of its energy per substep.

Units: m, m/s, kg, N/m, N*s/m, s.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from ...colliders.geometry import advance_colliders
from ...colliders.response import note_impulse, push_rigid_row
from ...colliders.shapes import INV_MASS, RECT_CX, RECT_CY, VEL_X, VEL_Y
from ..base import (Integrator, Option, StepReport, contact_epilogue, finish_position_step, held_contacts,
                    register_integrator)
from .anderson import AndersonMixing
from .assembly import system_matrix, with_entries
from .updated_factor import UpdatedFactor

if TYPE_CHECKING:  # SciPy's sparse module is imported when a matrix is first built (0.1 s at start-up)
    pass


@njit(cache=True)
def inertia_rhs(y, vertex_mass, grab_slot, grab_pull, h2, b):
    """The inertia's and the grabs' part of the global solve's right-hand side: ``b = M y + h^2
    S target`` (N, 2), kg m; the element kinds add theirs (``ElementKind.rhs``).

    Parameters
    ----------
    y : (N, 2) float64
        Inertial prediction (m).
    vertex_mass : (N,) float64
        kg (times ``1 + h air_drag``).
    grab_slot : (N,) int32
        Grab entry per vertex or -1.
    grab_pull : (K, 3) float64
        ``(S, S tx, S ty)`` per grab entry.
    h2 : float
        ``h^2`` (s^2).
    b : (N, 2) float64
        Output (kg m).

    Examples
    --------
    >>> import numpy as np
    >>> b = np.zeros((2, 2))
    >>> inertia_rhs(np.array([[0.0, 0.0], [2.0, 0.0]]), np.ones(2), np.array([-1, 0], np.int32),
    ...             np.array([[4.0, 8.0, 0.0]]), 0.25, b)
    >>> b.tolist()  # M y, plus h^2 S target at the held vertex
    [[0.0, 0.0], [4.0, 0.0]]
    """
    for i in range(y.shape[0]):
        m = vertex_mass[i]
        b[i, 0] = m * y[i, 0]
        b[i, 1] = m * y[i, 1]
        g = grab_slot[i]
        if g >= 0:
            b[i, 0] += h2 * grab_pull[g, 1]
            b[i, 1] += h2 * grab_pull[g, 2]


@njit(cache=True)
def free_estimate(ptr, ind, val, x, b, rows, pinned, out):
    """Where each listed vertex goes in one Jacobi step of the contact-free system ``A x = b``
    (``A`` in CSR arrays ``ptr, ind, val``) with the other vertices held at ``x``: ``out[r]
    = x[r] + (b[r] - (A x)[r]) / A[r, r]``; a pinned vertex stays at ``x``.

    The contacts' local steps project this estimate rather than the iterate itself. The
    iterate of a vertex in contact is held by the contact's own weight (ten times the
    vertex's diagonal), so a projection of the iterate kept it near where the last iteration
    left it, and three iterations were far from converged: a frictionless vertex was held
    back along the surface, and the pull leaked momentum into what it touched (a box thrown
    onto a pinned plank without friction sped up sideways from 3.0 to 3.20 m/s; now 2.98,
    and 3.000 with 10 iterations).

    Examples
    --------
    >>> import numpy as np
    >>> ptr, ind, val = np.array([0, 2, 4]), np.array([0, 1, 0, 1]), np.array([2.0, -1.0, -1.0, 2.0])
    >>> x, b, out = np.zeros((2, 2)), np.array([[1.0, 0.0], [0.0, 0.0]]), np.zeros((2, 2))
    >>> free_estimate(ptr, ind, val, x, b, np.array([0]), np.zeros(2, np.bool_), out)
    >>> out[0].tolist()  # 0 + (1 - 0) / 2
    [0.5, 0.0]
    """
    for k in range(rows.shape[0]):
        r = rows[k]
        if pinned[r]:
            out[r, 0], out[r, 1] = x[r, 0], x[r, 1]
            continue
        ax, ay, d = 0.0, 0.0, 1.0
        for q in range(ptr[r], ptr[r + 1]):
            j = ind[q]
            ax += val[q] * x[j, 0]
            ay += val[q] * x[j, 1]
            if j == r:
                d = val[q]
        out[r, 0] = x[r, 0] + (b[r, 0] - ax) / d
        out[r, 1] = x[r, 1] + (b[r, 1] - ay) / d


@njit(cache=True)
def contact_rhs(x, x_n, planes, index, count, weight, target, b):
    """Add the collider contacts' local step to ``b``: each listed vertex pulled, with its
    ``weight`` (kg), to its projection onto the outside of its contact plane, with
    Coulomb friction at position level; the projections go to ``target`` (count, 2).

    ``push`` is how far the vertex is inside (0 if outside: an inactive contact projects
    to itself and exerts no force at convergence). Along the plane the target is where
    the vertex started the substep (it sticks) if that is within ``static_friction *
    push``; otherwise the vertex is held back by ``friction * push``. Normal and
    tangential pulls share the weight, so their ratio is the force ratio: Coulomb's cone.

    Examples
    --------
    >>> import numpy as np
    >>> b = np.zeros((1, 2))
    >>> x, x_n = np.array([[0.3, -0.1]]), np.array([[0.0, 0.5]])
    >>> floor = np.array([[0.0, 1.0, 0.0, 0.5, 0.3, 0.0, 0.0]])
    >>> contact_rhs(x, x_n, floor, np.zeros(1, np.int32), 1, np.array([2.0]), np.zeros((1, 2)), b)
    >>> b.round(9).tolist()  # slid 0.3 m, more than 0.5 * 0.1: held back by 0.3 * 0.1
    [[0.54, 0.0]]
    """
    for k in range(count):
        i = index[k]
        nx, ny = planes[k, 0], planes[k, 1]
        gap = x[i, 0] * nx + x[i, 1] * ny - planes[k, 2]
        px, py = x[i, 0], x[i, 1]
        if gap < 0.0:
            push = -gap
            px += push * nx
            py += push * ny
            # tangential motion since the substep began, relative to the collider's surface
            # (which moved by planes[k, 5:7]; t = (-ny, nx))
            slide = (x_n[i, 0] + planes[k, 5] - x[i, 0]) * -ny + (x_n[i, 1] + planes[k, 6] - x[i, 1]) * nx
            if abs(slide) > planes[k, 3] * push:
                slide = planes[k, 4] * push * (1.0 if slide > 0.0 else -1.0)
            px -= slide * ny
            py += slide * nx
        target[k, 0] = px
        target[k, 1] = py
        b[i, 0] += weight[k] * px
        b[i, 1] += weight[k] * py


@njit(cache=True)
def recoil_planes(planes, index, rows, count, x_n, y, mass, rects, h):
    """Move each rigid body's contact planes with the velocity the body will have once the
    vertices headed into it stick to it: ``V* = (M V + sum m v) / (M + sum m)`` over the
    listed vertices of its row (``v = (y - x_n) / h``, the predicted motion), instead of
    its velocity ``V`` now. Held still at ``V``, a light crate took the stop of a whole heavy
    jelly within a substep and then flew off with more energy than the jelly brought; at
    ``V*`` the solve makes the inelastic exchange of two masses."""
    for k in range(count):
        r = rows[k]
        if r < 0 or rects[r, INV_MASS] == 0.0:
            continue  # a collider, or a rigid row already moved
        # the first listed vertex of this row sums the row (later ones find it done: -r - 1)
        big_m = 1.0 / rects[r, INV_MASS]
        m_sum, px, py = big_m, big_m * rects[r, VEL_X], big_m * rects[r, VEL_Y]
        for q in range(k, count):
            if rows[q] == r:
                i = index[q]
                m_sum += mass[i]
                px += mass[i] * (y[i, 0] - x_n[i, 0]) / h
                py += mass[i] * (y[i, 1] - x_n[i, 1]) / h
        sx, sy = h * (px / m_sum - rects[r, VEL_X]), h * (py / m_sum - rects[r, VEL_Y])
        for q in range(k, count):
            if rows[q] == r:
                planes[q, 2] += sx * planes[q, 0] + sy * planes[q, 1]
                planes[q, 5] += sx
                planes[q, 6] += sy
                rows[q] = -r - 1  # done (rigid_plane_impulses reads it back)


@njit(cache=True)
def rigid_plane_impulses(x, index, rows, count, weight, target, rects, hits, inv_mass, h):
    """Give rigid bodies back what their outlines' planes did in the solve: contact ``k``
    pulled vertex ``i`` toward ``target[k]`` with ``weight[k] (target - x) / h^2`` N over the
    substep ``h``, so the vertex took the impulse ``J = weight (target - x) / h``. For a
    plane of a rigid body's row (``rows[k] = -r - 1``, from :func:`recoil_planes`), ``J / m``
    goes to ``hits`` as the velocity change it made (the rigid stage gives the body ``-J``)
    and the row's packed velocity takes its share at once. With ``target`` the last
    iteration's projections and ``x`` the solve's result, the solve's own equations make the
    body's momentum change exactly these impulses (its elastic forces sum to zero), so
    momentum is kept to rounding."""
    for k in range(count):
        if rows[k] >= 0:
            continue
        r = -rows[k] - 1
        i = index[k]
        jx = weight[k] * (target[k, 0] - x[i, 0]) / h
        jy = weight[k] * (target[k, 1] - x[i, 1]) / h
        if jx == 0.0 and jy == 0.0:
            continue
        w = inv_mass[i]
        note_impulse(hits, i, r, x[i, 0], x[i, 1], 0.0, 0.0, x[i, 0], x[i, 1], w * jx, w * jy)
        push_rigid_row(rects, r, x[i, 0] - rects[r, RECT_CX], x[i, 1] - rects[r, RECT_CY], jx, jy)


@njit(cache=True)
def body_contact_rhs(x, x_n, triple, s, weight, normal, target, mu, count, b):
    """Add the body contacts' local step to ``b``.

    Contact ``c`` joins vertex ``p`` and the point ``(1 - s) a + s b`` of an edge
    (``triple[c] = p, a, b``) through the term ``w/2 |D x - q|^2``, ``D x = x_p - (1 - s)
    x_a - s x_b``: a spring between the vertex and the edge point, whose coefficients sum to
    zero, so that its forces keep linear momentum exactly. The local step's ``q`` is ``D x``
    put at least ``target`` in front of the edge along ``normal``, with Coulomb friction on
    the relative motion since the substep began (``mu`` = dynamic, static), as for colliders.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.5, -0.1], [0.0, 0.0], [1.0, 0.0]])  # a vertex 0.1 m behind an edge
    >>> b = np.zeros((3, 2))
    >>> body_contact_rhs(x, x, np.array([[0, 1, 2]]), np.array([0.5]), np.array([1.0]),
    ...                  np.array([[0.0, 1.0]]), np.array([0.01]), np.array([[0.3, 0.5]]), 1, b)
    >>> b.round(9).tolist()  # q = (0, 0.01): 1 cm in front; D^T q
    [[0.0, 0.01], [0.0, -0.005], [0.0, -0.005]]
    """
    for c in range(count):
        p, a, e = triple[c, 0], triple[c, 1], triple[c, 2]
        t = s[c]
        ca = 1.0 - t
        nx, ny = normal[c, 0], normal[c, 1]
        qx = x[p, 0] - ca * x[a, 0] - t * x[e, 0]
        qy = x[p, 1] - ca * x[a, 1] - t * x[e, 1]
        gap = target[c] - (qx * nx + qy * ny)
        if gap > 0.0:
            qx += gap * nx
            qy += gap * ny
            # relative motion along the edge since the substep began (t = (-ny, nx))
            rx = x_n[p, 0] - ca * x_n[a, 0] - t * x_n[e, 0]
            ry = x_n[p, 1] - ca * x_n[a, 1] - t * x_n[e, 1]
            slide = (rx - qx) * -ny + (ry - qy) * nx
            if abs(slide) > mu[c, 1] * gap:
                slide = mu[c, 0] * gap * (1.0 if slide > 0.0 else -1.0)
            qx -= slide * ny
            qy += slide * nx
        w = weight[c]
        b[p, 0] += w * qx
        b[p, 1] += w * qy
        b[a, 0] -= w * ca * qx
        b[a, 1] -= w * ca * qy
        b[e, 0] -= w * t * qx
        b[e, 1] -= w * t * qy


def _row_items(t) -> np.ndarray:
    """The rows of an integer array (M, 3) as single comparable items (for set operations)."""
    t = np.ascontiguousarray(t, dtype=np.int64)
    return t.view(np.dtype((np.void, 3 * t.itemsize))).ravel()


@register_integrator("implicit-euler")
class ImplicitEuler(Integrator):
    """Backward Euler with prefactored local/global iterations (Liu et al. 2013).

    Unconditionally stable: any ``h`` and stiffness give a finite, bounded answer, at the
    price of numerical damping (see the module docstring and ``docs/integrators.md``).

    Options
    -------
    tolerance : float
        m/s, in [0, 1e6); default 0, a fixed ``iterations`` per substep (cheap, and not
        converged: see the module docstring). Above 0 each substep iterates until the next
        iteration would change no vertex's velocity by more (the objective's gradient as a
        force on the vertex's own mass for the substep), Anderson-accelerated; 1e-3 keeps a
        spinning body's spin (``implicit-bdf2`` takes it by default).
    max_iterations : int
        Iterations per substep at most with a tolerance (in [1, 1000000]; default 500). A
        substep that reaches it stands and is counted as unconverged.
    iterations : int
        With ``tolerance = 0`` the local/global iterations per substep, else the least
        number (in [1, 10000]; default 3). Each costs one pass over the springs and
        elements and one pair of triangular solves.
    contact_weight : float
        Weight of a contact (collider or body) in the solve, in multiples of the diagonal
        entry of its vertex (in (0, 1e12); default 10; larger holds contacts tighter in
        few iterations).

    :meth:`stats` (``world.integrator_stats``) counts ``factorizations``, how many times the
    matrix was factored (at the start, and after changes of the parameters, ``h`` or
    ``contact_weight``, and after small changes, tears, contact sets and grabs, have added
    up: :mod:`~deforma.physics.integrators.implicit.updated_factor`), and ``updates``, how
    many times a small change of the matrix was taken into the factor by a low-rank
    correction instead of factoring again; ``iterations``, the iterations run in all;
    ``unconverged``, the substeps that stopped at ``max_iterations``; and ``rejected``, the
    accelerated iterates the safeguard dropped.

    Examples
    --------
    >>> from deforma.physics.integrators import make_integrator
    >>> make_integrator("implicit-euler", {"tolerance": 1e-4}).options
    {'iterations': 3, 'tolerance': 0.0001, 'max_iterations': 500, 'contact_weight': 10.0}
    """

    name = "implicit-euler"
    unconditionally_stable = True
    second_order = False
    OPTIONS = (Option("iterations", 3, "int", low=1, high=10_000,
                      doc="local/global iterations per substep with tolerance 0, else the least number"),
               Option("tolerance", 0.0, "float", low=0.0, high=1e6, closed_low=True,
                      doc="m/s: iterate until the next iteration would change no velocity by more (0: a "
                          "fixed number of iterations)"),
               Option("max_iterations", 500, "int", low=1, high=1_000_000,
                      doc="iterations per substep at most, with a tolerance"),
               Option("contact_weight", 10.0, "float", low=0.0, high=1e12,
                      doc="a contact's weight in the solve, in multiples of its vertex's diagonal entry"))

    def __init__(self, **options):
        super().__init__(**options)
        self.factorizations = 0
        self.updates = 0
        self._key = None
        self._touching = None
        self._triples = None
        self._factor = None
        self._ref = None  # each vertex's row in the factor's reference matrix (None: unknown)
        self._dirty = None  # the vertices whose contact-free columns may differ from the reference's (None: any)
        self._scratch_n = -1
        self._mixer = AndersonMixing(5)
        self.iterations_run = 0
        self.unconverged = 0
        self._history = None  # BDF2: the last substep's increments and what they belong to

    def stats(self) -> dict:
        """``{"factorizations", "updates", "iterations", "unconverged", "rejected"}`` so far
        (see the class docstring)."""
        return {"factorizations": self.factorizations, "updates": self.updates, "iterations": self.iterations_run,
                "unconverged": self.unconverged, "rejected": self._mixer.rejected}

    def _base_if_needed(self, model, control, h):
        # Everything the contact-free matrix depends on: the Model's parameters through its
        # version counter (bumped by every in-place change), the grabbed vertices and their
        # strengths (compared by value: moving a grab's target changes only the right side),
        # h and the air drag.
        old = self._key
        if old is not None and old[0] is model and old[1] == model.version and old[2] == h \
                and old[5] == model.air_drag and np.array_equal(old[3], control.grab_slot) \
                and np.array_equal(old[4], control.grab_pull[:, 0]):
            return
        key = (model, model.version, h, control.grab_slot.copy(), control.grab_pull[:, 0].copy(), model.air_drag)
        # The factor stays usable through a change of the matrix when each vertex's row in its
        # reference matrix is known: the same Model, or one a tear rebuilt from it (each vertex
        # then comes from a vertex of the old one). Anything else factors again.
        torn = model.torn_from if old is not None and model is not old[0] else None
        if torn is not None and not (torn[0] == old[0].serial and len(torn[1]) == model.n_vertices):
            torn = None
        if old is None or self._ref is None:
            self._ref = None
        elif model is not old[0]:
            self._ref = self._ref[torn[1]] if torn is not None else None
        # Air drag -c v joins backward Euler as (1 + h c) M (x - y) / h^2 = f(x) + M g with
        # y = x_n + (h v_n + h^2 g) / (1 + h c): the heavier mass is in the matrix, so that
        # forces (not only gravity) balance at rest as they do without drag.
        mass = model.vertex_mass * (1.0 + h * model.air_drag)
        patch = None
        if torn is not None and model.fused and self._patchable(old, model, torn, control, h):
            # a tear: only the columns of the vertices it touched are assembled again
            source = torn[1]
            fresh = torn[2] | (mass != self._mass[source]) | (model.pinned != old[0].pinned[source])
            patch = (self._a, self._diag, source, fresh)
        # a patched column is the reference's where it was before; an assembled one may differ
        self._dirty = self._dirty[patch[2]] | patch[3] if patch is not None and self._dirty is not None else None
        self._mass = mass
        self._weights = [k.matrix_weights(h) for k in model.elements]  # in the order of model.elements
        self._a, self._diag = system_matrix(model, control.grab_slot, control.grab_pull, h, mass, patch,
                                            self._weights, fused=model.fused)
        if not model.fused:  # the assembly ran no kind: each gives its entries
            for kind, weights in zip(model.elements, self._weights):
                rows, cols, vals = kind.matrix_entries(h, weights)
                self._a = with_entries(self._a, rows, cols, vals, model.pinned)
                on = rows == cols
                self._diag = self._diag + np.bincount(rows[on], vals[on], model.n_vertices)
        self._rows = None  # its rows, for free_estimate, made when a contact first needs them
        self._key = key
        self._pinned = np.flatnonzero(model.pinned)
        self._touching = None  # the contact terms must be added again

    @staticmethod
    def _patchable(old, model, torn, control, h) -> bool:
        """Whether the matrix of ``old``'s Model (the key it was built for) is that of the torn
        ``model`` but for the vertices the tear touched: neither Model changed in place since
        (a parameter, plastic flow; the new Model took over the old one's rest shape), the same
        ``h``, air drag and grabs."""
        was = old[0]
        if old[1] != was.version or torn[3] != model.version or old[2] != h or old[5] != model.air_drag:
            return False
        source = torn[1]
        return np.array_equal(old[3][source], control.grab_slot) and np.array_equal(old[4], control.grab_pull[:, 0])

    def _matrix_if_changed(self, model, touching, triples, s):
        """The matrix with this contact set, when it differs from the one the factor solves
        with (``None``: the factor stands); :meth:`_take` gives it to the factor."""
        # The vertices in collider contact add their weight to the diagonal, the body
        # contacts their vertex-to-edge-point springs: a new set changes the matrix. A body
        # contact keeps the edge parameter s it had when the matrix was built (it is in the
        # matrix), so a resting heap, whose s only jitters, keeps its factor.
        weight = self._options["contact_weight"]
        if self._touching is not None and self._weight_used == weight \
                and np.array_equal(self._touching, touching) and np.array_equal(self._triples, triples):
            return None
        s = s.copy()
        if self._touching is not None and len(triples) and len(self._triples):
            # a pair that stays keeps its s: only the pairs that come or go change the matrix,
            # so the factor's correction covers them (a heap changes its pairs a few at a time,
            # and new s for all of them made each change touch every pair's rows)
            _, new, old = np.intersect1d(_row_items(triples), _row_items(self._triples), return_indices=True)
            s[new] = self._s[old]
        self._weight_used = weight
        self._touching = touching.copy()
        self._triples = triples.copy()
        self._s = s
        self._contact_weight = weight * self._diag[touching]
        self._pair_weight = weight * self._diag[triples[:, 0]]
        a = self._a
        if len(touching) or len(triples):
            co = np.stack([np.ones_like(s), s - 1.0, -s], axis=1)  # D's coefficients: sum 0
            rows = np.concatenate([touching, np.repeat(triples, 3, axis=1).ravel()])
            cols = np.concatenate([touching, np.tile(triples, (1, 3)).ravel()])
            vals = np.concatenate([self._contact_weight,
                                   (self._pair_weight[:, None, None] * co[:, :, None] * co[:, None, :]).ravel()])
            a = with_entries(a, rows, cols, vals, model.pinned)
        self._solving = a
        return a

    def _take(self, model, a, b) -> np.ndarray:
        """Solve with matrix ``a`` (:meth:`_matrix_if_changed`) from now on; returns ``a^-1 b``."""
        # A small change (a tear, a new contact set, a grab) is taken into the factor by a
        # low-rank correction, which solves b with its new columns (one call into the factor,
        # not two); a large one, or one whose rows are unknown, factors again.
        listed = np.concatenate([self._touching, self._triples.ravel()])
        if self._ref is not None:
            cols = None
            if self._dirty is not None:  # what may differ: changed columns, and those of either's contacts
                mask = self._dirty.copy()
                mask[listed] = True
                cols = np.union1d(self._ref[mask], self._ref_contacts)
            if self._factor.update(a, self._ref, cols, rhs=b):
                self.updates += 1
                return self._factor.solution
        if self._factor is None:
            self._factor = UpdatedFactor(a)
        else:
            self._factor.refactor(a)
        self._ref = np.arange(model.n_vertices)
        self._dirty = np.zeros(model.n_vertices, bool)
        self._ref_contacts = np.unique(listed)
        self.factorizations += 1
        return self._factor.solve(b)

    def _increments(self, model, control, x, v, h):
        """BDF2: the increments ``(x_n - x_{n-1}, v_n - v_{n-1})`` of the substep before this
        step's first (m, m/s; (N, 2) each, copies).

        Kept as increments, not as the earlier state, so that whatever moved the state
        between steps (an impulse, an explosion, the gas kick, positions set by hand) moves
        the earlier state with it instead of reading as an acceleration. A step run again
        from its start (the World undid it, or grew its contact buffer) takes the increments
        it started with; a torn Model carries each vertex's from the vertex it copies;
        anything else (a first step, a new body) starts from a past under gravity and the
        applied forces alone, ``(h v_n - h^2 a / 2, h a)`` (exact in free fall; an O(h^2)
        error where elastic forces or contacts act, which BDF2's second root, 1/3, damps).
        """
        hist = self._history
        if hist is not None and hist["model"] is not model:
            torn = model.torn_from
            if torn is not None and torn[0] == hist["model"].serial and len(torn[1]) == model.n_vertices:
                source = torn[1]
                hist = {"model": model, "start": None, "end": None,
                        "now": tuple(np.take(a, source, axis=0) for a in hist["now"])}
            else:
                hist = None
        if hist is None:
            a = np.empty_like(v)
            a[:] = model.gravity
            if control.has_force:
                a += control.force * model.vertex_inv_mass[:, None]
            dv = h * a
            dx = h * v - (0.5 * h) * dv
            dx[model.pinned] = 0.0
            dv[model.pinned] = 0.0
        elif hist["start"] is not None and np.array_equal(x, hist["start"]) and not np.array_equal(x, hist["end"]):
            dx, dv = hist["before"]  # the last step again, from its start
        else:
            dx, dv = hist["now"]
        self._history = {"model": model, "start": x.copy(), "end": None, "before": (dx, dv),
                         "now": (dx.copy(), dv.copy())}
        return self._history["now"]

    @staticmethod
    def _second_order_velocities(model, x, v, solved, x_s, x_n, hits, stamp, hs, h):
        """BDF2's velocities, into ``v`` (which holds backward Euler's, ``(x - x_n) / h``,
        after the collider response): ``(x - x^) / hs`` where the response left the vertex
        alone. Where it moved it, the response's normal velocity (a stop) and its friction
        stay, and a vertex it lets slide takes BDF2's difference from backward Euler along
        the face too: with backward Euler's velocity there, the vertices sliding on a
        face lagged the rest by half a step's acceleration every step, and a block slid down
        a frictionless slope at 0.87 of g sin a (a box pushed at 2 m/s settled at 1.75 m/s).
        A vertex the response holds still (static friction) stays still."""
        diff = (solved - x_s) * (1.0 / hs) - (solved - x_n) * (1.0 / h)
        free = (x == solved).all(axis=1) & ~model.pinned
        v[free] += diff[free]
        hit = np.flatnonzero(~free & ~model.pinned & (hits.stamp == stamp))
        if len(hit):
            n = hits.normal[hit]
            vt = v[hit] - (v[hit] * n).sum(axis=1)[:, None] * n
            dt = diff[hit] - (diff[hit] * n).sum(axis=1)[:, None] * n
            sliding = (vt * vt).sum(axis=1) > 0.0
            v[hit[sliding]] += dt[sliding]

    def step(self, model, state_in, state_out, control, contacts, h, *, substeps=1, max_speed=math.inf):
        n = model.n_vertices
        if self._scratch_n != n:
            self._x_n = np.empty((n, 2))
            self._x_s = np.empty((n, 2))
            self._v_n = np.empty((n, 2))
            self._y = np.empty((n, 2))
            self._b = np.empty((n, 2))
            self._planes = np.empty((n, 7))
            self._z = np.empty((n, 2))
            self._touch = np.empty(n, np.int32)
            self._plane_rows = np.empty(n, np.int32)
            self._targets = np.empty((n, 2))
            self._scratch_n = n
        # BDF2 is backward Euler with the step hs = 2h/3 from (x^, v^) = ((4 x_n - x_{n-1}) / 3,
        # (4 v_n - v_{n-1}) / 3): x = x^ + hs v and v = v^ + hs a(x) (see the module docstring)
        second = self.second_order
        hs = h * (2.0 / 3.0) if second else h
        self._base_if_needed(model, control, hs)
        x, v = state_out.x, state_out.v
        x_n, y, b = self._x_n, self._y, self._b
        x_s = self._x_s if second else x_n  # where the solve starts from: x^, or x_n
        gx, gy = model.gravity
        h2 = hs * hs
        vmax2 = float(max_speed) ** 2
        keep = 1.0 / (1.0 + hs * model.air_drag)
        if second:
            dx, dv = self._increments(model, control, x, v, h)
        rects, hits, scr, topo, buf = control.colliders, contacts.hits, contacts.scratch, model.contact, contacts.buffer
        least = self._options["iterations"]
        tolerance = self._options["tolerance"]
        converge = tolerance > 0.0
        most = self._options["max_iterations"]
        mixer = self._mixer
        unconverged = 0
        for _ in range(substeps):
            mixer.reset()
            advance_colliders(rects, h)  # moving colliders to where they are at the end of the substep
            np.copyto(x_n, x)
            if second:
                np.copyto(self._v_n, v)
                np.multiply(dx, 1.0 / 3.0, out=x_s)
                x_s += x_n
                v += dv * (1.0 / 3.0)
            if keep != 1.0:  # air drag: the prediction's share here, the mass's in the matrix (see _base_if_needed)
                v *= keep
            np.multiply(v, hs, out=y)
            y += x_s
            y[:, 0] += h2 * keep * gx  # so that free motion gives (v + h g) / (1 + h air_drag), as the
            y[:, 1] += h2 * keep * gy  # other integrators do
            if control.has_force:
                y += (h2 * keep) * control.force * model.vertex_inv_mass[:, None]
            # x starts at x_n: the first iteration is then backward Euler linearised at the
            # start of the substep (Baraff & Witkin's one Newton step, with the directions
            # of x_n). Starting at the prediction y measured worse on impacts: y can already
            # have a row of vertices pushed through the next, and the iteration keeps it.
            count, n_body = held_contacts(x_n, y, rects, self._planes, self._touch, self._plane_rows, True, float(h),
                                          topo, scr, buf)
            recoil_planes(self._planes, self._touch, self._plane_rows, count, x_n, y, model.vertex_mass, rects,
                          float(h))
            if n_body < 0:
                return StepReport(0, False)  # the contact buffer is too small; the world grows it and repeats
            cv = topo.cv_vertex
            edge = buf.edge[:n_body]
            triples = np.stack([cv[buf.vertex[:n_body]], cv[topo.ce_a[edge]], cv[topo.ce_b[edge]]], axis=1)
            changed = self._matrix_if_changed(model, self._touch[:count], triples, buf.s[:n_body])
            self._listed = np.concatenate([self._touch[:count], triples.ravel()])  # the vertices the contacts read
            it = 0
            while True:
                inertia_rhs(y, self._mass, control.grab_slot, control.grab_pull, h2, b)
                for kind, weights in zip(model.elements, self._weights):
                    kind.rhs(x, x_s, hs, weights, b)  # damping reads the velocity (x - x_s) / hs
                # The first projection is of the prediction, where the vertex is headed. The
                # converged solve then projects the iterate itself, so that its fixed point is
                # the minimum of the step's objective with the contacts' penalties; the fixed
                # number of iterations projects where the contact-free system would move the
                # iterate instead (free_estimate says why).
                z = y
                if it > 0 and len(self._listed):  # without contacts nothing reads z
                    if converge:
                        z = x
                    else:
                        if self._rows is None:  # not its columns: next to a pinned row they differ
                            self._rows = self._a.tocsr()
                        z = self._z
                        free_estimate(self._rows.indptr, self._rows.indices, self._rows.data, x, b,
                                      self._listed, model.pinned, z)
                contact_rhs(z, x_n, self._planes, self._touch, count, self._contact_weight, self._targets, b)
                body_contact_rhs(z, x_n, self._triples, self._s, self._pair_weight, buf.normal, buf.target, buf.mu,
                                 n_body, b)
                b[self._pinned] = x_n[self._pinned]  # pinned: x_p = where it is
                if changed is not None:  # the first solve with a new matrix
                    g = self._take(model, changed, b)
                    changed = None
                else:
                    g = self._factor.solve(b)
                it += 1
                if not converge:
                    x[...] = g
                    if it >= least:
                        break
                    continue
                # Converged when the objective's gradient, taken as a force on each vertex's own
                # mass for the substep, would change no velocity by more than the tolerance
                # (m/s). The step f = A^-1 grad itself is no measure: a stiff body's rotation
                # is almost absent from A, so there f is h^2 k / m times smaller than the error
                # (a block of 1e7 Pa spun 20 steps kept 0.84 of its angular momentum with f
                # below 1e-4 m/s, 0.887 converged); the gradient is right there, and errs on
                # the safe side along stiff directions, where the iteration converges fast.
                f = g - x
                r = self._solving @ f
                r /= self._mass[:, None]
                done = float(np.max(r[:, 0] * r[:, 0] + r[:, 1] * r[:, 1], initial=0.0)) <= (tolerance * hs) ** 2
                if (done and it >= least) or it >= most:
                    x[...] = g
                    if not done:
                        unconverged += 1
                    break
                # the first iteration's map (projecting the prediction) is not the others'
                x[...] = mixer.next(x, g) if it > 1 else g
            self.iterations_run += it
            rigid_plane_impulses(x, self._touch, self._plane_rows, count, self._contact_weight, self._targets, rects,
                                 hits, model.vertex_inv_mass, float(hs))
            if second:
                solved = x.copy()
            stamp = scr.status["stamp"][0] + 1
            bad = finish_position_step(x, v, x_n, rects, hits, stamp, float(h), vmax2)
            if bad:
                return StepReport(int(bad), True)
            if second:
                self._second_order_velocities(model, x, v, solved, x_s, x_n, hits, stamp, hs, float(h))
            # scr.xp still holds x_n (detect_contacts only read it): no second gather_start; the
            # stage's impulses change velocities only (contact_stage says why)
            if contact_epilogue(x, v, model.vertex_inv_mass, x_n, topo, scr, buf, rects, hits, float(h), False) < 0:
                return StepReport(0, False)  # the contact buffer is too small; the world grows it and repeats
            if second:
                np.subtract(x, x_n, out=dx)
                np.subtract(v, self._v_n, out=dv)
        if second:
            self._history["end"] = x.copy()
        self.unconverged += unconverged
        return StepReport(unconverged=unconverged)

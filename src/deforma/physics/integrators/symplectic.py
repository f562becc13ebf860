"""The symplectic (semi-implicit) Euler integrator, ``"symplectic-euler"``: the default.

Semi-implicit (symplectic) Euler, per substep::

    v = (v + h * F(x, v) / m) / (1 + h * air_drag)
    x += h * v
    x, v = collide(x_before, x, v)              # colliders, per vertex
    x, v = push_edges_off_corners(x, v)         # collider corners against body outlines
    x, v = contact_stage(x_before, x, v)        # bodies against bodies and themselves

Every integrator ends its substeps with the same responses: the collider response per vertex
(fused into its last pass over the vertices), then the shared epilogue
(:func:`~deforma.physics.integrators.base.contact_epilogue`: collider corners against
outlines, the body contact stage of :mod:`~deforma.physics.contact`), which needs the
boundary's positions at the start of the substep
(:func:`~deforma.physics.contact.broad_phase.gather_start`).

It is fused into two passes over memory per substep: springs, each thread scattering a
contiguous run of them into its own force buffer, then one per-vertex pass that sums the
buffers, adds gravity and the grab pull, integrates, collides and checks the result. Both
passes use all of Numba's threads for bodies big enough to pay for waking them
(``PARALLEL_MIN_VERTICES``, measured in ``benchmarks/``).
"""

from __future__ import annotations

import math
import time

import numba
import numpy as np
from numba import njit, prange

from ..colliders.geometry import advance_colliders, jump_reach, n_colliders
from ..colliders.response import collide_point, has_rigid_rows, record_hit
from ..colliders.shapes import RECT_XMAX, RECT_XMIN, RECT_YMAX, RECT_YMIN
from ..contact.broad_phase import gather_start
from ..elements.springs import SpringArrays, scatter_spring_forces
from ..elements.triangles import TriangleArrays, element_forces
from ..jit import serial_and_parallel
from .base import Integrator, Option, StepReport, contact_epilogue, is_bad, register_integrator
from .driver import MODE_OPTION_DOC, PARALLEL_MIN_VERTICES, DriverChoice


@njit(cache=True, inline="always")
def _semi_implicit_euler(x0, y0, vx, vy, fx, fy, inv_mass, gx, gy, keep, h):
    # keep = 1 / (1 + h air_drag): the drag -air_drag v taken at the end of the substep (stable at any h)
    vx = (vx + h * (fx * inv_mass + gx)) * keep
    vy = (vy + h * (fy * inv_mass + gy)) * keep
    return x0 + h * vx, y0 + h * vy, vx, vy


# Both drivers below run the same two passes per substep:
#   1. springs, split into len(chunk_ptr) - 1 contiguous chunks, each scattered into its own
#      force buffer fbuf[t] (no two threads write the same buffer, so no races);
#   2. per vertex: sum and re-zero the buffers, add gravity and the grab pull, integrate,
#      collide, check. One chunk gives the serial step.
# The per-vertex body is spelled out rather than split into helpers that take arrays: each
# array passed to a compiled helper per vertex costs atomic reference-count updates that
# Numba does not always prune (a helper taking a dozen arrays made the step 10x slower).
# Scalar-only helpers are free.

def _symplectic_euler(x, v, fbuf, chunk_ptr, elem_ptr, chunk_vertices, springs, tris, elem_damped, inv_mass, gx, gy,
                      keep, force, has_force, grab_slot, grab_pull, rects, hits, ctopo, cscr, cbuf, h, substeps, vmax2):
    """``substeps`` symplectic Euler substeps of ``h`` s with collisions.

    ``fbuf`` (T, N, 2) are zeroed force buffers, one per chunk ``t`` of the springs ``springs``
    (a :class:`~deforma.physics.elements.springs.SpringArrays`; ``chunk_ptr[t]:chunk_ptr[t +
    1]``) and of the triangle elements ``tris`` (a
    :class:`~deforma.physics.elements.triangles.TriangleArrays`; ``elem_ptr[t]:elem_ptr[t +
    1]``; ``elem_damped``: whether any has damping), and are left zeroed; chunk
    ``t`` touches only the vertices ``chunk_vertices[t, 0]:chunk_vertices[t, 1]`` (see
    :func:`spring_chunks`). ``force`` (N, 2) is added to every vertex's force if
    ``has_force`` (applied forces, and the forces of element kinds outside this driver). A
    vertex with ``inv_mass`` 0 is pinned: it stays where it is. Advances ``x``, ``v`` in
    place; stops early and returns the number of vertices that ended non-finite or
    faster than ``sqrt(vmax2)`` m/s (or 0 at once when the contact buffer ``cbuf`` is too
    small: ``cscr.status`` says so). ``hits`` records collider contacts (written only on a
    hit); ``ctopo``, ``cscr``, ``cbuf``: the contact stage's topology, scratch and buffer.

    Compiled twice below: ``symplectic_euler_serial`` (one thread: ``prange`` is ``range``)
    and ``symplectic_euler_parallel`` (one spring chunk per thread, the vertex pass split
    across threads); both give the same result for the same chunks.
    """
    n_chunks = chunk_ptr.shape[0] - 1
    reach2 = jump_reach(rects)
    n_rects = n_colliders(rects)
    dynamic = has_rigid_rows(rects)  # then the substep's start is kept for collide_dynamic
    x_start = np.empty_like(x) if dynamic else np.empty((0, 2))
    for sub in range(substeps):
        advance_colliders(rects, h)  # moving colliders to where they are at the end of the substep
        gather_start(x, ctopo, cscr)
        if dynamic:
            x_start[...] = x
        stamp = cscr.status.stamp[0] + 1  # the contact stage counts this substep when it runs
        for t in prange(n_chunks):
            lo, hi = chunk_ptr[t], chunk_ptr[t + 1]
            scatter_spring_forces(x, v, springs.i[lo:hi], springs.j[lo:hi], springs.rest[lo:hi], springs.ks[lo:hi],
                                  springs.kd[lo:hi], fbuf[t])
            lo, hi = elem_ptr[t], elem_ptr[t + 1]
            if hi > lo:
                element_forces(x, v, tris.elem[lo:hi], tris.b[lo:hi], tris.area[lo:hi], tris.mu[lo:hi],
                               tris.lam[lo:hi], tris.beta[lo:hi], tris.kind[lo:hi], elem_damped, fbuf[t])
        bad = 0
        for i in prange(x.shape[0]):
            x0, y0, vx, vy = x[i, 0], x[i, 1], v[i, 0], v[i, 1]
            if n_chunks == 1:  # one buffer over every vertex: no range test (~7% of a 1e3-vertex step)
                fx = fbuf[0, i, 0]
                fy = fbuf[0, i, 1]
                fbuf[0, i, 0] = 0.0
                fbuf[0, i, 1] = 0.0
            else:
                fx = 0.0
                fy = 0.0
                for t in range(n_chunks):
                    if chunk_vertices[t, 0] <= i < chunk_vertices[t, 1]:  # only where chunk t wrote
                        fx += fbuf[t, i, 0]
                        fy += fbuf[t, i, 1]
                        fbuf[t, i, 0] = 0.0
                        fbuf[t, i, 1] = 0.0
            if has_force:
                fx += force[i, 0]
                fy += force[i, 1]
            g = grab_slot[i]
            if g >= 0:  # the grab pull: strength * (target - x), summed over the grabs holding i
                fx += grab_pull[g, 1] - grab_pull[g, 0] * x0
                fy += grab_pull[g, 2] - grab_pull[g, 0] * y0
            if inv_mass[i] == 0.0:  # pinned: it stays (its buffers are re-zeroed above)
                v[i, 0] = 0.0
                v[i, 1] = 0.0
                continue
            px, py, vx, vy = _semi_implicit_euler(x0, y0, vx, vy, fx, fy, inv_mass[i], gx, gy, keep, h)
            near = False
            for r in range(n_rects):  # broad phase: bounding boxes (a helper for these
                # lines, even inlined, costs reference counting on rects per vertex: 2.5x slower)
                if rects[r, RECT_XMIN] < px < rects[r, RECT_XMAX] and rects[r, RECT_YMIN] < py < rects[r, RECT_YMAX]:
                    near = True
            if near or (px - x0) * (px - x0) + (py - y0) * (py - y0) > reach2:  # or it may have jumped one
                qx, qy, ux, uy = px, py, vx, vy
                px, py, vx, vy, hit, nx, ny, depth = collide_point(x0, y0, px, py, vx, vy, rects, h)
                if hit >= 0:
                    record_hit(hits, i, stamp, hit, nx, ny, depth, qx, qy, ux, uy, px, py, vx, vy)
            x[i, 0], x[i, 1], v[i, 0], v[i, 1] = px, py, vx, vy
            bad += is_bad(px, py, vx, vy, vmax2)
        if bad:
            return bad
        if contact_epilogue(x, v, inv_mass, x_start, ctopo, cscr, cbuf, rects, hits, h, True) < 0:
            return 0
    return 0


symplectic_euler_serial, symplectic_euler_parallel = serial_and_parallel(_symplectic_euler, "symplectic_euler")


def element_chunks(elem, n_chunks: int) -> tuple[np.ndarray, np.ndarray]:
    """Split the elements into ``n_chunks`` equal runs, as :func:`spring_chunks` does springs.

    Examples
    --------
    >>> import numpy as np
    >>> ptr, verts = element_chunks(np.array([[0, 1, 2], [1, 3, 2]], np.int32), 2)
    >>> ptr.tolist(), verts.tolist()
    ([0, 1, 2], [[0, 3], [1, 4]])
    """
    return _row_chunks(elem, n_chunks)


def _row_chunks(rows, n_chunks: int) -> tuple[np.ndarray, np.ndarray]:
    """``n_chunks`` equal runs of the rows of an (E, k) vertex-index array, and the vertex range each touches."""
    n = len(rows)
    ptr = (np.arange(n_chunks + 1, dtype=np.int64) * n) // n_chunks
    verts = np.zeros((n_chunks, 2), np.int64)
    for t in range(n_chunks):
        lo, hi = ptr[t], ptr[t + 1]
        if hi > lo:
            verts[t] = rows[lo:hi].min(), rows[lo:hi].max() + 1
    return ptr, verts


def merged_chunks(spring_i, spring_j, elem, n_chunks: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Spring and element runs per chunk and the vertices each chunk touches (both runs).

    Returns ``(spring_ptr, elem_ptr, chunk_vertices)``.
    """
    sp_ptr, sp_v = spring_chunks(spring_i, spring_j, n_chunks)
    el_ptr, el_v = element_chunks(elem, n_chunks)
    verts = np.zeros((n_chunks, 2), np.int64)
    for t in range(n_chunks):
        ranges = [r for r, used in ((sp_v[t], sp_ptr[t + 1] > sp_ptr[t]), (el_v[t], el_ptr[t + 1] > el_ptr[t]))
                  if used]
        if ranges:
            verts[t] = min(r[0] for r in ranges), max(r[1] for r in ranges)
    return sp_ptr, el_ptr, verts


def spring_chunks(spring_i, spring_j, n_chunks: int) -> tuple[np.ndarray, np.ndarray]:
    """Split the springs into ``n_chunks`` equal runs; say which vertices each run touches.

    Returns ``(chunk_ptr, chunk_vertices)``: run ``t`` is springs ``chunk_ptr[t]:chunk_ptr[t +
    1]`` and touches only vertices ``chunk_vertices[t, 0]:chunk_vertices[t, 1]``. Springs
    are sorted by their first vertex, so on a mesh numbered row by row each run covers a
    narrow band of vertices: its force buffer stays in cache and the vertex pass reads a
    buffer only where its run wrote.

    Examples
    --------
    >>> import numpy as np
    >>> ptr, verts = spring_chunks(np.array([0, 0, 1, 2], np.int32), np.array([1, 2, 3, 3], np.int32), 2)
    >>> ptr.tolist(), verts.tolist()
    ([0, 2, 4], [[0, 3], [1, 4]])
    """
    return _row_chunks(np.stack([spring_i, spring_j], axis=1), n_chunks)


@register_integrator("symplectic-euler")
class SymplecticEuler(Integrator):
    """Semi-implicit Euler (the original's): ``v += h F/m; x += h v``, then collisions.

    Stable for ``h`` below roughly ``2 / omega_max`` (see ``World.stable_dt``); energy
    stays bounded without damping.

    Bodies of at least ``PARALLEL_MIN_VERTICES`` vertices split their springs into one
    chunk per Numba thread, and both the one-thread and the all-threads driver then give
    bitwise the same result. Which one runs is measured, not assumed: threads that meet at
    a barrier every pass are fast on an idle machine but can be 100x slower when other
    processes keep the cores busy, so now and then two steps run on the other driver (every
    16 steps, backing off to every 4096 while it keeps losing) and the faster one (median of
    its last three timed steps) is used.

    Options
    -------
    mode : {"auto", "serial", "parallel"}
        ``"auto"`` (default) measures which driver is faster, as above; ``"serial"`` or
        ``"parallel"`` pins one (benchmarks, tests). The result is the same bit for bit.

    Examples
    --------
    >>> from deforma.physics.integrators import make_integrator
    >>> make_integrator("symplectic-euler").name
    'symplectic-euler'
    """

    name = "symplectic-euler"
    OPTIONS = (Option("mode", "auto", "choice", choices=("auto", "serial", "parallel"), doc=MODE_OPTION_DOC),)

    def __init__(self, **options):
        super().__init__(**options)
        self._fbuf = np.zeros((0, 0, 2))
        self._model = None
        self._chunks = np.zeros(1, np.int64)
        self._elem_chunks = np.zeros(1, np.int64)
        self._chunk_vertices = np.zeros((0, 2), np.int64)
        self._threads = None  # numba.get_num_threads(), re-read every 1024 steps
        self._damped = (-1, None, False)  # (Model version, Model, whether any element is damped)
        self._ticks = 0
        self._driver = DriverChoice()

    def step(self, model, state_in, state_out, control, contacts, h, *, substeps=1, max_speed=math.inf):
        n = model.n_vertices
        self._ticks += 1
        if self._ticks >= 1024 or self._threads is None:  # costs 1 us: a few % of a small step
            self._ticks, self._threads = 0, numba.get_num_threads()
        threads = self._threads
        # the chunking, and so the result, depends on the body size and thread count only
        n_chunks = threads if n >= PARALLEL_MIN_VERTICES and threads > 1 else 1
        mode = self._options["mode"]
        may_parallel = n_chunks > 1 and mode != "serial"
        if self._model is not model or self._fbuf.shape[:2] != (n_chunks, n):
            # scratch kept between steps: the kernels allocate nothing and leave it zeroed
            self._model = model  # a new Model means new topology: new chunks
            self._fbuf = np.zeros((n_chunks, n, 2))
            self._chunks, self._elem_chunks, self._chunk_vertices = merged_chunks(
                model.spring_i, model.spring_j, model.elem, n_chunks)
            self._driver.reset()
        if self._damped[0] != model.version or self._damped[1] is not model:  # a material may change it in place
            self._damped = (model.version, model, bool(model.elem_damping.any()))
        if not may_parallel:
            which = "serial"
        elif mode == "parallel":
            which = "parallel"
        else:
            which = self._driver.choose()
        kernel = symplectic_euler_parallel if which == "parallel" else symplectic_euler_serial
        gx, gy = model.gravity
        start = time.perf_counter()
        common = (model.vertex_inv_mass, float(gx), float(gy), 1.0 / (1.0 + float(h) * model.air_drag))
        tail = (control.grab_slot, control.grab_pull, control.colliders, contacts.hits, model.contact,
                contacts.scratch, contacts.buffer, float(h))
        if model.fused:  # the compiled driver runs the springs and triangles itself, every substep
            bad = kernel(state_out.x, state_out.v, self._fbuf, self._chunks, self._elem_chunks, self._chunk_vertices,
                         model.springs.arrays, model.triangles.arrays, self._damped[2], *common, control.force,
                         control.has_force, *tail, int(substeps), float(max_speed) ** 2)
        else:
            bad = self._step_kinds(kernel, model, state_out, control, contacts, substeps, max_speed, common, tail)
        if may_parallel:
            self._driver.record(which, (time.perf_counter() - start) / substeps)
        return StepReport(int(bad), contacts.complete)

    def _step_kinds(self, kernel, model, state, control, contacts, substeps, max_speed, common, tail) -> int:
        """The substeps one at a time, the forces of every element kind summed by the kinds
        themselves and handed to the driver as applied forces (with the step's own); the
        driver then runs no element. The same arithmetic as the fused driver on one chunk."""
        x, v = state.x, state.v
        force = np.zeros_like(x)
        ptr = np.zeros(len(self._chunks), np.int64)  # every chunk empty: the driver runs no element
        for _ in range(substeps):
            force[...] = 0.0
            for kind in model.elements:
                kind.forces(x, v, force)
            if control.has_force:
                force += control.force
            bad = kernel(x, v, self._fbuf, ptr, ptr, self._chunk_vertices, SpringArrays.empty(),
                         TriangleArrays.empty(), False, *common, force, True, *tail, 1, float(max_speed) ** 2)
            if bad or not contacts.complete:
                return bad
        return 0

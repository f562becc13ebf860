"""The implicit solve's global matrix: assembled column by column, patched after a tear, and
merged with the contacts' entries (compiled passes over CSC arrays, SciPy's own layout).

Units: kg (the matrix is ``M`` plus stiffness times ``h^2``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit


if TYPE_CHECKING:  # SciPy's sparse module is imported when a matrix is first built (0.1 s at start-up)
    import scipy.sparse as sp


def first_index(source, n_old) -> np.ndarray:
    """For each of ``n_old`` old vertices, the lowest ``i`` with ``source[i]`` equal to it
    (-1 where none): after a tear, the vertex itself rather than one of its copies.

    Examples
    --------
    >>> first_index(np.array([0, 1, 2, 1, 2]), 4).tolist()
    [0, 1, 2, -1]
    """
    first = np.full(n_old, -1, np.int64)
    first[source[::-1]] = np.arange(len(source) - 1, -1, -1)  # the last write, the lowest index, stays
    return first


@njit(cache=True, inline="always")
def sort_few(keys, count):
    """Sort ``keys[:count]`` in place: an insertion sort, for the few rows of one column."""
    for a in range(1, count):
        r = keys[a]
        q = a - 1
        while q >= 0 and keys[q] > r:
            keys[q + 1] = keys[q]
            q -= 1
        keys[q + 1] = r


def system_matrix(model, grab_slot, grab_pull, h: float, mass=None, patch=None, weights=None, fused=True):
    """The constant global matrix ``M + L_w + K_w + h^2 S_grab`` (N x N, kg), canonical CSC,
    each pinned row the identity's, and its diagonal before the pinning (N,): the compiled
    assembly of the built-in element kinds.

    ``L_w`` is the graph Laplacian of the springs weighted by ``h^2 ks + h kd``, ``K_w`` the
    elements' ``sum_e w_e D D^T`` (``TriangleKind.matrix_weights``); with ``fused`` False
    both are left out (the caller merges every kind's ``matrix_entries``). The x and y coordinates share
    it, so one N x N factor serves both. ``mass`` replaces ``M``'s diagonal (the solve uses
    ``M (1 + h air_drag)``). A pinned row's equation is ``x_p = b_p`` (the caller puts the
    pinned position in ``b_p``), while the free rows keep their coupling to it, so that it
    acts on them as a known position.

    ``patch = (a, diag, source, fresh)``: ``model`` is a torn copy of the Model whose matrix
    and diagonal are ``a`` and ``diag`` (same ``h``, mass factor and grabs), vertex ``i``
    a copy of its vertex ``source[i]``, and only the ``fresh`` vertices (N,) bool have
    springs, elements or a mass the tear changed (:attr:`Model.torn_from`). Their columns
    are assembled; every other column is the old one, its rows renumbered: the same numbers,
    as it sums the same terms in the same order. ``weights``: the kinds' ``matrix_weights``
    for ``h``, in the order of ``model.elements``, when the caller has them already.

    Examples
    --------
    >>> from deforma.physics.model import Model
    >>> from deforma.physics.topology import BodyTopology
    >>> t = BodyTopology.from_arrays([[0, 0], [1, 0]], [[0, 1]])
    >>> m = Model([t], masses=[2.0], stiffness=[100.0], damping=[0.0])
    >>> a, diag = system_matrix(m, np.full(2, -1, np.int32), np.zeros((0, 3)), 0.1)
    >>> a.toarray().round(9).tolist(), diag.round(9).tolist()
    ([[2.0, -1.0], [-1.0, 2.0]], [2.0, 2.0])
    """
    import scipy.sparse as sp

    n = model.n_vertices
    diag = (model.vertex_mass if mass is None else mass).copy()
    held = np.flatnonzero(grab_slot >= 0)
    diag[held] += h * h * grab_pull[grab_slot[held], 0]
    if patch is None:
        fresh, source, first = np.ones(n, np.bool_), np.zeros(0, np.int64), np.zeros(0, np.int64)
        old = (np.zeros(1, np.int32), np.zeros(0, np.int32), np.zeros(0), np.zeros(0))
    else:
        a, old_diag, source, fresh = patch
        source = np.ascontiguousarray(source, dtype=np.int64)
        first = first_index(source, a.shape[0])
        old = (a.indptr, a.indices, a.data, old_diag)  # SciPy's own arrays (int32 here): no copies
    if fused:
        # the kinds' weights for h, in the order of model.elements (made here unless given)
        weights = {id(k): w for k, w in zip(model.elements, weights)} if weights is not None else \
            {id(k): k.matrix_weights(h) for k in (model.springs, model.triangles)}
        wk, wd = weights[id(model.springs)]
        springs = (model.spring_i, model.spring_j, wk + wd)
        elements = (model.elem, model.elem_b, weights[id(model.triangles)])
    else:
        springs = (np.zeros(0, np.int32), np.zeros(0, np.int32), np.zeros(0))
        elements = (np.zeros((0, 3), np.int32), np.zeros((0, 4)), np.zeros(0))
    ptr, ind, val = _assemble(diag, *springs, *elements, model.pinned,
                              np.ascontiguousarray(fresh, dtype=np.bool_), source, first, *old)
    a = sp.csc_matrix((val, ind, ptr), shape=(n, n))
    a.has_sorted_indices = True
    return a, diag


@njit(cache=True)
def _assemble(diag, si, sj, sw, tris, b, ew, pinned, fresh, source, first, optr, oind, oval, odiag):
    """CSC arrays of :func:`system_matrix` (``diag`` comes in as the masses and grabs and
    leaves as the whole diagonal before pinning), column by column: each ``fresh`` vertex's
    springs and elements are summed into a dense work column, whose touched rows are then
    sorted; any other column is copied from the old matrix ``(optr, oind, oval)`` (diagonal
    ``odiag``), column ``source[j]``, rows renumbered by ``first``. One pass over the
    incidences; the coordinate-format build it replaced sorted 1.9e5 entries (4-5 ms on a
    1e4-vertex sheet, at every tear). Entries that sum to exactly zero off the diagonal are
    dropped (a right triangle's two legs do not couple: a stored zero would cost the factor
    fill)."""
    n = diag.shape[0]
    ns, nt = si.shape[0], tris.shape[0]
    start = np.zeros(n + 1, np.int64)  # per fresh vertex: its springs (s) and element corners (-1 - 3 e - c)
    for k in range(ns):
        if fresh[si[k]]:
            start[si[k] + 1] += 1
        if fresh[sj[k]]:
            start[sj[k] + 1] += 1
    for e in range(nt):
        for c in range(3):
            if fresh[tris[e, c]]:
                start[tris[e, c] + 1] += 1
    for v in range(n):
        start[v + 1] += start[v]
    fill = start[:-1].copy()
    inc = np.empty(start[n], np.int64)
    for k in range(ns):
        if fresh[si[k]]:
            inc[fill[si[k]]] = k
            fill[si[k]] += 1
        if fresh[sj[k]]:
            inc[fill[sj[k]]] = k
            fill[sj[k]] += 1
    for e in range(nt):
        for c in range(3):
            if fresh[tris[e, c]]:
                inc[fill[tris[e, c]]] = -1 - 3 * e - c
                fill[tris[e, c]] += 1
    work = np.zeros(n)
    seen = np.zeros(n, np.bool_)
    rows = np.empty(n, np.int64)
    size = n + 2 * ns + 6 * nt
    if size >= 2 ** 31:
        raise ValueError("_assemble: the matrix would have 2^31 entries or more")
    # int32 indices, as SciPy keeps them (it would copy int64 ones down to int32)
    ptr = np.zeros(n + 1, np.int32)
    ind = np.empty(size, np.int32)
    val = np.empty(size)
    out = 0
    for j in range(n):
        if not fresh[j]:
            o = source[j]
            if out + optr[o + 1] - optr[o] > size:  # Numba does not check indices: refuse rather than write astray
                raise ValueError("_assemble: a kept column has more entries than its vertex's incidences allow")
            for p in range(optr[o], optr[o + 1]):
                ind[out] = first[oind[p]]
                val[out] = oval[p]
                out += 1
            diag[j] = odiag[o]
            ptr[j + 1] = out
            continue
        # the work column, written out here rather than through a helper: a compiled helper
        # that writes arrays costs reference counting at every call (2.5 against 0.27 ms
        # for the 1.8e5 entries of a 1e4-vertex sheet)
        rows[0] = j
        seen[j] = True
        work[j] = diag[j]
        m = 1
        for p in range(start[j], start[j + 1]):
            k = inc[p]
            if k >= 0:
                o = sj[k] if si[k] == j else si[k]
                work[j] += sw[k]
                if not seen[o]:
                    seen[o] = True
                    rows[m] = o
                    m += 1
                work[o] -= sw[k]
            else:
                e, c = (-1 - k) // 3, (-1 - k) % 3
                d1x, d1y, d2x, d2y = b[e, 0], b[e, 1], b[e, 2], b[e, 3]
                dxc = -d1x - d2x if c == 0 else (d1x if c == 1 else d2x)
                dyc = -d1y - d2y if c == 0 else (d1y if c == 1 else d2y)
                for v in range(3):
                    r = tris[e, v]
                    if not seen[r]:
                        seen[r] = True
                        rows[m] = r
                        m += 1
                    dxv = -d1x - d2x if v == 0 else (d1x if v == 1 else d2x)
                    dyv = -d1y - d2y if v == 0 else (d1y if v == 1 else d2y)
                    work[r] += ew[e] * (dxv * dxc + dyv * dyc)  # w_e D_v . D_c
        diag[j] = work[j]
        sort_few(rows, m)  # a column holds a vertex's few neighbours
        for a in range(m):
            r = rows[a]
            v = work[r]
            work[r] = 0.0
            seen[r] = False
            if r == j:
                ind[out] = r
                val[out] = 1.0 if pinned[j] else v
                out += 1
            elif v != 0.0 and not pinned[r]:
                ind[out] = r
                val[out] = v
                out += 1
        ptr[j + 1] = out
    return ptr, ind[:out], val[:out]


@njit(cache=True, inline="always")
def _sort_rows(ind, val, lo, hi):
    """Sort ``ind[lo:hi]`` (row indices of one column) and ``val`` with it, in place: an
    insertion sort, as a column holds a vertex's few neighbours."""
    for a in range(lo + 1, hi):
        r, v = ind[a], val[a]
        b = a - 1
        while b >= lo and ind[b] > r:
            ind[b + 1] = ind[b]
            val[b + 1] = val[b]
            b -= 1
        ind[b + 1] = r
        val[b + 1] = v


@njit(cache=True)
def _merge(ptr, ind, val, rows, cols, vals, pinned):
    """CSC arrays of the canonical CSC matrix ``(ptr, ind, val)`` plus the entries ``(rows,
    cols, vals)`` (those in ``pinned`` rows left out), summed where they meet; entries that
    sum to exactly zero off the diagonal dropped (a right triangle's two legs do not couple:
    a stored zero would cost the factor fill)."""
    n = ptr.shape[0] - 1
    extra = np.zeros(n + 1, np.int64)
    for k in range(rows.shape[0]):
        if not pinned[rows[k]]:
            extra[cols[k] + 1] += 1
    for c in range(n):
        extra[c + 1] += extra[c]
    er = np.empty(extra[n], np.int64)
    ev = np.empty(extra[n])
    fill = extra[:-1].copy()
    for k in range(rows.shape[0]):
        if not pinned[rows[k]]:
            c = cols[k]
            er[fill[c]] = rows[k]
            ev[fill[c]] = vals[k]
            fill[c] += 1
    if ind.shape[0] + er.shape[0] >= 2 ** 31:
        raise ValueError("_merge: the matrix would have 2^31 entries or more")
    out_ptr = np.zeros(n + 1, np.int32)  # int32, as SciPy keeps them (it would copy int64 ones down)
    out_ind = np.empty(ind.shape[0] + er.shape[0], np.int32)
    out_val = np.empty(ind.shape[0] + er.shape[0])
    out = 0
    for c in range(n):
        lo, hi = extra[c], extra[c + 1]
        _sort_rows(er, ev, lo, hi)  # the column's few extra entries in row order
        first = out
        p, q = ptr[c], lo
        while p < ptr[c + 1] or q < hi:
            if q >= hi or (p < ptr[c + 1] and ind[p] <= er[q]):
                r, v = ind[p], val[p]
                p += 1
            else:
                r, v = er[q], ev[q]
                q += 1
            if out > first and out_ind[out - 1] == r:
                out_val[out - 1] += v
            else:
                if out > first and out_val[out - 1] == 0.0 and out_ind[out - 1] != c:
                    out -= 1
                out_ind[out] = r
                out_val[out] = v
                out += 1
        if out > first and out_val[out - 1] == 0.0 and out_ind[out - 1] != c:
            out -= 1
        out_ptr[c + 1] = out
    return out_ptr, out_ind[:out], out_val[:out]


def with_entries(a, rows, cols, vals, pinned) -> sp.csc_matrix:
    """The canonical CSC matrix ``a`` (from :func:`system_matrix`, pinned rows already the
    identity's) plus the entries ``(rows, cols, vals)``, none added to a ``pinned`` row: the
    contacts' terms on the contact-free matrix, merged column by column.

    Examples
    --------
    >>> import scipy.sparse as sp
    >>> a = sp.csc_matrix(np.diag([2.0, 3.0]))
    >>> b = with_entries(a, np.array([0, 1]), np.array([1, 0]), np.array([-1.0, -1.0]), np.zeros(2, bool))
    >>> b.toarray().tolist()
    [[2.0, -1.0], [-1.0, 3.0]]
    """
    import scipy.sparse as sp

    ptr, ind, val = _merge(a.indptr, a.indices, a.data,
                           np.asarray(rows, dtype=np.int64), np.asarray(cols, dtype=np.int64),
                           np.asarray(vals, dtype=np.float64), np.asarray(pinned, dtype=np.bool_))
    out = sp.csc_matrix((val, ind, ptr), shape=a.shape)
    out.has_sorted_indices = True
    return out

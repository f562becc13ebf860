"""A sparse factorisation kept across small changes of its matrix: tears, contacts, grabs.

Implicit Euler (:mod:`deforma.physics.integrators.implicit`) solves with a factored matrix ``A`` that
changes now and then: a tear splits vertices (the matrix gains rows and its entries move to
the copies), a new contact set adds a few weights, a mouse grab one more. Factoring again
took 15-18 ms on a 1e4-vertex sheet (and grows faster than the mesh); one solve with the
factor costs 0.3-0.5 ms per right-hand side. :class:`UpdatedFactor` keeps the factor of a
*reference* matrix ``A_R`` (``n0 x n0``) and solves with the current matrix ``A`` (``n x n``)
by a low-rank correction, exactly up to rounding:

**The vertex map.** Every current vertex ``i`` comes from a reference vertex ``ref[i]`` (a
tear copies vertices, it never deletes one). The first current vertex of each reference
vertex is its *primary*, the others are *copies* (``nc`` of them). With ``T`` the ``n x
(n0 + nc)`` matrix ``x_i = xi[ref[i]] (+ xi_c[copy(i)] for a copy)``, ``A x = b`` is
``T^T A T xi = T^T b``, and ``T^T A T = [[A_R + Delta, B], [C, D]]``. A tear reassigns
triangles to copies and shares masses between them, so the sums in ``T^T A T``'s first
block give ``A_R`` back (up to rounding): ``Delta`` holds only what changed besides the
split (contacts, grabs), on a few rows ``r`` (``k_o`` of them), while ``B``, ``C`` and ``D``
(the copies' rows and columns) grow by about one column per split vertex.

**The correction.** With ``Z = A_R^-1 E_r`` (``E_r`` the identity's columns ``r``), ``V =
A_R^-1 B`` and ``p = Delta xi_r``, ``A x = b`` becomes ``xi = U - Z p - V xi_c`` with ``U =
A_R^-1 b_o``, and the ``k_o + nc`` unknowns ``(p, xi_c)`` solve the small dense system::

    [[I + Delta Z_r,  Delta V_r  ],   [p   ]   [Delta U_r     ]
     [-C Z,           D - C V    ]] . [xi_c] = [b_c - C U     ]

(Woodbury's identity for ``Delta``, a Schur complement for the copies). A solve is then one
solve with the reference factor, one product with the ``n0 x (k_o + nc)`` matrix ``[Z V]``
and a small dense solve. The columns of ``Z`` and ``V`` are computed once (a batched solve)
and kept while the reference stays: a copy's column of ``B`` does not change when its
neighbours split later (it is summed back onto reference vertices), so a crack running
through a sheet costs about one new column per split vertex.

**When to factor again.** The product grows with ``k_o + nc``; past ``max_rank`` columns
(or when the small system is ill-conditioned) :meth:`UpdatedFactor.update` declines and the
caller factors the current matrix, which becomes the new reference.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from .assembly import first_index, sort_few

if TYPE_CHECKING:
    import scipy.sparse as sp

#: Columns of ``[Z V]`` past which :meth:`UpdatedFactor.update` declines. On a 1e4-vertex
#: sheet (2 cores) the product with 64 columns costs about 0.3 ms per solve, a solved column
#: about 0.35 ms and a factorisation 15 ms: 64 columns cost a factorisation's time or more
#: to solve, and the product about a third of the solve it corrects.
MAX_RANK = 64

#: :meth:`UpdatedFactor.update` also declines past this share of the matrix's rows in
#: columns: a small matrix is factored again faster than corrected.
MAX_SHARE = 1 / 16

#: Entries of ``Delta`` at most this times the largest diagonal entry of ``A_R`` are
#: rounding (a split sums shares back in another order), not a change.
ROUNDING = 1e-12

#: Condition number of the small system past which the correction is not trusted.
MAX_CONDITION = 1e10


def factor(a: "sp.csc_matrix"):
    """SuperLU factor of the canonical CSC matrix ``a`` (symmetric positive definite but for
    rows that are the identity's): no pivoting, a symmetric minimum-degree ordering (40%
    less fill than COLAMD on a 1e5 mesh)."""
    import scipy.sparse.linalg as spla

    return spla.splu(a, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))


@njit(cache=True)
def _blocks(ptr, ind, val, ref, copies, n0, rptr, rind, rval, tol, limit, cols):
    """The blocks of ``T^T A T`` against ``A_R`` (see the module docstring).

    ``(ptr, ind, val)``: ``A`` (CSC, n x n); ``ref``: each row's reference row; ``copies``:
    the rows that are copies, in order; ``(rptr, rind, rval)``: ``A_R`` (CSC, n0 x n0);
    ``cols``: the reference columns to compare (sorted; every other column group is taken to
    be its reference column: no copy in it or among its rows, no change).
    Returns ``Delta``'s entries above ``tol`` as ``(rows, cols, vals)`` (stopping once they
    touch more than ``limit`` rows: the caller refactors), ``B`` as CSC arrays (n0 x nc), ``C``
    as CSR arrays (nc x n0), both with sorted indices and no duplicates, and ``D`` (nc x nc).
    One pass over those columns of ``A`` and ``A_R``, no sorting but of a column's few rows.
    """
    n = ptr.shape[0] - 1
    nc = copies.shape[0]
    copy = np.full(n, -1, np.int64)
    for c in range(nc):
        copy[copies[c]] = c
    # current columns grouped by reference vertex (a counting sort)
    start = np.zeros(n0 + 1, np.int64)
    for j in range(n):
        start[ref[j] + 1] += 1
    for a in range(n0):
        start[a + 1] += start[a]
    fill = start[:-1].copy()
    group = np.empty(n, np.int64)
    for j in range(n):
        group[fill[ref[j]]] = j
        fill[ref[j]] += 1
    work = np.zeros(n0)
    seen = np.zeros(n0, np.bool_)
    touched = np.empty(n0, np.int64)
    d = np.zeros((nc, nc))
    # C's entries (row c = copy c's row of A, columns summed by reference vertex): those of
    # A's rows that are copies, bucketed by copy first
    c_count = np.zeros(nc + 1, np.int64)
    for a in cols:
        for g in range(start[a], start[a + 1]):
            j = group[g]
            for p in range(ptr[j], ptr[j + 1]):
                if copy[ind[p]] >= 0:
                    c_count[copy[ind[p]] + 1] += 1
    for c in range(nc):
        c_count[c + 1] += c_count[c]
    c_fill = c_count[:-1].copy()
    c_col = np.empty(c_count[nc], np.int64)
    c_val = np.empty(c_count[nc])
    # Delta's entries: at most n0 in a column, and the columns before the one where the dirty
    # rows pass limit have at most limit rows each
    dr = np.empty((limit + 1) * (limit + 1) + n0, np.int64)
    dc = np.empty(dr.shape[0], np.int64)
    dv = np.empty(dr.shape[0])
    nd = 0
    dirty = np.zeros(n0, np.bool_)
    n_dirty = 0
    for a in cols:
        nt = 0
        for g in range(start[a], start[a + 1]):
            j = group[g]
            cj = copy[j]
            for p in range(ptr[j], ptr[j + 1]):
                i = ind[p]
                r = ref[i]
                if not seen[r]:  # written out, not a helper: implicit._assemble says why
                    seen[r] = True
                    touched[nt] = r
                    nt += 1
                work[r] += val[p]
                ci = copy[i]
                if ci >= 0:
                    c_col[c_fill[ci]] = a
                    c_val[c_fill[ci]] = val[p]
                    c_fill[ci] += 1
                    if cj >= 0:
                        d[ci, cj] += val[p]
        for p in range(rptr[a], rptr[a + 1]):
            r = rind[p]
            if not seen[r]:
                seen[r] = True
                touched[nt] = r
                nt += 1
            work[r] -= rval[p]
        for t in range(nt):
            ri = touched[t]
            if abs(work[ri]) > tol:
                dr[nd], dc[nd], dv[nd] = ri, a, work[ri]
                nd += 1
                for q in (ri, a):
                    if not dirty[q]:
                        dirty[q] = True
                        n_dirty += 1
            work[ri] = 0.0
            seen[ri] = False
        if n_dirty > limit:  # the caller declines: B and C are not needed (and C is not complete)
            return dr[:nd], dc[:nd], dv[:nd], np.zeros(1, np.int64), np.zeros(0, np.int64), np.zeros(0), \
                np.zeros(1, np.int64), np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 0))
    # B's columns: each copy's column of A, rows summed by reference vertex
    b_ptr = np.zeros(nc + 1, np.int64)
    for c in range(nc):
        b_ptr[c + 1] = b_ptr[c] + ptr[copies[c] + 1] - ptr[copies[c]]
    b_ind = np.empty(b_ptr[nc], np.int64)
    b_val = np.empty(b_ptr[nc])
    out = 0
    for c in range(nc):
        j = copies[c]
        nt = 0
        for p in range(ptr[j], ptr[j + 1]):
            r = ref[ind[p]]
            if not seen[r]:
                seen[r] = True
                touched[nt] = r
                nt += 1
            work[r] += val[p]
        out = _emit_sorted(touched, nt, work, seen, b_ind, b_val, out)
        b_ptr[c + 1] = out
    # C's rows, canonical the same way
    cc_ptr = np.zeros(nc + 1, np.int64)
    out = 0
    for c in range(nc):
        nt = 0
        for p in range(c_count[c], c_count[c + 1]):
            r = c_col[p]
            if not seen[r]:
                seen[r] = True
                touched[nt] = r
                nt += 1
            work[r] += c_val[p]
        out = _emit_sorted(touched, nt, work, seen, c_col, c_val, out)  # in place: out <= p
        cc_ptr[c + 1] = out
    return dr[:nd], dc[:nd], dv[:nd], b_ptr, b_ind[:b_ptr[nc]], b_val[:b_ptr[nc]], cc_ptr, c_col[:out], \
        c_val[:out], d


@njit(cache=True, inline="always")
def _emit_sorted(touched, nt, work, seen, ind, val, out):
    """Write the ``nt`` touched rows of ``work`` (sorted, an insertion sort: a column's few
    rows) to ``ind, val`` from ``out``, clearing them; returns the new end."""
    sort_few(touched, nt)
    for a in range(nt):
        r = touched[a]
        ind[out] = r
        val[out] = work[r]
        out += 1
        work[r] = 0.0
        seen[r] = False
    return out


@njit(cache=True)
def _gather(b, primary, ref, copies):
    """``T^T b``'s first block: each reference vertex's primary row plus its copies' rows."""
    out = np.empty((primary.shape[0], b.shape[1]))
    for a in range(primary.shape[0]):
        out[a] = b[primary[a]]
    for i in copies:
        out[ref[i]] += b[i]
    return out


@njit(cache=True)
def _reduced(u, b, r, delta, copies, cptr, cind, cval, lu, piv):
    """The small system's solution ``(p, xi_c)`` for ``U = A_R^-1 b_o`` (``lu``, ``piv``:
    its LU factors with row interchanges, as LAPACK's getrf gives them). Compiled, as are
    the other steps of a solve: NumPy's BLAS calls on such small arrays cost milliseconds
    here, where BLAS threads wait on the kernels' threads."""
    ko, nc, m = r.shape[0], copies.shape[0], b.shape[1]
    rhs = np.zeros((ko + nc, m))
    for col in range(m):  # element by element: a row slice per term cost 0.1 ms at rank 46
        for i in range(ko):
            for j in range(ko):
                rhs[i, col] += delta[i, j] * u[r[j], col]
        for i in range(nc):
            rhs[ko + i, col] = b[copies[i], col]
            for p in range(cptr[i], cptr[i + 1]):
                rhs[ko + i, col] -= cval[p] * u[cind[p], col]
    k = ko + nc
    for i in range(k):  # the row interchanges, then L (unit diagonal), then U
        t = piv[i]
        if t != i:
            for col in range(m):
                rhs[i, col], rhs[t, col] = rhs[t, col], rhs[i, col]
    for col in range(m):
        for i in range(k):
            for j in range(i):
                rhs[i, col] -= lu[i, j] * rhs[j, col]
        for i in range(k - 1, -1, -1):
            for j in range(i + 1, k):
                rhs[i, col] -= lu[i, j] * rhs[j, col]
            rhs[i, col] /= lu[i, i]
    return rhs


@njit(cache=True)
def _small_system(store, slots, r, delta, cptr, cind, cval, d):
    """The small system's matrix (see the module docstring) from the solved columns ``[Z V]``
    (the store's ``slots``): ``[[I + Delta Z_r, Delta V_r], [-C Z, D - C V]]``, with ``C``
    as CSR arrays. Compiled: a few rows of ``[Z V]`` each, where NumPy's gathers and BLAS
    products cost more than the sums."""
    ko, nc, k = r.shape[0], cptr.shape[0] - 1, slots.shape[0]
    m = np.zeros((k, k))
    for i in range(ko):
        for t in range(k):
            col = slots[t]
            acc = 0.0
            for j in range(ko):
                acc += delta[i, j] * store[r[j], col]
            m[i, t] = acc
        m[i, i] += 1.0
    for i in range(nc):
        for t in range(k):
            col = slots[t]
            acc = 0.0
            for p in range(cptr[i], cptr[i + 1]):
                acc += cval[p] * store[cind[p], col]
            m[ko + i, t] = (d[i, t - ko] if t >= ko else 0.0) - acc
    return m


@njit(cache=True)
def _finish(u, store, slots, s, ref, copies, ko):
    """``x = T (U - [Z V] s)``: the correction, then each vertex its reference row plus,
    for a copy, its own unknown."""
    n0, m = u.shape
    k = slots.shape[0]
    t = 0
    if m == 2:  # x and y together, four columns of the store a pass: u is read and written a
        # quarter as often (0.19 against 0.39 ms for 46 columns of a 1e4-vertex sheet)
        while t + 4 <= k:
            c0, c1, c2, c3 = store[:, slots[t]], store[:, slots[t + 1]], store[:, slots[t + 2]], store[:, slots[t + 3]]
            a0, a1, a2, a3 = s[t, 0], s[t + 1, 0], s[t + 2, 0], s[t + 3, 0]
            b0, b1, b2, b3 = s[t, 1], s[t + 1, 1], s[t + 2, 1], s[t + 3, 1]
            for a in range(n0):
                u[a, 0] -= a0 * c0[a] + a1 * c1[a] + a2 * c2[a] + a3 * c3[a]
                u[a, 1] -= b0 * c0[a] + b1 * c1[a] + b2 * c2[a] + b3 * c3[a]
            t += 4
    for t in range(t, k):
        col = store[:, slots[t]]  # contiguous: the store is column-major
        for b in range(m):
            f = s[t, b]
            for a in range(n0):
                u[a, b] -= f * col[a]
    x = np.empty((ref.shape[0], m))
    for i in range(ref.shape[0]):
        r = ref[i]
        for b in range(m):
            x[i, b] = u[r, b]
    for c in range(copies.shape[0]):
        for b in range(m):
            x[copies[c], b] += s[ko + c, b]
    return x


class UpdatedFactor:
    """Solves with a sparse matrix through the factor of a reference matrix and a low-rank
    correction (see the module docstring).

    Parameters
    ----------
    a : scipy.sparse.csc_matrix
        The reference matrix ``A_R`` (canonical CSC), factored here.

    Attributes
    ----------
    rank : int
        Columns of the correction (0 right after factoring).
    max_rank, max_share : int, float
        Past ``max_rank`` columns, or ``max_share`` of the rows, :meth:`update` declines
        (defaults :data:`MAX_RANK`, :data:`MAX_SHARE`).
    solves : int
        Columns solved with the reference factor to build corrections (a measure of the
        updates' cost).
    solution : ndarray or None
        The solution of the right-hand side the last :meth:`update` was given.

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> a = sp.csc_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    >>> f = UpdatedFactor(a)
    >>> f.max_share = 1.0  # a matrix this small would rather be factored again
    >>> b = sp.csc_matrix(np.array([[2.0, -1.0, 0.0], [-1.0, 1.5, 0.0], [0.0, 0.0, 0.5]]))  # vertex 1 split
    >>> f.update(b, np.array([0, 1, 1]))
    True
    >>> np.allclose(b @ f.solve(np.array([1.0, 2.0, 3.0])), [1.0, 2.0, 3.0])
    True
    """

    def __init__(self, a: "sp.csc_matrix"):
        self.max_rank = MAX_RANK
        self.max_share = MAX_SHARE
        self.solves = 0
        self.solution = None
        self._reference(a)

    def _reference(self, a):
        self._a = a
        self._lu = factor(a)
        self._n0 = a.shape[0]
        self._tol = ROUNDING * float(np.abs(a.diagonal()).max(initial=0.0))
        # Solved columns (A_R^-1 e_row for Delta's rows, A_R^-1 B[:, c] for the copies), kept
        # while the reference stays, one per slot of a column-major store
        self._store = np.empty((self._n0, 0), order="F")
        self._slot = {}  # ("row", r) or a column of B by its bytes -> slot
        self._identity()

    def _identity(self):
        self.rank = 0
        self._ref = None  # the current matrix is A_R itself

    def update(self, a: "sp.csc_matrix", ref: np.ndarray, cols=None, rhs=None) -> bool:
        """Solve with ``a`` from now on, where current vertex ``i`` comes from reference vertex
        ``ref[i]`` (every reference vertex at least once). Returns False, changing nothing,
        when the correction would be too large or ill-conditioned: factor ``a`` instead
        (:meth:`refactor`).

        ``cols``: when the caller knows them, the reference vertices whose columns may differ
        (those of every changed entry, copy or copy's neighbour); only they are compared.

        ``rhs``: a right-hand side ((n,) or (n, k)) the caller will solve next: it is solved
        with ``a`` in the same call into the factor as the correction's new columns, and
        left in :attr:`solution` (``None`` when this returns False). On a 1e4-vertex sheet a
        call costs 0.5 ms with one right-hand side and 0.25 ms for each one more, so a call
        of its own cost the columns about a right-hand side's time more.
        """
        import scipy.linalg as sla

        self.solution = None

        n, n0 = a.shape[0], self._n0
        ref = np.ascontiguousarray(ref, dtype=np.int64)
        if ref.shape != (n,) or (n and (ref.min() < 0 or ref.max() >= n0)):
            raise ValueError("ref must map every row of the matrix to a row of the reference")
        first = first_index(ref, n0)  # the lowest current index of each reference vertex
        if (first < 0).any():
            raise ValueError("ref must reach every row of the reference")
        copies = np.flatnonzero(first[ref] != np.arange(n))
        nc = len(copies)
        most = min(self.max_rank, int(self.max_share * n0))
        if nc > most:
            return False
        if cols is not None:
            cols = np.unique(np.asarray(cols, dtype=np.int64))
            if len(cols) and (cols[0] < 0 or cols[-1] >= n0):
                raise ValueError("cols must be rows of the reference")
        dr, dc, dv, b_ptr, b_ind, b_val, c_ptr, c_ind, c_val, d = _blocks(
            a.indptr, a.indices, a.data, ref, copies, n0,  # SciPy's own arrays: no copies
            self._a.indptr, self._a.indices, self._a.data, self._tol, most - nc,
            np.arange(n0) if cols is None else np.ascontiguousarray(cols, dtype=np.int64))
        r = np.union1d(dr, dc)
        ko = len(r)
        k = ko + nc
        if k > most:
            return False
        if k == 0:
            self._identity()
            if rhs is not None:
                self.solution = self._lu.solve(rhs)
            return True
        delta = np.zeros((ko, ko))
        np.add.at(delta, (np.searchsorted(r, dr), np.searchsorted(r, dc)), dv)
        b = (b_ptr, b_ind, b_val)
        keys = [("row", int(x)) for x in r] + [
            b_ind[b_ptr[j]:b_ptr[j + 1]].tobytes() + b_val[b_ptr[j]:b_ptr[j + 1]].tobytes() for j in range(nc)]
        extra = None if rhs is None else _gather(rhs.reshape(n, -1), first, ref, copies)
        slots, u = self._columns(keys, b, extra)
        m = _small_system(self._store, slots, r, delta, c_ptr, c_ind, c_val, d)
        if not np.all(np.isfinite(m)):
            return False
        lu, piv = sla.lu_factor(m, check_finite=False)
        rcond, info = sla.lapack.dgecon(lu, np.abs(m).sum(axis=0).max())  # LAPACK's estimate, from the LU
        if info != 0 or not rcond * MAX_CONDITION > 1.0:
            return False
        self._small = (lu, piv.astype(np.int64))
        self._slots = slots
        self._delta, self._r, self._c = delta, r, (c_ptr, c_ind, c_val)
        self._ref, self._copies, self._primary = ref, copies, first
        self.rank = k
        if rhs is not None:
            self.solution = self._corrected(u, rhs)
        return True

    def refactor(self, a: "sp.csc_matrix") -> None:
        """Factor ``a``, which becomes the reference."""
        self._reference(a)

    def _columns(self, keys, b, extra=None):
        """Slots of the store holding the solved column of each key (``("row", r)``: the
        identity's column ``r``; bytes: copy ``j``'s column of ``B``, CSC arrays ``b``), solving the missing
        ones in one batch; columns no key names may be dropped to make room. ``extra``
        (n0, w): more right-hand sides for the same batch; returns ``(slots, their
        solutions)`` (``None`` without)."""
        missing = [t for t, key in enumerate(keys) if key not in self._slot]
        w = 0 if extra is None else extra.shape[1]
        solved_extra = None
        if not missing and extra is not None:
            solved_extra = self._lu.solve(extra)
        if missing:
            rhs = np.zeros((self._n0, len(missing) + w), order="F")
            if w:
                rhs[:, len(missing):] = extra
            b_ptr, b_ind, b_val = b
            nr = sum(isinstance(key, tuple) for key in keys)
            for col, t in enumerate(missing):
                if t < nr:
                    rhs[keys[t][1], col] = 1.0
                else:
                    j = t - nr
                    lo, hi = b_ptr[j], b_ptr[j + 1]
                    rhs[b_ind[lo:hi], col] = b_val[lo:hi]
            self.solves += len(missing)
            solved = self._lu.solve(rhs)
            if w:
                solved_extra = solved[:, len(missing):]
            used = set(self._slot[key] for key in keys if key in self._slot)
            if self._ref is not None:  # the correction in use keeps its columns until replaced
                used.update(int(t) for t in self._slots)
            free = [t for t in range(self._store.shape[1]) if t not in used]
            if len(free) < len(missing):  # grow the store (to 2 max_rank + 16 columns: older ones are dropped)
                # (at least 2 columns: a one-column array is C-contiguous too, and the kernels
                # compiled a second time for it, 1.6 s into a run of `crates`)
                cap = max(2, len(used) + len(missing), min(2 * self._store.shape[1], 2 * self.max_rank + 16))
                grown = np.empty((self._n0, cap), order="F")
                grown[:, :self._store.shape[1]] = self._store
                free += list(range(self._store.shape[1], cap))
                self._store = grown
            taken = {t: key for key, t in self._slot.items()}
            for col, t in enumerate(missing):
                slot = free[col]
                if slot in taken:
                    del self._slot[taken[slot]]
                self._slot[keys[t]] = slot
                self._store[:, slot] = solved[:, col]
        return np.array([self._slot[key] for key in keys], np.int64), solved_extra

    def solve(self, b: np.ndarray) -> np.ndarray:
        """``A^-1 b`` for the current matrix ``A``; ``b`` is (n,) or (n, k)."""
        if self._ref is None:
            return self._lu.solve(b)
        b2 = b.reshape(len(b), -1)
        return self._corrected(self._lu.solve(_gather(b2, self._primary, self._ref, self._copies)), b)

    def _corrected(self, u, b):
        """``A^-1 b`` from ``u = A_R^-1 T^T b``'s first block (the correction in use)."""
        b2 = b.reshape(len(b), -1)
        u = u.reshape(len(u), -1)
        lu, piv = self._small
        s = _reduced(u, b2, self._r, self._delta, self._copies, *self._c, lu, piv)
        x = _finish(u, self._store, self._slots, s, self._ref, self._copies, len(self._r))
        return x.reshape(b.shape)

    def __deepcopy__(self, memo):
        # SciPy's SuperLU factor can be neither copied nor pickled: the copy factors the same
        # reference matrix again (the same factor, bit for bit) the first time it solves.
        import copy

        new = type(self).__new__(type(self))
        memo[id(self)] = new
        for name, value in self.__dict__.items():
            if name != "_lu":
                new.__dict__[name] = copy.deepcopy(value, memo)
        new._lu = _FactorOnFirstSolve(new)
        return new


class _FactorOnFirstSolve:
    """A copied :class:`UpdatedFactor`'s reference factor until its first solve."""

    def __init__(self, owner):
        self.owner = owner

    def solve(self, b):
        self.owner._lu = factor(self.owner._a)
        return self.owner._lu.solve(b)

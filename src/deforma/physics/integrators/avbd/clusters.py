"""A coarse level for block descent: patches of vertices moved by one affine map each.

A vertex sweep carries a correction one ring of vertices per colour pass, so the slow modes
of a large body (its sag under its own weight, a column's stretch) take hundreds of sweeps:
the README's 3.7 m springs bunny on a floor folded at ten sweeps a step. Between sweeps,
each patch ("cluster") of about ``size`` neighbouring vertices takes one Newton step over
the affine motions ``dx_v = d + A (x_v - c)`` of its vertices (6 unknowns: ``d``, and the
2 x 2 ``A``), the rest held: the same objective as the vertex blocks (inertia, elements,
grabs, contact rows), its gradient and Hessian gathered through the Jacobian of each
element's deformation gradient in ``(d, A)``. Patches are visited one after another
(Gauss-Seidel), so a correction crosses a patch per visit instead of a ring.

Element by element: a triangle with the patch's corners ``v`` moving has ``dF[a, c] = d[a]
S_c + sum_b A[a, b] T_bc`` with ``S_c = sum_v D_v[c]``, ``T_bc = sum_v r_v[b] D_v[c]`` (for a
triangle inside the patch ``S = 0`` and ``T = F``: ``dF = A F``); a spring with its ends
``i``, ``j`` gets ``d(x_j - x_i) = `` the moving ends' ``+-(d + A r)``.

Units: m, s, kg, N, N/m.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ...elements import corotated, neo_hookean
from ...elements.triangles import deformation_gradient, rate_stress, stress
from ...material import KIND_COROTATED
from .blocks import outer_block


def make_clusters(x, body_start, inv_mass, size):
    """Group each body's free vertices into patches of about ``size`` by a grid over their
    positions ``x``: ``(cluster (N,) int64, -1 for pinned vertices; count)``."""
    n = len(x)
    cluster = np.full(n, -1, np.int64)
    count = 0
    for body in range(len(body_start) - 1):
        lo, hi = int(body_start[body]), int(body_start[body + 1])
        free = np.flatnonzero(inv_mass[lo:hi] != 0.0) + lo
        if len(free) == 0:
            continue
        p = x[free]
        span = np.maximum(np.ptp(p, axis=0), 1e-12)
        cells = max(1, round(len(free) / size))
        # square cells: as many as it takes to hold about `size` vertices each
        side = float(np.sqrt(span[0] * span[1] / cells)) if span.min() > 1e-9 else float(span.max() / cells)
        side = max(side, 1e-12)
        key = np.floor((p - p.min(axis=0)) / side).astype(np.int64)
        _, label = np.unique(key[:, 0] * (1 << 31) + key[:, 1], return_inverse=True)
        cluster[free] = label + count
        count += int(label.max()) + 1
    return cluster, count


def cluster_members(cluster, count, items):
    """CSR lists: each cluster's vertices, and the items (triangles (T, 3) or springs (E, 2))
    with a corner in it: ``(v_start, v_list, e_start, e_list)``."""
    free = np.flatnonzero(cluster >= 0)
    order = free[np.argsort(cluster[free], kind="stable")]
    v_start = np.searchsorted(cluster[order], np.arange(count + 1))
    if len(items):
        c = cluster[items]  # (E, k)
        pairs = np.unique(np.stack([np.repeat(np.arange(len(items)), items.shape[1]), c.ravel()], axis=1), axis=0)
        pairs = pairs[pairs[:, 1] >= 0]
        pairs = pairs[np.argsort(pairs[:, 1], kind="stable")]
        e_start = np.searchsorted(pairs[:, 1], np.arange(count + 1))
        e_list = pairs[:, 0].astype(np.int64)
    else:
        e_start, e_list = np.zeros(count + 1, np.int64), np.zeros(0, np.int64)
    return v_start.astype(np.int64), order.astype(np.int64), e_start.astype(np.int64), e_list


#: the unknowns that move x, and those that move y (``_X_UNKNOWNS[p]``, ``_Y_UNKNOWNS[p]``
#: pair with entry ``p`` of the ``a`` in :func:`add_moments` and the columns of ``J0`` in
#: :func:`_add_jacobian_terms`)
_X_UNKNOWNS = (0, 2, 3)
_Y_UNKNOWNS = (1, 4, 5)


@njit(cache=True, inline="always")
def _add_jacobian_terms(g, hm, j00, j01, j02, j10, j11, j12, p0, p1, p2, p3, hf, a):
    """``g += a jac^T p``, ``hm += a jac^T hf jac`` for a triangle's (4, 6) ``jac`` of vec F
    ``(F00, F01, F10, F11)`` in the unknowns, ``p`` its stress (4) and ``hf`` its stress
    derivative (4, 4). ``jac`` is ``J0`` (2 x 3, rows ``j0.``, ``j1.``) twice: F's first row
    moves with the x unknowns alone, its second with the y ones, so ``jac^T hf jac`` is four
    3 x 3 blocks ``J0^T hf_uv J0`` of the 2 x 2 blocks of ``hf`` (the full 4 x 6 products
    cost the patches a fifth of their time). Each block is summed as the full product sums
    it, so the result is the same to the last bit."""
    j0, j1 = (j00, j01, j02), (j10, j11, j12)  # J0's rows
    for p in range(3):
        g[_X_UNKNOWNS[p]] += a * (j0[p] * p0 + j1[p] * p1)
        g[_Y_UNKNOWNS[p]] += a * (j0[p] * p2 + j1[p] * p3)
    for bu in range(2):
        for bv in range(2):
            h00, h01 = hf[2 * bu, 2 * bv], hf[2 * bu, 2 * bv + 1]
            h10, h11 = hf[2 * bu + 1, 2 * bv], hf[2 * bu + 1, 2 * bv + 1]
            for q in range(3):
                m0, m1 = h00 * j0[q] + h01 * j1[q], h10 * j0[q] + h11 * j1[q]  # (hf_uv J0)[:, q]
                cq = _X_UNKNOWNS[q] if bv == 0 else _Y_UNKNOWNS[q]
                for p in range(3):
                    val = a * (j0[p] * m0 + j1[p] * m1)
                    hm[_X_UNKNOWNS[p] if bu == 0 else _Y_UNKNOWNS[p], cq] += val


@njit(cache=True, inline="always")
def add_moments(mom, gx, gy, hxx, hxy, hyy, a0, a1, a2):
    """Add a term whose x and y move by ``a . (d0, A00, A01)`` and ``a . (d1, A10, A11)``, with
    gradient ``(gx, gy)`` and Hessian ``[[hxx, hxy], [hxy, hyy]]``, to the moments ``mom``
    (24,): ``sum g_x a``, ``sum g_y a``, then the upper triangles of ``sum h_xx a a^T``,
    ``sum h_xy a a^T`` and ``sum h_yy a a^T``. Summed here and spread over the 6 x 6 system
    once a patch (:func:`add_moment_terms`): spread per vertex and spring, the patches took
    twice as long as the vertex sweep."""
    mom[0] += gx * a0
    mom[1] += gx * a1
    mom[2] += gx * a2
    mom[3] += gy * a0
    mom[4] += gy * a1
    mom[5] += gy * a2
    p00, p01, p02, p11, p12, p22 = a0 * a0, a0 * a1, a0 * a2, a1 * a1, a1 * a2, a2 * a2
    mom[6] += hxx * p00
    mom[7] += hxx * p01
    mom[8] += hxx * p02
    mom[9] += hxx * p11
    mom[10] += hxx * p12
    mom[11] += hxx * p22
    mom[12] += hxy * p00
    mom[13] += hxy * p01
    mom[14] += hxy * p02
    mom[15] += hxy * p11
    mom[16] += hxy * p12
    mom[17] += hxy * p22
    mom[18] += hyy * p00
    mom[19] += hyy * p01
    mom[20] += hyy * p02
    mom[21] += hyy * p11
    mom[22] += hyy * p12
    mom[23] += hyy * p22


#: where entry (p, q) of a symmetric 3 x 3 lies in an upper triangle of :func:`add_moments`
_UPPER = ((0, 1, 2), (1, 3, 4), (2, 4, 5))


@njit(cache=True)
def add_moment_terms(mom, g, hm):
    """Spread :func:`add_moments`' sums over the patch's gradient ``g`` (6,) and Hessian
    ``hm`` (6, 6)."""
    for p in range(3):
        xp, yp = _X_UNKNOWNS[p], _Y_UNKNOWNS[p]
        g[xp] += mom[p]
        g[yp] += mom[3 + p]
        for q in range(3):
            xq, yq = _X_UNKNOWNS[q], _Y_UNKNOWNS[q]
            u = _UPPER[p][q]
            hm[xp, xq] += mom[6 + u]
            hm[xp, yq] += mom[12 + u]
            hm[yp, xq] += mom[12 + u]
            hm[yp, yq] += mom[18 + u]


@njit(cache=True)
def cluster_sweep(x, x_n, y, mass_h2, cluster, v_start, v_list, te_start, te_list, se_start, se_list, elem, b,
                  area, mu, lam, beta, kind, spring_i, spring_j, rest, ks, kd, grab_slot, grab_pull, rs, inv_h):
    """One Gauss-Seidel pass over the clusters, each an affine Newton step (module docstring)."""
    hf = np.empty((4, 4))
    cf = np.empty((4, 4))
    pvec = np.empty(4)
    g = np.empty(6)
    hm = np.empty((6, 6))
    mom = np.empty(24)
    delta = np.empty(6)
    n_clusters = v_start.shape[0] - 1
    for cl in range(n_clusters):
        lo, hi = v_start[cl], v_start[cl + 1]
        if hi - lo < 4:
            continue
        touching = False
        for p in range(lo, hi):
            if rs.rowed[v_list[p]]:
                touching = True
        if touching:
            # a patch on a contact is left to the vertex blocks and the whole-body step:
            # moved affinely against its rows (piecewise, with friction), it sheared a
            # block sliding down a slope to a stop
            continue
        sm = cx = cy = 0.0
        for p in range(lo, hi):
            i = v_list[p]
            sm += mass_h2[i]
            cx += mass_h2[i] * x[i, 0]
            cy += mass_h2[i] * x[i, 1]
        cx /= sm
        cy /= sm
        for p in range(6):
            g[p] = 0.0
            for q in range(6):
                hm[p, q] = 0.0
        for p in range(24):
            mom[p] = 0.0
        # unknowns: (d0, d1, A00, A01, A10, A11); dx_v = (d0 + A00 rx + A01 ry, d1 + A10 rx + A11 ry):
        # a vertex moves its x by a . (d0, A00, A01) and its y by a . (d1, A10, A11), a = (1, rx, ry)
        for p in range(lo, hi):
            i = v_list[p]
            gx, gy, hxx, hxy, hyy = outer_block(x, y, i, mass_h2, grab_slot, grab_pull)  # no rows: see above
            add_moments(mom, gx, gy, hxx, hxy, hyy, 1.0, x[i, 0] - cx, x[i, 1] - cy)
        # triangles with a corner in the cluster
        for q in range(te_start[cl], te_start[cl + 1]):
            e = te_list[q]
            i0, i1, i2 = elem[e, 0], elem[e, 1], elem[e, 2]
            b0, b1, b2, b3 = b[e, 0], b[e, 1], b[e, 2], b[e, 3]
            s0 = s1 = t00 = t01 = t10 = t11 = 0.0
            for corner in range(3):
                v = elem[e, corner]
                if cluster[v] != cl:
                    continue
                if corner == 1:
                    d0, d1 = b0, b1
                elif corner == 2:
                    d0, d1 = b2, b3
                else:
                    d0, d1 = -b0 - b2, -b1 - b3
                rx, ry = x[v, 0] - cx, x[v, 1] - cy
                s0 += d0
                s1 += d1
                t00 += rx * d0
                t01 += rx * d1
                t10 += ry * d0
                t11 += ry * d1
            # vec F = (F00, F01, F10, F11); dF[a, c] = d[a] S_c + A[a, 0] T_0c + A[a, 1] T_1c: its
            # Jacobian in the unknowns is J0 = [[s0, t00, t10], [s1, t01, t11]] for each row of F
            f00, f01, f10, f11 = deformation_gradient(x, i0, i1, i2, b0, b1, b2, b3)
            p00, p01, p10, p11 = stress(kind[e], f00, f01, f10, f11, mu[e], lam[e])
            pvec[0], pvec[1], pvec[2], pvec[3] = p00, p01, p10, p11
            if kind[e] == KIND_COROTATED:
                corotated.stress_derivative(f00, f01, f10, f11, mu[e], lam[e], hf)
            else:
                neo_hookean.stress_derivative(f00, f01, f10, f11, mu[e], lam[e], hf)
            be = beta[e]
            if be > 0.0:
                q00, q01, q10, q11 = deformation_gradient(x_n, i0, i1, i2, b0, b1, b2, b3)
                u00, u01, u10, u11 = rate_stress(f00, f01, f10, f11, (f00 - q00) * inv_h, (f01 - q01) * inv_h,
                                                 (f10 - q10) * inv_h, (f11 - q11) * inv_h, mu[e], lam[e])
                pvec[0] += be * u00
                pvec[1] += be * u01
                pvec[2] += be * u10
                pvec[3] += be * u11
                # the damping stress's linear map, times beta / h
                for col in range(4):
                    e00 = 1.0 if col == 0 else 0.0
                    e01 = 1.0 if col == 1 else 0.0
                    e10 = 1.0 if col == 2 else 0.0
                    e11 = 1.0 if col == 3 else 0.0
                    c00, c01, c10, c11 = rate_stress(f00, f01, f10, f11, e00, e01, e10, e11, mu[e], lam[e])
                    cf[0, col], cf[1, col], cf[2, col], cf[3, col] = c00, c01, c10, c11
                for mm in range(4):
                    for kk in range(4):
                        hf[mm, kk] += be * inv_h * 0.5 * (cf[mm, kk] + cf[kk, mm])
            _add_jacobian_terms(g, hm, s0, t00, t10, s1, t01, t11, pvec[0], pvec[1], pvec[2], pvec[3], hf,
                                area[e])
        # springs with an end in the cluster
        for q in range(se_start[cl], se_start[cl + 1]):
            e = se_list[q]
            i, j = spring_i[e], spring_j[e]
            dx = x[j, 0] - x[i, 0]
            dy = x[j, 1] - x[i, 1]
            length = np.sqrt(dx * dx + dy * dy)
            if length > 0.0:
                ux, uy = dx / length, dy / length
                tt = max(1.0 - rest[e] / length, 0.0)
            else:
                ux, uy, tt = 1.0, 0.0, 0.0
            rv = ((x[j, 0] - x_n[j, 0] - x[i, 0] + x_n[i, 0]) * ux
                  + (x[j, 1] - x_n[j, 1] - x[i, 1] + x_n[i, 1]) * uy) * inv_h
            f = ks[e] * (length - rest[e]) + kd[e] * rv
            kk = ks[e] + kd[e] * inv_h
            kxx = kk * ux * ux + ks[e] * tt * (1.0 - ux * ux)
            kxy = kk * ux * uy - ks[e] * tt * ux * uy
            kyy = kk * uy * uy + ks[e] * tt * (1.0 - uy * uy)
            # J of (x_j - x_i) in the unknowns: the moving ends' +-(d + A r), as (sign, rx, ry)
            # sums: jx = (sg, 0, srx, sry, 0, 0), jy = (0, sg, 0, 0, srx, sry)
            sg = srx = sry = 0.0
            for end in range(2):
                v = j if end == 1 else i
                if cluster[v] != cl:
                    continue
                w = 1.0 if end == 1 else -1.0
                sg += w
                srx += w * (x[v, 0] - cx)
                sry += w * (x[v, 1] - cy)
            add_moments(mom, f * ux, f * uy, kxx, kxy, kyy, sg, srx, sry)
        add_moment_terms(mom, g, hm)
        # the Newton step: H delta = -g, H projected to be positive definite (eigenvalues
        # below a small share of the inertia's raised to it)
        w, vec = np.linalg.eigh(hm)
        floor = 1e-3 * sm
        for a in range(6):
            delta[a] = 0.0
        for mm in range(6):
            lam_m = max(w[mm], floor)
            s = 0.0
            for a in range(6):
                s += vec[a, mm] * g[a]
            for a in range(6):
                delta[a] -= vec[a, mm] * s / lam_m
        for p in range(lo, hi):
            i = v_list[p]
            rx, ry = x[i, 0] - cx, x[i, 1] - cy
            x[i, 0] += delta[0] + delta[2] * rx + delta[3] * ry
            x[i, 1] += delta[1] + delta[4] * rx + delta[5] * ry

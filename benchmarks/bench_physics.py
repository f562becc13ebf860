"""Physics benchmark: steps per second of one soft body among a few colliders.

Peers, measured in the same run on the same mesh and state:

- a bare Numba spring-force kernel (serial edge loop scattering into ``f``: the obvious
  way to write it), the same kernel with deforma's indexing trick (the fair yardstick for
  "how much does the rest of the step cost"), and the forces alone on all cores (per-spring
  forces plus a per-vertex gather);
- an idiomatic NumPy implementation of the same full step (vectorised forces with
  ``np.bincount``, symplectic Euler, the same collision and Coulomb friction scheme);
- the same full step written for Taichi's CPU backend (``ti.init(arch=ti.cpu)``, atomic
  scatter of spring forces, one parallel vertex loop for integration and collisions).

The deforma figure is a full ``world.step()``: forces, integration, collisions against
three rotated rectangles, friction and the blow-up check.
"""


import gc
import math
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import numba
from numba import njit

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Row  # noqa: E402

import deforma  # noqa: E402
from deforma.physics.colliders.shapes import pack_colliders  # noqa: E402

GRAVITY = (0.0, -9.81)


def grid_mesh(n: int, size: float = 1.0) -> deforma.mesh.Mesh:
    """n x n vertices on a size x size square, two triangles per cell."""
    xs, ys = np.meshgrid(np.linspace(0, size, n), np.linspace(0, size, n))
    idx = np.arange(n * n).reshape(n, n)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    return deforma.mesh.Mesh(np.c_[xs.ravel(), ys.ravel()], np.r_[np.c_[a, b, c], np.c_[a, c, d]])


def make_world(n: int):
    """A 1 m body of n*n vertices on a floor (its bottom row in contact), a slope and a box beside it."""
    w = deforma.World(sleep=False, dt=1 / 600, integrator="symplectic-euler", gravity=GRAVITY, stiffness=2000.0,
                      damping=0.5, mass=1.0)
    w.add_collider(deforma.Rect((0.0, -0.25), (4.0, 0.5), 0.0))
    w.add_collider(deforma.Rect((-1.2, 0.5), (0.8, 0.1), 30.0))
    w.add_collider(deforma.Rect((1.0, 0.1), (0.2, 0.2), 10.0))
    body = w.add_body(grid_mesh(n), position=(0.0, 0.5 + 1e-6))  # touching the floor at once
    w.dt = 0.5 * w.stable_dt()
    return w, body


@njit(cache=True)
def bare_spring_forces(x, v, si, sj, rest, ks, kd, f):
    """The obvious spring-force kernel: one serial edge loop, scatter to both ends."""
    f[:] = 0.0
    for e in range(si.shape[0]):
        i = si[e]
        j = sj[e]
        dx = x[j, 0] - x[i, 0]
        dy = x[j, 1] - x[i, 1]
        length = math.sqrt(dx * dx + dy * dy)
        nx = dx / length
        ny = dy / length
        s = ks[e] * (length - rest[e]) + kd[e] * ((v[j, 0] - v[i, 0]) * nx + (v[j, 1] - v[i, 1]) * ny)
        f[i, 0] += s * nx
        f[i, 1] += s * ny
        f[j, 0] -= s * nx
        f[j, 1] -= s * ny


@njit(cache=True)
def bare_spring_forces_tuned(x, v, si, sj, rest, ks, kd, f):
    """The same kernel with deforma's one trick: indices Numba knows are >= 0 (loop over
    range(len), vertex ids read as unsigned) skip the negative-index wraparound test."""
    f[:] = 0.0
    for e in range(si.shape[0]):
        i = np.uint64(si[e])
        j = np.uint64(sj[e])
        dx = x[j, 0] - x[i, 0]
        dy = x[j, 1] - x[i, 1]
        length = math.sqrt(dx * dx + dy * dy)
        nx = dx / length
        ny = dy / length
        s = ks[e] * (length - rest[e]) + kd[e] * ((v[j, 0] - v[i, 0]) * nx + (v[j, 1] - v[i, 1]) * ny)
        f[i, 0] += s * nx
        f[i, 1] += s * ny
        f[j, 0] -= s * nx
        f[j, 1] -= s * ny


def numpy_step(x, v, m, si, sj, rest, ks, kd, rects, h):
    """The same full step in idiomatic NumPy (one collision pass per rectangle)."""
    n = len(x)
    d = x[sj] - x[si]
    length = np.sqrt(np.einsum("ij,ij->i", d, d))
    u = d / length[:, None]
    s = ks * (length - rest) + kd * np.einsum("ij,ij->i", v[sj] - v[si], u)
    fe = s[:, None] * u
    f = np.empty_like(x)
    for k in range(2):
        f[:, k] = np.bincount(si, fe[:, k], n) - np.bincount(sj, fe[:, k], n) + m * GRAVITY[k]
    x0 = x.copy()
    v += h * f / m[:, None]
    x += h * v
    for r in rects:
        c, ax, hx, hy, mu_d, mu_s, skin = r[0:2], r[2:4], r[4], r[5], r[6], r[7], r[12]
        perp = np.array([-ax[1], ax[0]])
        p = x - c
        a, b = p @ ax, p @ perp
        inside = (np.abs(a) < hx) & (np.abs(b) < hy)
        if not inside.any():
            continue
        idx = np.flatnonzero(inside)
        a, b = a[idx], b[idx]
        p0 = x0[idx] - c
        a0, b0 = p0 @ ax, p0 @ perp
        came = (a0 >= hx) | (a0 <= -hx) | (b0 >= hy) | (b0 <= -hy)
        depth = np.stack([hx - a, hx + a, hy - b, hy + b], axis=1)
        allowed = np.stack([a0 >= hx, a0 <= -hx, b0 >= hy, b0 <= -hy], axis=1) | ~came[:, None]
        face = np.argmin(np.where(allowed, depth, np.inf), axis=1)
        normals = np.array([ax, -ax, perp, -perp])[face]
        tangents = np.array([perp, perp, ax, ax])[face]
        along = np.where(face < 2, b, a)
        dist = np.where(face < 2, hx, hy) + skin
        vv = v[idx]
        vn = np.einsum("ij,ij->i", vv, normals)
        vt = np.einsum("ij,ij->i", vv, tangents)
        jn = np.maximum(-vn, 0.0)
        vn = np.maximum(vn, 0.0)
        stick = np.abs(vt) <= mu_s * jn
        vt_new = np.where(stick, 0.0, np.sign(vt) * np.maximum(np.abs(vt) - mu_d * jn, 0.0))
        along = along + h * (vt_new - vt)
        x[idx] = c + dist[:, None] * normals + along[:, None] * tangents
        v[idx] = vn[:, None] * normals + vt_new[:, None] * tangents
    return x, v


class TaichiStep:
    """The same full step for Taichi's CPU backend (built once per mesh)."""

    def __init__(self, x, v, m, si, sj, rest, ks, kd, rects):
        import taichi as ti

        n, e, r = len(x), len(si), len(rects)
        self.x = ti.Vector.field(2, ti.f64, n)
        self.v = ti.Vector.field(2, ti.f64, n)
        self.f = ti.Vector.field(2, ti.f64, n)
        self.m = ti.field(ti.f64, n)
        self.si, self.sj = ti.field(ti.i32, e), ti.field(ti.i32, e)
        self.rest, self.ks, self.kd = ti.field(ti.f64, e), ti.field(ti.f64, e), ti.field(ti.f64, e)
        self.rects = ti.field(ti.f64, (r, rects.shape[1]))
        for fld, arr in ((self.x, x), (self.v, v), (self.m, m), (self.si, si), (self.sj, sj), (self.rest, rest),
                         (self.ks, ks), (self.kd, kd), (self.rects, rects)):
            fld.from_numpy(np.ascontiguousarray(arr))
        X, V, F, M, SI, SJ, REST, KS, KD, R = (self.x, self.v, self.f, self.m, self.si, self.sj, self.rest,
                                                self.ks, self.kd, self.rects)
        gx, gy = GRAVITY

        @ti.kernel
        def forces():
            for i in F:
                F[i] = M[i] * ti.Vector([gx, gy])
            for k in SI:
                i, j = SI[k], SJ[k]
                d = X[j] - X[i]
                length = d.norm()
                u = d / length
                s = KS[k] * (length - REST[k]) + KD[k] * (V[j] - V[i]).dot(u)
                F[i] += s * u
                F[j] -= s * u

        @ti.kernel
        def integrate_collide(h: ti.f64):
            for i in X:
                p0 = X[i]
                vel = V[i] + h * F[i] / M[i]
                p = p0 + h * vel
                for q in range(r):
                    c = ti.Vector([R[q, 0], R[q, 1]])
                    ax = ti.Vector([R[q, 2], R[q, 3]])
                    perp = ti.Vector([-ax[1], ax[0]])
                    hx, hy = R[q, 4], R[q, 5]
                    a, b = (p - c).dot(ax), (p - c).dot(perp)
                    if ti.abs(a) < hx and ti.abs(b) < hy:
                        a0, b0 = (p0 - c).dot(ax), (p0 - c).dot(perp)
                        came = a0 >= hx or a0 <= -hx or b0 >= hy or b0 <= -hy
                        best = 1e300
                        nrm = ax
                        tan = perp
                        along = b
                        dist = hx
                        if (not came or a0 >= hx) and hx - a < best:
                            best, nrm, tan, along, dist = hx - a, ax, perp, b, hx
                        if (not came or a0 <= -hx) and hx + a < best:
                            best, nrm, tan, along, dist = hx + a, -ax, perp, b, hx
                        if (not came or b0 >= hy) and hy - b < best:
                            best, nrm, tan, along, dist = hy - b, perp, ax, a, hy
                        if (not came or b0 <= -hy) and hy + b < best:
                            best, nrm, tan, along, dist = hy + b, -perp, ax, a, hy
                        vn = vel.dot(nrm)
                        vt = vel.dot(tan)
                        jn = ti.max(-vn, 0.0)
                        vn = ti.max(vn, 0.0)
                        vt_new = vt
                        if ti.abs(vt) <= R[q, 7] * jn:
                            vt_new = 0.0
                        else:
                            vt_new = ti.math.sign(vt) * ti.max(ti.abs(vt) - R[q, 6] * jn, 0.0)
                        along += h * (vt_new - vt)
                        p = c + (dist + R[q, 12]) * nrm + along * tan
                        vel = vn * nrm + vt_new * tan
                X[i] = p
                V[i] = vel

        self._forces, self._integrate = forces, integrate_collide
        self._sync = ti.sync

    def step(self, h):
        self._forces()
        self._integrate(h)
        self._sync()


def _interleaved(candidates: dict, repeat: int, *, batch_seconds: float = 0.05) -> dict:
    """Median seconds per step of each candidate, timed round-robin.

    The machine this runs on is shared: other processes come and go within seconds. Timing
    the candidates in turns, ``repeat`` rounds, exposes them all to the same conditions, so
    their ratios stay meaningful even when the absolute figures move. Each turn runs
    consecutive steps for about ``batch_seconds``, as a running simulation does (single steps
    between other candidates' work would time cold caches).
    """
    for fn in candidates.values():  # warm-up: compile, start threads, touch memory
        fn()
    times = {name: [] for name in candidates}
    for _ in range(repeat):
        for name, fn in candidates.items():
            gc.collect()
            k = 0
            t0 = time.perf_counter()
            while True:
                fn()
                k += 1
                elapsed = time.perf_counter() - t0
                if elapsed >= batch_seconds:
                    break
            times[name].append(elapsed / k)
    return {name: statistics.median(t) for name, t in times.items()}


def run(quick: bool) -> list[Row]:
    sides = (32, 100) if quick else (32, 100, 316)
    repeat = 5 if quick else 15
    load0 = os.getloadavg()[0]
    rows: list[Row] = []
    taichi_cases = []
    for n in sides:
        worlds = {}
        for mode in ("auto", "serial", "parallel"):
            w, body = make_world(n)
            w.integrator_options = {"mode": mode}
            for _ in range(200):  # touch down (the contact path runs) and let auto mode settle
                w.step()
            worlds[mode] = w
        w = worlds["auto"]
        nv, case = body.n_vertices, f"{body.n_vertices} vertices, {body.n_springs} springs, 3 rects"
        m, s = w._model, w._state
        x, v = s.x.copy(), s.v.copy()
        f = np.zeros_like(x)
        args = (m.spring_i, m.spring_j, m.spring_rest_length, m.spring_stiffness, m.spring_damping)
        rects = pack_colliders(w.colliders, friction=w.friction, static_friction=w.static_friction)
        xn, vn = x.copy(), v.copy()
        candidates = {
            "auto": worlds["auto"].step,
            "serial": worlds["serial"].step,
            "parallel": worlds["parallel"].step,
            "bare": lambda: bare_spring_forces(x, v, *args, f),
            "tuned": lambda: bare_spring_forces_tuned(x, v, *args, f),
            "numpy": lambda: numpy_step(xn, vn, m.vertex_mass, *args, rects, w.dt),
        }
        taichi_cases.append((n, nv, (x.copy(), v.copy(), m.vertex_mass, *args, rects), w.dt))
        t = _interleaved(candidates, repeat)

        rows.append(Row("physics", f"deforma world.step() (auto threads), {case}", 1 / t["auto"], "steps/s"))
        rows.append(Row("physics", f"  same, pinned to one thread ({nv} v)", 1 / t["serial"], "steps/s",
                        ratio=f"{t['serial'] / t['auto']:.2f}x the auto step's time"))
        rows.append(Row("physics", f"  same, pinned to {numba.get_num_threads()} threads ({nv} v)",
                        1 / t["parallel"], "steps/s", ratio=f"{t['parallel'] / t['auto']:.2f}x the auto step's time"))
        rows.append(Row("physics", f"  bare Numba spring forces, serial, obvious ({nv} v)", 1 / t["bare"],
                        "steps/s", ratio=f"full step {t['auto'] / t['bare']:.2f}x its time", goal="full step <= 1.5x",
                        met=t["auto"] <= 1.5 * t["bare"]))
        rows.append(Row("physics", f"  bare Numba spring forces, serial, tuned like deforma's ({nv} v)",
                        1 / t["tuned"], "steps/s", ratio=f"full step {t['auto'] / t['tuned']:.2f}x its time",
                        goal="full step <= 1.5x", met=t["auto"] <= 1.5 * t["tuned"]))
        rows.append(Row("physics", f"  NumPy full step ({nv} v)", 1 / t["numpy"], "steps/s",
                        ratio=f"deforma {t['numpy'] / t['auto']:.1f}x faster", goal=">= 10x faster",
                        met=t["numpy"] >= 10 * t["auto"]))
    # Taichi last, each size timed in turns with a fresh deforma world: its runtime starts a
    # thread pool at ti.init, which must not be alive while the other peers are measured.
    try:
        import taichi as ti

        ti.init(arch=ti.cpu, log_level=ti.WARN, default_fp=ti.f64)
    except Exception as err:  # noqa: BLE001 - a missing or broken optional peer is reported, not fatal
        print(f"physics: taichi unavailable ({err}); its rows are skipped", file=sys.stderr)
        taichi_cases = []
    for n, nv, arrays, h in taichi_cases:
        w, _ = make_world(n)
        for _ in range(200):
            w.step()
        tstep = TaichiStep(*arrays)
        t = _interleaved({"auto": w.step, "taichi": lambda: tstep.step(h)}, repeat)
        rows.append(Row("physics", f"  Taichi CPU full step ({nv} v)", 1 / t["taichi"], "steps/s",
                        ratio=f"deforma {t['taichi'] / t['auto']:.1f}x faster (deforma {1 / t['auto']:.4g}/s here)",
                        goal=">= 3x faster", met=t["taichi"] >= 3 * t["auto"]))
    # other processes steal cores from threads waiting at barriers: say how busy it was
    print(f"physics: load average {load0:.2f} at start, {os.getloadavg()[0]:.2f} at end", file=sys.stderr)
    return rows


if __name__ == "__main__":
    from common import format_table

    print(f"threads: {os.cpu_count()}")
    print(format_table(run(quick="--quick" in sys.argv)))

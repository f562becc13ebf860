"""One triangle-FEM symplectic-Euler step, written for two peer frameworks and NumPy.

The peers let a benchmark time deforma's FEM step against Taichi and NVIDIA Warp on the
same mesh and state, in the same run. Each is written the way a competent user of that
framework would write it: no deliberate slowness, no heroic tricks.

- :func:`make_taichi_stepper`: Taichi's CPU backend (``ti.init(arch=ti.cpu)``), ``ti.field``
  storage, one ``@ti.kernel`` per substep whose top-level loops (zero forces, element forces
  with atomic scatter, vertex update) are each parallel.
- :func:`make_warp_stepper`: Warp on device ``"cpu"``, ``wp.array`` storage, one kernel
  launched over the elements with ``wp.atomic_add`` and one over the vertices.
- :func:`numpy_reference_step`: vectorised NumPy, the yardstick the peers are tested against.

Threading, which matters when reading the timings:

- Taichi runs its parallel loops on a thread pool of ``cpu_max_num_threads`` threads, by
  default every hardware thread of the machine, started at ``ti.init``.
- Warp's CPU backend runs a launch as a serial loop over the launch's indices on the calling
  thread: one thread, whatever the core count. (Checked for warp-lang 1.19: the generated CPU
  entry point is ``for (task_index = 0; task_index < dim->size; ++task_index)``, and the
  process's CPU time equals its wall time while the stepper runs.)

So on an N-core machine Taichi may use N cores and Warp one; a fair reading reports both.

The scatter costs the two very differently, which explains most of the gap between them.
On the CPU, Warp's ``atomic_add`` is a plain read-modify-write (safe only because the launch
is serial), while Taichi's ``+=`` in a parallel loop is a true float64 atomic, a
compare-and-swap loop on x86. Measured with taichi 1.7.4 on a 1e5-vertex grid, the
scatter alone took about 10 ms a substep on one thread against under 1 ms for the same
loop without atomics, and a second thread barely helped it.

The maths, float64 throughout. Per substep, for each triangle (i, j, k) with rest-shape
inverse ``B`` and rest area ``area``:

- ``Ds = [x_j - x_i | x_k - x_i]``, ``F = Ds @ B``;
- ``"neo-hookean"`` (stable Neo-Hookean, 2D): ``lp = lam + mu``, ``alpha = 1 + mu / lp``,
  ``P = mu F + lp (det F - alpha) cof F`` with ``cof F = [[F11, -F10], [-F01, F00]]``;
- ``"corotated"``: ``R`` the polar rotation of ``F`` in 2D closed form (``c = F00 + F11``,
  ``s = F10 - F01``, ``R = [[c, -s], [s, c]] / hypot(c, s)``, ``I`` if that is zero),
  ``P = 2 mu (F - R) + lam (tr(R^T F) - 2) R``;
- ``H = -area P B^T``; ``f_j += H[:, 0]``, ``f_k += H[:, 1]``, ``f_i -= H[:, 0] + H[:, 1]``.

Then for each vertex ``v += h (f inv_mass + g)``, ``x += h v``, and a vertex below
``floor_y`` is put on it with zero velocity. Forces start from zero every substep.

Taichi and Warp are imported lazily so that this module imports without them.
"""

import functools

import numpy as np

MODELS = ("corotated", "neo-hookean")

# ti.init resets the whole Taichi runtime (every field of every stepper already made), so it
# must run at most once per process; this flag says whether this module has seen it done.
_TAICHI_READY = False


def _check_inputs(x, v, tris, B, area, mu, lam, inv_mass, model):
    """Validate shapes and the model name; return float64/int32 contiguous copies.

    Parameters
    ----------
    x, v : array_like, shape (N, 2)
        Positions (m) and velocities (m/s).
    tris : array_like, shape (M, 3)
        Counter-clockwise vertex indices.
    B : array_like, shape (M, 2, 2)
        Inverse rest matrices.
    area, mu, lam : array_like, shape (M,)
        Rest areas (m^2) and Lamé parameters (Pa).
    inv_mass : array_like, shape (N,)
        Inverse vertex masses (1/kg); 0 pins a vertex against forces, not gravity.
    model : {"corotated", "neo-hookean"}
        Material model.

    Returns
    -------
    tuple of numpy.ndarray
        ``(x, v, tris, B, area, mu, lam, inv_mass)``, copied so that the caller's arrays are
        never written to.
    """
    if model not in MODELS:
        raise ValueError(f"model must be one of {MODELS}, not {model!r}")
    f64 = functools.partial(np.array, dtype=np.float64, order="C", copy=True)
    x, v, B, area, mu, lam, inv_mass = f64(x), f64(v), f64(B), f64(area), f64(mu), f64(lam), f64(inv_mass)
    tris = np.array(tris, dtype=np.int32, order="C", copy=True)
    n, m = len(x), len(tris)
    if x.shape != (n, 2) or v.shape != (n, 2) or inv_mass.shape != (n,):
        raise ValueError("x and v must be (N, 2) and inv_mass (N,)")
    if tris.shape != (m, 3) or B.shape != (m, 2, 2) or area.shape != (m,) or mu.shape != (m,) or lam.shape != (m,):
        raise ValueError("tris must be (M, 3), B (M, 2, 2) and area, mu, lam (M,)")
    if m and (tris.min() < 0 or tris.max() >= n):
        raise ValueError("tris holds a vertex index outside [0, N)")
    return x, v, tris, B, area, mu, lam, inv_mass


# --------------------------------------------------------------------------------------
# A test and timing body
# --------------------------------------------------------------------------------------


def grid_body(n=10, size=1.0, seed=0):
    """A deformed n x n grid body, as the keyword arguments of the steppers (less ``model``).

    The rest shape is the n x n grid on a size x size square, two counter-clockwise
    triangles per cell; ``B`` and ``area`` come from it. The initial positions move every
    vertex by up to 5% of the grid spacing (fixed seed) and then push one vertex across the
    opposite edge of its triangle, so that one triangle starts inverted, the case where the
    two models differ most. The bottom row rests on ``floor_y = 0``, so the displacement puts
    about half of it below the floor and the clamp is exercised at once. One vertex is
    pinned (``inv_mass = 0``).

    Parameters
    ----------
    n : int
        Vertices per side (n * n in all, 2 (n - 1)^2 triangles).
    size : float
        Side of the square (m).
    seed : int
        Seed of the random displacement, velocities and material scatter.

    Returns
    -------
    dict
        ``x, v, tris, B, area, mu, lam, inv_mass, h, gravity, floor_y``. The material is
        E = 10 kPa, nu = 0.3 (each element's Lamé parameters scattered by +-10%), 1000 kg/m^2;
        ``h`` is 1 ms for n = 10 and shrinks with the spacing, which keeps it about 30 times
        under the explicit stability limit at every n.
    """
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.linspace(0.0, size, n), np.linspace(0.0, size, n))
    X = np.c_[xs.ravel(), ys.ravel()]
    idx = np.arange(n * n).reshape(n, n)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tris = np.r_[np.c_[a, b, c], np.c_[a, c, d]].astype(np.int32)
    Dm = np.stack([X[tris[:, 1]] - X[tris[:, 0]], X[tris[:, 2]] - X[tris[:, 0]]], axis=-1)
    det = np.linalg.det(Dm)
    flip = det < 0  # make every triangle counter-clockwise, whatever the construction gave
    tris[flip] = tris[flip][:, [0, 2, 1]]
    Dm[flip] = Dm[flip][:, :, ::-1]
    area = 0.5 * np.abs(det)
    B = np.linalg.inv(Dm)

    spacing = size / (n - 1)
    x = X + rng.uniform(-0.05, 0.05, X.shape) * spacing
    # Invert one triangle: its first vertex goes to the far side of its opposite edge.
    t = tris[len(tris) // 4 + n // 2]
    mid = 0.5 * (x[t[1]] + x[t[2]])
    x[t[0]] = mid + 0.3 * (mid - x[t[0]])
    v = rng.normal(0.0, 0.05, X.shape)

    E, nu, rho = 1e4, 0.3, 1000.0  # Pa, -, kg/m^2
    m = len(tris)
    mu = E / (2 * (1 + nu)) * rng.uniform(0.9, 1.1, m)
    lam = E * nu / ((1 + nu) * (1 - 2 * nu)) * rng.uniform(0.9, 1.1, m)
    mass = np.bincount(tris.ravel(), np.repeat(rho * area / 3, 3), n * n)  # lumped
    inv_mass = 1.0 / mass
    inv_mass[-1] = 0.0
    return dict(x=x, v=v, tris=tris, B=B, area=area, mu=mu, lam=lam, inv_mass=inv_mass,
                h=1e-3 * spacing / (size / 9), gravity=(0.0, -9.81), floor_y=0.0)


# --------------------------------------------------------------------------------------
# NumPy reference
# --------------------------------------------------------------------------------------


def _numpy_forces(x, tris, B, area, mu, lam, model):
    """Elastic vertex forces (N, 2) of every triangle, vectorised over the elements."""
    i, j, k = tris[:, 0], tris[:, 1], tris[:, 2]
    Ds = np.stack([x[j] - x[i], x[k] - x[i]], axis=-1)  # columns are the two edge vectors
    F = Ds @ B
    F00, F01, F10, F11 = F[:, 0, 0], F[:, 0, 1], F[:, 1, 0], F[:, 1, 1]
    if model == "neo-hookean":
        lp = lam + mu
        alpha = 1.0 + mu / lp
        J = F00 * F11 - F01 * F10
        cof = np.stack([np.stack([F11, -F10], -1), np.stack([-F01, F00], -1)], -2)
        P = mu[:, None, None] * F + (lp * (J - alpha))[:, None, None] * cof
    else:
        c, s = F00 + F11, F10 - F01
        r = np.hypot(c, s)
        # r == 0 only for a degenerate F with no preferred rotation: the identity then.
        zero = r == 0.0
        r_safe = np.where(zero, 1.0, r)
        c, s = np.where(zero, 1.0, c / r_safe), np.where(zero, 0.0, s / r_safe)
        R = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)
        tr_S = np.einsum("eji,eji->e", R, F)  # trace(R^T F) without forming R^T F
        P = 2.0 * mu[:, None, None] * (F - R) + (lam * (tr_S - 2.0))[:, None, None] * R
    H = -area[:, None, None] * (P @ np.swapaxes(B, 1, 2))
    h0, h1 = H[:, :, 0], H[:, :, 1]
    n = len(x)
    f = np.empty_like(x)
    # bincount is NumPy's fast scatter-add (np.add.at is several times slower).
    for d in range(2):
        f[:, d] = (np.bincount(j, h0[:, d], n) + np.bincount(k, h1[:, d], n)
                   - np.bincount(i, h0[:, d] + h1[:, d], n))
    return f


def numpy_reference_step(x, v, tris, B, area, mu, lam, inv_mass, model, h, gravity, floor_y, n_substeps):
    """Advance the FEM body ``n_substeps`` substeps with vectorised NumPy.

    Parameters
    ----------
    x, v : array_like, shape (N, 2)
        Positions (m) and velocities (m/s); not modified.
    tris : array_like of int, shape (M, 3)
        Counter-clockwise triangles (i, j, k).
    B : array_like, shape (M, 2, 2)
        Inverse of each rest matrix ``Dm = [X_j - X_i | X_k - X_i]``.
    area : array_like, shape (M,)
        Rest areas (m^2).
    mu, lam : array_like, shape (M,)
        Lamé parameters (Pa).
    inv_mass : array_like, shape (N,)
        Inverse vertex masses (1/kg).
    model : {"corotated", "neo-hookean"}
        Material model.
    h : float
        Substep (s).
    gravity : tuple of float
        ``(gx, gy)`` in m/s^2.
    floor_y : float
        Height of the floor (m).
    n_substeps : int
        Number of substeps.

    Returns
    -------
    x, v : numpy.ndarray, shape (N, 2)
        New positions and velocities.
    """
    x, v, tris, B, area, mu, lam, inv_mass = _check_inputs(x, v, tris, B, area, mu, lam, inv_mass, model)
    g = np.asarray(gravity, dtype=np.float64)
    for _ in range(n_substeps):
        f = _numpy_forces(x, tris, B, area, mu, lam, model)
        v += h * (f * inv_mass[:, None] + g)
        x += h * v
        below = x[:, 1] < floor_y
        x[below, 1] = floor_y
        v[below] = 0.0
    return x, v


# --------------------------------------------------------------------------------------
# Taichi
# --------------------------------------------------------------------------------------


def _taichi():
    """Import Taichi and make sure its CPU runtime is up, initialising it at most once.

    Another module of the same process (benchmarks/bench_physics.py does) may already have
    called ``ti.init``; calling it again would free that module's fields, so an existing
    runtime is reused as long as it is a CPU one.
    """
    global _TAICHI_READY
    import taichi as ti
    from taichi.lang import impl

    if not _TAICHI_READY:
        if impl.get_runtime().prog is None:
            ti.init(arch=ti.cpu, default_fp=ti.f64, log_level=ti.WARN)
        _TAICHI_READY = True
    if impl.current_cfg().arch not in (ti.x64, ti.arm64):
        raise RuntimeError(f"Taichi was initialised on {impl.current_cfg().arch}, not on the CPU")
    return ti


def make_taichi_stepper(x, v, tris, B, area, mu, lam, inv_mass, model, h, gravity, floor_y):
    """Build the FEM step on Taichi's CPU backend.

    Taichi runs each top-level loop of a kernel in parallel on its thread pool, which by
    default has one thread per hardware thread of the machine (all CPU threads). The first
    ``step`` call compiles the kernel; time it after a warm-up call.

    Parameters
    ----------
    x, v, tris, B, area, mu, lam, inv_mass, model, h, gravity, floor_y
        As for :func:`numpy_reference_step`. The arrays are copied into Taichi fields.

    Returns
    -------
    step : callable
        ``step(n_substeps) -> None``; advances the state and returns once the work is done
        (``ti.sync()``), so that a timer around it measures real work.
    positions : callable
        ``positions() -> numpy.ndarray`` of shape (N, 2), a copy of the current positions.
    """
    x, v, tris, B, area, mu, lam, inv_mass = _check_inputs(x, v, tris, B, area, mu, lam, inv_mass, model)
    ti = _taichi()
    n, m = len(x), len(tris)
    X = ti.Vector.field(2, ti.f64, n)
    V = ti.Vector.field(2, ti.f64, n)
    Fv = ti.Vector.field(2, ti.f64, n)  # vertex forces
    IM = ti.field(ti.f64, n)
    T = ti.Vector.field(3, ti.i32, m)
    BM = ti.Matrix.field(2, 2, ti.f64, m)
    A, MU, LAM = ti.field(ti.f64, m), ti.field(ti.f64, m), ti.field(ti.f64, m)
    for fld, arr in ((X, x), (V, v), (IM, inv_mass), (T, tris), (BM, B), (A, area), (MU, mu), (LAM, lam)):
        fld.from_numpy(arr)
    neo = model == "neo-hookean"  # a Python bool: ti.static compiles only the chosen model
    gx, gy = (float(c) for c in gravity)

    # The scalars are kernel arguments rather than captured constants: a captured Python
    # float takes the runtime's default_fp, which is f32 if someone else initialised Taichi.
    @ti.kernel
    def substep(h: ti.f64, gx: ti.f64, gy: ti.f64, floor_y: ti.f64):
        # Top-level loops run one after another, each in parallel: a barrier between them.
        for p in Fv:
            Fv[p] = ti.Vector([0.0, 0.0], ti.f64)
        for e in T:
            a, b, c = T[e][0], T[e][1], T[e][2]
            Bm = BM[e]
            F = ti.Matrix.cols([X[b] - X[a], X[c] - X[a]]) @ Bm
            P = ti.Matrix.zero(ti.f64, 2, 2)
            if ti.static(neo):
                lp = LAM[e] + MU[e]
                alpha = 1.0 + MU[e] / lp
                J = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
                cof = ti.Matrix([[F[1, 1], -F[1, 0]], [-F[0, 1], F[0, 0]]], ti.f64)
                P = MU[e] * F + lp * (J - alpha) * cof
            else:
                cs, sn = F[0, 0] + F[1, 1], F[1, 0] - F[0, 1]
                r = ti.sqrt(cs * cs + sn * sn)
                R = ti.Matrix.identity(ti.f64, 2)
                if r > 0.0:
                    R = ti.Matrix([[cs, -sn], [sn, cs]], ti.f64) / r
                S = R.transpose() @ F
                P = 2.0 * MU[e] * (F - R) + LAM[e] * (S.trace() - 2.0) * R
            H = -A[e] * (P @ Bm.transpose())
            h0 = ti.Vector([H[0, 0], H[1, 0]], ti.f64)
            h1 = ti.Vector([H[0, 1], H[1, 1]], ti.f64)
            # += on a field inside a parallel loop is an atomic add in Taichi.
            Fv[b] += h0
            Fv[c] += h1
            Fv[a] -= h0 + h1
        for p in X:
            vel = V[p] + h * (Fv[p] * IM[p] + ti.Vector([gx, gy], ti.f64))
            pos = X[p] + h * vel
            if pos[1] < floor_y:
                pos[1] = floor_y
                vel = ti.Vector([0.0, 0.0], ti.f64)
            X[p] = pos
            V[p] = vel

    h, floor_y = float(h), float(floor_y)

    def step(n_substeps: int) -> None:
        for _ in range(n_substeps):
            substep(h, gx, gy, floor_y)
        ti.sync()  # launches are asynchronous: wait so that the caller's timer sees the work

    def positions() -> np.ndarray:
        return X.to_numpy().astype(np.float64, copy=False)

    return step, positions


# --------------------------------------------------------------------------------------
# Warp
# --------------------------------------------------------------------------------------


@functools.cache
def _warp_kernels():
    """Import and initialise Warp and define its two kernels, once per process.

    The kernels are defined here rather than at module level so that this module imports
    without Warp; the cache makes every stepper share them (Warp compiles a module once).
    The model is a runtime argument: the branch is the same for every element, so it
    costs next to nothing, and it works on every Warp >= 1.0 (kernel closures are newer).
    """
    import warp as wp

    wp.init()
    f64 = wp.float64  # for the constants in the kernel bodies

    @wp.kernel
    def element_forces(x: wp.array(dtype=wp.vec2d), tris: wp.array(dtype=wp.vec3i),
                       B: wp.array(dtype=wp.mat22d), area: wp.array(dtype=wp.float64),
                       mu: wp.array(dtype=wp.float64), lam: wp.array(dtype=wp.float64), neo_hookean: int,
                       f: wp.array(dtype=wp.vec2d)):
        e = wp.tid()
        t = tris[e]
        i, j, k = t[0], t[1], t[2]
        xi = x[i]
        d1 = x[j] - xi
        d2 = x[k] - xi
        Bm = B[e]
        F = wp.mat22d(d1[0], d2[0], d1[1], d2[1]) @ Bm  # row-major constructor: d1, d2 as columns
        one = f64(1.0)
        two = f64(2.0)
        P = wp.mat22d()
        if neo_hookean != 0:
            lp = lam[e] + mu[e]
            alpha = one + mu[e] / lp
            J = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
            cof = wp.mat22d(F[1, 1], -F[1, 0], -F[0, 1], F[0, 0])
            P = mu[e] * F + lp * (J - alpha) * cof
        else:
            cs = F[0, 0] + F[1, 1]
            sn = F[1, 0] - F[0, 1]
            r = wp.sqrt(cs * cs + sn * sn)
            R = wp.identity(n=2, dtype=wp.float64)
            if r > f64(0.0):
                R = wp.mat22d(cs, -sn, sn, cs) / r
            S = wp.transpose(R) @ F
            P = two * mu[e] * (F - R) + lam[e] * (wp.trace(S) - two) * R
        H = -area[e] * (P @ wp.transpose(Bm))
        h0 = wp.vec2d(H[0, 0], H[1, 0])
        h1 = wp.vec2d(H[0, 1], H[1, 1])
        wp.atomic_add(f, j, h0)
        wp.atomic_add(f, k, h1)
        wp.atomic_sub(f, i, h0 + h1)

    @wp.kernel
    def integrate(x: wp.array(dtype=wp.vec2d), v: wp.array(dtype=wp.vec2d), f: wp.array(dtype=wp.vec2d),
                  inv_mass: wp.array(dtype=wp.float64), h: wp.float64, g: wp.vec2d, floor_y: wp.float64):
        p = wp.tid()
        vel = v[p] + h * (f[p] * inv_mass[p] + g)
        pos = x[p] + h * vel
        if pos[1] < floor_y:
            pos = wp.vec2d(pos[0], floor_y)
            vel = wp.vec2d()
        x[p] = pos
        v[p] = vel

    return wp, element_forces, integrate


def make_warp_stepper(x, v, tris, B, area, mu, lam, inv_mass, model, h, gravity, floor_y):
    """Build the FEM step on NVIDIA Warp's CPU device.

    Warp's CPU backend runs each launch as a serial loop on the calling thread: one core,
    however many the machine has. The first ``step`` call compiles the kernels (or loads
    them from Warp's kernel cache); time it after a warm-up call.

    Parameters
    ----------
    x, v, tris, B, area, mu, lam, inv_mass, model, h, gravity, floor_y
        As for :func:`numpy_reference_step`. The arrays are copied into ``wp.array`` s.

    Returns
    -------
    step : callable
        ``step(n_substeps) -> None``; advances the state and returns once the work is done
        (``wp.synchronize()``), so that a timer around it measures real work.
    positions : callable
        ``positions() -> numpy.ndarray`` of shape (N, 2), a copy of the current positions.
    """
    x, v, tris, B, area, mu, lam, inv_mass = _check_inputs(x, v, tris, B, area, mu, lam, inv_mass, model)
    wp, element_forces, integrate = _warp_kernels()
    dev = "cpu"
    n, m = len(x), len(tris)
    X = wp.array(x, dtype=wp.vec2d, device=dev)
    V = wp.array(v, dtype=wp.vec2d, device=dev)
    Fv = wp.zeros(n, dtype=wp.vec2d, device=dev)
    IM = wp.array(inv_mass, dtype=wp.float64, device=dev)
    T = wp.array(tris, dtype=wp.vec3i, device=dev)
    BM = wp.array(B, dtype=wp.mat22d, device=dev)
    A = wp.array(area, dtype=wp.float64, device=dev)
    MU = wp.array(mu, dtype=wp.float64, device=dev)
    LAM = wp.array(lam, dtype=wp.float64, device=dev)
    neo = int(model == "neo-hookean")
    g = wp.vec2d(*(float(c) for c in gravity))
    h, floor_y = float(h), float(floor_y)

    def step(n_substeps: int) -> None:
        for _ in range(n_substeps):
            Fv.zero_()
            wp.launch(element_forces, dim=m, inputs=[X, T, BM, A, MU, LAM, neo, Fv], device=dev)
            wp.launch(integrate, dim=n, inputs=[X, V, Fv, IM, h, g, floor_y], device=dev)
        wp.synchronize()  # CPU launches already block, but this keeps the contract explicit

    def positions() -> np.ndarray:
        return X.numpy().astype(np.float64, copy=True)

    return step, positions


# --------------------------------------------------------------------------------------
# Timing from the command line
# --------------------------------------------------------------------------------------


def _time_peer(name, make, body, model, n_substeps, repeat):
    """Print the median wall time of ``step(n_substeps)`` and its CPU-to-wall ratio.

    The CPU-to-wall ratio (process CPU time over wall time) shows how many cores the peer
    kept busy: about 1 for a serial backend, up to the core count for a parallel one.
    """
    import statistics
    import time

    step, _ = make(model=model, **body)
    step(n_substeps)  # warm-up: compilation (or a kernel-cache load) is not timed
    walls, cpus = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        step(n_substeps)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    wall, cpu = statistics.median(walls), statistics.median(cpus)
    print(f"{name:8s} {model:12s} {n_substeps} substeps: median {wall * 1e3:8.2f} ms "
          f"({wall / n_substeps * 1e3:.3f} ms/substep, CPU/wall {cpu / wall:.2f})", flush=True)


def main(argv=None):
    """Time each available peer on a :func:`grid_body` of n x n vertices."""
    import argparse
    import os

    p = argparse.ArgumentParser(description="Time the FEM peers on one grid body.")
    p.add_argument("--n", type=int, default=316, help="vertices per side (default 316: ~1e5 vertices)")
    p.add_argument("--substeps", type=int, default=10)
    p.add_argument("--repeat", type=int, default=7)
    p.add_argument("--models", default=",".join(MODELS))
    p.add_argument("--peers", default="numpy,warp,taichi")
    a = p.parse_args(argv)
    body = grid_body(a.n)
    print(f"{a.n * a.n} vertices, {len(body['tris'])} triangles, {os.cpu_count()} CPUs", flush=True)

    def numpy_maker(model, **kw):
        state = {"x": kw["x"], "v": kw["v"]}

        def step(k):
            state["x"], state["v"] = numpy_reference_step(**{**kw, **state}, model=model, n_substeps=k)

        return step, lambda: state["x"]

    makers = {"numpy": numpy_maker, "warp": make_warp_stepper, "taichi": make_taichi_stepper}
    # Taichi last: ti.init starts its thread pool, which should not be around for the others.
    for peer in (pp for pp in makers if pp in a.peers.split(",")):
        for model in a.models.split(","):
            _time_peer(peer, makers[peer], body, model, a.substeps, a.repeat)


if __name__ == "__main__":
    main()

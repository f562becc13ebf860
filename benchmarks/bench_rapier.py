"""Rapier benchmark: deforma's avbd against Rapier 2D's FEM soft bodies (npm, under node).

The case is the hanging column of docs/physics.md's validation: 0.2 m x 2 m, ``nx`` x ``10 nx``
cells of two triangles, the top row pinned, E = 1e5, nu = 0.3, 100 kg/m^2, corotated, g = 9.81,
``dt = 1/60 s`` and one step a frame. Both get the same drag of 20 1/s (deforma's ``air_drag``,
Rapier's linear damping: both ``v / (1 + h c)`` a step) so that the column settles within the
5 s simulated before any step is timed. Neither has colliders: the column touches nothing.

The peer is ``@dimforge/rapier2d-compat`` 0.21.0 (Rapier 0.36's soft bodies) driven by
``rapier_peer.mjs`` under node: ``SoftBodyDesc`` over the same vertices and triangles,
``SoftBodySolver.Fem``, ``SoftBodyCellModel.Corotational``, the same lumped masses (a third
of each triangle's ``rho * area`` to each corner). Rapier's 2D cells are in plane strain
(measured: its column narrows by ``nu / (1 - nu)`` of its stretch and settles where deforma's
plane-strain column does), so deforma runs ``Material(..., plane="strain")`` here.

Accuracy is the tip displacement (the mean drop of the bottom row) once settled, against the
static equilibrium of the same mesh (``world.solve_static``); both share the mesh's own
discretisation error (0.8% under ``rho g L^2 (1 - nu^2) / (2 E)`` at 4 x 40 cells).

Rapier runs at its defaults (4 substeps a step, the FEM's conjugate gradient capped at 20
iterations) and with more substeps or iterations; each configuration has its row. The goal
(the issue): Rapier at least 3x slower than deforma at equal or better accuracy. It is judged
on the fastest configuration whose error is at most deforma's (or 0.1%, whichever is larger),
or, if none is that accurate, on the most accurate one.

Timing: in each round every configuration runs in a fresh node process (settling, then its
steps each timed inside node, the process's start-up and WebAssembly set-up left out), then
deforma's world (settled once, before the first round) is timed for as many steps, so that
the shared machine's load falls on both; medians over all rounds. Rapier's WebAssembly runs
on one thread; deforma's CPU-to-wall ratio is given.

Needs node and the package, which nothing here downloads: the package is looked for in the
folder named by ``$DEFORMA_RAPIER_MODULES`` (a ``node_modules`` folder or one holding it), then
in ``benchmarks/node_modules``. Install it with
``npm install --no-save --no-package-lock --prefix benchmarks @dimforge/rapier2d-compat@0.21.0``.
Without them the module makes no rows and says so in one line.
"""

from __future__ import annotations

import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from common import Row  # noqa: E402

import deforma  # noqa: E402

PACKAGE = "@dimforge/rapier2d-compat"
ENV = "DEFORMA_RAPIER_MODULES"
SCRIPT = HERE / "rapier_peer.mjs"
INSTALL = f"npm install --no-save --no-package-lock --prefix benchmarks {PACKAGE}@0.21.0"

E, NU, RHO, G, L, W = 1e5, 0.3, 100.0, 9.81, 2.0, 0.2
DT, DRAG = 1 / 60, 20.0
SETTLE_STEPS = 300  # 5 s
MATCH = 1e-3  # errors up to this (relative) count as equally accurate

# (label, settings for rapier_peer.mjs); Rapier's defaults first.
CONFIGS = (
    ("defaults: 4 substeps, CG <= 20 iterations", {}),
    ("4 substeps, CG <= 200 iterations", {"fem_max_linear_iterations": 200}),
    ("8 substeps, CG <= 20 iterations", {"solver_iterations": 8}),
    ("8 substeps, CG <= 200 iterations", {"solver_iterations": 8, "fem_max_linear_iterations": 200}),
)


def find_modules() -> Path | None:
    """The node_modules folder holding the package: ``$DEFORMA_RAPIER_MODULES``, then
    ``benchmarks/node_modules`` (each may also be a folder holding a node_modules)."""
    for c in (os.environ.get(ENV), HERE / "node_modules"):
        if not c:
            continue
        for d in (Path(c), Path(c) / "node_modules"):
            if (d / PACKAGE / "package.json").is_file():
                return d.resolve()
    return None


def column(nx: int):
    """The column as a grid of nx x 10 nx cells, top edge at y = 0 (tests/physics/test_fem_validation.py's)."""
    ny = 10 * nx
    xs, ys = np.meshgrid(np.linspace(0, W, nx + 1), np.linspace(-L, 0, ny + 1))
    idx = np.arange((nx + 1) * (ny + 1)).reshape(ny + 1, nx + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    return deforma.mesh.Mesh(np.c_[xs.ravel(), ys.ravel()], np.r_[np.c_[a, b, c], np.c_[a, c, d]])


def deforma_world(mesh, pinned):
    """deforma's avbd at 1/60 s, one step a frame, on ``mesh`` in plane strain, pinned at ``pinned``."""
    w = deforma.World(sleep=False, integrator="avbd", dt=DT, substeps=1, air_drag=DRAG)
    mat = deforma.Material("corotated", youngs_modulus=E, poisson_ratio=NU, density=RHO, plane="strain")
    b = w.add_body(mesh, material=mat, position=None, collide=False, self_collision=False)
    b.pin(pinned)
    return w, b


def static_tip(mesh, pinned, tip) -> float:
    """The tip's drop at the static equilibrium of the same mesh and material."""
    w, b = deforma_world(mesh, pinned)
    w.solve_static(tolerance=1e-7)
    return float(mesh.vertices[tip, 1].mean() - b.positions[tip, 1].mean())


def rapier_run(node: str, modules: Path, case: dict, settings: dict, timed_steps: int) -> dict:
    """One node process: settle, then ``timed_steps`` steps each timed; its JSON answer."""
    payload = dict(case, **settings, modules=str(modules), settle_steps=SETTLE_STEPS,
                   timed_steps=timed_steps, times=True)
    r = subprocess.run([node, str(SCRIPT), "-"], input=json.dumps(payload), capture_output=True, text=True,
                       timeout=600, check=False)
    if r.returncode != 0:
        raise RuntimeError(r.stderr.strip().splitlines()[-1] if r.stderr.strip() else f"exit {r.returncode}")
    return json.loads(r.stdout)


def relative_error(tip, reference: float) -> float:
    return float("inf") if tip is None or not np.isfinite(tip) else abs(tip / reference - 1.0)


def speed(ratio: float) -> str:
    """Rapier's step time over deforma's, in words."""
    return f"deforma {ratio:.2f}x faster" if ratio >= 1 else f"deforma {1 / ratio:.2f}x slower"


def run(quick: bool) -> list[Row]:
    node = shutil.which("node")
    modules = find_modules()
    if node is None or modules is None:
        missing = "node" if node is None else f"{PACKAGE} (in ${ENV} or benchmarks/node_modules)"
        print(f"rapier: skipped, {missing} not found; it needs node and the package: {INSTALL}", file=sys.stderr)
        return []
    sizes = (4,) if quick else (4, 8)
    rounds, timed = (1, 10) if quick else (3, 30)
    rows: list[Row] = []
    for nx in sizes:
        mesh = column(nx)
        pinned = np.flatnonzero(np.isclose(mesh.vertices[:, 1], 0.0))
        tip = np.flatnonzero(np.isclose(mesh.vertices[:, 1], -L))
        case = {"vertices": mesh.vertices.tolist(), "triangles": mesh.triangles.tolist(), "pinned": pinned.tolist(),
                "tip": tip.tolist(), "E": E, "nu": NU, "rho": RHO, "gravity": G, "dt": DT, "model": "corotated",
                "linear_damping": DRAG}
        reference = static_tip(mesh, pinned, tip)
        world, body = deforma_world(mesh, pinned)
        for _ in range(SETTLE_STEPS):  # also compiles
            world.step()
        d_times, d_cpu, r_times, answers = [], 0.0, {label: [] for label, _ in CONFIGS}, {}
        try:
            for _ in range(rounds):
                for label, settings in CONFIGS:
                    answers[label] = rapier_run(node, modules, case, settings, timed)
                    r_times[label] += answers[label]["step_s"]
                c0 = time.process_time()
                for _ in range(timed):
                    t0 = time.perf_counter()
                    world.step()
                    d_times.append(time.perf_counter() - t0)
                d_cpu += time.process_time() - c0
        except (RuntimeError, subprocess.TimeoutExpired, json.JSONDecodeError) as err:
            print(f"rapier: skipped, {SCRIPT.name} failed: {err}", file=sys.stderr)
            return rows
        t_d = statistics.median(d_times)
        tip_d = float(mesh.vertices[tip, 1].mean() - body.positions[tip, 1].mean())
        err_d = relative_error(tip_d, reference)
        version = next(iter(answers.values()))["version"]
        head = (f"column {nx} x {10 * nx} cells ({len(mesh.vertices)} vertices), corotated, plane strain, "
                f"1/60 s x 1")
        rows.append(Row("rapier", f"deforma avbd, {head}: ms per step", t_d * 1e3, "ms",
                        f"tip {tip_d * 1e3:.3f} mm, {err_d:.2%} off the static {reference * 1e3:.3f} mm; "
                        f"CPU/wall {d_cpu / sum(d_times):.2f}"))
        t_r = {label: statistics.median(r_times[label]) for label, _ in CONFIGS}
        err_r = {label: relative_error(answers[label]["tip_displacement"], reference) for label, _ in CONFIGS}
        matching = [lb for lb, _ in CONFIGS if err_r[lb] <= max(err_d, MATCH)]
        judged = min(matching, key=t_r.get) if matching else min(err_r, key=err_r.get)
        for label, _ in CONFIGS:
            tip_r = answers[label]["tip_displacement"]
            tip_text = "no tip (NaN)" if tip_r is None else f"tip {tip_r * 1e3:.3f} mm, {err_r[label]:.2%} off"
            goal = label == judged
            rows.append(Row("rapier", f"  Rapier {version} Fem, {label}", t_r[label] * 1e3, "ms",
                            f"{speed(t_r[label] / t_d)}; {tip_text}",
                            "Rapier >= 3x slower at equal or better accuracy" if goal else "",
                            (t_r[label] >= 3 * t_d and err_d <= max(err_r[label], MATCH)) if goal else None))
    return rows


if __name__ == "__main__":
    from common import format_table

    print(format_table(run(quick="--quick" in sys.argv)))

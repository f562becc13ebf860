"""Material behaviours benchmark: what tearing, plasticity, the stretch limit and pressure cost.

Measured on a 2 m x 1 m sheet (``mesh.box`` detail 98 with side points: 1e4 vertices; 2500
with ``--quick``) of corotated elements at 1/600 s, under each integrator:

- a step with no behaviour against a step whose material has every behaviour switched on
  with thresholds it never reaches (what the checks cost: each reads every element once or
  twice, about what the elastic forces cost; a behaviour left off costs one test per body);
- tearing: the sheet clamped at its left side (pinned) and at its right side (pinned
  vertices moved by the script), pulled apart until it tears across (implicit Euler; XPBD
  at one substep is too soft for such a clamp: the strain piles up next to the moving one,
  which tears a wedge off, rather than across the sheet); the median step that tears (the
  cut, the split vertices, the rebuilt model and matrix, and the factor's low-rank
  correction) against the median step that does not (the goal: at most 2x); and the same
  under symplectic Euler at the substeps its stable step needs (no factor: the tear's own
  bookkeeping against a step of many substeps).
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Row, interleaved_medians  # noqa: E402

import deforma  # noqa: E402

BASE = dict(youngs_modulus=2e4, poisson_ratio=0.3, density=2.0)


def sheet_world(detail: int, integrator: str, **behaviours):
    """A world with the sheet clamped at both sides; returns ``(world, body, right clamp)``.

    Symplectic Euler takes the substeps its stable step needs (``World.stable_dt``: 43 at
    1e4 vertices, 22 at 2500); the other two take one.
    """
    mat = deforma.Material("corotated", **BASE, **behaviours)
    w = deforma.World(sleep=False, gravity=(0.0, 0.0), integrator=integrator, material=mat)
    body = w.add_body(deforma.mesh.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=detail, edges=True), position=None)
    x = body.positions
    right = np.flatnonzero(x[:, 0] > 2.0 - 1e-9)
    body.pin(np.concatenate([np.flatnonzero(x[:, 0] < 1e-9), right]))
    if integrator == "symplectic-euler":
        w.substeps = int(np.ceil(w.dt / (0.9 * w.stable_dt())))
    return w, body, right


def tearing_steps(detail: int, integrator: str, steps: int):
    """Step times (s) and which steps tore, and the pieces at the end."""
    w, body, right = sheet_world(detail, integrator, tear_strain=0.2)
    times, tore = [], []
    for k in range(steps):
        x = body.positions
        x[right, 0] += 0.5 / 600 * (1 + k / 100)  # the clamp speeds up: 0.5 m/s, then faster
        body.positions = x
        n = body.n_vertices
        t0 = time.perf_counter()
        w.step()
        times.append(time.perf_counter() - t0)
        tore.append(body.n_vertices != n)
    return np.array(times), np.array(tore), int(body.pieces.max()) + 1


def run(quick: bool) -> list[Row]:
    detail = 48 if quick else 98
    rows: list[Row] = []
    for integrator in ("implicit-euler", "symplectic-euler", "xpbd"):
        off, _, _ = sheet_world(detail, integrator)
        on, _, _ = sheet_world(detail, integrator, tear_strain=50.0, yield_strain=50.0, max_stretch=50.0)
        n = off.bodies[0].n_vertices
        t = interleaved_medians({"off": off.step, "on": on.step}, 7 if quick else 21)
        rows.append(Row("behaviours", f"{integrator} step, {n}-vertex corotated sheet, no behaviour",
                        t["off"] * 1e3, "ms"))
        rows.append(Row("behaviours", "  same, tearing + plasticity + stretch limit on, never reached",
                        t["on"] * 1e3, "ms", ratio=f"{t['on'] / t['off']:.2f}x (the checks)"))
        if integrator == "xpbd":
            continue  # XPBD at one substep is too soft for this clamp: the strain piles up next to it
        times, tore, pieces = tearing_steps(detail, integrator, 300 if quick else 400)
        first, last = np.flatnonzero(tore)[[0, -1]]
        plain = statistics.median(times[5:][~tore[5:]])
        tear = statistics.median(times[tore])
        during = float(times[first:last + 1].mean())
        rows.append(Row("behaviours", f"  {integrator}: a step that tears ({tore.sum()} of {len(tore)} steps tore; "
                        f"{pieces} pieces)", tear * 1e3, "ms", ratio=f"{tear / plain:.2f}x a step that does not",
                        goal="<= 2x", met=tear <= 2 * plain))
        rows.append(Row("behaviours", f"  {integrator}: mean step while it tears (steps {first}-{last})", during * 1e3,
                        "ms", ratio=f"{during / plain:.2f}x a step that does not", goal="<= 2x",
                        met=during <= 2 * plain))
    return rows


if __name__ == "__main__":
    from common import format_table

    print(format_table(run(quick="--quick" in sys.argv)))

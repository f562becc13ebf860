"""Finite-element benchmark: the symplectic Euler step of a 1e5-vertex FEM body.

Measured in one run on the same mesh, state and substep (``fem_peers.grid_body``: a
deformed 316 x 316 grid, one inverted triangle, one pinned vertex, resting on a floor):

- deforma ``world.step()`` with a ``"corotated"`` or ``"neo-hookean"`` material (10 substeps:
  element forces, integration, the floor collider, the blow-up check), against
- deforma's spring step on the same mesh (the goal: FEM at most 2x its cost),
- the same element forces and integration written for Taichi (CPU, all threads) and NVIDIA
  Warp (CPU, one thread), see ``fem_peers.py`` (the goal: deforma at least 3x faster than each).

The body neither collides with other bodies nor with itself (the peers have no contacts), so
the step is elements + integration + the floor, as in the peers.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Row, interleaved_medians  # noqa: E402
from fem_peers import MODELS, grid_body, make_taichi_stepper, make_warp_stepper  # noqa: E402

import deforma  # noqa: E402

SUBSTEPS = 10


def deforma_world(body: dict, model: str | None):
    """A world holding ``body`` as finite elements of ``model`` (or springs if None), stepping
    ``SUBSTEPS`` substeps of the body's ``h`` per ``step()``."""
    n = len(body["x"])
    side = int(round(np.sqrt(n)))
    xs, ys = np.meshgrid(np.linspace(0.0, 1.0, side), np.linspace(0.0, 1.0, side))
    mesh = deforma.mesh.Mesh(np.c_[xs.ravel(), ys.ravel()], body["tris"])
    mat = None if model is None else deforma.Material(model, youngs_modulus=1e4, poisson_ratio=0.3, density=1000.0)
    # springs: the same total mass (1000 kg/m^2 on 1 m^2) and a stiffness of the same order as E
    w = deforma.World(sleep=False, dt=SUBSTEPS * body["h"], substeps=SUBSTEPS, material=mat, stiffness=1e4, damping=0.0,
                      mass=1000.0, integrator="symplectic-euler")
    w.add_collider(deforma.Rect((0.5, -0.5), (10.0, 1.0), 0.0))  # top face at y = 0: the peers' floor
    b = w.add_body(mesh, position=None, collide=False, self_collision=False)
    b.positions = body["x"]
    b.velocities = body["v"]
    b.pin([n - 1])
    return w


def run(quick: bool) -> list[Row]:
    side = 100 if quick else 316
    repeat = 5 if quick else 11
    body = grid_body(side)
    nv, nt = len(body["x"]), len(body["tris"])
    case = f"{nv} vertices, {nt} triangles, {SUBSTEPS} substeps"
    rows: list[Row] = []
    springs = deforma_world(body, None)
    peers = {}
    for peer, make in (("warp", make_warp_stepper), ("taichi", make_taichi_stepper)):
        try:
            for model in MODELS:
                step, _ = make(model=model, **body)
                peers[(peer, model)] = (lambda s=step: s(SUBSTEPS))
        except Exception as err:  # noqa: BLE001 - a missing optional peer is reported, not fatal
            print(f"fem: {peer} unavailable ({err}); its rows are skipped", file=sys.stderr)
    for model in MODELS:
        fem = deforma_world(body, model)
        candidates = {"fem": fem.step, "springs": springs.step}
        candidates.update({peer: f for (peer, m), f in peers.items() if m == model})
        t = interleaved_medians(candidates, repeat)
        rows.append(Row("fem", f"deforma {model} world.step(), {case}", t["fem"] * 1e3, "ms"))
        rows.append(Row("fem", "  deforma springs world.step(), same mesh", t["springs"] * 1e3, "ms",
                        ratio=f"FEM {t['fem'] / t['springs']:.2f}x its time", goal="FEM <= 2x",
                        met=t["fem"] <= 2 * t["springs"]))
        for peer in ("warp", "taichi"):
            if peer in t:
                rows.append(Row("fem", f"  {peer} (CPU) same elements and integration", t[peer] * 1e3, "ms",
                                ratio=f"deforma {t[peer] / t['fem']:.1f}x faster", goal=">= 3x faster",
                                met=t[peer] >= 3 * t["fem"]))
    return rows


if __name__ == "__main__":
    from common import format_table

    print(format_table(run(quick="--quick" in sys.argv)))

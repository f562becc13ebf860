"""A heap of 48 soft bodies (~200 vertices each) poured into a box at 1/60 s (issue 34's heap).

Run ``python tools/heap.py [integrator ...]`` (default: symplectic-euler, implicit-euler,
implicit-bdf2). One line per integrator: the substeps the world takes, steps per second (wall),
and after 10 s the inverted triangles, the fastest vertex and whether any outlines cross, or
the error in one line.
"""

import sys
import time
import warnings

import numpy as np

import deforma
from deforma.mesh import quality

sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "tests" / "physics"))
from contact_checks import crossings  # noqa: E402 - the tests' exact outline-crossing check


def heap(integrator: str) -> deforma.World:
    mat = deforma.Material("corotated", youngs_modulus=2000.0, poisson_ratio=0.3, density=5.5, damping=0.01)
    w = deforma.World(dt=1 / 60, integrator=integrator, material=mat, air_drag=0.5)
    for center, size in (((0.0, -0.25), (4.4, 0.5)), ((-2.2, 2.5), (0.4, 6.0)), ((2.2, 2.5), (0.4, 6.0))):
        w.add_collider(deforma.Rect(center, size, 0.0))
    box = deforma.mesh.box(((-0.2, -0.2), (0.2, -0.2), (0.2, 0.2), (-0.2, 0.2)), detail=12)
    for k in range(48):  # 6 columns x 8 rows, every other row shifted: they tumble as they land
        col, row = k % 6, k // 6
        w.add_body(box, position=(-1.6 + 0.64 * col + 0.16 * (row % 2), 0.4 + 0.6 * row))
    return w


def main(names) -> None:
    warnings.simplefilter("ignore")
    for name in names:
        w = heap(name)
        n = sum(b.n_vertices for b in w.bodies)
        start = time.perf_counter()
        try:
            for _ in range(600):
                w.step()
            wall = time.perf_counter() - start
            inverted = sum(int((quality.triangle_signed_areas(b.positions, b.triangles) < 0).sum()) for b in w.bodies)
            speed = max(float(np.linalg.norm(b.velocities, axis=1).max()) for b in w.bodies)
            crossing = crossings(w, exact=True)[1]
            print(f"{name}: {n} vertices, substeps {w.substeps}, {600 / wall:.1f} steps/s ({wall:.0f} s for 10 s), "
                  f"{inverted} inverted triangles, fastest vertex {100 * speed:.2f} cm/s, {crossing} crossing outline pairs",
                  flush=True)
        except Exception as e:  # noqa: BLE001 - one line per integrator
            print(f"{name}: stopped at step {w.step_count} after {time.perf_counter() - start:.0f} s: {e}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:] or ["symplectic-euler", "implicit-euler", "implicit-bdf2"])

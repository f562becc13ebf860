"""Every built-in picture, at every resolution a user picks (2-8), as a body of the default
``deforma.World()`` dropped 20 cm onto a floor: does it run 10 s?

Run ``python tools/default_world.py [seconds]``; one line per case (vertices, substeps the
world chose, wall time, the fastest vertex at the end, or the error in one line).
"""

import sys
import time
import warnings

import numpy as np

import deforma


def main(seconds: float = 10.0) -> None:
    for name in ("bunny", "donut", "armadillo"):
        for resolution in range(2, 9):
            mesh = deforma.mesh.from_image(name, resolution=resolution, detect_edges=True, edge_step=2, scale=0.01)
            w = deforma.World()
            w.add_collider(deforma.Rect((0.0, -0.25), (8.0, 0.5), 0.0))
            with warnings.catch_warnings(record=True) as said:
                warnings.simplefilter("always")
                body = w.add_body(mesh, position=(0.0, np.ptp(mesh.vertices[:, 1]) / 2 + 0.2))
            start = time.perf_counter()
            try:
                for _ in range(round(seconds / w.dt)):
                    w.step()
                outcome = f"fastest vertex {np.linalg.norm(body.velocities, axis=1).max():.3f} m/s"
            except Exception as e:  # noqa: BLE001 - reported, one line per case
                outcome = f"stopped at step {w.step_count}: {e}"
            print(f"{name:9s} resolution {resolution}: {len(mesh.vertices):6d} vertices, substeps {w.substeps:3d}, "
                  f"{time.perf_counter() - start:7.1f} s wall, {len(said)} warnings, {outcome}", flush=True)


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 10.0)

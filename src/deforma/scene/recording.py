"""A played world's states, frame by frame, and the NPZ they are saved as (``deforma run --states``).

The arrays are described in ``docs/cli.md`` (``--states``): every body's positions per frame,
its mesh (triangles, springs, rest positions, uv) at the end, the colliders' shapes, poses per
frame and motion, ``fps``, ``dt`` and the scene that was run as TOML text. ``deforma run
--states`` and ``deforma sweep --states`` write the same file through :class:`Recording`.

Examples
--------
>>> import numpy as np
>>> from deforma.scene import load
>>> scene = load("sample")
>>> world = scene.build()
>>> recording = Recording(world, scene)
>>> for _ in range(3):
...     recording.add()
...     world.step()
>>> recording.save("sample_states.npz")
>>> states = np.load("sample_states.npz")
>>> states["body0_positions"].shape[0], states["collider_pose"].shape
(3, (3, 1, 3))
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import tomli_w

from ..files import write_atomic
from ..physics import Circle, Polygon, Rect, Segment
from .schema import scene_to_dict

__all__ = ["Recording"]

#: ``collider_kind`` of each collider class; another class is written as its lower-case name.
COLLIDER_KIND = {Rect: "rect", Circle: "circle", Polygon: "polygon", Segment: "segment"}


class Recording:
    """The states of ``world`` at the frames it is recorded at, saved with ``scene`` as an NPZ.

    Parameters
    ----------
    world : deforma.World
        The world being played; :meth:`add` records it as it is now.
    scene : deforma.scene.Scene
        What was played: its ``run.fps`` and its TOML go into the file.

    Attributes
    ----------
    times : list of float
        The world's time at each recorded frame, seconds.
    positions : list of list of (N, 2) arrays
        Per frame, a copy of every body's positions (metres).
    poses : list of list of (float, float, float)
        Per frame, ``(cx, cy, angle)`` of every collider (metres, degrees).
    """

    def __init__(self, world, scene):
        self.world = world
        self.scene = scene
        self.times: list[float] = []
        self.positions: list[list[np.ndarray]] = []
        self.poses: list[list[tuple]] = []

    def add(self) -> None:
        """Record the world as it is now: one frame."""
        w = self.world
        self.times.append(w.time)
        self.positions.append([b.positions.copy() for b in w.bodies])
        self.poses.append([(*c.center, c.angle) for c in w.colliders])

    def arrays(self, *, base_dir) -> dict:
        """The NPZ's arrays by name; the scene's texture files are named relative to ``base_dir``."""
        world, frames = self.world, self.positions
        arrays = {"time": np.asarray(self.times), "fps": np.float64(self.scene.run.fps), "dt": np.float64(world.dt)}
        for i, b in enumerate(world.bodies):
            counts = [len(f[i]) for f in frames]
            if min(counts) == max(counts):
                arrays[f"body{i}_positions"] = np.stack([f[i] for f in frames])
            else:
                # a body that tore: a tear keeps the vertex numbers and appends the copies, so every
                # frame is a prefix of the final numbering; vertices not made yet are NaN
                pos = np.full((len(frames), max(counts), 2), np.nan)
                for k, f in enumerate(frames):
                    pos[k, :counts[k]] = f[i]
                arrays[f"body{i}_positions"] = pos
                arrays[f"body{i}_vertex_count"] = np.asarray(counts)
            arrays[f"body{i}_triangles"] = np.asarray(b.triangles)
            arrays[f"body{i}_springs"] = np.asarray(b.springs)
            arrays[f"body{i}_rest"] = np.asarray(b.topology.rest_positions)
            uv = getattr(b.mesh, "uv", None)
            if uv is not None:
                arrays[f"body{i}_uv"] = np.asarray(uv)
        arrays.update(_collider_arrays(world.colliders, self.poses))
        arrays["scene_toml"] = np.array(tomli_w.dumps(scene_to_dict(self.scene, base_dir=Path(base_dir).resolve())))
        return arrays

    def save(self, path, *, kept_in=None) -> None:
        """Write the NPZ to ``path``, whole or not at all. The scene's texture files are named
        relative to ``kept_in``, the folder the file will be read from (default: its own)."""
        arrays = self.arrays(base_dir=Path(path).parent if kept_in is None else kept_in)
        write_atomic(path, lambda f: np.savez_compressed(f, **arrays))

    def to_bytes(self, *, kept_in=None) -> bytes:
        """The NPZ as bytes (a sweep's worker may be on another machine than the file), its texture
        files named relative to ``kept_in`` (default: the working folder), where it will be read."""
        arrays = self.arrays(base_dir=Path.cwd() if kept_in is None else kept_in)
        buffer = io.BytesIO()
        np.savez_compressed(buffer, **arrays)
        return buffer.getvalue()


def _collider_arrays(colliders, poses) -> dict:
    """The arrays that describe the colliders (docs/cli.md): every shape, its pose per frame
    (``poses``: per frame, ``(cx, cy, angle)`` per collider) and at the end."""
    rows, outlines, holes = [], [], {}
    for j, c in enumerate(colliders):
        # w, h: a rect's size; for the other shapes their box in their own frame, what a reader
        # that draws every row as a rectangle (as before there were other shapes) draws instead
        if isinstance(c, Rect):
            w, h = c.size
        elif isinstance(c, Circle):
            w = h = 2 * c.radius
        elif isinstance(c, Segment):
            w, h = c.length + 2 * c.radius, 2 * c.radius
        else:
            t = np.radians(c.angle)
            local = (np.asarray(c.points) - np.asarray(c.center)) @ np.array([[np.cos(t), -np.sin(t)],
                                                                               [np.sin(t), np.cos(t)]])
            w, h = np.ptp(local, axis=0)
        rows.append([*c.center, w, h, c.angle])
        outlines.append(np.asarray(c.outline(), dtype=np.float64))
        if isinstance(c, Polygon) and c.holes:
            holes[f"collider{j}_holes"] = _padded(c.holes)
    n = len(colliders)
    return {
        "colliders": np.array(rows, dtype=np.float64).reshape(-1, 5),
        "collider_kind": np.array([COLLIDER_KIND.get(type(c), type(c).__name__.lower()) for c in colliders],
                                  dtype="U8"),
        "collider_radius": np.array([getattr(c, "radius", np.nan) for c in colliders], dtype=np.float64),
        "collider_velocity": np.array([c.velocity for c in colliders], dtype=np.float64).reshape(-1, 2),
        "collider_angular_velocity": np.array([c.angular_velocity for c in colliders], dtype=np.float64),
        "collider_outline": _padded(outlines) if outlines else np.zeros((0, 0, 2)),
        "collider_pose": np.array(poses, dtype=np.float64).reshape(len(poses), n, 3),
        **holes,
    }


def _padded(loops) -> np.ndarray:
    """(L, K, 2) from loops of different lengths, NaN after each loop's last point."""
    out = np.full((len(loops), max(len(p) for p in loops), 2), np.nan)
    for k, p in enumerate(loops):
        out[k, :len(p)] = p
    return out

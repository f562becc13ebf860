"""Small meshes for the physics tests, built without deforma.mesh.box (not a dependency here)."""

import math

import numpy as np

from deforma.mesh import Mesh


def grid_mesh(width, height, nx, ny, *, angle=0.0, center=(0.0, 0.0)):
    """A width x height (m) rectangle of nx x ny vertices, split into right triangles,
    rotated by ``angle`` degrees about its centre and centred on ``center``."""
    xs, ys = np.meshgrid(np.linspace(-width / 2, width / 2, nx), np.linspace(-height / 2, height / 2, ny))
    v = np.c_[xs.ravel(), ys.ravel()]
    idx = np.arange(nx * ny).reshape(ny, nx)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    tris = np.r_[np.c_[a, b, c], np.c_[a, c, d]]
    t = math.radians(angle)
    rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    return Mesh(v @ rot.T + np.asarray(center, float), tris)


class Chain:
    """Vertices joined by springs, without triangles (e.g. two masses on one spring)."""

    def __init__(self, vertices, edges):
        self.vertices = np.asarray(vertices, float)
        self.edges = np.asarray(edges, np.int32)

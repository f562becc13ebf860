"""deforma: deformable 2D objects.

A shape (a box or an image) becomes a Delaunay triangle mesh, the mesh becomes a
mass-spring soft body, and the body moves under gravity among rotated-rectangle
colliders with friction.

Examples
--------
>>> import numpy as np, deforma
>>> tris = deforma.delaunay(np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float))
>>> tris.shape
(2, 3)
"""

from . import mesh
from .mesh.delaunay import delaunay
from .physics import Material, Rect, SimulationUnstable, World
from .scene import load_scene, save_scene

__all__ = ["Material", "Rect", "SimulationUnstable", "World", "delaunay", "load_scene", "mesh", "save_scene"]
__version__ = "0.1.0"

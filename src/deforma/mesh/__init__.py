"""Geometry only: Delaunay triangulation and the meshes built on it (no physics)."""

from .box import box
from .delaunay import delaunay
from .export import read_meshes, write_meshes
from .image import from_image
from .mesh import Mesh
from .outline import outline

__all__ = ["Mesh", "box", "delaunay", "from_image", "outline", "read_meshes", "write_meshes"]

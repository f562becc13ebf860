"""deforma: deformable 2D objects.

A shape (a box or an image) becomes a Delaunay triangle mesh, the mesh becomes a
soft body (springs or finite elements), and the body moves under gravity among colliders
of any shape (rectangles, circles, polygons, capsules; fixed or moving) with friction.

Examples
--------
>>> import numpy as np, deforma
>>> tris = deforma.delaunay(np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float))
>>> tris.shape
(2, 3)
"""

from . import kernel_cache as _kernel_cache

_kernel_cache.use_source_keyed_cache()  # before any kernel is defined: see deforma.kernel_cache

from . import mesh  # noqa: E402
from .mesh.delaunay import delaunay  # noqa: E402
from .physics import (Circle, Material, Polygon, Rect, Segment, SimulationUnstable, World,  # noqa: E402
                      colliders_from_image)
from .scene import load_scene, save_scene  # noqa: E402

__all__ = ["Circle", "Material", "Polygon", "Rect", "Segment", "SimulationUnstable", "World", "colliders_from_image",
           "delaunay", "load_scene", "mesh", "save_scene", "show", "sweep"]
__version__ = "0.1.0"


def __getattr__(name):
    # deforma.show draws with OpenGL: its module is imported on first use, so that
    # `import deforma` needs no GL package (deforma.render imports moderngl only to draw)
    if name == "show":
        from .render.notebook import show

        globals()["show"] = show  # found directly from now on
        return show
    if name == "sweep":  # the sweeps module needs no Ray to import; running a sweep does
        from .sweeps import sweep

        globals()["sweep"] = sweep
        return sweep
    raise AttributeError(f"module 'deforma' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | {"show", "sweep"})

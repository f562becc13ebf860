"""Drawing and video: a moderngl renderer (window or headless) and MP4/GIF/PNG writers.

Optional: needs the ``render`` extra (``pip install 'deforma[render]'``). moderngl is
imported only when something is drawn, so importing this package is cheap and safe.

Examples
--------
>>> from deforma.render import Renderer, Camera
>>> r = Renderer.headless((320, 180), camera=Camera(center=(0, 0), size=(4, 2.25)))
>>> r.render(colliders=[((0, -0.5), (3, 0.2), 10.0)])
>>> r.read().shape
(180, 320, 3)
>>> r.release()                # frees the context too
"""

from .renderer import Camera, MeshHandle, Renderer, collider_corners, create_headless_context
from .video import FrameWriter, open_writer
from .world_view import WorldView

__all__ = ["Camera", "FrameWriter", "MeshHandle", "Renderer", "collider_corners", "create_headless_context",
           "open_writer", "WorldView"]

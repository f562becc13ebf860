"""Draw a whole :class:`deforma.World` with the looks its scene gives it (textures, colours, camera).

Shared by ``deforma run`` and the viewer: it uploads each body's triangles, uv and texture
once and then, per frame, only the positions.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .renderer import Camera, Renderer, _as_rgba

if TYPE_CHECKING:
    from ..physics import Body, World
    from ..scene import Scene
    from .renderer import MeshHandle

__all__ = ["BODY_PALETTE", "WorldView"]

#: A joint's dot: its radius in pixels, its sides, its rim and centre colours.
JOINT_DOT_PIXELS = 5.0
JOINT_DOT_SIDES = 16
JOINT_DOT_COLORS = ("#1d2433", "#f4f1de")

#: Colours for bodies that name neither a colour nor a texture, in order of the bodies.
BODY_PALETTE = ("#e07a5f", "#3d9970", "#f2a541", "#5b8def", "#b56576", "#81b29a")


class WorldView:
    """A renderer bound to a world: ``view.draw()`` paints the world's current state.

    Parameters
    ----------
    renderer : Renderer
    world : deforma.World
    scene : deforma.scene.Scene, optional
        Camera, background, wireframe and each body's colour/texture. Default: the scene the
        world was built from (``deforma.scene.scene_of(world)``).
    overlay : bool, optional
        Write the simulated time and a scale bar onto every picture :meth:`draw` reads
        (see :func:`deforma.render.overlay.draw_overlay`). Default off; the ``overlay``
        attribute turns it on or off later. While it is on, the world is framed between the
        rows the text uses (:func:`deforma.render.overlay.overlay_insets`): the camera's
        rectangle, grown to the height of every collider and body at the start, fits in the
        band between the time and the scale bar, so the text covers none of them.
    looks_from : deforma.World, optional
        The world whose scene gives the bodies' and colliders' looks (colours, textures), body
        by body and collider by collider, when ``world`` is a copy of it
        (``copy.deepcopy``): a copy is not the world its scene was built into. Default:
        the world shown (``world``, or whatever world the attribute ``world`` is set to later).

    Examples
    --------
    >>> import deforma
    >>> from deforma.render import Renderer, WorldView
    >>> world = deforma.load_scene("sample")
    >>> view = WorldView(Renderer.headless((320, 180)), world)
    >>> view.draw().shape
    (180, 320, 3)
    >>> view.overlay = True                     # "t = 0.00 s" and a 1 m bar in the corners
    >>> view.draw().shape
    (180, 320, 3)
    >>> view.renderer.release()
    """

    def __init__(self, renderer: Renderer, world: World, scene: Scene | None = None, *, overlay: bool = False,
                 looks_from: World | None = None) -> None:
        from ..scene import scene_of

        self.renderer = renderer
        self.world = world
        self.looks_from = looks_from
        self.scene = scene if scene is not None else scene_of(self._looks())
        cam = self.scene.camera
        renderer.camera = Camera(cam.center, cam.size)
        # the camera asked for (the scene's, or one set on the renderer since); what the
        # renderer shows may differ from it by the overlay's framing (see _place_camera)
        self._wanted: Camera = renderer.camera
        self._placed: Camera = renderer.camera
        self._content_height: tuple[float, float] | None = None
        renderer.background_top = _as_rgba(cam.background[0])[:3]
        renderer.background_bottom = _as_rgba(cam.background[1])[:3]
        self.wireframe = cam.wireframe
        #: The body the camera keeps in the middle (``[camera] follow``), or None.
        self.follow = world.bodies[cam.follow] if cam.follow is not None and cam.follow < len(world.bodies) else None
        self.overlay = bool(overlay)
        self.dim_sleeping = False  # draw sleeping bodies darker (the viewer turns it on)
        self.collider_colors: list | None = None
        self._handles: list[MeshHandle] = []
        self._bodies: list[Body] = []
        self._shown: list[tuple[int, int]] | None = None
        # the joints' dots (a dark disc, a light one on it), made when first needed
        self._markers: tuple[MeshHandle, MeshHandle] | None = None
        self.sync()

    def sync(self) -> None:
        """Pick up bodies and colliders added or removed since the last call."""
        from ..scene import load_texture, scene_of

        try:
            current = scene_of(self._looks())
        except AttributeError:
            # a collider shape the scene format cannot describe (yet): the colliders are then
            # drawn in the default colour; the bodies' looks still need the scene below
            current = None
        colors = [c.color for c in current.collider] if current is not None else []
        self.collider_colors = colors if any(colors) else None
        self._n_colliders = len(self.world.colliders)
        bodies = self.world.bodies
        if [(id(b), id(b.topology)) for b in bodies] == self._shown:
            return
        if current is None:
            current = scene_of(self._looks())  # raises what the scene could not describe
        for h in self._handles:
            self.renderer.remove_mesh(h)
        self._handles = []
        for k, (b, spec) in enumerate(zip(bodies, current.body)):
            # a texture named in the scene wins; else the picture an image mesh carries
            image: np.ndarray | None
            if spec.texture is not None:
                image = load_texture(spec.texture)
            else:
                image = getattr(b.mesh, "texture", None)
                if image is None and spec.shape == "image":
                    image = load_texture(spec.source)
            color = spec.color
            if image is None and color is None:
                color = BODY_PALETTE[k % len(BODY_PALETTE)]
            uv = getattr(b.mesh, "uv", None)
            self._handles.append(self.renderer.add_mesh(b.triangles, uv, texture=image, color=color,
                                                        edges=b.springs))
        self._bodies = bodies
        self._shown = [(id(b), id(b.topology)) for b in bodies]  # a torn body has a new topology
        self._topologies = [b.topology for b in bodies]

    def _draw_joints(self) -> None:
        """A dot on every joint, over the bodies: 5 pixels across, dark with a light centre."""
        joints = getattr(self.world, "joints", ())
        if not joints:
            return
        r = self.renderer
        t = np.arange(JOINT_DOT_SIDES) * 2 * np.pi / JOINT_DOT_SIDES
        ring = np.vstack([[0.0, 0.0], np.column_stack([np.cos(t), np.sin(t)])])
        if self._markers is None:
            fan = np.array([[0, 1 + k, 1 + (k + 1) % JOINT_DOT_SIDES] for k in range(JOINT_DOT_SIDES)])
            self._markers = (r.add_mesh(fan, color=JOINT_DOT_COLORS[0]), r.add_mesh(fan, color=JOINT_DOT_COLORS[1]))
        px = r.camera.metres_per_pixel(r.size)
        for j in joints:
            p = j.point
            for handle, radius in zip(self._markers, (JOINT_DOT_PIXELS * px, 0.5 * JOINT_DOT_PIXELS * px)):
                r.draw_mesh(handle, p + radius * ring)

    def _looks(self):
        # the world whose scene gives the looks: the one shown unless told otherwise, so that a
        # view given another world (the viewer's, when a scene is loaded) takes that world's
        return self.world if self.looks_from is None else self.looks_from

    def draw(self, *, read: bool = True) -> np.ndarray | None:
        """Paint the world's current state; returns the picture (H, W, 3) uint8 when ``read``.

        With :attr:`overlay` on, the picture returned carries the time and scale overlay (it is
        written onto the read-back pixels, so the framebuffer itself has none).
        """
        bodies = self.world.bodies
        if len(bodies) != len(self._bodies) or any(a is not b or a.topology is not t
                                                   for a, b, t in zip(bodies, self._bodies, self._topologies)) \
                or len(self.world.colliders) != self._n_colliders:
            self.sync()
        r = self.renderer
        self._place_camera()
        r.render([(h, b.positions, self.dim_sleeping and b.sleeping) for h, b in zip(self._handles, self._bodies)],
                 self.world.colliders,
                 wireframe=self.wireframe, collider_colors=self.collider_colors)
        self._draw_joints()
        if not read:
            return None
        frame = r.read()
        if self.overlay:
            self.overlay_onto(frame, time=self.world.time)
        return frame

    def _place_camera(self) -> None:
        """Set the renderer's camera for this frame: the one wanted, on the followed body, and
        with the overlay on, framed between the overlay's rows."""
        from .framing import camera_box, fit_camera
        from .overlay import overlay_insets

        r = self.renderer
        if r.camera is not self._placed:  # set by the caller since: that is the camera wanted now
            self._wanted = r.camera
        cam = self._wanted
        if self.follow is not None and any(b is self.follow for b in self.world.bodies):
            cam = Camera(tuple(map(float, self.follow.center_of_mass)), cam.size)  # type: ignore[arg-type]  # (x, y)
        if self.overlay:
            if self._content_height is None:  # the scene's extent at the start, kept: no zooming along
                self._content_height = self._height()
            x0, y0, x1, y1 = camera_box(cam.center, cam.size)
            lo, hi = self._content_height
            top, bottom = overlay_insets(r.size[1])
            cam = fit_camera((x0, min(y0, lo), x1, max(y1, hi)), r.size, insets=(0, top, 0, bottom))
        r.camera = self._placed = cam

    def _height(self) -> tuple[float, float]:
        """Lowest and highest point of every collider and body now (m); only the height matters:
        what lies beyond the picture's sides is not drawn, so no text can cover it."""
        from .framing import content_bounds

        box = content_bounds(self.world)
        if box is None:
            return (np.inf, -np.inf)
        return (box[1], box[3])

    def overlay_onto(self, frame: np.ndarray, *, time: float, metres_per_pixel: float | None = None) -> None:
        """Write the time and scale overlay onto ``frame`` (a picture this view drew, read back
        later: :class:`deforma.render.recorder.FrameRecorder`); the scale defaults to the camera's now."""
        from .overlay import draw_overlay

        r = self.renderer
        mpp = r.camera.metres_per_pixel(r.size) if metres_per_pixel is None else metres_per_pixel
        draw_overlay(frame, time=time, metres_per_pixel=mpp)

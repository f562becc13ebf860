"""The interactive viewer: a pygame-ce OpenGL window, mouse and keys, the inspector panel.

``deforma view [SCENE]`` runs :func:`run`. Each frame:

1. events: the panel gets the ones over it (and key presses while a text box has focus);
   the others grab and pull bodies, drag colliders, pan, zoom, or are shortcut keys
   (:mod:`deforma.viewer.controls`);
2. physics: a :class:`~deforma.viewer.clock.FixedStepClock` turns the frame's wall time into
   whole ``world.dt`` steps, so the motion is the same at any frame rate; a slow frame is
   capped instead of spiralling, and an unstable step pauses the viewer and shows the hint;
3. drawing: the shared :class:`deforma.render.WorldView` paints the world into the window's
   framebuffer, then the pinned vertices (small dark squares), the panel, status line and
   help are drawn over it.

With ``frames=N`` (``--frames``) the viewer runs N frames of exactly 1/60 s of simulated
time each, without waiting for input or the wall clock, so a script gets the same picture
every time.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .clock import FixedStepClock
from .controls import KEYS, help_rows
from .session import Session

if TYPE_CHECKING:
    import pygame

    from ..physics import Grab
    from ..render.renderer import Camera
    from ..scene import Scene
    from .overlay import OverlayLayer

#: Smallest window (pixels) the viewer lays out: the inspector panel (340 px wide: 104 px of
#: buttons, a scrolling list showing at least 4 rows of 26 px, a 64 px message box) beside a
#: world area of 300 px, which holds the 260 px "unstable" message box. Smaller windows broke
#: inside pygame_gui (a scroll bar with no room divides by zero or recurses without end) or
#: asked for a message box of negative width (issue 17); the panel can be shown at any time
#: (Tab), so the size is checked with the panel. Kept equal to ``inspector``'s constants by a test.
MIN_WINDOW_SIZE = (340 + 300, 104 + 4 * 26 + 64)


def check_window_size(size: Iterable[float]) -> tuple[int, int]:
    """``size`` as two ints, or ValueError naming it and :data:`MIN_WINDOW_SIZE`."""
    try:
        w, h = (int(v) for v in size)
    except (TypeError, ValueError):
        raise ValueError(f"size must be (width, height) in pixels, got {size!r}") from None
    mw, mh = MIN_WINDOW_SIZE
    if w < mw or h < mh:
        raise ValueError(f"window size {w}x{h} is too small for the viewer: at least {mw}x{mh} pixels "
                         f"(the inspector panel and the world beside it)")
    return w, h

__all__ = ["Viewer", "run"]

#: Simulated seconds per frame in ``frames=N`` mode (a 60 Hz display).
HEADLESS_FRAME_TIME = 1 / 60
#: Wall seconds of physics per frame before the rest of the frame's steps are dropped:
#: keeps the window responsive when a setting makes the physics slower than real time.
PHYSICS_BUDGET = 0.05
STATUS_INTERVAL = 0.25   # seconds between status line updates
#: Pixels between the status line and the window's left and bottom edges.
STATUS_MARGIN = 10
#: Pixels kept free between the framed world and the edges of the area it is framed in, so
#: that no collider or body touches an edge or the status line.
FRAME_PAD = 8
GREETING = "Left-drag the body to pull it, Space blows it up, H lists every key."
SELECTED_COLLIDER_COLOR = "#6d8fcb"  # a bluer slate: selected, not shouting
#: How far off a body's outline (pixels) the pin key and shift+click still find a vertex, and
#: a click still picks a collider (a wire has no inside).
PIN_PICK_PIXELS = 10


def _font_path() -> str | None:
    try:
        import pygame_gui

        p = Path(pygame_gui.__file__).parent / "data" / "NotoSans-Regular.ttf"
        return str(p) if p.is_file() else None
    except ImportError:  # pragma: no cover - pygame_gui is required by the viewer anyway
        return None


def _wrap(text: str, font: pygame.font.Font, width: int) -> list[str]:
    lines: list[str] = []
    line = ""
    for word in text.split():
        trial = f"{line} {word}".strip()
        if line and font.size(trial)[0] > width:
            lines.append(line)
            line = word
        else:
            line = trial
    if line:
        lines.append(line)
    return lines


class Viewer:
    """A window showing a scene, with the inspector panel, mouse pull and explosion.

    Parameters
    ----------
    scene : str, path or deforma.scene.Scene, optional
        A built-in scene name, a ``.toml`` file or a scene object.
    size : (int, int), keyword-only
        Window size in pixels.
    panel : bool, keyword-only
        Show the inspector panel (Tab toggles it).
    vsync : bool, keyword-only
        Wait for the display's refresh (off for benchmarks and scripts).
    samples : int, keyword-only
        Multisampling of the window (0 off; 4 smooths edges at a cost on software GL).
    save_path : str, keyword-only
        Initial file name in the panel's "save scene" box.

    Raises
    ------
    RuntimeError
        No window with OpenGL 3.3 can be opened (no display, no GL driver); one line.

    Examples
    --------
    >>> import os; _ = os.environ.setdefault("SDL_VIDEODRIVER", "offscreen")  # works without a display
    >>> v = Viewer("demo", size=(640, 360))
    >>> for _ in range(30): v.frame(1 / 60)
    >>> v.screenshot().shape
    (360, 640, 3)
    >>> v.close()
    """

    def __init__(self, scene: Session | Scene | str | os.PathLike[str] = "demo", *,
                 size: Sequence[float] = (1280, 720), panel: bool = True, vsync: bool = False, samples: int = 0,
                 save_path: str | None = None) -> None:
        import pygame

        self.pg = pygame
        self.window_size = check_window_size(size)
        self.session = session = scene if isinstance(scene, Session) else Session(scene)
        self._open_window(vsync=vsync, samples=samples)
        import moderngl

        from ..render import Renderer, WorldView
        from .inspector import Inspector
        from .overlay import Overlay

        try:
            self.ctx = moderngl.create_context(require=330)
        except Exception as e:  # noqa: BLE001 - moderngl raises plain Exceptions
            pygame.display.quit()
            raise RuntimeError(f"cannot use OpenGL 3.3 in the window ({e})") from None
        self.renderer = Renderer(self.ctx, self.window_size, target=self.ctx.screen)
        self.view = WorldView(self.renderer, session.world)
        self.view.follow = None  # the session moves the camera (Session.follow_camera), panning stops it
        self.view.dim_sleeping = True
        self._frame_scene()
        self.overlay = Overlay(self.ctx)
        name = session.scene.scene.name or "scene"
        self.save_path = save_path or f"{name}-edited.toml"
        actions = {"pause": self.toggle_pause, "step": self.single_step, "reset": self.reset,
                   "wireframe": self.toggle_wireframe}
        self._Inspector = Inspector
        self._actions = actions
        self.inspector = Inspector(session, self.window_size[1], save_path=self.save_path, actions=actions)
        self.inspector.say(GREETING)
        self.panel_visible = bool(panel)
        self._panel_stale = True
        self.panel_layer = self.overlay.layer(self.inspector.surface.get_size())
        pygame.font.init()
        fp = _font_path()
        self.font = pygame.font.Font(fp, 15)
        self.small_font = pygame.font.Font(fp, 14)
        self.status_layer: OverlayLayer | None = None
        self.help_layer: OverlayLayer | None = None
        self.message_layer: OverlayLayer | None = None
        self._message_key: tuple[str | None, tuple[int, int]] | None = None
        self.help_visible = False
        self.clock = FixedStepClock()
        self.paused = False
        self.unstable: str | None = None
        self.running = True
        self.grab: Grab | None = None
        self._joining: list[tuple[float, float]] | None = None  # the J key's clicks (world points) while joining
        self._collider_drag: tuple[float, float] | None = None  # offset from the pointer to the collider centre
        self._pan: tuple[float, ...] | None = None              # last pointer position while panning
        self.pointer: tuple[float, ...] = (0, 0)
        self._generation = session.generation
        self._n_colliders = len(session.world.colliders)
        self._single = 0
        self.frames = 0
        self.steps = 0
        self._last_time = time.perf_counter()
        self._stat_time = self._last_time
        self._stat_frames = 0
        self._stat_steps = 0
        self.fps = 0.0
        self.steps_per_second = 0.0
        self._status_text: str | None = None
        self._screenshot_requests: list[str] = []
        self.last_screenshot: np.ndarray | None = None
        #: screenshots that could not be saved: path -> why (a scripted run reports them)
        self.screenshot_errors: dict[str, str] = {}
        self._keymap = self._make_keymap()
        self.renderer.resize(self.world_size)
        self.renderer.camera = self.view_camera()
        pygame.display.set_caption(f"deforma - {name}")

    # -- window ------------------------------------------------------------------------------
    def _open_window(self, *, vsync: bool, samples: int) -> None:
        pg = self.pg
        try:
            pg.display.init()
            pg.font.init()  # pygame_gui's fonts need it before the panel is made
            pg.display.gl_set_attribute(pg.GL_CONTEXT_MAJOR_VERSION, 3)
            pg.display.gl_set_attribute(pg.GL_CONTEXT_MINOR_VERSION, 3)
            pg.display.gl_set_attribute(pg.GL_CONTEXT_PROFILE_MASK, pg.GL_CONTEXT_PROFILE_CORE)
            if samples and samples > 1:
                pg.display.gl_set_attribute(pg.GL_MULTISAMPLEBUFFERS, 1)
                pg.display.gl_set_attribute(pg.GL_MULTISAMPLESAMPLES, int(samples))
            flags = pg.OPENGL | pg.DOUBLEBUF | pg.RESIZABLE
            try:
                pg.display.set_mode(self.window_size, flags, vsync=1 if vsync else 0)
            except pg.error:
                if not vsync:
                    raise
                pg.display.set_mode(self.window_size, flags)  # vsync is a wish, not a need
        except pg.error as e:
            pg.display.quit()
            raise RuntimeError(f"cannot open an OpenGL 3.3 window ({e}); the viewer needs a display "
                               f"(for scripts: SDL_VIDEODRIVER=offscreen)") from None

    @property
    def world_size(self) -> tuple[int, int]:
        """Pixels of the window that show the world (left of the panel)."""
        from .inspector import PANEL_WIDTH

        w, h = self.window_size
        if self.panel_visible:
            w = max(1, w - PANEL_WIDTH)
        return (w, h)

    @property
    def status_band(self) -> int:
        """Rows at the bottom of the window that the status line covers, with its margin."""
        h = self.status_layer.size[1] if self.status_layer is not None else self.small_font.get_height() + 10
        return h + STATUS_MARGIN

    def free_rect(self) -> tuple[int, int, int, int]:
        """``(left, top, right, bottom)`` window pixels the world is framed in: left of the panel,
        above the status line, :data:`FRAME_PAD` in from each."""
        w, h = self.world_size
        return (FRAME_PAD, FRAME_PAD, w - FRAME_PAD, h - self.status_band - FRAME_PAD)

    def _frame_scene(self) -> None:
        """Grow the session's camera rectangle to hold every collider and body of the scene as
        it starts: a scene file's camera may cut off a wall or a floor the picture should show.

        A camera that follows a body (``[camera] follow``, a side-scroller such as ``car``)
        keeps its width around that body, since its level runs on past the picture's sides on
        purpose; it grows to every body and to the colliders' full height, centred on the body
        as :meth:`Session.follow_camera` will put it.
        """
        from ..render.framing import camera_box, content_bounds, union

        s = self.session
        world = s.world
        box = camera_box(s.camera_center, s.camera_size)
        if s.follow is not None and s.follow < len(world.bodies):
            bodies = content_bounds(world, colliders=False)
            colliders = content_bounds(world, bodies=False)
            box = union(box, bodies)
            if colliders is not None:
                box = union(box, (box[0], colliders[1], box[2], colliders[3]))
            cx, cy = (float(v) for v in world.bodies[s.follow].center_of_mass)
            hw, hh = max(cx - box[0], box[2] - cx), max(cy - box[1], box[3] - cy)
            box = (cx - hw, cy - hh, cx + hw, cy + hh)
        else:
            box = union(box, content_bounds(world))
        x0, y0, x1, y1 = box
        s.camera_center = ((x0 + x1) / 2, (y0 + y1) / 2)
        s.camera_size = (x1 - x0, y1 - y0)

    def view_camera(self) -> Camera:
        """The camera the world is drawn with: the session's camera rectangle, whole and as
        large as fits, centred in :meth:`free_rect` (so the panel and the status line cover
        none of it)."""
        from ..render.framing import camera_box, fit_camera

        s = self.session
        w, h = self.world_size
        left, top, right, bottom = self.free_rect()
        return fit_camera(camera_box(s.camera_center, s.camera_size), (w, h),
                          insets=(left, top, w - right, h - bottom))

    def _resize(self, size: Sequence[float]) -> None:
        # a window dragged smaller is laid out at the smallest size (the rest is cut off)
        self.window_size = (max(MIN_WINDOW_SIZE[0], int(size[0])), max(MIN_WINDOW_SIZE[1], int(size[1])))
        message = (self.inspector.message, self.inspector.message_is_error)
        self.inspector = self._Inspector(self.session, self.window_size[1], save_path=self.inspector.save_entry.get_text(),
                                         actions=self._actions)
        self.inspector.say(message[0], error=message[1])

    def close(self) -> None:
        """Free GL resources and close the window."""
        for layer in (self.panel_layer, self.status_layer, self.help_layer, self.message_layer):
            if layer is not None:
                layer.release()
        self.overlay.release()
        self.renderer.release()
        self.ctx.release()
        self.pg.display.quit()

    # -- actions -----------------------------------------------------------------------------
    def _make_keymap(self) -> dict[int, str]:
        pg = self.pg
        out: dict[int, str] = {}
        for names, action, _ in KEYS:
            for n in names:
                out[pg.key.key_code(n)] = action
        return out

    def toggle_pause(self) -> None:
        """Pause or resume; resuming after an instability clears its message."""
        self.paused = not self.paused
        if not self.paused:
            self.unstable = None
        self.clock.reset()

    def single_step(self) -> None:
        """Pause (if running) and advance exactly one step."""
        self.paused = True
        self._single += 1

    def reset(self) -> None:
        """Bodies back to their start (keeps every edited value)."""
        self._release_grab()
        self.session.reset()
        self.unstable = None
        self.clock.reset()

    def toggle_wireframe(self) -> None:
        self.session.wireframe = not self.session.wireframe

    def explode(self) -> None:
        """The space key: every vertex gets the explosive force upward (m/s)."""
        self.session.world.explode(self.session.explosive_force)

    def toggle_pin(self, pos: Sequence[float] | None = None) -> None:
        """Pin the vertex nearest the pointer (window pixel ``pos``) on the body under it, or
        free it if it is pinned: the F key and shift+click."""
        pos = self.pointer if pos is None else pos
        if self._over_panel(pos):
            return
        radius = PIN_PICK_PIXELS * self._metres_per_pixel()
        hit = self.session.toggle_pin(self.to_world(pos), radius=radius)
        if hit is None:
            self.inspector.say("no body under the pointer to pin")
        else:
            body, vertex, pinned = hit
            self.inspector.say(f"{'pinned' if pinned else 'unpinned'} vertex {vertex} of body {body}"
                               + ("; U unpins all" if pinned else ""))

    def start_join(self) -> None:
        """The J key: the next two left clicks make a hinge (J again: forget it)."""
        self._release_grab()
        if self._joining is not None:
            self._joining = None
            self.inspector.say("join cancelled")
            return
        self._joining = []
        self.inspector.say("join: click a rigid body where the hinge goes, then the body to hinge it to "
                           "(the background or the same body: the world)")

    def _join_click(self, pos: Sequence[float]) -> None:
        assert self._joining is not None  # only called while joining
        self._joining.append(self.to_world(pos))
        if len(self._joining) < 2:
            self.inspector.say("now click the body to hinge it to (the background: the world)")
            return
        first, second = self._joining
        self._joining = None
        try:
            j = self.session.join(first, second)
        except ValueError as e:
            self.inspector.say(str(e), error=True)
            return
        other = "the world" if j.b is None else f"body {j.b._index}"
        self.inspector.say(f"hinged body {j.a._index} to {other} at ({first[0]:.2f}, {first[1]:.2f}) m")

    def unpin_all(self) -> None:
        """Free every pinned vertex (the U key)."""
        n = self.session.unpin_all()
        self.inspector.say(f"unpinned {n} vertices" if n else "nothing was pinned")

    def select_object(self, name: str) -> None:
        """Switch the edited body to ``bunny``, ``donut``, ``armadillo`` or ``box``."""
        self._release_grab()
        self.inspector.apply_object(name)

    def load(self, scene: Session | Scene | str | os.PathLike[str]) -> None:
        """Open another scene (a name, a file, or a Session) in the same window."""
        self._release_grab()
        self.session = scene if isinstance(scene, Session) else Session(scene)
        self._frame_scene()
        self.inspector = self._Inspector(self.session, self.window_size[1], save_path=self.save_path,
                                         actions=self._actions)
        if self.session.note:  # e.g. a scene under XPBD with too few substeps
            self.inspector.say(self.session.note, error=self.session.note_is_warning)
        self._generation = -1  # forces the view to re-upload meshes
        self.unstable = None
        self.paused = False
        self.clock.reset()

    def request_screenshot(self, path: str | None = None) -> None:
        """Save the next drawn frame to ``path`` (default ``deforma-NNN.png``, never overwriting)."""
        if path is None:
            k = 1
            while Path(f"deforma-{k:03d}.png").exists():
                k += 1
            path = f"deforma-{k:03d}.png"
        self._screenshot_requests.append(str(path))

    def rotate_collider(self, degrees: float) -> None:
        """Turn the selected collider about its centre (the Z and X keys)."""
        s = self.session
        # only one the person picked (it is drawn highlighted), not the panel's default choice
        i = s.collider_index  # None: no collider (s.collider is None)
        if i is None or not s.collider_active:
            self.inspector.say("click a collider first to turn it")
            return
        angle = s.rotate_collider(degrees)
        self.inspector.say(f"{s.collider_shape} {i + 1} at {angle:g}°")
        self.inspector.refresh()

    def remove_collider(self) -> None:
        """Remove the selected collider (the Delete key)."""
        s = self.session
        if s.collider is None or not s.collider_active:
            self.inspector.say("click a collider first to remove it")
            return
        self._collider_drag = None
        shape = s.collider_shape
        s.remove_collider()
        self.inspector.say(f"removed the {shape}")
        self.inspector.refresh()

    def _do(self, action: str, *, mod: int = 0) -> None:
        if action.startswith("rotate:"):
            step = float(action.split(":", 1)[1])
            # Shift for fine turns: 1° a press
            self.rotate_collider(step / abs(step) if mod & self.pg.KMOD_SHIFT else step)
        elif action == "remove_collider":
            self.remove_collider()
        elif action == "explode":
            self.explode()
        elif action == "pause":
            self.toggle_pause()
        elif action == "step":
            self.single_step()
        elif action == "reset":
            self.reset()
        elif action == "wireframe":
            self.toggle_wireframe()
        elif action == "pin":
            self.toggle_pin()
        elif action == "unpin":
            self.unpin_all()
        elif action == "join":
            self.start_join()
        elif action.startswith("drive:"):
            self.inspector.say(self.session.drive(int(action.split(":", 1)[1])))
        elif action.startswith("object:"):
            self.select_object(action.split(":", 1)[1])
        elif action == "panel":
            self.panel_visible = not self.panel_visible
            self._panel_stale = True
        elif action == "screenshot":
            self.request_screenshot()
        elif action == "help":
            self.help_visible = not self.help_visible
        elif action == "quit":
            self.running = False

    # -- input -------------------------------------------------------------------------------
    def to_world(self, pos: ArrayLike) -> tuple[float, float]:
        """Window pixel (column, row from the top) to world metres."""
        p = self.renderer.camera.pixel_to_world(np.asarray(pos, float), self.world_size)
        return float(p[0]), float(p[1])

    def to_pixel(self, point: ArrayLike) -> tuple[float, float]:
        """World metres to window pixel (column, row from the top)."""
        q = self.renderer.camera.world_to_pixel(np.asarray(point, float), self.world_size)
        return float(q[0]), float(q[1])

    def _over_panel(self, pos: Sequence[float]) -> bool:
        return self.panel_visible and pos[0] >= self.world_size[0]

    def _panel_event(self, e: pygame.event.Event) -> pygame.event.Event:
        pg = self.pg
        if e.type in (pg.MOUSEMOTION, pg.MOUSEBUTTONDOWN, pg.MOUSEBUTTONUP):
            d = dict(e.dict)
            d["pos"] = (e.pos[0] - self.world_size[0], e.pos[1])
            return pg.event.Event(e.type, d)
        return e

    def _release_grab(self) -> None:
        if self.grab is not None:
            try:
                self.session.world.release(self.grab)
            except ValueError:
                pass  # the world was rebuilt: the grab went with it
            self.grab = None
        self._collider_drag = None

    def handle_event(self, e: pygame.event.Event) -> None:
        """React to one pygame event (the panel's, the world's or a shortcut)."""
        pg = self.pg
        t = e.type
        if t == pg.QUIT:
            self.running = False
            return
        if t == pg.VIDEORESIZE:
            self._resize(e.size)
            return
        if t == pg.DROPFILE and str(e.file).lower().endswith(".toml"):
            try:
                self.load(e.file)
            except ValueError as err:
                self.inspector.say(str(err), error=True)
            return
        if t in (pg.MOUSEMOTION, pg.MOUSEBUTTONDOWN, pg.MOUSEBUTTONUP):
            self.pointer = tuple(e.pos)
            busy = self.grab is not None or self._collider_drag is not None or self._pan is not None
            if self.panel_visible and (t != pg.MOUSEBUTTONDOWN or self._over_panel(e.pos)):
                # the panel sees every motion and release (hover, slider drags ending outside it)
                used = self.inspector.process_event(self._panel_event(e))
                if t == pg.MOUSEBUTTONDOWN and (used or self._over_panel(e.pos)):
                    return
            if t == pg.MOUSEMOTION and not busy and self._over_panel(e.pos):
                return
            self._world_mouse(e)
            return
        if t == pg.MOUSEWHEEL:
            if self._over_panel(self.pointer):
                self.inspector.process_event(e)
            else:
                self._zoom(e.y)
            return
        if t in (pg.KEYDOWN, pg.KEYUP, pg.TEXTINPUT, pg.TEXTEDITING):
            if self.panel_visible and self.inspector.typing:
                self.inspector.process_event(e)
                return
            if t == pg.KEYDOWN:
                if e.key == pg.K_s and e.mod & pg.KMOD_CTRL:
                    self.inspector.save()
                    self.panel_visible = True
                    return
                action = self._keymap.get(e.key)
                if action is not None:
                    self._do(action, mod=getattr(e, "mod", 0))
            return
        # the panel's own events (button presses, entries finished, ...)
        self.inspector.process_event(e)

    def _world_mouse(self, e: pygame.event.Event) -> None:
        pg = self.pg
        s = self.session
        t = e.type
        if t == pg.MOUSEBUTTONDOWN and e.button == 1 and pg.key.get_mods() & pg.KMOD_SHIFT:
            self._release_grab()
            self.toggle_pin(e.pos)
        elif t == pg.MOUSEBUTTONDOWN and e.button == 1 and self._joining is not None:
            self._join_click(e.pos)
        elif t == pg.MOUSEBUTTONDOWN and e.button == 1:
            p = self.to_world(e.pos)
            self._release_grab()
            # the triangle under the pointer, as World.grab picks it: mouse strength is per held
            # vertex, so grabbing a whole patch of a fine mesh would multiply the pull and tear it
            g = s.world.grab(p)
            if len(g.vertices):
                self.grab = g
                body = s.world.bodies.index(g.body)
                if body != s.body_index:
                    s.select_body(body)
                    self.inspector.refresh(force=True)
                return
            s.world.release(g)
            i = s.collider_at(p, radius=PIN_PICK_PIXELS * self._metres_per_pixel())
            if i is not None:
                s.select_collider(i)
                c = s.world.colliders[i]
                self._collider_drag = (c.center[0] - p[0], c.center[1] - p[1])
                self.inspector.refresh()
        elif t == pg.MOUSEBUTTONDOWN and e.button in (2, 3):
            self._pan = tuple(e.pos)
        elif t == pg.MOUSEMOTION:
            if self.grab is not None:
                s.world.drag(self.grab, self.to_world(e.pos))
            elif self._collider_drag is not None:
                p = self.to_world(e.pos)
                dx, dy = self._collider_drag
                s.move_collider((p[0] + dx, p[1] + dy))
            elif self._pan is not None:
                a, b = self.to_world(self._pan), self.to_world(e.pos)
                s.follow = None  # panned: the camera stays where it is put
                cx, cy = s.camera_center
                s.camera_center = (cx - (b[0] - a[0]), cy - (b[1] - a[1]))
                self._pan = tuple(e.pos)
        elif t == pg.MOUSEBUTTONUP:
            if e.button == 1:
                self._release_grab()
            elif e.button in (2, 3):
                self._pan = None

    def _metres_per_pixel(self) -> float:
        hx, _ = self.renderer.camera.extent(self.world_size)
        return 2 * hx / self.world_size[0]

    def _zoom(self, clicks: float) -> None:
        s = self.session
        f = 0.9 ** float(clicks)
        before = self.to_world(self.pointer)
        w, h = s.camera_size
        s.camera_size = (min(max(w * f, 0.2), 500.0), min(max(h * f, 0.2), 500.0))
        self.renderer.camera = self.view_camera()
        after = self.to_world(self.pointer)
        cx, cy = s.camera_center
        s.camera_center = (cx + before[0] - after[0], cy + before[1] - after[1])  # zoom about the pointer

    # -- one frame ---------------------------------------------------------------------------
    def frame(self, frame_time: float | None = None) -> None:
        """Handle pending events, advance the physics and draw one frame.

        Parameters
        ----------
        frame_time : float, optional
            Seconds this frame stands for. Default: the wall time since the previous frame
            (and the physics then also stops at :data:`PHYSICS_BUDGET` seconds of work).
            Given, the frame advances exactly that much simulated time (scripts, tests).
        """
        now = time.perf_counter()
        live = frame_time is None
        if frame_time is None:
            frame_time = now - self._last_time
        self._last_time = now
        for e in self.pg.event.get():
            self.handle_event(e)
            if not self.running:
                return
        self._simulate(frame_time, budget=PHYSICS_BUDGET if live else None)
        self._draw(frame_time)
        self.pg.display.flip()
        self.frames += 1
        self._stat_frames += 1

    def _simulate(self, frame_time: float, *, budget: float | None) -> None:
        from ..physics import SimulationUnstable

        world = self.session.world
        n = 0 if self.paused else self.clock.advance(frame_time, dt=world.dt)
        n += self._single
        self._single = 0
        t0 = time.perf_counter()
        for k in range(n):
            try:
                world.step()
            except SimulationUnstable as e:
                self.paused = True
                self.unstable = e.hint
                self._release_grab()
                self.clock.reset()
                return
            self.steps += 1
            self._stat_steps += 1
            if budget is not None and time.perf_counter() - t0 > budget and k + 1 < n:
                self.clock.dropped += (n - k - 1) * world.dt
                break

    def _sync_view(self) -> None:
        s, v = self.session, self.view
        if self._generation != s.generation or v.world is not s.world:
            v.world = s.world
            v.sync()
            self._generation = s.generation
            self._n_colliders = len(s.world.colliders)
            self.grab = None
        elif len(s.world.colliders) != self._n_colliders:
            v.sync()
            self._n_colliders = len(s.world.colliders)
        colors = list(s.collider_colors) + [None] * (len(s.world.colliders) - len(s.collider_colors))
        if s.collider_index is not None and s.collider_active and self.panel_visible:
            colors[s.collider_index] = SELECTED_COLLIDER_COLOR
        v.collider_colors = colors if any(colors) else None
        v.wireframe = s.wireframe

    def _draw(self, frame_time: float) -> None:
        s = self.session
        self._sync_view()
        r = self.renderer
        r.resize(self.world_size)
        s.follow_camera()
        cam = self.view_camera()
        if cam != r.camera:
            r.camera = cam
        self.view.draw(read=False)
        win = self.window_size
        self._draw_pins(win)
        if self.panel_visible:
            self.inspector.set_paused(self.paused)
            surf = self.inspector.update(frame_time)
            if surf is not None or self._panel_stale:
                self.panel_layer.upload(self.inspector.surface)
                self._panel_stale = False
            self.overlay.draw(self.panel_layer, (self.world_size[0], 0), win, blend=False)
        self._draw_status(win)
        if self.unstable is not None:
            self._draw_message(win)
        if self.help_visible:
            self._draw_help(win)
        if self._screenshot_requests:
            img = self.screenshot()
            from PIL import Image

            from ..files import write_atomic

            for path in self._screenshot_requests:
                try:
                    # whole or not at all, like every other output: a full disk leaves no half PNG
                    write_atomic(path, lambda f: Image.fromarray(img).save(f, format="PNG"))
                    self.screenshot_errors.pop(path, None)
                    if self.panel_visible:
                        self.inspector.say(f"screenshot saved to {path}")
                except (OSError, ValueError) as e:
                    self.screenshot_errors[path] = str(e)
                    self.inspector.say(f"cannot save the screenshot: {e}", error=True)
            self._screenshot_requests.clear()

    def pinned_points(self) -> np.ndarray:
        """(N, 2) world positions (metres) of every pinned vertex of every body."""
        parts = [b.positions[b.pinned] for b in self.session.world.bodies]
        return np.concatenate(parts) if parts else np.zeros((0, 2))

    def _draw_pins(self, win: tuple[int, int]) -> None:
        points = self.pinned_points()
        if not len(points):
            return
        px = self.renderer.camera.world_to_pixel(points, self.world_size)
        ww, wh = self.world_size
        shown = (px[:, 0] >= 0) & (px[:, 0] < ww) & (px[:, 1] >= 0) & (px[:, 1] < wh)  # not over the panel
        self.overlay.draw_marks(px[shown], win)

    def screenshot(self) -> np.ndarray:
        """The window's current picture as an (H, W, 3) uint8 array, row 0 on top."""
        from .overlay import as_rgb_array

        w, h = self.window_size
        raw = self.ctx.screen.read(viewport=(0, 0, w, h), components=3, alignment=1)
        self.last_screenshot = as_rgb_array(raw, (w, h))
        return self.last_screenshot

    # -- text overlays -----------------------------------------------------------------------
    def _update_stats(self) -> None:
        now = time.perf_counter()
        dt = now - self._stat_time
        # a screenshot shows the figures of its own frame, not ones up to STATUS_INTERVAL old
        if dt >= STATUS_INTERVAL or self._status_text is None or self._screenshot_requests:
            if dt > 0 and self._stat_frames:
                self.fps = self._stat_frames / dt
                self.steps_per_second = self._stat_steps / dt
            self._stat_time, self._stat_frames, self._stat_steps = now, 0, 0
            w = self.session.world
            nv = sum(b.n_vertices for b in w.bodies)
            nt = sum(len(b.triangles) for b in w.bodies)
            try:
                energy = f"{w.energy().total:.2f} J"
            except (ValueError, FloatingPointError):
                energy = "-"
            state = "   PAUSED" if self.paused else ""
            self._status_text = (f"{self.fps:.0f} frames/s   {self.steps_per_second:.0f} steps/s   "
                                 f"{nv} vertices   {nt} triangles   energy {energy}   "
                                 f"t = {w.time:.2f} s{state}   H: help")

    def _draw_status(self, win: tuple[int, int]) -> None:
        from .overlay import rounded_box

        prev = self._status_text
        self._update_stats()
        if self.status_layer is None or prev != self._status_text:
            text = self.small_font.render(self._status_text, True, (245, 247, 250))
            box = rounded_box((text.get_width() + 20, text.get_height() + 10), (24, 30, 40, 190), 8)
            box.blit(text, (10, 5))
            if self.status_layer is None:
                self.status_layer = self.overlay.layer(box.get_size())
            self.status_layer.upload(box)
        h = self.status_layer.size[1]
        self.overlay.draw(self.status_layer, (STATUS_MARGIN, win[1] - h - STATUS_MARGIN), win)

    def _text_box(self, rows: Iterable[str | tuple[str, str]], *, width: int, fg: tuple[int, ...],
                  bg: tuple[int, ...], title: str | None = None, key_width: int = 0) -> pygame.Surface:
        """A rounded box of text rows; a row is a string or (key, text) drawn in two columns."""
        from .overlay import rounded_box

        f = self.small_font
        rendered: list[tuple[pygame.Surface | None, pygame.Surface, int]] = []
        if title:
            rendered.append((None, self.font.render(title, True, fg), 6))
        for row in rows:
            if isinstance(row, tuple):
                rendered.append((f.render(row[0], True, (150, 190, 255)), f.render(row[1], True, fg), 0))
            else:
                rendered.append((None, f.render(row, True, fg), 0))
        h = sum(t.get_height() + extra for _, t, extra in rendered) + 24
        w = min(width, max(t.get_width() + (key_width if k is not None else 0) for k, t, _ in rendered) + 32)
        box = rounded_box((w, h), bg, 10)
        y = 12
        for k, t, extra in rendered:
            if k is not None:
                box.blit(k, (16, y))
                box.blit(t, (16 + key_width, y))
            else:
                box.blit(t, (16, y))
            y += t.get_height() + extra
        return box

    def _draw_help(self, win: tuple[int, int]) -> None:
        if self.help_layer is None:
            rows = help_rows()
            key_width = max(self.small_font.size(k)[0] for k, _ in rows) + 18
            box = self._text_box(rows, width=760, fg=(245, 247, 250), bg=(24, 30, 40, 225),
                                 title="Keys and mouse", key_width=key_width)
            self.help_layer = self.overlay.layer(box.get_size())
            self.help_layer.upload(box)
        w, h = self.help_layer.size
        ww, wh = self.world_size
        self.overlay.draw(self.help_layer, (max(0, (ww - w) // 2), max(0, (wh - h) // 2)), win)

    def _draw_message(self, win: tuple[int, int]) -> None:
        key = (self.unstable, self.world_size)
        if self.message_layer is None or key != self._message_key:
            width = min(640, self.world_size[0] - 40)
            lines = _wrap(f"{self.unstable}. Change a value in the panel, then press P to resume or R to reset.",
                          self.small_font, width - 32)
            box = self._text_box(lines, width=width, fg=(255, 255, 255), bg=(170, 45, 40, 230),
                                 title="Simulation unstable: paused")
            if self.message_layer is not None:
                self.message_layer.release()
            self.message_layer = self.overlay.layer(box.get_size())
            self.message_layer.upload(box)
            self._message_key = key
        w, _ = self.message_layer.size
        self.overlay.draw(self.message_layer, (max(0, (self.world_size[0] - w) // 2), 20), win)

    # -- loop --------------------------------------------------------------------------------
    def run(self, *, frames: int | None = None, screenshot: str | None = None, max_fps: float = 240.0) -> None:
        """Run until quit, or exactly ``frames`` frames (1/60 s each) then save ``screenshot``."""
        if frames is not None:
            for k in range(frames):
                if k == frames - 1 and screenshot:
                    self.request_screenshot(screenshot)
                self.frame(HEADLESS_FRAME_TIME)
                if not self.running:
                    break
            return
        limiter = self.pg.time.Clock()
        while self.running:
            self.frame()
            limiter.tick(max_fps)


#: SDL video drivers that draw nowhere a person sees: fine for ``frames``, never without it.
INVISIBLE_DRIVERS = ("offscreen", "dummy")


def _no_display() -> bool:
    """True on Linux/BSD without X11 or Wayland (and no SDL driver chosen by the user).

    SDL would then quietly fall back to an invisible off-screen window, which is right for
    scripts (``--frames``) and wrong for a person waiting for a window.
    """
    import sys

    if sys.platform in ("win32", "darwin"):
        return False
    return not any(os.environ.get(k) for k in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER"))


def _refuse_invisible_fallback() -> None:
    """RuntimeError if SDL's video driver is one that draws nowhere a person sees.

    The environment can say there is a display and SDL still end up off-screen: ``DISPLAY``
    naming an X server that is not there, or a list such as ``SDL_VIDEODRIVER=x11,offscreen``
    whose first driver fails. SDL then falls back to its ``offscreen`` driver without a word
    and the window ran until it was killed; so the driver SDL actually chose is asked.
    """
    import pygame

    try:
        pygame.display.init()
    except pygame.error:
        return  # opening the window says why, in its own words
    driver = (pygame.display.get_driver() or "").lower()
    if driver in INVISIBLE_DRIVERS:
        pygame.display.quit()
        shown = ", ".join(f"{k}={os.environ[k]}" for k in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER")
                          if os.environ.get(k)) or "no display variables"
        raise RuntimeError(f"no display could be opened ({shown}), only SDL's invisible '{driver}' window, "
                           f"which nobody could see or close; give --frames N (and --screenshot out.png) "
                           f"to run N frames and stop, or use deforma run")


def run(scene: Scene | str | os.PathLike[str] = "demo", *, size: Sequence[float] = (1280, 720),
        frames: int | None = None, screenshot: str | None = None,
        panel: bool = True, wireframe: bool = False, samples: int = 0, paused: bool = False) -> Viewer | None:
    """Open the viewer on ``scene``: until the window is closed, or for ``frames`` frames.

    Parameters
    ----------
    scene : str or path
        Built-in scene name or ``.toml`` file.
    size : (int, int), keyword-only
        Window size in pixels.
    frames : int, keyword-only
        Run this many frames (each 1/60 s of simulated time) without waiting for input, then
        return. Without a display, the window is then made off-screen (SDL's ``offscreen``);
        without ``frames``, an off-screen window (``SDL_VIDEODRIVER=offscreen`` or ``dummy``)
        is refused, since nothing could close it.
    screenshot : str, keyword-only
        With ``frames``: save the last frame to this PNG.
    panel, wireframe, samples, paused : keyword-only
        Start with the panel shown, the springs drawn, this multisampling, paused.

    Raises
    ------
    RuntimeError
        No OpenGL window can be opened, or only an off-screen one without ``frames``;
        ValueError for a bad scene or output path.
    """
    size = check_window_size(size)
    if screenshot is not None:
        out = Path(screenshot)
        if out.suffix.lower() != ".png":
            raise ValueError(f"{screenshot}: a screenshot is written as PNG; give a name ending in .png")
        from ..files import check_folder

        check_folder(screenshot, out.parent)  # exists and writable, before a window opens
    session = Session(scene)  # a bad scene fails before a window opens
    if wireframe:
        session.wireframe = True
    if _no_display():
        if frames is None:
            raise RuntimeError("no display to open a window on (neither DISPLAY nor WAYLAND_DISPLAY is set); "
                               "for scripts use --frames N --screenshot out.png")
        os.environ["SDL_VIDEODRIVER"] = "offscreen"
    driver = os.environ.get("SDL_VIDEODRIVER", "").lower()
    if frames is None and driver in INVISIBLE_DRIVERS:
        # nobody can see or close such a window: it ran until killed
        raise RuntimeError(f"SDL_VIDEODRIVER={driver} opens a window nobody can see or close; "
                           f"give --frames N (and --screenshot out.png) to run N frames and stop")
    if frames is None:
        _refuse_invisible_fallback()
    v = Viewer(session, size=size, panel=panel, vsync=frames is None, samples=samples)
    v.paused = paused
    try:
        v.run(frames=frames, screenshot=screenshot)
    finally:
        v.close()
    if screenshot is not None and str(screenshot) in v.screenshot_errors:
        why = v.screenshot_errors[str(screenshot)].removeprefix(f"{screenshot}: ")  # said once
        raise OSError(f"{screenshot}: cannot save the screenshot: {why}")
    return None


if __name__ == "__main__":  # pragma: no cover
    import sys

    run(sys.argv[1] if len(sys.argv) > 1 else "demo")

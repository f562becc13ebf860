"""Animations inline in Jupyter and VS Code notebooks: :func:`deforma.show`.

``deforma.show("demo", seconds=2)`` simulates a scene headless, draws it with the same
renderer as ``deforma run`` (a scene's camera, colours and textures) and returns an
:class:`Animation`, which a notebook displays as an HTML5 ``<video>`` (H.264 MP4, base64 in
the page) or, without imageio-ffmpeg, as an animated GIF. ``Animation.save`` writes it to a
file.

Needs the ``render`` extra (moderngl, imageio-ffmpeg) and OpenGL 3.3, headless through EGL
where there is no display. ``import deforma`` does not import this module: ``deforma.show``
loads it on first use.
"""

from __future__ import annotations

import base64
import math
import os
import tempfile
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Iterator

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ..physics import World
    from ..scene import Scene

__all__ = ["MAX_EMBED_BYTES", "MAX_FRAMES", "Animation", "show"]

#: An animation larger than this (bytes) is not put into the notebook; ``save`` still writes
#: it. Matplotlib's ``animation.embed_limit`` has the same default: bigger outputs make
#: notebooks slow to open and can exceed the Jupyter server's output rate limit.
MAX_EMBED_BYTES = 20 * 2**20
#: At most this many frames per animation (a minute at 30 frames/s): every frame is drawn and
#: encoded before anything is shown, and a GIF holds all its frames in memory.
MAX_FRAMES = 1800
SIDE_RANGE = (16, 1920)      # pixels, width and height
SECONDS_MAX = 600.0
FPS_MAX = 120.0
DEFAULT_WIDTH = 640
FORMATS = ("mp4", "gif")


class Animation:
    """A rendered animation that displays itself in a notebook.

    Made by :func:`deforma.show`. In Jupyter, JupyterLab and VS Code the last expression of
    a cell is shown through :meth:`_repr_html_`: an HTML5 ``<video>`` for MP4 (looping,
    muted, with controls) or an ``<img>`` for a GIF, both embedded as base64. Viewers that
    show no HTML (a PDF export) get :meth:`_repr_png_`, the last frame.

    Attributes
    ----------
    data : bytes
        The encoded file: an MP4 or a GIF (see ``format``).
    format : str
        ``"mp4"`` or ``"gif"``.
    fps : float
        Frames per second.
    size : (int, int)
        Width and height in pixels.
    n_frames : int
        Number of frames; the video lasts ``n_frames / fps`` seconds.
    last_frame : (H, W, 3) ndarray of uint8
        The final picture.

    Examples
    --------
    >>> import deforma
    >>> anim = deforma.show("sample", seconds=0.5, fps=10, size=64)
    >>> anim.n_frames, anim.duration
    (5, 0.5)
    >>> anim.save("sample.gif").name        # converted from the MP4's frames
    'sample.gif'
    >>> [f.shape for f in anim.frames()][-1]
    (36, 64, 3)
    """

    def __init__(self, data: bytes, *, format: str, fps: float, size: tuple[int, int], n_frames: int,
                 last_frame: ArrayLike) -> None:
        self.data = bytes(data)
        self.format = format
        self.fps = float(fps)
        self.size = (int(size[0]), int(size[1]))
        self.n_frames = int(n_frames)
        self.last_frame = np.asarray(last_frame, dtype=np.uint8)

    @property
    def duration(self) -> float:
        """Length of the video in seconds (``n_frames / fps``)."""
        return self.n_frames / self.fps

    def _repr_html_(self) -> str:
        w, h = self.size
        style = "max-width: 100%; height: auto"
        if len(self.data) > MAX_EMBED_BYTES:
            still = base64.b64encode(self._repr_png_()).decode("ascii")
            return (f'<div><img width="{w}" height="{h}" style="{style}" alt="the last frame" '
                    f'src="data:image/png;base64,{still}"><p>deforma: this animation is '
                    f'{len(self.data) / 2**20:.1f} MB, more than the {MAX_EMBED_BYTES / 2**20:.0f} MB put into a '
                    f'notebook, so only its last frame is shown. <code>.save("out.{self.format}")</code> writes '
                    f'it to a file; fewer seconds, a lower fps or a smaller size make it fit.</p></div>')
        b64 = base64.b64encode(self.data).decode("ascii")
        if self.format == "mp4":
            return (f'<video width="{w}" height="{h}" style="{style}" controls autoplay loop muted playsinline>'
                    f'<source type="video/mp4" src="data:video/mp4;base64,{b64}"></video>')
        return (f'<img width="{w}" height="{h}" style="{style}" alt="deforma animation" '
                f'src="data:image/gif;base64,{b64}">')

    def _repr_png_(self) -> bytes:
        from PIL import Image

        from ..mesh.picture import png_bytes

        return png_bytes(Image.fromarray(self.last_frame))

    def frames(self) -> Iterator[np.ndarray]:
        """The frames decoded again, one (H, W, 3) uint8 array at a time (MP4 is lossy: close,
        not equal, to what was drawn)."""
        w, h = self.size
        with tempfile.TemporaryDirectory(prefix="deforma-show-") as tmp:
            path = Path(tmp) / f"animation.{self.format}"
            path.write_bytes(self.data)
            if self.format == "gif":
                from PIL import Image, ImageSequence

                with Image.open(path) as im:
                    for frame in ImageSequence.Iterator(im):
                        yield np.asarray(frame.convert("RGB"))
                return
            import imageio_ffmpeg

            reader = imageio_ffmpeg.read_frames(str(path))
            meta = next(reader)
            pw, ph = meta["size"]  # the writer pads odd sizes by a pixel
            try:
                for raw in reader:
                    yield np.frombuffer(raw, np.uint8).reshape(ph, pw, 3)[:h, :w]
            finally:
                reader.close()

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the animation to ``path``: ``.mp4``, ``.gif``, or a folder of PNG frames.

        The same format as :attr:`format` is written byte for byte; another is converted from
        the decoded frames. As with ``deforma run``, the file appears complete or not at all.

        Returns
        -------
        Path
            ``path``.

        Raises
        ------
        ValueError
            An unknown suffix or a folder that does not exist.
        """
        from ..files import write_atomic
        from .video import check_output, open_writer

        kind = check_output(path)
        target = Path(path)
        if kind == self.format:
            write_atomic(target, lambda f: f.write(self.data))
            return target
        with open_writer(path, fps=self.fps) as writer:
            for frame in self.frames():
                writer.write(frame)
        return target

    def __repr__(self) -> str:
        w, h = self.size
        return (f"Animation({self.format}, {w}x{h}, {self.n_frames} frames at {self.fps:g} frames/s, "
                f"{len(self.data) / 1024:.0f} kB)")


def _number(value, name: str, hi: float, unit: str) -> float | None:
    if value is None:
        return None
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
    if not ok or not (math.isfinite(value) and 0 < value <= hi):
        raise ValueError(f"{name} must be a number in (0, {hi:g}] {unit}, got {value!r}")
    return float(value)


def _side(value: object) -> bool | np.bool_:
    return (isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
            and SIDE_RANGE[0] <= value <= SIDE_RANGE[1])


def _check_size(size):
    """None, a width, or (width, height), each checked; returns (width or None, height or None)."""
    if size is None:
        return None, None
    if _side(size):
        return int(size), None
    if isinstance(size, (tuple, list)) and len(size) == 2 and all(_side(v) for v in size):
        return int(size[0]), int(size[1])
    lo, hi = SIDE_RANGE
    raise ValueError(f"size must be a width in pixels or (width, height), each a whole number in [{lo}, {hi}], "
                     f"got {size!r}")


def _check_format(format) -> str:
    if format is None:
        try:
            import imageio_ffmpeg  # noqa: F401
        except ImportError:
            return "gif"
        return "mp4"
    if format not in FORMATS:
        raise ValueError(f"format must be one of {', '.join(map(repr, FORMATS))} or None, got {format!r}")
    return format


def _world_and_scene(scene_or_world):
    """(world, scene): a world built from a scene name, a path or a Scene, or the world given."""
    from .. import scene as scenes
    from ..physics import World

    if isinstance(scene_or_world, World):
        return scene_or_world, scenes.scene_of(scene_or_world)
    if isinstance(scene_or_world, scenes.Scene):
        return scene_or_world.build(), scene_or_world
    if isinstance(scene_or_world, (str, os.PathLike)):
        scene = scenes.load(scene_or_world)  # SceneError: a one-line ValueError
        return scene.build(), scene
    raise TypeError(f"show needs a built-in scene name, a path to a .toml scene, a Scene or a World, "
                    f"got {type(scene_or_world).__name__}")


def _camera(world, scene):
    """The scene's camera, or, for a world made in code (no camera chosen), one that frames it."""
    from ..mesh.picture import content_bounds
    from ..scene import CameraSettings

    cam = scene.camera
    if scene.path is not None or cam != CameraSettings():
        return cam
    lo, hi = content_bounds(world)
    span = np.maximum(hi - lo, 1e-3 * max(1.0, float(np.abs(np.r_[lo, hi]).max())))
    return replace(cam, center=tuple(((lo + hi) / 2).tolist()), size=tuple((1.1 * span).tolist()))


def _picture_size(width, height, camera) -> tuple[int, int]:
    """The requested size; a missing side follows the camera's aspect ratio (even, for H.264)."""
    if width is not None and height is not None:
        return width, height
    lo, hi = SIDE_RANGE
    aspect = camera.size[1] / camera.size[0]
    width = DEFAULT_WIDTH if width is None else width
    height = int(min(hi, max(lo, 2 * round(width * aspect / 2))))
    return width, height


def show(scene_or_world: str | os.PathLike[str] | Scene | World, *, seconds: float | None = None,
         fps: float | None = None, size: int | tuple[int, int] | None = None, format: str | None = None,
         overlay: bool = False) -> Animation:
    """Simulate a scene or a world and return an animation that plays inline in a notebook.

    Parameters
    ----------
    scene_or_world : str, path, Scene or World
        A built-in scene name (``deforma scenes`` lists them), a ``.toml`` scene file, a
        :class:`deforma.scene.Scene`, or a :class:`deforma.World`. A scene is built afresh on
        every call. A World is shown from its current state, and is left as it was: the
        animation steps a copy (``copy.deepcopy(world)``), which moves exactly as the world
        itself would, so showing it twice shows the same thing, and ``world.step()`` afterwards
        goes on from where the world was, not from the animation's end.
    seconds : float, optional
        Simulated time in seconds, in (0, 600]. Default: the scene's ``run.seconds`` (5 s for
        a world made in code).
    fps : float, optional
        Frames per second, in (0, 120]. Default: the scene's ``run.fps`` (30).
    size : int or (int, int), optional
        Picture width, or (width, height), in pixels, each in [16, 1920]. Default: 640 wide,
        the height following the camera's aspect ratio.
    format : {"mp4", "gif"}, optional
        ``"mp4"`` (H.264, small, an HTML5 video) when imageio-ffmpeg is installed, else
        ``"gif"`` (larger, but an image any viewer animates).
    overlay : bool, optional
        Write the simulated time (``t = 1.25 s``, top left) and a scale bar (bottom left) on
        every frame, as ``deforma run --overlay`` does. Default off.

    Returns
    -------
    Animation
        Displays inline (``_repr_html_``); ``.save("out.mp4")`` writes it.

    Raises
    ------
    ValueError
        An unknown scene or an invalid file (one line naming it), a value out of range, or
        more than :data:`MAX_FRAMES` frames (``seconds * fps``).
    TypeError
        ``scene_or_world`` is none of the above.
    deforma.SimulationUnstable
        The simulation ran away; nothing is returned.
    RuntimeError
        No OpenGL 3.3 context could be made.

    Notes
    -----
    What is embedded is capped: at most 1800 frames, and an animation over 20 MB
    (:data:`MAX_EMBED_BYTES`) shows only its last frame with a note (``save`` still writes
    all of it). At the default 640 px, H.264 takes 10-200 kB per second of video (more
    the more moves), a GIF about ten times that.

    The picture is what ``deforma run`` draws: a scene's camera, background, colours and
    textures. A world made in code gets a camera that frames its bodies and colliders as
    they are at the start.

    Examples
    --------
    >>> import deforma
    >>> anim = deforma.show("sample", seconds=0.5, size=160)
    >>> anim.size, anim.n_frames
    ((160, 90), 15)
    >>> anim._repr_html_().startswith(("<video", "<img"))
    True
    """
    from ..scene.playback import Playback, frame_count

    seconds = _number(seconds, "seconds", SECONDS_MAX, "s")
    fps = _number(fps, "fps", FPS_MAX, "frames/s")
    width, height = _check_size(size)
    format = _check_format(format)
    if not isinstance(overlay, (bool, np.bool_)):  # overlay="no" is truthy: refuse it rather than draw it
        raise ValueError(f"overlay must be True or False, got {overlay!r}")
    world, scene = _world_and_scene(scene_or_world)
    seconds = seconds if seconds is not None else scene.run.seconds
    fps = fps if fps is not None else scene.run.fps
    n_frames = frame_count(seconds, fps)
    if n_frames > MAX_FRAMES:
        raise ValueError(f"seconds * fps = {seconds:g} s * {fps:g} frames/s gives {n_frames} frames; at most "
                         f"{MAX_FRAMES} are put into a notebook: pass fewer seconds or a lower fps")
    camera = _camera(world, scene)
    picture = _picture_size(width, height, camera)

    from .recorder import FrameRecorder
    from .renderer import Renderer
    from .video import open_writer
    from .world_view import WorldView

    # the caller's world stays as it was: the animation runs a copy (built scenes are ours to step)
    looks = world
    if world is scene_or_world:
        import copy

        world = copy.deepcopy(world)
    renderer = Renderer.headless(picture, samples=4)
    try:
        view = WorldView(renderer, world, replace(scene, camera=camera), overlay=bool(overlay), looks_from=looks)
        with tempfile.TemporaryDirectory(prefix="deforma-show-") as tmp:
            path = Path(tmp) / f"animation.{format}"
            with open_writer(path, fps=fps) as writer:
                # the scene's explosions and pulls that are still ahead of the world's clock; each
                # frame drawn while the next is simulated (render/recorder.py)
                recorder = FrameRecorder(view, writer)
                for _ in Playback(scene, world, fps=fps).frames(n_frames):
                    recorder.add()
                recorder.finish()
            data = path.read_bytes()
    finally:
        renderer.release()
    return Animation(data, format=format, fps=fps, size=picture, n_frames=n_frames,
                     last_frame=recorder.last_frame)  # type: ignore[arg-type]  # n_frames >= 1 were drawn

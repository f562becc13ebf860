"""The ``deforma`` command: run scenes headless into videos, draw meshes, list what is built in.

``deforma run demo -o demo.mp4``    simulate the demo scene and write a video
``deforma mesh bunny -o mesh.png``  a picture of a triangulation with its figures
``deforma scenes``                  the built-in scenes and textures
``deforma view demo``               a window: watch, pull, blow up and edit a scene live
``deforma sweep S.toml -o OUT``     many runs of a scene with varied parameters, on Ray (docs/sweeps.md)

User mistakes (unknown scene, invalid file, output folder missing, unstable simulation) give
one line on stderr and a non-zero exit code; ``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from . import __version__
from .checks import StepBeyondStableWarning, check_box_points

__all__ = ["main"]

#: Exit codes: 1 a user error (scene, output, options), 3 the simulation became unstable,
#: 4 rendering unavailable (no OpenGL), 130 interrupted (Ctrl-C); SIGTERM and SIGHUP give
#: 128 + the signal's number (143, 129), as a shell reports a process they ended.
EXIT_ERROR, EXIT_UNSTABLE, EXIT_NO_GL, EXIT_INTERRUPTED = 1, 3, 4, 130


class Stopped(BaseException):
    """SIGTERM or SIGHUP arrived: unwinds like Ctrl-C, so every writer discards its temporary file."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


#: The signal whose :class:`Stopped` the handler raised, until the handlers are restored
#: (see :func:`_raise_if_stopped`).
_stopping: list[int] = []


def _raise_if_stopped() -> None:
    """Raise :class:`Stopped` again for a signal whose handler ran but whose exception Python
    dropped. A handler that runs inside a fork hook (ffmpeg's process being started) or a
    finaliser has its exception printed as "Exception ignored" and the command goes on: a run
    sent SIGHUP just then wrote its whole video and exited 0. The frame loop calls this once
    a frame."""
    if _stopping:
        raise Stopped(_stopping[0])


def _stop_on_signals():
    """Make SIGTERM and SIGHUP raise :class:`Stopped`; returns a function that restores the old handlers."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return lambda: None  # only the main thread may set handlers (tests may call main() elsewhere)
    signums = [getattr(signal, n) for n in ("SIGTERM", "SIGHUP") if hasattr(signal, n)]

    def handler(signum, frame):
        for n in signums:  # a second signal must not cut through the clean-up
            signal.signal(n, signal.SIG_IGN)
        _stopping.append(signum)
        raise Stopped(signum)

    previous = {n: signal.signal(n, handler) for n in signums}

    def restore():
        _stopping.clear()
        for n, h in previous.items():
            signal.signal(n, h)
    return restore


class CliError(Exception):
    """A one-line message for the user, with an exit code."""

    def __init__(self, message: str, code: int = EXIT_ERROR):
        super().__init__(message)
        self.code = code


# -- argument types -------------------------------------------------------------------------------
def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels like 1280x720, got {text!r}") from None
    if not (16 <= w <= 7680 and 16 <= h <= 4320):
        raise argparse.ArgumentTypeError(f"width must be in [16, 7680] and height in [16, 4320] pixels, got {text!r}")
    return w, h


def _window_size(text: str) -> tuple[int, int]:
    """``view --size``: a size as for ``run``, and at least the viewer's smallest layout."""
    w, h = _size(text)
    try:
        from .viewer.app import check_window_size
    except ImportError:  # pragma: no cover - no viewer packages: cmd_view says so
        return w, h
    try:
        return check_window_size((w, h))
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def _positive(kind, *, hi=None):
    def parse(text):
        try:
            v = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a {'number' if kind is float else 'whole number'}, "
                                             f"got {text!r}") from None
        if not (v > 0 and math.isfinite(v)) or (hi is not None and v > hi):
            limit = f" and <= {hi:g}" if hi is not None else ""
            raise argparse.ArgumentTypeError(f"must be > 0{limit}, got {text!r}")
        return v
    return parse


def _count(hi=None):
    """An argparse type: a whole number in [0, hi] (>= 0 without ``hi``)."""
    def parse(text):
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if v < 0 or (hi is not None and v > hi):
            raise argparse.ArgumentTypeError(f"must be >= 0{'' if hi is None else f' and <= {hi}'}, got {text!r}")
        return v
    return parse


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="deforma", description="Deformable 2D objects: run scenes, draw meshes.")
    p.add_argument("--debug", action="store_true", help="show the full traceback on errors")
    p.add_argument("--version", action="version", version=f"deforma {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", required=True)

    r = sub.add_parser("run", help="simulate a scene headless; write a video, PNG frames and/or states",
                       description="Simulate a scene headless and write a video (MP4 or GIF), PNG frames "
                                   "and/or the states (positions per frame, mesh, parameters) as .npz.")
    r.add_argument("scene", metavar="SCENE", help="built-in scene name (see `deforma scenes`) or a .toml file")
    r.add_argument("--seconds", type=_positive(float, hi=3600), help="simulated time (default: the scene's run.seconds)")
    r.add_argument("--fps", type=_positive(float, hi=240), help="frames per second (default: the scene's run.fps)")
    r.add_argument("--size", type=_size, default=(1280, 720), metavar="WxH", help="picture size (default 1280x720)")
    r.add_argument("-o", "--output", metavar="OUT", help="out.mp4, out.gif, or a folder/ for PNG frames")
    r.add_argument("--states", metavar="OUT.npz", help="save positions per frame, meshes and parameters")
    r.add_argument("--export", metavar="DIR", help="write every body's deformed mesh per frame into the new folder DIR")
    r.add_argument("--format", choices=("obj", "json", "svg"), help="--export's format (default obj: with uv and "
                   "a material library naming each body's picture)")
    r.add_argument("--wireframe", action="store_true", help="draw the springs over the bodies")
    r.add_argument("--overlay", action="store_true",
                   help="write the simulated time (top left) and a scale bar (bottom left) on every frame")
    r.add_argument("--samples", type=int, default=4, choices=(0, 4), help="multisampling for smooth edges (default 4)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.add_argument("--springs", action="store_true",
                   help="make every body of the original's springs instead of its material (finite elements)")

    m = sub.add_parser("mesh", help="a picture of a triangulation with its figures (points, triangles, min angle)",
                       description="Triangulate a built-in texture, an image file or a box (SOURCE = box) and "
                                   "draw the triangles over the picture, like the original's figures 2-4.")
    m.add_argument("source", metavar="SOURCE", help="bunny, donut, armadillo, an image path, or box")
    m.add_argument("--resolution", type=_positive(int), default=4, help="image: sample every n-th pixel (default 4)")
    m.add_argument("--detect-edges", action=argparse.BooleanOptionalAction, default=True,
                   help="image: add points along the outline (default on)")
    m.add_argument("--edge-step", type=_positive(int), default=2, help="image: every n-th outline pixel (default 2)")
    m.add_argument("--background", default="black", metavar="COLOUR",
                   help="image without transparency: what the shape is on, black (default), white, auto (the "
                        "border's colour) or '#rrggbb' (quote it: # starts a shell comment)")
    m.add_argument("--threshold", type=float, metavar="T",
                   help="image: how far from the background a pixel must be to be the shape, 0 <= T < 1 of full "
                        "scale in the channel that differs most (default 0.06; for alpha 0.5)")
    # its upper bound is the box's point count, refused in one line by cmd_mesh (checks.MAX_BODY_POINTS)
    m.add_argument("--detail", type=_count(), default=8,
                   help="box: n*n interior points (default 8; at most 100,000 points: 314 with edges)")
    m.add_argument("--edges", action=argparse.BooleanOptionalAction, default=True,
                   help="box: points on the sides too (default on, as in mesh.box and scene files; "
                        "--no-edges gives the original's thin side triangles)")
    m.add_argument("--width", type=_positive(int, hi=8000), default=800, help="picture width in pixels (default 800)")
    m.add_argument("-o", "--output", required=True, metavar="OUT.png", help="the picture to write")

    sub.add_parser("scenes", help="list the built-in scenes and textures")
    sub.add_parser("warmup", help="compile every built-in scene's kernels now (a first run does it in the background)",
                   description="Compile the physics kernels of every built-in scene, as the first run that "
                               "compiles does in a second process: for an image or a CI cache built ahead.")

    v = sub.add_parser("view", help="open a window: watch, pull, blow up and edit a scene live",
                       description="The interactive viewer: a window with the inspector panel, mouse pull (left "
                                   "drag), explosion (space); H in the window lists every key. With --frames it "
                                   "runs that many 1/60 s frames without waiting for input (off-screen when "
                                   "there is no display) and can save the last one.")
    v.add_argument("scene", metavar="SCENE", nargs="?", default="demo",
                   help="built-in scene name or a .toml file (default: demo)")
    v.add_argument("--size", type=_window_size, default=(1280, 720), metavar="WxH",
                   help="window size (default 1280x720, at least 640x272)")
    v.add_argument("--frames", type=_positive(int), metavar="N", help="run N frames, then close")
    v.add_argument("--screenshot", metavar="OUT.png", help="with --frames: save the last frame")
    v.add_argument("--no-panel", action="store_true", help="start with the inspector hidden (Tab shows it)")
    v.add_argument("--wireframe", action="store_true", help="draw the springs over the bodies")
    v.add_argument("--samples", type=int, default=0, choices=(0, 2, 4, 8), help="window multisampling (default 0)")
    v.add_argument("--paused", action="store_true", help="start paused")
    v.add_argument("--springs", action="store_true",
                   help="make every body of the original's springs instead of its material (finite elements)")

    w = sub.add_parser("sweep", help="many runs of one scene with varied parameters, on a Ray cluster",
                       description="Run every run of a sweep file (TOML: scene, seconds, mode, [parameters]; see "
                                   "docs/sweeps.md) on Ray and add one row per run to OUTDIR/results.parquet. "
                                   "Runs already in the table are skipped. Needs the sweep extra: "
                                   "pip install 'deforma[sweep]'.")
    w.add_argument("spec", metavar="SPEC.toml", help="the sweep file")
    w.add_argument("-o", "--output", required=True, metavar="OUTDIR",
                   help="folder for results.parquet, states/ and videos/")
    w.add_argument("--workers", type=_positive(int, hi=4096), metavar="N",
                   help="CPUs of the local Ray cluster (default: every core); ignored with --address")
    w.add_argument("--address", metavar="ADDR", help="a running Ray cluster: HOST:PORT (from `ray start --head`), "
                                                     "ray://HOST:PORT or auto")
    w.add_argument("--states", action="store_true", help="also write each ok run's states to OUTDIR/states/ID.npz")
    w.add_argument("--video", nargs="?", const="mp4", choices=("mp4", "gif"), metavar="FORMAT",
                   help="also draw each run and write each ok run's video to OUTDIR/videos/ID.mp4 (or gif with "
                        "--video gif); a worker without OpenGL makes that run an error")
    w.add_argument("--video-size", type=_size, default=(640, 360), metavar="WxH",
                   help="size of the videos in pixels (default 640x360)")
    w.add_argument("--retry-failed", action="store_true", help="run again the runs that were unstable or failed")
    w.add_argument("--force", action="store_true", help="add rows to a table that holds a different sweep's runs")
    w.add_argument("--quiet", action="store_true", help="no progress bar")
    return p


# -- run ----------------------------------------------------------------------------------------------
def _check_states_path(path: str) -> None:
    p = Path(path)
    if p.suffix.lower() != ".npz":
        raise CliError(f"{path}: states are written as .npz; give a name ending in .npz")
    if p.is_dir():  # said now, not after the whole simulation
        raise CliError(f"{path}: is a folder; give the states file's name, ending in .npz")
    _check_folder(path)


def _check_folder(path) -> None:
    """The folder ``path`` goes into exists and is writable, checked before any work."""
    from .files import check_folder

    try:
        check_folder(path, Path(path).parent)
    except ValueError as e:
        raise CliError(str(e)) from None


def _progress(total: int, enabled: bool, label: str, unit: str = "frame"):
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency; degrade to no bar
        return None
    # disable=None: tqdm draws only on a terminal, never into logs or pipes
    return tqdm(total=total, unit=unit, desc=label, disable=None if enabled else True, leave=False,
                dynamic_ncols=True)


def _check_export_path(path: str) -> None:
    """``--export DIR``: a new folder, or an empty one, in a folder that exists and is writable."""
    from .files import check_folder

    target = Path(path)
    if target.exists() and not (target.is_dir() and not any(target.iterdir())):
        what = "a file" if not target.is_dir() else "a folder that is not empty"
        raise CliError(f"{path}: --export writes a new folder, and this is {what}: give a new or empty folder")
    try:
        check_folder(path, target.resolve().parent)
    except ValueError as e:
        raise CliError(str(e)) from None


class _MeshExport:
    """``--export DIR``: each frame's meshes written into a hidden temporary folder beside DIR,
    which becomes DIR when the run ends well (:meth:`publish`) and is removed otherwise."""

    def __init__(self, path: str, fmt: str, scene):
        from .files import temp_folder_in

        self.target = Path(path)
        self.fmt = fmt
        self.colors = [getattr(b, "color", None) for b in scene.body]
        self.tmp = None
        try:
            self.tmp = temp_folder_in(self.target.resolve().parent)
        except OSError as e:
            raise self._failed(e) from None
        self.materials = None
        self._first = True

    def write(self, world, frame: int) -> None:
        from .mesh.export import write_materials, write_meshes

        bodies = [b for b in world.bodies if len(b.triangles)]
        meshes = [b.to_mesh() for b in bodies]
        names = [f"body{b.index}" for b in bodies]
        colors = [self.colors[b.index] if b.index < len(self.colors) else None for b in bodies]
        try:
            if self._first and self.fmt == "obj":  # the pictures do not change: once
                self.materials = write_materials(meshes, self.tmp, names=names)
            self._first = False
            write_meshes(meshes, self.tmp / f"frame_{frame:05d}.{self.fmt}", names=names, colors=colors,
                         materials=self.materials, frame=frame, time=world.time)
        except OSError as e:
            # a full disk said only "[Errno 28] No space left on device": name the folder the
            # user gave (the frames go to a hidden temporary one beside it, removed by abort())
            raise self._failed(e) from None

    def _failed(self, error: OSError) -> OSError:
        from .files import failed_write

        return failed_write(f"--export {self.target}", error)

    def publish(self) -> None:
        try:
            if self.target.is_dir():  # an empty folder (checked before the run): replaced
                self.target.rmdir()
            os.replace(self.tmp, self.target)
        except OSError as e:
            raise self._failed(e) from None
        self.tmp = None

    def abort(self) -> None:
        if self.tmp is not None:
            shutil.rmtree(self.tmp, ignore_errors=True)
            self.tmp = None


def _check_distinct_outputs(a) -> None:
    """Refuse two of ``-o``, ``--states`` and ``--export`` naming one path: the second to be
    put in place failed on the first (``--export o.mp4 -o o.mp4`` left a folder o.mp4 behind,
    ``--export s.npz --states s.npz`` the states and a hidden temporary folder's name). Refuse
    ``-o`` or ``--states`` inside the ``--export`` folder too: that folder is put in place
    whole at the end and must then be empty (``--export d --states d/s.npz`` wrote the states,
    then failed after the whole run on "Directory not empty")."""
    given = [(flag, Path(p)) for flag, p in (("-o", a.output), ("--states", a.states), ("--export", a.export)) if p]
    for i, (flag, path) in enumerate(given):
        for other, path2 in given[i + 1:]:
            if path.resolve() == path2.resolve():
                raise CliError(f"{flag} and {other} both name {path}: give each output a path of its own")
    if a.export:
        folder = Path(a.export).resolve()
        for flag, path in (("-o", a.output), ("--states", a.states)):
            if path and folder in Path(path).resolve().parents:
                raise CliError(f"{flag} {path} is inside --export {a.export}, a folder put in place whole when the run "
                               f"ends: give {flag} a path outside it")


def cmd_run(a) -> int:
    from .startup import COMPILE_MESSAGE, CompileWatch, warn

    shown = {}  # the progress bar once drawn: the message must not cut through it

    def say_compiling():
        # even with --quiet: a silent 20 s on the first run looks like a hang (issue 18)
        bar = shown.get("bar")
        if bar is not None and not bar.disable:
            bar.write(COMPILE_MESSAGE, file=sys.stderr)
        else:
            warn(COMPILE_MESSAGE)

    background = []

    def first_compile():
        say_compiling()
        # the other scenes' kernels in a second process, on the core the compiler leaves idle
        from .scene.assets import builtin_scenes
        from .warmup import start_background

        job = start_background(a.scene if a.scene in builtin_scenes() else None)
        if job is not None:
            background.append(job)

    done = False
    try:
        with CompileWatch(on_first=first_compile) as watch:
            code = _run_scene(a, watch, shown)
        done = True
        return code
    finally:
        for job in background:
            # a run that ended well waits for the warm-up; one stopped by an error, Ctrl-C or
            # a signal does not keep the user waiting for it (the next run starts it again)
            if done:
                job.wait(warn)
            else:
                job.stop()


def _run_scene(a, watch, shown: dict) -> int:
    """``deforma run``'s work; ``watch`` counts Numba compiling, ``shown["bar"]`` is the bar."""
    from dataclasses import replace

    from . import scene as scenes
    from .physics import SimulationUnstable
    from .physics.diagnostics import StepTooLong
    from .scene.playback import Playback, frame_count

    scene = scenes.load(a.scene)  # SceneError is a one-line ValueError
    if a.springs:
        scene = scenes.with_springs(scene)
    seconds = a.seconds if a.seconds is not None else scene.run.seconds
    fps = a.fps if a.fps is not None else scene.run.fps
    scene = replace(scene, run=replace(scene.run, seconds=float(seconds), fps=float(fps)))
    # check every output before any work, so a typo does not cost a whole simulation
    _check_distinct_outputs(a)
    if a.output:
        from .render.video import check_output

        check_output(a.output)
    if a.states:
        _check_states_path(a.states)
    if a.format and not a.export:
        raise CliError("--format says how --export writes the meshes: give --export DIR too")
    if a.export:
        _check_export_path(a.export)
    n_frames = frame_count(seconds, fps)
    if a.output:
        from .render.video import check_run_memory

        # from the size, writer and frame count alone, before the scene is built: an 8k MP4
        # peaked at 4.5 GB (ffmpeg's encoder 3.2 of it), a 30 s 1080p GIF kept 900 frames
        check_run_memory(a.output, a.size, samples=a.samples, frames=n_frames, fps=fps)
    world = scene.build()
    from .physics.diagnostics import xpbd_advice

    advice = xpbd_advice(world)
    if advice:
        print(f"note: {advice} (docs/integrators.md)", file=sys.stderr)

    view = writer = recorder = None
    if a.output:
        from .render import Renderer, WorldView, open_writer
        from .render.recorder import FrameRecorder

        try:
            renderer = Renderer.headless(a.size, samples=a.samples)
        except RuntimeError as e:
            raise CliError(str(e), EXIT_NO_GL) from None
        view = WorldView(renderer, world, overlay=a.overlay)
        if a.wireframe:
            view.wireframe = True

    label = Path(a.scene).stem if a.scene.endswith(".toml") else a.scene
    # tqdm draws only on a terminal; elsewhere (a pipe, a log, --quiet) it is not even imported:
    # its import is 65 ms of the start-up to the first frame (issue 18)
    on_terminal = not a.quiet and bool(getattr(sys.stderr, "isatty", lambda: False)())
    bar = shown["bar"] = _progress(n_frames, True, label) if on_terminal else None
    t_wall = time.perf_counter()
    compile_before = watch.seconds
    export = None
    try:
        if a.output:
            # inside the try: from here on an interrupt removes the temporary file
            writer = open_writer(a.output, fps=fps)
            # frames drawn while the next ones are simulated, encoded in the writer's thread
            recorder = FrameRecorder(view, writer)
        if a.export:
            export = _MeshExport(a.export, a.format or "obj", scene)
        # the scene's [[event]] explosions and [[pull]] grabs, frame by frame
        playback = Playback(scene, world, fps=fps, record=bool(a.states))
        for k in playback.frames(n_frames):
            _raise_if_stopped()
            if recorder is not None:
                recorder.add()
            if export is not None:
                export.write(world, k)
            if bar is not None:
                bar.update(1)
        # every output complete before any is put in place: a disk too full for the states
        # (or a video that could not be finished) keeps the earlier files as they were
        if writer is not None:
            recorder.finish()
            writer.finish()
        if a.states:
            playback.recording.save(a.states)
        if export is not None:
            export.publish()
        if writer is not None:
            writer.close()
    except SimulationUnstable as e:
        # one error type for "this world cannot step at this dt": refused before the step
        # (StepTooLong: "auto" substeps past the limit) or blown up in it; both exit 3
        what = "cannot step" if isinstance(e, StepTooLong) else "simulation became unstable"
        raise CliError(f"{a.scene}: {what} at t = {world.time:.3f} s: {e}; "
                       f"nothing was written", EXIT_UNSTABLE) from None
    finally:
        if bar is not None:
            bar.close()
        if writer is not None:
            writer.abort()  # no-op after close(); discards the temporary file otherwise
        if export is not None:
            export.abort()  # no-op after publish(); removes the temporary folder otherwise
        if view is not None:
            view.renderer.release()
    # honest figures: the whole command's wall time, start-up and compiling included, and the
    # real-time factor of the frames alone (a first run's compiling is not the simulation's speed)
    total = time.perf_counter() - a.started
    frames_wall = time.perf_counter() - t_wall - (watch.seconds - compile_before)
    compiling = watch.seconds if watch.compiled else 0.0  # else a helper without cache: start-up
    startup = max(0.0, total - frames_wall - compiling)
    outputs = [o for o in (a.output, a.states, a.export) if o]
    sim = world.time
    print(f"{label}: {n_frames} frames, {sim:.2f} s simulated in {total:.2f} s wall ("
          + (f"{compiling:.2f} s compiling kernels, first run only; " if watch.compiled else "")
          + f"{startup:.2f} s start-up; frames {frames_wall:.2f} s, "
          f"{sim / frames_wall if frames_wall > 0 else float('inf'):.2f}x real time)"
          + (f" -> {', '.join(outputs)}" if outputs else
             f"; nothing written: add -o {label}.mp4 (or .gif, or a folder/ for PNGs) for a video, "
             f"--states {label}.npz for the positions"))
    return 0


# -- mesh ---------------------------------------------------------------------------------------------
#: Largest picture ``deforma mesh`` draws: its height, like ``--width``, at most this many pixels.
MESH_PICTURE_MAX_SIDE = 8000
#: Largest drawing canvas (before the shrink that smooths the lines), in pixels: above it the
#: picture is drawn at its final size, so memory stays near 1 GB whatever the options.
MESH_CANVAS_MAX_PIXELS = 64_000_000


def _mesh_picture_size(mesh, width: int) -> tuple[int, int]:
    """The picture's (width, height) without the caption, from the mesh's aspect ratio.

    A mesh much taller than wide would ask for a picture of millions of pixels in height; the
    width is then narrowed so the height stays within :data:`MESH_PICTURE_MAX_SIDE`.
    """
    v = mesh.vertices
    span = np.maximum(v.max(axis=0) - v.min(axis=0), 1e-12)
    aspect = float(span[1] / span[0])
    margin = 0.06
    height = lambda w: w * (1 - 2 * margin) * aspect + 2 * margin * w  # noqa: E731
    if height(width) > MESH_PICTURE_MAX_SIDE:
        width = int(MESH_PICTURE_MAX_SIDE / height(1.0))
        if width < 16:
            raise CliError(f"the mesh is {aspect:.3g} times taller than wide: its picture would be over "
                           f"{MESH_PICTURE_MAX_SIDE} px high even 16 px wide; at most {MESH_PICTURE_MAX_SIDE} px "
                           f"per side")
    return width, max(1, int(round(height(width))))


def _mesh_picture(mesh, picture, width: int, caption: str):
    """Triangles over the picture (or a plain background for a box), with a caption bar.

    Every size here follows from ``width`` (at most 8000) and the mesh's aspect ratio (see
    :func:`_mesh_picture_size`), never from the source picture: only the part of the picture
    under the mesh's frame is scaled, so a 3-pixel shape on a large picture does not blow the
    picture up to tens of thousands of pixels (issue 17).
    """
    from PIL import Image, ImageDraw, ImageFont

    width, _ = _mesh_picture_size(mesh, width)
    ss = 2  # draw at twice the size and shrink: smooth lines without an antialiasing library
    v = mesh.vertices
    lo, hi = v.min(axis=0), v.max(axis=0)
    span = np.maximum(hi - lo, 1e-12)
    margin = 0.06
    aspect = span[1] / span[0]
    if (width * ss) * (width * ss) * max(aspect, 1.0) > MESH_CANVAS_MAX_PIXELS:
        ss = 1
    W = width * ss
    inner_w = W * (1 - 2 * margin)
    inner_h = inner_w * aspect
    H = int(round(inner_h + 2 * margin * W))
    pad = margin * W
    scale = inner_w / span[0]

    def to_px(p):
        return np.c_[pad + (p[:, 0] - lo[0]) * scale, pad + (hi[1] - p[:, 1]) * scale]

    img = Image.new("RGB", (W, H), (246, 244, 239))
    if picture is not None:
        # place the picture so that its uv square maps where the vertices' uv say
        uv = mesh.uv
        A = np.c_[uv, np.ones(len(uv))]
        coef, *_ = np.linalg.lstsq(A, v, rcond=None)  # v ~ uv @ coef[:2] + coef[2]
        corners = np.array([[0, 1, 1], [1, 1, 1]]) @ coef  # uv (0,1) top-left, (1,1) top-right
        origin = np.array([0, 0, 1]) @ coef
        tl, tr, bl = to_px(corners[:1]), to_px(corners[1:]), to_px(origin[None])
        x0, y0 = float(tl[0, 0]), float(tl[0, 1])
        pw, ph = float(tr[0, 0]) - x0, float(bl[0, 1]) - y0
        # only the part of the picture inside the canvas is resized, to the canvas's pixels
        cx0, cy0 = max(0, int(np.floor(x0))), max(0, int(np.floor(y0)))
        cx1, cy1 = min(W, int(np.ceil(x0 + pw))), min(H, int(np.ceil(y0 + ph)))
        if pw > 0 and ph > 0 and cx1 > cx0 and cy1 > cy0:
            src = Image.fromarray(picture).convert("RGBA")
            sx, sy = src.width / pw, src.height / ph
            box = (max(0.0, (cx0 - x0) * sx), max(0.0, (cy0 - y0) * sy),  # within the picture: Pillow
                   min(src.width, (cx1 - x0) * sx), min(src.height, (cy1 - y0) * sy))  # wants that
            pic = src.resize((cx1 - cx0, cy1 - cy0), Image.LANCZOS, box=box)
            faded = Image.new("RGBA", pic.size, (246, 244, 239, 255))
            faded.alpha_composite(pic)
            img.paste(faded.convert("RGB"), (cx0, cy0))
    draw = ImageDraw.Draw(img)
    px = to_px(v)
    line = (31, 58, 104)
    for i, j in mesh.edges:
        draw.line([tuple(px[i]), tuple(px[j])], fill=line, width=ss)
    r = 2.2 * ss
    for x, y in px:
        draw.ellipse([x - r, y - r, x + r, y + r], fill=(214, 69, 65))
    img = img.resize((width, int(round(H / ss))), Image.LANCZOS)
    bar_h = 34
    out = Image.new("RGB", (img.width, img.height + bar_h), (255, 255, 255))
    out.paste(img, (0, 0))
    d = ImageDraw.Draw(out)
    try:
        font = ImageFont.load_default(size=16)
    except TypeError:  # Pillow < 10.1
        font = ImageFont.load_default()
    d.text((12, img.height + 8), caption, fill=(30, 30, 30), font=font)
    return out


def cmd_mesh(a) -> int:
    from . import mesh as meshes
    from .scene.assets import builtin_textures, load_texture, resolve_texture

    out = Path(a.output)
    if out.suffix.lower() != ".png":
        raise CliError(f"{a.output}: the picture is written as PNG; give a name ending in .png")
    _check_folder(a.output)
    t0 = time.perf_counter()
    if a.source == "box":
        check_box_points(a.detail, a.edges, "--detail")  # named as typed, before anything is built
        m = meshes.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=a.detail, edges=a.edges)
        picture = None
        what = f"box, detail {a.detail}{', edges' if a.edges else ''}"
    else:
        ref = resolve_texture(a.source, base_dir=Path.cwd())
        # a bad background or threshold is a ValueError: main() makes it one line, exit 1
        m = meshes.from_image(ref, resolution=a.resolution, detect_edges=a.detect_edges, edge_step=a.edge_step,
                              background=a.background, threshold=a.threshold)
        picture = m.texture if getattr(m, "texture", None) is not None else load_texture(ref)
        name = a.source if a.source in builtin_textures() else Path(a.source).name
        what = (f"{name}, resolution {a.resolution}"
                + (f", edges every {a.edge_step} px" if a.detect_edges else ", no edge detection")
                + ("" if a.background == "black" else f", background {a.background}"))
    seconds = time.perf_counter() - t0
    min_angle = float(m.min_angle) if hasattr(m, "min_angle") else float("nan")
    caption = (f"{what}: {len(m.vertices)} points, {len(m.triangles)} triangles, "
               f"min angle {min_angle:.1f}\N{DEGREE SIGN}")
    img = _mesh_picture(m, picture, a.width, caption)
    from .files import write_atomic

    write_atomic(out, lambda f: img.save(f, format="PNG"))
    print(f"{caption} (meshed in {seconds:.2f} s) -> {a.output}")
    return 0


# -- scenes -------------------------------------------------------------------------------------------
def cmd_scenes(a) -> int:
    from . import scene as scenes

    print("built-in scenes (deforma run NAME):")
    names = scenes.builtin_scenes()
    width = max((len(n) for n in names), default=0)
    for name in names:
        try:
            desc = scenes.load(name).scene.description
        except ValueError as e:  # a broken built-in must not hide the others
            desc = f"(cannot load: {e})"
        print(f"  {name:<{width}}  {desc}")
    print("built-in textures (texture = or source = in a scene, deforma mesh NAME):")
    print("  " + (", ".join(scenes.builtin_textures()) or "(none installed)"))
    print("built-in patterns (texture = only: pictures with no shape to mesh):")
    print("  " + (", ".join(scenes.builtin_patterns()) or "(none installed)"))
    return 0


def cmd_warmup(a) -> int:
    from .scene.assets import builtin_scenes
    from .startup import CompileWatch
    from .warmup import warm_up

    on_terminal = bool(getattr(sys.stderr, "isatty", lambda: False)())
    bar = _progress(len(builtin_scenes()), on_terminal, "warm-up", "scene") if on_terminal else None
    done = []

    def progress(name: str) -> None:
        done.append(name)
        if bar is not None:
            bar.set_postfix_str(name)
            bar.update(1)

    with CompileWatch() as watch:
        seconds = warm_up(progress=progress)
    if bar is not None:
        bar.close()
    print(f"warm-up: {len(done)} built-in scenes in {seconds:.1f} s "
          + (f"({watch.seconds:.1f} s compiling {watch.compiled} kernels)" if watch.compiled
             else "(every kernel was already compiled)"))
    return 0


# -- sweep --------------------------------------------------------------------------------------------
def cmd_sweep(a) -> int:
    from . import sweeps

    bar = {}

    def progress(done, total, failures):
        bar["done"] = done
        b = bar.get("bar")
        if b is None:
            b = bar["bar"] = _progress(total, not a.quiet, Path(a.spec).stem)
            if b is None:
                return
            b.unit = "run"
            b.n = b.last_print_n = done  # runs already in the table: not part of the rate
        b.set_postfix(failures=failures, refresh=False)
        b.update(done - b.n)

    try:
        r = sweeps.sweep(a.spec, a.output, workers=a.workers, address=a.address, states=a.states, video=a.video,
                         video_size=a.video_size, retry_failed=a.retry_failed, force=a.force, progress=progress)
    except KeyboardInterrupt:
        if a.debug:
            raise
        # not main()'s "no partial output": every finished run is in the table, on purpose
        print(f"deforma: interrupted; {bar.get('done', 0)} finished runs are in {Path(a.output) / 'results.parquet'}"
              f" (the same command carries on)", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        if bar.get("bar") is not None:
            bar["bar"].close()
    print(f"{Path(a.spec).name}: {r.total} runs, {r.skipped} already in the table, {r.ran} run now "
          f"({r.ok} ok, {r.unstable} unstable, {r.error} error) -> {r.table}")
    return 0


# -- view ---------------------------------------------------------------------------------------------
def cmd_view(a) -> int:
    if a.screenshot and a.frames is None:
        raise CliError("--screenshot needs --frames N (in the window, F2 takes screenshots)")
    try:
        from . import viewer
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise CliError(f"the viewer needs pygame-ce, pygame_gui and moderngl ({e}); "
                       f"pip install 'deforma[render]'", EXIT_NO_GL) from None
    try:
        scene = a.scene
        if a.springs:
            from . import scene as scenes

            scene = scenes.with_springs(scenes.load(a.scene))
        viewer.run(scene, size=a.size, frames=a.frames, screenshot=a.screenshot, panel=not a.no_panel,
                   wireframe=a.wireframe, samples=a.samples, paused=a.paused)
    except ImportError as e:  # pragma: no cover - pygame or moderngl missing
        raise CliError(f"the viewer needs pygame-ce, pygame_gui and moderngl ({e}); "
                       f"pip install 'deforma[render]'", EXIT_NO_GL) from None
    except RuntimeError as e:  # no display or no OpenGL 3.3
        raise CliError(str(e), EXIT_NO_GL) from None
    if a.screenshot:
        print(f"{a.scene}: {a.frames} frames -> {a.screenshot}")
    return 0


def main(argv=None) -> int:
    """Entry point of the ``deforma`` command; returns the exit code."""
    from .startup import seconds_since_process_start

    # the command's wall time starts with the process (imports included); called from Python
    # (tests, scripts), with this call
    started = time.perf_counter() - (seconds_since_process_start() if argv is None else 0.0)
    parser = _parser()
    a = parser.parse_args(argv)
    a.started = started
    commands = {"run": cmd_run, "mesh": cmd_mesh, "scenes": cmd_scenes, "view": cmd_view, "sweep": cmd_sweep,
                "warmup": cmd_warmup}
    restore_signals = _stop_on_signals()
    with warnings.catch_warnings():  # put back as they were when the command returns
        # a warning of the physics (an unconverged solve) once per command, whatever came
        # before in this process, as one line of the command's own (not Python's two)
        warnings.simplefilter("default", RuntimeWarning)
        if not a.debug:
            warnings.showwarning = lambda message, *_args, **_kw: print(f"deforma: warning: {message}",
                                                                         file=sys.stderr)
        # a scene whose step is beyond the explicit limit: a run says so, with what to set,
        # when a step blows up (the add_body warning would be a second line before it)
        warnings.filterwarnings("ignore", category=StepBeyondStableWarning)
        try:
            return commands[a.command](a)
        except KeyboardInterrupt:
            if a.debug:
                raise
            print("deforma: interrupted; no partial output was left", file=sys.stderr)
            return EXIT_INTERRUPTED
        except Stopped as e:
            import signal

            if a.debug:
                raise
            print(f"deforma: stopped by {signal.Signals(e.signum).name}; no partial output was left", file=sys.stderr)
            return 128 + e.signum
        except CliError as e:
            if a.debug:
                raise
            print(f"deforma: error: {e}", file=sys.stderr)
            return e.code
        except (ValueError, OSError, RuntimeError) as e:
            # a missing optional package (imageio-ffmpeg) or a file problem: one line, not a trace
            if a.debug:
                raise
            print(f"deforma: error: {e}", file=sys.stderr)
            return EXIT_ERROR
        finally:
            restore_signals()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

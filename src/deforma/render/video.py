"""Write rendered frames to MP4 (imageio-ffmpeg), GIF or a folder of PNGs (Pillow).

Every writer puts its bytes in a temporary file beside the target and renames it into
place only when the last frame is written (:mod:`deforma.files`), so an interrupted run
(Ctrl-C, a crash, an unstable simulation) never leaves a broken video: either the old file or
a complete one. A PNG folder's frames are gathered in a hidden folder inside it and moved
into place at the end, so an interrupted run adds no frames either.

Every writer encodes in a thread of its own (:attr:`FrameWriter.QUEUE_FRAMES` frames may wait
for it): piping raw frames to ffmpeg, a GIF's dithering (Pillow) and PNG compression release
Python's lock, so they go on while the caller simulates and draws the next frames. A failure in
that thread is raised, as one line, by the next :meth:`~FrameWriter.write` or by
:meth:`~FrameWriter.finish`, and the output is discarded as before.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import os
import queue
import shutil
import signal
import threading
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike
    from PIL import Image

from ..files import check_folder, failed_write, publish, temp_beside, temp_folder_in

__all__ = ["FrameWriter", "GifWriter", "Mp4Writer", "PngFolderWriter", "check_output", "open_writer", "output_kind"]

VIDEO_SUFFIXES = {".mp4": "mp4", ".gif": "gif"}


def output_kind(path: str | os.PathLike[str]) -> str:
    """'mp4', 'gif' or 'png' (a folder of frames) from the output path.

    A path ending in ``/`` is a folder; otherwise ``.mp4`` and ``.gif`` name videos, and an
    existing folder or a name without a suffix is a folder.

    Raises
    ------
    ValueError
        For any other suffix, naming the ones allowed.
    """
    s = str(path)
    p = Path(s)
    if s.endswith(("/", os.sep)):
        return "png"
    kind = VIDEO_SUFFIXES.get(p.suffix.lower())
    if kind is None and (p.is_dir() or p.suffix == ""):
        return "png"
    if kind is None:
        raise ValueError(f"{s}: unknown output type {p.suffix!r}; allowed: .mp4, .gif, or a folder for PNG frames")
    return kind


def check_output(path: str | os.PathLike[str]) -> str:
    """Check, before any work, that ``path`` can be written; returns its kind (see :func:`output_kind`).

    The parent folder must exist and be writable; a PNG folder may not exist yet (its
    parent must) and is created by the writer.

    Raises
    ------
    ValueError
        If the type is unknown, the folder is missing or not writable, or the path is a folder
        where a file is wanted.
    """
    kind = output_kind(path)
    p = Path(str(path).rstrip("/" + os.sep) or ".")
    if kind == "png":
        if p.exists() and not p.is_dir():
            raise ValueError(f"{path}: exists and is not a folder; PNG frames need a folder")
        folder = p if p.exists() else p.parent
    else:
        if p.is_dir():
            raise ValueError(f"{path}: is a folder; give a file name ending in .{kind}")
        folder = p.parent
    check_folder(path, folder)
    return kind


class FrameWriter:
    """Base class: a context manager that takes (H, W, 3) uint8 frames of one size.

    Use :func:`open_writer` to get the right writer for a path. Leaving the ``with`` block
    normally commits the output; leaving it through an exception (KeyboardInterrupt too)
    discards it. :meth:`write` keeps a copy of the frame and returns: the frame is encoded in
    the writer's own thread.
    """

    #: Frames that may wait for the writer's thread; :meth:`write` blocks while that many do,
    #: so memory stays bounded (:func:`run_memory` counts them, with the one being encoded and
    #: the one being handed over).
    QUEUE_FRAMES = 2

    def __init__(self, path: str | os.PathLike[str], *, fps: float) -> None:
        if not (isinstance(fps, (int, float)) and np.isfinite(fps) and 0 < fps <= 1000):
            raise ValueError(f"fps must be a number in (0, 1000], got {fps!r}")
        self.path = Path(str(path).rstrip("/" + os.sep) or ".")
        self.fps = float(fps)
        self.frames_written = 0   # frames encoded so far (by the writer's thread)
        self.size: tuple[int, int] | None = None
        self._closed = False
        self._finished = False
        self._queue: queue.Queue[np.ndarray | None] | None = None
        self._thread: threading.Thread | None = None
        self._failure: BaseException | None = None   # what the thread's last frame raised
        self._dropping = False                       # the thread skips the frames left (abort)

    def _check(self, frame) -> np.ndarray:
        f = np.asarray(frame)
        if f.dtype != np.uint8 or f.ndim != 3 or f.shape[2] not in (3, 4):
            raise ValueError(f"a frame must be an (H, W, 3) uint8 array, got {f.dtype} {f.shape}")
        f = f[:, :, :3]
        size = (f.shape[1], f.shape[0])
        if self.size is None:
            self.size = size
        elif size != self.size:
            raise ValueError(f"every frame must have the first frame's size {self.size}, got {size}")
        return f

    def write(self, frame: ArrayLike) -> None:
        """Append one frame: a copy goes to the writer's thread (this waits while
        :attr:`QUEUE_FRAMES` frames are waiting there).

        Raises
        ------
        OSError
            One line naming the file, when encoding an earlier frame failed (a full disk,
            ffmpeg stopped); the output is then discarded.
        ValueError
            For a frame of another size or type than the first, or a closed writer.
        """
        self._raise_failure()
        if self._closed:
            raise ValueError(f"{self.path}: writer is closed")
        f = np.array(self._check(frame), order="C")   # the caller may reuse its array at once
        if self._thread is None:
            self._start(f)
            self._queue = queue.Queue(maxsize=self.QUEUE_FRAMES)
            self._thread = threading.Thread(target=self._work, name=f"deforma writer {self.path.name}", daemon=True)
            self._thread.start()
        self._queue.put(f)  # type: ignore[union-attr]  # made with the thread

    def _work(self) -> None:
        """The writer's thread: encodes frames in order until it is given None; after a failure
        (kept for the caller's thread to raise) or an abort it only empties the queue."""
        while True:
            f = self._queue.get()  # type: ignore[union-attr]  # the thread's own queue
            if f is None:
                return
            if self._failure is not None or self._dropping:
                continue
            try:
                self._write(f)
                self.frames_written += 1
            except BaseException as e:  # noqa: BLE001 - raised again in the caller's thread
                self._failure = e

    def _join(self, *, drop: bool = False) -> None:
        """Wait until the thread has encoded every frame given (or, with ``drop``, skipped them)
        and ended. An interrupt meanwhile (Ctrl-C, a signal) makes it skip the rest; it is raised
        once the thread has ended, so the output is never discarded under the thread's feet."""
        t = self._thread
        if t is None:
            return
        if drop:
            self._dropping = True
            while True:  # only the caller's thread puts: after this there is room for None
                try:
                    self._queue.get_nowait()  # type: ignore[union-attr]  # made with the thread
                except queue.Empty:
                    break
        interrupt = None
        queued = False
        while t.is_alive():
            try:
                if not queued:
                    # waits for room while the thread works through the frames
                    self._queue.put(None)  # type: ignore[union-attr]
                    queued = True
                t.join()
            except BaseException as e:  # noqa: BLE001 - the thread's frame takes milliseconds
                interrupt = interrupt or e
                self._dropping = True
        self._thread = None
        if interrupt is not None:
            raise interrupt

    def _raise_failure(self) -> None:
        """Raise what the thread's encoding raised, as :meth:`write` raised it before threads:
        the output discarded, an OSError as one line naming the file."""
        if self._failure is None and self._closed and self._thread is not None:
            # closed by the writer's thread (an MP4's failed ffmpeg closes it as it fails): its
            # failure is on its way; without the wait, a write in between said only "writer is
            # closed" and a finish said nothing
            self._join(drop=True)
        e = self._failure
        if e is None:
            return
        self._join(drop=True)
        self._failure = None
        if not self._closed:
            self._closed = True
            self._discard()
        if isinstance(e, OSError) and str(self.path) not in str(e):
            raise failed_write(self.path, e) from None
        raise e

    def finish(self) -> None:
        """Complete the file in its temporary place, not yet moved onto the target: a caller
        with more outputs finishes them all before it puts any in place (``deforma run -o
        out.mp4 --states s.npz`` on a disk too full for the states keeps the earlier video).
        Waits for the writer's thread to encode every frame given."""
        if not self._closed and not self._finished:
            try:
                self._join()
            except BaseException:
                self.abort()
                raise
            self._raise_failure()
            self._finished = True
            try:
                self._finish()
            except OSError as e:
                self._closed = True
                self._discard()
                if str(self.path) in str(e):  # already says which file (the MP4 writer's own)
                    raise
                raise failed_write(self.path, e) from None
            except BaseException:
                self._closed = True
                self._discard()
                raise
        else:
            self._raise_failure()

    def close(self) -> None:
        """Finish the file and move it into place."""
        self._raise_failure()
        if not self._closed:
            self.finish()
            self._closed = True
            try:
                self._publish()
            except OSError as e:
                self._discard()
                raise failed_write(self.path, e) from None
            except BaseException:
                self._discard()
                raise

    def abort(self) -> None:
        """Throw away everything written so far; the target is left as it was."""
        try:
            self._join(drop=True)
        finally:
            if not self._closed:
                self._closed = True
                self._discard()

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.close()
        else:
            self.abort()
        return False

    def _start(self, frame) -> None:
        """Before the first frame goes to the writer's thread, in the caller's: start what the
        encoding needs (a process, for an MP4)."""

    def _write(self, frame):  # pragma: no cover - abstract
        raise NotImplementedError

    def _finish(self):  # pragma: no cover - abstract
        raise NotImplementedError

    def _publish(self):  # pragma: no cover - abstract
        raise NotImplementedError

    def _discard(self):  # pragma: no cover - abstract
        raise NotImplementedError


def mp4_complete(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a whole MP4 file: its top-level boxes (4-byte size, 4-byte type; a
    size of 1 is followed by an 8-byte one, 0 runs to the end) tile it exactly, and it has
    its ``ftyp``, ``moov`` and ``mdat``. ffmpeg that runs out of disk while it finishes the
    file (the ``+faststart`` rewrite copies it once more) prints "Error writing trailer" and
    leaves a truncated file, exiting as if all were well: this is how it is caught.

    Examples
    --------
    >>> import struct, tempfile
    >>> from pathlib import Path
    >>> box = lambda kind, body=b"": struct.pack(">I", 8 + len(body)) + kind + body
    >>> p = Path(tempfile.mkdtemp()) / "v.mp4"
    >>> _ = p.write_bytes(box(b"ftyp", b"isom") + box(b"moov") + box(b"mdat", b"x" * 9))
    >>> mp4_complete(p)
    True
    >>> _ = p.write_bytes(p.read_bytes()[:-3])  # cut short
    >>> mp4_complete(p)
    False
    """
    try:
        with open(path, "rb") as f:
            end = os.fstat(f.fileno()).st_size
            at, kinds = 0, set()
            while at < end:
                f.seek(at)
                head = f.read(8)
                if len(head) < 8:
                    return False
                size, kind = int.from_bytes(head[:4], "big"), head[4:]
                if size == 1:
                    big = f.read(8)
                    if len(big) < 8:
                        return False
                    size = int.from_bytes(big, "big")
                elif size == 0:
                    size = end - at
                if size < 8:
                    return False
                kinds.add(kind)
                at += size
    except OSError:
        return False
    return at == end and {b"ftyp", b"moov", b"mdat"} <= kinds


@contextlib.contextmanager
def _signals_held():
    """Hold Ctrl-C, SIGTERM and SIGHUP until the block ends, then act on them as they would
    have acted (the handlers in place when it began run then). In the main thread only;
    elsewhere the block runs as it is.

    What for: starting ffmpeg. imageio-ffmpeg starts its process and only then enters the
    ``try`` that stops it; an interrupt in between left it running in its own process group
    with nothing to stop it, and as it finished when the run exited it wrote its file again
    after the run had removed it (a Ctrl-C'd run said "no partial output was left" and left
    its ``.partial.mp4``).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []
    previous = {}
    try:
        for name in ("SIGINT", "SIGTERM", "SIGHUP"):
            n = getattr(signal, name, None)
            if n is not None and signal.getsignal(n) is not None:  # (None: set outside Python)
                previous[n] = signal.signal(n, lambda signum, frame: held.append(signum))
        yield
    finally:
        for n, h in previous.items():
            signal.signal(n, h)
        for n in dict.fromkeys(held):
            signal.raise_signal(n)


class Mp4Writer(FrameWriter):
    """H.264 MP4 (yuv420p, plays everywhere) through the ffmpeg binary bundled with imageio-ffmpeg.

    Odd widths or heights are padded by one pixel, as yuv420p needs even sizes.
    """

    def __init__(self, path: str | os.PathLike[str], *, fps: float, quality: float = 7.0) -> None:
        super().__init__(path, fps=fps)
        try:
            import imageio_ffmpeg  # noqa: F401
        except ImportError:
            raise RuntimeError("MP4 output needs imageio-ffmpeg: pip install 'deforma[render]'") from None
        self.quality = quality
        self._tmp = temp_beside(self.path)
        self._gen = None
        self._proc = None

    def _start(self, frame):
        # ffmpeg is started here, in the caller's thread: started from the writer's thread, the
        # fork ran Python's after-fork hooks in a thread the child does not know ("SystemError:
        # RLock returned a result with an exception set" on stderr, in a notebook's deforma.show)
        import imageio_ffmpeg

        h, w = frame.shape[:2]
        self._padded = (w + w % 2, h + h % 2)
        with _signals_held():  # until ffmpeg's process is in hand (see _signals_held)
            self._gen = imageio_ffmpeg.write_frames(
                str(self._tmp), self._padded, fps=self.fps, codec="libx264", pix_fmt_in="rgb24",
                pix_fmt_out="yuv420p", quality=self.quality, macro_block_size=1, ffmpeg_log_level="quiet",
                # veryfast: half the encoding time of the default preset, and no bigger here
                output_params=["-preset", "veryfast", "-movflags", "+faststart"],
            )
            try:
                self._gen.send(None)
            except OSError as e:
                raise self._failed(e) from None
            # ffmpeg's process, to be sure it is gone before its file is removed (_discard)
            frame_locals = self._gen.gi_frame.f_locals if self._gen.gi_frame is not None else {}
            self._proc = frame_locals.get("p")

    def _write(self, frame):
        h, w = frame.shape[:2]
        if (w, h) != self._padded:
            frame = np.pad(frame, ((0, self._padded[1] - h), (0, self._padded[0] - w), (0, 0)), mode="edge")
        try:
            self._gen.send(np.ascontiguousarray(frame))
        except OSError as e:  # BrokenPipeError too: ffmpeg stopped (a full disk, most often)
            raise self._failed(e) from None

    def _failed(self, exc: OSError) -> OSError:
        """One line for a failed ffmpeg: imageio-ffmpeg's message adds the whole command line."""
        no_space = any(getattr(x, "errno", None) in (errno.ENOSPC, errno.EDQUOT)
                       for x in (exc, exc.__cause__, exc.__context__))
        try:
            # ffmpeg reports ENOSPC to itself; we only see the pipe break: look at the disk
            no_space = no_space or shutil.disk_usage(self._tmp.parent).free < 16 * 2**20
        except OSError:
            pass
        self._closed = True
        self._discard()
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        why = "no space left on the device" if no_space else f"ffmpeg stopped ({first})"
        return OSError(f"{self.path}: writing the video failed after {self.frames_written} frames: {why}; "
                       f"nothing was written")

    def _finish(self):
        if self._gen is None:
            raise ValueError(f"{self.path}: no frames were written")
        try:
            self._gen.close()
        except OSError as e:
            raise self._failed(e) from None
        if not mp4_complete(self._tmp):  # ffmpeg could not finish it, and did not say so
            raise self._failed(OSError("the finished file is cut short"))

    def _publish(self):
        publish(self._tmp, self.path)

    def _discard(self):
        if self._gen is not None:
            # (stopped before its first frame, imageio-ffmpeg warns on stderr that "the written
            # video is invalid": it is being removed, and the run says so in its own line)
            log = logging.getLogger("imageio_ffmpeg")
            was = log.disabled
            log.disabled = True
            try:
                self._gen.close()
            except BaseException:  # noqa: BLE001 - ffmpeg may already be gone after Ctrl-C
                pass
            finally:
                log.disabled = was
        # imageio-ffmpeg kills ffmpeg when stopped (SIGTERM, Ctrl-C) but does not wait for it:
        # ffmpeg, still finishing a call, wrote its file again after it was removed (a run
        # stopped by SIGTERM under load left its .partial.mp4 behind)
        proc = self._proc
        if proc is not None:
            try:
                if proc.poll() is None:
                    proc.kill()
                proc.wait(timeout=10)
            except BaseException:  # noqa: BLE001 - a second signal: remove what we can
                pass
        self._tmp.unlink(missing_ok=True)


class GifWriter(FrameWriter):
    """Animated GIF with one shared 256-colour palette, looping forever.

    The palette is chosen from the first second of frames (kept in memory until then), so
    colours do not flicker between frames. GIF times are in hundredths of a second: frame
    durations alternate (e.g. 30 and 40 ms at 30 fps) so the average rate is exact.
    Identical consecutive frames are stored once with their durations added (Pillow does
    this), so a still ending costs nothing.
    """

    def __init__(self, path: str | os.PathLike[str], *, fps: float) -> None:
        super().__init__(path, fps=fps)
        self._pending: list[np.ndarray] = []
        self._frames: list[Image.Image] = []
        self._palette: Image.Image | None = None
        self._palette_after = max(1, int(round(self.fps)))
        # the temporary file exists from the start, like the MP4's: it reserves the name and
        # shows a run is in progress; it gets its bytes at the end (GIF needs all frames)
        self._tmp = temp_beside(self.path)

    def _quantize(self, frame):
        from PIL import Image

        # error diffusion hides the banding a 256-colour palette gives smooth gradients
        return Image.fromarray(frame).quantize(palette=self._palette, dither=Image.Dither.FLOYDSTEINBERG)

    def _build_palette(self):
        from PIL import Image

        picks = self._pending[:: max(1, len(self._pending) // 4)]
        mosaic = Image.fromarray(np.concatenate(picks, axis=0))
        self._palette = mosaic.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
        self._frames.extend(self._quantize(f) for f in self._pending)
        self._pending.clear()

    def _write(self, frame):
        if self._palette is None:
            self._pending.append(frame)  # a private copy already (FrameWriter.write)
            if len(self._pending) >= self._palette_after:
                self._build_palette()
        else:
            self._frames.append(self._quantize(frame))

    def durations_ms(self, n: int) -> list[int]:
        """Per-frame durations in ms, multiples of 10, summing to n / fps seconds (rounded)."""
        cs = np.round(np.arange(n + 1) * 100.0 / self.fps).astype(int)
        return [int(max(d, 1)) * 10 for d in np.diff(cs)]

    def _finish(self):
        if self._palette is None and self._pending:
            self._build_palette()
        if not self._frames:
            raise ValueError(f"{self.path}: no frames were written")
        try:
            first, rest = self._frames[0], self._frames[1:]
            first.save(self._tmp, format="GIF", save_all=True, append_images=rest, loop=0,
                       duration=self.durations_ms(len(self._frames)), disposal=1, optimize=False)
        finally:
            self._frames = []

    def _publish(self):
        publish(self._tmp, self.path)

    def _discard(self):
        self._frames = []
        self._pending = []
        self._tmp.unlink(missing_ok=True)


class PngFolderWriter(FrameWriter):
    """Numbered PNG frames ``frame_00000.png, ...`` in a folder (created if missing).

    The frames are written into a hidden folder inside it and moved into place when the last
    one is written, so an interrupted or failed run adds no frames (and removes the folder if
    it made it). Once a run's frames are in place, frames numbered beyond them (an earlier,
    longer run's ``frame_NNNNN.png``) are deleted, so the folder holds one run; other files
    are left alone.
    """

    def __init__(self, path: str | os.PathLike[str], *, fps: float, compress_level: int = 3) -> None:
        super().__init__(path, fps=fps)
        self.compress_level = compress_level
        self._staging: Path | None = None
        self._made_folder = False

    def frame_path(self, i: int) -> Path:
        return self.path / f"frame_{i:05d}.png"

    def _write(self, frame):
        from PIL import Image

        if self._staging is None:
            if not self.path.is_dir():
                self.path.mkdir()
                self._made_folder = True
            self._staging = temp_folder_in(self.path)
        target = self._staging / self.frame_path(self.frames_written).name
        try:
            Image.fromarray(frame).save(target, format="PNG", compress_level=self.compress_level)
        except BaseException:
            target.unlink(missing_ok=True)
            raise

    def _finish(self):
        if self.frames_written == 0:
            raise ValueError(f"{self.path}: no frames were written")

    def _publish(self):
        try:
            mask = os.umask(0)
            os.umask(mask)
            for i in range(self.frames_written):
                staged = self._staging / self.frame_path(i).name
                os.chmod(staged, 0o666 & ~mask)
                os.replace(staged, self.frame_path(i))
            for old in self.path.glob("frame_*.png"):
                stem = old.stem[len("frame_"):]
                if len(stem) == 5 and stem.isdigit() and int(stem) >= self.frames_written:
                    old.unlink(missing_ok=True)
        finally:
            self._discard()

    def _discard(self):
        if self._staging is not None:
            shutil.rmtree(self._staging, ignore_errors=True)
            self._staging = None
        if self._made_folder:
            try:
                self.path.rmdir()  # only if empty: a committed run's frames stay
            except OSError:
                pass


def open_writer(path: str | os.PathLike[str], *, fps: float) -> FrameWriter:
    """The writer for ``path``: ``.mp4``, ``.gif``, or a folder (``frames/``) of PNGs.

    Parameters
    ----------
    path : str or Path
        Output file or folder. Its folder must exist (see :func:`check_output`).
    fps : float
        Frames per second of the video.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> d = tempfile.mkdtemp()
    >>> with open_writer(os.path.join(d, "ramp.gif"), fps=10) as w:
    ...     for k in range(5):
    ...         w.write(np.full((8, 8, 3), 50 * k, np.uint8))
    >>> from PIL import Image
    >>> Image.open(os.path.join(d, "ramp.gif")).n_frames
    5
    """
    kind = check_output(path)
    return {"mp4": Mp4Writer, "gif": GifWriter, "png": PngFolderWriter}[kind](path, fps=fps)


# -- memory of a headless run ----------------------------------------------------------------------
#: The most memory ``deforma run -o`` plans for (bytes): the run is refused up front when
#: :func:`run_memory` says more, naming a size (or a frame count) that fits. Measured peaks
#: under it stay under it (``tests/test_cli_limits.py``); ``docs/cli.md`` states it.
MAX_RUN_MEMORY = 2_000_000_000
# Measured (issue 51, the sample scene, software OpenGL): the process before any frame
# (Python, NumPy, the compiled kernels, the scene) ...
_BASE_BYTES = 550 * 2**20
# ... the renderer per pixel of --size: framebuffers (x4 with multisampling), the read-back
# frame and the overlay's copy (7680x4320: 0.74 GB without multisampling, 1.39 GB with it) ...
_RENDER_BYTES_PER_PIXEL = {0: 7, 4: 27}
# ... and ffmpeg's H.264 encoder, a process of its own that queues and looks ahead over whole
# frames (7680x4320: 3.16 GB; 3840x2160: 0.89 GB).
_MP4_BYTES_PER_PIXEL = 115
_MP4_BASE_BYTES = 40 * 2**20


def run_memory(size: tuple[int, int], *, samples: int, kind: str, frames: int, fps: float) -> dict[str, int]:
    """Estimate the peak memory of a headless run writing ``frames`` frames of ``size``.

    Parameters
    ----------
    size : (int, int)
        Width and height of the pictures in pixels.
    samples : {0, 4}
        Multisampling of the renderer.
    kind : {"mp4", "gif", "png"}
        The writer (see :func:`output_kind`).
    frames : int
        Frames the run writes.
    fps : float
        Frames per second (a GIF keeps its first second of frames whole to choose its palette).

    Returns
    -------
    dict of str to int
        Bytes by part: ``"process"``, ``"renderer"`` (with the second buffer of frames drawn in
        flight, :func:`deforma.render.recorder.pipeline_bytes`) and ``"writer"`` (the frames
        queued for the writer's thread, and ffmpeg's encoder for an MP4, every frame for a GIF,
        which is written only when the last one is known; a PNG folder's frames go to disk one
        by one).

    Examples
    --------
    >>> parts = run_memory((1280, 720), samples=4, kind="mp4", frames=90, fps=30)
    >>> sum(parts.values()) < MAX_RUN_MEMORY
    True
    """
    from .recorder import pipeline_bytes

    pixels = int(size[0]) * int(size[1])
    # the renderer's second off-screen buffer where frames are drawn two in flight (render/recorder.py)
    renderer = pixels * _RENDER_BYTES_PER_PIXEL.get(samples, 27) + pipeline_bytes(size, samples=samples)
    # RGB frames on their way to the writer's thread: those queued, the one it encodes, the
    # copy being handed over (FrameWriter.write)
    parts = {"process": _BASE_BYTES, "renderer": renderer, "writer": (FrameWriter.QUEUE_FRAMES + 2) * 3 * pixels}
    if kind == "mp4":
        parts["writer"] += _MP4_BASE_BYTES + pixels * _MP4_BYTES_PER_PIXEL
    elif kind == "gif":
        # one byte a pixel per kept frame, twice (Pillow's list and its frames' deltas when
        # saving), and the first second as RGB (the copy kept and the palette's mosaic)
        parts["writer"] += 2 * frames * pixels + 2 * min(frames, max(1, int(round(fps)))) * 3 * pixels
    return parts


def check_run_memory(path: str | os.PathLike[str], size: tuple[int, int], *, samples: int, frames: int, fps: float,
                     size_option: str = "--size", who: str = "deforma run") -> None:
    """Refuse, before anything runs, a run whose :func:`run_memory` is over :data:`MAX_RUN_MEMORY`.

    ``size_option`` and ``who`` are how the message names the size option and the command (a
    sweep's videos: ``--video-size``, "a sweep's run").

    Raises
    ------
    ValueError
        One line: the estimate by part and what fits instead (a smaller ``--size`` with the same
        shape, and for a GIF an MP4 or fewer frames).
    """
    kind = output_kind(path)
    parts = run_memory(size, samples=samples, kind=kind, frames=frames, fps=fps)
    total = sum(parts.values())
    if total <= MAX_RUN_MEMORY:
        return
    gb = lambda b: f"{b / 1e9:.1f} GB"  # noqa: E731
    w, h = size
    what = {"mp4": f"a {w}x{h} MP4", "gif": f"a {w}x{h} GIF of {frames} frames", "png": f"{w}x{h} PNG frames"}[kind]
    writer = {"mp4": " + ffmpeg's H.264 encoder ", "gif": " + the GIF's frames, kept until the end ",
              "png": " + the frames queued for writing "}[kind]
    detail = f"renderer {gb(parts['renderer'])}" + (f"{writer}{gb(parts['writer'])}" if writer else "")
    fits = []
    if kind == "gif":
        if sum(run_memory(size, samples=samples, kind="mp4", frames=frames, fps=fps).values()) <= MAX_RUN_MEMORY:
            fits.append("-o with .mp4 (its frames are streamed)")
        per_frame = 2 * w * h
        room = MAX_RUN_MEMORY - parts["process"] - parts["renderer"] - (parts["writer"] - 2 * frames * w * h)
        if room >= per_frame:
            most = room // per_frame
            fits.append(f"at most {most} frames (--seconds {most / fps:.3g} at {fps:g} fps)")
    # the largest size of the same shape that fits: a bisection over the width
    lo, hi = 0, w
    while lo < hi:
        mid = (lo + hi + 1) // 2
        mh = max(16, h * mid // w)
        if mid >= 16 and sum(run_memory((mid, mh), samples=samples, kind=kind, frames=frames, fps=fps).values()) \
                <= MAX_RUN_MEMORY:
            lo = mid
        else:
            hi = mid - 1
    if lo >= 16:
        fits.append(f"{size_option} {lo}x{max(16, h * lo // w)} or smaller")
    if samples and sum(run_memory(size, samples=0, kind=kind, frames=frames, fps=fps).values()) <= MAX_RUN_MEMORY:
        fits.append("--samples 0")
    raise ValueError(f"{path}: {what} needs about {gb(total)} of memory ({detail}); {who} stays within "
                     f"{gb(MAX_RUN_MEMORY)}: give " + (" or ".join(fits) if fits else f"a smaller {size_option}"))

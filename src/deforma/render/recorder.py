"""A headless run's frames drawn while the next frames are simulated: ``deforma run -o``'s pictures.

Each frame of a run is simulated (the physics, in this thread), drawn (OpenGL), read back and
encoded. Done one after the other, the drawing and encoding took longer than the physics
(issue 50: the demo at 1280x720 spent 20 ms per frame rasterising and resolving its 4x
multisampling on Mesa's software rasteriser and 20 ms reading it back, against 27 ms of
physics). But llvmpipe rasterises in threads of its own once the work is flushed, and waits
only where pixels are needed; so :class:`FrameRecorder` keeps two frames in flight, in two
off-screen buffers of the renderer, and each :meth:`~FrameRecorder.add` does::

    read frame k - 2 (resolved while frame k was simulated)  -> the writer (its own thread)
    resolve frame k - 1 (queued: llvmpipe's threads do it)
    draw frame k into buffer k % 2, flush (rasterised while frame k + 1 is simulated)

The read comes first: a read waits for all the work queued before it. The pictures are the
ones :meth:`WorldView.draw` gives, pixel for pixel; they only reach the writer two frames
later, and :meth:`~FrameRecorder.finish` delivers the last ones.

Frames larger than :data:`PIPELINE_MAX_PIXELS` are drawn and read one at a time: a second
buffer costs 20 bytes a pixel with multisampling (:func:`pipeline_bytes`), and
:func:`deforma.render.video.run_memory` counts it where it is used.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from .video import FrameWriter
    from .world_view import WorldView

__all__ = ["FrameRecorder", "PIPELINE_MAX_PIXELS", "frames_in_flight", "pipeline_bytes"]

#: Largest picture (pixels) drawn with two frames in flight: 2560x1440. Above it frames are
#: drawn and read one at a time, so a 4K MP4 keeps within the run's memory bound.
PIPELINE_MAX_PIXELS = 2560 * 1440

#: Bytes a pixel of one off-screen buffer: a 4x multisampled RGBA colour buffer and its
#: resolved copy (16 + 4), or the resolved one alone without multisampling.
_BUFFER_BYTES_PER_PIXEL = {0: 4, 4: 20}


def frames_in_flight(size: Sequence[float], *, samples: int = 4) -> int:
    """How many frames a :class:`FrameRecorder` draws ahead of the one it reads: 2, or 1 above
    :data:`PIPELINE_MAX_PIXELS`.

    Examples
    --------
    >>> frames_in_flight((1280, 720)), frames_in_flight((3840, 2160))
    (2, 1)
    """
    return 2 if int(size[0]) * int(size[1]) <= PIPELINE_MAX_PIXELS else 1


def pipeline_bytes(size: Sequence[float], *, samples: int) -> int:
    """Memory (bytes) the second off-screen buffer of a pipelined recorder adds; 0 when frames
    of ``size`` are drawn one at a time.

    Examples
    --------
    >>> pipeline_bytes((1280, 720), samples=4), pipeline_bytes((3840, 2160), samples=4)
    (18432000, 0)
    """
    if frames_in_flight(size, samples=samples) < 2:
        return 0
    return int(size[0]) * int(size[1]) * _BUFFER_BYTES_PER_PIXEL.get(samples, 20)


class FrameRecorder:
    """Draws a :class:`~deforma.render.WorldView`'s world into a frame writer, frames in flight.

    Parameters
    ----------
    view : WorldView
        On a headless renderer (:meth:`Renderer.headless`): its off-screen buffers 0 and 1
        are used in turn.
    writer : FrameWriter
        Takes the frames, in order, the last ones when :meth:`finish` is called. Opening,
        closing and discarding it stay the caller's.
    in_flight : {1, 2}, optional, keyword-only
        Frames drawn before the first is read: 2 overlaps drawing with the simulation, 1 draws
        and reads each frame at once (as :meth:`WorldView.draw`). Default:
        :func:`frames_in_flight` of the renderer's size.

    Examples
    --------
    >>> import deforma, os, tempfile
    >>> from deforma.render import Renderer, WorldView, open_writer
    >>> from deforma.render.recorder import FrameRecorder
    >>> world = deforma.load_scene("sample")
    >>> view = WorldView(Renderer.headless((160, 90)), world)
    >>> path = os.path.join(tempfile.mkdtemp(), "s.gif")
    >>> with open_writer(path, fps=30) as writer:
    ...     recorder = FrameRecorder(view, writer)
    ...     for _ in range(5):
    ...         world.step()
    ...         recorder.add()             # drawn now, read back two frames later
    ...     recorder.finish()              # the last two frames go to the writer
    >>> recorder.frames, recorder.last_frame.shape
    (5, (90, 160, 3))
    >>> view.renderer.release()
    """

    def __init__(self, view: WorldView, writer: FrameWriter, *, in_flight: int | None = None) -> None:
        r = view.renderer
        if in_flight is None:
            in_flight = frames_in_flight(r.size, samples=getattr(r, "_samples", 0))
        if in_flight not in (1, 2):
            raise ValueError(f"in_flight must be 1 or 2, got {in_flight!r}")
        self.view = view
        self.writer = writer
        self.in_flight = in_flight
        self.frames = 0          # frames handed to the writer
        self.last_frame: np.ndarray | None = None  # the last of them, (H, W, 3) uint8
        self._drawn: deque = deque()  # frames drawn, not yet read: [buffer, time, scale, resolved]

    def add(self) -> None:
        """Draw the world as it is now; its picture reaches the writer by the second next call
        (or :meth:`finish`)."""
        view, r = self.view, self.view.renderer
        if self.in_flight == 1:
            frame = view.draw()
            assert frame is not None  # draw() reads the picture back by default
            self._deliver(frame)
            return
        drawn = self._drawn
        if len(drawn) == 2:
            self._read_oldest()                        # frame k - 2: resolved meanwhile
        if drawn and not drawn[-1][3]:
            r.resolve_buffer(drawn[-1][0])             # frame k - 1
            drawn[-1][3] = True
            r.flush()
        buffer = (drawn[-1][0] + 1) % 2 if drawn else 0
        r.use_buffer(buffer)
        view.draw(read=False)                          # frame k
        r.flush()
        drawn.append([buffer, view.world.time, r.camera.metres_per_pixel(r.size), False])

    def finish(self) -> None:
        """Read every frame still in flight and hand it to the writer, oldest first."""
        r = self.view.renderer
        for entry in self._drawn:
            if not entry[3]:
                r.resolve_buffer(entry[0])
                entry[3] = True
        while self._drawn:
            self._read_oldest()
        r.use_buffer(0)

    def _read_oldest(self) -> None:
        buffer, time, scale, _ = self._drawn.popleft()
        frame = self.view.renderer.read_buffer(buffer)
        if self.view.overlay:
            self.view.overlay_onto(frame, time=time, metres_per_pixel=scale)
        self._deliver(frame)

    def _deliver(self, frame: np.ndarray) -> None:
        self.last_frame = frame
        self.writer.write(frame)
        self.frames += 1

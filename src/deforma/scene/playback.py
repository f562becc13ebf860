"""A scene played on a world frame by frame: the one frame loop of ``deforma run``, ``deforma
sweep`` and ``deforma.show``.

At each frame the scene's :class:`~deforma.scene.Script` (its ``[[event]]`` explosions and
``[[pull]]`` grabs) steps the world until the world's clock reaches the frame's time; the
frame is then recorded (a :class:`~deforma.scene.recording.Recording`, the ``--states`` file)
and drawn into a video when the runner asked for them. What a runner does besides (a progress
bar, a sweep's metrics) it does between the frames :meth:`Playback.frames` yields; what it
does when the world becomes unstable (``SimulationUnstable`` comes out of the loop) is its own.

Nothing here draws by itself: a runner that wants pictures passes its view (a
:class:`deforma.render.WorldView`) and its writer, so this module imports no GL package.
"""

from __future__ import annotations

from collections.abc import Iterator

from .recording import Recording
from .script import Script

__all__ = ["Playback", "frame_count"]


def frame_count(seconds: float, fps: float) -> int:
    """How many frames ``seconds`` of simulated time make at ``fps`` frames per second (at least one).

    Examples
    --------
    >>> frame_count(2.0, 30.0), frame_count(0.01, 30.0)
    (60, 1)
    """
    return max(1, int(round(seconds * fps)))


class Playback:
    """A scene played on a world at ``fps`` frames per second, from the world's current time.

    Parameters
    ----------
    scene : deforma.scene.Scene
        What to play: its events and pulls (see :class:`~deforma.scene.Script`), and what a
        recording saves with the states.
    world : deforma.World
        What to play it on; frame ``k`` is at ``world.time + k / fps`` as the world was when
        the playback was made.
    fps : float, keyword-only
        Frames per second.
    view : deforma.render.WorldView, optional, keyword-only
        Draws each frame (``view.draw()``), which goes to ``writer``; give both or neither.
    writer : deforma.render.FrameWriter, optional, keyword-only
        Takes each drawn frame. Opening, closing and discarding it stay the runner's.
    record : bool, optional, keyword-only
        Keep every frame's states in :attr:`recording`.

    Attributes
    ----------
    recording : Recording or None
        The recorded frames (with ``record=True``).
    last_frame : (H, W, 3) ndarray of uint8 or None
        The last frame drawn.

    Examples
    --------
    >>> from deforma.scene import load
    >>> scene = load("explode")
    >>> world = scene.build()
    >>> playback = Playback(scene, world, fps=10.0, record=True)
    >>> for k in playback.frames(frame_count(2.0, 10.0)):
    ...     pass                                 # a runner's own work per frame goes here
    >>> len(playback.recording.times), round(world.time, 6)   # the explosion at 1.5 s happened
    (20, 1.9)
    """

    def __init__(self, scene, world, *, fps: float, view=None, writer=None, record: bool = False):
        if (view is None) != (writer is None):
            raise ValueError("a playback draws with a view into a writer: give both or neither")
        self.world = world
        self.fps = fps
        self.view = view
        self.writer = writer
        self.recording = Recording(world, scene) if record else None
        self.last_frame = None
        self._script = Script(scene, world)
        self._start = world.time

    def frames(self, count: int) -> Iterator[int]:
        """Play ``count`` frames, yielding each frame's number once the world is there and the
        frame is recorded and drawn."""
        for k in range(count):
            self._script.advance(self._start + k / self.fps)  # step until the world's clock reaches the frame
            if self.recording is not None:
                self.recording.add()
            if self.view is not None:
                self.last_frame = self.view.draw()
                self.writer.write(self.last_frame)
            yield k

    def play(self, count: int) -> None:
        """Play ``count`` frames with nothing to do between them."""
        for _ in self.frames(count):
            pass

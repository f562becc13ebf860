"""Fixed-step simulation clock: physics advances in whole ``dt`` steps against wall time.

Drawing and simulation are decoupled the usual way (Glenn Fiedler's "fix your timestep"):
each frame adds the wall time it took to an accumulator and the world takes as many fixed
steps as fit. The physics is then the same at 30 or 240 frames/s. A frame that took too long
(a stall, a window drag, a breakpoint) is capped, so the simulation falls behind real time
for a moment instead of trying to catch up with ever more steps ("spiral of death").
"""

from __future__ import annotations

import math

__all__ = ["FixedStepClock"]


class FixedStepClock:
    """How many fixed steps of ``dt`` seconds to take for each frame.

    Parameters
    ----------
    max_frame_time : float, keyword-only
        Longest wall time, seconds, that one frame may add (> 0). Longer frames are cut to
        this, so a slow frame never asks for more than ``max_frame_time / dt`` steps.
    max_steps : int, keyword-only
        Hard cap on steps per frame (>= 1), whatever ``dt`` is.

    Examples
    --------
    >>> c = FixedStepClock()
    >>> c.advance(1 / 60, dt=1 / 600)       # one 60 Hz frame = ten 600 Hz steps
    10
    >>> c.advance(1 / 120, dt=1 / 600)      # the remainder carries over between frames
    5
    >>> c.advance(5.0, dt=1 / 600)          # a 5 s stall is cut to max_frame_time (0.1 s)
    60
    """

    def __init__(self, *, max_frame_time: float = 0.1, max_steps: int = 1000):
        if not (isinstance(max_frame_time, (int, float)) and math.isfinite(max_frame_time) and max_frame_time > 0):
            raise ValueError(f"max_frame_time must be a finite number of seconds > 0, got {max_frame_time!r}")
        if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
            raise ValueError(f"max_steps must be an integer >= 1, got {max_steps!r}")
        self.max_frame_time = float(max_frame_time)
        self.max_steps = max_steps
        self.accumulator = 0.0
        #: Wall seconds dropped by the caps since the start (how far the simulation fell behind).
        self.dropped = 0.0

    def advance(self, frame_time: float, *, dt: float) -> int:
        """Add ``frame_time`` wall seconds and return the number of whole ``dt`` steps due now."""
        if not dt > 0:
            raise ValueError(f"dt must be > 0 s, got {dt!r}")
        t = max(0.0, float(frame_time))
        if t > self.max_frame_time:
            self.dropped += t - self.max_frame_time
            t = self.max_frame_time
        self.accumulator += t
        # a tiny tolerance so 1/60 s of 1/600 s steps gives 10, not 9 plus a rounding remainder
        n = int(math.floor(self.accumulator / dt + 1e-9))
        if n > self.max_steps:
            self.dropped += (n - self.max_steps) * dt
            n = self.max_steps
            self.accumulator = 0.0
        else:
            self.accumulator = max(0.0, self.accumulator - n * dt)
        return n

    def reset(self) -> None:
        """Forget the carried-over remainder (after a pause or a rebuild)."""
        self.accumulator = 0.0

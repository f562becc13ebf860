"""Which of a kernel's two builds runs, one thread or all threads: measured, not assumed.

Threads that meet at a barrier are fast on a quiet machine and can be ten times slower than
one thread when another process holds a core. :class:`DriverChoice` times both builds as they
run and keeps to the faster, looking at the other now and then (less often while it keeps
losing, often again once it wins). Both builds compute the same thing, so the choice never
changes a result.

Examples
--------
>>> d = DriverChoice()
>>> d.choose()  # the first calls try both
'parallel'
"""

from __future__ import annotations

import math

__all__ = ["DriverChoice", "MODE_OPTION_DOC", "PARALLEL_MIN_VERTICES"]

#: Below this many vertices one thread is faster than two (thread wake-up ~ a few us): both
#: integrators with two builds run one thread there, whatever their ``mode``'s measure.
PARALLEL_MIN_VERTICES = 512

#: an integrator option ``mode``'s description, for the integrators that have two builds
MODE_OPTION_DOC = "which driver runs: measured (auto), one thread (serial) or all threads (parallel)"


class DriverChoice:
    """Timing of the ``"serial"`` and ``"parallel"`` builds of one kernel, and the choice."""

    def __init__(self):
        self.reset()

    def reset(self) -> None:
        """Forget every timing (the work changed: a new Model, other chunks)."""
        self._samples = {"serial": [], "parallel": []}  # recent seconds per call
        self._estimate = {"serial": math.inf, "parallel": math.inf}
        self._last = None  # driver of the previous call
        self._calls = 0  # calls since the last probe
        self._probing = 0  # calls of the other driver still to make
        self._probe_every = 16
        self._last_best = None

    def choose(self) -> str:
        """The build to run next: each is tried first, then the faster one, probing the other."""
        smp = self._samples
        for k in ("parallel", "serial"):
            if len(smp[k]) < 3:
                return k
        est = self._estimate
        best, other = ("parallel", "serial") if est["parallel"] <= est["serial"] else ("serial", "parallel")
        if self._probing:
            self._probing -= 1
            return other
        self._calls += 1
        if self._calls < self._probe_every:
            return best
        # Probe the other driver for two calls (only the second is timed: the first wakes
        # sleeping threads and warms caches). A probe can cost 100x a call when the cores
        # are busy, so probe less often while it keeps losing, often again once it wins.
        self._calls, self._probing = 0, 1
        if est[other] > 10 * est[best]:  # hopeless (cores taken): look again much later
            self._probe_every = 4096
        elif best != self._last_best:
            self._probe_every = 16
        else:
            self._probe_every = min(2 * self._probe_every, 4096)
        self._last_best = best
        return other

    def record(self, which: str, took: float) -> None:
        """``which`` build ran a call in ``took`` s; counted only if it also ran the call before
        (threads awake, caches warm)."""
        if which == self._last:
            smp = self._samples[which]
            smp.append(took)
            del smp[:-3]
            self._estimate[which] = sorted(smp)[len(smp) // 2]  # median: one outlier is ignored
        self._last = which

"""Start-up of a command: telling the user when Numba compiles, and timing it honestly.

deforma's kernels are ``@njit(cache=True)``: the first use on an install compiles them
(20 s to 2 minutes for ``deforma run sample``, by machine), later runs load them from Numba's cache. Numba fires
its ``numba:compile`` event only when it really compiles, after the cache lookup failed, so a
listener on that event tells a cold cache from a warm one exactly, at the moment compiling
starts, and costs nothing on a warm run. Checking the cache's index files ahead would need to
know which kernels and signatures a scene will use; timing the first step would speak only
after the silence it is meant to explain.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Callable

__all__ = ["CompileWatch", "is_cached_kernel", "seconds_since_process_start"]

#: What ``deforma run`` says on stderr when the first kernel starts compiling.
COMPILE_MESSAGE = ("deforma: compiling the physics kernels (once per install or upgrade: 1 to 4 minutes on 2 "
                   "cores, see docs/benchmarks.md#start-up; later runs load them from the cache)...")

_IMPORTED = time.perf_counter()


def is_cached_kernel(dispatcher) -> bool:
    """Whether a Numba dispatcher keeps its compiled code on disk (``cache=True``).

    Only these count as "the kernels are not cached yet" when they compile: a helper without
    a cache (``inline="always"``) compiles in every process and says nothing about the cache.
    """
    from numba.core.caching import NullCache

    cache = getattr(dispatcher, "_cache", None)
    return cache is not None and not isinstance(cache, NullCache)


class CompileWatch:
    """Listen to Numba compiling deforma's cached kernels while in a ``with`` block.

    ``on_first`` is called once, when the first cached kernel starts compiling (a cold
    cache); ``seconds`` is the wall time spent in compiles that were not nested in another.

    Examples
    --------
    >>> with CompileWatch(on_first=lambda: print("compiling...")) as watch:
    ...     pass
    >>> watch.compiled, watch.seconds
    (0, 0.0)
    """

    def __init__(self, *, on_first: Callable[[], None] | None = None):
        from numba.core import event

        self.on_first = on_first
        self.compiled = 0  # cached kernels compiled (cache misses)
        self.seconds = 0.0
        self._depth = 0
        self._started = 0.0
        self._installed = None
        watch = self

        class _Listener(event.Listener):
            def on_start(self, ev):
                if watch._depth == 0:
                    watch._started = time.perf_counter()
                watch._depth += 1
                if is_cached_kernel(ev.data.get("dispatcher")):
                    watch.compiled += 1
                    if watch.compiled == 1 and watch.on_first is not None:
                        watch.on_first()

            def on_end(self, ev):
                watch._depth -= 1
                if watch._depth == 0:
                    watch.seconds += time.perf_counter() - watch._started

        self._listener = _Listener()

    def __enter__(self) -> CompileWatch:
        from numba.core import event

        event.register("numba:compile", self._listener)
        return self

    def __exit__(self, *exc) -> None:
        from numba.core import event

        event.unregister("numba:compile", self._listener)


#: A process older than this (s) when deforma was imported began as something else that then
#: ran Python in its place: ``bash -c "pip install ... && deforma run demo"`` execs its last
#: command, so that process started with the shell, before pip, and the run's summary counted
#: pip's 45 s as its start-up. Python and the imports before deforma's take about 1 s.
EXEC_AGE = 10.0


def _process_age() -> float | None:
    """Wall seconds since this process started, from ``/proc`` (Linux, 10 ms steps), or None."""
    try:
        with open("/proc/self/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        start_ticks = int(fields[19])  # field 22 of stat(5), counted after the ")" of field 2
        with open("/proc/uptime") as f:
            uptime = float(f.read().split()[0])
        age = uptime - start_ticks / os.sysconf("SC_CLK_TCK")
        if 0.0 <= age < 1e7:
            return age
    except (OSError, ValueError, IndexError, AttributeError):
        pass
    return None


def seconds_since_process_start() -> float:
    """Wall seconds since the Python interpreter of this process started.

    From ``/proc`` on Linux, unless the process was already :data:`EXEC_AGE` s old when
    deforma was imported (a shell that ran Python in its place: its start is not
    Python's). Then, and where ``/proc`` cannot be read, the seconds since deforma was
    imported: the interpreter's start and the imports before deforma's (about 1 s) are
    not counted.
    """
    since_import = time.perf_counter() - _IMPORTED
    age = _process_age()
    if age is None or age - since_import > EXEC_AGE:
        return since_import
    return age


def warn(message: str) -> None:
    """One line on stderr, flushed at once (the user is waiting)."""
    print(message, file=sys.stderr, flush=True)

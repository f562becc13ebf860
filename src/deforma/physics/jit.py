"""Numba compilation helpers shared by the physics kernels."""

from __future__ import annotations

import types

from numba import njit

__all__ = ["serial_and_parallel"]


def _compiled_as(fn, name: str, **options):
    # Numba's on-disk cache is keyed by the function's qualified name (and source line), not
    # by its options: two builds of one function object would overwrite each other's cache
    # entries. A copy under its own name keeps them apart.
    f = types.FunctionType(fn.__code__, fn.__globals__, name, fn.__defaults__, fn.__closure__)
    f.__qualname__ = name
    f.__doc__ = fn.__doc__
    return njit(cache=True, **options)(f)


def serial_and_parallel(fn, name: str):
    """Compile one kernel body written with ``prange`` twice: one thread and all threads.

    In the one-thread build ``prange`` is ``range``, so both builds compute the same thing
    from one source. Returns ``(serial, parallel)``, named ``name + "_serial"`` and
    ``name + "_parallel"`` (also in Numba's cache).
    """
    return _compiled_as(fn, f"{name}_serial"), _compiled_as(fn, f"{name}_parallel", parallel=True)

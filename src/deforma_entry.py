"""The ``deforma`` command's first lines, before the package is imported.

Importing :mod:`deforma` (NumPy, Numba, SciPy and the compiled kernels' cache) takes about half
a second, during which Python's own handlers would answer Ctrl-C with a traceback and exit
code -2, and SIGTERM with -15. The command therefore starts here, in a module of its own
outside the package: it first makes Ctrl-C, SIGTERM and SIGHUP end the process at once with
the shell's codes (130, 143, 129) and one line (nothing has been written yet), then imports
:func:`deforma.cli.main`, which installs its own handlers for the rest of the run.
"""

import os
import signal
import sys

_SIGNALS = tuple(getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n))


def _stop_while_starting(signum, frame):  # pragma: no cover - runs only in a killed process
    what = "interrupted" if signum == signal.SIGINT else f"stopped by {signal.Signals(signum).name}"
    try:
        os.write(2, f"deforma: {what} while starting; nothing was written\n".encode())
    except OSError:
        pass
    os._exit(128 + signum)  # 130 for Ctrl-C, 143 for SIGTERM, 129 for SIGHUP


def main() -> int:
    """Entry point of the ``deforma`` console script: see the module docstring."""
    before = {signum: signal.getsignal(signum) for signum in _SIGNALS}
    for signum, handler in before.items():
        if handler is not signal.SIG_IGN:  # a signal the parent ignores (nohup, a background job) stays so
            signal.signal(signum, _stop_while_starting)
    from deforma.cli import main as run

    # from here on Ctrl-C is a KeyboardInterrupt again, which the command cleans up after, and
    # SIGTERM / SIGHUP are the command's to handle
    for signum, handler in before.items():
        signal.signal(signum, handler)
    return run()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

"""Signal several `deforma run` processes started together, each as if it ran alone.

The interrupt tests start their runs at once (each in a folder of its own) so that the
interpreter starts and Numba cache loads overlap; every run is still signalled on its own
clock, as the one-run tests did: half a second after its writer's temporary file appeared (or
after ``wait`` seconds without one).
"""

import os
import time


def partials(folder):
    """Names of the temporary (``.partial``) files and folders anywhere under ``folder``."""
    found = []
    for _, dirs, files in os.walk(folder):
        found += [f for f in dirs + files if ".partial" in f]
    return found


def signal_when_under_way(runs, send, *, wait=60.0, settle=0.5):
    """``runs``: (folder, process) pairs; calls ``send(process)`` for each once it is under way."""
    start = time.time()
    seen = {}
    pending = list(range(len(runs)))
    while pending:
        now = time.time()
        for k in list(pending):
            folder, p = runs[k]
            if k not in seen and (partials(folder) or now > start + wait):
                seen[k] = now
            if k in seen and now >= seen[k] + settle:
                send(p)
                pending.remove(k)
        time.sleep(0.05)


def kill_leftovers(processes):
    """Kill and reap whatever is still running (after a failed assert)."""
    for p in processes:
        if p.poll() is None:
            p.kill()
            p.wait()

"""A scene's scripted input, applied to a world as its clock passes: ``[[event]]`` explosions
(the space key) and ``[[pull]]`` grabs (the mouse).

One :class:`Script` drives every headless runner (``deforma run``, ``deforma sweep`` and
``deforma.show``, through their one frame loop, :class:`deforma.scene.playback.Playback`), so a
scene plays the same way in all of them. The viewer does not play it: there a person presses
the keys and holds the mouse.
"""

from __future__ import annotations

import numpy as np

__all__ = ["Script"]


class _Pulling:
    """One ``[[pull]]`` while it runs: its grab, once made."""

    def __init__(self, pull):
        self.pull = pull
        self.grab = None
        self.done = False

    def target(self, t: float) -> tuple:
        p = self.pull
        if p.to is None:
            return p.at
        end = p.start if p.end is None else p.end
        s = 1.0 if end <= p.start else min(max((t - p.start) / (end - p.start), 0.0), 1.0)
        a, b = np.asarray(p.at, float), np.asarray(p.to, float)
        return tuple(a + s * (b - a))


class Script:
    """The scene's ``[[event]]`` and ``[[pull]]`` entries still ahead of the world's clock.

    Parameters
    ----------
    scene : deforma.scene.Scene
        What to play (its ``event``, ``pull`` and ``interaction.explosive_force``).
    world : deforma.World
        What to play it on; times are on ``world.time``, so a world already run for a while
        skips what is over (a pull whose grab time has passed grabs at once).

    Examples
    --------
    >>> import deforma
    >>> from deforma.scene import load
    >>> scene = load("explode")
    >>> world = scene.build()
    >>> script = Script(scene, world)
    >>> script.advance(2.0)                    # steps the world to t = 2 s, exploding at 1.5 s
    >>> round(world.time, 6)
    2.0
    """

    def __init__(self, scene, world):
        self.world = world
        half = 0.5 * world.dt
        self._explosive_force = float(scene.interaction.explosive_force)
        self._events = sorted((e for e in scene.event if e.time >= world.time - half), key=lambda e: e.time)
        self._pulls = [_Pulling(p) for p in scene.pull if p.release is None or p.release >= world.time - half]

    def apply(self) -> None:
        """Do what is due at the world's current time (call before each ``world.step()``)."""
        w = self.world
        t, half = w.time, 0.5 * w.dt
        while self._events and self._events[0].time <= t + half:
            e = self._events.pop(0)
            w.explode(e.strength if e.strength is not None else self._explosive_force)
        for run in self._pulls:
            p = run.pull
            if run.done or t < p.start - half:
                continue
            if run.grab is None:
                run.grab = w.grab(p.at, strength=p.strength, radius=p.radius)
            if p.release is not None and t >= p.release - half:
                w.release(run.grab)
                run.done = True
            elif run.grab.active:
                w.drag(run.grab, run.target(t))

    def advance(self, until: float) -> None:
        """Step the world until its clock reaches ``until`` seconds (within half a step),
        applying the script before each step (``dt`` need not divide the time)."""
        w = self.world
        while w.time < until - 0.5 * w.dt:
            self.apply()
            w.step()

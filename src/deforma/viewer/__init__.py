"""The interactive viewer: ``deforma view [SCENE]``.

A pygame-ce OpenGL window drawn with the shared moderngl renderer, an inspector panel
(pygame_gui) with every parameter of the original Unity inspector, mouse pull, explosion and
keys (see :mod:`deforma.viewer.controls` and ``docs/viewer.md``).

Needs the ``render`` extra (``pip install 'deforma[render]'``). Only :func:`run` and
:class:`Viewer` import pygame; :class:`Session` and the clock work without any GUI package.

Examples
--------
>>> from deforma.viewer import Session
>>> s = Session("demo")
>>> s.set_param("stiffness", 2500.0)
>>> s.world.stiffness
2500.0
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

# pygame prints a banner on import; a command-line tool should not
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

from .clock import FixedStepClock  # noqa: E402
from .session import Session  # noqa: E402

if TYPE_CHECKING:
    from ..scene import Scene
    from .app import Viewer


def run(scene: Scene | str | os.PathLike[str] = "demo", **kwargs: Any) -> Viewer | None:
    """Open the viewer (see :func:`deforma.viewer.app.run`)."""
    from .app import run as _run

    return _run(scene, **kwargs)


def __getattr__(name: str) -> Any:
    if name == "Viewer":  # imported on demand: it pulls in pygame
        from .app import Viewer

        return Viewer
    raise AttributeError(name)


__all__ = ["FixedStepClock", "Session", "Viewer", "run"]

"""The viewer tests drive a real pygame-ce window with real OpenGL, never skipped.

SDL's ``offscreen`` video driver gives an OpenGL 3.3 context (Mesa llvmpipe through EGL)
without a display, in CI too. It must be chosen before pygame initialises its display.
"""

import os

os.environ["SDL_VIDEODRIVER"] = "offscreen"
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")

import pytest  # noqa: E402


@pytest.fixture(scope="session")
def viewer():
    """One window for the whole session (opening one costs about a second); tests load scenes into it."""
    from deforma.viewer.app import Viewer

    from seed_scenes import seed

    v = Viewer(seed("demo"), size=(1280, 720))
    yield v
    v.close()


@pytest.fixture
def demo(viewer):
    """The viewer with a fresh demo scene (the seed's springs), panel shown, running, no pending events."""
    import pygame
    from seed_scenes import seed

    viewer.load(seed("demo"))
    viewer.panel_visible = True
    viewer.help_visible = False
    viewer.running = True
    pygame.event.clear()
    viewer.frame(1 / 60)
    return viewer

"""Fixtures shared by the test packages."""

import pytest


@pytest.fixture(scope="module")
def gl_ctx():
    """A headless EGL context shared by a test module (rendering tests never skip).

    Released after the module: a standalone context left alive would keep a pygame-ce window
    opened later in the same process (the viewer tests) from finding its own OpenGL context.
    """
    from deforma.render import create_headless_context

    ctx = create_headless_context()
    yield ctx
    ctx.release()

import pytest

pytest.importorskip  # rendering tests never skip: moderngl and EGL are test requirements


@pytest.fixture(scope="session")
def gl_ctx():
    """One headless EGL context for the whole session (creating one costs ~50 ms)."""
    from deforma.render import create_headless_context

    return create_headless_context()

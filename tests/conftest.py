"""Fixtures shared by the test packages."""

import os

import numpy as np
import pytest

# No background warm-up from the tests' runs (tests/test_warmup.py turns it on where it is
# tested): a test that fakes a cold cache in a temporary folder would start one compiling
# every kernel into that folder, and wait minutes for it; subprocesses inherit this.
os.environ.setdefault("DEFORMA_WARMUP", "0")


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


@pytest.fixture
def patched_matrices(monkeypatch):
    """Check every matrix implicit Euler patches after a tear against the one assembled from
    scratch (the same arrays, bit for bit); returns the list of the checked patches' fresh
    vertex masks, which grows as the test runs."""
    from deforma.physics.integrators.implicit import solver as implicit

    full = implicit.system_matrix
    checked = []

    def system_matrix(m, grab_slot, grab_pull, h, mass=None, patch=None, weights=None, fused=True):
        a, diag = full(m, grab_slot, grab_pull, h, mass, patch, weights, fused)
        if patch is not None:
            b, diag_b = full(m, grab_slot, grab_pull, h, mass, fused=fused)  # its own weights, too
            for got, want in ((a.indptr, b.indptr), (a.indices, b.indices), (a.data, b.data), (diag, diag_b)):
                np.testing.assert_array_equal(got, want)
            checked.append(patch[3])
        return a, diag

    monkeypatch.setattr(implicit, "system_matrix", system_matrix)
    return checked


def pytest_collection_modifyitems(config, items):
    """Under pytest-xdist (``-n``, ``--dist loadgroup``): each test file runs whole in one
    worker, in its order (module-scoped fixtures and tests that build on the one before), and
    every file that opens OpenGL contexts or windows (render/, viewer/, and the examples that
    draw) runs in one worker, in the order a serial run has: two viewer tests, run after
    another set of GL files in a second process, read a black window."""
    for item in items:
        path = item.path.as_posix()
        gl = "/tests/render/" in path or "/tests/viewer/" in path
        item.add_marker(pytest.mark.xdist_group("gl" if gl else path))

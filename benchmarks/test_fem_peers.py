"""The FEM peers in fem_peers.py compute the same step as the NumPy reference.

Run with ``pytest benchmarks/test_fem_peers.py`` (the project's testpaths cover tests/ only,
so the default run does not need Taichi or Warp).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fem_peers  # noqa: E402

N_SUBSTEPS = 20
RTOL = 1e-9


def test_grid_body_is_as_described():
    body = fem_peers.grid_body()
    tris, x = body["tris"], body["x"]
    Ds = np.stack([x[tris[:, 1]] - x[tris[:, 0]], x[tris[:, 2]] - x[tris[:, 0]]], axis=-1)
    J = np.linalg.det(Ds @ body["B"])
    assert (np.linalg.det(np.linalg.inv(body["B"])) > 0).all()  # rest shape counter-clockwise
    assert 1 <= (J < 0).sum() <= 3  # the inverted triangle (and at most its two edge neighbours)
    assert (x[:, 1] < body["floor_y"]).any()


@pytest.mark.parametrize("model", fem_peers.MODELS)
def test_reference_moves_and_models_differ(model):
    """Guard against a vacuous comparison: the step moves the body, and the model matters."""
    body = fem_peers.grid_body()
    x, _ = fem_peers.numpy_reference_step(model=model, n_substeps=N_SUBSTEPS, **body)
    other = next(mm for mm in fem_peers.MODELS if mm != model)
    x_other, _ = fem_peers.numpy_reference_step(model=other, n_substeps=N_SUBSTEPS, **body)
    assert np.abs(x - body["x"]).max() > 1e-3
    assert np.abs(x - x_other).max() > 1e-6
    assert (x[:, 1] >= body["floor_y"]).all()


def _check_peer(make, model):
    body = fem_peers.grid_body()
    x_ref, _ = fem_peers.numpy_reference_step(model=model, n_substeps=N_SUBSTEPS, **body)
    step, positions = make(model=model, **body)
    np.testing.assert_array_equal(positions(), body["x"])  # state copied in, not stepped yet
    step(N_SUBSTEPS)
    x = positions()
    assert x.shape == x_ref.shape and x.dtype == np.float64
    # Compare the displacements, not the positions: ~1 m positions would hide errors in the
    # millimetre motion of 20 substeps behind their own size.
    disp, disp_ref = x - body["x"], x_ref - body["x"]
    err = np.abs(disp - disp_ref).max() / np.abs(disp_ref).max()
    assert err <= RTOL, f"relative error {err:.3g}"


@pytest.mark.parametrize("model", fem_peers.MODELS)
def test_taichi_matches_reference(model):
    pytest.importorskip("taichi")
    _check_peer(fem_peers.make_taichi_stepper, model)


@pytest.mark.parametrize("model", fem_peers.MODELS)
def test_warp_matches_reference(model):
    pytest.importorskip("warp")
    _check_peer(fem_peers.make_warp_stepper, model)


def test_unknown_model_is_rejected():
    with pytest.raises(ValueError, match="model"):
        fem_peers.numpy_reference_step(model="linear", n_substeps=1, **fem_peers.grid_body())

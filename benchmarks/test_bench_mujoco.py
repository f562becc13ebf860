"""bench_mujoco.py builds the MuJoCo peer it times, and deforma's column meets its answer.

Run with ``pytest benchmarks/test_bench_mujoco.py`` (the project's testpaths cover tests/ only,
so the default run does not need MuJoCo).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_mujoco  # noqa: E402


def test_the_mujoco_flex_builds_and_steps():
    mujoco = pytest.importorskip("mujoco")
    told = []
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(told.append)  # its preconditioner warning, not MUJOCO_LOG.TXT
    try:
        mesh = bench_mujoco.column(4)
        top = np.flatnonzero(np.isclose(mesh.vertices[:, 1], 0.0))
        model, data = bench_mujoco.mujoco_flex(mesh, pinned=top, drag=bench_mujoco.DRAG)
        # one body of two slide joints per free vertex, each with deforma's lumped mass
        assert model.nflex == 1 and model.nv == 2 * (len(mesh.vertices) - len(top))
        masses = bench_mujoco.lumped_masses(mesh, bench_mujoco.RHO)
        assert model.body_mass.sum() == pytest.approx(np.delete(masses, top).sum(), rel=1e-12)
        assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_DISCRETE
        for _ in range(60):
            mujoco.mj_step(model, data)
        x = bench_mujoco.mujoco_positions(data)
        assert np.isfinite(x).all()
        np.testing.assert_allclose(x[top], mesh.vertices[top], atol=1e-12)  # pinned
        drop = -bench_mujoco.L - x[np.isclose(mesh.vertices[:, 1], -bench_mujoco.L), 1].mean()
        assert 0.9 < drop / bench_mujoco.EXPECTED < 1.05  # it hangs by its elasticity, in the plane
        assert np.abs(np.asarray(data.flexvert_xpos)[:, 1]).max() < 1e-9

        model, data = bench_mujoco.mujoco_flex(bench_mujoco.block(4), floor=True, lift=0.5 + bench_mujoco.RADIUS)
        for _ in range(30):
            mujoco.mj_step(model, data)
        assert data.ncon > 0 and np.abs(data.qvel).max() < 0.05  # standing on the floor
    finally:
        mujoco.set_mju_user_warning(previous)


def test_deformas_column_is_within_one_percent_of_the_analytic_drop():
    mesh = bench_mujoco.column(4)
    top = np.flatnonzero(np.isclose(mesh.vertices[:, 1], 0.0))
    w, b = bench_mujoco.deforma_world(mesh, "corotated", pinned=top, air_drag=bench_mujoco.DRAG)
    for _ in range(180):
        w.step()
    drop = -bench_mujoco.L - b.positions[np.isclose(mesh.vertices[:, 1], -bench_mujoco.L), 1].mean()
    assert drop == pytest.approx(bench_mujoco.EXPECTED, rel=0.01)

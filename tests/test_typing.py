"""The public API type-checks (mypy) and the tree lints clean (ruff): issue 50, "Typed and linted".

mypy and ruff are test dependencies (the ``test`` extra): missing, these tests fail rather
than skip. The modules mypy checks are listed here and in ``[tool.mypy] files`` of
pyproject.toml (what a bare ``mypy`` checks); a test keeps the two the same. mypy's cache
lives under the temporary folder, so a warm run takes a few seconds (about 10 s cold).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: The public API, the physics seams, the renderer and the viewer, fully annotated and checked.
TYPED_MODULES = [
    "src/deforma/__init__.py",
    "src/deforma/mesh/__init__.py", "src/deforma/mesh/box.py", "src/deforma/mesh/delaunay.py",
    "src/deforma/mesh/export.py", "src/deforma/mesh/image.py", "src/deforma/mesh/mesh.py", "src/deforma/mesh/outline.py",
    "src/deforma/physics/__init__.py", "src/deforma/physics/world.py", "src/deforma/physics/body.py",
    "src/deforma/physics/material.py", "src/deforma/physics/joint.py", "src/deforma/physics/colliders/shapes.py",
    "src/deforma/physics/integrators/__init__.py", "src/deforma/physics/integrators/base.py",
    "src/deforma/scene/__init__.py", "src/deforma/scene/build.py",
    "src/deforma/render/renderer.py", "src/deforma/render/video.py", "src/deforma/render/world_view.py",
    "src/deforma/render/notebook.py", "src/deforma/render/recorder.py",
    "src/deforma/render/__init__.py", "src/deforma/render/collider_mesh.py", "src/deforma/render/fill.py",
    "src/deforma/render/framing.py", "src/deforma/render/overlay.py",
    "src/deforma/viewer/__init__.py", "src/deforma/viewer/app.py", "src/deforma/viewer/clock.py",
    "src/deforma/viewer/controls.py", "src/deforma/viewer/inspector.py", "src/deforma/viewer/overlay.py",
    "src/deforma/viewer/params.py", "src/deforma/viewer/session.py",
    "src/deforma/sweeps.py",
]

LINTED = ["src", "tests", "benchmarks", "tools"]


def _tool(module: str) -> None:
    try:
        __import__(module)
    except ImportError:
        pytest.fail(f"{module} is not installed: it is a test dependency (pip install -e '.[test]')", pytrace=False)


def _run(args: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", *args], cwd=ROOT, capture_output=True, text=True, timeout=300)


def test_mypy_config_lists_the_typed_modules():
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["mypy"]
    assert config["files"] == TYPED_MODULES
    assert all((ROOT / m).is_file() for m in TYPED_MODULES)


def test_public_api_type_checks():
    _tool("mypy")
    cache = Path(tempfile.gettempdir()) / "deforma-mypy-cache"
    r = _run(["mypy", "--cache-dir", str(cache), *TYPED_MODULES])
    assert r.returncode == 0, f"mypy found problems:\n{r.stdout}{r.stderr}"


def test_ruff_lints_clean():
    _tool("ruff")
    r = _run(["ruff", "check", "--no-cache", *LINTED])
    assert r.returncode == 0, f"ruff found problems:\n{r.stdout}{r.stderr}"


def test_py_typed_ships():
    assert (ROOT / "src/deforma/py.typed").is_file()
    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["deforma"]
    assert "py.typed" in data

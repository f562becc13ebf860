"""``python -m deforma.examples`` lists the examples, runs one by name headless, refuses an unknown name
in one line (issue 50).

Each case runs the command in a subprocess, as a user would, with no display
(``SDL_VIDEODRIVER=offscreen``, ``DISPLAY`` unset): an example that waited for a window would
hang here, so every run has a timeout. The examples run are the quickest; the gallery
(``tools/gallery.py``) runs them all.
"""

import os
import pkgutil
import subprocess
import sys

import pytest
from PIL import Image

import deforma.examples as examples

#: Numba compiles a cold cache's kernels (about a minute on 2 cores) on top of the example's seconds.
TIMEOUT_SECONDS = 400


def run(*args, cwd=None):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["SDL_VIDEODRIVER"] = "offscreen"
    return subprocess.run([sys.executable, "-m", "deforma.examples", *args], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=TIMEOUT_SECONDS)


def test_every_example_module_is_listed():
    modules = {m.name for m in pkgutil.iter_modules(examples.__path__) if not m.name.startswith("_")}
    assert modules == set(examples.NAMES)
    for name in ("meshes", "materials", "contact", "tearing", "colliders", "rigid", "sweeps", "notebook"):
        assert name in examples.NAMES  # what issue 50 asks the examples to cover


def test_the_listing_has_one_line_per_example_with_what_it_shows():
    out = run()
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert lines[0].startswith("examples (python -m deforma.examples NAME")
    assert len(lines) == 1 + len(examples.NAMES)
    for name, line in zip(examples.NAMES, lines[1:]):
        shown, _, summary = line.strip().partition(" ")
        assert shown == name and len(summary.strip()) > 20, line
    assert run("--help").stdout == out.stdout


def test_an_unknown_name_is_one_line_with_the_names_and_a_non_zero_exit():
    out = run("mehses")
    assert out.returncode == 2 and out.stdout == ""
    assert len(out.stderr.strip().splitlines()) == 1 and "Traceback" not in out.stderr
    assert "did you mean 'meshes'?" in out.stderr
    assert all(name in out.stderr for name in examples.NAMES)


def test_an_output_it_cannot_write_is_one_line_and_a_non_zero_exit(tmp_path):
    (tmp_path / "taken").write_text("a file where a folder would have to be")
    out = run("meshes", "--output", str(tmp_path / "taken" / "meshes.png"))
    assert out.returncode == 1 and "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1 and "taken" in out.stderr


@pytest.mark.parametrize("name, expected", [
    ("meshes", ["bunny", "donut", "armadillo"]),
    ("materials", ["springs", "jelly", "foam", "rubber"]),
])
def test_an_example_runs_headless_and_draws_its_picture(tmp_path, name, expected):
    picture = tmp_path / f"{name}.png"
    out = run(name, "--output", str(picture), cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert all(word in out.stdout for word in expected), out.stdout
    with Image.open(picture) as im:
        assert im.format == "PNG" and max(im.size) == 480
        assert len(im.convert("RGB").getcolors(2**16) or []) > 3  # drawn, not blank
    assert sorted(p.name for p in tmp_path.iterdir()) == [picture.name]  # nothing else written


def test_each_example_has_options_and_help():
    out = run("tearing", "--help")
    assert out.returncode == 0 and "--output" in out.stdout and "python -m deforma.examples tearing" in out.stdout

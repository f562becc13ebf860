"""The integrators example (src/deforma/examples/integrators.py; examples/compare_integrators.py points
at it) runs headless and writes its video and plot."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "src" / "deforma" / "examples" / "integrators.py"


#: two_mass_period_error(integrator, h) -> its value or the exception it raised, shared by the
#: tests of this module: each writes the plot, whose period-error panel steps the same two masses
#: at the same five steps (about 18,000 Python-level steps), a deterministic result
_PERIOD_ERRORS = {}


def load_example():
    spec = importlib.util.spec_from_file_location("compare_integrators", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    computed = mod.two_mass_period_error

    def two_mass_period_error(integrator, h):
        key = (integrator, h)
        if key not in _PERIOD_ERRORS:
            try:
                _PERIOD_ERRORS[key] = computed(integrator, h)
            except Exception as e:  # SimulationUnstable: the plot draws a gap
                _PERIOD_ERRORS[key] = e
        value = _PERIOD_ERRORS[key]
        if isinstance(value, Exception):
            raise value
        return value

    mod.two_mass_period_error = two_mass_period_error  # plot() looks it up in the module
    return mod


def test_period_error_helper_matches_the_discrete_formulas():
    import math
    ex = load_example()
    h, w = 1e-2, math.sqrt(150.0 / 0.75)
    assert ex.two_mass_period_error("symplectic-euler", h) == pytest.approx(
        (h * w) / (2 * math.asin(h * w / 2)) - 1, rel=0.02)
    assert ex.two_mass_period_error("implicit-euler", h) == pytest.approx((h * w) / math.atan(h * w) - 1, rel=0.02)


def test_example_writes_a_side_by_side_gif_and_a_plot(tmp_path):
    pytest.importorskip("matplotlib")  # an optional dependency of the example only
    from PIL import Image

    ex = load_example()
    gif, png = tmp_path / "cmp.gif", tmp_path / "cmp.png"
    ex.main(["--seconds", "0.5", "--fps", "10", "--panel", "160", "90", "--dt", "0.0166667", "--substeps", "4",
             "--video", str(gif), "--plot", str(png)])
    with Image.open(gif) as im:
        assert im.n_frames == 5 and im.size == (160 * len(ex.INTEGRATORS), 90)  # one panel per integrator
    with Image.open(png) as im:
        a = np.asarray(im.convert("RGB"))
        assert a.shape[1] > a.shape[0] and a.std() > 10  # a wide figure with something drawn


def test_example_writes_into_the_current_folder_by_default(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    ex = load_example()
    docs = Path(__file__).resolve().parents[2] / "docs"
    before = {p.name: p.stat().st_mtime_ns for p in docs.iterdir()}
    monkeypatch.chdir(tmp_path)
    ex.main(["--seconds", "0.2", "--fps", "10", "--panel", "80", "48", "--dt", "0.0166667", "--substeps", "4"])
    assert (tmp_path / "integrators.gif").is_file() and (tmp_path / "integrators.png").is_file()
    assert {p.name: p.stat().st_mtime_ns for p in docs.iterdir()} == before  # the tracked pictures untouched

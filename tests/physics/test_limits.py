"""Hardening: numbers outside the range their formulas mean something in are refused in one
line; hints stay true at the edges; a run that lost a body's shape is reported."""

import math
import re
import subprocess
import sys

import numpy as np
import pytest

import deforma
from deforma.checks import LIMITS, MAX_SUBSTEPS

BOX = deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=4)


@pytest.mark.parametrize("name, value, message", [
    ("dt", 1e-300, r"dt must be in \[1e-06, 0.1\] s"),
    ("dt", 1.0, r"dt must be in \[1e-06, 0.1\] s"),
    ("substeps", 10**9, r"substeps must be an integer in \[1, 1000\]"),
    ("max_speed", 1e308, r"max_speed must be in"),
    ("stiffness", 1e308, r"stiffness must be in \[0, 1e\+12\] N/m"),
    ("damping", 1e12, r"damping must be in \[0, 1e\+09\]"),
    ("mass", 1e-300, r"mass must be in"),
    ("gravity", (0.0, -1e300), r"gravity must lie within"),
    ("friction", 1e6, r"friction must be in \[0, 100\]"),
    ("air_drag", 1e9, r"air_drag must be in"),
    ("stiffness", -1.0, r"stiffness must be >= 0 N/m"),
    ("dt", 1j, r"dt must be a real number"),
])
def test_out_of_range_world_values_are_refused_in_one_line(name, value, message):
    w = deforma.World()
    before = getattr(w, name)
    with pytest.raises(ValueError, match=message) as e:
        setattr(w, name, value)
    assert "\n" not in str(e.value)
    assert getattr(w, name) == before


def test_substeps_cannot_make_a_substep_vanishingly_short():
    w = deforma.World(dt=1e-6)
    with pytest.raises(ValueError, match=r"dt / substeps must be >= 1e-07 s"):
        w.substeps = 100


def test_infinite_max_speed_still_means_no_speed_check():
    w = deforma.World(max_speed=math.inf)
    w.add_body(BOX, position=(0, 1))
    w.step()
    assert w.max_speed == math.inf


@pytest.mark.parametrize("center, size", [((0, 0), (1e300, 1)), ((1e300, 0), (1, 1))])
def test_colliders_of_absurd_size_are_refused(center, size):
    with pytest.raises(ValueError, match="within"):
        deforma.Rect(center, size, 0.0)


def test_stable_step_is_finite_and_positive_at_the_extremes():
    w = deforma.World(dt=1 / 600, integrator="symplectic-euler", mass=LIMITS["mass"][0],
                      stiffness=LIMITS["stiffness"][1], damping=LIMITS["damping"][1])
    w.add_body(BOX, position=(0, 1))
    assert 0 < w.stable_dt() < 1e-9


def test_hints_stay_short_and_true_at_the_extremes():
    # a step far beyond the stable one: no hint asking for a substep count of 80 digits
    w = deforma.World(integrator="symplectic-euler", dt=0.1, mass=LIMITS["mass"][0], stiffness=LIMITS["stiffness"][1],
                      damping=0.0)
    w.add_body(BOX, position=(0, 1))
    with pytest.raises(deforma.SimulationUnstable) as e:
        for _ in range(10):
            w.step()
    assert not re.search(r"\d{12,}", str(e.value))
    assert str(MAX_SUBSTEPS) in e.value.hint


def test_a_huge_explosion_is_named_in_the_hint_not_dt():
    w = deforma.World()
    w.add_body(BOX, position=(0, 1))
    w.explode(1e6)
    with pytest.raises(deforma.SimulationUnstable) as e:
        w.step()
    assert "explode" in e.value.hint and "dt" not in e.value.hint


def test_a_body_started_inside_a_collider_is_reported_not_stretched_silently():
    w = deforma.World()
    w.add_collider(deforma.Rect((0, 0), (3, 3), 0.0))
    w.add_body(BOX, position=(0.1, 0.0))
    with pytest.raises(deforma.SimulationUnstable, match="lost its shape at step [0-9]+: a spring is"):
        for _ in range(100):
            w.step()


def test_a_step_too_long_for_xpbd_is_reported_as_a_lost_shape():
    # the case: xpbd at 1/30 s crushed the demo's body with half its triangles inside out
    w = deforma.load_scene("demo")
    w.integrator = "xpbd"
    w.dt = 1 / 30
    with pytest.raises(deforma.SimulationUnstable, match="lost its shape at step [0-9]+: its area fell") as e:
        for _ in range(120):
            w.step()
    assert np.isfinite(w.bodies[0].positions).all()
    # the hint says how many substeps hold the body up under XPBD
    assert f"raise substeps to {w.xpbd_substeps()} (world.xpbd_substeps())" in e.value.hint
    assert w.xpbd_substeps() > w.substeps


def test_the_built_in_scenes_never_lose_their_shape_check():
    # the check runs in every step of the suite's scene runs; here, directly, on the pile
    w = deforma.load_scene("pile")
    for _ in range(64):
        w.step()
    assert all(v == 0 for v in w._lost_shape.values())


def test_a_scene_with_a_vanishing_step_is_refused_by_the_command(tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text('[physics]\ndt = 1e-300\n\n[[body]]\nshape = "box"\n')
    out = tmp_path / "x.gif"
    r = subprocess.run([sys.executable, "-m", "deforma.cli", "run", str(scene), "-o", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode != 0
    assert "dt must be in [1e-06, 0.1] s" in r.stderr and "Traceback" not in r.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == [scene]


def test_sizes_that_would_overflow_are_refused_where_they_enter():
    with pytest.raises(ValueError, match=r"scale must be in \[1e-09, 1000\] m per pixel"):
        deforma.mesh.from_image("bunny", resolution=8, scale=1e300)
    with pytest.raises(ValueError, match="corners must lie within"):
        deforma.mesh.box(((0, 0), (1e300, 0), (1e300, 1e300), (0, 1e300)), detail=2)
    w = deforma.World()
    with pytest.raises(ValueError, match="vertices must lie within"):
        w.add_body(deforma.mesh.Mesh([[0, 0], [1e12, 0], [0, 1e12]], [[0, 1, 2]]))
    assert not w.bodies

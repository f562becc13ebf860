"""The ``[physics.integrator_options]`` table of scene files: it builds the world with the
options, round-trips through save_scene / load_scene writing only what differs from the
defaults, and refuses a bad entry in one line naming its key path."""

import os
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

import deforma
from deforma import scene as scenes
from deforma.cli import EXIT_ERROR, main
from deforma.physics.integrators import make_integrator
from deforma.scene import SceneError
from deforma.scene.schema import PhysicsSettings, Scene
from scene_checks import write
from test_scene_integrator import SCENE


def scene_file(tmp_path, integrator, options="", name="s.toml"):
    """The small scene of test_scene_integrator.py under ``integrator``, with ``options`` (TOML,
    a [physics.integrator_options] table) after it."""
    return write(tmp_path, SCENE.format(name=integrator) + options, name)


def test_a_world_built_from_a_scene_has_its_options_and_steps(tmp_path):
    p = scene_file(tmp_path, "implicit-euler", "\n[physics.integrator_options]\niterations = 7\ncontact_weight = 25\n")
    scene = scenes.load(p)
    # kept as the integrator keeps them, in the order it lists them
    assert scene.physics.integrator_options == (("iterations", 7), ("contact_weight", 25.0))
    world = scenes.load_scene(p)
    assert world.integrator_options == {"iterations": 7, "tolerance": 0.0, "max_iterations": 500,
                                       "contact_weight": 25.0}
    for _ in range(30):
        world.step()
    assert np.isfinite(world.bodies[0].positions).all()


@pytest.mark.parametrize("integrator, options, expected", [
    ("implicit-euler", {"iterations": 5, "contact_weight": 40.0}, {"iterations": 5, "contact_weight": 40.0}),
    ("xpbd", {"iterations": 4}, {"iterations": 4}),
    ("symplectic-euler", {"mode": "serial"}, {"mode": "serial"}),
])
def test_options_round_trip_through_save_and_load(tmp_path, integrator, options, expected):
    table = "\n[physics.integrator_options]\n" + "".join(
        f"{k} = {v!r}\n".replace("'", '"') for k, v in options.items())
    world = scenes.load_scene(scene_file(tmp_path, integrator, table))
    out = scenes.save_scene(world, tmp_path / "back.toml")
    text = out.read_text()
    assert "[physics.integrator_options]" in text
    back = scenes.load(out)
    assert dict(back.physics.integrator_options) == expected
    assert back == scenes.scene_of(world)
    assert scenes.load_scene(out).integrator_options == world.integrator_options


def test_only_options_that_differ_from_the_defaults_are_written(tmp_path):
    world = deforma.World(integrator="implicit-euler", integrator_options={"iterations": 3, "contact_weight": 20.0})
    assert scenes.scene_of(world).physics.integrator_options == (("contact_weight", 20.0),)
    out = scenes.save_scene(world, tmp_path / "w.toml")
    table = out.read_text().split("[physics.integrator_options]\n", 1)[1].split("\n\n", 1)[0]
    assert table.strip() == "contact_weight = 20.0"
    world.integrator_options = {}  # every option back to its default: no table at all
    out = scenes.save_scene(world, tmp_path / "d.toml")
    assert "integrator_options" not in out.read_text()
    world.integrator_options = {"contact_weight": 20.0}
    world.integrator = "xpbd"  # a switch puts every option back to the new integrator's defaults
    assert scenes.scene_of(world).physics.integrator_options == ()


def test_a_file_without_the_table_behaves_as_before(tmp_path):
    for name in ("symplectic-euler", "implicit-euler", "xpbd"):
        p = scene_file(tmp_path, name, name=f"{name}.toml")
        scene = scenes.load(p)
        assert scene.physics.integrator_options == ()
        assert scenes.load_scene(p).integrator_options == make_integrator(name).options
        out = scenes.save_scene(scenes.load_scene(p), tmp_path / f"{name}-back.toml")
        assert "integrator_options" not in out.read_text()
        assert scenes.load(out).physics == scene.physics


def test_the_order_in_the_file_does_not_matter_and_whole_floats_count_as_integers(tmp_path):
    a = scenes.load(scene_file(tmp_path, "implicit-euler",
                               "\n[physics.integrator_options]\ncontact_weight = 5.0\niterations = 4.0\n", "a.toml"))
    b = scenes.load(scene_file(tmp_path, "implicit-euler",
                               "\n[physics.integrator_options]\niterations = 4\ncontact_weight = 5\n", "b.toml"))
    assert a == b and a.physics.integrator_options == (("iterations", 4), ("contact_weight", 5.0))
    assert isinstance(a.physics.integrator_options[0][1], int)


BAD = [
    ("implicit-euler", "iteratons = 5", "iteratons",
     "unknown implicit-euler option 'iteratons' (did you mean 'iterations'?); implicit-euler takes iterations, "
     "tolerance, max_iterations, contact_weight"),
    ("xpbd", "contact_weight = 5.0", "contact_weight",
     "'contact_weight' is an option of implicit-euler and implicit-bdf2, not of xpbd (xpbd takes iterations)"),
    ("symplectic-euler", "iterations = 5", "iterations",
     "'iterations' is an option of implicit-euler, xpbd, implicit-bdf2 and avbd, not of symplectic-euler "
     "(symplectic-euler takes mode)"),
    ("implicit-euler", "iterations = 0", "iterations",
     "implicit-euler option iterations must be an integer in [1, 10000], got 0"),
    ("xpbd", "iterations = 20000", "iterations",
     "xpbd option iterations must be an integer in [1, 10000], got 20000"),
    ("implicit-euler", "iterations = 2.5", "iterations",
     "implicit-euler option iterations must be an integer in [1, 10000], got 2.5"),
    ("implicit-euler", 'iterations = "5"', "iterations",
     "implicit-euler option iterations must be an integer in [1, 10000], got '5'"),
    ("implicit-euler", "iterations = true", "iterations",
     "implicit-euler option iterations must be an integer in [1, 10000], got True"),
    ("implicit-euler", "contact_weight = 0.0", "contact_weight",
     "implicit-euler option contact_weight must be a number in (0, 1e+12), got 0.0"),
    ("implicit-euler", "contact_weight = inf", "contact_weight",
     "implicit-euler option contact_weight must be a number in (0, 1e+12), got inf"),
    ("implicit-euler", "contact_weight = nan", "contact_weight",
     "implicit-euler option contact_weight must be a number in (0, 1e+12), got nan"),
    ("implicit-euler", "contact_weight = [1.0]", "contact_weight",
     "implicit-euler option contact_weight must be a number in (0, 1e+12), got [1.0]"),
    ("symplectic-euler", 'mode = "fast"', "mode",
     "symplectic-euler option mode must be one of 'auto', 'serial', 'parallel', got 'fast'"),
]


@pytest.mark.parametrize("integrator, line, key, message", BAD, ids=[b[1] for b in BAD])
def test_a_bad_option_is_refused_in_one_line_naming_its_key_path(tmp_path, integrator, line, key, message):
    p = scene_file(tmp_path, integrator, f"\n[physics.integrator_options]\n{line}\n", "bad.toml")
    with pytest.raises(SceneError) as e:
        scenes.load(p)
    assert str(e.value) == f"{p}: physics.integrator_options.{key}: {message}"


def test_a_table_that_is_not_a_table_is_refused(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[physics]\nintegrator = \"xpbd\"\nintegrator_options = 5\n")
    with pytest.raises(SceneError, match=r"bad.toml: physics.integrator_options: expected a table of name = value "
                                         r"\(\[physics.integrator_options\]\), got integer 5$"):
        scenes.load(p)


def test_a_scene_made_in_code_is_checked_when_built():
    scene = Scene(physics=PhysicsSettings(integrator="xpbd", integrator_options=(("contact_weight", 5.0),)))
    with pytest.raises(SceneError, match=r"^<scene>: physics.integrator_options: 'contact_weight' is an option of "
                                         r"implicit-euler and implicit-bdf2, not of xpbd"):
        scenes.build(scene)
    good = replace(scene, physics=replace(scene.physics, integrator_options=(("iterations", 6),)))
    assert scenes.build(good).integrator_options == {"iterations": 6}


def test_run_of_a_bad_file_exits_with_one_line(tmp_path, capsys):
    p = scene_file(tmp_path, "implicit-euler", "\n[physics.integrator_options]\niteratons = 5\n", "bad.toml")
    code = main(["run", str(p), "--quiet"])
    out, err = capsys.readouterr()
    err = "".join(line for line in err.splitlines(True) if not line.startswith("deforma: compiling the physics"))
    assert code == EXIT_ERROR and out == "" and err.count("\n") == 1
    assert "bad.toml: physics.integrator_options.iteratons: unknown implicit-euler option 'iteratons' " \
           "(did you mean 'iterations'?)" in err


def test_the_installed_command_prints_the_key_path_and_no_traceback(tmp_path):
    p = scene_file(tmp_path, "xpbd", "\n[physics.integrator_options]\ncontact_weight = 5.0\n", "bad.toml")
    exe = os.path.join(os.path.dirname(sys.executable), "deforma")
    r = subprocess.run([exe, "run", str(p), "--quiet"], capture_output=True, text=True, timeout=120)
    assert r.returncode == EXIT_ERROR and "Traceback" not in r.stderr
    lines = [line for line in r.stderr.splitlines() if not line.startswith("deforma: compiling the physics")]
    assert len(lines) == 1
    assert lines[0].startswith("deforma: error: ")
    assert "physics.integrator_options.contact_weight: 'contact_weight' is an option of implicit-euler and " \
           "implicit-bdf2, not of xpbd" in lines[0]

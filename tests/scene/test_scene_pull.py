"""[[pull]]: the mouse, scripted. Validation, what it does to a world, and that every headless
runner (deforma run, deforma.show) plays it through the one Script."""

import numpy as np
import pytest

import deforma
from deforma import scene as scenes
from deforma.scene import Script
from scene_checks import assert_refused, write

HANG = """
    [physics]
    gravity = [0, 0]
    integrator = "implicit-euler"
    [[body]]
    detail = 4
    pin = [[-0.6, -0.6], [-0.4, 0.6]]
"""


@pytest.mark.parametrize("text, message", [
    ("[[pull]]\nto = [1, 1]\n", "pull[0].at: missing: where the pull grabs"),
    ("[[pull]]\nat = [0, 0]\nto = [1, 0]\nstart = 2.0\nend = 1.0\n", "pull[0].end: must be >= start (2 s), got 1"),
    ("[[pull]]\nat = [0, 0]\nto = [1, 0]\nend = 1.0\nrelease = 0.5\n", "pull[0].release: must be >= end (1 s), got 0.5"),
    ("[[pull]]\nat = [0, 0]\nend = 1.0\n", "pull[0].to: missing: where the target moves by end"),
    ("[[pull]]\nat = [0, 0]\nradius = 0\n", "pull[0].radius: must be > 0 m, got 0"),
    ("[[pull]]\nat = [0, 0]\nstrength = -5\n", "pull[0].strength: must be > 0 N/m, got -5"),
    # what World.grab refuses is said at load time with the key's path
    ("[[pull]]\nat = [1e308, 0]\n", "pull[0].at: must lie within +-1e+09 m, got [1e+308, 0]"),
    ("[[pull]]\nat = [0, 0]\nto = [0, -1e308]\n", "pull[0].to: must lie within +-1e+09 m"),
    ("[[pull]]\nat = [0, 0]\nradius = 1e308\n", "pull[0].radius: must be in [1e-09, 1e+06] m, got 1e+308"),
    ("[[pull]]\nat = [0, 0]\nstrength = 1e308\n", "pull[0].strength: must be in [1e-09, 1e+12] N/m, got 1e+308"),
    ("[[pull]]\nat = [0]\n", "pull[0].at: expected two numbers [x, y]"),
    ("[[pull]]\nat = [0, 0]\nstop = 1\n", "pull[0].stop: unknown key; "),
    ("[pull]\nat = [0, 0]\n", "pull: expected an array of tables ([[pull]])"),
])
def test_bad_pulls_give_one_line_naming_the_key(tmp_path, text, message):
    assert_refused(write(tmp_path, text), message)


def test_a_pull_grabs_moves_the_target_linearly_and_lets_go(tmp_path):
    s = scenes.load(write(tmp_path, HANG + """
        [[pull]]
        at = [0.45, 0.0]
        to = [1.5, 0.0]
        start = 0.1
        end = 0.6
        release = 0.8
        radius = 0.1
        strength = 500.0
    """))
    w = s.build()
    script = Script(s, w)
    script.advance(0.1)
    assert not w._grabs  # nothing before start
    script.advance(0.35)
    (g,) = w._grabs
    assert g.strength == 500.0 and len(g.vertices) >= 3
    assert g.target[0] == pytest.approx(0.45 + 1.05 * (w.time - w.dt - 0.1) / 0.5, abs=1e-9)  # set before the last step
    script.advance(0.7)
    assert g.target == pytest.approx((1.5, 0.0))
    assert w.bodies[0].positions[:, 0].max() > 0.6  # pulled to the right
    script.advance(0.9)
    assert not g.active and not w._grabs


def test_a_pull_without_to_holds_and_takes_the_scenes_mouse_strength(tmp_path):
    s = scenes.load(write(tmp_path, HANG + """
        [interaction]
        mouse_strength = 77.0
        [[pull]]
        at = [0.5, 0.5]
    """))
    w = s.build()
    Script(s, w).advance(0.05)
    (g,) = w._grabs
    assert g.strength == 77.0 and g.target == (0.5, 0.5)


def test_a_world_run_for_a_while_skips_pulls_that_are_over(tmp_path):
    s = scenes.load(write(tmp_path, HANG + """
        [[pull]]
        at = [0.45, 0.0]
        release = 0.2
        [[pull]]
        at = [0.45, 0.0]
        start = 0.1
    """))
    w = s.build()
    for _ in range(int(0.5 / w.dt)):
        w.step()
    Script(s, w).advance(0.6)
    assert len(w._grabs) == 1  # the second, grabbed at once


def test_pulls_round_trip(tmp_path):
    p = write(tmp_path, HANG + """
        [[pull]]
        at = [0.45, 0.0]
        to = [1.5, -0.5]
        start = 0.25
        end = 1.0
        release = 1.5
        radius = 0.1
    """)
    s = scenes.load(p)
    again = scenes.load(deforma.save_scene(s.build(), tmp_path / "again.toml"))
    assert again.pull == s.pull and len(again.pull) == 1


def test_deforma_run_and_show_play_the_same_pull(tmp_path):
    # the same scene through the CLI's states and through deforma.show on a world: the same end
    from deforma.cli import main

    p = write(tmp_path, HANG + """
        [run]
        seconds = 0.5
        fps = 10
        [[pull]]
        at = [0.45, 0.0]
        to = [1.0, 0.3]
        start = 0.1
        end = 0.3
        radius = 0.1
        strength = 300.0
        [[event]]
        time = 0.2
        strength = 0.5
    """)
    assert main(["run", str(p), "--states", str(tmp_path / "s.npz"), "--quiet"]) == 0
    ran = np.load(tmp_path / "s.npz")["body0_positions"][-1]
    world = scenes.load_scene(p)
    Script(scenes.load(p), world).advance(0.4)  # the last of 5 frames at 10 fps
    np.testing.assert_allclose(ran, world.bodies[0].positions, atol=1e-12)
    assert np.abs(ran - scenes.load_scene(p).bodies[0].positions).max() > 0.1


def test_show_plays_pulls(gl_ctx, tmp_path):
    p = write(tmp_path, HANG + """
        [[pull]]
        at = [0.45, 0.0]
        to = [1.5, 0.0]
        end = 0.2
        radius = 0.1
        strength = 300.0
    """)
    world = scenes.load_scene(p)
    pulled = deforma.show(world, seconds=0.3, fps=10, size=64).last_frame
    assert not world._grabs and world.time == 0.0  # show animates a copy; the world is as it was
    still = deforma.show(scenes.load_scene(write(tmp_path, HANG, name="still.toml")), seconds=0.3, fps=10,
                         size=64).last_frame
    assert (pulled != still).any(axis=-1).sum() >= 10  # the pull moved the body in the picture


def test_states_of_a_body_that_tears_keep_the_numbering_with_nan_before_a_vertex_exists(tmp_path):
    from deforma.cli import main

    p = write(tmp_path, """
        [run]
        seconds = 1.0
        fps = 10
        [physics]
        gravity = [0, 0]
        integrator = "xpbd"
        tear_strain = 0.3
        [[body]]
        detail = 4
        pin = [[-0.6, -0.6], [-0.4, 0.6]]
        [[pull]]
        at = [0.45, 0.0]
        to = [3.0, 0.0]
        end = 0.5
        radius = 0.15
        strength = 5000.0
    """)
    assert main(["run", str(p), "--states", str(tmp_path / "s.npz"), "--quiet"]) == 0
    d = np.load(tmp_path / "s.npz")
    pos, counts = d["body0_positions"], d["body0_vertex_count"]
    assert counts[0] < counts[-1] == pos.shape[1] == len(d["body0_rest"])
    for k, n in enumerate(counts):
        assert np.isfinite(pos[k, :n]).all() and np.isnan(pos[k, n:]).all()

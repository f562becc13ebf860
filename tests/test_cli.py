"""The `deforma` command: outputs with the right frame counts, and one-line errors."""

import os
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from deforma import scene as scenes
from deforma.cli import EXIT_ERROR, EXIT_INTERRUPTED, EXIT_UNSTABLE, main
from signal_runs import kill_leftovers, signal_when_under_way

SMALL = ["--size", "96x64", "--quiet"]


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    # on a cold Numba cache a run first says it is compiling (tested on its own below); the
    # checks here are about what follows
    err = "".join(line for line in err.splitlines(True) if not line.startswith("deforma: compiling the physics"))
    return code, out, err


def test_scenes_lists_builtin_scenes_and_textures(capsys):
    code, out, err = run(capsys, "scenes")
    assert code == 0
    for name in scenes.builtin_scenes():
        assert f"  {name}  " in out or f"  {name} " in out
    for name in scenes.builtin_textures():
        assert name in out


def test_run_writes_mp4_with_the_expected_frames(tmp_path, capsys):
    import imageio_ffmpeg

    out = tmp_path / "s.mp4"
    code, stdout, err = run(capsys, "run", "sample", "--seconds", "0.5", "--fps", "20", "-o", str(out), *SMALL)
    assert code == 0, err
    frames = list(imageio_ffmpeg.read_frames(str(out)))
    assert len(frames) - 1 == 10 and tuple(frames[0]["size"]) == (96, 64)
    # the summary line: frames, simulated time, wall time, real-time factor
    assert stdout.startswith("sample: 10 frames, 0.45 s simulated in ") and "x real time" in stdout
    assert sorted(os.listdir(tmp_path)) == ["s.mp4"]


THROWN = """
[camera]
center = [0.0, 3.0]
size = [16.0, 9.0]
[[body]]
detail = 3
position = [0.0, 1.0]
[[event]]
time = 0.0
strength = 10.0
"""


def test_run_under_xpbd_with_too_few_substeps_says_how_many_hold_the_bodies(tmp_path, capsys):
    scene = tmp_path / "stand.toml"
    scene.write_text('[physics]\ndt = 0.016666666666666666\nintegrator = "xpbd"\n'
                     '[[body]]\nshape = "box"\ncorners = [[-0.5, 0], [0.5, 0], [0.5, 1], [-0.5, 1]]\ndetail = 28\n'
                     '[[collider]]\ncenter = [0, -0.2]\nsize = [3, 0.4]\n')
    code, _, err = run(capsys, "run", str(scene), "--seconds", "0.05")
    assert code == 0, err
    assert "note: under xpbd with substeps = 1 the bodies sag under their own weight" in err
    assert "raise substeps to 22 (world.xpbd_substeps())" in err
    scene.write_text(scene.read_text().replace('integrator = "xpbd"', 'integrator = "xpbd"\nsubsteps = 22'))
    code, _, err = run(capsys, "run", str(scene), "--seconds", "0.05")
    assert code == 0 and "note:" not in err, err


def test_run_writes_gif_with_the_expected_frames(tmp_path, capsys):
    # thrown up at 10 m/s, the box moves pixels every frame, so no two frames are alike
    # (a GIF stores identical neighbours once, with their durations added)
    scene = tmp_path / "thrown.toml"
    scene.write_text(THROWN)
    out = tmp_path / "s.gif"
    code, _, err = run(capsys, "run", str(scene), "--seconds", "0.4", "--fps", "25", "-o", str(out), *SMALL)
    assert code == 0, err
    im = Image.open(out)
    assert im.n_frames == 10 and im.size == (96, 64)
    total = 0
    for k in range(im.n_frames):
        im.seek(k)
        total += im.info["duration"]
    assert total == 400


def test_run_writes_png_frames_and_states(tmp_path, capsys):
    frames = tmp_path / "frames"
    states = tmp_path / "s.npz"
    code, _, err = run(capsys, "run", "sample", "--seconds", "0.3", "--fps", "10", "-o", f"{frames}/",
                       "--states", str(states), *SMALL)
    assert code == 0, err
    assert sorted(os.listdir(frames)) == [f"frame_{k:05d}.png" for k in range(3)]
    d = np.load(states)
    world = scenes.load_scene("sample")
    n = len(world.bodies[0].positions)
    assert d["body0_positions"].shape == (3, n, 2)
    np.testing.assert_allclose(d["time"], [0.0, 0.1, 0.2], atol=1e-9)
    np.testing.assert_allclose(d["body0_positions"][0], world.bodies[0].positions)
    np.testing.assert_array_equal(d["body0_triangles"], world.bodies[0].triangles)
    assert d["colliders"].shape == (1, 5)
    # the parameters come along as the scene file itself
    import tomllib

    doc = tomllib.loads(str(d["scene_toml"]))
    from dataclasses import replace

    sample = scenes.load("sample")
    assert scenes.parse_scene(doc) == replace(sample, run=replace(sample.run, seconds=0.3, fps=10.0))
    # the body fell: the last frame is lower than the first
    assert d["body0_positions"][-1][:, 1].mean() < d["body0_positions"][0][:, 1].mean() - 0.05


def test_run_without_output_only_simulates(capsys):
    code, out, _ = run(capsys, "run", "sample", "--seconds", "0.2", "--quiet")
    assert code == 0 and "frames" in out
    assert out.count("\n") == 1 and "nothing written: add -o sample.mp4" in out and "--states sample.npz" in out


def test_unknown_scene_lists_builtins(capsys):
    code, out, err = run(capsys, "run", "sampel", "--quiet")
    assert code == EXIT_ERROR and out == ""
    assert err.count("\n") == 1 and "unknown scene 'sampel'" in err and "sample" in err and "demo" in err


def test_invalid_scene_file_names_the_key(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("[physics]\ndt = 'x'\n")
    code, _, err = run(capsys, "run", str(bad), "--quiet")
    assert code == EXIT_ERROR and err.count("\n") == 1
    assert "bad.toml: physics.dt: expected a number" in err


def test_scene_with_overlapping_bodies_names_them_and_writes_nothing(tmp_path, capsys):
    p = tmp_path / "overlap.toml"
    p.write_text("[[body]]\ndetail = 3\nposition = [0, 2]\n\n[[body]]\ndetail = 3\nposition = [0.4, 2.5]\n")
    out = tmp_path / "o.gif"
    code, stdout, err = run(capsys, "run", str(p), "-o", str(out), *SMALL)
    assert code == EXIT_ERROR
    assert "body[1]: the new body (1) would overlap body 0" in err and err.count("\n") == 1
    assert sorted(os.listdir(tmp_path)) == ["overlap.toml"]


def test_missing_output_folder_is_reported_before_simulating(tmp_path, capsys, monkeypatch):
    import deforma.scene.schema as schema

    built = []
    monkeypatch.setattr(schema.Scene, "build", lambda self: built.append(1))
    for out in (tmp_path / "no" / "x.mp4", tmp_path / "no" / "frames/"):
        code, _, err = run(capsys, "run", "sample", "-o", str(out), "--quiet")
        assert code == EXIT_ERROR and "does not exist" in err and err.count("\n") == 1
    code, _, err = run(capsys, "run", "sample", "--states", str(tmp_path / "no" / "s.npz"), "--quiet")
    assert code == EXIT_ERROR and "does not exist" in err
    code, _, err = run(capsys, "run", "sample", "-o", str(tmp_path / "x.avi"), "--quiet")
    assert code == EXIT_ERROR and "allowed: .mp4, .gif" in err
    assert built == []


def test_unwritable_output_folder(tmp_path, capsys, monkeypatch):
    # root may write anywhere, so a read-only folder is simulated through os.access
    monkeypatch.setattr(os, "access", lambda path, mode: False)
    code, _, err = run(capsys, "run", "sample", "-o", str(tmp_path / "x.gif"), "--quiet")
    assert code == EXIT_ERROR and "is not writable" in err


UNSTABLE = """
[physics]
integrator = "symplectic-euler"
dt = 0.02
substeps = 1
stiffness = 50000.0
[[body]]
detail = 4
position = [0.0, 1.0]
[[collider]]
center = [0.0, 0.0]
size = [5.0, 0.5]
"""


def test_states_on_a_full_disk_keep_the_earlier_video_and_name_the_file(tmp_path, capsys, monkeypatch):
    import errno

    video, states = tmp_path / "v.mp4", tmp_path / "s.npz"
    video.write_bytes(b"earlier video")

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(np, "savez_compressed", full)
    code, _, err = run(capsys, "run", "sample", "--seconds", "0.2", "-o", str(video), "--states", str(states), *SMALL)
    assert code == EXIT_ERROR and err.count("\n") == 1
    assert f"{states}: could not be written: no space left on the device; nothing was written" in err
    assert video.read_bytes() == b"earlier video" and sorted(os.listdir(tmp_path)) == ["v.mp4"]


def test_unstable_simulation_fails_cleanly_and_writes_nothing(tmp_path, capsys):
    p = tmp_path / "boom.toml"
    p.write_text(UNSTABLE)
    out, states = tmp_path / "boom.gif", tmp_path / "boom.npz"
    code, _, err = run(capsys, "run", str(p), "-o", str(out), "--states", str(states), *SMALL)
    assert code == EXIT_UNSTABLE
    assert err.count("\n") == 1 and "became unstable" in err and "nothing was written" in err
    assert sorted(os.listdir(tmp_path)) == ["boom.toml"]


def test_interrupted_run_leaves_no_file(tmp_path, capsys, monkeypatch):
    from deforma.render import world_view

    calls = []
    real = world_view.WorldView.draw

    def draw(self, **kw):
        calls.append(1)
        if len(calls) == 4:
            raise KeyboardInterrupt
        return real(self, **kw)

    monkeypatch.setattr(world_view.WorldView, "draw", draw)
    out = tmp_path / "x.mp4"
    code, _, err = run(capsys, "run", "sample", "--seconds", "1", "-o", str(out), *SMALL)
    assert code == EXIT_INTERRUPTED and "interrupted" in err
    assert os.listdir(tmp_path) == []


def test_bad_options_are_usage_errors(capsys):
    with pytest.raises(SystemExit) as e:
        main(["run", "sample", "--size", "big"])
    assert e.value.code == 2
    assert "expected WIDTHxHEIGHT" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["run", "sample", "--fps", "-3"])
    # mesh box's --detail is checked by argparse like the other counts (exit 2, the flag named);
    # one too large for a body's points is refused by cmd_mesh in one line (tests/test_fuzz.py)
    for bad in ("-1", "x"):
        with pytest.raises(SystemExit) as e:
            main(["mesh", "box", "--detail", bad, "-o", "m.png"])
        assert e.value.code == 2 and "argument --detail" in capsys.readouterr().err


def test_mesh_picture_of_a_box(tmp_path, capsys):
    out = tmp_path / "box.png"
    code, stdout, err = run(capsys, "mesh", "box", "--detail", "3", "--edges", "-o", str(out), "--width", "300")
    assert code == 0, err
    # detail 3 with edges: a 5 x 5 grid of points, 2 * 4 * 4 triangles, right angles halved
    assert "25 points, 32 triangles, min angle 26.6" in stdout
    im = np.asarray(Image.open(out).convert("RGB"))
    assert im.shape[1] == 300
    assert sorted(os.listdir(tmp_path)) == ["box.png"]
    # side points are the default (as in mesh.box and scene files); --no-edges is the original's
    code, stdout, err = run(capsys, "mesh", "box", "--detail", "3", "-o", str(out), "--width", "300")
    assert code == 0 and "25 points, 32 triangles" in stdout, err
    code, stdout, err = run(capsys, "mesh", "box", "--detail", "3", "--no-edges", "-o", str(out), "--width", "300")
    assert code == 0 and "13 points" in stdout, err


def test_mesh_rejects_bad_output(tmp_path, capsys):
    code, _, err = run(capsys, "mesh", "box", "-o", str(tmp_path / "m.jpg"))
    assert code == EXIT_ERROR and "give a name ending in .png" in err


def test_the_installed_command_prints_one_line_and_no_traceback(tmp_path):
    exe = os.path.join(os.path.dirname(sys.executable), "deforma")
    r = subprocess.run([exe, "run", "no-such-scene"], capture_output=True, text=True, timeout=60)
    assert r.returncode == EXIT_ERROR
    assert r.stderr.startswith("deforma: error: unknown scene") and r.stderr.count("\n") == 1
    assert "Traceback" not in r.stderr
    r = subprocess.run([exe, "--debug", "run", "no-such-scene"], capture_output=True, text=True, timeout=60)
    assert r.returncode != 0 and "Traceback" in r.stderr


def test_ctrl_c_on_a_real_run_leaves_no_file(tmp_path):
    import signal

    from deforma.startup import COMPILE_MESSAGE

    exe = os.path.join(os.path.dirname(sys.executable), "deforma")
    # an MP4 and a GIF run at once, each in a folder of its own and signalled on its own clock
    # once under way (tests/signal_runs.py); a new session each, so the signal goes to the whole
    # group as Ctrl-C does (ffmpeg included)
    runs = []
    for name in ("out.mp4", "out.gif"):
        cwd = tmp_path / name.replace(".", "_")
        cwd.mkdir()
        runs.append((name, cwd, subprocess.Popen([exe, "run", "sample", "--seconds", "120", "--size", "64x48", "-o",
                                                  name, "--states", "s.npz", "--quiet"], cwd=cwd,
                                                 stderr=subprocess.PIPE, text=True, start_new_session=True)))
    try:
        signal_when_under_way([(cwd, p) for _, cwd, p in runs], lambda p: os.killpg(p.pid, signal.SIGINT))
        for name, cwd, p in runs:
            _, err = p.communicate(timeout=60)
            assert p.returncode == EXIT_INTERRUPTED, (name, err)
            # on a cold Numba cache (a fresh checkout, a changed kernel) the run first says it compiles
            assert err.replace(COMPILE_MESSAGE + "\n", "", 1) == "deforma: interrupted; no partial output was left\n"
            assert os.listdir(cwd) == [], name
    finally:
        kill_leftovers([p for _, _, p in runs])


def test_mesh_picture_of_a_builtin_texture(tmp_path, capsys):
    import deforma

    out = tmp_path / "bunny.png"
    code, stdout, err = run(capsys, "mesh", "bunny", "--resolution", "16", "--edge-step", "8", "-o", str(out),
                            "--width", "240")
    assert code == 0, err
    m = deforma.mesh.from_image("bunny", resolution=16, edge_step=8)
    assert f"{len(m.vertices)} points, {len(m.triangles)} triangles, min angle {m.min_angle:.1f}" in stdout
    img = np.asarray(Image.open(out).convert("RGB")).astype(int)
    # the picture is drawn under the mesh: the bunny's brown is there, not only the paper colour
    brownish = (img[..., 0] > img[..., 2] + 40) & (img[..., 0] < 230)
    assert brownish.mean() > 0.1


def test_version_prints_the_installed_version_and_exits_0(capsys):
    from importlib.metadata import version

    import deforma

    with pytest.raises(SystemExit) as e:
        main(["--version"])
    out, _ = capsys.readouterr()
    assert e.value.code == 0
    assert out.strip() == f"deforma {deforma.__version__}" and deforma.__version__ == version("deforma")


def test_springs_switch_runs_a_material_scene_with_the_original_springs(tmp_path, capsys):
    import tomllib

    assert scenes.load_scene("sample").bodies[0].is_fem  # shipped as finite elements
    states = tmp_path / "s.npz"
    code, _, err = run(capsys, "run", "sample", "--springs", "--seconds", "0.6", "--states", str(states), "--quiet")
    assert code == 0, err
    doc = tomllib.loads(str(np.load(states)["scene_toml"]))
    assert doc["physics"]["material"] == "springs" and "material" not in doc["body"][0]
    d = np.load(states)
    world = scenes.load_scene("sample")
    world.material = None  # what --springs makes of it: the same springs, stepped the same way
    for _ in range(int(round(d["time"][-1] / world.dt))):
        world.step()
    assert not world.bodies[0].is_fem
    np.testing.assert_allclose(d["body0_positions"][-1], world.bodies[0].positions, atol=1e-9)


TOPPLE = """[run]
seconds = 1.0
fps = 5
[physics]
dt = 0.016666666666666666
integrator = "implicit-bdf2"
material = "corotated"
youngs_modulus = 1e7
poisson_ratio = 0.3
density = 100.0
[[body]]
shape = "box"
corners = [[-0.123205, -0.186603], [0.223205, 0.013397], [0.123205, 0.186603], [-0.223205, -0.013397]]
detail = 6
position = [0.0, 1.0]
[[collider]]
center = [0.0, -0.25]
size = [6.0, 0.5]
"""


def test_a_physics_warning_is_one_line_of_the_commands_own(tmp_path, capsys):
    # a stiff block landing on its corner: a few substeps of the impact stop at max_iterations
    p = tmp_path / "topple.toml"
    p.write_text(TOPPLE)
    code, out, err = run(capsys, "run", str(p), "--quiet", "--states", str(tmp_path / "s.npz"))
    assert code == 0
    lines = [line for line in err.splitlines() if not line.startswith("deforma: compiling the physics")]
    assert lines == ["deforma: warning: the implicit solve stopped at max_iterations short of its tolerance in some "
                     "substeps (world.integrator_stats counts them): raise max_iterations or tolerance, or take "
                     "more substeps"]


@pytest.mark.parametrize("signame, code, said", [("SIGINT", 130, "interrupted"), ("SIGTERM", 143, "stopped by SIGTERM")])
def test_a_signal_while_the_package_loads_exits_with_the_shell_code_and_one_line(signame, code, said):
    # the console script starts in deforma_entry, which sets its handlers before importing the
    # package (half a second of NumPy, Numba and SciPy); the signal is sent from inside that import
    script = (
        "import builtins, os, signal, sys, time\n"
        "import deforma_entry\n"
        "real = builtins.__import__\n"
        "def importing(name, *args, **kwargs):\n"
        "    if name == 'deforma.cli':\n"
        f"        os.kill(os.getpid(), signal.{signame})\n"
        "        time.sleep(5)\n"
        "    return real(name, *args, **kwargs)\n"
        "builtins.__import__ = importing\n"
        "sys.argv = ['deforma', 'scenes']\n"
        "sys.exit(deforma_entry.main())\n"
    )
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert p.returncode == code, p.stderr
    assert p.stderr == f"deforma: {said} while starting; nothing was written\n" and p.stdout == ""


def test_the_console_script_starts_in_deforma_entry():
    from importlib.metadata import entry_points

    (script,) = [e for e in entry_points(group="console_scripts") if e.name == "deforma"]
    assert script.value == "deforma_entry:main"


def test_states_onto_a_folder_are_refused_before_the_run(tmp_path, capsys, monkeypatch):
    from deforma.scene import playback

    (tmp_path / "s.npz").mkdir()
    monkeypatch.setattr(playback.Playback, "frames", lambda *a, **k: pytest.fail("the run started"))
    code, _, err = run(capsys, "run", "sample", "--states", str(tmp_path / "s.npz"), *SMALL)
    assert code == EXIT_ERROR and err == f"deforma: error: {tmp_path / 's.npz'}: is a folder; give the states file's " \
                                         f"name, ending in .npz\n"

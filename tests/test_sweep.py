"""deforma sweep: six short runs of a tiny scene on one local Ray cluster shared by the module.

Ray's start-up (about 10 s here) dominates, so every test uses the same cluster (2 CPUs).
"""

import socket
import time

import numpy as np
import pytest

pytest.importorskip("ray")
pytest.importorskip("pyarrow")

import deforma.sweeps as sweeps  # noqa: E402
from signal_runs import kill_leftovers  # noqa: E402
from deforma.cli import main  # noqa: E402

TINY_SCENE = """
[run]
seconds = 0.3
fps = 10

[physics]
dt = 0.002
substeps = 1
integrator = "symplectic-euler"
material = "springs"
stiffness = 1000.0
damping = 1.0
mass = 1.0

[[body]]
shape = "box"
corners = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]
detail = 2
position = [0.0, 1.0]

[[collider]]
center = [0.0, 0.0]
size = [6.0, 0.4]
"""

# 3 stiffnesses x 2 positions; 1e9 N/m with symplectic Euler at dt = 2 ms blows up
SWEEP = """
scene = "tiny.toml"
seconds = 0.3

[parameters]
"physics.stiffness" = [500, 1000, 1e9]
"body[0].position" = [[0, 1], [1, 1]]
"""


@pytest.fixture(scope="module")
def cluster():
    import ray

    started = sweeps.connect(workers=2)
    yield
    if started:
        ray.shutdown()


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("sweep")
    (d / "tiny.toml").write_text(TINY_SCENE)
    return d


def _spec(folder, name, text):
    p = folder / name
    p.write_text(text)
    return p


def _rows(outdir):
    return sweeps.read_results(outdir).to_pylist()


@pytest.fixture(scope="module")
def done(cluster, folder):
    """The six runs, with states and GIFs, swept once for the tests that read the table."""
    spec = _spec(folder, "sweep.toml", SWEEP)
    out = folder / "out"
    result = sweeps.sweep(spec, out, states=True, video="gif", video_size=(160, 90))
    return spec, out, result


def test_one_row_per_run_unstable_marked_with_hint(done):
    spec, out, result = done
    assert (result.total, result.ran, result.ok, result.unstable, result.error) == (6, 6, 4, 2, 0)
    rows = _rows(out)
    assert len(rows) == 6 and len({r["run_id"] for r in rows}) == 6
    for r in rows:
        if r["physics.stiffness"] == 1e9:
            assert r["status"] == "unstable"
            assert "dt" in r["hint"] and r["states_path"] is None
        else:
            assert r["status"] == "ok", r["message"]
            assert r["steps"] == 150 and r["simulated_s"] == pytest.approx(0.3)
            assert np.isfinite(r["final_energy_j"]) and 0 <= r["max_spring_strain"] < 1
            # 0.3 s is too short for a dropped box to settle (tests below show one that does)
            assert np.isnan(r["time_to_rest_s"])
            # the box starts at the x of its position and falls onto the ground
            (cx, cy), = r["centroid"]
            assert cx == pytest.approx(r["body[0].position"][0], abs=0.05) and cy < 1.0


def test_states_reload(done):
    spec, out, _ = done
    for r in _rows(out):
        if r["status"] == "ok":
            with np.load(out / r["states_path"]) as z:
                positions = z["body0_positions"]
                assert positions.shape[0] == 4 and np.isfinite(positions).all()  # frames at 0, 0.1, 0.2, 0.3 s
                assert "physics.stiffness" not in str(z["scene_toml"])
                assert f"stiffness = {r['physics.stiffness']}" in str(z["scene_toml"])


def test_videos(done):
    from PIL import Image

    spec, out, _ = done
    for r in _rows(out):
        if r["status"] == "ok":
            assert r["video_path"] == f"videos/{r['run_id']}.gif"
            with Image.open(out / r["video_path"]) as gif:
                assert gif.size == (160, 90) and gif.n_frames == 4  # the states' frames: 0, 0.1, 0.2, 0.3 s
        else:
            assert r["video_path"] is None  # an unstable run's video is discarded, as its states
    assert sorted(p.name for p in (out / "videos").iterdir()) == sorted(
        f"{r['run_id']}.gif" for r in _rows(out) if r["status"] == "ok")


def test_states_name_a_texture_file_from_the_folder_they_are_kept_in(folder, tmp_path):
    # The NPZ is written in a temporary folder on the worker; its scene named the texture file
    # relative to that folder, so the scene did not load from OUTDIR/states/
    import tomllib
    from pathlib import Path

    from PIL import Image

    from deforma.scene.schema import parse_scene

    (folder / "pics").mkdir(exist_ok=True)
    Image.new("RGB", (8, 8), (200, 40, 40)).save(folder / "pics" / "red.png")
    (folder / "textured.toml").write_text(TINY_SCENE.replace("detail = 2\n", 'detail = 2\ntexture = "pics/red.png"\n'))
    spec = sweeps.load_spec(_spec(folder, "tex.toml", 'scene = "textured.toml"\nseconds = 0.3\n[parameters]\n'
                                                   '"physics.stiffness" = [1000]\n'))
    kept = tmp_path / "out" / "states"
    kept.mkdir(parents=True)
    row = sweeps.simulate(sweeps.scene_for(spec, {}, source="test"), states=str(kept))
    assert row["status"] == "ok", row["message"]
    (kept / "run.npz").write_bytes(row["states"])
    with np.load(kept / "run.npz") as z:
        doc = tomllib.loads(str(z["scene_toml"]))
    texture = doc["body"][0]["texture"]
    assert (kept / texture).resolve() == (folder / "pics" / "red.png").resolve()
    # the scene loads from where it is kept (parse_scene refuses a texture file that is not there)
    scene = parse_scene(doc, source="run.npz", base_dir=kept)
    assert Path(scene.body[0].texture).resolve() == (folder / "pics" / "red.png").resolve()


def test_video_mp4_in_process(folder):
    spec = sweeps.load_spec(_spec(folder, "one.toml", 'scene = "tiny.toml"\nseconds = 0.3\n[parameters]\n'
                                                   '"physics.stiffness" = [1000]\n'))
    row = sweeps.simulate(sweeps.scene_for(spec, {}, source="test"), video="mp4", video_size=(160, 90))
    assert row["status"] == "ok", row["message"]
    assert row["video"][4:8] == b"ftyp"  # an MP4 file's first box


def test_video_without_opengl_fails_that_run_only(folder, monkeypatch):
    """No OpenGL context (moderngl's EGL and default backends both refuse): the run's row is an
    error saying what to install; nothing raises, so the sweep goes on with the next run."""
    import moderngl

    def no_gl(**kwargs):
        raise Exception("eglGetDisplay failed")
    monkeypatch.setattr(moderngl, "create_standalone_context", no_gl)
    spec = sweeps.load_spec(_spec(folder, "one.toml", 'scene = "tiny.toml"\nseconds = 0.3\n[parameters]\n'
                                                   '"physics.stiffness" = [1000]\n'))
    row = sweeps.simulate(sweeps.scene_for(spec, {}, source="test"), video="mp4")
    assert row["status"] == "error" and row.get("video") is None and row["steps"] == 0
    assert row["message"].startswith("no video: cannot open a headless OpenGL 3.3 context (egl: eglGetDisplay failed")
    assert "libegl1" in row["message"] and "\n" not in row["message"]
    # without --video the same run is fine
    assert sweeps.simulate(sweeps.scene_for(spec, {}, source="test"))["status"] == "ok"


@pytest.mark.parametrize("video, size, message", [
    ("avi", (640, 360), r"video: expected one of mp4, gif .*'avi'"),
    ("mp4", (8, 360), r"video_size: .*\(8, 360\)"),
])
def test_bad_video_options_refused_before_anything_runs(folder, video, size, message):
    spec = _spec(folder, "sweep_v.toml", SWEEP)
    with pytest.raises(sweeps.SweepError, match=message):
        sweeps.sweep(spec, folder / "never_v", video=video, video_size=size)
    assert not (folder / "never_v").exists()


def test_second_invocation_runs_nothing(done):
    spec, out, _ = done
    t0 = time.perf_counter()
    again = sweeps.sweep(spec, out)
    assert (again.total, again.skipped, again.ran) == (6, 6, 0)
    assert len(_rows(out)) == 6
    assert time.perf_counter() - t0 < 5


def test_retry_failed_replaces_the_failed_rows(done):
    spec, out, _ = done
    again = sweeps.sweep(spec, out, retry_failed=True)
    assert (again.ran, again.unstable) == (2, 2)
    rows = _rows(out)
    assert len(rows) == 6 and sorted(r["status"] for r in rows).count("unstable") == 2


def test_a_sweep_cut_short_completes_without_duplicates(cluster, folder):
    spec = _spec(folder, "cut.toml", SWEEP)
    out = folder / "cut"
    sweeps.sweep(spec, out)
    parts = sorted((out / "results.parquet").glob("part-*.parquet"))
    for p in parts[:3]:  # as if the sweep had been killed with three runs in flight
        p.unlink()
    (out / "results.parquet" / ".part-x.123.partial.parquet").write_bytes(b"half a file")
    again = sweeps.sweep(spec, out)
    assert (again.skipped, again.ran) == (3, 3)
    rows = _rows(out)
    assert len(rows) == 6 and len({r["run_id"] for r in rows}) == 6


# 8 runs of 4 simulated seconds (about 0.2 s of wall time each): long enough to be stopped half-way
SLOW_SWEEP = """
scene = "tiny.toml"
seconds = 4.0

[parameters]
"physics.stiffness" = [500, 700, 1000, 1500]
"body[0].position" = [[0, 1], [1, 1]]
"""


def test_a_sweep_stopped_half_way_with_ctrl_c_and_restarted_completes_without_duplicates(cluster, folder):
    """`deforma sweep` in a process of its own (joined to the module's cluster, so no second
    start-up) gets SIGINT once its first rows are in the table: exit code 130, the finished runs
    kept; the same sweep again runs only the rest. (A kill without clean-up is the test above.)"""
    import os
    import signal
    import subprocess
    import sys

    import ray

    spec = _spec(folder, "slow.toml", SLOW_SWEEP)
    out = folder / "slow"
    parts = out / "results.parquet"
    p = subprocess.Popen([sys.executable, "-m", "deforma.cli", "sweep", str(spec), "-o", str(out), "--address",
                          ray.get_runtime_context().gcs_address, "--quiet"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.perf_counter() + 300  # a worker with a cold Numba cache compiles for a minute or more
        while not list(parts.glob("part-*.parquet")):
            assert p.poll() is None, p.communicate()
            assert time.perf_counter() < deadline, "no run finished within 300 s"
            time.sleep(0.02)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=30)
    finally:
        kill_leftovers([p])
    assert p.returncode == 130, err
    assert err.startswith("deforma: interrupted; ") and "the same command carries on" in err
    kept = {r["run_id"] for r in _rows(out)}
    assert 1 <= len(kept) < 8, "not stopped half-way"
    assert not [f for f in os.listdir(parts) if not f.startswith("part-")]  # no temporary file left
    again = sweeps.sweep(spec, out)
    assert (again.total, again.skipped, again.ran, again.ok) == (8, len(kept), 8 - len(kept), 8 - len(kept))
    rows = _rows(out)
    assert len(rows) == 8 and len({r["run_id"] for r in rows}) == 8
    assert kept <= {r["run_id"] for r in rows} and all(r["status"] == "ok" for r in rows)


def test_other_spec_refused_unless_force(done, folder):
    _, out, _ = done
    other = _spec(folder, "other.toml", SWEEP.replace("seconds = 0.3", "seconds = 0.2"))
    with pytest.raises(sweeps.SweepError, match="different sweep.*--force"):
        sweeps.sweep(other, out)
    assert len(_rows(out)) == 6  # nothing lost


@pytest.mark.parametrize("bounds", ['"physics.friction" = { min = 0, max = inf }',
                                    '"physics.friction" = { min = -inf, max = 1 }',
                                    '"physics.friction" = { min = 0, max = nan }',
                                    '"physics.friction" = { min = -1e308, max = 1e308 }',
                                    '"physics.friction" = { min = 0, max = 100000000000000000000000000000000000000000'
                                    '0000000000000000000000000000000000000000000000000000000000000000000000000000000000'
                                    '0000000000000000000000000000000000000000000000000000000000000000000000000000000000'
                                    '0000000000000000000000000000000000000000000000000000000000000000000000000000000000'
                                    '000000000000000000000000000000000000000000000000000 }',
                                    '"body[0].position" = { min = [0, 0], max = [1, inf] }'])
def test_a_range_that_cannot_be_drawn_from_is_named_before_anything_runs(folder, bounds):
    # random mode draws uniformly in [min, max]: an infinite end or width was a NumPy
    # OverflowError traceback; now one line, and nothing is written
    spec = _spec(folder, "inf.toml", f'scene = "tiny.toml"\nseconds = 0.3\nmode = "random"\nsamples = 2\n'
                                     f'[parameters]\n{bounds}\n')
    with pytest.raises(sweeps.SweepError, match=r"a range needs finite numbers .* min <= max and a finite width") as e:
        sweeps.sweep(spec, folder / "never_inf")
    assert "\n" not in str(e.value)
    assert not (folder / "never_inf").exists()


GRID_1000 = "[" + ", ".join(str(i / 1000) for i in range(1000)) + "]"


@pytest.mark.parametrize("text, message", [
    (f'[parameters]\n"physics.friction" = {GRID_1000}\n"physics.static_friction" = {GRID_1000}\n',
     r"^big\.toml: \[parameters\]: 1000000 combinations; a sweep file plans at most 10000 runs \(more: split"),
    ('mode = "random"\nsamples = 1000000\n[parameters]\n"physics.friction" = { min = 0.1, max = 0.9 }\n',
     r"^big\.toml: samples: 1000000 runs; a sweep file plans at most 10000 \(more: several files with other seeds"),
    ('mode = "random"\nsamples = 1' + "0" * 400 + '\n[parameters]\n"physics.friction" = { min = 0.1, max = 0.9 }\n',
     r"^big\.toml: samples: over 1e100 runs; a sweep file plans at most 10000"),
])
def test_a_plan_past_the_run_limit_is_refused_from_its_count_before_anything_is_built(folder, text, message):
    # a million runs planned for minutes (300-500 MB) before the first one started (issue 51);
    # now the count alone is refused, quickly and in little memory, and nothing is written
    import tracemalloc

    spec = _spec(folder, "big.toml", 'scene = "tiny.toml"\nseconds = 0.3\n' + text)
    sweeps.load_spec(_spec(folder, "small.toml", SWEEP))  # the scene loader imported: not measured
    tracemalloc.start()
    try:
        start = time.perf_counter()
        with pytest.raises(sweeps.SweepError, match=message) as e:
            sweeps.sweep(spec, folder / "never_big")
        seconds = time.perf_counter() - start
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert "\n" not in str(e.value)
    assert seconds < 1.0 and peak < 5e6, (seconds, peak)
    assert not (folder / "never_big").exists()


def test_the_run_limit_is_inclusive(folder, monkeypatch):
    monkeypatch.setattr(sweeps, "MAX_RUNS", 6)
    assert len(sweeps.plan(sweeps.load_spec(_spec(folder, "six.toml", SWEEP)))) == 6  # 3 x 2
    eight = SWEEP.replace("[500, 1000, 1e9]", "[500, 1000, 1e9, 2000]")
    with pytest.raises(sweeps.SweepError, match=r"8 combinations; a sweep file plans at most 6 runs"):
        sweeps.load_spec(_spec(folder, "eight.toml", eight))
    random = ('scene = "tiny.toml"\nseconds = 0.3\nmode = "random"\nsamples = {}\n[parameters]\n'
              '"physics.friction" = {{ min = 0.1, max = 0.9 }}\n')
    assert len(sweeps.plan(sweeps.load_spec(_spec(folder, "r6.toml", random.format(6))))) == 6
    with pytest.raises(sweeps.SweepError, match=r"samples: 7 runs; a sweep file plans at most 6"):
        sweeps.load_spec(_spec(folder, "r7.toml", random.format(7)))


@pytest.mark.parametrize("text, message", [
    ('mode = "random"\nsamples = 2\n[parameters]\n"physics.friction" = { min = 0, max = inf }\n',
     "a range needs finite numbers"),
    ('mode = "random"\nsamples = 1000000\n[parameters]\n"physics.friction" = { min = 0.1, max = 0.9 }\n',
     "samples: 1000000 runs; a sweep file plans at most 10000"),
    # past Python's 4300 digits the TOML reader's own int() refuses it, in its words and without the file
    ('mode = "random"\nsamples = -1' + "0" * 5000 + '\n', "invalid TOML: an integer of more than 4300 digits"),
])
def test_cli_refuses_a_bad_plan_in_one_line_writing_nothing(folder, capsys, text, message):
    spec = _spec(folder, "bad_plan.toml", 'scene = "tiny.toml"\nseconds = 0.3\n' + text)
    assert main(["sweep", str(spec), "-o", str(folder / "never_cli")]) == 1
    captured = capsys.readouterr()
    assert captured.err.startswith("deforma: error: ") and "bad_plan.toml: " in captured.err and message in captured.err
    assert captured.err.count("\n") == 1 and "Traceback" not in captured.err and captured.out == ""
    assert not (folder / "never_cli").exists()


@pytest.mark.parametrize("parameters, message", [
    ('"physics.stifness" = [1, 2]', r"physics\.stifness: unknown key; did you mean 'stiffness'"),
    ('"phyiscs.stiffness" = [1, 2]', r"phyiscs\.stiffness: unknown table 'phyiscs'; did you mean 'physics'"),
    ('"body[3].position" = [[0, 1]]', r"the scene has 1 \[\[body\]\] table"),
    ('"physics.stiffness" = []', r'"physics.stiffness": empty list'),
    ('"physics.stiffness" = [100, -5]', r"run 1 \(\w+\): physics\.stiffness: .*-5"),
    ('"physics.stiffness" = { min = 1, max = 2 }', r"range .* needs mode = \"random\""),
])
def test_bad_parameters_named_before_anything_runs(folder, parameters, message):
    spec = _spec(folder, "bad.toml", f'scene = "tiny.toml"\nseconds = 0.3\n[parameters]\n{parameters}\n')
    with pytest.raises(sweeps.SweepError, match=message) as e:
        sweeps.sweep(spec, folder / "never")
    assert "\n" not in str(e.value)
    assert not (folder / "never").exists()


def test_random_mode_is_reproducible(folder):
    text = ('scene = "tiny.toml"\nseconds = 0.3\nmode = "random"\nsamples = 5\nseed = 7\n[parameters]\n'
            '"physics.friction" = { min = 0.1, max = 0.9 }\n"body[0].position" = { min = [-1, 1], max = [1, 2] }\n'
            '"physics.stiffness" = [500, 1000]\n')
    spec = sweeps.load_spec(_spec(folder, "random.toml", text))
    runs = sweeps.plan(spec)
    assert [r.parameters for r in runs] == [r.parameters for r in sweeps.plan(spec)]
    assert len(runs) == 5 and all(0.1 <= r.parameters["physics.friction"] <= 0.9 for r in runs)
    assert all(r.parameters["physics.stiffness"] in (500, 1000) for r in runs)


# the tiny box, but with implicit Euler and strong damping: it lands at about 0.25 s and settles
# within a second; the event throws it up only when a run sets its time below the run's end
REST_SCENE = TINY_SCENE.replace('"symplectic-euler"', '"implicit-euler"').replace("damping = 1.0", "damping = 20.0") + """
[[event]]
time = 100.0
action = "explode"
"""


@pytest.mark.parametrize("parameters, rests", [
    ({"physics.gravity": [0.0, 0.0]}, (0.0, 0.0)),      # still from the first frame
    ({}, (0.3, 1.5)),                                   # lands, bounces, settles
    ({"body[0].position": [0.0, 100.0]}, None),         # falls for the whole run
    ({"event[0].time": 1.5}, None),                     # settles, then thrown up half a second before the end
])
def test_time_to_rest(folder, parameters, rests):
    (folder / "rest.toml").write_text(REST_SCENE)
    spec = sweeps.load_spec(_spec(folder, "rest_sweep.toml", 'scene = "rest.toml"\nseconds = 2.0\n[parameters]\n'
                                                          '"physics.stiffness" = [1000]\n'))
    row = sweeps.simulate(sweeps.scene_for(spec, parameters, source="test"))
    assert row["status"] == "ok", row["message"]
    if rests is None:
        assert np.isnan(row["time_to_rest_s"])
    else:
        assert rests[0] <= row["time_to_rest_s"] <= rests[1]


def test_unreachable_address_fails_fast():
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    t0 = time.perf_counter()
    with pytest.raises(sweeps.SweepError, match=f"cannot reach a Ray cluster at 127.0.0.1:{port}"):
        sweeps._check_reachable(f"127.0.0.1:{port}")
    assert time.perf_counter() - t0 < 30


@pytest.mark.parametrize("address", [
    "1.2.3.4:\u00b2",                          # isdigit() but no int(): a ValueError of int()'s own
    "127.0.0.1:0", "127.0.0.1:65536",          # no such port (the resolver wrapped 65536 + P to P)
    "127.0.0.1:99999999999999999999",          # an OverflowError traceback from the resolver
    "127.0.0.1:" + "1" * 5000,                 # past int()'s 4300 digits
    "a" * 64 + ".example:6379", "x..y:6379",   # labels the resolver's IDNA codec refuses (UnicodeError)
    "bad\nhost:6379",                          # a line break would make the message two lines
], ids=["superscript", "port 0", "port 65536", "20 digits", "5000 digits", "long label", "empty label",
        "line break"])
def test_an_address_that_is_no_host_and_port_is_refused_at_once_in_one_line(address):
    t0 = time.perf_counter()
    with pytest.raises(sweeps.SweepError, match=r"^--address .*: expected HOST:PORT .*a port in 1-65535") as e:
        sweeps._check_reachable(address)
    assert "\n" not in str(e.value) and time.perf_counter() - t0 < 1


@pytest.mark.parametrize("address", ["garbage", "unreachable", "127.0.0.1:99999999999999999999"])
@pytest.mark.parametrize("existed", [False, True])
def test_a_failed_address_leaves_nothing_behind(folder, tmp_path, address, existed):
    """`deforma sweep --address` that cannot connect: one line, exit 1, no traceback, and no
    folder made (the table's folder was made before the connection and left behind); a folder
    that was there stays, as it was. In a process of its own: this one may hold the module's
    cluster, and then an address is not looked at."""
    import os
    import subprocess
    import sys

    expected = None if address == "unreachable" else "expected HOST:PORT"
    address = f"127.0.0.1:{_free_port()}" if address == "unreachable" else address
    spec = _spec(folder, "address.toml", SWEEP)
    if existed:
        (tmp_path / "out").mkdir()
    out = tmp_path / "out" / "res"
    env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "deforma.cli", "sweep", str(spec), "-o", str(out), "--address", address,
                        "--states", "--video", "gif", "--quiet"], capture_output=True, text=True, env=env, timeout=120)
    assert time.perf_counter() - t0 < 60
    assert r.returncode == 1 and r.stdout == "", (r.stdout, r.stderr)
    assert r.stderr.startswith("deforma: error: ") and r.stderr.count("\n") == 1, r.stderr
    assert "Traceback" not in r.stderr
    assert (expected or f"cannot reach a Ray cluster at {address}") in r.stderr
    assert sorted(os.listdir(tmp_path)) == (["out"] if existed else [])
    assert not existed or os.listdir(tmp_path / "out") == []


def test_cli(done, folder, capsys):
    spec, out, _ = done
    assert main(["sweep", str(spec), "-o", str(out), "--quiet", "--video", "gif", "--video-size", "160x90"]) == 0
    assert "6 runs, 6 already in the table, 0 run now" in capsys.readouterr().out
    bad = _spec(folder, "bad_cli.toml", 'scene = "tiny.toml"\nseconds = 0.3\n[parameters]\n"physics.stifness" = [1]\n')
    assert main(["sweep", str(bad), "-o", str(folder / "never")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("deforma: error: ") and "did you mean 'stiffness'" in err and err.count("\n") == 1


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_sweep_on_a_cluster_started_with_ray_start(folder):
    """`ray start --head` on a free port, then `deforma sweep --address` in its own process
    (this process already holds the module's local cluster)."""
    import os
    import signal
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    port = _free_port()
    ray_exe = Path(sys.executable).with_name("ray")
    head = subprocess.Popen([str(ray_exe), "start", "--head", f"--port={port}", "--node-ip-address=127.0.0.1",
                             "--num-cpus=2", "--include-dashboard=false", "--disable-usage-stats", "--block"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        deadline = time.perf_counter() + 30
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                assert time.perf_counter() < deadline, "ray start --head did not listen within 30 s"
                assert head.poll() is None, "ray start --head exited"
                time.sleep(0.2)
        env = dict(os.environ)
        if (Path.home() / ".ray" / "auth_token").exists():  # Ray >= 2.59 turns on token auth for `ray start`
            env.setdefault("RAY_AUTH_MODE", "token")
        spec = _spec(folder, "remote.toml", SWEEP)
        out = folder / "remote"
        r = subprocess.run([sys.executable, "-m", "deforma.cli", "sweep", str(spec), "-o", str(out), "--address",
                            f"127.0.0.1:{port}", "--states"], capture_output=True, text=True, env=env, timeout=180)
        assert r.returncode == 0, r.stderr
        assert "6 runs, 0 already in the table, 6 run now (4 ok, 2 unstable, 0 error)" in r.stdout
        rows = _rows(out)
        assert len(rows) == 6
        assert all(r["status"] == ("unstable" if r["physics.stiffness"] == 1e9 else "ok") for r in rows)
        for row in rows:
            if row["status"] == "ok":
                with np.load(out / row["states_path"]) as z:
                    assert np.isfinite(z["body0_positions"]).all()
    finally:
        # the head and everything it started are in the session this test made: end that group
        # (a graceful stop waits on a drain that can time out, so the group is killed after 3 s)
        try:
            os.killpg(head.pid, signal.SIGTERM)
            try:
                head.wait(timeout=3)
            except subprocess.TimeoutExpired:
                pass
            os.killpg(head.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        head.wait(timeout=10)
        # what `ray stop` would do: forget the killed head, so a later bare ray.init() does not try it
        current = Path(tempfile.gettempdir()) / "ray" / "ray_current_cluster"
        if current.exists() and current.read_text().strip().endswith(f":{port}"):
            current.unlink()

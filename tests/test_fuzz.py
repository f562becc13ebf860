"""Fuzz: hostile scene values and small random pictures get a clear one-line error or a
sound result, never another exception (issue 17: the next class of bad input is found by the
suite, not by a user)."""

import math

import numpy as np
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import deforma
from deforma.physics.elements.triangles import signed_areas
from deforma.scene.build import build
from deforma.scene.schema import SceneError, parse_scene

PHYSICS_KEYS = ["dt", "substeps", "gravity", "damping", "mass", "stiffness", "friction", "static_friction",
                "max_speed", "integrator", "integrator_options", "contact_thickness", "air_drag", "sleep", "material",
                "youngs_modulus", "poisson_ratio", "density", "material_damping", "plane", "tear_strain",
                "yield_strain", "plastic_rate", "max_stretch"]
BODY_KEYS = ["mass", "stiffness", "damping", "material", "youngs_modulus", "poisson_ratio", "density",
             "material_damping", "plane", "tear_strain", "yield_strain", "plastic_rate", "max_stretch", "pressure",
             "collide", "self_collision", "friction", "static_friction", "angle", "velocity", "angular_velocity",
             "pin", "pin_vertices", "shape", "corners", "detail", "edges", "position", "color", "texture"]
COLLIDER_KEYS = ["shape", "center", "size", "angle", "friction", "static_friction", "velocity", "angular_velocity",
                 "color"]
CAMERA_KEYS = ["center", "size", "wireframe", "follow", "background"]
INTERACTION_KEYS = ["explosive_force", "mouse_strength"]
RUN_KEYS = ["seconds", "fps"]
EVENT_KEYS = ["time", "action", "strength"]
PULL_KEYS = ["at", "to", "start", "end", "release", "radius", "strength"]
JOINT_KEYS = ["a", "b", "at", "kind", "stiffness", "damping", "motor_speed", "max_torque", "break_force"]

hostile = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**20, 10**20),
                    st.sampled_from([0, -1, 1e-300, 1e300, 1e-7, 2, 10**9, 10**400, -10**400]), st.booleans(),
                    st.text(max_size=6), st.dictionaries(st.text(max_size=3), st.integers(-2, 2), max_size=2))
sane = st.one_of(st.floats(1e-3, 1e3), st.integers(1, 12), st.sampled_from([0.0, 0.3, 0.5, 1.05, 1 / 600]))
pairs = st.lists(st.one_of(sane, st.floats(-5, 5)), min_size=2, max_size=2)
INTEGRATORS = ["symplectic-euler", "implicit-euler", "implicit-bdf2", "xpbd", "avbd"]
MATERIALS = ["springs", "corotated", "neo-hookean", "rigid", "jelly", "rubber", "wood"]
names = st.sampled_from(INTEGRATORS + MATERIALS)
PAIR_KEYS = {"gravity", "position", "center", "size", "velocity", "at", "to"}
NAME_KEYS = {"integrator", "material"}
SWITCH_KEYS = {"collide", "self_collision", "edges", "sleep", "wireframe"}
#: every integrator's options, as [physics.integrator_options] takes them (the names the integrators list)
OPTION_VALUES = {
    "iterations": st.integers(1, 12), "max_iterations": st.integers(1, 50), "order": st.integers(1, 2),
    "rigid_passes": st.integers(1, 6), "cluster_size": st.sampled_from([0, 1, 4, 64, 10**6]),
    "tolerance": st.sampled_from([0.0, 1e-3, 1.0, 1e5]), "contact_weight": st.sampled_from([1e-3, 10.0, 1e12]),
    "reach": st.sampled_from([0.0, 0.5, 5.0]), "chebyshev": st.sampled_from([0.0, 0.5, 0.99]),
    "penalty_start": st.sampled_from([1e-6, 1.0, 1e6]), "penalty_ramp": st.sampled_from([0.0, 1e5, 1e12]),
    "penalty_max": st.sampled_from([1.0, 1e10, 1e17]), "mode": st.sampled_from(["auto", "serial", "parallel"]),
    "start": st.sampled_from(["velocity", "rigid"]),
}
#: values of the right kind for the keys that are neither numbers, pairs, names nor switches
KIND_VALUES = {
    "plane": st.sampled_from(["stress", "strain"]),
    "shape": st.sampled_from(["box", "mesh", "image", "rect", "circle", "segment", "polygon"]),
    "color": st.sampled_from(["#e07a5f", "#E07A5F80", "#zzzzzz", "red", "#fff"]),
    "texture": st.sampled_from(["bunny", "cloth", "donut", "no-such-picture.png", ""]),
    "background": st.lists(st.sampled_from(["#dbe8f5", "#000000", "#ABCDEF80", "white"]), min_size=2, max_size=2),
    "pin": st.lists(pairs, min_size=2, max_size=2),
    "pin_vertices": st.lists(st.integers(-2, 40), max_size=4),
    "corners": st.lists(pairs, min_size=4, max_size=4),
    "follow": st.sampled_from([0, 1, 2, -1, 10**9, True, 0.0, 1.5]),
    "a": st.sampled_from([0, 1, 2, -1, True, 0.0]), "b": st.sampled_from([0, 1, 2, -1, False, 1.0]),
    "kind": st.sampled_from(["pin", "weld", "spring", "motor", "hinge"]),
    "action": st.sampled_from(["explode", "implode"]),
    "time": st.sampled_from([0.0, 0.02, 0.05, 1.0]), "start": st.sampled_from([0.0, 0.02, 0.05]),
    "end": st.sampled_from([0.0, 0.03, 0.1]), "release": st.sampled_from([0.0, 0.04, 0.2]),
    "motor_speed": st.one_of(st.floats(-1e3, 1e3), st.sampled_from([0.0, 1e6, -1e6, 1e7])),
    "angle": st.one_of(st.floats(-360, 360), st.sampled_from([720.0, 1e6])),
    "angular_velocity": st.one_of(st.floats(-720, 720), st.sampled_from([1e6, 1e9])),
}


@st.composite
def integrator_options(draw, integrator, least=0):
    """``least`` to three options: of ``integrator`` (its own names) but one time in six another's or an unknown
    name; each value of its kind, or (one time in four) hostile."""
    from deforma.physics.integrators import make_integrator

    own = [o.name for o in type(make_integrator(integrator)).OPTIONS]
    names = st.integers(0, 5).flatmap(lambda k: st.sampled_from(own) if k else
                                      st.sampled_from([*OPTION_VALUES, "itertions", ""]))
    keys = draw(st.lists(names, min_size=least, max_size=3, unique=True))
    return {k: draw(hostile if draw(st.integers(0, 3)) == 0 or k not in OPTION_VALUES else OPTION_VALUES[k])
            for k in keys}


@st.composite
def settings_for(draw, keys, most):
    """Up to ``most`` of ``keys``, each with a value of its kind, or (one time in four) a hostile one."""
    out = {}
    for key in draw(st.lists(st.sampled_from(keys), max_size=most, unique=True)):
        if draw(st.integers(0, 3)) == 0:
            out[key] = draw(st.one_of(hostile, st.lists(hostile, max_size=3)))
        elif key == "integrator_options":
            integrator = out.get("integrator")
            out[key] = draw(integrator_options(integrator if integrator in INTEGRATORS else "avbd"))
        elif key in KIND_VALUES:
            out[key] = draw(KIND_VALUES[key])
        elif key in PAIR_KEYS:
            out[key] = draw(pairs)
        elif key in NAME_KEYS:
            out[key] = draw(names)
        elif key in SWITCH_KEYS:
            out[key] = draw(st.booleans())
        else:
            out[key] = draw(sane)
    return out


def one_line(e: Exception) -> None:
    text = str(e)
    assert text and "\n" not in text and "Traceback" not in text, text


def _load_build_and_step(data):
    """parse_scene, build and five steps with the scene's events and pulls played: a one-line SceneError,
    ValueError (what needs the built bodies) or SimulationUnstable (the world put back), or a sound world."""
    from deforma.scene.script import Script

    try:
        scene = parse_scene(data, source="fuzz.toml")
    except SceneError as e:
        event("refused by the loader")
        one_line(e)
        assert str(e).startswith("fuzz.toml: "), str(e)
        return None
    try:
        world = build(scene)
    except ValueError as e:  # checks that need the built bodies (overlaps, meshes)
        event("refused when built")
        one_line(e)
        return None
    try:
        script = Script(scene, world)
        for _ in range(5):
            script.apply()
            world.step()
    except deforma.SimulationUnstable as e:
        event("reported unstable")
        one_line(e)
        assert e.hint and np.isfinite(world.state.x).all()  # put back as it was
        return world
    event("ran")
    assert np.isfinite(world.state.x).all()
    return world


@settings(max_examples=250, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(physics=settings_for(PHYSICS_KEYS, 3), body=settings_for(BODY_KEYS, 2),
       collider=settings_for(COLLIDER_KEYS, 1), camera=st.just({}) | settings_for(CAMERA_KEYS, 1),
       interaction=st.just({}) | settings_for(INTERACTION_KEYS, 1), run=st.just({}) | settings_for(RUN_KEYS, 1),
       events=st.lists(settings_for(EVENT_KEYS, 3), max_size=1), pulls=st.lists(settings_for(PULL_KEYS, 3), max_size=1))
def test_hostile_scene_values_are_refused_in_one_line_or_run(physics, body, collider, camera, interaction, run, events,
                                                             pulls):
    data = {"physics": physics, "body": [{"shape": "box", "detail": 2, **body}],
            "collider": [{"center": [0.0, -0.5], "size": [4.0, 1.0], **collider}],
            "camera": camera, "interaction": interaction, "run": run}
    if events:
        data["event"] = events
    if pulls:
        data["pull"] = [{"at": [0.0, 0.0], **p} for p in pulls]  # on the box, unless the pull says otherwise
    _load_build_and_step(data)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(integrator=st.integers(0, 7).flatmap(lambda k: st.sampled_from(INTEGRATORS) if k else hostile),
       data=st.data())
def test_hostile_integrator_options_are_refused_in_one_line_or_run(integrator, data):
    # each integrator's options (avbd's iterations to rigid_passes and mode, implicit-euler's and implicit-bdf2's
    # tolerance, max_iterations, contact_weight, xpbd's iterations, symplectic-euler's mode) on a soft box under
    # a rigid one
    options = data.draw(integrator_options(integrator if integrator in INTEGRATORS else "avbd", least=1))
    scene = {"physics": {"integrator": integrator, "integrator_options": options},
             "body": [{"shape": "box", "detail": 2, "position": [0.0, 0.6]},
                      {"shape": "box", "detail": 1, "position": [0.0, 1.8], "material": "rigid", "density": 50.0}],
             "collider": [{"center": [0.0, -0.5], "size": [4.0, 1.0]}]}
    _load_build_and_step(scene)


#: the keys that go with each kind of joint (a spring's stiffness and damping, a pin's motor)
JOINT_KIND_KEYS = {"pin": ["motor_speed", "max_torque", "break_force"], "weld": ["break_force"],
                   "spring": ["stiffness", "damping", "break_force"]}


@st.composite
def joint_tables(draw):
    """One or two [[joint]] tables on the two boxes below, where they touch: a kind and some of its own keys,
    plus up to two of any joint keys (a, b and at too), each of its kind or (one time in four) hostile."""
    out = []
    for _ in range(draw(st.integers(1, 2))):
        kind = draw(st.sampled_from(list(JOINT_KIND_KEYS)))
        joint = {"a": 0, "b": 1, "at": [0.5, draw(st.sampled_from([1.0, 0.8, 1.4]))], "kind": kind}
        if draw(st.booleans()):
            del joint["b"]  # held to the world
        joint.update(draw(settings_for(JOINT_KIND_KEYS[kind], 3)))
        joint.update(draw(settings_for(JOINT_KEYS, 2)))
        out.append(joint)
    return out


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(joints=joint_tables(), second=st.sampled_from([{"material": "rigid", "density": 80.0}, {},
                                                     {"material": "jelly"}, {"material": "rigid"}]),
       integrator=st.sampled_from(["avbd", "avbd", "symplectic-euler", "implicit-bdf2", "xpbd"]))
def test_hostile_joints_are_refused_in_one_line_or_run(joints, second, integrator):
    # a rigid box beside a second box (rigid, springs, a jelly, or rigid without a density), joined where they touch
    data = {"physics": {"integrator": integrator},
            "body": [{"shape": "box", "detail": 1, "position": [0.0, 1.0], "material": "rigid", "density": 100.0},
                     {"shape": "box", "detail": 2, "position": [1.0, 1.0], **second}],
            "collider": [{"center": [0.0, -0.5], "size": [4.0, 1.0]}], "joint": joints}
    world = _load_build_and_step(data)
    if world is not None:
        assert len(world.joints) <= len(joints)  # made, or broken by its break_force
        for j in world.joints:
            assert np.isfinite(j.force).all() and math.isfinite(j.torque)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(1, 8), st.integers(1, 8), st.integers(1, 6), st.integers(0, 2**32 - 1), st.floats(0.05, 0.95),
       st.sampled_from(["black", "white", "auto"]))
def test_small_random_pictures_mesh_into_a_manifold_or_a_clear_error(h, w, cell, seed, fill, background):
    # random blocks of cell x cell pixels: blobs, bars, holes, pinches and specks
    rng = np.random.default_rng(seed)
    ink = np.kron(rng.random((h, w)) < fill, np.ones((cell, cell), bool))
    ink = np.pad(ink, 1)  # a border of background (a picture whose border is ink is its own case)
    base, pen = (255, 0) if background == "white" else (0, 255)
    grey = np.where(ink, pen, base).astype(np.uint8)
    rgb = np.repeat(grey[:, :, None], 3, axis=2)
    try:
        m = deforma.mesh.from_image(rgb, resolution=1, scale=0.01, background=background)
    except ValueError as e:
        event("picture refused")
        one_line(e)
        return
    event("meshed")
    t = m.triangles
    assert (signed_areas(m.vertices, t) > 0).all()
    # every edge in one or two triangles; every boundary vertex on exactly one outline run
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    assert counts.max() <= 2
    b = m.boundary_edges
    assert np.array_equal(np.bincount(b[:, 0], minlength=len(m.vertices)),
                          np.bincount(b[:, 1], minlength=len(m.vertices)))
    assert np.bincount(b[:, 0], minlength=len(m.vertices)).max() <= 1
    assert math.isfinite(m.area) and m.area > 0


# -- issue 51: hardening, round three -------------------------------------------------------------
# Each case was tried as a user would; these are the ones that still failed, one test each.
import io  # noqa: E402
import os  # noqa: E402
import re  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import pytest  # noqa: E402

#: Peak memory of a run refused up front (MB): start-up only, far below any video's buffers.
REFUSED_PEAK_MB = 400


def _lying_png_bytes(width: int, height: int) -> bytes:
    """A PNG whose header says width x height and whose data holds one white row, ending cleanly."""
    import struct
    import zlib

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(b"\x00" + b"\xff" * 3 * width)) + chunk(b"IEND", b""))


def _peak_of(args, cwd, timeout=60):
    """Run ``args`` in a child; (returncode, stderr, the largest peak RSS of it or any of its children in MB)."""
    code = ("import resource, subprocess, sys\n"
            "r = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
            "sys.stderr.write(r.stderr)\n"
            "print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024)")
    r = subprocess.run([sys.executable, "-c", code, *map(str, args)], capture_output=True, text=True,
                       timeout=timeout, cwd=cwd)
    rc, peak = r.stdout.split()
    return int(rc), r.stderr, float(peak)


def test_a_lying_png_opened_from_memory_is_refused_before_a_pixel_is_decoded():
    # Image.open(BytesIO(...)) has no file name: it was decoded as 6000 x 6000 and meshed (1.97 GB, 12 s)
    from PIL import Image

    picture = Image.open(io.BytesIO(_lying_png_bytes(6000, 6000)))
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"image file is truncated: its header says 6000x6000 pixels") as e:
        deforma.mesh.from_image(picture)
    one_line(e.value)
    assert time.perf_counter() - t0 < 2
    code = ("import io, resource, sys, deforma\nfrom PIL import Image\n"
            "im = Image.open(io.BytesIO(sys.stdin.buffer.read()))\n"
            "before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss\n"
            "try:\n    deforma.mesh.from_image(im)\nexcept ValueError:\n    pass\n"
            "print((resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024)")
    r = subprocess.run([sys.executable, "-c", code], input=_lying_png_bytes(6000, 6000), capture_output=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    assert float(r.stdout) < 50, f"peak memory grew by {r.stdout.decode().strip()} MB"


def test_a_box_of_high_detail_is_meshed_in_about_linear_time():
    # the symmetric re-split of its cells scanned every triangle per cell: 18 s at detail 300,
    # 63 s at 400, about half an hour at the largest detail (1000), before a run could start
    corners = ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5))
    deforma.mesh.box(corners, detail=4)  # compiled kernels loaded before the clock starts
    t0 = time.perf_counter()
    m = deforma.mesh.box(corners, detail=300)
    assert time.perf_counter() - t0 < 8  # 2.3 s here; 18 s before
    assert len(m.vertices) == 302**2 and len(m.triangles) == 2 * 301**2


def test_export_onto_a_full_disk_names_the_folder_and_leaves_nothing(tmp_path, capsys, monkeypatch):
    import errno

    import deforma.mesh.export
    from deforma.cli import EXIT_ERROR, main

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(deforma.mesh.export, "write_meshes", full)
    target = tmp_path / "frames"
    code = main(["run", "sample", "--seconds", "0.1", "--export", str(target)])
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("deforma: compiling")]
    assert code == EXIT_ERROR and len(lines) == 1 and "Traceback" not in err, err
    assert lines[0] == (f"deforma: error: --export {target}: could not be written: no space left on the device; "
                        f"nothing was written")
    assert os.listdir(tmp_path) == []  # neither the folder nor its hidden temporary one


@pytest.mark.parametrize("args, names", [
    (["--size", "7680x4320", "--overlay", "-o", "o.mp4"], ["a 7680x4320 MP4", "ffmpeg's H.264 encoder"]),
    (["--size", "7680x4320", "--fps", "240", "-o", "o.gif"], ["GIF of 960 frames", "kept until the end"]),
    (["--seconds", "30", "--size", "1920x1080", "-o", "o.gif"], ["GIF of 900 frames", ".mp4", "at most"]),
])
def test_a_render_too_big_for_memory_is_refused_up_front_with_what_fits(tmp_path, args, names):
    # they ran for minutes at up to 3.45 GB (an 8k MP4 peaked at 3.16 GB in ffmpeg, 1.39 GB here)
    from deforma.render.video import MAX_RUN_MEMORY, run_memory

    t0 = time.perf_counter()
    rc, err, peak = _peak_of(["deforma", "run", "sample", *args], tmp_path)
    assert time.perf_counter() - t0 < 10
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("deforma: compiling")]
    assert rc == 1 and len(lines) == 1 and "Traceback" not in err, err
    assert "needs about" in lines[0] and "deforma run stays within 2.0 GB" in lines[0]
    assert all(n in lines[0] for n in names), lines[0]
    # the size it offers fits, and is the largest of that shape that does
    w, h = map(int, re.search(r"--size (\d+)x(\d+) or smaller", lines[0]).groups())
    kind, fps = args[-1].rsplit(".", 1)[1], float(args[args.index("--fps") + 1]) if "--fps" in args else 30.0
    frames = 960 if "--fps" in args else (900 if "--seconds" in args else 120)
    fits = lambda w, h: sum(run_memory((w, h), samples=4, kind=kind, frames=frames, fps=fps).values())  # noqa: E731
    assert fits(w, h) <= MAX_RUN_MEMORY < fits(w + 2, h + 2)
    assert os.listdir(tmp_path) == []
    assert peak < REFUSED_PEAK_MB, f"{peak:.0f} MB before refusing"


def test_a_run_within_the_memory_bound_peaks_under_its_estimate(tmp_path):
    from deforma.render.video import run_memory

    args = ["--seconds", "0.2", "--size", "640x360", "--overlay", "-o", "v.mp4"]
    rc, err, peak = _peak_of(["deforma", "run", "sample", *args], tmp_path, timeout=300)
    assert rc == 0, err
    estimate = sum(run_memory((640, 360), samples=4, kind="mp4", frames=6, fps=30).values()) / 2**20
    assert peak < estimate, f"measured {peak:.0f} MB, estimated {estimate:.0f} MB"
    assert os.listdir(tmp_path) == ["v.mp4"]


@pytest.mark.parametrize("strength", [1e6, 1e12])
def test_a_runaway_under_a_strong_grab_names_the_grab(strength):
    # the hint said only "lower the stiffness or damping, raise the mass": the grab is what to lower
    import warnings

    w = deforma.World(integrator="symplectic-euler", substeps=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=3))
    grab = w.grab((0.5, 0.5), strength=strength)
    grab.target = (50, 50)  # dragged far off
    with pytest.raises(deforma.SimulationUnstable) as e:
        for _ in range(20):
            w.step()
    one_line(e.value)
    assert f"set by the grabs, up to {strength:.3g} N/m on a vertex" in e.value.hint
    assert "lower the grab strength" in e.value.hint


def test_a_sweep_video_too_big_for_memory_is_refused_before_anything_runs(tmp_path):
    # each run's MP4 is deforma run -o's renderer and ffmpeg: 7680x4320 would need 5 GB a worker
    from deforma.sweeps import SweepError, sweep

    spec = tmp_path / "s.toml"
    spec.write_text('scene = "sample"\nseconds = 0.1\n[parameters]\n"physics.friction" = [0.1, 0.5]\n')
    with pytest.raises(SweepError, match=r"^video_size: a 7680x4320 MP4 needs about .* each run of a sweep stays "
                                         r"within 2.0 GB: give --video-size \d+x\d+ or smaller$") as e:
        sweep(spec, tmp_path / "out", video="mp4", video_size=(7680, 4320))
    one_line(e.value)
    assert sorted(os.listdir(tmp_path)) == ["s.toml"]


# "this world cannot step at this dt": one error type, SimulationUnstable (StepTooLong, also a
# ValueError, where substeps = "auto" would need more than 1000 substeps)
def _stiff_world():
    import warnings

    w = deforma.World(integrator="symplectic-euler", dt=0.1, substeps=1, stiffness=1e7)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # add_body says it at once; here it is asked for
        b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=4), position=(0, 2))
    return w, b


def test_auto_substeps_past_the_limit_is_simulation_unstable_naming_the_dt_that_fits():
    from deforma.physics.diagnostics import StepTooLong

    w, b = _stiff_world()
    before = b.positions.copy()
    with pytest.raises(deforma.SimulationUnstable) as e:  # it was a bare ValueError
        w.substeps = "auto"
    one_line(e.value)
    assert isinstance(e.value, StepTooLong) and isinstance(e.value, ValueError)  # old `except ValueError` works
    assert e.value.needed == 3802 and e.value.body is b and e.value.step == 0
    assert re.fullmatch(r'substeps = "auto" would need 3802 substeps of dt = 0\.1 s \(stable step 2\.63e-05 s\), '
                        r'more than 1000: lower dt to 0\.0263 s or less \(1000 substeps of it hold\), soften the bodies, or use '
                        r'integrator="implicit-euler" \(stable at any step\)', str(e.value)), str(e.value)
    assert e.value.hint in str(e.value)
    assert w.substeps == 1 and not w.auto_substeps and np.array_equal(b.positions, before)  # nothing changed
    # the dt it names fits: "auto" takes it, at most 1000 substeps, and the step runs
    w.dt = e.value.largest_dt
    w.substeps = "auto"
    assert 990 < w.substeps <= 1000
    # the same type when a step finds it (a dt raised after "auto" was set): the world as before
    w.dt = 0.1
    with pytest.raises(StepTooLong) as e2:
        w.step()
    one_line(e2.value)
    assert w.step_count == 0 and np.array_equal(b.positions, before)


def test_run_that_cannot_step_at_its_dt_says_so_in_one_line_and_writes_nothing(tmp_path, capsys):
    from deforma.cli import EXIT_UNSTABLE, main

    scene = tmp_path / "stiff.toml"
    scene.write_text('[physics]\ndt = 0.1\nintegrator = "symplectic-euler"\nstiffness = 1e7\n'
                     '[[body]]\nshape = "box"\ncorners = [[0, 0], [1, 0], [1, 1], [0, 1]]\ndetail = 4\n'
                     'position = [0.0, 2.0]\n[[collider]]\ncenter = [0.0, -0.5]\nsize = [4.0, 1.0]\n')
    code = main(["run", str(scene), "--seconds", "0.5", "--states", str(tmp_path / "s.npz"),
                 "--export", str(tmp_path / "frames")])
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("deforma: compiling")]
    assert code == EXIT_UNSTABLE and len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"deforma: error: {scene}: cannot step at t = 0.000 s: substeps = \"auto\" would "
                               f"need 3802 substeps"), lines[0]
    assert "lower dt to 0.0263 s or less" in lines[0] and lines[0].endswith("; nothing was written")
    assert os.listdir(tmp_path) == ["stiff.toml"]


# a body too big to be useful: more than MAX_BODY_POINTS points is refused from the count, before
# any triangulation (detail = 1000 meshed for 27 s, then took 29 s a step; resolution = 1 on a big
# picture ran past 240 s with nothing shown)
def _disc_picture(side):
    """A white disc filling a black side x side picture: about 0.785 side**2 foreground pixels."""
    y, x = np.mgrid[:side, :side]
    return np.where((x - side / 2 + 0.5) ** 2 + (y - side / 2 + 0.5) ** 2 < (side / 2 - 2) ** 2, 255, 0).astype(np.uint8)


def test_a_box_past_the_point_limit_is_refused_from_its_count_naming_the_detail_that_fits():
    from deforma.checks import MAX_BODY_POINTS, MAX_DETAIL, box_point_count

    corners = ((0, 0), (1, 0), (1, 1), (0, 1))
    t0 = time.perf_counter()
    with pytest.raises(ValueError) as e:
        deforma.mesh.box(corners, detail=1000)
    assert time.perf_counter() - t0 < 1  # counted, not meshed
    one_line(e.value)
    assert str(e.value) == ("detail=1000 gives a box of 1004004 points (with edges), more than the 100000 one body "
                            "may have (MAX_BODY_POINTS): give detail=314 or less")
    with pytest.raises(ValueError, match=r"^detail=317 gives a box of 100493 points, .*: give detail=316 or less$"):
        deforma.mesh.box(corners, detail=317, edges=False)
    with pytest.raises(ValueError, match=r"^detail must be at most 314: .* got an integer of 401 digits$") as e:
        deforma.mesh.box(corners, detail=10**400)
    one_line(e.value)
    # the details it names are the largest that fit, with edges and without
    assert MAX_BODY_POINTS == 100_000 and MAX_DETAIL == 316
    assert box_point_count(314, True) <= MAX_BODY_POINTS < box_point_count(315, True)
    assert box_point_count(316, False) <= MAX_BODY_POINTS < box_point_count(317, False)
    assert len(deforma.mesh.box(corners, detail=20).vertices) == box_point_count(20, True)
    assert len(deforma.mesh.box(corners, detail=20, edges=False).vertices) == box_point_count(20, False)


def test_a_picture_past_the_point_limit_is_refused_before_triangulating_naming_a_resolution_that_fits():
    # 785,000 foreground pixels: under the old limit (a million points), meshed for minutes
    from deforma.checks import MAX_BODY_POINTS

    picture = _disc_picture(1000)
    t0 = time.perf_counter()
    with pytest.raises(ValueError) as e:
        deforma.mesh.from_image(picture, resolution=1)
    assert time.perf_counter() - t0 < 5  # read and counted, not triangulated
    one_line(e.value)
    m = re.fullmatch(r"the picture would give about (\d+) points with resolution=1 and edge_step=2; at most 100000 "
                     r"\(MAX_BODY_POINTS, the most one body may have\) allowed: give resolution=(\d+) or more",
                     str(e.value))
    assert m, str(e.value)
    assert int(m.group(1)) > 780_000
    fits = int(m.group(2))
    assert len(deforma.mesh.from_image(picture, resolution=fits).vertices) <= MAX_BODY_POINTS
    with pytest.raises(ValueError, match=r"the picture would give about"):
        deforma.mesh.from_image(picture, resolution=fits - 1)  # and it is the smallest that does
    # max_points may lower the limit, not raise it
    with pytest.raises(ValueError, match=r"^max_points must be an integer in \[3, 100000\], got 1000000$"):
        deforma.mesh.from_image(picture, max_points=1_000_000)


def test_an_outline_too_long_for_the_limit_names_the_edge_step_too():
    # a grid of 1 px specks is no shape; 2 px wide stripes are: their outline alone passes half the limit
    picture = np.zeros((1000, 1000), np.uint8)
    picture[:, 2::5] = picture[:, 3::5] = 255
    picture[:2], picture[-2:], picture[:, :2], picture[:, -2:] = 0, 0, 0, 0
    with pytest.raises(ValueError, match=r"allowed: give edge_step=\d+ or more and resolution=\d+ or more$") as e:
        deforma.mesh.from_image(picture, resolution=1, edge_step=1)
    one_line(e.value)


@pytest.mark.parametrize("body, names", [
    ('shape = "box"\ndetail = 1000\n',
     "body[0].detail: detail=1000 gives a box of 1004004 points (with edges), more than the 100000 one body may have "
     "(MAX_BODY_POINTS): give detail=314 or less"),
    ('shape = "image"\nsource = "disc.png"\nresolution = 1\n',
     "body[0]: the picture would give about"),
])
def test_run_of_a_body_past_the_point_limit_is_one_line_before_anything_runs(tmp_path, body, names):
    from PIL import Image

    Image.fromarray(_disc_picture(1000)).save(tmp_path / "disc.png")
    scene = tmp_path / "big.toml"
    scene.write_text(f"[[body]]\n{body}[[collider]]\ncenter = [0.0, -6.0]\nsize = [20.0, 1.0]\n")
    t0 = time.perf_counter()
    rc, err, peak = _peak_of(["deforma", "run", scene, "--seconds", "0.1", "-o", tmp_path / "o.mp4",
                              "--states", tmp_path / "s.npz"], tmp_path)
    assert time.perf_counter() - t0 < 30
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("deforma: compiling")]
    assert rc == 1 and len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith("deforma: error: ") and f"big.toml: {names}" in lines[0], lines[0]
    assert sorted(os.listdir(tmp_path)) == ["big.toml", "disc.png"]
    assert peak < REFUSED_PEAK_MB, f"{peak:.0f} MB before refusing"


@pytest.mark.parametrize("args, message", [
    (["box", "--detail", "1000"], "deforma: error: --detail=1000 gives a box of 1004004 points (with edges), more "
                                  "than the 100000 one body may have (MAX_BODY_POINTS): give --detail=314 or less"),
    (["disc.png", "--resolution", "1"], "deforma: error: the picture would give about"),
])
def test_mesh_of_a_body_past_the_point_limit_is_one_line_writing_nothing(tmp_path, capsys, args, message):
    from PIL import Image

    from deforma.cli import main

    Image.fromarray(_disc_picture(1000)).save(tmp_path / "disc.png")
    t0 = time.perf_counter()
    code = main(["mesh", *[str(tmp_path / a) if a.endswith(".png") else a for a in args], "-o", str(tmp_path / "m.png")])
    err = capsys.readouterr().err
    assert time.perf_counter() - t0 < 5
    assert code == 1 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert err.startswith(message), err
    assert sorted(os.listdir(tmp_path)) == ["disc.png"]


# -- found by the fuzz tests above once they covered every key (issue 51) ---------------------------
@pytest.mark.parametrize("data, message", [
    # a shape that is an array or a table: TypeError (unhashable) looking it up
    ({"body": [{"shape": [1]}]}, "f.toml: body[0].shape: expected a string, got array [1]; allowed: box, image, mesh"),
    ({"collider": [{"shape": {"a": 1}}]}, "f.toml: collider[0].shape: expected a string, got table {'a': 1}; allowed: "
                                          "rect, circle, polygon, segment, image"),
    # an integer too large for a float in a number option: OverflowError in the option's check
    ({"physics": {"integrator_options": {"tolerance": 10**400}}},
     "f.toml: physics.integrator_options.tolerance: avbd option tolerance must be a number in [0, inf), got an "
     "integer of 401 digits"),
    ({"physics": {"integrator": "implicit-bdf2", "integrator_options": {"max_iterations": 10**5000}}},
     "f.toml: physics.integrator_options.max_iterations: implicit-bdf2 option max_iterations must be an integer in "
     "[1, 1e+06], got an integer of more than 4300 digits"),
    # a vertex index past int64: OverflowError when the pins were made
    ({"body": [{"shape": "box", "detail": 2, "pin_vertices": [3, 10**30]}]},
     f"<scene>: body[0].pin_vertices: vertex index {10**30} is out of range; the body has vertices 0..15"),
    # named physics: grab_strength, a key the file does not have
    ({"interaction": {"mouse_strength": 1e-300}},
     "f.toml: interaction.mouse_strength: must be in [1e-09, 1e+12] N/m, got 1e-300"),
    # said to be made of finite elements with an elasticity, which a rigid body has not
    ({"body": [{"shape": "box", "material": "rigid", "density": 5.0, "mass": 2.0}]},
     "f.toml: body[0].mass: the body is 'rigid', whose mass is density * area and which does not deform: remove "
     "mass, or set material = \"springs\""),
])
def test_keys_the_fuzz_found_are_refused_in_one_line_naming_the_key(data, message):
    with pytest.raises(SceneError) as e:
        build(parse_scene(data, source="f.toml"))
    one_line(e.value)
    assert str(e.value) == message


def test_an_integer_option_too_large_for_a_float_is_refused_by_the_world_in_one_line():
    for options in ({"tolerance": 10**400}, {"penalty_max": -10**5000}):
        with pytest.raises(ValueError, match=r"^avbd option \w+ must be a number in .* got an integer of "
                                             r"(401|more than 4300) digits$") as e:
            deforma.World(integrator_options=options)
        one_line(e.value)
        w = deforma.World(integrator_options={"iterations": 4})
        with pytest.raises(ValueError, match=r"^avbd option"):
            w.integrator_options = options
        assert w.integrator_options["iterations"] == 4  # nothing changed

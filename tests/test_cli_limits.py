"""Hostile sizes and interruptions give one line and leave nothing behind (issue 17)."""

import io
import struct
import zlib

import numpy as np
import pytest
from PIL import Image

from deforma.cli import EXIT_ERROR, MESH_PICTURE_MAX_SIDE, main
from signal_runs import kill_leftovers, signal_when_under_way


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(err):
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("deforma: compiling")]
    assert len(lines) == 1, err
    return lines[0]


def bomb_png(path, w, h):
    """A valid 1x1 PNG whose header claims w x h pixels: Pillow reads the size without decoding."""
    b = io.BytesIO()
    Image.new("L", (1, 1), 255).save(b, "PNG")
    d = bytearray(b.getvalue())
    d[16:24] = struct.pack(">II", w, h)
    d[29:33] = struct.pack(">I", zlib.crc32(bytes(d[12:29])))
    path.write_bytes(bytes(d))
    return path


def peak_rss_mb():
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


# -- memory -------------------------------------------------------------------------------------------
def test_mesh_of_a_tiny_shape_on_a_large_picture_draws_only_the_mesh_frame(tmp_path, capsys):
    # a 3x3 block on 100x100 black asked for a ~47,000 px backdrop and was killed at 23.7 GB
    a = np.zeros((100, 100), np.uint8)
    a[48:51, 48:51] = 255
    Image.fromarray(a).save(tmp_path / "tiny.png")
    out = tmp_path / "m.png"
    code, stdout, err = run(capsys, "mesh", tmp_path / "tiny.png", "-o", out)
    assert code == 0, err
    w, h = Image.open(out).size
    assert w == 800 and h < 1000
    assert peak_rss_mb() < 2048
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.png", "tiny.png"]


def test_mesh_of_a_very_tall_shape_stays_within_the_picture_limit(tmp_path, capsys):
    a = np.zeros((2040, 40), np.uint8)
    a[20:2020, 10:30] = 255
    Image.fromarray(a).save(tmp_path / "tall.png")
    out = tmp_path / "m.png"
    code, stdout, err = run(capsys, "mesh", tmp_path / "tall.png", "--resolution", "20", "--edge-step", "20",
                            "-o", out)
    assert code == 0, err
    w, h = Image.open(out).size
    assert h <= MESH_PICTURE_MAX_SIDE + 40 and w < 800  # the caption bar adds 34 px


def test_mesh_of_a_shape_too_tall_for_any_picture_is_refused(tmp_path, capsys):
    a = np.zeros((4040, 24), np.uint8)
    a[20:4020, 10:14] = 255
    Image.fromarray(a).save(tmp_path / "line.png")
    code, _, err = run(capsys, "mesh", tmp_path / "line.png", "--resolution", "50", "--edge-step", "50",
                       "-o", tmp_path / "m.png")
    assert code == EXIT_ERROR
    line = one_line_error(err)
    assert str(MESH_PICTURE_MAX_SIDE) in line and "taller than wide" in line
    assert not (tmp_path / "m.png").exists()


@pytest.mark.parametrize("key", ["texture", "source"])
def test_a_decompression_bomb_as_texture_or_source_is_refused(tmp_path, capsys, key):
    bomb_png(tmp_path / "bomb.png", 30000, 30000)
    body = ('shape = "box"\ncorners = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]\ntexture = "bomb.png"\n'
            if key == "texture" else 'shape = "image"\nsource = "bomb.png"\n')
    (tmp_path / "s.toml").write_text(f"[run]\nseconds = 0.1\nfps = 10\n[[body]]\n{body}")
    code, _, err = run(capsys, "run", tmp_path / "s.toml", "-o", tmp_path / "out.gif", "--size", "64x64")
    assert code == EXIT_ERROR
    line = one_line_error(err)
    assert "bomb.png" in line and "40000000" in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bomb.png", "s.toml"]


# -- interrupted and failed output --------------------------------------------------------------------
def _exe():
    import os
    import sys

    return os.path.join(os.path.dirname(sys.executable), "deforma")


def _dead_pid():
    import subprocess
    import sys

    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_sigterm_and_sighup_clean_up_like_ctrl_c(tmp_path):
    # three runs at once (SIGTERM and SIGHUP into an MP4, SIGTERM into a PNG folder), each in a
    # folder of its own and signalled on its own clock (tests/signal_runs.py)
    import os
    import signal
    import subprocess

    from deforma.startup import COMPILE_MESSAGE

    runs = []
    for k, (signame, output) in enumerate([("SIGTERM", "big.mp4"), ("SIGHUP", "big.mp4"), ("SIGTERM", "frames/")]):
        cwd = tmp_path / f"{k}-{signame}"
        cwd.mkdir()
        p = subprocess.Popen([_exe(), "run", "sample", "--seconds", "120", "--size", "64x48", "-o", output, "--quiet"],
                             cwd=cwd, stderr=subprocess.PIPE, text=True, start_new_session=True)
        runs.append((signame, cwd, p))
    names = {p: signame for signame, _, p in runs}
    try:
        # the process alone (a service manager's stop, a closed terminal's hang-up)
        signal_when_under_way([(cwd, p) for _, cwd, p in runs], lambda p: os.kill(p.pid, getattr(signal, names[p])))
        for signame, cwd, p in runs:
            _, err = p.communicate(timeout=30)
            assert p.returncode == 128 + getattr(signal, signame), (signame, err)
            assert err.replace(COMPILE_MESSAGE + "\n", "", 1) == f"deforma: stopped by {signame}; no partial output was left\n"
            assert os.listdir(cwd) == [], signame
    finally:
        kill_leftovers([p for _, _, p in runs])


def test_a_stop_whose_exception_python_dropped_still_stops_the_run(tmp_path, capsys, monkeypatch):
    # a SIGHUP that arrived as ffmpeg's process was started ran its handler inside a fork hook,
    # where Python prints the handler's exception as "Exception ignored" and drops it: that run
    # wrote its whole video and exited 0. Here the signal comes inside a finaliser, where Python
    # drops it the same way; the run must stop at its next frame and leave nothing.
    import os
    import signal
    import sys

    from deforma.cli import Stopped
    from deforma.render import world_view

    dropped, calls = [], []
    monkeypatch.setattr(sys, "unraisablehook", lambda u: dropped.append(u.exc_type))
    real = world_view.WorldView.draw

    class Finaliser:
        def __del__(self):
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(1000):  # the handler runs here, inside the finaliser
                pass

    def draw(self, **kw):
        calls.append(1)
        if len(calls) == 3:
            Finaliser()  # dropped at once: its __del__ runs now
        return real(self, **kw)

    monkeypatch.setattr(world_view.WorldView, "draw", draw)
    code, _, err = run(capsys, "run", "sample", "--seconds", "1", "--size", "64x48", "--quiet", "-o",
                       str(tmp_path / "out.mp4"))
    assert dropped == [Stopped]  # Python did drop the handler's exception
    assert code == 128 + signal.SIGTERM and err.endswith("stopped by SIGTERM; no partial output was left\n")
    assert len(calls) == 3 and os.listdir(tmp_path) == []


def test_ctrl_c_in_a_png_folder_run_leaves_no_frames(tmp_path, capsys, monkeypatch):
    import os

    from deforma.cli import EXIT_INTERRUPTED
    from deforma.render import world_view

    calls = []
    real = world_view.WorldView.draw

    def draw(self, **kw):
        calls.append(1)
        if len(calls) == 6:
            raise KeyboardInterrupt
        return real(self, **kw)

    monkeypatch.setattr(world_view.WorldView, "draw", draw)
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "frame_00000.png").write_bytes(b"earlier run")
    for out in (tmp_path / "new", tmp_path / "old"):
        calls.clear()
        code, _, err = run(capsys, "run", "sample", "--seconds", "1", "--size", "64x48", "--quiet", "-o", f"{out}/")
        assert code == EXIT_INTERRUPTED and "no partial output was left" in err
    # the folder it made is gone; the existing one is as it was
    assert sorted(os.listdir(tmp_path)) == ["old"]
    assert os.listdir(tmp_path / "old") == ["frame_00000.png"]
    assert (tmp_path / "old" / "frame_00000.png").read_bytes() == b"earlier run"


def test_png_folder_run_publishes_every_frame(tmp_path, capsys):
    import os

    code, _, err = run(capsys, "run", "sample", "--seconds", "0.2", "--fps", "10", "--size", "64x48", "--quiet",
                       "-o", f"{tmp_path / 'f'}/")
    assert code == 0, err
    assert sorted(os.listdir(tmp_path / "f")) == ["frame_00000.png", "frame_00001.png"]


def test_the_temporary_files_of_killed_runs_are_removed_by_the_next_run(tmp_path, capsys):
    import os
    import time

    pid = _dead_pid()
    stale = [tmp_path / f".out.{pid}.abcd1234.partial.mp4", tmp_path / f".s.{pid}.x_y_z_12.partial.npz"]
    for f in stale:
        f.write_bytes(b"killed run")
    staged = tmp_path / f".frames.{pid}.qwertyui.partial"
    staged.mkdir()
    (staged / "frame_00000.png").write_bytes(b"")
    alive = tmp_path / f".out.{os.getppid()}.abcd1234.partial.mp4"  # a live process: kept
    other = tmp_path / ".notes.partial.txt"  # not ours: kept
    for f in (alive, other):
        f.write_bytes(b"keep")
    # last written before this (long-running) test process began: a day ago
    old = time.time() - 86400
    for f in (*stale, staged, alive, other):
        os.utime(f, (old, old))
    code, _, err = run(capsys, "run", "sample", "--seconds", "0.1", "--fps", "10", "--size", "64x48", "--quiet",
                       "-o", tmp_path / "out.gif")
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([alive.name, other.name, "out.gif"])


def test_a_recent_temporary_file_of_a_dead_process_is_kept(tmp_path):
    # last written after this run began: another machine's run may be writing it into a shared folder
    import time

    from deforma.files import remove_stale_partials

    f = tmp_path / f".out.{_dead_pid()}.abcd1234.partial.mp4"
    f.write_bytes(b"")
    assert remove_stale_partials(tmp_path, before=time.time() - 60) == [] and f.exists()
    assert remove_stale_partials(tmp_path, before=time.time() + 60) == [f] and not f.exists()


@pytest.mark.parametrize("failure", ["enospc", "pipe"])
def test_a_failing_ffmpeg_is_one_line_and_leaves_nothing(tmp_path, capsys, monkeypatch, failure):
    import errno
    import os

    import imageio_ffmpeg

    import deforma.render.video as video

    def write_frames(path, *args, **kw):
        open(path, "wb").close()
        n = 0
        while True:
            yield
            n += 1
            if n == 3:
                if failure == "enospc":
                    raise OSError(errno.ENOSPC, "No space left on device")
                raise OSError("[Errno 32] Broken pipe\n\nFFMPEG COMMAND:\n/usr/bin/ffmpeg -y -f rawvideo ...\n\n"
                              "FFMPEG STDERR OUTPUT:\n")

    monkeypatch.setattr(imageio_ffmpeg, "write_frames", write_frames)
    if failure == "pipe":
        monkeypatch.setattr(video.shutil, "disk_usage", lambda p: type("U", (), {"free": 10**12})())
    code, _, err = run(capsys, "run", "sample", "--seconds", "1", "--size", "64x48", "--quiet",
                       "-o", tmp_path / "big.mp4")
    assert code == EXIT_ERROR
    line = one_line_error(err)
    assert "FFMPEG" not in line and "big.mp4" in line and "nothing was written" in line
    assert ("no space left" in line) == (failure == "enospc")
    assert os.listdir(tmp_path) == []


def test_view_screenshot_into_an_unwritable_folder_is_refused(tmp_path, capsys, monkeypatch):
    import os

    monkeypatch.setattr(os, "access", lambda path, mode: False)  # root writes anywhere: simulated
    code, out, err = run(capsys, "view", "sample", "--frames", "2", "--screenshot", tmp_path / "s.png")
    assert code == EXIT_ERROR and out == ""
    assert "is not writable" in one_line_error(err)
    assert os.listdir(tmp_path) == []


def test_view_screenshot_that_cannot_be_saved_fails(tmp_path):
    import os
    import subprocess
    import sys

    (tmp_path / "s.png").mkdir()  # saving onto a folder fails after the frames ran
    env = dict(os.environ, SDL_VIDEODRIVER="offscreen")
    r = subprocess.run([sys.executable, "-m", "deforma.cli", "view", "sample", "--frames", "2", "--size", "640x360",
                        "--screenshot", "s.png"], capture_output=True, text=True, env=env, timeout=120, cwd=tmp_path)
    assert r.returncode == EXIT_ERROR and r.stdout == ""
    assert "cannot save the screenshot" in one_line_error(r.stderr)
    assert os.listdir(tmp_path) == ["s.png"] and os.listdir(tmp_path / "s.png") == []


# -- viewer sizes and deep TOML -----------------------------------------------------------------------
@pytest.mark.parametrize("size", ["640x214", "100x100", "320x180", "639x720", "1280x271"])
def test_view_refuses_a_window_smaller_than_its_layout(capsys, size):
    from deforma.viewer.app import MIN_WINDOW_SIZE

    with pytest.raises(SystemExit) as e:
        main(["view", "sample", "--frames", "1", "--size", size])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert f"window size {size} is too small for the viewer: at least {MIN_WINDOW_SIZE[0]}x{MIN_WINDOW_SIZE[1]}" in err


def test_the_smallest_window_matches_the_inspector_layout():
    from deforma.viewer import inspector
    from deforma.viewer.app import MIN_WINDOW_SIZE, check_window_size

    assert MIN_WINDOW_SIZE == (inspector.PANEL_WIDTH + 300, inspector.TOP + 4 * inspector.ROW + inspector.MESSAGE_HEIGHT)
    assert check_window_size(MIN_WINDOW_SIZE) == MIN_WINDOW_SIZE
    with pytest.raises(ValueError, match="at least 640x272"):
        check_window_size((640, 271))


def test_view_runs_at_the_smallest_window_with_an_unstable_scene(tmp_path):
    # at 320x180 an unstable scene asked for a message box of negative width
    import os
    import subprocess
    import sys

    from deforma.viewer.app import MIN_WINDOW_SIZE

    unstable = "[physics]\nintegrator = \"symplectic-euler\"\ndt = 0.02\nstiffness = 50000.0\n[[body]]\ndetail = 4\n" \
               "position = [0.0, 1.0]\n" \
               "[[collider]]\ncenter = [0.0, 0.0]\nsize = [5.0, 0.5]\n"
    w, h = MIN_WINDOW_SIZE
    env = dict(os.environ, SDL_VIDEODRIVER="offscreen")
    runs = {}
    for scene in ("sample", "boom.toml"):  # the two viewers at once, each in a folder of its own
        cwd = tmp_path / scene.replace(".", "_")
        cwd.mkdir()
        (cwd / "boom.toml").write_text(unstable)
        runs[cwd] = subprocess.Popen([sys.executable, "-m", "deforma.cli", "view", scene, "--frames", "30", "--size",
                                      f"{w}x{h}", "--screenshot", "s.png"], stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True, env=env, cwd=cwd)
    try:
        for cwd, p in runs.items():
            _, err = p.communicate(timeout=120)
            assert p.returncode == 0, err
            assert Image.open(cwd / "s.png").size == (w, h)
    finally:
        kill_leftovers(runs.values())


def test_deeply_nested_toml_names_the_file(tmp_path, capsys):
    p = tmp_path / "deep.toml"
    p.write_text("[[body]]\nvertices = " + "[" * 5000 + "]" * 5000 + "\n")
    code, _, err = run(capsys, "run", p)
    assert code == EXIT_ERROR
    line = one_line_error(err)
    assert str(p) in line and "nested too deep" in line


def test_a_sigkilled_runs_temporary_file_is_removed_by_the_next_run(tmp_path):
    import os
    import signal
    import subprocess
    import time

    p = subprocess.Popen([_exe(), "run", "sample", "--seconds", "120", "--size", "64x48", "-o", "big.mp4", "--quiet"],
                         cwd=tmp_path, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.time() + 60
    while time.time() < deadline and not any(".partial" in f for f in os.listdir(tmp_path)):
        time.sleep(0.05)
    time.sleep(0.3)
    os.killpg(p.pid, signal.SIGKILL)
    p.wait(timeout=30)
    assert any(".partial" in f for f in os.listdir(tmp_path))  # nothing could clean up
    time.sleep(0.05)  # the next run starts strictly after the file was last written
    r = subprocess.run([_exe(), "run", "sample", "--seconds", "0.1", "--fps", "10", "--size", "64x48", "--quiet",
                        "-o", "small.gif"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert os.listdir(tmp_path) == ["small.gif"]

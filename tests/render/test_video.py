"""Video writers: frame counts, and nothing half-written when a run is interrupted."""

import os

import numpy as np
import pytest
from PIL import Image

from deforma.render.video import GifWriter, check_output, open_writer, output_kind


def moving_frames(n, size=(64, 48)):
    """Frames with a white square moving right, so every frame differs."""
    w, h = size
    for k in range(n):
        f = np.full((h, w, 3), (40, 60, 90), np.uint8)
        f[10:30, 2 * k : 2 * k + 12] = 255
        yield f


def test_mp4_has_the_frames_written(tmp_path):
    import imageio_ffmpeg

    out = tmp_path / "a.mp4"
    with open_writer(out, fps=24) as w:
        for f in moving_frames(17):
            w.write(f)
    frames = list(imageio_ffmpeg.read_frames(str(out)))
    meta, frames = frames[0], frames[1:]
    assert len(frames) == 17
    assert tuple(meta["size"]) == (64, 48)
    assert meta["fps"] == pytest.approx(24)
    assert sorted(os.listdir(tmp_path)) == ["a.mp4"]   # no temporary file left


def test_mp4_pads_odd_sizes(tmp_path):
    import imageio_ffmpeg

    out = tmp_path / "odd.mp4"
    with open_writer(out, fps=10) as w:
        for f in moving_frames(3, size=(63, 47)):
            w.write(f)
    meta = next(imageio_ffmpeg.read_frames(str(out)))
    assert tuple(meta["size"]) == (64, 48)


def test_gif_has_the_frames_and_the_timing(tmp_path):
    out = tmp_path / "a.gif"
    with open_writer(out, fps=30) as w:
        for f in moving_frames(20):
            w.write(f)
    im = Image.open(out)
    assert im.n_frames == 20
    total = 0
    for k in range(im.n_frames):
        im.seek(k)
        total += im.info["duration"]
    assert total == pytest.approx(20 / 30 * 1000, abs=10)
    im.seek(5)
    rgb = np.asarray(im.convert("RGB"))
    assert rgb[20, 15].tolist() == [255, 255, 255] and rgb[40, 5].tolist() == [40, 60, 90]


def test_gif_durations_average_to_the_frame_rate():
    d = GifWriter.__new__(GifWriter)
    d.fps = 30.0
    ms = d.durations_ms(30)
    assert sum(ms) == 1000 and set(ms) == {30, 40}


def test_png_folder_gets_numbered_frames(tmp_path):
    out = tmp_path / "frames"
    with open_writer(str(out) + "/", fps=10) as w:
        for f in moving_frames(4):
            w.write(f)
    assert sorted(os.listdir(out)) == [f"frame_{k:05d}.png" for k in range(4)]
    assert np.asarray(Image.open(out / "frame_00003.png")).shape == (48, 64, 3)


def test_a_shorter_run_into_the_same_png_folder_leaves_only_its_frames(tmp_path):
    out = tmp_path / "frames"
    for n in (6, 3):
        with open_writer(str(out) + "/", fps=10) as w:
            for f in moving_frames(n):
                w.write(f)
    (out / "notes.txt").write_text("mine")
    (out / "frame_final.png").write_bytes(b"")  # not a frame number: not ours to delete
    with open_writer(str(out) + "/", fps=10) as w:
        for f in moving_frames(2):
            w.write(f)
    assert sorted(os.listdir(out)) == ["frame_00000.png", "frame_00001.png", "frame_final.png", "notes.txt"]


@pytest.mark.parametrize("name", ["a.mp4", "a.gif"])
def test_interrupted_write_leaves_the_old_file_and_no_temporary(tmp_path, name):
    out = tmp_path / name
    out.write_bytes(b"old")
    with pytest.raises(KeyboardInterrupt):
        with open_writer(out, fps=10) as w:
            for k, f in enumerate(moving_frames(40)):
                w.write(f)
                if k == 30:
                    raise KeyboardInterrupt
    assert out.read_bytes() == b"old"
    assert sorted(os.listdir(tmp_path)) == [name]


def test_ctrl_c_as_ffmpeg_starts_leaves_no_file(tmp_path):
    # imageio-ffmpeg starts its process, then enters the try that stops it: a Ctrl-C in between
    # left the process running with its input open, and it wrote its file once the run had
    # exited (which closed that input), after the run had removed it. Here, in a run of its
    # own, a stand-in encoder writes its file 0.3 s after its input ends, and the Ctrl-C comes
    # right after it starts.
    import subprocess
    import sys
    import time

    script = """
import signal, subprocess, sys
import imageio_ffmpeg
import numpy as np
from deforma.render.video import open_writer

def encoder(path, size, **kwargs):
    code = f"import sys, time; sys.stdin.buffer.read(); time.sleep(0.3); open({str(path)!r}, 'wb').write(b'late')"
    p = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE)
    signal.raise_signal(signal.SIGINT)
    try:
        while True:
            p.stdin.write((yield))
    finally:  # as imageio-ffmpeg's: ends the input, and kills it unless closed
        p.stdin.close()
        if p.poll() is None and sys.exc_info()[0] is not GeneratorExit:
            p.kill()

imageio_ffmpeg.write_frames = encoder
try:
    with open_writer(sys.argv[1], fps=10) as w:
        w.write(np.zeros((48, 64, 3), np.uint8))
except KeyboardInterrupt:
    sys.exit(130)
"""
    run = subprocess.run([sys.executable, "-c", script, str(tmp_path / "a.mp4")], capture_output=True, text=True,
                         timeout=60)
    assert run.returncode == 130, run.stderr
    time.sleep(1.0)  # past the stand-in's 0.3 s after the run's exit
    assert os.listdir(tmp_path) == []


def test_output_kinds():
    assert output_kind("x.MP4") == "mp4"
    assert output_kind("x.gif") == "gif"
    assert output_kind("frames/") == "png"
    assert output_kind("frames") == "png"
    with pytest.raises(ValueError, match="allowed: .mp4, .gif, or a folder"):
        output_kind("x.avi")


def test_check_output_errors(tmp_path, monkeypatch):
    with pytest.raises(ValueError, match="does not exist"):
        check_output(tmp_path / "missing" / "a.mp4")
    with pytest.raises(ValueError, match="does not exist"):
        check_output(tmp_path / "missing" / "frames/")
    (tmp_path / "file").write_text("x")
    with pytest.raises(ValueError, match="not a folder"):
        check_output(str(tmp_path / "file") + "/")
    with pytest.raises(ValueError, match="is a folder"):
        (tmp_path / "d.mp4").mkdir()
        check_output(tmp_path / "d.mp4")
    # root may write anywhere, so a read-only folder is simulated through os.access
    monkeypatch.setattr(os, "access", lambda path, mode: False)
    with pytest.raises(ValueError, match="not writable"):
        check_output(tmp_path / "a.gif")


def test_frames_must_keep_one_size(tmp_path):
    with pytest.raises(ValueError, match="first frame's size"):
        with open_writer(tmp_path / "a.gif", fps=10) as w:
            w.write(np.zeros((8, 8, 3), np.uint8))
            w.write(np.zeros((8, 9, 3), np.uint8))
    assert not (tmp_path / "a.gif").exists()


@pytest.mark.parametrize("name", ["p.mp4", "p.gif", "frames/"])
def test_outputs_get_normal_file_permissions(tmp_path, name):
    old = os.umask(0o022)
    try:
        with open_writer(tmp_path / name, fps=10) as w:
            for f in moving_frames(2):
                w.write(f)
    finally:
        os.umask(old)
    target = tmp_path / name.rstrip("/")
    files = [target] if target.is_file() else sorted(target.iterdir())
    for f in files:
        assert f.stat().st_mode & 0o777 == 0o644, f


def test_a_real_mp4_is_complete_and_a_cut_one_is_not(tmp_path):
    from deforma.render.video import mp4_complete

    out = tmp_path / "a.mp4"
    with open_writer(out, fps=24) as w:
        for f in moving_frames(17):
            w.write(f)
    assert mp4_complete(out)
    data = out.read_bytes()
    for keep in (0.3, 0.6, 0.99):  # what ffmpeg leaves when the disk fills while it finishes
        out.write_bytes(data[: int(len(data) * keep)])
        assert not mp4_complete(out), keep


def _full_disk(*args, **kwargs):
    import errno

    raise OSError(errno.ENOSPC, "No space left on device")


@pytest.mark.parametrize("name", ["v.mp4", "v.gif", "frames"])
def test_a_full_disk_keeps_the_earlier_output_and_says_which_file(tmp_path, monkeypatch, name):
    from deforma.render import video

    target = tmp_path / name
    if name == "frames":
        target.mkdir()
        (target / "frame_00000.png").write_bytes(b"earlier")
        monkeypatch.setattr(Image.Image, "save", _full_disk)  # the first frame fails
        earlier = target / "frame_00000.png"
    else:
        target.write_bytes(b"earlier")
        earlier = target
        if name.endswith(".mp4"):
            # ffmpeg out of disk while it finishes the file exits as if all were well: the file is
            # found cut short (test_a_real_mp4_is_complete_and_a_cut_one_is_not)
            monkeypatch.setattr(video, "mp4_complete", lambda path: False)
        else:
            monkeypatch.setattr(Image.Image, "save", _full_disk)
    w = open_writer(target, fps=10)
    with pytest.raises(OSError) as e:
        for f in moving_frames(5):
            w.write(f)
        w.close()
    text = str(e.value)
    why = "ffmpeg stopped (the finished file is cut short)" if name.endswith(".mp4") else "no space left on the device"
    assert text.startswith(f"{target}: ") and why in text and "nothing was written" in text
    assert "\n" not in text and earlier.read_bytes() == b"earlier"
    assert sorted(p.name for p in tmp_path.rglob("*")) == sorted([name] + (["frame_00000.png"] if name == "frames"
                                                                            else []))

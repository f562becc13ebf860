"""Frames in flight (render/recorder.py) and the writers' thread (render/video.py): the same
pictures as drawing one frame at a time, and a failure in the thread is one line with nothing left."""

import errno
import os
import threading

import numpy as np
import pytest
from PIL import Image

import deforma
from deforma.render import Renderer, WorldView, open_writer
from deforma.render.recorder import PIPELINE_MAX_PIXELS, FrameRecorder, frames_in_flight, pipeline_bytes
from deforma.render.video import FrameWriter, GifWriter, run_memory


class Collect:
    """A writer that keeps what it is given."""

    def __init__(self):
        self.frames = []

    def write(self, frame):
        self.frames.append(np.array(frame))


def frames_of(in_flight, samples, n=7, overlay=True):
    world = deforma.load_scene("sample")
    view = WorldView(Renderer.headless((96, 64), samples=samples), world, overlay=overlay)
    out = Collect()
    rec = FrameRecorder(view, out, in_flight=in_flight)
    try:
        for _ in range(n):
            for _ in range(3):
                world.step()
            rec.add()
        rec.finish()
    finally:
        view.renderer.release()
    assert rec.frames == n and rec.last_frame is not None
    return out.frames


@pytest.mark.parametrize("samples", [4, 0])
def test_frames_in_flight_are_the_pictures_drawn_one_at_a_time(samples):
    one, two = frames_of(1, samples), frames_of(2, samples)
    assert len(one) == len(two) == 7
    for k, (a, b) in enumerate(zip(one, two)):
        assert a.shape == (64, 96, 3) and np.array_equal(a, b), k
    assert not np.array_equal(one[0], one[-1])  # the body moved: each frame is its own time


def test_a_recorder_with_fewer_frames_than_in_flight_delivers_them_all():
    assert len(frames_of(2, 4, n=1)) == 1
    assert len(frames_of(2, 4, n=2)) == 2


def test_frames_in_flight_follow_the_size_and_the_memory_estimate_counts_them():
    assert frames_in_flight((1280, 720)) == 2 and frames_in_flight((3840, 2160)) == 1
    assert frames_in_flight((2560, 1440)) == 2 and 2560 * 1440 == PIPELINE_MAX_PIXELS
    assert pipeline_bytes((1280, 720), samples=4) == 1280 * 720 * 20
    assert pipeline_bytes((1280, 720), samples=0) == 1280 * 720 * 4
    assert pipeline_bytes((3840, 2160), samples=4) == 0
    small = run_memory((1280, 720), samples=4, kind="png", frames=10, fps=30)
    assert small["writer"] == (FrameWriter.QUEUE_FRAMES + 2) * 3 * 1280 * 720
    # a 4K MP4 still fits the 2 GB a run plans for (its frames are drawn one at a time)
    from deforma.render.video import MAX_RUN_MEMORY

    assert sum(run_memory((3840, 2160), samples=4, kind="mp4", frames=300, fps=30).values()) <= MAX_RUN_MEMORY


def test_renderer_buffers_read_what_was_drawn_into_them():
    r = Renderer.headless((32, 24), samples=4)
    try:
        h = r.add_mesh([[0, 1, 2]], color="#ff0000")
        r.render()
        empty = r.read()
        r.use_buffer(1)
        assert r.buffer == 1
        r.render([(h, [[-8, -4.5], [8, -4.5], [-8, 4.5]])])
        r.resolve_buffer(1)
        r.flush()
        red = r.read_buffer(1)
        r.resolve_buffer(0)
        assert np.array_equal(r.read_buffer(0), empty) and not np.array_equal(red, empty)
        assert red[17, 6].tolist() == [255, 0, 0]  # inside the triangle, off its darker outline
        with pytest.raises(ValueError, match="buffer index"):
            r.use_buffer(8)
    finally:
        r.release()


def test_write_keeps_a_copy_of_the_frame(tmp_path):
    frame = np.full((8, 8, 3), 200, np.uint8)
    with open_writer(tmp_path / "f/", fps=10) as w:
        w.write(frame)
        frame[:] = 0  # the caller reuses its array at once
    assert np.asarray(Image.open(tmp_path / "f" / "frame_00000.png")).min() == 200


def failing_quantize(after):
    calls = []
    real = GifWriter._quantize

    def quantize(self, frame):
        assert threading.current_thread() is not threading.main_thread()  # the writer's own thread
        calls.append(1)
        if len(calls) > after:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, frame)

    return quantize


def test_a_failure_in_the_writers_thread_is_raised_once_and_leaves_nothing(tmp_path, monkeypatch):
    monkeypatch.setattr(GifWriter, "_quantize", failing_quantize(after=3))
    target = tmp_path / "v.gif"
    target.write_bytes(b"earlier")
    w = open_writer(target, fps=2)  # the palette after 2 frames, then a frame at a time
    with pytest.raises(OSError) as e:
        for k in range(50):
            w.write(np.full((16, 16, 3), 5 * k, np.uint8))
        w.close()
    text = str(e.value)
    assert text.startswith(f"{target}: ") and "no space left on the device" in text and "\n" not in text
    assert target.read_bytes() == b"earlier" and os.listdir(tmp_path) == ["v.gif"]
    w.abort()  # what a runner's cleanup does next: nothing more to do, nothing raised
    with pytest.raises(ValueError, match="closed"):
        w.write(np.zeros((16, 16, 3), np.uint8))


@pytest.mark.parametrize("then", ["write", "close"])
def test_a_writer_its_thread_closed_as_it_failed_raises_that_failure(tmp_path, monkeypatch, then):
    # an MP4's failed ffmpeg closes the writer from the thread before the failure is kept: a
    # write or close in between must wait for it, not say "writer is closed" (or nothing)
    import time

    import deforma.render.video as video

    started = threading.Event()

    def fail(self, frame):
        self._closed = True  # as Mp4Writer._failed does, in the writer's thread
        started.set()
        time.sleep(0.2)
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(video.PngFolderWriter, "_write", fail)
    w = open_writer(tmp_path / "frames", fps=2)
    w.write(np.zeros((16, 16, 3), np.uint8))
    assert started.wait(5)
    with pytest.raises(OSError) as e:
        if then == "write":
            w.write(np.zeros((16, 16, 3), np.uint8))
        else:
            w.close()
    assert "no space left on the device" in str(e.value) and "\n" not in str(e.value)


def test_an_interrupt_while_the_thread_works_discards_the_output(tmp_path, monkeypatch):
    import time

    real = GifWriter._write

    def slow(self, frame):
        time.sleep(0.01)
        real(self, frame)

    monkeypatch.setattr(GifWriter, "_write", slow)
    with pytest.raises(KeyboardInterrupt):
        with open_writer(tmp_path / "a.gif", fps=10) as w:
            for k in range(20):
                w.write(np.full((16, 16, 3), k, np.uint8))
            raise KeyboardInterrupt
    assert os.listdir(tmp_path) == []
    assert not any(t.name.startswith("deforma writer") for t in threading.enumerate())


def test_a_run_whose_writer_thread_fails_mid_run_is_one_line_and_leaves_nothing(tmp_path, capsys, monkeypatch):
    from deforma.cli import EXIT_ERROR, main

    monkeypatch.setattr(GifWriter, "_quantize", failing_quantize(after=4))
    code = main(["run", "sample", "--seconds", "1", "--fps", "10", "--size", "64x48", "--quiet",
                 "-o", str(tmp_path / "run.gif")])
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("deforma: compiling")]
    assert code == EXIT_ERROR and len(lines) == 1 and "Traceback" not in err, err
    assert "run.gif" in lines[0] and "no space left on the device" in lines[0] and "nothing was written" in lines[0]
    assert os.listdir(tmp_path) == []

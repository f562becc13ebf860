"""The time/scale overlay: where it draws, how long the bar is, that it is off unless asked, and
that the world is framed between its text so that the text covers nothing the scene shows."""

import numpy as np
import pytest
from PIL import Image

import deforma
from deforma.cli import main
from deforma.render import Renderer, WorldView
from deforma.render.overlay import draw_overlay, format_length, overlay_insets, scale_bar_length

BACKGROUND = (200, 210, 220)


def changed(a, b):
    return (a != b).any(axis=2)


def blank(h=180, w=320):
    return np.full((h, w, 3), BACKGROUND, np.uint8)


def test_overlay_draws_only_in_the_left_corners():
    frame = blank()
    out = draw_overlay(frame, time=1.25, metres_per_pixel=8.0 / 320)
    assert out is frame
    diff = changed(frame, blank())
    h, w = diff.shape
    assert diff[: h // 5, : w // 2].any()          # the time, top left
    assert diff[-h // 5 :, : w // 2].any()         # the scale bar, bottom left
    assert not diff[h // 5 : -h // 5].any()        # the middle band is untouched
    assert not diff[:, w // 2 :].any()             # and so is the right half


def test_the_time_text_follows_the_time():
    a, b = blank(), blank()
    draw_overlay(a, time=0.0, metres_per_pixel=0.025)
    draw_overlay(b, time=3.5, metres_per_pixel=0.025)
    diff = changed(a, b)
    assert diff[:36].any() and not diff[36:].any()  # only the time's corner differs


def test_scale_bar_has_the_length_it_names():
    frame = blank(200, 800)
    mpp = 8.0 / 800                                 # 100 px per metre: a 1 m bar (<= 1.6 m)
    draw_overlay(frame, time=0.0, metres_per_pixel=mpp)
    assert scale_bar_length(mpp, 800) == 1.0
    dark = frame.sum(axis=2) < 200
    # the bar's rows: the longest dark run in the bottom fifth, from the left margin on
    runs = [np.flatnonzero(row) for row in dark[-40:, :400]]
    longest = max((r[-1] - r[0] + 1 for r in runs if len(r) and np.all(np.diff(r) == 1)), default=0)
    assert longest == pytest.approx(100, abs=1)


@pytest.mark.parametrize("mpp, width, length, label", [
    (0.01, 800, 1.0, "1 m"), (0.05, 1280, 10.0, "10 m"), (0.0004, 640, 0.05, "5 cm"),
    (0.025, 320, 1.0, "1 m"), (0.02, 320, 1.0, "1 m"), (0.1, 1280, 20.0, "20 m"),
    (1e-5, 1000, 0.002, "2 mm"), (10.0, 1000, 2000.0, "2 km"),
])
def test_scale_bar_lengths_are_round_and_fit(mpp, width, length, label):
    got = scale_bar_length(mpp, width)
    assert got == pytest.approx(length) and format_length(got) == label
    assert got / mpp <= 0.2 * width + 1e-6


@pytest.mark.parametrize("kwargs, message", [
    ({"frame": np.zeros((10, 10), np.uint8)}, "frame must be an (H, W, 3) uint8 array"),
    ({"frame": np.zeros((10, 10, 3), np.float32)}, "frame must be an (H, W, 3) uint8 array"),
    ({"time": float("nan")}, "time must be a finite number"),
    ({"metres_per_pixel": 0.0}, "metres_per_pixel must be a finite number > 0"),
])
def test_bad_input_is_one_clear_error(kwargs, message):
    args = {"frame": blank(), "time": 1.0, "metres_per_pixel": 0.01, **kwargs}
    frame = args.pop("frame")
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        draw_overlay(frame, **args)


def in_bands(diff):
    """The overlay's pixels lie in its top and bottom rows, in the picture's left half."""
    h, w = diff.shape
    top, bottom = overlay_insets(h)
    return (diff[:top, : w // 2].any() and diff[h - bottom :, : w // 2].any()
            and not diff[top : h - bottom].any() and not diff[:, w // 2 :].any())


def test_world_view_overlay_is_off_by_default_and_only_writes_in_its_bands(gl_ctx):
    world = deforma.load_scene("sample")
    view = WorldView(Renderer(gl_ctx, (320, 180), samples=0), world)
    try:
        plain = view.draw()
        view.overlay = True
        marked = view.draw()
        framed = view.renderer.read()              # the same frame without the text
        view.overlay = False
        again = view.draw()
    finally:
        view.renderer.release()
    assert np.array_equal(plain, again)            # off: the frame is exactly the renderer's
    assert in_bands(changed(framed, marked))


@pytest.mark.parametrize("size", [(320, 180), (1280, 720), (400, 400)])
@pytest.mark.parametrize("name", ["explode", "demo", "dent", "balloon", "pile", "jelly", "car"])
def test_the_overlay_covers_no_collider_or_body(gl_ctx, name, size):
    # issue 50: the scale bar's label lay over the floor of explode, demo, dent and balloon
    view = WorldView(Renderer(gl_ctx, size, samples=0), deforma.load_scene(name), overlay=True)
    r = view.renderer
    try:
        marked = view.draw()
        framed = r.read()                          # the frame the text was written onto
        r.render()                                 # the same camera with nothing in the world
        empty = r.read()
    finally:
        r.release()
    text = changed(framed, marked)
    assert in_bands(text)
    covered = changed(framed, empty) & text
    assert not covered.any(), f"{name} {size}: the overlay covers {covered.sum()} pixels of the scene"


def read_frames(folder):
    return [np.asarray(Image.open(p).convert("RGB")) for p in sorted(folder.glob("frame_*.png"))]


def test_deforma_run_overlay_flag(tmp_path, capsys):
    args = ["run", "sample", "--seconds", "0.1", "--fps", "20", "--size", "320x180", "--samples", "0", "--quiet"]
    assert main([*args, "-o", f"{tmp_path / 'plain'}/"]) == 0
    assert main([*args, "-o", f"{tmp_path / 'marked'}/", "--overlay"]) == 0
    capsys.readouterr()
    plain, marked = read_frames(tmp_path / "plain"), read_frames(tmp_path / "marked")
    assert len(plain) == len(marked) == 2
    # without the flag the first frame is exactly what a WorldView draws of the scene's start
    view = WorldView(Renderer.headless((320, 180), samples=0), deforma.load_scene("sample"))
    try:
        assert np.array_equal(plain[0], view.draw())
    finally:
        view.renderer.release()
    # with it the first frame is the scene framed between the text, and the text
    view = WorldView(Renderer.headless((320, 180), samples=0), deforma.load_scene("sample"), overlay=True)
    try:
        assert np.array_equal(marked[0], view.draw())
        assert in_bands(changed(view.renderer.read(), marked[0]))
    finally:
        view.renderer.release()
    # the frames' clocks differ (0.00 s, 0.05 s)
    top = overlay_insets(180)[0]
    assert changed(marked[0][:top, :160], marked[1][:top, :160]).any()


def test_show_overlay_marks_the_frames():
    kwargs = {"seconds": 0.1, "fps": 10, "size": (320, 180), "format": "gif"}
    plain = deforma.show("sample", **kwargs).last_frame
    marked = deforma.show("sample", overlay=True, **kwargs).last_frame
    top, bottom = overlay_insets(180)
    diff = changed(plain, marked)  # framed between the text, so the whole picture moved a little
    assert diff[:top, :160].any() and diff[-bottom:, :160].any()


def test_a_camera_that_follows_a_body_keeps_its_centre_of_mass_in_the_middle():
    # the car scene's [camera] follows its chassis (body 0)
    world = deforma.load_scene("car")
    r = Renderer.headless((160, 90), samples=0)
    try:
        view = WorldView(r, world)
        chassis = world.bodies[0]
        assert view.follow is chassis
        for _ in range(120):
            world.step()
        view.draw(read=False)
        np.testing.assert_allclose(r.camera.center, chassis.center_of_mass)
        assert chassis.center_of_mass[0] > -3.0  # it drove off (from -3.35 m): the camera went along
        size = r.camera.size
        view.follow = None  # a view that follows nothing keeps its camera
        world.step()
        view.draw(read=False)
        assert r.camera.center != tuple(chassis.center_of_mass) and r.camera.size == size
    finally:
        r.release()

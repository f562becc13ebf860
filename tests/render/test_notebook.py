"""deforma.show: a scene or a world as an animation that plays inline in a notebook."""

import base64
import io
import re
import subprocess
import sys
import textwrap
from dataclasses import replace

import numpy as np
import pytest
from PIL import Image

import deforma
from deforma.render import notebook
from deforma.scene import Event

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def is_mp4(data: bytes) -> bool:
    return data[4:8] == b"ftyp"  # an ISO media file starts with its ftyp box


def embedded(html: str, mime: str) -> bytes:
    m = re.search(rf'src="data:{re.escape(mime)};base64,([A-Za-z0-9+/=]+)"', html)
    assert m, html[:200]
    return base64.b64decode(m.group(1))


@pytest.fixture(scope="module")
def sample():
    # module scope: a headless context per show() call is the expensive part, make one
    return deforma.show("sample", seconds=1.0, size=192)


def test_show_a_scene_embeds_an_mp4_video(sample):
    anim = sample
    assert isinstance(anim, notebook.Animation)
    assert anim.format == "mp4" and is_mp4(anim.data)
    assert anim.size == (192, 108)           # the sample's camera is 8 x 4.5 m: 16:9
    assert anim.fps == 30.0 and anim.n_frames == 30 and anim.duration == pytest.approx(1.0)
    html = anim._repr_html_()
    assert html.startswith("<video") and "autoplay" in html and "loop" in html and "muted" in html
    assert 'width="192" height="108"' in html
    assert embedded(html, "video/mp4") == anim.data
    assert "30 frames at 30 frames/s" in repr(anim)


def test_the_last_frame_is_a_still_picture_of_the_scene(sample):
    png = sample._repr_png_()
    assert png[:8] == PNG_SIGNATURE
    img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    assert img.shape == (108, 192, 3)
    # the sample's box is drawn in its scene colour #e07a5f, resting on the grey plane
    box = np.all(np.abs(img - (0xE0, 0x7A, 0x5F)) < 40, axis=-1)
    assert box.mean() > 0.02
    assert img.std() > 20  # not blank


def test_frames_decode_to_what_was_drawn(sample):
    frames = list(sample.frames())
    assert len(frames) == sample.n_frames
    assert frames[-1].shape == (108, 192, 3)
    # H.264 is lossy: close to the drawn frame, not equal
    assert np.abs(frames[-1].astype(int) - sample.last_frame.astype(int)).mean() < 6


def test_save_writes_the_same_bytes_or_converts(sample, tmp_path):
    out = sample.save(tmp_path / "a.mp4")
    assert out == tmp_path / "a.mp4" and out.read_bytes() == sample.data
    sample.save(tmp_path / "a.gif")
    with Image.open(tmp_path / "a.gif") as im:
        assert im.n_frames == sample.n_frames and im.size == (192, 108)
    sample.save(tmp_path / "frames/")
    assert len(list((tmp_path / "frames").glob("frame_*.png"))) == sample.n_frames
    with pytest.raises(ValueError, match="unknown output type '.avi'"):
        sample.save(tmp_path / "a.avi")
    with pytest.raises(ValueError, match="does not exist"):
        sample.save(tmp_path / "missing" / "a.mp4")
    assert not list(tmp_path.glob(".*partial*"))


def test_gif_format_embeds_an_animated_image(tmp_path):
    anim = deforma.show("sample", seconds=0.5, fps=10, size=(96, 64), format="gif")
    assert anim.format == "gif" and anim.data[:6] == b"GIF89a" and anim.n_frames == 5
    html = anim._repr_html_()
    assert html.startswith("<img")
    with Image.open(io.BytesIO(embedded(html, "image/gif"))) as im:
        assert im.n_frames == 5 and im.size == (96, 64)
    assert is_mp4(anim.save(tmp_path / "b.mp4").read_bytes())


def test_gif_is_the_default_without_imageio_ffmpeg(monkeypatch):
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # as if not installed
    assert notebook._check_format(None) == "gif"


def test_an_animation_over_the_embed_limit_shows_its_last_frame_and_a_note(sample, monkeypatch):
    monkeypatch.setattr(notebook, "MAX_EMBED_BYTES", len(sample.data) - 1)
    html = sample._repr_html_()
    assert "<video" not in html and "more than the" in html and ".save(" in html
    assert embedded(html, "image/png")[:8] == PNG_SIGNATURE


def body_rows(frame, colour=(0xE0, 0x7A, 0x5F)):
    """Mean row of the pixels in a body's colour (the default first body colour)."""
    rows, _ = np.nonzero(np.all(np.abs(frame.astype(int) - colour) < 40, axis=-1))
    return rows.mean()


@pytest.mark.parametrize("integrator", ["symplectic-euler", "implicit-euler", "xpbd"])
def test_show_leaves_a_world_as_it_was(integrator):
    world = deforma.World(integrator=integrator)
    world.add_collider(deforma.Rect(center=(0, -0.25), size=(4, 0.5), angle=0.0))
    body = world.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=3), position=(0, 0.6))
    for _ in range(60):  # resting on the floor: the implicit integrator holds a factor now
        world.step()
    t, x, v = world.time, body.positions.copy(), body.velocities.copy()
    first = deforma.show(world, seconds=0.5, fps=20, size=160)
    assert first.n_frames == 10  # the first at the start, the last 9 / 20 s later
    assert world.time == t and world.step_count == 60
    np.testing.assert_array_equal(body.positions, x)
    np.testing.assert_array_equal(body.velocities, v)
    again = deforma.show(world, seconds=0.5, fps=20, size=160)
    np.testing.assert_array_equal(first.last_frame, again.last_frame)  # the same start, the same film
    world.step()  # and the world goes on from where it was
    assert world.time == pytest.approx(t + world.dt)


def test_show_plays_a_world_made_in_code_in_a_camera_that_frames_it():
    world = deforma.World()
    world.add_collider(deforma.Rect(center=(0, -0.25), size=(4, 0.5), angle=0.0))
    world.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=3), position=(0, 2))
    frames = list(deforma.show(world, seconds=0.5, fps=20, size=160, format="gif").frames())
    assert body_rows(frames[-1]) > body_rows(frames[0]) + 10  # it fell (rows grow downwards)
    # no camera was chosen: one frames the world (the default camera would show it too,
    # but a world far from the origin would be off the picture)
    far = deforma.World()
    far.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=3), position=(100, 100))
    frame = deforma.show(far, seconds=0.1, size=160).last_frame.astype(int)
    assert np.all(np.abs(frame - (0xE0, 0x7A, 0x5F)) < 40, axis=-1).mean() > 0.05


def test_show_a_world_keeps_its_scene_camera_and_fires_its_events():
    scene = deforma.scene.load("sample")
    kicked = replace(scene, event=(Event(time=0.05, strength=4.0),)).build()
    anim = deforma.show(kicked, seconds=0.2, size=128)
    assert anim.size == (128, 72)
    assert kicked.time == 0.0  # shown, not stepped
    still = deforma.show(scene.build(), seconds=0.2, size=128)
    # the explosion at 0.05 s sent the box up; without it, the box only fell
    assert body_rows(anim.last_frame) < body_rows(still.last_frame) - 5
    # the animation runs a copy of the world: the looks still come from the world's scene
    blue = replace(scene, body=(replace(scene.body[0], color="#2040c0"),)).build()
    frame = deforma.show(blue, seconds=0.1, size=128).last_frame
    assert np.all(np.abs(frame.astype(int) - (0x20, 0x40, 0xC0)) < 40, axis=-1).mean() > 0.02


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"scene_or_world": "no-such-scene"}, r"unknown scene 'no-such-scene'"),
    ({"scene_or_world": "missing.toml"}, r"missing.toml: no such scene file"),
    ({"seconds": 0}, r"seconds must be a number in \(0, 600\] s, got 0"),
    ({"seconds": -1.0}, r"seconds must be a number in \(0, 600\] s, got -1.0"),
    ({"seconds": float("nan")}, r"seconds must be a number"),
    ({"seconds": True}, r"seconds must be a number"),
    ({"fps": 0}, r"fps must be a number in \(0, 120\] frames/s"),
    ({"fps": 500}, r"fps must be a number in \(0, 120\] frames/s"),
    ({"size": 8}, r"size must be a width in pixels or \(width, height\), each a whole number in \[16, 1920\]"),
    ({"size": (640, 4000)}, r"size must be a width in pixels or \(width, height\)"),
    ({"size": (640,)}, r"size must be a width"),
    ({"size": "640x360"}, r"size must be a width"),
    ({"size": 320.5}, r"size must be a width"),
    ({"format": "webm"}, r"format must be one of 'mp4', 'gif' or None, got 'webm'"),
    ({"overlay": "no"}, r"overlay must be True or False, got 'no'"),
    ({"seconds": 600, "fps": 60}, r"gives 36000 frames; at most 1800"),
])
def test_bad_input_is_one_clear_value_error_line(kwargs, message):
    kwargs = {"scene_or_world": "sample", **kwargs}
    with pytest.raises(ValueError, match=message) as e:
        deforma.show(kwargs.pop("scene_or_world"), **kwargs)
    assert "\n" not in str(e.value)


def test_not_a_scene_or_world_is_a_type_error():
    with pytest.raises(TypeError, match="needs a built-in scene name, a path to a .toml scene, a Scene or a World"):
        deforma.show(42)


def test_import_deforma_stays_light_and_show_is_found_on_use():
    code = textwrap.dedent(
        """
        import sys
        import deforma
        assert "show" in dir(deforma) and "show" in deforma.__all__
        assert not [k for k in sys.modules if k.startswith(("deforma.render", "moderngl", "pygame"))]
        show = deforma.show
        from deforma.render.notebook import show as real
        assert show is real and deforma.show is real
        assert "moderngl" not in sys.modules  # imported only when something is drawn
        try:
            deforma.nothing_here
        except AttributeError as e:
            assert "no attribute 'nothing_here'" in str(e)
        print("ok")
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"

"""Image bodies on any background: the ``background`` and ``threshold`` keys (issue 18)."""

import numpy as np
import pytest
from PIL import Image
from scene_checks import assert_refused, write

import deforma
from deforma import scene as scenes
from deforma.mesh.image import foreground_mask

R = 40  # px
SCALE = 0.01  # m/px
DISC_AREA = np.pi * (R * SCALE) ** 2  # m^2


@pytest.fixture
def disc_png(tmp_path):
    """A dark disc of radius R on white, as a photo-like picture would be."""
    yy, xx = np.mgrid[0:120, 0:120] + 0.5
    img = np.full((120, 120, 3), 255, np.uint8)
    img[(xx - 60) ** 2 + (yy - 60) ** 2 < R**2] = (50, 40, 35)
    path = tmp_path / "disc.png"
    Image.fromarray(img).save(path)
    return path


def image_scene(tmp_path, keys):
    return write(tmp_path, f"""
        [[body]]
        shape = "image"
        source = "disc.png"
        resolution = 6
        edge_step = 3
        scale = {SCALE}
        position = [0.0, 1.0]
        {keys}
        """)


@pytest.mark.parametrize("keys", ['background = "white"', 'background = "auto"', 'background = "#FFFFFF"',
                                  'background = "white"\nthreshold = 0.2'])
def test_an_image_body_on_white_is_the_disc(tmp_path, disc_png, keys):
    world = scenes.load_scene(image_scene(tmp_path, keys))
    assert world.bodies[0].mesh.area == pytest.approx(DISC_AREA, rel=0.02)


def test_background_and_threshold_round_trip(tmp_path, disc_png):
    path = image_scene(tmp_path, 'background = "#FFFFFF"\nthreshold = 0.2')
    spec = scenes.load(path).body[0]
    assert (spec.background, spec.threshold) == ("#ffffff", 0.2)
    saved = deforma.save_scene(deforma.load_scene(path), tmp_path / "saved.toml")
    text = saved.read_text()
    assert 'background = "#ffffff"' in text and "threshold = 0.2" in text
    again = scenes.load(saved).body[0]
    assert (again.background, again.threshold) == ("#ffffff", 0.2)
    assert deforma.load_scene(saved).bodies[0].mesh.area == pytest.approx(DISC_AREA, rel=0.02)
    # the defaults: background written (every key is), threshold left to the picture's kind
    text = deforma.save_scene(deforma.load_scene("textures"), tmp_path / "t.toml").read_text()
    assert 'background = "black"' in text and "threshold" not in text


def test_defaults_are_the_seed_rule():
    spec = scenes.schema.ImageBody()
    assert (spec.background, spec.threshold) == ("black", None)


@pytest.mark.parametrize("keys, message", [
    ('background = "whte"', "body[0].background: unknown value string 'whte'; did you mean 'white'? allowed: black, "
                            "white, auto or a colour '#rrggbb'"),
    ('background = "#12345"', "body[0].background: unknown value"),
    ('background = "#ffffff80"', "body[0].background: unknown value"),
    ("background = [255, 255, 255]", "body[0].background: unknown value array"),
    ("threshold = 1.0", "body[0].threshold: must be in [0, 1), got 1"),
    ("threshold = -0.5", "body[0].threshold: must be in [0, 1)"),
    ('threshold = "low"', "body[0].threshold: expected a number"),
])
def test_bad_values_are_refused_on_load(tmp_path, disc_png, keys, message):
    assert_refused(image_scene(tmp_path, keys), message)


def test_a_picture_not_on_its_background_is_refused_when_built(tmp_path, disc_png):
    # the seed's default (black) on a white picture would make the whole rectangle the body
    assert_refused(image_scene(tmp_path, ""), "body[0]: the whole picture is foreground")
    assert_refused(image_scene(tmp_path, 'background = "white"\nthreshold = 0.9'), "body[0]: the picture has no "
                                                                                     "foreground")


def test_the_texture_drawn_is_transparent_off_the_shape(tmp_path, disc_png):
    world = scenes.load_scene(image_scene(tmp_path, 'background = "white"'))
    texture = world.bodies[0].mesh.texture
    mask = foreground_mask(disc_png, background="white")
    assert np.array_equal(texture[..., 3] > 0, mask)
    assert np.array_equal(scenes.load_texture(str(disc_png), background="white"), texture)


def test_load_texture_checks_its_background_and_threshold(disc_png):
    for kwargs in ({"background": "blue-ish"}, {"background": [255, 255]}, {"threshold": [0.1]},
                   {"threshold": 1.0}):
        with pytest.raises(ValueError, match="background must be|threshold must be") as e:
            scenes.load_texture(str(disc_png), **kwargs)
        assert "\n" not in str(e.value)
    # every spelling of a colour is one cache entry and one answer
    a = scenes.load_texture(str(disc_png), background="#FFFFFF")
    assert scenes.load_texture(str(disc_png), background=[255, 255, 255]) is a
    assert scenes.load_texture(str(disc_png), background=np.array([255, 255, 255])) is a

"""Pictures on any background: ``from_image(background=..., threshold=...)`` (issue 18).

Known answers: a disc of radius R meshes into pi R^2 whatever it is drawn on, once the
background is named; "auto" is the border's colour; transparency decides when present; the
default is the seed's rule (non-black); every bad value is one ValueError line.
"""

import numpy as np
import pytest
from PIL import Image

import deforma
from deforma.mesh import from_image
from deforma.mesh.image import (BUILTIN_TEXTURES, COLOR_THRESHOLD, _border_rgb, builtin_textures, foreground_mask,
                                load_rgba, read_rgba)

R = 60  # px, the disc's radius
SIZE = 200  # px, the picture's side
DISC_AREA = np.pi * R**2
INK = (40, 30, 60)  # a dark, nearly black colour: neither black nor white background suits both


def disc_mask(size=SIZE, r=R, centre=None):
    yy, xx = np.mgrid[0:size, 0:size] + 0.5
    cy, cx = centre if centre is not None else (size / 2, size / 2)
    return (xx - cx) ** 2 + (yy - cy) ** 2 < r**2


def disc_on(background, ink=INK, **kw):
    """An RGB picture: a disc of ``ink`` on ``background``."""
    img = np.empty((SIZE, SIZE, 3), np.uint8)
    img[:] = background
    img[disc_mask(**kw)] = ink
    return img


def one_line_value_error(match, fn, *args, **kwargs):
    with pytest.raises(ValueError, match=match) as info:
        fn(*args, **kwargs)
    assert "\n" not in str(info.value)
    return str(info.value)


def test_dark_disc_on_white_meshes_into_the_disc():
    on_white = from_image(disc_on((255, 255, 255)), background="white", scale=1.0)
    on_black = from_image(disc_on((0, 0, 0), ink=(200, 180, 160)), scale=1.0)  # the seed's default
    assert on_white.area == pytest.approx(DISC_AREA, rel=0.01)
    assert on_white.area == pytest.approx(on_black.area, rel=1e-9)  # the same pixels, the same mesh
    assert len(on_white.boundary) == 1 and on_white.euler_characteristic == 1
    # and in metres: 1 cm per pixel
    assert from_image(disc_on((255, 255, 255)), background="white", scale=0.01).area == pytest.approx(
        DISC_AREA * 1e-4, rel=0.01)


def test_photo_like_jpeg_on_white(tmp_path):
    # JPEG noise around a flat white background stays background at the default threshold
    path = tmp_path / "disc.jpg"
    Image.fromarray(disc_on((255, 255, 255))).save(path, quality=85)
    for background in ("white", "auto"):
        m = from_image(path, background=background, scale=1.0)
        assert m.area == pytest.approx(DISC_AREA, rel=0.02), background
        assert len(m.boundary) == 1


def test_auto_is_the_border_colour():
    blue = (30, 120, 200)
    img = disc_on(blue)
    assert _border_rgb(read_rgba(img), 255 * COLOR_THRESHOLD) == blue
    auto = from_image(img, background="auto", scale=1.0)
    given = from_image(img, background=blue, scale=1.0)
    assert np.array_equal(auto.vertices, given.vertices) and np.array_equal(auto.triangles, given.triangles)
    assert auto.area == pytest.approx(DISC_AREA, rel=0.01)
    # the median ignores a shape that touches the border on one side (a third of the top row)
    touching = disc_on(blue, centre=(R - 20, SIZE / 2))
    assert _border_rgb(read_rgba(touching), 255 * COLOR_THRESHOLD) == blue
    inside = disc_mask(centre=(R - 20, SIZE / 2))
    assert from_image(touching, background="auto", scale=1.0).area == pytest.approx(inside.sum(), rel=0.01)


def test_auto_on_black_and_white_pictures_gives_the_named_backgrounds():
    for bg, name in (((0, 0, 0), "black"), ((255, 255, 255), "white")):
        img = disc_on(bg, ink=(128, 60, 200))
        assert np.array_equal(foreground_mask(img, background="auto"), foreground_mask(img, background=name))


def test_colour_backgrounds_in_every_form():
    green = (60, 170, 90)
    img = disc_on(green)
    areas = [from_image(img, background=bg, scale=1.0).area
             for bg in (green, list(green), np.array(green), "#3caa5a", "#3CAA5A", " #3caa5a ")]
    assert areas == pytest.approx([DISC_AREA] * len(areas), rel=0.01)
    assert len(set(areas)) == 1
    # a background colour the picture is not on: the whole picture would be the body, refused
    one_line_value_error("whole picture is foreground", from_image, img, background="white")


def test_threshold_is_the_largest_channel_difference_as_a_fraction():
    # on white, a square 40 grey levels off (0.157 of full scale) in one channel and a square
    # 20 levels off (0.078) in all three: both count at 0.06, only the first at 0.1
    img = np.full((120, 200, 3), 255, np.uint8)
    img[20:100, 20:90] = (255, 215, 255)
    img[20:100, 110:180] = (235, 235, 235)
    square = 80 * 70
    assert foreground_mask(img, background="white").sum() == 2 * square
    assert foreground_mask(img, background="white", threshold=0.1).sum() == square
    assert foreground_mask(img, background="white", threshold=0.2).sum() == 0
    assert from_image(img, background="white", threshold=0.1, scale=1.0).area == pytest.approx(square, rel=0.002)
    # the cut is strict: exactly 20/255 off is background at threshold 20/255, foreground below
    assert foreground_mask(img, background="white", threshold=20 / 255).sum() == square
    assert foreground_mask(img, background="white", threshold=19.5 / 255).sum() == 2 * square
    # threshold 0: any difference at all
    assert foreground_mask(img, background=(235, 235, 235), threshold=0.0).sum() == 120 * 200 - square


def test_default_is_the_seed_rule_brightest_channel_above_6_percent():
    # 4 x 4 blocks (above the speck size) whose brightest channel runs 0..40
    levels = np.arange(41, dtype=np.uint8)
    img = np.zeros((8, 4 * len(levels), 3), np.uint8)
    for k, v in enumerate(levels):
        img[2:6, 4 * k : 4 * k + 4, k % 3] = v
    fg = foreground_mask(img)
    lit = fg[3].reshape(-1, 4).all(axis=1)
    assert np.array_equal(lit, levels > 0.06 * 255)  # 16 and up: 15.3 is the cut
    assert np.array_equal(fg, foreground_mask(img, background="black"))
    assert np.array_equal(fg, foreground_mask(img, background="#000000", threshold=0.06))


def test_transparency_wins_over_any_background():
    # an opaque WHITE disc on a transparent white background: by colour (on white) there would
    # be nothing; alpha says the disc is the shape, whatever background is named
    rgba = np.zeros((SIZE, SIZE, 4), np.uint8)
    rgba[..., :3] = 255
    rgba[disc_mask(), 3] = 255
    for bg in ("black", "white", "auto", (255, 255, 255), "#123456"):
        m = from_image(rgba, background=bg, scale=1.0)
        assert m.area == pytest.approx(DISC_AREA, rel=0.01), bg
    # threshold is then the alpha level: a half-transparent ring counts at 0.4, not at 0.6
    ring = disc_mask(r=R + 20) & ~disc_mask()
    rgba[ring, 3] = 128
    outer = np.pi * (R + 20) ** 2
    assert from_image(rgba, threshold=0.4, scale=1.0).area == pytest.approx(outer, rel=0.01)
    assert from_image(rgba, threshold=0.6, scale=1.0).area == pytest.approx(DISC_AREA, rel=0.01)
    # an alpha channel without transparency does not decide: the colours do
    opaque = np.dstack([disc_on((255, 255, 255)), np.full((SIZE, SIZE), 255, np.uint8)])
    assert from_image(opaque, background="white", scale=1.0).area == pytest.approx(DISC_AREA, rel=0.01)


def test_the_texture_hides_the_background():
    img = disc_on((255, 255, 255))
    m = from_image(img, background="white", scale=1.0)
    mask = foreground_mask(img, background="white")
    assert np.array_equal(m.texture[..., 3], np.where(mask, 255, 0))
    assert np.array_equal(m.texture[..., :3], img)  # colours as they were
    assert np.array_equal(load_rgba(img, background="white"), m.texture)
    # a picture with transparency keeps its own alpha
    bunny = from_image("bunny", resolution=16, edge_step=8)
    assert np.array_equal(bunny.texture, read_rgba("bunny"))


def test_one_loader_one_texture_list(tmp_path):
    from deforma import scene

    assert scene.builtin_textures() == builtin_textures()
    assert BUILTIN_TEXTURES == tuple(builtin_textures()) == ("armadillo", "bunny", "donut")
    # a scene's texture is the same picture the mesher reads, with the same background rule
    path = tmp_path / "disc.png"
    Image.fromarray(disc_on((255, 255, 255))).save(path)
    assert np.array_equal(scene.load_texture(str(path), background="white"), load_rgba(path, background="white"))
    # (the seed's loader cut at 16 and decided transparency by file mode; now one rule)
    grey = np.zeros((12, 12, 3), np.uint8)
    grey[2:10, 2:10] = 16
    Image.fromarray(grey).save(tmp_path / "grey.png")
    assert scene.load_texture(str(tmp_path / "grey.png"))[5, 5, 3] == 255
    assert np.array_equal(scene.load_texture("donut"), read_rgba("donut"))
    msg = one_line_value_error("not found", from_image, "rabbit")
    assert all(repr(name) in msg for name in BUILTIN_TEXTURES)


@pytest.mark.parametrize("background", ["blak", "grey", "", "#fff", "#ffffff00", "#gggggg", "ffffff", (1, 2),
                                        (0, 0, 256), (-1, 0, 0), (0.5, 0.5, 0.5), (True, False, True), None, 255])
def test_bad_backgrounds(background):
    msg = one_line_value_error("background must be", from_image, disc_on((255, 255, 255)), background=background)
    for allowed in ('"black"', '"white"', '"auto"', '"#rrggbb"', "(r, g, b)", "0-255"):
        assert allowed in msg


@pytest.mark.parametrize("threshold", [-0.1, 1.0, 1.5, 255, float("nan"), "high", True])
def test_bad_thresholds(threshold):
    msg = one_line_value_error(r"threshold must be a number in \[0, 1\)", from_image, "donut", threshold=threshold)
    assert "fraction of full scale" in msg


def test_backgrounds_that_leave_nothing_or_everything():
    white_disc = disc_on((255, 255, 255))
    # default (black) on a picture with no black: the whole rectangle, refused with a hint
    msg = one_line_value_error("whole picture is foreground", from_image, white_disc)
    assert "'black' (#000000)" in msg and "border is #ffffff" in msg and '"auto"' in msg
    msg = one_line_value_error("has no foreground", from_image, np.full((50, 50, 3), 255, np.uint8),
                               background="white")
    assert "'white' (#ffffff)" in msg and "threshold 0.06" in msg
    one_line_value_error("has no foreground", from_image, white_disc, background="white", threshold=0.99)
    one_line_value_error("has no foreground", from_image, disc_on((9, 9, 9), ink=(12, 12, 12)), background="auto")
    # with transparency: all transparent, or nothing transparent enough
    rgba = np.zeros((50, 50, 4), np.uint8)
    rgba[..., 3] = 200
    one_line_value_error("whole picture is foreground.*alpha", from_image, rgba)
    one_line_value_error("has no foreground.*alpha", from_image, rgba, threshold=0.9)


def test_auto_needs_a_border_of_one_colour():
    noise = np.random.default_rng(0).integers(0, 256, (100, 100, 3), dtype=np.uint8)
    msg = one_line_value_error('background="auto" found no main colour', from_image, noise, background="auto")
    assert "give the background" in msg
    # half black, half white: no main colour either
    halves = np.zeros((100, 100, 3), np.uint8)
    halves[:, 50:] = 255
    one_line_value_error("no main colour", from_image, halves, background="auto")


def test_the_public_signature():
    import inspect

    sig = inspect.signature(deforma.mesh.from_image)
    for name, default in (("background", "black"), ("threshold", None)):
        assert sig.parameters[name].kind is inspect.Parameter.KEYWORD_ONLY
        assert sig.parameters[name].default == default

"""Pictures of meshes and worlds (Pillow, no OpenGL): what a notebook shows for a Mesh or a World."""

import io
import subprocess
import sys
import textwrap
from types import SimpleNamespace

import numpy as np
import pytest
from PIL import Image

import deforma
from deforma.mesh import Mesh, picture

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def decode(png: bytes) -> np.ndarray:
    assert png[:8] == PNG_SIGNATURE
    with Image.open(io.BytesIO(png)) as im:
        assert im.format == "PNG"
        return np.asarray(im.convert("RGB")).astype(int)


def near(img, color, tol=12):
    """Mask of pixels within ``tol`` of ``color`` in every channel."""
    return np.all(np.abs(img - np.asarray(color)) <= tol, axis=-1)


def background_fraction(img):
    return near(img, picture.BACKGROUND, 2).mean()


def square_mesh(n=3, texture=None):
    xs, ys = np.meshgrid(np.linspace(0, 2, n), np.linspace(0, 1, n))
    v = np.c_[xs.ravel(), ys.ravel()]
    i = np.arange(n * n).reshape(n, n)
    a, b, c, d = i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(), i[1:, :-1].ravel()
    return Mesh(v, np.r_[np.c_[a, b, c], np.c_[a, c, d]], texture=texture)


def test_mesh_repr_png_is_a_wireframe_fitted_to_400_pixels():
    img = decode(square_mesh()._repr_png_())
    h, w = img.shape[:2]
    assert w == 400 and h == round(400 * 0.04 * 2 + (400 * 0.92) / 2)  # a 2 x 1 mesh, 4 % margins
    # the mesh covers all but the margin: 368 x 184 of 400 x 216 pixels (the outline blurs ~1 px)
    assert background_fraction(img) == pytest.approx(1 - 368 * 184 / (400 * 216), abs=0.05)
    filled = near(img, picture.MESH_FILL)
    assert filled.mean() > 0.3
    # the edges are drawn: dark pixels along the mesh's middle row (y = 0.5 m) and its outline
    dark = img.sum(axis=-1) < sum(picture.MESH_FILL) - 60  # a 1 px line, blended by the shrink
    assert dark[h // 2 - 2 : h // 2 + 2, 20:-20].any(axis=0).mean() > 0.9
    assert dark[:, 20:-20].any(axis=1).sum() > 3
    # the margin is empty: the corners of the picture are background
    assert near(img[:10, :10], picture.BACKGROUND, 2).all()


def test_mesh_picture_takes_the_texture_colours():
    red = np.zeros((8, 8, 4), np.uint8)
    red[..., 0], red[..., 3] = 220, 255
    img = np.asarray(picture.mesh_picture(square_mesh(texture=red), size=200)).astype(int)
    assert near(img, (220, 0, 0), 20).mean() > 0.4
    assert not near(img, picture.MESH_FILL).any()


def test_a_transparent_sample_takes_the_mean_opaque_colour():
    tex = np.zeros((4, 4, 4), np.uint8)
    tex[:, :2] = (0, 0, 200, 255)   # left half blue and opaque, right half transparent
    colors = picture._triangle_colors([[0, 1, 2], [0, 2, 3]], [[0, 0], [1, 0], [1, 1], [0, 1]], tex, (1, 2, 3))
    # both centres fall where the picture is opaque blue or transparent: either way blue
    assert colors.tolist() == [[0, 0, 200], [0, 0, 200]]


def test_a_dense_mesh_is_drawn_without_its_edges():
    m = deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=150)  # ~45 000 triangles
    img = np.asarray(picture.mesh_picture(m, size=200)).astype(int)
    assert near(img, picture.MESH_FILL).mean() > 0.7      # a solid fill, not a dark blot of lines
    assert (img.sum(axis=-1) < 350).mean() < 0.01


def test_world_repr_png_shows_bodies_and_colliders_where_they_are():
    world = deforma.World()
    world.add_collider(deforma.Rect(center=(0, -0.25), size=(4, 0.5), angle=0.0))
    world.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=3), position=(-1.0, 2.0))
    img = decode(world._repr_png_())
    h, w = img.shape[:2]
    assert max(h, w) == 400
    body = near(img, picture.BODY_FILLS[0], 20)
    collider = near(img, picture.COLLIDER_FILL, 20)
    assert body.mean() > 0.03 and collider.mean() > 0.03
    rows_b, cols_b = np.nonzero(body)
    rows_c, cols_c = np.nonzero(collider)
    assert rows_b.max() < rows_c.min()            # the body is above the ground (y up)
    assert cols_b.mean() < w / 2 < cols_c.mean() + 20  # and left of the middle, the ground centred
    # the picture follows the state: move the body right and it moves in the picture
    world.bodies[0].positions = world.bodies[0].positions + (2.0, 0.0)
    moved = near(decode(world._repr_png_()), picture.BODY_FILLS[0], 20)
    assert np.nonzero(moved)[1].mean() > w / 2


def test_world_picture_of_a_scene_uses_the_bodies_textures():
    world = deforma.load_scene("demo")  # a textured bunny: no flat palette colour anywhere
    img = np.asarray(picture.world_picture(world)).astype(int)
    assert not near(img, picture.BODY_FILLS[0], 3).any()
    assert (~near(img, picture.BACKGROUND, 2) & ~near(img, picture.COLLIDER_FILL, 30)).mean() > 0.005


def test_an_empty_world_is_a_blank_picture():
    img = decode(deforma.World()._repr_png_())
    assert img.shape[:2] == (400, 400)
    assert background_fraction(img) == 1.0


def test_collider_shapes_by_their_attributes():
    # Rect's corners, a polygon's points, a circle's centre and radius, a segment's ends
    colliders = [
        SimpleNamespace(points=[(0, 0), (1, 0), (0.5, 1)]),
        SimpleNamespace(center=(3, 0.5), radius=0.5),
        SimpleNamespace(a=(0, -1), b=(4, -1), radius=0.2),
        SimpleNamespace(a=(0, -2), b=(4, -2), radius=0.0),
    ]
    fake = SimpleNamespace(bodies=[], colliders=colliders)
    lo, hi = picture.content_bounds(fake)
    np.testing.assert_allclose(lo, [-0.2, -2.0], atol=1e-9)
    np.testing.assert_allclose(hi, [4.2, 1.0], atol=1e-9)
    img = np.asarray(picture.world_picture(fake)).astype(int)
    assert near(img, picture.COLLIDER_FILL, 20).mean() > 0.05
    with pytest.raises(TypeError, match="cannot draw a collider of type object"):
        picture.world_picture(SimpleNamespace(bodies=[], colliders=[object()]))


@pytest.mark.parametrize("size", [8, 5000, 400.0, True, "400"])
def test_bad_sizes_are_one_line_value_errors(size):
    with pytest.raises(ValueError, match=r"size must be a whole number of pixels in \[16, 4096\]") as e:
        picture.mesh_picture(square_mesh(), size=size)
    assert "\n" not in str(e.value)


def test_pictures_need_no_gl_or_video_package():
    code = textwrap.dedent(
        """
        import sys
        for name in ("moderngl", "glcontext", "pygame", "pygame_gui", "imageio", "imageio_ffmpeg"):
            sys.modules[name] = None
        import deforma
        m = deforma.mesh.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=4)
        w = deforma.load_scene("sample")
        assert m._repr_png_()[:4] == w._repr_png_()[:4] == b"\\x89PNG"
        assert not any(k.startswith("deforma.render") for k in sys.modules)
        print("ok")
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"

"""Headless rendering with EGL: pixels land where the geometry is."""

import numpy as np
import pytest

from deforma.render import Camera, Renderer, collider_corners

RED = [255, 0, 0]


def body_mask(img):
    """Pixels of a red body: its fill (255, 0, 0) or its darker outline (153, 0, 0)."""
    return (img[..., 0] > 100) & (img[..., 1] < 60) & (img[..., 2] < 60)


def square_mesh(x0, y0, x1, y1, n=4):
    xs, ys = np.meshgrid(np.linspace(x0, x1, n), np.linspace(y0, y1, n))
    pts = np.c_[xs.ravel(), ys.ravel()]
    i = np.arange(n * n).reshape(n, n)
    a, b, c, d = i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(), i[1:, :-1].ravel()
    tris = np.r_[np.c_[a, b, c], np.c_[a, c, d]].astype(np.int32)
    uv = (pts - (x0, y0)) / (x1 - x0, y1 - y0)
    return pts, tris, uv


@pytest.fixture
def renderer(gl_ctx):
    # 200 x 100 pixels showing x in [-2, 2], y in [-1, 1]: 50 pixels per metre
    r = Renderer(gl_ctx, (200, 100), samples=0, camera=Camera((0, 0), (4, 2)))
    yield r
    r.release()


def test_camera_fits_the_view_to_the_aspect_ratio():
    cam = Camera((1, 2), (4, 2))
    assert cam.extent((200, 100)) == (2.0, 1.0)
    assert cam.extent((100, 100)) == (2.0, 2.0)   # taller picture: more height, same width
    assert cam.extent((400, 100)) == (4.0, 1.0)   # wider picture: more width, same height
    px = cam.world_to_pixel([(1, 2), (-1, 3)], (200, 100))
    np.testing.assert_allclose(px, [[100, 50], [0, 0]])
    np.testing.assert_allclose(cam.pixel_to_world(px, (200, 100)), [[1, 2], [-1, 3]])


def test_camera_rejects_bad_values():
    with pytest.raises(ValueError, match="size must be two positive"):
        Camera((0, 0), (0, 1))
    with pytest.raises(ValueError, match="center must be two finite"):
        Camera((0, float("nan")), (1, 1))


def test_flat_body_covers_exactly_its_pixels(renderer):
    pts, tris, uv = square_mesh(-1.0, -0.5, 0.5, 0.5)
    h = renderer.add_mesh(tris, uv, color="#ff0000")
    renderer.render([(h, pts)])
    img = renderer.read()
    assert img.shape == (100, 200, 3)
    body = body_mask(img)
    rows, cols = np.nonzero(body)
    # x in [-1, 0.5] -> columns [50, 125); y in [-0.5, 0.5] -> rows [25, 75); the 1-px
    # outline on a pixel boundary may fall on either side of it
    np.testing.assert_allclose((cols.min(), cols.max(), rows.min(), rows.max()), (50, 124, 25, 74), atol=1)
    assert abs(int(body.sum()) - 75 * 50) <= 2 * (75 + 50)
    # the fill is exactly the colour asked for; only the one-pixel outline is darker
    assert np.all(img[26:74, 51:124] == RED)


def test_a_dimmed_body_is_darker_in_the_same_place(renderer):
    # the viewer draws sleeping bodies so (WorldView.dim_sleeping)
    pts, tris, uv = square_mesh(-1.0, -0.5, 0.5, 0.5)
    h = renderer.add_mesh(tris, uv, color="#ff0000")
    renderer.render([(h, pts, True)])
    img = renderer.read()
    assert np.all(img[26:74, 51:124] == [153, 0, 0])  # 0.6 of its red
    renderer.render([(h, pts, False)])
    assert np.all(renderer.read()[26:74, 51:124] == RED)


def test_moving_the_body_moves_its_pixels(renderer):
    pts, tris, uv = square_mesh(-1.0, -0.5, 0.5, 0.5)
    h = renderer.add_mesh(tris, uv, color="#ff0000")
    renderer.render([(h, pts + (1.0, 0.2))])   # 50 px right, 10 px up
    rows, cols = np.nonzero(body_mask(renderer.read()))
    np.testing.assert_allclose((cols.min(), cols.max(), rows.min(), rows.max()), (100, 174, 15, 64), atol=1)


def test_texture_is_upright_and_follows_the_uvs(renderer):
    tex = np.zeros((64, 64, 4), np.uint8)
    tex[..., 3] = 255
    tex[:32, :, 0] = 255      # top half of the image red
    tex[32:, :, 2] = 255      # bottom half blue
    pts, tris, uv = square_mesh(-1.0, -1.0, 1.0, 1.0)
    h = renderer.add_mesh(tris, uv, texture=tex)
    renderer.render([(h, pts)])
    img = renderer.read().astype(int)
    top, bottom = img[20, 100], img[80, 100]   # y = +0.6 and y = -0.6
    assert top[0] > 200 and top[2] < 50
    assert bottom[2] > 200 and bottom[0] < 50
    # mirrored uvs put blue on top: the picture really comes from the uvs
    h2 = renderer.add_mesh(tris, uv * (1, -1) + (0, 1), texture=tex)
    renderer.render([(h2, pts)])
    assert renderer.read()[20, 100, 2] > 200


def test_transparent_texels_show_the_background(renderer):
    tex = np.full((8, 8, 4), 255, np.uint8)
    tex[:, :4, 3] = 0         # left half fully transparent
    pts, tris, uv = square_mesh(-1.0, -1.0, 1.0, 1.0)
    renderer.render()
    empty = renderer.read()
    h = renderer.add_mesh(tris, uv, texture=tex, color=(0, 1, 0))
    renderer.render([(h, pts)])
    img = renderer.read()
    np.testing.assert_array_equal(img[50, 60], empty[50, 60])      # x = -0.8: transparent
    assert img[50, 140].tolist() == [0, 255, 0]                   # x = +0.8: tinted green


def test_rotated_collider_is_drawn_where_it_is(renderer):
    renderer.render()
    empty = renderer.read().astype(int)
    rect = ((0.5, 0.0), (2.0, 0.4), 30.0)
    renderer.render(colliders=[rect])
    img = renderer.read().astype(int)
    cam, vp = renderer.camera, renderer.size
    changed = np.abs(img - empty).sum(-1) > 30
    # points inside the rectangle, along its long axis, are drawn
    a = np.radians(30)
    for t in (-0.8, -0.4, 0.0, 0.4, 0.8):
        c, r = cam.world_to_pixel((0.5 + t * np.cos(a), t * np.sin(a)), vp).astype(int)
        assert changed[r, c], (t, c, r)
    # a point beside it (0.5 m off its axis) is not
    c, r = cam.world_to_pixel((0.5 - 0.5 * np.sin(a), 0.5 * np.cos(a)), vp).astype(int)
    assert not changed[r, c]
    # the drawn area is the rectangle's area: 2 m * 0.4 m * 2500 px/m^2 = 2000 px
    assert abs(changed.sum() - 2000) < 150


def test_collider_corners_are_counter_clockwise_and_rotated():
    c = collider_corners((1, 1), (2, 1), 90.0)
    np.testing.assert_allclose(c, [[1.5, 0], [1.5, 2], [0.5, 2], [0.5, 0]], atol=1e-12)


def test_wireframe_draws_the_springs_over_the_body(renderer):
    pts, tris, uv = square_mesh(-1.0, -1.0, 1.0, 1.0, n=5)
    h = renderer.add_mesh(tris, uv, color="#ff0000")
    renderer.render([(h, pts)])
    plain = np.all(renderer.read() == RED, axis=-1).sum()
    renderer.render([(h, pts)], wireframe=True)
    wired = np.all(renderer.read() == RED, axis=-1).sum()
    # plain: only the outline (4 sides of 100 px) is darker; wired: the interior springs too
    assert 100 * 100 - 4 * 101 <= plain < 100 * 100
    assert 0.05 * plain < plain - wired < 0.5 * plain


def test_read_gives_rgba_and_a_fresh_array(renderer):
    renderer.render()
    a = renderer.read()
    b = renderer.read(components=4)
    assert b.shape == (100, 200, 4) and np.all(b[..., 3] == 255)
    a[:] = 0
    assert renderer.read().any()


def test_multisampled_render_matches_geometry(gl_ctx):
    r = Renderer(gl_ctx, (200, 100), samples=4, camera=Camera((0, 0), (4, 2)))
    pts, tris, uv = square_mesh(-1.0, -0.5, 0.5, 0.5)
    h = r.add_mesh(tris, uv, color="#ff0000")
    r.render([(h, pts)])
    img = r.read()
    # the interior is solid; smoothing only touches the border pixels
    assert np.all(img[26:74, 51:124] == RED)
    assert abs(int(body_mask(img).sum()) - 75 * 50) < 2 * (75 + 50)
    r.release()


def test_resize_changes_the_picture(renderer):
    renderer.resize((64, 32))
    renderer.render()
    assert renderer.read().shape == (32, 64, 3)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(texture=np.zeros((4, 4, 4), np.float32)), "uint8"),
        (dict(color="#12345"), "colour must be"),
        (dict(color=(2, 0, 0)), "colour must be"),
    ],
)
def test_add_mesh_rejects_bad_input(renderer, kwargs, message):
    pts, tris, uv = square_mesh(0, 0, 1, 1)
    with pytest.raises(ValueError, match=message):
        renderer.add_mesh(tris, uv, **kwargs)


def test_bad_positions_and_sizes_are_rejected(renderer):
    pts, tris, uv = square_mesh(0, 0, 1, 1)
    h = renderer.add_mesh(tris, uv)
    with pytest.raises(ValueError, match="positions must have shape"):
        renderer.draw_mesh(h, pts[:-1])
    with pytest.raises(ValueError, match="needs uv"):
        renderer.add_mesh(tris, texture=np.zeros((2, 2, 3), np.uint8))
    with pytest.raises(ValueError, match="size must be two integers"):
        renderer.resize((0, 10))


def test_drawing_into_a_given_framebuffer_like_a_window(gl_ctx):
    # a window passes target=ctx.screen; any framebuffer behaves the same way
    fbo = gl_ctx.simple_framebuffer((120, 60))
    r = Renderer(gl_ctx, (120, 60), target=fbo, camera=Camera((0, 0), (4, 2)))
    pts, tris, uv = square_mesh(-1.0, -0.5, 0.5, 0.5)
    h = r.add_mesh(tris, uv, color="#ff0000")
    r.render([(h, pts)])
    img = r.read()
    assert img.shape == (60, 120, 3)
    # 30 px per metre: the fill covers columns [30, 75) and rows [15, 45)
    assert np.all(img[17:43, 32:73] == RED)
    assert not body_mask(img)[:, 80:].any()
    r.release()
    fbo.release()


def test_draw_image_puts_a_panel_at_its_pixels(renderer):
    panel = np.zeros((10, 20, 4), np.uint8)
    panel[..., 1] = 255
    panel[..., 3] = 255
    panel[0, :, :] = (0, 0, 255, 255)      # its top row blue: the panel must not be upside down
    panel[:, 15:, 3] = 0                   # its right quarter transparent
    renderer.render()
    empty = renderer.read()
    renderer.draw_image(panel, (30, 40))
    img = renderer.read()
    assert np.all(img[41:50, 30:45] == [0, 255, 0])
    assert np.all(img[40, 30:45] == [0, 0, 255])
    np.testing.assert_array_equal(img[40:50, 45:50], empty[40:50, 45:50])
    changed = np.any(img != empty, axis=-1)
    assert changed.sum() == 10 * 15


def test_shrunk_textures_are_filtered_not_aliased(renderer):
    # stripes 3 texels wide: drawn 8x smaller each pixel spans 1.3 periods, so a single
    # bilinear sample per pixel lands on varying phases (stripes of black and white that
    # should not be there); mipmaps average them to grey
    tex = np.zeros((256, 256, 4), np.uint8)
    tex[..., 3] = 255
    xx = np.arange(256)
    tex[:, (xx // 3) % 2 == 0, :3] = 255
    pts, tris, uv = square_mesh(-0.32, -0.32, 0.32, 0.32)      # 32 x 32 pixels
    h = renderer.add_mesh(tris, uv, texture=tex)
    renderer.render([(h, pts)])
    inner = renderer.read()[52 - 12 : 52 + 12, 100 - 12 : 100 + 12].astype(float)
    assert h.mipmapped is True
    # with mipmaps the 8-texel averages stay within 96..160 (std 26); without, 0 or 255 (std 104)
    assert abs(inner.mean() - 127.5) < 12 and inner.std() < 50
    # drawn larger than the picture, plain bilinear filtering is used (cheaper)
    big = renderer.add_mesh(tris, uv, texture=tex[:8, :8])
    renderer.render([(big, pts)])
    assert big.mipmapped is False

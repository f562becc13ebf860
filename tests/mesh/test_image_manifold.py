"""from_image always returns a manifold mesh or one clear ValueError (issue 17): thin rings
and crossing lines, 16-bit greyscale pictures, tiny pictures."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PIL import Image

from deforma.mesh import from_image
from deforma.mesh.mesh import split_pinches


def assert_manifold(m):
    """Every boundary vertex has exactly one boundary edge in and one out, every vertex's
    triangles form one fan, and the loops account for every boundary edge."""
    be = m.boundary_edges
    outs, ins = Counter(be[:, 0].tolist()), Counter(be[:, 1].tolist())
    assert set(outs) == set(ins)
    assert all(outs[v] == 1 and ins[v] == 1 for v in outs), "a pinch vertex"
    assert sum(len(loop) for loop in m.boundary) == len(be)
    t, src = split_pinches(m.triangles, len(m.vertices))
    assert np.array_equal(t, m.triangles) and len(src) == len(m.vertices)  # nothing left to split
    assert np.array_equal(np.unique(m.triangles), np.arange(len(m.vertices)))


def ring(n, r, width):
    yy, xx = np.mgrid[:n, :n]
    d = np.hypot(xx - n / 2 + 0.5, yy - n / 2 + 0.5)
    img = np.zeros((n, n), np.uint8)
    img[np.abs(d - r) < width] = 255
    return img


def lines():
    img = np.zeros((64, 64), np.uint8)
    img[32, 5:60] = img[10, 5:60] = 255
    img[5:60, 20] = img[5:60, 40] = 255
    return img


def diagonal_cross():
    img = np.zeros((64, 64), np.uint8)
    for i in range(8, 56):
        img[i, i : i + 2] = 255
        img[i, 62 - i : 64 - i] = 255
    return img


CASES = {
    "ring 1px r20": ring(64, 20, 0.5),
    "ring r12 w0.7": ring(40, 12, 0.7),  # was 1-3 pinch vertices
    "ring r25 w0.6": ring(64, 25, 0.6),
    "crossing lines": lines(),  # was 4 pinch vertices
    "diagonal cross": diagonal_cross(),
}


@pytest.mark.parametrize("name", CASES)
@pytest.mark.parametrize("kw", [{}, {"resolution": 1, "edge_step": 1}, {"resolution": 2, "edge_step": 4},
                                {"detect_edges": False, "resolution": 1}])
def test_thin_shapes_mesh_manifold_or_refuse(name, kw):
    try:
        m = from_image(CASES[name], **kw)
    except ValueError as err:
        assert "\n" not in str(err)
        return
    assert_manifold(m)


def test_pinches_are_split_not_dropped():
    # two squares touching at one corner pixel: both kept, the corner vertex split in two
    img = np.zeros((40, 40), np.uint8)
    img[5:20, 5:20] = 255
    img[20:35, 20:35] = 255
    m = from_image(img, resolution=2, edge_step=1, scale=1.0)
    assert_manifold(m)
    assert m.area == pytest.approx(2 * 15 * 15, rel=0.03)


def test_split_pinches_bow_tie_and_untouched_mesh():
    t, src = split_pinches(np.array([[0, 1, 2], [0, 3, 4]]), 5)
    assert t.tolist() == [[0, 1, 2], [5, 3, 4]] and src.tolist() == [0, 1, 2, 3, 4, 0]
    quad = np.array([[0, 1, 2], [0, 2, 3]])
    t, src = split_pinches(quad, 4)
    assert np.array_equal(t, quad) and src.tolist() == [0, 1, 2, 3]


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**32 - 1), st.integers(12, 40), st.floats(0.05, 0.5), st.sampled_from([1, 2, 4]))
def test_property_random_thin_pictures_are_manifold(seed, n, density, resolution):
    """Random sparse pixels and strokes: whatever comes out is manifold, or one ValueError."""
    rng = np.random.default_rng(seed)
    img = (rng.random((n, n)) < density).astype(np.uint8) * 255
    for _ in range(3):  # a few one-pixel strokes
        r, c = rng.integers(0, n, 2)
        img[r, :] = 255 if rng.random() < 0.5 else img[r, :]
        img[:, c] = 255 if rng.random() < 0.5 else img[:, c]
    try:
        m = from_image(img, resolution=resolution, edge_step=1)
    except ValueError as err:
        assert "\n" not in str(err)
        return
    assert_manifold(m)


# -- 16-bit greyscale and tiny pictures ----------------------------------------------------


def disc16(tmp_path=None):
    yy, xx = np.mgrid[:64, :64]
    a = np.where(np.hypot(xx - 32, yy - 32) < 20, 60000, 20000).astype(np.uint16)
    return Image.fromarray(a)


def test_16_bit_grey_disc_on_grey_background(tmp_path):
    im = disc16()
    assert im.mode == "I;16"
    path = tmp_path / "disc16.png"
    im.save(path)
    for source in (im, path):
        m = from_image(source, background="auto", scale=1.0)  # the border: 20000 -> #4e4e4e
        assert m.area == pytest.approx(np.pi * 20**2, rel=0.03)
        assert_manifold(m)
        # on black the whole square differs: refused with the border's colour, not meshed
        with pytest.raises(ValueError, match=r"whole picture is foreground.*#4e4e4e"):
            from_image(source)


def test_16_bit_full_range_maps_to_8_bit():
    a = np.zeros((30, 30), np.uint16)
    a[5:25, 5:25] = 65535
    m = from_image(Image.fromarray(a), scale=1.0)
    assert m.area == pytest.approx(400, rel=0.03)
    assert int(m.texture[10, 10, 0]) == 255


def test_32_bit_float_outside_unit_range_is_refused():
    with pytest.raises(ValueError, match=r"mode F.*\[0, 1\]"):
        from_image(Image.fromarray(np.full((20, 20), 7.0, np.float32)))


@pytest.mark.parametrize("size", [1, 2])
def test_tiny_white_picture_is_told_it_is_a_speck(size):
    with pytest.raises(ValueError, match="only specks") as info:
        from_image(np.full((size, size, 3), 255, np.uint8))
    assert "transparent or black" not in str(info.value) and "no pixel differs" not in str(info.value)


def test_tiny_white_picture_that_is_all_foreground():
    with pytest.raises(ValueError, match="whole picture is foreground"):
        from_image(np.full((4, 4, 3), 255, np.uint8))

"""Meshes from pictures: they follow the shape (holes, ears, concavities) and reject bad input."""

import numpy as np
import pytest
from PIL import Image
from scipy import ndimage
from skimage.measure import find_contours

import deforma
from deforma.mesh import from_image
from deforma.mesh.image import BUILTIN_TEXTURES, MAX_PIXELS, foreground_mask

SCALE = 0.01


def image_px(mesh):
    """Vertices back in picture pixels (x right, y down) through the mesh's uv."""
    h, w = mesh.texture.shape[:2]
    return np.c_[mesh.uv[:, 0] * w, (1 - mesh.uv[:, 1]) * h]


def centroids_on(mask, mesh):
    c = image_px(mesh)[mesh.triangles].mean(axis=1)
    return mask[np.floor(c[:, 1]).astype(int), np.floor(c[:, 0]).astype(int)]


def covered(mesh, p):
    """Whether picture point p (x, y in pixels) lies in some triangle."""
    q = image_px(mesh)[mesh.triangles]
    a, b, c = q[:, 0], q[:, 1], q[:, 2]

    def side(u, v):
        return (v[:, 0] - u[:, 0]) * (p[1] - u[:, 1]) - (v[:, 1] - u[:, 1]) * (p[0] - u[:, 0])

    s = np.stack([side(a, b), side(b, c), side(c, a)], axis=1)
    return bool(((s >= 0).all(axis=1) | (s <= 0).all(axis=1)).any())


@pytest.fixture(scope="module")
def masks():
    return {n: foreground_mask(n) for n in BUILTIN_TEXTURES}


PARAMS = [(4, 2), (8, 4), (3, 6)]


@pytest.mark.parametrize("name", BUILTIN_TEXTURES)
@pytest.mark.parametrize("resolution, edge_step", PARAMS)
def test_builtin_follows_its_shape(name, resolution, edge_step, masks):
    m = from_image(name, resolution=resolution, detect_edges=True, edge_step=edge_step, scale=SCALE)
    fg = masks[name]
    assert centroids_on(fg, m).all()
    assert m.area == pytest.approx(fg.sum() * SCALE**2, rel=0.02)
    assert (m.triangle_areas > 0).all() and m.min_angle > 3.0
    assert np.array_equal(np.unique(m.triangles), np.arange(len(m.vertices)))  # no stray points


@pytest.mark.parametrize("name", BUILTIN_TEXTURES)
def test_outline_is_made_of_mesh_edges(name):
    # the mesh boundary runs along the sub-pixel contour (alpha = 0.5) all the way round
    m = from_image(name, resolution=6, edge_step=3, scale=SCALE)
    alpha = np.pad(m.texture[..., 3].astype(float), 1)
    rings = [c[:, ::-1] - 1 + 0.5 for c in find_contours(alpha, 127.5) if len(c) > 20]
    # contour polylines, densified so that nearest-point distances are distances to the line
    f = np.linspace(0, 1, 8, endpoint=False)[None, :, None]
    contour = np.concatenate([(r[:-1, None] + f * (r[1:, None] - r[:-1, None])).reshape(-1, 2) for r in rings])
    px = image_px(m)
    loops = np.concatenate(m.boundary)

    def nearest(a, b):
        d = np.full(len(a), np.inf)
        for chunk in np.array_split(np.arange(len(b)), max(1, len(b) // 500)):
            d = np.minimum(d, np.hypot(*(a[:, None, :] - b[None, chunk, :]).transpose(2, 0, 1)).min(axis=1))
        return d

    assert nearest(px[loops], contour).max() < 0.2  # every boundary vertex is on the outline
    assert nearest(contour, px[loops]).max() < 3.0 + 1.0  # and the outline is traced everywhere
    # boundary edges are short: they follow the outline instead of cutting across it
    # (edge_step apart, up to 1.5 edge_step where a point next to a sharp feature was merged)
    e = px[m.boundary_edges]
    lengths = np.hypot(*(e[:, 1] - e[:, 0]).T)
    assert lengths.max() <= 1.5 * 3.0 + 0.5
    assert np.median(lengths) == pytest.approx(3.0, abs=0.1)


def _point_segment_distances(p, a, b):
    """(P, S) distances from points p to segments a-b."""
    ab = b - a
    t = np.clip(((p[:, None, :] - a[None]) * ab[None]).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0, 1)
    q = a[None] + t[..., None] * ab[None]
    return np.hypot(*(p[:, None, :] - q).transpose(2, 0, 1))


@pytest.mark.parametrize("name", BUILTIN_TEXTURES)
@pytest.mark.parametrize("resolution, edge_step", [(22, 16), (12, 8), (30, 30)])
def test_coarse_outline_has_no_needles_and_stays_within_a_pixel(name, resolution, edge_step):
    # Coarse settings (the pile scene's are 22/16) used to put two outline points a pixel
    # apart at ear tips and toes; with an interior point a spacing away that made needles
    # (2.2-2.5 degrees, 0.7-0.9 px high). Close pairs are merged where the outline allows.
    m = from_image(name, resolution=resolution, edge_step=edge_step, scale=1.0)
    px = image_px(m)
    q = px[m.triangles]
    twice = np.abs((q[:, 1, 0] - q[:, 0, 0]) * (q[:, 2, 1] - q[:, 0, 1]) - (q[:, 1, 1] - q[:, 0, 1]) * (q[:, 2, 0] - q[:, 0, 0]))
    longest = np.max([np.hypot(*(q[:, k] - q[:, (k + 1) % 3]).T) for k in range(3)], axis=0)
    assert m.min_angle >= 10.0
    assert (twice / longest).min() >= 1.0  # the thinnest triangle's height, px
    # ... and the merged outline still follows the picture: every point of the sub-pixel
    # contour is within a pixel of the mesh boundary
    alpha = np.pad(m.texture[..., 3].astype(float), 1)
    contour = np.concatenate([c[:, ::-1] - 1 + 0.5 for c in find_contours(alpha, 127.5) if len(c) > 20])
    e = px[m.boundary_edges]
    d = np.concatenate([_point_segment_distances(chunk, e[:, 0], e[:, 1]).min(axis=1)
                        for chunk in np.array_split(contour, max(1, len(contour) // 500))])
    assert d.max() <= 1.0 + 1e-6


def test_donut_keeps_its_hole(masks):
    m = from_image("donut", resolution=4, edge_step=2, scale=SCALE)
    assert len(m.boundary) == 2
    assert m.euler_characteristic == 0
    h, w = masks["donut"].shape
    assert not covered(m, (w / 2, h / 2))
    outer, hole = (m.vertices[b] for b in m.boundary)
    # the hole's loop lies inside the outer one and runs the other way
    assert np.hypot(*hole.T).max() < np.hypot(*outer.T).min()


@pytest.mark.parametrize("detect_edges", [True, False])
def test_bunny_ears_stay_apart(detect_edges, masks):
    m = from_image("bunny", resolution=4, detect_edges=detect_edges, edge_step=2, scale=SCALE)
    fg = masks["bunny"]
    row = int(0.10 * fg.shape[0])  # through both ears, above the head
    runs = np.flatnonzero(np.diff(fg[row].astype(int)))
    assert len(runs) == 4, "the texture has two separate ears at this height"
    gap = np.arange(runs[1] + 2, runs[2])  # background pixels between the ears
    assert len(gap) > 10
    for x in gap:
        assert not covered(m, (x + 0.5, row + 0.5))
    # and both ears are meshed there
    for x in (0.5 * (runs[0] + runs[1]), 0.5 * (runs[2] + runs[3])):
        assert covered(m, (x + 0.5, row + 0.5)) or not detect_edges


@pytest.mark.parametrize("name", BUILTIN_TEXTURES)
def test_grid_only_mesh_covers_no_background(name, masks):
    m = from_image(name, resolution=6, detect_edges=False, scale=SCALE)
    fg = masks[name]
    assert centroids_on(fg, m).all()
    # no background pixel centre inside any triangle, by brute force over the background
    # pixels next to the foreground: a triangle whose corners are all foreground cannot
    # cover background without covering some of those
    px = image_px(m)
    rows, cols = np.nonzero(~fg & (ndimage.distance_transform_edt(~fg) <= 2.5))
    centres = np.c_[cols + 0.5, rows + 0.5]
    lo, hi = px.min(axis=0), px.max(axis=0)
    centres = centres[((centres >= lo) & (centres <= hi)).all(axis=1)]
    q = px[m.triangles]
    for start in range(0, len(q), 400):
        t = q[start : start + 400]
        a, b, c = (t[:, None, k, :] for k in range(3))
        p = centres[None, :, :]

        def side(u, v):
            return (v[..., 0] - u[..., 0]) * (p[..., 1] - u[..., 1]) - (v[..., 1] - u[..., 1]) * (p[..., 0] - u[..., 0])

        inside = (side(a, b) >= 0) & (side(b, c) >= 0) & (side(c, a) >= 0)
        assert not inside.any()
    assert 0.85 * fg.sum() * SCALE**2 < m.area < fg.sum() * SCALE**2
    assert m.min_angle >= 10.0


def test_full_rectangle_grid_known_answer():
    # 40 x 60 foreground in a 5 px black frame (a picture that is all foreground is refused),
    # every 5th pixel from pixel 2: rows and columns 7, 12, ...: 8 rows x 12 columns of points
    img = np.zeros((50, 70), bool)
    img[5:45, 5:65] = True
    m = from_image(img, resolution=5, detect_edges=False, scale=0.1)
    assert len(m.vertices) == 96
    assert m.area == pytest.approx(35 * 55 * 0.1**2, rel=1e-12)
    assert np.allclose(m.vertices.min(axis=0), [-2.75, -1.75]) and np.allclose(m.vertices.max(axis=0), [2.75, 1.75])
    xs = np.unique(m.vertices[:, 0].round(9))
    assert np.allclose(np.diff(xs), 0.5)  # resolution * scale


def test_disc_and_notched_shape_known_areas():
    yy, xx = np.mgrid[0:200, 0:200] + 0.5
    disc = (xx - 100) ** 2 + (yy - 100) ** 2 < 80**2
    m = from_image(disc, resolution=5, edge_step=2, scale=1.0)
    assert m.area == pytest.approx(np.pi * 80**2, rel=0.005)
    assert len(m.boundary) == 1 and m.euler_characteristic == 1
    # a C shape: the notch must stay open (concave parts stay concave)
    c_shape = disc & ~((yy > 90) & (yy < 110) & (xx > 60))
    m = from_image(c_shape, resolution=5, edge_step=4, scale=1.0)
    assert m.area == pytest.approx(c_shape.sum(), rel=0.01)
    assert not covered(m, (150.5, 100.5)) and not covered(m, (100.5, 100.5))
    assert centroids_on(c_shape, m).all()


def test_coordinates_centred_y_up_scaled():
    a = from_image("bunny", resolution=8, edge_step=4, scale=0.01)
    b = from_image("bunny", resolution=8, edge_step=4, scale=0.02)
    assert np.allclose(b.vertices, 2 * a.vertices)
    lo, hi = a.vertices.min(axis=0), a.vertices.max(axis=0)
    assert np.allclose(lo + hi, 0, atol=1e-12)  # bounding box centred on the origin
    assert np.corrcoef(a.vertices[:, 1], a.uv[:, 1])[0, 1] > 0.9999  # y up, v up
    assert np.corrcoef(a.vertices[:, 0], a.uv[:, 0])[0, 1] > 0.9999
    # size: the foreground's extent in pixels times metres per pixel
    fg = foreground_mask("bunny")
    rows, cols = np.nonzero(fg)
    assert hi[0] - lo[0] == pytest.approx((cols.max() + 1 - cols.min()) * 0.01, abs=0.02)
    assert hi[1] - lo[1] == pytest.approx((rows.max() + 1 - rows.min()) * 0.01, abs=0.02)
    assert a.texture.shape == (384, 384, 4) and a.texture.dtype == np.uint8
    assert 0 <= a.uv.min() and a.uv.max() <= 1


def test_builtin_textures_are_package_data_and_colourful():
    for name in BUILTIN_TEXTURES:
        m = from_image(name, resolution=12, edge_step=6)
        rgba = m.texture
        assert 256 <= rgba.shape[0] <= 512 and 256 <= rgba.shape[1] <= 512
        assert rgba[0, 0, 3] == 0  # transparent background
        opaque = rgba[rgba[..., 3] == 255][:, :3]
        colours = {tuple(c // 32) for c in opaque}  # a picture, not a silhouette
        assert len(colours) > 25


def test_sources_path_pil_and_arrays(tmp_path):
    img = Image.new("RGB", (64, 48), (0, 0, 0))
    img.paste((200, 40, 40), (10, 8, 50, 40))  # a red 40 x 32 rectangle on black
    area = 40 * 32
    png = tmp_path / "r.png"
    img.save(png)
    jpg = tmp_path / "r.jpg"
    img.save(jpg, quality=90, subsampling=0)  # black with JPEG noise stays background
    rgb = np.asarray(img)
    rgba = np.dstack([rgb, np.where(rgb.max(axis=2) > 0, 255, 0).astype(np.uint8)])
    sources = [png, str(png), jpg, img, img.convert("RGBA"), rgb, rgba, rgb / 255.0, rgb.max(axis=2) > 0]
    for src in sources:
        m = from_image(src, resolution=4, edge_step=2, scale=1.0)
        assert m.area == pytest.approx(area, rel=0.02), type(src)
        assert len(m.boundary) == 1


def test_transparent_beats_colour():
    # an opaque black disc on a transparent white background: the disc is the shape
    yy, xx = np.mgrid[0:100, 0:100] + 0.5
    disc = (xx - 50) ** 2 + (yy - 50) ** 2 < 30**2
    rgba = np.zeros((100, 100, 4), np.uint8)
    rgba[..., :3] = 255
    rgba[disc] = (0, 0, 0, 255)
    m = from_image(rgba, resolution=4, edge_step=2, scale=1.0)
    assert m.area == pytest.approx(np.pi * 30**2, rel=0.01)


def one_line_value_error(match, fn, *args, **kwargs):
    with pytest.raises(ValueError, match=match) as info:
        fn(*args, **kwargs)
    assert "\n" not in str(info.value)


def test_missing_and_unreadable_files(tmp_path):
    one_line_value_error("not found.*bunny", from_image, tmp_path / "nope.png")
    one_line_value_error("not found", from_image, "rabbit")
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"this is not a picture")
    one_line_value_error("cannot read image.*PNG or JPEG", from_image, bad)
    truncated = tmp_path / "cut.png"
    Image.new("RGB", (300, 300), (9, 200, 9)).save(truncated)
    truncated.write_bytes(truncated.read_bytes()[:200])
    one_line_value_error("cannot read image", from_image, truncated)
    one_line_value_error("source must be", from_image, 42)
    one_line_value_error("source must be", from_image, np.zeros((4, 4, 2)))


def lying_png(path, width, height):
    """A PNG whose header says ``width x height`` and whose data holds one white row: the
    compressed stream ends cleanly after it, so Pillow decodes it without a word."""
    import struct
    import zlib

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
                     + chunk(b"IDAT", zlib.compress(b"\x00" + b"\xff" * 3 * width)) + chunk(b"IEND", b""))
    return path


def test_a_png_whose_header_lies_about_its_size_is_refused_at_once(tmp_path, capsys):
    # it was meshed as a 6000 x 6000 picture (the missing rows black): about 2 GB and 6-19 s
    import subprocess
    import sys
    import time

    from deforma.cli import main

    liar = lying_png(tmp_path / "liar.png", 6000, 6000)
    truncated = r"cannot read image .*liar.png' \(image file is truncated: its header says 6000x6000 pixels"
    t0 = time.perf_counter()
    one_line_value_error(truncated, from_image, liar)
    one_line_value_error(truncated, deforma.mesh.image.read_rgba, liar)
    assert time.perf_counter() - t0 < 5
    # the command line: one line, exit 1, no picture written
    assert main(["mesh", str(liar), "-o", str(tmp_path / "m.png")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("deforma: error: cannot read image") and err.count("\n") == 1 and "truncated" in err
    # a rigid image body of a scene file
    (tmp_path / "s.toml").write_text('[[body]]\nshape = "image"\nsource = "liar.png"\nmaterial = "rigid"\n')
    with pytest.raises(deforma.scene.SceneError, match=r"body\[0\]\.source: cannot read image .*truncated") as e:
        deforma.load_scene(tmp_path / "s.toml")
    assert "\n" not in str(e.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["liar.png", "s.toml"]
    # the peak memory, in a process of its own: far below one 6000 x 6000 RGB picture (108 MB)
    code = ("import resource, sys, deforma\n"
            "before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss\n"
            "try:\n    deforma.mesh.from_image(sys.argv[1])\nexcept ValueError:\n    pass\n"
            "print((resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024)")
    r = subprocess.run([sys.executable, "-c", code, str(liar)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert float(r.stdout) < 50, f"peak memory grew by {r.stdout.strip()} MB"


def test_a_png_cut_at_a_row_or_interlaced_is_judged_by_its_rows(tmp_path):
    """The rows a PNG's header promises are counted the way they are stored: a file one row
    short is refused, whole ones (any colour type, bit depth, palette or interlaced) are read."""
    import struct
    import zlib

    adam7 = ((0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    def png(w, h, depth, colour, interlaced, rows, piece):
        """The rows of each pass (up to ``rows`` of them), in IDAT chunks of ``piece`` bytes."""
        bits = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[colour] * depth
        raw = []
        for x0, y0, dx, dy in adam7 if interlaced else ((0, 0, 1, 1),):
            pw, ph = -(-(w - x0) // dx), -(-(h - y0) // dy)
            raw += [b"\x00" + b"\x55" * ((pw * bits + 7) // 8)] * (ph if pw > 0 else 0)
        head = struct.pack(">IIBBBBB", w, h, depth, colour, 0, 0, int(interlaced))
        plte = chunk(b"PLTE", b"\x00\x00\x00\xff\xff\xff" * 128) if colour == 3 else b""
        data = zlib.compress(b"".join(raw[:rows]))
        p = tmp_path / "p.png"
        p.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + plte
                      + b"".join(chunk(b"IDAT", data[i:i + piece]) for i in range(0, len(data), piece))
                      + chunk(b"IEND", b""))
        return p, len(raw)

    # one IDAT chunk (what Pillow read short without a word), and 5-byte ones (as some writers split it)
    for piece in (1 << 20, 5):
        for w, h, depth, colour, interlaced in [(37, 29, 8, 2, False), (37, 29, 8, 2, True), (5, 3, 1, 0, True),
                                                (33, 17, 16, 6, True), (9, 4, 2, 3, False), (1, 1, 8, 4, True)]:
            p, rows = png(w, h, depth, colour, interlaced, None, piece)
            assert deforma.mesh.image.read_rgba(p).shape == (h, w, 4)
            if rows > 1:
                p, _ = png(w, h, depth, colour, interlaced, rows - 1, piece)
                one_line_value_error("image file is truncated", deforma.mesh.image.read_rgba, p)


def test_no_foreground():
    one_line_value_error("no foreground", from_image, np.zeros((50, 50, 3), np.uint8))
    one_line_value_error("no foreground", from_image, np.zeros((50, 50, 4), np.uint8))
    one_line_value_error("no foreground", from_image, Image.new("RGBA", (50, 50), (255, 255, 255, 0)))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"resolution": 0}, r"resolution must be an integer >= 1"),
        ({"resolution": -3}, r"resolution must be an integer >= 1"),
        ({"resolution": 2.5}, r"resolution must be an integer >= 1"),
        ({"edge_step": 0}, r"edge_step must be an integer >= 1"),
        ({"scale": 0}, r"scale must be > 0 m per pixel"),
        ({"scale": float("inf")}, r"scale must be finite"),
        ({"detect_edges": "yes"}, "detect_edges must be True or False"),
        ({"threshold": 1.0}, r"threshold must be a number in \[0, 1\)"),
        ({"max_points": 0}, r"max_points must be an integer in \[3, 100000\]"),
    ],
)
def test_bad_parameters(kwargs, match):
    one_line_value_error(match, from_image, "donut", **kwargs)


def test_too_many_points_and_too_large_images():
    one_line_value_error(r"about \d+ points .* at most max_points=1000", from_image, "bunny", resolution=1, max_points=1000)
    one_line_value_error(f"at most {MAX_PIXELS} allowed", from_image, Image.new("1", (8000, 6000)))
    one_line_value_error(f"at most {MAX_PIXELS} allowed", from_image, np.zeros((MAX_PIXELS + 1, 1), bool))


def test_too_coarse_for_grid_only():
    yy, xx = np.mgrid[0:40, 0:40]
    thin = (abs(xx - yy) < 2)  # a diagonal line 3 pixels wide
    one_line_value_error("resolution=", from_image, thin, resolution=10, detect_edges=False)


def test_public_name():
    assert deforma.mesh.from_image is from_image


def test_narrow_slit_stays_open():
    # a 2 px slit, 40 px deep, is narrower than edge_step: the outline must still go into it
    img = np.zeros((120, 120), bool)
    img[10:110, 10:110] = True
    img[10:50, 59:61] = False
    m = from_image(img, resolution=4, edge_step=8, scale=1.0)
    for y in range(12, 48, 3):
        assert not covered(m, (60.0, y + 0.5)), y
    assert m.area == pytest.approx(img.sum(), rel=0.01)


def test_outline_recovery_splits_an_encroached_segment():
    from deforma.mesh.image import _mesh_with_outline, _Ring

    def square(lo, hi):
        side = np.linspace(0, hi - lo, 81)[:-1]
        return lo + np.concatenate([np.c_[side, 0 * side], np.c_[(hi - lo) + 0 * side, side],
                                    np.c_[(hi - lo) - side, (hi - lo) + 0 * side], np.c_[0 * side, (hi - lo) - side]])

    # a 60 px square with a 20 px square hole, outlines sampled every 10 px, and an interior
    # point 1 px below the middle of the hole's first segment: Delaunay joins that point to
    # the segment's ends, so the segment is not an edge until it is split
    outer, hole = _Ring(square(0, 60), 10), _Ring(square(20, 40), 10)
    assert (len(outer.points()), len(hole.points())) == (24, 8)
    interior = np.array([[25.0, 19.0], [10.0, 10.0], [50.0, 50.0]])
    points, tris = _mesh_with_outline([outer, hole], interior)
    assert len(hole.points()) == 9  # the hole's first segment was split once
    assert np.allclose(hole.points()[1], [25.0, 20.0])
    assert not np.any(np.all(points == [25.0, 19.0], axis=1))  # the encroaching point went
    m = deforma.mesh.Mesh(points, tris)
    assert m.area == pytest.approx(3600.0 - 400.0)
    assert len(m.boundary) == 2 and m.euler_characteristic == 0
    # every outline segment is a boundary edge of the mesh
    b = {tuple(sorted(e)) for e in m.boundary_edges.tolist()}
    for start, n in ((0, 24), (24, 9)):
        assert all(tuple(sorted((start + i, start + (i + 1) % n))) in b for i in range(n))

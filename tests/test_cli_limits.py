"""Hostile sizes and interruptions give one line and leave nothing behind (issue 17)."""

import io
import struct
import zlib

import numpy as np
import pytest
from PIL import Image

from deforma.cli import EXIT_ERROR, MESH_PICTURE_MAX_SIDE, main


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(err):
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("deforma: compiling")]
    assert len(lines) == 1, err
    return lines[0]


def bomb_png(path, w, h):
    """A valid 1x1 PNG whose header claims w x h pixels: Pillow reads the size without decoding."""
    b = io.BytesIO()
    Image.new("L", (1, 1), 255).save(b, "PNG")
    d = bytearray(b.getvalue())
    d[16:24] = struct.pack(">II", w, h)
    d[29:33] = struct.pack(">I", zlib.crc32(bytes(d[12:29])))
    path.write_bytes(bytes(d))
    return path


def peak_rss_mb():
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


# -- memory -------------------------------------------------------------------------------------------
def test_mesh_of_a_tiny_shape_on_a_large_picture_draws_only_the_mesh_frame(tmp_path, capsys):
    # a 3x3 block on 100x100 black asked for a ~47,000 px backdrop and was killed at 23.7 GB
    a = np.zeros((100, 100), np.uint8)
    a[48:51, 48:51] = 255
    Image.fromarray(a).save(tmp_path / "tiny.png")
    out = tmp_path / "m.png"
    code, stdout, err = run(capsys, "mesh", tmp_path / "tiny.png", "-o", out)
    assert code == 0, err
    w, h = Image.open(out).size
    assert w == 800 and h < 1000
    assert peak_rss_mb() < 2048
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.png", "tiny.png"]


def test_mesh_of_a_very_tall_shape_stays_within_the_picture_limit(tmp_path, capsys):
    a = np.zeros((2040, 40), np.uint8)
    a[20:2020, 10:30] = 255
    Image.fromarray(a).save(tmp_path / "tall.png")
    out = tmp_path / "m.png"
    code, stdout, err = run(capsys, "mesh", tmp_path / "tall.png", "--resolution", "20", "--edge-step", "20",
                            "-o", out)
    assert code == 0, err
    w, h = Image.open(out).size
    assert h <= MESH_PICTURE_MAX_SIDE + 40 and w < 800  # the caption bar adds 34 px


def test_mesh_of_a_shape_too_tall_for_any_picture_is_refused(tmp_path, capsys):
    a = np.zeros((4040, 24), np.uint8)
    a[20:4020, 10:14] = 255
    Image.fromarray(a).save(tmp_path / "line.png")
    code, _, err = run(capsys, "mesh", tmp_path / "line.png", "--resolution", "50", "--edge-step", "50",
                       "-o", tmp_path / "m.png")
    assert code == EXIT_ERROR
    line = one_line_error(err)
    assert str(MESH_PICTURE_MAX_SIDE) in line and "taller than wide" in line
    assert not (tmp_path / "m.png").exists()


@pytest.mark.parametrize("key", ["texture", "source"])
def test_a_decompression_bomb_as_texture_or_source_is_refused(tmp_path, capsys, key):
    bomb_png(tmp_path / "bomb.png", 30000, 30000)
    body = ('shape = "box"\ncorners = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]\ntexture = "bomb.png"\n'
            if key == "texture" else 'shape = "image"\nsource = "bomb.png"\n')
    (tmp_path / "s.toml").write_text(f"[run]\nseconds = 0.1\nfps = 10\n[[body]]\n{body}")
    code, _, err = run(capsys, "run", tmp_path / "s.toml", "-o", tmp_path / "out.gif", "--size", "64x64")
    assert code == EXIT_ERROR
    line = one_line_error(err)
    assert "bomb.png" in line and "40000000" in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bomb.png", "s.toml"]

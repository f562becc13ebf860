"""`deforma mesh PICTURE --background ... --threshold ...`: pictures on any background (issue 18)."""

import numpy as np
import pytest
from PIL import Image

import deforma
from deforma.cli import EXIT_ERROR, main


@pytest.fixture
def disc_png(tmp_path):
    """A dark disc of radius 50 px on white."""
    yy, xx = np.mgrid[0:140, 0:140] + 0.5
    img = np.full((140, 140, 3), 255, np.uint8)
    img[(xx - 70) ** 2 + (yy - 70) ** 2 < 50**2] = (30, 40, 70)
    path = tmp_path / "disc.png"
    Image.fromarray(img).save(path)
    return path


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("options", [["--background", "white"], ["--background", "auto"], ["--background=#ffffff"],
                                     ["--background", "WHITE", "--threshold", "0.3"]])
def test_a_picture_on_white_meshes_into_its_shape(tmp_path, capsys, disc_png, options):
    out = tmp_path / "m.png"
    code, stdout, err = run(capsys, "mesh", disc_png, "--resolution", "8", "--edge-step", "4", *options, "-o", out)
    assert code == 0, err
    background = options[0].split("=")[1] if "=" in options[0] else options[1]
    threshold = float(options[3]) if len(options) > 2 else None
    m = deforma.mesh.from_image(disc_png, resolution=8, edge_step=4, background=background, threshold=threshold)
    assert m.area == pytest.approx(np.pi * 0.5**2, rel=0.02)  # 50 px at the default 1 cm per pixel
    assert f": {len(m.vertices)} points, {len(m.triangles)} triangles" in stdout
    assert f"background {background}" in stdout
    assert Image.open(out).size[0] == 800


@pytest.mark.parametrize("options, message", [
    ([], "the whole picture is foreground: every pixel differs from the background 'black' (#000000)"),
    (["--background", "grey"], 'background must be "black", "white", "auto"'),
    (["--background=#fffff"], 'a colour "#rrggbb"'),
    (["--background", "white", "--threshold", "1"], "threshold must be a number in [0, 1)"),
    (["--background", "white", "--threshold", "-0.2"], "threshold must be a number in [0, 1)"),
    (["--background", "white", "--threshold", "0.95"], "the picture has no foreground"),
])
def test_bad_values_are_one_line_and_exit_1(tmp_path, capsys, disc_png, options, message):
    out = tmp_path / "m.png"
    code, stdout, err = run(capsys, "mesh", disc_png, *options, "-o", out)
    assert code == EXIT_ERROR
    assert err.startswith("deforma: error: ") and err.count("\n") == 1, err
    assert message in err
    assert stdout == "" and not out.exists()


def test_a_threshold_that_is_not_a_number_is_a_usage_error(tmp_path, capsys, disc_png):
    with pytest.raises(SystemExit) as e:
        main(["mesh", str(disc_png), "--threshold", "high", "-o", str(tmp_path / "m.png")])
    assert e.value.code == 2
    assert "--threshold: invalid float value: 'high'" in capsys.readouterr().err


def test_builtin_textures_keep_their_transparency(tmp_path, capsys):
    # the bunny has an alpha channel: any background is ignored, the mesh is the same
    figures = []
    for background in ("black", "white"):
        code, stdout, err = run(capsys, "mesh", "bunny", "--resolution", "16", "--edge-step", "8",
                                "--background", background, "-o", tmp_path / f"{background}.png")
        assert code == 0, err
        figures.append(stdout.split(": ", 1)[1].split(" (meshed")[0])
    assert figures[0] == figures[1]

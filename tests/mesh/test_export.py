"""Meshes out of deforma: body.to_mesh(), write_meshes / read_meshes (OBJ, JSON, SVG) and
``deforma run --export DIR --format obj|json|svg``."""

import json
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import deforma
from deforma.cli import EXIT_ERROR, EXIT_UNSTABLE, main
from deforma.mesh import read_meshes, write_meshes
from deforma.mesh.export import write_materials

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "physics"))
from physics_meshes import Chain  # noqa: E402


def deformed_world():
    """A textured bunny and a box, 30 steps after landing on a floor: bent, not at rest."""
    w = deforma.World(dt=1 / 60, integrator="implicit-euler")
    w.add_collider(deforma.Rect((0.0, -0.25), (8.0, 0.5), 0.0))
    bunny = w.add_body(deforma.mesh.from_image("bunny", resolution=8, scale=0.005), position=(-1.0, 1.0))
    box = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=4), position=(1.0, 0.6))
    for _ in range(30):
        w.step()
    return w, bunny, box


def test_to_mesh_is_the_current_shape_with_its_uv_and_picture():
    w, bunny, box = deformed_world()
    m = bunny.to_mesh()
    assert np.array_equal(m.vertices, bunny.positions) and np.array_equal(m.triangles, bunny.triangles)
    assert np.array_equal(m.uv, bunny.mesh.uv) and m.texture is bunny.mesh.texture
    assert not np.allclose(m.vertices - m.vertices.mean(0), bunny.mesh.vertices - bunny.mesh.vertices.mean(0))
    m.vertices[0] += 1.0  # a copy: the body does not move
    assert not np.array_equal(m.vertices, bunny.positions)


@pytest.mark.parametrize("suffix", [".obj", ".json"])
def test_obj_and_json_read_back_exactly(tmp_path, suffix):
    w, bunny, box = deformed_world()
    meshes = [bunny.to_mesh(), box.to_mesh()]
    write_meshes(meshes, tmp_path / f"f{suffix}")
    back = read_meshes(tmp_path / f"f{suffix}")
    assert len(back) == 2
    for a, b in zip(meshes, back):
        assert np.array_equal(a.vertices, b.vertices)  # bit for bit: shortest round-trip decimals
        assert np.array_equal(a.triangles, b.triangles) and np.array_equal(a.uv, b.uv)


def test_svg_is_one_filled_path_per_body(tmp_path):
    w, bunny, box = deformed_world()
    write_meshes([bunny.to_mesh(), box.to_mesh()], tmp_path / "f.svg", colors=["#ff0000", None])
    root = ET.parse(tmp_path / "f.svg").getroot()
    paths = root.findall("{http://www.w3.org/2000/svg}path")
    assert [p.get("id") for p in paths] == ["body0", "body1"]
    assert paths[0].get("fill") == "#ff0000" and paths[1].get("fill") == "#9aa5b1"
    assert paths[1].get("d").count("Z") == len(box.triangles)


def test_a_torn_body_gives_its_torn_mesh_and_a_chain_none():
    w = deforma.World(dt=1 / 600, gravity=(0, 0),
                      material=deforma.Material("corotated", youngs_modulus=1e4, poisson_ratio=0.3, density=10.0,
                                                tear_strain=0.2))
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 0.5), (0, 0.5)), detail=5))
    b.velocities[:, 0] = np.where(b.positions[:, 0] > 0.5, 3.0, -3.0)  # pulled apart
    for _ in range(60):
        w.step()
    assert b.n_vertices > 25 + 4  # it tore: vertices were split
    m = b.to_mesh()
    assert len(m.vertices) == b.n_vertices and np.array_equal(m.triangles, b.triangles)
    chain = w.add_body(Chain([[3, 0], [4, 0]], [[0, 1]]), material=deforma.Material("springs"))
    with pytest.raises(ValueError, match=r"body 1 has no triangles \(a chain of springs\)"):
        chain.to_mesh()


def test_bad_files_are_one_line_errors(tmp_path):
    (tmp_path / "x.json").write_text('{"bodies": [{"vertices": []}]}')
    (tmp_path / "x.txt").write_text("")
    for name, message in (("x.json", r"x.json: not a mesh file deforma wrote \(KeyError"),
                          ("x.txt", r"meshes are read from .obj or .json; got '.txt'")):
        with pytest.raises(ValueError, match=message) as e:
            read_meshes(tmp_path / name)
        assert "\n" not in str(e.value)
    m = deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
    with pytest.raises(ValueError, match=r"meshes are written as .obj, .json, .svg; got '.ply'"):
        write_meshes([m], tmp_path / "x.ply")


def test_json_nested_too_deep_is_a_one_line_error(tmp_path):
    (tmp_path / "deep.json").write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(ValueError, match=r"deep.json: not a mesh file deforma wrote \(RecursionError") as e:
        read_meshes(tmp_path / "deep.json")
    assert "\n" not in str(e.value)


@pytest.mark.parametrize("suffix", [".obj", ".json", ".svg"])
def test_names_not_one_per_mesh_are_refused_and_nothing_is_written(tmp_path, suffix):
    # two meshes and one name: every body was written but the second was dropped, silently
    m = deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
    for names in (["one"], ["one", "two", "three"]):
        with pytest.raises(ValueError, match=r"names has \d entries for 2 meshes; give one name per mesh") as e:
            write_meshes([m, m], tmp_path / f"x{suffix}", names=names)
        assert "\n" not in str(e.value)
    assert not list(tmp_path.iterdir())
    write_meshes([m, m], tmp_path / f"x{suffix}", names=["one", "two"])
    if suffix != ".svg":
        assert len(read_meshes(tmp_path / f"x{suffix}")) == 2


@pytest.mark.parametrize("bad", ["two words", "line\nbreak", 'say "hi"', "../up", ".hidden", "", 3, None])
def test_names_that_would_break_a_file_are_refused_and_nothing_is_written(tmp_path, bad):
    # a line break made extra OBJ lines, a quote broke the SVG, "../x" wrote a picture outside
    # the folder (write_materials names its pictures so)
    m = deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]], texture=np.zeros((2, 2, 4), np.uint8))
    for write in (lambda: write_meshes([m, m], tmp_path / "x.obj", names=["ok", bad]),
                  lambda: write_materials([m, m], tmp_path, names=["ok", bad])):
        with pytest.raises(ValueError, match=r"names\[1\] = .*: a name is letters, digits") as e:
            write()
        assert "\n" not in str(e.value)
    assert not list(tmp_path.iterdir())


def test_one_mesh_alone_is_written_as_a_list_of_one(tmp_path):
    m = deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
    write_meshes(m, tmp_path / "one.obj", names=["tri.1"])
    (back,) = read_meshes(tmp_path / "one.obj")
    assert back.vertices.tolist() == m.vertices.tolist()


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    err = "".join(line for line in err.splitlines(True) if not line.startswith("deforma: compiling the physics"))
    return code, out, err


def test_run_exports_a_file_per_frame_and_the_pictures_once(tmp_path, capsys):
    out = tmp_path / "meshes"
    code, stdout, err = run(capsys, "run", "textures", "--seconds", "0.2", "--fps", "20", "--export", str(out),
                            "--quiet")
    assert code == 0 and "-> " + str(out) in stdout
    files = sorted(p.name for p in out.iterdir())
    frames = [f for f in files if f.startswith("frame_")]
    assert frames == [f"frame_{k:05d}.obj" for k in range(4)]
    assert "materials.mtl" in files and any(f.endswith(".png") for f in files)
    last = read_meshes(out / frames[-1])
    world = deforma.scene.load("textures").build()
    assert len(last) == len(world.bodies)
    assert [len(m.vertices) for m in last] == [b.n_vertices for b in world.bodies]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary folder left


def test_run_exports_json_with_frame_and_time(tmp_path, capsys):
    out = tmp_path / "j"
    out.mkdir()  # an empty folder is taken
    code, _, _ = run(capsys, "run", "jelly", "--seconds", "0.1", "--fps", "30", "--export", str(out),
                     "--format", "json", "--quiet")
    assert code == 0
    data = json.loads((out / "frame_00002.json").read_text())
    assert data["frame"] == 2 and data["time"] == pytest.approx(2 / 30, abs=1e-9)  # frame k: t = k / fps
    assert [b["name"] for b in data["bodies"]] == ["body0", "body1", "body2"]


@pytest.mark.parametrize("setup, args, message", [
    ("file", ["--export", "{p}"], "--export writes a new folder, and this is a file"),
    ("full", ["--export", "{p}"], "--export writes a new folder, and this is a folder that is not empty"),
    ("none", ["--export", "{p}/a/b"], "does not exist"),
    ("none", ["--format", "svg"], "--format says how --export writes the meshes: give --export DIR too"),
    ("none", ["--export", "{p}.mp4", "-o", "{p}.mp4"], "-o and --export both name"),
    ("none", ["--export", "{p}.npz", "--states", "{p}.npz"], "--states and --export both name"),
    ("none", ["-o", "{p}.npz", "--states", "{p}/../target.npz"], "-o and --states both name"),
    # inside the export folder, which is put in place whole at the end: the states were written,
    # then the run failed on "Directory not empty" after all its work
    ("empty", ["--export", "{p}", "--states", "{p}/s.npz"], "--states {p}/s.npz is inside --export {p}, a folder"),
    ("empty", ["--export", "{p}", "-o", "{p}/x.gif"], "-o {p}/x.gif is inside --export {p}, a folder"),
    ("none", ["--export", "{p}", "-o", "{p}/frames/"], "-o {p}/frames/ is inside --export {p}, a folder"),
])
def test_bad_export_arguments_are_refused_before_any_work(tmp_path, capsys, setup, args, message):
    p = tmp_path / "target"
    if setup == "file":
        p.write_text("keep")
    elif setup == "full":
        p.mkdir()
        (p / "keep.txt").write_text("keep")
    elif setup == "empty":
        p.mkdir()
    before = sorted(tmp_path.rglob("*"))
    code, _, err = run(capsys, "run", "jelly", "--seconds", "0.1", *[a.format(p=p) for a in args], "--quiet")
    assert code == EXIT_ERROR and message.format(p=p) in err and err.count("\n") == 1 and "Traceback" not in err
    assert sorted(tmp_path.rglob("*")) == before


def test_no_meshes_are_an_empty_svg_as_they_are_an_empty_obj_and_json(tmp_path, capsys):
    # a scene of colliders only: its SVG frames ended the run in NumPy's "need at least one array
    # to concatenate"; OBJ and JSON wrote files without objects
    write_meshes([], tmp_path / "none.svg")
    root = ET.parse(tmp_path / "none.svg").getroot()
    assert root.get("width") == root.get("height") == "800" and len(root) == 0
    scene = tmp_path / "empty.toml"
    scene.write_text("[[collider]]\ncenter = [0.0, 0.0]\nsize = [5.0, 0.5]\n")
    code, _, err = run(capsys, "run", str(scene), "--seconds", "0.1", "--fps", "20", "--export", str(tmp_path / "m"),
                       "--format", "svg", "--quiet")
    assert code == 0 and err == ""
    assert sorted(p.name for p in (tmp_path / "m").iterdir()) == [f"frame_0000{k}.svg" for k in range(2)]


def test_an_unstable_run_exports_nothing(tmp_path, capsys):
    scene = tmp_path / "boom.toml"
    scene.write_text("[physics]\nintegrator = \"symplectic-euler\"\ndt = 0.02\nsubsteps = 1\nstiffness = 50000.0\n"
                     "[[body]]\ndetail = 4\n"
                     "position = [0.0, 1.0]\n[[collider]]\ncenter = [0.0, 0.0]\nsize = [5.0, 0.5]\n")
    code, _, err = run(capsys, "run", str(scene), "--export", str(tmp_path / "m"), "--quiet")
    assert code == EXIT_UNSTABLE and "nothing was written" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["boom.toml"]

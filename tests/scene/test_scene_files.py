"""Scene files: validation with one clear error, and a round trip that loses nothing."""

import os
import re

import numpy as np
import pytest

import deforma
from deforma import scene as scenes
from deforma.scene import SceneError
from scene_checks import assert_refused, write


def test_defaults_fill_what_a_file_leaves_out(tmp_path):
    s = scenes.load(write(tmp_path, """
        [physics]
        stiffness = 250.0
        [[body]]
        detail = 3
    """))
    assert s.physics.stiffness == 250.0
    assert s.physics.dt == scenes.PhysicsSettings().dt
    assert s.body[0] == scenes.BoxBody(detail=3)
    world = s.build()
    assert world.stiffness == 250.0 and len(world.bodies) == 1 and len(world.bodies[0].positions) == 3 * 3 + 4 + 4 * 3


def test_a_scene_builds_the_world_it_describes(tmp_path):
    s = scenes.load(write(tmp_path, """
        [physics]
        dt = 0.001
        substeps = 3
        gravity = [1.0, -5.0]
        damping = 0.7
        mass = 2.5
        stiffness = 321.0
        friction = 0.25
        static_friction = 0.75
        [interaction]
        mouse_strength = 80.0
        [[body]]
        shape = "box"
        corners = [[0, 0], [2, 0], [2, 1], [0, 1]]
        detail = 2
        edges = false
        position = [5.0, 6.0]
        mass = 4.0
        [[collider]]
        center = [1, 2]
        size = [3, 0.5]
        angle = 12.5
        friction = 0.9
    """))
    w = s.build()
    assert (w.dt, w.substeps, w.gravity, w.damping, w.mass, w.stiffness, w.friction, w.static_friction) == \
        (0.001, 3, (1.0, -5.0), 0.7, 2.5, 321.0, 0.25, 0.75)
    assert w.grab_strength == 80.0
    (b,) = w.bodies
    assert b.mass == 4.0 and b.stiffness == 321.0
    lo, hi = b.positions.min(axis=0), b.positions.max(axis=0)
    np.testing.assert_allclose((lo + hi) / 2, [5.0, 6.0])
    np.testing.assert_allclose(hi - lo, [2.0, 1.0])
    (c,) = w.colliders
    assert (c.center, c.size, c.angle, c.friction, c.static_friction) == ((1.0, 2.0), (3.0, 0.5), 12.5, 0.9, None)


@pytest.mark.parametrize("name", sorted(scenes.builtin_scenes()))
def test_builtin_scene_round_trip_loses_nothing(tmp_path, name):
    first = scenes.load(name)
    path = deforma.scene.save_scene(first.build(), tmp_path / f"{name}.toml")
    again = scenes.load(path)
    if any(c.shape == "image" for c in first.collider):
        # an image collider is written as its pieces (polygons of the same colour): nothing lost
        from dataclasses import replace

        first = replace(first, collider=scenes.scene_of(first.build()).collider)
        assert "image" not in {c.shape for c in again.collider}
    assert again == first
    # and writing it again gives the same bytes
    path2 = deforma.scene.save_scene(again.build(), tmp_path / "again.toml")
    assert path2.read_text() == path.read_text()
    # built-in pictures are written by name, never as a path into the installed package
    assert "assets" not in path.read_text()


def test_a_pattern_is_a_texture_by_name_but_no_mesh_source(tmp_path):
    s = scenes.load(write(tmp_path, """
        [[body]]
        texture = "cloth"
    """))
    assert s.body[0].texture == "cloth" and s.body[0].texture in scenes.builtin_patterns()
    assert 'texture = "cloth"' in scenes.save_scene(s, tmp_path / "saved.toml").read_text()
    assert scenes.load_texture("cloth").shape[2] == 4
    with pytest.raises(SceneError, match=r"body\[0\]: source .cloth. is a pattern.*texture = .cloth.*armadillo"):
        scenes.load_scene(write(tmp_path, """
            [[body]]
            shape = "image"
            source = "cloth"
        """))


def test_live_changes_are_saved(tmp_path):
    w = scenes.load_scene("sample")
    w.material = None  # the seed's springs (the shipped box is finite elements)
    w.stiffness = 1234.0
    w.gravity = (0.0, -3.0)
    w.bodies[0].damping = 9.0
    w.add_collider(deforma.Rect((3, 1), (1, 1), 45.0, static_friction=0.8))
    w.add_body(deforma.mesh.Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]]), position=(7, 7))
    p = scenes.save_scene(w, tmp_path / "changed.toml")
    w2 = scenes.load_scene(p)
    assert w2.stiffness == 1234.0 and w2.gravity == (0.0, -3.0)
    assert w2.bodies[0].damping == 9.0 and w2.bodies[0].stiffness == 1234.0
    c = w2.colliders[-1]
    assert (c.center, c.size, c.angle, c.static_friction) == ((3.0, 1.0), (1.0, 1.0), 45.0, 0.8)
    # a body made in code is saved as its mesh, placed where it was
    np.testing.assert_allclose(w2.bodies[1].positions, w.bodies[1].topology.rest_positions)
    np.testing.assert_array_equal(w2.bodies[1].triangles, w.bodies[1].triangles)


def test_live_contact_settings_are_saved(tmp_path):
    w = scenes.load_scene("jelly")
    w.contact_thickness = 0.004
    w.air_drag = 0.7
    w.bodies[0].self_collision = False
    w.bodies[1].collide = False
    w.bodies[2].friction = 0.9
    w2 = scenes.load_scene(scenes.save_scene(w, tmp_path / "contacts.toml"))
    assert (w2.contact_thickness, w2.air_drag) == (0.004, 0.7)
    assert [(b.collide, b.self_collision) for b in w2.bodies] == [(True, False), (False, True), (True, True)]
    assert [b.friction for b in w2.bodies] == [w.friction, w.friction, 0.9]


def test_relative_texture_paths_follow_the_file(tmp_path):
    from PIL import Image

    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    Image.new("RGB", (8, 8), (200, 10, 10)).save(tmp_path / "a" / "tex.png")
    s = scenes.load(write(tmp_path / "a", """
        [[body]]
        texture = "tex.png"
    """))
    assert s.body[0].texture == str((tmp_path / "a" / "tex.png").resolve())
    p = scenes.save_scene(s, tmp_path / "b" / "moved.toml")
    assert 'texture = "../a/tex.png"' in p.read_text()
    assert scenes.load(p) == s


def test_save_scene_writes_atomically_and_checks_the_target(tmp_path):
    w = scenes.load_scene("sample")
    with pytest.raises(ValueError, match="must end in .toml"):
        scenes.save_scene(w, tmp_path / "x.txt")
    with pytest.raises(ValueError, match="does not exist"):
        scenes.save_scene(w, tmp_path / "nope" / "x.toml")
    scenes.save_scene(w, tmp_path / "x.toml")
    assert sorted(os.listdir(tmp_path)) == ["x.toml"]
    (tmp_path / "d.toml").mkdir()
    with pytest.raises(ValueError, match=r"d.toml: is a folder; give the scene file's name, ending in .toml"):
        scenes.save_scene(w, tmp_path / "d.toml")
    with pytest.raises(TypeError, match="save_scene saves a deforma.World or a deforma.scene.Scene, got int"):
        scenes.save_scene(42, tmp_path / "y.toml")


def test_save_scene_on_a_full_disk_keeps_the_earlier_file_and_names_it(tmp_path, monkeypatch):
    import errno

    w = scenes.load_scene("sample")
    target = tmp_path / "x.toml"
    target.write_text("# earlier")
    real = open

    def full_disk_open(file, mode="r", *args, **kwargs):
        if "w" in mode and ".partial" in str(file):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(file, mode, *args, **kwargs)

    monkeypatch.setattr("builtins.open", full_disk_open)
    with pytest.raises(OSError) as e:
        scenes.save_scene(w, target)
    monkeypatch.undo()
    assert str(e.value) == f"{target}: could not be written: no space left on the device; nothing was written"
    assert target.read_text() == "# earlier" and sorted(os.listdir(tmp_path)) == ["x.toml"]


BAD = [
    ("[physics]\nstifness = 3.0\n", "physics.stifness: unknown key; did you mean 'stiffness'?"),
    ("[phisics]\ndt = 0.1\n", "phisics: unknown key; did you mean 'physics'?"),
    ("[[body]]\ndetial = 3\n", "body[0].detial: unknown key; did you mean 'detail'?"),
    ("[[body]]\nshape = 'image'\ndetail = 3\n", "body[0].detail: unknown key"),
    ("[physics]\ndt = 'fast'\n", "physics.dt: expected a number, got string 'fast'"),
    ("[physics]\ndt = -0.01\n", "physics.dt: must be in (0, 0.1] s, got -0.01"),
    ("[physics]\nsubsteps = 1.5\n", "physics.substeps: expected an integer, got number 1.5"),
    ("[physics]\nsubsteps = 0\n", "physics.substeps: must be in [1, 1000], got 0"),
    ("[physics]\ngravity = [0, 'down']\n", "physics.gravity[1]: expected a number"),
    ("[physics]\ngravity = 9.81\n", "physics.gravity: expected two numbers [x, y]"),
    ("[physics]\nfriction = -1\n", "physics.friction: must be >= 0, got -1"),
    ("[[body]]\ndetail = -2\n", "body[0].detail: must be >= 0, got -2"),
    ("[[body]]\ndetail = 1" + "0" * 400 + "\n",  # TOML integers are unbounded: not an OverflowError
     "body[0].detail: expected a finite number, got an integer of 401 digits, too large for a float"),
    ("[physics]\ngravity = [0, -1" + "0" * 400 + "]\n", "physics.gravity[1]: expected a finite number, got an integer"),
    ("[run]\nseconds = 1" + "0" * 5000 + "\n",  # past 4300 digits the TOML reader's int() refuses it
     "invalid TOML: an integer of more than 4300 digits (every number in a scene is far smaller)"),
    ("[[body]]\nedges = 1\n", "body[0].edges: expected true or false, got integer 1"),
    ("[[body]]\ncorners = [[0, 0], [1, 0], [1, 1]]\n", "body[0].corners: expected four corners"),
    ("[[body]]\nshape = 'circle'\n", "body[0].shape: unknown value 'circle'; allowed: box, image, mesh"),
    ("[[body]]\ncolor = 'red'\n", "body[0].color: expected a colour '#rrggbb'"),
    ("[[body]]\ntexture = 'missing.png'\n", "body[0].texture: no such file"),
    ("[[body]]\nshape = 'image'\nsource = 'bunyy'\n", "body[0].source: unknown texture 'bunyy'"),
    ("[[collider]]\nsize = [1, 0]\n", "collider[0].size: both must be > 0"),
    ("[[collider]]\nangle = 720\n", "collider[0].angle: must be in [-360, 360] degrees"),
    ("[[event]]\naction = 'explod'\n", "event[0].action: unknown value 'explod'; did you mean 'explode'?"),
    ("body = 3\n", "body: expected an array of tables ([[body]])"),
    ("[run]\nfps = 0\n", "run.fps: must be in [1, 240] frames/s, got 0"),
    ("[physics\ndt = 1\n", "invalid TOML"),
    ("[[body]]\nshape = 'box'\ncorners = [[0, 0], [1, 1], [1, 0], [0, 1]]\n", "body[0]:"),
    ("[physics]\nintegrator = 'rk99'\n",
     "physics.integrator: unknown value 'rk99'; allowed: symplectic-euler, implicit-euler, xpbd"),
    ("[physics]\nintegrator = 'xpdb'\n", "physics.integrator: unknown value 'xpdb'; did you mean 'xpbd'?"),
    ("[physics]\ncontact_thickness = -0.001\n", "physics.contact_thickness: must be > 0 m, got -0.001"),
    ("[physics]\ncontact_thickness = 0.5\n[[body]]\ndetail = 4\n",
     "body[0]: contact_thickness 0.5 m is not below the shortest boundary edge of the new body"),
    ("[physics]\nair_drag = -1\n", "physics.air_drag: must be >= 0 1/s, got -1"),
    ("[[body]]\ncollide = 'yes'\n", "body[0].collide: expected true or false"),
    ("[[body]]\nstatic_friction = -0.5\n", "body[0].static_friction: must be >= 0, got -0.5"),
    ("[[body]]\nposition = [0, 0]\n[[body]]\nposition = [0.3, 0.2]\n",
     "body[1]: the new body (1) would overlap body 0 (their outlines cross or one lies inside the other)"),
]


@pytest.mark.parametrize("text, message", BAD)
def test_invalid_files_give_one_error_naming_file_and_key(tmp_path, text, message):
    assert_refused(write(tmp_path, text, "bad.toml"), message)


def test_unknown_scene_lists_the_builtins():
    with pytest.raises(SceneError) as e:
        scenes.load("sampel")
    msg = str(e.value)
    assert "unknown scene 'sampel'; did you mean 'sample'?" in msg
    for name in scenes.builtin_scenes():
        assert name in msg


def test_build_errors_name_the_file_as_the_user_does(tmp_path, monkeypatch):
    # the Scene keeps the absolute path (for its pictures); messages show it relative to the
    # working folder, as the file was named, like the errors found while reading it
    (tmp_path / "two.toml").write_text("[[body]]\nposition = [0, 1]\n\n[[body]]\nposition = [0.1, 1]\n")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneError, match=r"^two\.toml: body\[1\]: the new body \(1\) would overlap body 0"):
        scenes.load("two.toml").build()
    (tmp_path / "..two.toml").write_text((tmp_path / "two.toml").read_text())  # a name, not the parent folder
    with pytest.raises(SceneError, match=r"^\.\.two\.toml: body\[1\]"):
        scenes.load("..two.toml").build()
    elsewhere = tmp_path / "sub"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    with pytest.raises(SceneError, match=r"^" + re.escape(str(tmp_path / "two.toml")) + r": body\[1\]"):
        scenes.load(tmp_path / "two.toml").build()


def test_missing_and_unreadable_files(tmp_path):
    with pytest.raises(SceneError, match="no such scene file"):
        scenes.load(tmp_path / "absent.toml")
    with pytest.raises(SceneError, match="is a folder, not a scene file"):
        scenes.load(tmp_path)
    p = tmp_path / "binary.toml"
    p.write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(SceneError, match="not a text file"):
        scenes.load(p)


def test_scene_error_is_a_value_error():
    assert issubclass(SceneError, ValueError)


def test_saved_vectors_are_written_on_one_line(tmp_path):
    from deforma.scene.build import _inline_short_arrays
    import tomli_w
    import tomllib

    text = scenes.save_scene(scenes.load_scene("sample"), tmp_path / "s.toml").read_text()
    assert "gravity = [0.0, -9.81]\n" in text and "center = [0.0, 0.0]\n" in text
    assert "corners = [[-0.75, -0.5], [0.75, -0.5], [0.75, 0.5], [-0.75, 0.5]]\n" in text
    # nested and long arrays keep their values; a long one keeps one element per line
    doc = {"v": [[0.123456789, -2.5]] * 9, "t": [[0, 1, 2], [2, 3, 0]], "s": ["#ffffff", "#000000"]}
    compact = _inline_short_arrays(tomli_w.dumps(doc))
    assert tomllib.loads(compact) == doc
    assert "    [0.123456789, -2.5],\n" in compact and "t = [[0, 1, 2], [2, 3, 0]]\n" in compact


@pytest.mark.parametrize("content, why", [
    (b"not a picture", "cannot identify image file"),
    (b"", "cannot identify image file"),
    ("liar", "image file is truncated"),  # a PNG whose header says 100 x 100 and holds 10 x 10
])
def test_an_unreadable_texture_file_is_refused_naming_its_key(tmp_path, content, why):
    import struct
    import zlib

    if content == "liar":
        def chunk(kind, data):
            return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
        raw = b"".join(b"\x00" + b"\xff\x00\x00" * 10 for _ in range(10))
        content = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 100, 100, 8, 2, 0, 0, 0))
                   + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
    (tmp_path / "t.png").write_bytes(content)
    p = tmp_path / "s.toml"
    p.write_text('[[body]]\ndetail = 2\ntexture = "t.png"\n')
    with pytest.raises(scenes.SceneError) as e:
        scenes.load(p)
    text = str(e.value)
    assert "\n" not in text and text.startswith(f"{p}: body[0].texture: cannot read image") and why in text


def test_a_camera_follows_a_body_named_by_its_place(tmp_path):
    p = tmp_path / "follow.toml"
    body = '[[body]]\nshape = "box"\ncorners = [[0, 0], [1, 0], [1, 1], [0, 1]]\n'
    p.write_text("[camera]\nfollow = 1\n" + body + body.replace("[[0, 0], [1, 0], [1, 1], [0, 1]]",
                                                                   "[[2, 0], [3, 0], [3, 1], [2, 1]]"))
    scene = deforma.scene.load(p)
    assert scene.camera.follow == 1
    world = deforma.scene.build(scene)
    again = deforma.scene.load(deforma.save_scene(world, tmp_path / "again.toml"))
    assert again.camera.follow == 1
    for follow, message in (("2", "camera.follow: there is no body 2: the scene has 2 [[body]] tables"),
                            ("-1", "camera.follow"), ("0.5", "camera.follow")):
        p.write_text(f"[camera]\nfollow = {follow}\n" + body + body)
        with pytest.raises(deforma.scene.SceneError) as e:
            deforma.scene.load(p)
        assert message in str(e.value) and "\n" not in str(e.value)

"""Scene files with materials and pins: what they build, what they refuse, and round trips."""

import textwrap

import numpy as np
import pytest

import deforma
from deforma import scene as scenes
from deforma.physics.material import MODELS
from deforma.scene import SceneError
from deforma.scene.schema import MATERIAL_MODELS
from scene_checks import assert_refused, write

FEM = textwrap.dedent("""
    [physics]
    substeps = 12
    material = "neo-hookean"
    youngs_modulus = 2e4
    poisson_ratio = 0.3
    density = 2.0
    material_damping = 0.0005
""")


def material(model, e=2e4, nu=0.3, rho=2.0, damping=0.0):
    return deforma.Material(model, youngs_modulus=e, poisson_ratio=nu, density=rho, damping=damping)


def test_the_scene_knows_the_physics_models():
    assert MATERIAL_MODELS == MODELS


def test_physics_material_is_the_worlds_default(tmp_path):
    w = scenes.load_scene(write(tmp_path, FEM + """
        [[body]]
        detail = 3
        position = [0, 2]
    """))
    assert w.material == material("neo-hookean", damping=0.0005)
    (b,) = w.bodies
    assert b.is_fem and b.material == w.material
    assert b.mass == pytest.approx(2.0 * 1.0)  # density * area of the unit box
    w.material = None  # it followed the world: no material of its own
    assert not w.bodies[0].is_fem


def test_springs_is_the_default_and_builds_no_material(tmp_path):
    w = scenes.load_scene(write(tmp_path, "[[body]]\ndetail = 2\n"))
    assert w.material is None and w.bodies[0].material == deforma.Material("springs")


def test_a_body_takes_what_it_leaves_out_from_physics(tmp_path):
    w = scenes.load_scene(write(tmp_path, """
        [physics]
        youngs_modulus = 3e4
        poisson_ratio = 0.25
        density = 4.0
        [[body]]
        detail = 2
        position = [0, 2]
        [[body]]
        detail = 2
        position = [3, 2]
        material = "corotated"
        density = 1.5
        [[body]]
        detail = 2
        position = [6, 2]
        mass = 3.0
    """))
    springs, fem, heavy = w.bodies
    assert w.material is None
    assert springs.material == deforma.Material("springs") and springs.mass == 1.0
    assert fem.material == material("corotated", e=3e4, nu=0.25, rho=1.5)
    assert heavy.mass == 3.0 and not heavy.is_fem


def test_a_body_can_be_springs_in_a_fem_world(tmp_path):
    w = scenes.load_scene(write(tmp_path, FEM + """
        [[body]]
        detail = 2
        position = [0, 2]
        material = "springs"
        stiffness = 500.0
    """))
    (b,) = w.bodies
    assert not b.is_fem and b.stiffness == 500.0 and w.material.is_fem


def test_pin_box_pins_exactly_the_vertices_inside_and_they_stay(tmp_path):
    w = scenes.load_scene(write(tmp_path, """
        [physics]
        substeps = 4
        stiffness = 100.0
        [[body]]
        detail = 4
        position = [0, 3]
        pin = [[0.6, 3.6], [-0.6, 3.4]]
    """))
    (b,) = w.bodies
    x0 = b.positions.copy()
    top = np.isclose(x0[:, 1], 3.5)
    np.testing.assert_array_equal(b.pinned, top)  # the corners may come in any order
    assert top.sum() == 4 + 2  # two corners and four side points
    for _ in range(300):
        w.step()
    np.testing.assert_array_equal(b.positions[top], x0[top])
    assert b.positions[~top, 1].min() < x0[~top, 1].min() - 0.01  # the rest hangs


def test_pin_vertices_and_box_together_pin_the_union(tmp_path):
    w = scenes.load_scene(write(tmp_path, """
        [[body]]
        shape = "mesh"
        vertices = [[0, 0], [1, 0], [1, 1], [0, 1]]
        triangles = [[0, 1, 2], [0, 2, 3]]
        pin = [[-0.1, -0.1], [0.1, 0.1]]
        pin_vertices = [2]
    """))
    assert w.bodies[0].pinned.tolist() == [True, False, True, False]


BAD = [
    (FEM.replace("youngs_modulus = 2e4\n", "") + "[[body]]\ndetail = 2\n",
     "physics: the 'neo-hookean' material needs youngs_modulus (E in Pa"),
    ("[physics]\npoisson_ratio = 0.3\ndensity = 1.0\n[[body]]\nmaterial = 'corotated'\n",
     "body[0]: the 'corotated' material needs youngs_modulus (E in Pa, nu in (-1, 0.5), density in kg/m^2): set it "
     "on the body or in [physics]"),
    ("[[body]]\nmaterial = 'neo-hookean'\nyoungs_modulus = 1e4\n", "body[0]: the 'neo-hookean' material needs "
                                                                   "poisson_ratio, density"),
    ("[[body]]\nyoungs_modulus = 1e4\n", "body[0].youngs_modulus: the 'springs' material takes no youngs_modulus"),
    (FEM + "[[body]]\nmaterial = 'springs'\ndensity = 3.0\n", "body[0].density: the 'springs' material takes no "
                                                               "density"),
    (FEM + "[[body]]\nmass = 2.0\n", "body[0].mass: the body is made of 'neo-hookean' finite elements "
                                     "(physics.material), whose mass is density * area"),
    (FEM + "[[body]]\nmaterial = 'corotated'\nstiffness = 10.0\n", "body[0].stiffness: the body is made of "
                                                                   "'corotated' finite elements, whose"),
    ("[physics]\nyoungs_modulus = 1e4\n[[body]]\ndetail = 2\n",
     "physics.youngs_modulus: no body is made of finite elements to use it (physics.material is 'springs')"),
    ("[physics]\nmaterial = 'steel'\n", "physics.material: unknown value 'steel'; allowed: springs, corotated, "
                                        "neo-hookean, rigid, jelly, gummy, rubber, foam, wood, cloth"),
    ("[[body]]\nmaterial = 'neohookean'\n", "body[0].material: unknown value 'neohookean'; did you mean "
                                            "'neo-hookean'?"),
    ("[physics]\npoisson_ratio = 0.5\n", "physics.poisson_ratio: must be in (-1, 0.5), got 0.5"),
    ("[physics]\nyoungs_modulus = 0\n", "physics.youngs_modulus: must be in (0, 1e+15] Pa, got 0"),
    ("[[body]]\ndensity = -1.0\n", "body[0].density: must be in (0, 1e+12] kg/m^2, got -1"),
    ("[[body]]\nmaterial_damping = -0.1\n", "body[0].material_damping: must be in [0, 1e+06] s"),
    ("[[body]]\nposition = [0, 3]\npin = [[5, 5], [6, 6]]\n",
     "body[0].pin: the box [[5, 5], [6, 6]] holds no vertex of the body, which spans x -0.5..0.5 m, y 2.5..3.5 m"),
    ("[[body]]\npin = [[0, 0]]\n", "body[0].pin: expected two corners [[x0, y0], [x1, y1]]"),
    ("[[body]]\npin = [[0, 0], [1, 0]]\n", "body[0].pin: the box must have a width and a height"),
    ("[[body]]\ndetail = 2\npin_vertices = [0, 99]\n",
     "body[0].pin_vertices: vertex index 99 is out of range; the body has vertices 0..15"),
    ("[[body]]\npin_vertices = [-1]\n", "body[0].pin_vertices[0]: vertex indices must be >= 0, got -1"),
    ("[[body]]\npin_vertices = 3\n", "body[0].pin_vertices: expected vertex indices [i, j, ...]"),
    (FEM + "plane = '3d'\n", "physics.plane: unknown value '3d'; allowed: stress, strain"),
    ("[[body]]\nplane = 'strain'\n", "body[0].plane: the 'springs' material takes no plane"),
    ("[physics]\nplane = 'strain'\n[[body]]\ndetail = 2\n",
     "physics.plane: no body is made of finite elements to use it (physics.material is 'springs')"),
]


@pytest.mark.parametrize("text, message", BAD)
def test_invalid_material_and_pin_keys_give_one_error_naming_file_body_and_key(tmp_path, text, message):
    assert_refused(write(tmp_path, text, "bad.toml"), message)


def test_a_scene_made_in_code_is_refused_at_build_too():
    s = scenes.Scene(body=(scenes.BoxBody(material="corotated"),))
    with pytest.raises(SceneError, match=r"body\[0\]: the 'corotated' material needs youngs_modulus"):
        s.build()


# -- round trips -------------------------------------------------------------------------------

def full_scene(tmp_path):
    return write(tmp_path, """
        [physics]
        substeps = 12
        youngs_modulus = 2e4
        poisson_ratio = 0.3
        density = 2.0
        [[body]]
        detail = 3
        position = [0, 2]
        material = "neo-hookean"
        pin = [[-1, 2.4], [1, 2.6]]
        [[body]]
        detail = 3
        position = [3, 2]
        material = "corotated"
        youngs_modulus = 5e4
        material_damping = 0.001
        pin_vertices = [0, 1]
        [[body]]
        detail = 3
        position = [6, 2]
        stiffness = 800.0
    """, "full.toml")


def test_materials_and_pins_round_trip_unchanged(tmp_path):
    first = scenes.load(full_scene(tmp_path))
    path = scenes.save_scene(first.build(), tmp_path / "saved.toml")
    assert scenes.load(path) == first
    again = scenes.save_scene(scenes.load_scene(path), tmp_path / "again.toml")
    assert again.read_text() == path.read_text()


def saved(world, tmp_path, name="saved.toml"):
    path = scenes.save_scene(world, tmp_path / name)
    return scenes.load(path), scenes.load_scene(path)


def test_live_world_material_is_saved_and_fem_bodies_drop_spring_keys(tmp_path):
    w = scenes.load_scene(full_scene(tmp_path))
    w.material = material("corotated", e=7e4, nu=0.2, rho=3.0, damping=0.002)
    scene, w2 = saved(w, tmp_path)
    assert (scene.physics.material, scene.physics.youngs_modulus, scene.physics.material_damping) == \
        ("corotated", 7e4, 0.002)
    assert scene.body[2].stiffness is None  # it follows the world's elements now: no springs to write
    assert [b.material for b in w2.bodies] == [b.material for b in w.bodies]
    assert w2.material == w.material


def test_live_body_materials_are_saved_as_its_own_keys(tmp_path):
    w = scenes.load_scene(full_scene(tmp_path))
    w.material = material("corotated")
    a, b, c = w.bodies
    a.material = deforma.Material("springs")
    b.material = None  # follows the world
    c.material = material("neo-hookean", e=9e3, nu=0.45, rho=0.5)
    scene, w2 = saved(w, tmp_path)
    assert scene.body[0].material == "springs" and scene.body[0].youngs_modulus is None
    assert scene.body[1].material is None and scene.body[1].youngs_modulus is None
    assert scene.body[2].material == "neo-hookean" and scene.body[2].stiffness is None
    assert [x.material for x in w2.bodies] == [x.material for x in w.bodies]
    w2.material = None  # and the one that followed still does
    assert [x.is_fem for x in w2.bodies] == [False, False, True]
    w.material = None  # a springs body in a springs world is written as following it
    scene, _ = saved(w, tmp_path, "springs.toml")
    assert scene.body[0].material is None


def test_physics_defaults_stay_while_a_body_uses_them_and_go_after(tmp_path):
    w = scenes.load_scene(full_scene(tmp_path))
    scene, _ = saved(w, tmp_path)
    assert scene.physics.youngs_modulus == 2e4 and scene.body[0].youngs_modulus is None
    for b in w.bodies:
        b.material = deforma.Material("springs")
    scene, w2 = saved(w, tmp_path, "springs.toml")  # loadable: no unused finite-element defaults
    assert scene.physics.youngs_modulus is None and not any(b.is_fem for b in w2.bodies)


def test_a_fem_world_switched_to_springs_keeps_bodies_of_their_own(tmp_path):
    w = scenes.load_scene(write(tmp_path, FEM + """
        [[body]]
        detail = 2
        position = [0, 2]
        [[body]]
        detail = 2
        position = [3, 2]
        youngs_modulus = 4e4
    """))
    w.material = None
    scene, w2 = saved(w, tmp_path)
    assert scene.physics.material == "springs"
    assert [b.material for b in w2.bodies] == [deforma.Material("springs"),
                                               material("neo-hookean", e=4e4, damping=0.0005)]


def test_pins_changed_live_are_saved_as_vertex_numbers(tmp_path):
    w = scenes.load_scene(full_scene(tmp_path))
    a, b, c = w.bodies
    box = a.pinned.copy()
    scene, _ = saved(w, tmp_path)
    assert scene.body[0].pin is not None and scene.body[0].pin_vertices is None  # unchanged: the box stays
    a.pin([box.argmin()])  # one more than the box holds
    b.unpin([0])
    c.pin([5, 7])
    scene, w2 = saved(w, tmp_path, "pins.toml")
    assert scene.body[0].pin is None and sorted(scene.body[0].pin_vertices) == sorted(np.flatnonzero(a.pinned))
    assert scene.body[1].pin_vertices == (1,)
    assert scene.body[2].pin_vertices == (5, 7)
    for x, y in zip(w.bodies, w2.bodies):
        np.testing.assert_array_equal(x.pinned, y.pinned)
    a.unpin()
    a.pin(box)  # back to what the box holds: the box is written again
    scene, _ = saved(w, tmp_path, "box.toml")
    assert scene.body[0].pin == ((-1.0, 2.4), (1.0, 2.6)) and scene.body[0].pin_vertices is None
    a.unpin()
    scene, w3 = saved(w, tmp_path, "none.toml")
    assert scene.body[0].pin is None and scene.body[0].pin_vertices is None and not w3.bodies[0].pinned.any()


def test_pins_and_materials_of_a_world_made_in_code_round_trip(tmp_path):
    w = deforma.World(integrator="symplectic-euler", dt=1 / 600, material=material("corotated"), substeps=12)
    m = deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2, edges=True)
    a = w.add_body(m, position=(0, 2))
    b = w.add_body(m, position=(3, 2), material=material("neo-hookean", e=5e4))
    c = w.add_body(m, position=(6, 2), material=deforma.Material("springs"), mass=2.0)
    a.pin([0, 3])
    _, w2 = saved(w, tmp_path)
    assert w2.material == w.material
    assert [x.material for x in w2.bodies] == [a.material, b.material, c.material]
    assert w2.bodies[2].mass == 2.0
    np.testing.assert_array_equal(w2.bodies[0].pinned, a.pinned)


def test_plane_strain_from_physics_or_a_body_builds_and_round_trips(tmp_path):
    path = write(tmp_path, FEM + """
        plane = "strain"
        [[body]]
        detail = 3
        position = [0, 2]
        [[body]]
        detail = 3
        position = [3, 2]
        plane = "stress"
    """)
    w = scenes.load_scene(path)
    assert w.material.plane == "strain" and w.material.lame()[1] == pytest.approx(2e4 * 0.3 / (1.3 * 0.4))
    assert [b.material.plane for b in w.bodies] == ["strain", "stress"]
    scene, w2 = saved(w, tmp_path)
    assert scene.physics.plane == "strain" and scene.body[1].plane == "stress"
    assert [b.material for b in w2.bodies] == [b.material for b in w.bodies]

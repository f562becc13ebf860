"""The viewer's model without a window: parameters, mesh rebuilds, colliders, save/load."""

import dataclasses

import numpy as np
import pytest

import deforma
from deforma.scene import BoxBody, ImageBody
from deforma.viewer.params import GROUPS, PARAMS, parse_value
from deforma.viewer.session import COLLIDER_FIELDS, OBJECTS, Session
from seed_scenes import seed


def test_every_original_inspector_value_is_a_parameter():
    names = set(PARAMS)
    assert {"detail", "edges", "scale", "resolution", "detect_edges", "edge_step", "dt", "gravity_x", "gravity_y",
            "damping", "mass", "stiffness", "static_friction", "friction", "explosive_force", "collider_x",
            "collider_y", "collider_width", "collider_height", "collider_angle", "mouse_strength"} <= names
    assert {"youngs_modulus", "poisson_ratio", "density", "material_damping"} <= names
    assert [g for g, _ in GROUPS] == ["Square", "Texture", "Physics", "Material", "Contact", "Collision", "Mouse"]
    assert {"tear_strain", "yield_strain", "plastic_rate", "max_stretch", "pressure"} <= names
    s = Session("demo")
    shape_only = set(COLLIDER_FIELDS) - set(s.collider_params())  # a rect has no radius: greyed out
    assert shape_only == {"collider_radius"}
    for name in names - shape_only:  # every parameter reads back from a live session (None: a value that is off)
        assert s.get_param(name) is not None or PARAMS[name].optional


def test_physics_values_apply_to_the_running_world():
    s = Session("demo")
    world = s.world
    s.set_param("stiffness", 2345.0)
    s.set_param("gravity_y", -3.0)
    s.set_param("mouse_strength", 80.0)
    s.set_param("substeps", 9.0)
    s.set_param("air_drag", 0.5)
    s.set_param("contact_thickness", 0.003)
    s.set_param("self_collision", False)
    assert s.world is world  # no rebuild
    assert (world.stiffness, world.gravity, world.grab_strength, world.substeps) == (2345.0, (0.0, -3.0), 80.0, 9)
    assert (world.air_drag, world.contact_thickness, world.bodies[0].self_collision) == (0.5, 0.003, False)
    assert s.get_param("self_collision") is False and s.get_param("collide") is True


@pytest.mark.parametrize("name, value", [("stiffness", -1.0), ("mass", 0.0), ("dt", float("nan")),
                                         ("detail", 5000), ("resolution", 1), ("scale", 0.0), ("substeps", 2.5),
                                         ("collider_width", -2.0), ("collider_angle", 1000.0),
                                         ("explosive_force", -1.0), ("air_drag", -1.0),
                                         ("contact_thickness", 1.0), ("youngs_modulus", 0.0),
                                         ("poisson_ratio", 0.5), ("density", -1.0), ("material_damping", -0.1),
                                         ("youngs_modulus", "stiff"), ("tear_strain", 0.0),
                                         ("yield_strain", -0.1), ("plastic_rate", 0.0), ("plastic_rate", None),
                                         ("max_stretch", 1.0), ("max_stretch", "long"), ("tear_strain", True),
                                         ("pressure", -5.0), ("pressure", float("inf"))])
def test_invalid_values_are_refused_and_change_nothing(name, value):
    s = Session("demo")
    before = s.scene
    world = s.world
    with pytest.raises(ValueError) as e:
        s.set_param(name, value)
    assert "\n" not in str(e.value)
    assert s.world is world and s.scene == before


def test_parse_value_refuses_text():
    with pytest.raises(ValueError, match="must be a number"):
        parse_value(PARAMS["stiffness"], "stiff")
    assert parse_value(PARAMS["substeps"], "12") == 12


@pytest.mark.parametrize("name", OBJECTS)
def test_select_object_rebuilds_the_body(name):
    s = Session("demo")
    start = s.body_spec.position
    s.select_object(name)
    spec = s.body_spec
    assert isinstance(spec, BoxBody if name == "box" else ImageBody)
    assert spec.position == start
    body = s.world.bodies[0]
    centre = (body.positions.min(axis=0) + body.positions.max(axis=0)) / 2
    np.testing.assert_allclose(centre, start, atol=1e-9)
    if name != "box":
        assert spec.source == name


def test_mesh_values_rebuild_with_the_new_recipe_and_keep_physics():
    s = Session("demo")
    s.set_param("stiffness", 1200.0)
    n = s.world.bodies[0].n_vertices
    s.set_param("resolution", 8)
    assert s.body_spec.resolution == 8 and s.world.bodies[0].n_vertices > n
    assert s.world.stiffness == 1200.0
    s.select_object("box")
    s.set_param("detail", 3)
    s.set_param("edges", False)
    assert s.world.bodies[0].n_vertices == 4 + 9


def test_switching_back_keeps_the_texture_settings():
    s = Session("demo")
    s.set_param("edge_step", 4)
    s.select_object("box")
    s.select_object("donut")
    assert s.body_spec.edge_step == 4 and s.body_spec.resolution == 12


def test_colliders_add_edit_remove():
    s = Session("demo")
    n = len(s.world.colliders)
    s.add_collider(center=(1.0, 2.0))
    assert len(s.world.colliders) == n + 1 and s.collider_index == n
    s.set_param("collider_angle", 30.0)
    s.set_param("collider_width", 4.0)
    c = s.world.colliders[n]
    assert (c.center, c.size, c.angle) == ((1.0, 2.0), (4.0, 0.3), 30.0)
    s.move_collider((0.5, 0.5))
    assert s.world.colliders[n].center == (0.5, 0.5)
    assert s.collider_at((0.5, 0.5)) == n
    s.remove_collider()
    assert len(s.world.colliders) == n


def test_save_and_load_back(tmp_path):
    s = Session("demo")
    s.set_param("stiffness", 2222.0)
    s.set_param("explosive_force", 7.5)
    s.select_object("donut")
    s.add_collider(center=(2.0, 6.0), angle=10.0)
    path = s.save(tmp_path / "edited.toml")
    scene = deforma.scene.load(path)
    assert scene.physics.stiffness == 2222.0 and scene.interaction.explosive_force == 7.5
    assert scene.body[0].source == "donut"
    assert scene.collider[-1].center == (2.0, 6.0) and scene.collider[-1].angle == 10.0
    world = deforma.load_scene(path)
    np.testing.assert_allclose(world.bodies[0].positions, Session(path).world.bodies[0].positions)
    with pytest.raises(ValueError, match=".toml"):
        s.save(tmp_path / "edited.txt")


def test_docs_list_every_key():
    from pathlib import Path

    from deforma.viewer.controls import KEYS, MOUSE, help_rows

    doc = (Path(__file__).resolve().parents[2] / "docs" / "viewer.md").read_text(encoding="utf-8")
    table = "\n".join(line for line in doc.splitlines() if line.startswith("| "))
    for names, _action, _text in KEYS:
        for n in names:
            shown = n.capitalize() if len(n) > 1 else n.upper()
            assert f"| {shown}" in table or f" {shown} " in table or f"/ {shown}" in table, n
    for button, _ in MOUSE:
        assert f"| {button}" in table
    assert len(help_rows()) == len(KEYS) + 1 + len(MOUSE)


def test_integrator_switches_on_the_running_world_and_is_saved(tmp_path):
    s = Session(seed("demo"))
    world = s.world
    assert s.integrator == "symplectic-euler"
    s.set_integrator("implicit-euler")
    assert s.world is world and world.integrator == "implicit-euler" and s.note == ""
    for _ in range(30):  # the switched world keeps stepping
        world.step()
    assert np.isfinite(world.bodies[0].positions).all()
    path = s.save(tmp_path / "implicit.toml")
    assert deforma.load_scene(path).integrator == "implicit-euler"


def test_xpbd_with_too_few_substeps_says_how_many_hold_the_bodies():
    s = Session("pile")  # 1/60 s: the heap's bodies need about 14 substeps under XPBD
    s.set_integrator("xpbd")
    assert s.note_is_warning and "raise substeps to 14 (world.xpbd_substeps()) or use implicit-euler" in s.note
    s.world.substeps = 14
    s.set_integrator("xpbd")
    assert s.note == ""
    s.set_integrator("implicit-euler")
    assert s.note == "" and not s.note_is_warning


def test_a_scene_under_xpbd_with_too_few_substeps_says_so_on_load_and_as_they_change(tmp_path):
    path = tmp_path / "stand.toml"
    path.write_text('[physics]\ndt = 0.016666666666666666\nintegrator = "xpbd"\n'
                    '[[body]]\nshape = "box"\ncorners = [[-0.5, 0], [0.5, 0], [0.5, 1], [-0.5, 1]]\ndetail = 28\n'
                    '[[collider]]\ncenter = [0, -0.2]\nsize = [3, 0.4]\n')
    s = Session(path)  # a 1 m body with 1/29 m spacing at 1/60 s: 22 substeps
    assert s.note_is_warning and "raise substeps to 22" in s.note
    s.set_param("substeps", 8)
    assert "with substeps = 8" in s.note
    s.set_param("substeps", 22)
    assert s.note == "" and not s.note_is_warning
    s.set_param("dt", 1 / 30)  # twice the step: twice the substeps (2 x 21.4, rounded up)
    assert "raise substeps to 43" in s.note
    s.set_param("gravity_y", 0.0)
    assert s.note == ""


def test_unknown_integrator_is_refused_with_the_names():
    s = Session(seed("demo"))
    with pytest.raises(ValueError, match="integrator must be one of .*xpbd.*got 'rk4'"):
        s.set_integrator("rk4")
    assert s.world.integrator == "symplectic-euler"


def test_switching_to_the_explicit_method_with_stiff_springs_warns():
    s = Session("demo")
    s.set_integrator("xpbd")
    s.set_param("stiffness", 1e6)
    s.set_integrator("symplectic-euler")
    assert "exceeds the explicit stable estimate" in s.note and "\n" not in s.note


# -- material ------------------------------------------------------------------------------------

def test_material_model_switches_on_the_running_world_with_the_defaults():
    s = Session(seed("sample"))
    world = s.world
    assert s.material_model == "springs" and world.material is None
    assert s.get_param("youngs_modulus") == 1e4 and s.get_param("material_damping") == 0.0
    s.set_material("neo-hookean")
    assert s.world is world and s.material_model == "neo-hookean"
    assert world.material == deforma.Material("neo-hookean", youngs_modulus=1e4, poisson_ratio=0.3, density=1.0,
                                              damping=0.0)
    rest = world.bodies[0].topology.rest_positions  # the sample's body is a rectangle
    area = np.prod(rest.max(axis=0) - rest.min(axis=0))
    assert world.bodies[0].is_fem and world.bodies[0].mass == pytest.approx(1.0 * area)  # density * area
    s.set_param("youngs_modulus", 5e4)
    s.set_param("poisson_ratio", 0.2)
    assert (world.material.youngs_modulus, world.material.poisson_ratio) == (5e4, 0.2)
    s.set_material("springs")
    assert world.material is None and not world.bodies[0].is_fem
    s.set_param("density", 3.0)  # kept while springs ...
    assert world.material is None and "kept for when" in s.note
    s.set_material("corotated")  # ... and used when a model needs it; the rest was kept too
    assert (world.material.model, world.material.youngs_modulus, world.material.density) == ("corotated", 5e4, 3.0)


def test_the_rigid_model_makes_the_bodies_rigid_and_keeps_the_elastic_values():
    s = Session(seed("sample"))
    world = s.world
    s.set_param("youngs_modulus", 5e4)
    s.set_material("rigid")
    assert world.material == deforma.Material("rigid", density=1.0) and world.bodies[0].material.is_rigid
    s.set_param("youngs_modulus", 6e4)  # kept for an elastic model, the bodies stay rigid
    assert world.material.is_rigid and "kept for when" in s.note
    s.set_param("density", 2.0)
    assert world.material == deforma.Material("rigid", density=2.0)
    for _ in range(30):
        world.step()
    s.set_material("corotated")
    assert (world.material.youngs_modulus, world.material.density) == (6e4, 2.0)


def test_a_fem_scene_shows_its_material():
    scene = deforma.scene.load("sample")
    physics = dataclasses.replace(scene.physics, material="corotated", youngs_modulus=2e5, poisson_ratio=0.25,
                                  density=7.0, material_damping=0.0)
    s = Session(dataclasses.replace(scene, physics=physics))
    assert s.material_model == "corotated"
    assert [s.get_param(n) for n in ("youngs_modulus", "poisson_ratio", "density", "material_damping")] == \
        [2e5, 0.25, 7.0, 0.0]


def test_fem_under_the_explicit_integrator_raises_substeps_or_says_what_to_do():
    s = Session("sample")
    s.world.substeps = 1
    s.material_values["material_damping"] = 0.0
    s.set_material("corotated")
    w = s.world
    assert w.substeps > 1 and "substeps raised to" in s.note and not s.note_is_warning
    assert w.dt / w.substeps <= w.stable_dt()
    for _ in range(120):
        w.step()  # stable as raised
    s.set_param("youngs_modulus", 1e8)  # far beyond what a live window raises substeps to
    assert s.note_is_warning and "implicit-euler or xpbd" in s.note and "\n" not in s.note
    s.set_integrator("implicit-euler")
    s.set_param("youngs_modulus", 1e7)  # a stable integrator needs no more substeps
    assert s.note == ""


def test_a_body_that_cannot_be_fem_refuses_the_material_and_nothing_changes():
    s = Session(seed("sample"))
    chain = type("Chain", (), {"vertices": np.array([[5.0, 5.0], [6.0, 5.0], [7.0, 5.0]]),
                               "edges": np.array([[0, 1], [1, 2]])})()
    s.world.add_body(chain)
    with pytest.raises(ValueError, match="needs a mesh with triangles") as e:
        s.set_material("neo-hookean")
    assert "\n" not in str(e.value)
    assert s.world.material is None and s.material_model == "springs"
    with pytest.raises(ValueError, match="material model must be one of springs, corotated, neo-hookean"):
        s.set_material("jelly")


def test_material_is_saved_and_survives_a_mesh_change(tmp_path):
    s = Session("demo")
    s.set_integrator("xpbd")
    s.set_material("neo-hookean")
    s.set_param("youngs_modulus", 3e4)
    s.select_object("box")  # a rebuild from the scene keeps the world's material
    assert s.world.material.youngs_modulus == 3e4 and s.world.bodies[0].is_fem
    scene = deforma.scene.load(s.save(tmp_path / "fem.toml"))
    assert (scene.physics.material, scene.physics.youngs_modulus) == ("neo-hookean", 3e4)
    assert Session(tmp_path / "fem.toml").material_model == "neo-hookean"


# -- pins ----------------------------------------------------------------------------------------

def test_toggle_pin_pins_the_nearest_vertex_of_the_body_under_the_point():
    s = Session("sample")
    b = s.world.bodies[0]
    x = b.positions.copy()
    target = int(np.argmax(x[:, 1] - x[:, 0]))  # the top-left corner
    point = x[target] + (0.02, -0.02)  # just inside the body
    assert s.toggle_pin(point) == (0, target, True)
    assert b.pinned.sum() == 1 and b.pinned[target]
    for _ in range(60):
        s.world.step()
    np.testing.assert_array_equal(b.positions[target], x[target])
    assert s.toggle_pin(point) == (0, target, False)  # again: free
    assert not b.pinned.any()
    assert s.toggle_pin((50.0, 50.0)) is None  # nothing there
    outside = x[target] + (-0.05, 0.05)  # just off the outline: found within the radius only
    assert s.toggle_pin(outside) is None
    assert s.toggle_pin(outside, radius=0.1) == (0, target, True)


def test_unpin_all_and_pins_survive_reset_and_save(tmp_path):
    s = Session("jelly")
    for k, body in enumerate(s.world.bodies):
        s.toggle_pin(body.center_of_mass)
    pinned = [b.pinned.copy() for b in s.world.bodies]
    assert all(p.sum() == 1 for p in pinned)
    s.reset()  # a rebuild from the scene: pins are part of it
    assert all(np.array_equal(b.pinned, p) for b, p in zip(s.world.bodies, pinned))
    world = deforma.load_scene(s.save(tmp_path / "pins.toml"))
    assert all(np.array_equal(b.pinned, p) for b, p in zip(world.bodies, pinned))
    assert s.unpin_all() == 3
    assert not any(b.pinned.any() for b in s.world.bodies)
    assert s.unpin_all() == 0


def test_a_mesh_change_keeps_a_pin_box_that_still_holds_vertices_and_clears_vertex_pins(tmp_path):
    p = tmp_path / "hang.toml"
    p.write_text("[[body]]\nshape = 'box'\ndetail = 4\nposition = [0, 3]\npin = [[-1, 3.45], [1, 3.55]]\n")
    s = Session(p)
    top = s.world.bodies[0].pinned.sum()
    assert top > 0
    s.set_param("detail", 6)
    b = s.world.bodies[0]
    assert b.pinned.sum() > top and np.allclose(b.positions[b.pinned, 1], 3.5)  # the new top edge
    s.unpin_all()
    s.toggle_pin(b.center_of_mass)
    s.set_param("detail", 3)
    assert not s.world.bodies[0].pinned.any() and "pins cleared" in s.note


def test_objects_are_the_builtin_textures_and_box():
    from deforma.mesh.image import builtin_textures

    assert set(OBJECTS) == set(builtin_textures()) | {"box"} and OBJECTS[-1] == "box"


def test_rebuilding_an_image_body_keeps_its_background_and_threshold():
    scene = deforma.scene.Scene(body=(ImageBody(source="donut", resolution=16, edge_step=8, scale=0.004,
                                                background="auto", threshold=0.2, position=(0.0, 2.0)),))
    s = Session(scene)
    s.set_param("resolution", 12)
    spec = s.body_spec
    assert spec.resolution == 12 and (spec.background, spec.threshold) == ("auto", 0.2)
    s.select_object("bunny")  # another picture: its own default cut
    assert (s.body_spec.background, s.body_spec.threshold) == ("black", None)


# -- material behaviours and gas pressure ----------------------------------------------------------

BEHAVIOUR_VALUES = {"tear_strain": 0.4, "yield_strain": 0.05, "plastic_rate": 0.5, "max_stretch": 1.1}


def test_behaviours_and_pressure_apply_to_the_running_world_and_are_saved(tmp_path):
    s = Session("balloon")
    world, b = s.world, s.world.bodies[0]
    assert [s.get_param(n) for n in (*BEHAVIOUR_VALUES, "pressure")] == [None, None, 1.0, None, 25.0]
    for name, value in BEHAVIOUR_VALUES.items():
        s.set_param(name, value)
    s.set_param("pressure", 250.0)
    assert s.world is world and world.bodies[0] is b  # no rebuild, the state kept
    assert world.material == deforma.Material("springs", **BEHAVIOUR_VALUES) and b.pressure == 250.0
    assert [s.get_param(n) for n in (*BEHAVIOUR_VALUES, "pressure")] == [*BEHAVIOUR_VALUES.values(), 250.0]
    scene = deforma.scene.load(s.save(tmp_path / "behaviours.toml"))  # what Ctrl+S writes
    assert {k: getattr(scene.physics, k) for k in BEHAVIOUR_VALUES} == BEHAVIOUR_VALUES
    assert scene.body[0].pressure == 250.0
    again = Session(tmp_path / "behaviours.toml")
    assert [again.get_param(n) for n in (*BEHAVIOUR_VALUES, "pressure")] == [*BEHAVIOUR_VALUES.values(), 250.0]
    s.select_object("donut")  # a mesh change rebuilds from the scene and keeps them
    assert s.world.material == deforma.Material("springs", **BEHAVIOUR_VALUES)
    assert s.world.bodies[0].pressure == 250.0


def test_none_turns_a_behaviour_and_the_gas_off():
    s = Session("tear")
    assert s.get_param("tear_strain") == 0.3
    s.set_param("tear_strain", None)
    assert s.world.material is None and s.get_param("tear_strain") is None  # the seed's plain springs again
    s.set_param("pressure", 100.0)
    s.set_param("pressure", None)
    assert s.world.bodies[0].pressure is None and s.get_param("pressure") is None
    assert parse_value(PARAMS["max_stretch"], " ") is None and parse_value(PARAMS["pressure"], "Off") is None
    with pytest.raises(ValueError, match="Plastic rate must be a number"):
        parse_value(PARAMS["plastic_rate"], "")  # not optional: it always has a value


def test_refused_behaviour_shows_the_materials_own_message():
    s = Session("dent")
    before = s.world.material
    with pytest.raises(ValueError, match=r"max_stretch must be a stretch ratio in \(1, 100\]"):
        s.set_param("max_stretch", 0.9)
    with pytest.raises(ValueError, match=r"yield_strain must be a strain in \(0, 100\]"):
        s.set_param("yield_strain", 200.0)
    assert s.world.material is before


def test_model_and_elastic_values_keep_the_behaviours():
    s = Session("dent")
    s.set_integrator("xpbd")
    assert s.world.material.model == "corotated" and s.world.material.yield_strain == 0.03
    s.set_param("youngs_modulus", 2e4)
    assert (s.world.material.youngs_modulus, s.world.material.yield_strain) == (2e4, 0.03)
    s.set_material("springs")
    assert s.world.material == deforma.Material("springs", yield_strain=0.03)
    s.set_material("neo-hookean")
    assert (s.world.material.model, s.world.material.yield_strain) == ("neo-hookean", 0.03)


def test_a_body_with_its_own_material_gets_the_behaviour_itself(tmp_path):
    scene = seed("sample")
    scene = dataclasses.replace(scene, body=(dataclasses.replace(scene.body[0], material="springs", tear_strain=0.5),
                                             *scene.body[1:]))
    s = Session(scene)
    assert s.world.material is None and s.get_param("tear_strain") == 0.5
    s.set_param("tear_strain", 0.8)
    assert s.world.material is None and s.world.bodies[0].material.tear_strain == 0.8
    assert deforma.scene.load(s.save(tmp_path / "own.toml")).body[0].tear_strain == 0.8


def test_pressure_on_an_open_outline_is_refused_and_changes_nothing():
    s = Session(seed("sample"))
    chain = type("Chain", (), {"vertices": np.array([[5.0, 5.0], [6.0, 5.0], [7.0, 5.0]]),
                               "edges": np.array([[0, 1], [1, 2]])})()
    s.world.add_body(chain)
    s.select_body(len(s.world.bodies) - 1)
    before = s.scene
    with pytest.raises(ValueError) as e:
        s.set_param("pressure", 100.0)
    assert "\n" not in str(e.value) and "outline" in str(e.value)
    assert s.get_param("pressure") is None and s.scene == before


def test_a_plane_strain_world_keeps_its_plane_through_the_panel(tmp_path):
    p = tmp_path / "strain.toml"
    p.write_text('[physics]\nmaterial = "corotated"\nyoungs_modulus = 2e4\npoisson_ratio = 0.3\ndensity = 2.0\n'
                 'plane = "strain"\n[[body]]\ndetail = 3\nposition = [0, 2]\n')
    s = Session(str(p))
    s.set_param("youngs_modulus", 3e4)
    assert s.world.material.plane == "strain" and s.world.material.youngs_modulus == 3e4
    s.set_material("neo-hookean")
    assert s.world.material.plane == "strain"
    assert deforma.load_scene(s.save(tmp_path / "again.toml")).material.plane == "strain"


def test_a_spring_value_set_on_a_finite_element_scene_is_noted_in_the_panel():
    s = Session("demo")
    s.set_param("stiffness", 3000.0)
    assert s.note_is_warning and s.note.startswith("world.stiffness changes no body: body 0 (neo-hookean)")


def test_two_clicks_hinge_a_rigid_body_to_another_or_to_the_world():
    s = Session("chain")
    world = s.world
    n = len(world.joints)
    crate = world.bodies[-1]
    corner = crate.positions[np.argmax(crate.positions[:, 0] + crate.positions[:, 1])] - 0.02
    j = s.join(corner, (50.0, 50.0))  # the second click off every body: the world
    assert j.a is crate and j.b is None and len(world.joints) == n + 1
    link = world.bodies[0].center_of_mass
    k = s.join(crate.center_of_mass, link)
    assert k.a is crate and k.b is world.bodies[0]
    with pytest.raises(ValueError, match="no body under the first click"):
        s.join((50.0, 50.0), link)
    s.reset()  # the scene of the world as it is: its joints too
    assert len(s.world.joints) == n + 2


def test_the_join_key_is_listed():
    from deforma.viewer.controls import KEYS

    assert any(action == "join" for _names, action, _text in KEYS)


def test_the_arrow_keys_drive_every_motor_and_wake_a_sleeping_car():
    s = Session("car")
    w = s.world
    motors = [j for j in w.joints if j.motor_speed is not None]
    assert len(motors) == 2 and all(j.motor_speed == -300.0 for j in motors)
    assert s.drive(-1) == "driving back: 2 motors at 300 degrees/s"
    assert [j.motor_speed for j in motors] == [300.0, 300.0]
    assert s.drive(0) == "braking: 2 motors at no spin" and [j.motor_speed for j in motors] == [0.0, 0.0]
    assert s.drive(1) == "driving forward: 2 motors at 300 degrees/s"  # the speed it was first driven at
    assert [j.motor_speed for j in motors] == [-300.0, -300.0]
    w.sleep = True
    w.step()  # (its islands: the car's bodies, held together by their joints)
    for b in w.bodies:
        b.sleeping = True
    s.drive(-1)
    assert not any(b.sleeping for b in w.bodies)  # a motor's change wakes what it turns
    assert Session("jelly").drive(1).startswith("no motor to drive")

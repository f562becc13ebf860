"""The viewer's model without a window: parameters, mesh rebuilds, colliders, save/load."""

import numpy as np
import pytest

import deforma
from deforma.scene import BoxBody, ImageBody
from deforma.viewer.params import GROUPS, PARAMS, parse_value
from deforma.viewer.session import OBJECTS, Session


def test_every_original_inspector_value_is_a_parameter():
    names = set(PARAMS)
    assert {"detail", "edges", "scale", "resolution", "detect_edges", "edge_step", "dt", "gravity_x", "gravity_y",
            "damping", "mass", "stiffness", "static_friction", "friction", "explosive_force", "collider_x",
            "collider_y", "collider_width", "collider_height", "collider_angle", "mouse_strength"} <= names
    assert [g for g, _ in GROUPS] == ["Square", "Texture", "Physics", "Contact", "Collision", "Mouse"]
    s = Session("demo")
    for name in names:  # every parameter reads back from a live session
        assert s.get_param(name) is not None


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
                                         ("contact_thickness", 1.0)])
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
    s = Session("demo")
    world = s.world
    assert s.integrator == "symplectic-euler"
    s.set_integrator("implicit-euler")
    assert s.world is world and world.integrator == "implicit-euler" and s.note == ""
    for _ in range(30):  # the switched world keeps stepping
        world.step()
    assert np.isfinite(world.bodies[0].positions).all()
    path = s.save(tmp_path / "implicit.toml")
    assert deforma.load_scene(path).integrator == "implicit-euler"


def test_unknown_integrator_is_refused_with_the_names():
    s = Session("demo")
    with pytest.raises(ValueError, match="integrator must be one of .*xpbd.*got 'rk4'"):
        s.set_integrator("rk4")
    assert s.world.integrator == "symplectic-euler"


def test_switching_to_the_explicit_method_with_stiff_springs_warns():
    s = Session("demo")
    s.set_integrator("xpbd")
    s.set_param("stiffness", 1e6)
    s.set_integrator("symplectic-euler")
    assert "exceeds the explicit stable estimate" in s.note and "\n" not in s.note

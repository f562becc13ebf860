"""Scene files with material behaviours (tear_strain, yield_strain, plastic_rate, max_stretch)
and gas pressure: what they build, what they refuse, and round trips."""

import pytest

import deforma
from deforma import scene as scenes
from deforma.scene.schema import BEHAVIOUR_KEYS, MATERIAL_KEYS
from scene_checks import assert_refused, write


def test_behaviours_are_material_keys_and_material_keywords():
    assert set(BEHAVIOUR_KEYS) <= set(MATERIAL_KEYS)
    m = deforma.Material("springs", **{k: 1.5 if k != "plastic_rate" else 0.5 for k in BEHAVIOUR_KEYS})
    assert [getattr(m, k) for k in BEHAVIOUR_KEYS] == [1.5, 1.5, 0.5, 1.5]


def test_physics_behaviours_give_a_springs_world_its_material(tmp_path):
    w = scenes.load_scene(write(tmp_path, """
        [physics]
        tear_strain = 0.6
        max_stretch = 1.3
        [[body]]
        detail = 2
    """))
    assert w.material == deforma.Material("springs", tear_strain=0.6, max_stretch=1.3)
    assert w.bodies[0].material == w.material


def test_a_body_takes_behaviours_it_leaves_out_from_physics(tmp_path):
    w = scenes.load_scene(write(tmp_path, """
        [physics]
        material = "corotated"
        youngs_modulus = 2e4
        poisson_ratio = 0.3
        density = 2.0
        yield_strain = 0.05
        [[body]]
        detail = 2
        plastic_rate = 0.25
        tear_strain = 2.0
    """))
    m = w.bodies[0].material
    assert (m.model, m.youngs_modulus, m.yield_strain, m.plastic_rate, m.tear_strain, m.max_stretch) == \
        ("corotated", 2e4, 0.05, 0.25, 2.0, None)
    assert w.material.yield_strain == 0.05 and w.material.tear_strain is None


def test_springs_switch_keeps_the_behaviours(tmp_path):
    s = scenes.with_springs(scenes.load(write(tmp_path, """
        [physics]
        material = "neo-hookean"
        youngs_modulus = 2e4
        poisson_ratio = 0.3
        density = 2.0
        [[body]]
        detail = 2
        material = "corotated"
        tear_strain = 0.5
    """)))
    (b,) = s.build().bodies
    assert b.material == deforma.Material("springs", tear_strain=0.5)


def test_pressure_fills_the_body(tmp_path):
    w = scenes.load_scene(write(tmp_path, """
        [[body]]
        detail = 3
        pressure = 250.0
        [[body]]
        detail = 3
        position = [3, 0]
    """))
    assert [b.pressure for b in w.bodies] == [250.0, None]


@pytest.mark.parametrize("text, message", [
    ("[physics]\ntear_strain = 0\n", "physics.tear_strain: must be in (0, 100], got 0"),
    ("[physics]\nmax_stretch = 1.0\n", "physics.max_stretch: must be in (1, 100], got 1"),
    ("[physics]\nplastic_rate = 1.5\n", "physics.plastic_rate: must be in (0, 1], got 1.5"),
    ("[[body]]\nyield_strain = -0.1\n", "body[0].yield_strain: must be in (0, 100], got -0.1"),
    ("[[body]]\nmax_stretch = \"x\"\n", "body[0].max_stretch: expected a number, got string 'x'"),
    ("[[body]]\npressure = -1.0\n", "body[0].pressure: must be in [0, 1e+12] N/m, got -1"),
    ("[[body]]\npressure = nan\n", "body[0].pressure: expected a finite number"),
    ("[[body]]\npresure = 1.0\n", "body[0].presure: unknown key; did you mean 'pressure'?"),
])
def test_bad_behaviour_and_pressure_keys_give_one_line_naming_the_key(tmp_path, text, message):
    assert_refused(write(tmp_path, text), message)


def saved(world, tmp_path, name="saved.toml"):
    return scenes.load(deforma.save_scene(world, tmp_path / name))


def test_behaviours_and_pressure_round_trip_unchanged(tmp_path):
    p = write(tmp_path, """
        [physics]
        yield_strain = 0.2
        plastic_rate = 0.5
        [[body]]
        detail = 3
        tear_strain = 0.8
        max_stretch = 1.5
        pressure = 120.0
        [[collider]]
        center = [0, -2]
    """)
    s = scenes.load(p)
    again = saved(scenes.build(s), tmp_path)
    assert again.physics == s.physics and again.body == s.body


def test_live_behaviours_and_pressure_are_saved(tmp_path):
    w = scenes.load_scene(write(tmp_path, "[[body]]\ndetail = 3\n[[body]]\ndetail = 3\nposition = [3, 0]\n"))
    w.material = deforma.Material("springs", max_stretch=1.2)
    a, b = w.bodies
    a.material = deforma.Material("corotated", youngs_modulus=1e4, poisson_ratio=0.3, density=1.0,
                                  tear_strain=0.4, max_stretch=1.2)
    a.pressure = 80.0
    w2 = scenes.build(saved(w, tmp_path))
    assert w2.material == w.material
    assert [x.material for x in w2.bodies] == [a.material, b.material]
    assert [x.pressure for x in w2.bodies] == [80.0, None]


def test_a_scene_body_that_tore_is_saved_from_its_recipe(tmp_path):
    w = scenes.load_scene(write(tmp_path, """
        [physics]
        gravity = [0, 0]
        tear_strain = 0.3
        [[body]]
        detail = 4
        pin = [[-0.6, -0.6], [-0.4, 0.6]]
    """))
    (b,) = w.bodies
    n = b.n_vertices
    g = w.grab((0.5, 0.0), radius=0.2, strength=5e3)
    w.drag(g, (3.0, 0.0))
    for _ in range(600):
        w.step()
        if b.n_vertices > n:
            break
    assert b.n_vertices > n
    s = saved(w, tmp_path)
    assert s.body[0].shape == "box" and s.body[0].pin is not None and s.body[0].pin_vertices is None
    assert scenes.build(s).bodies[0].n_vertices == n

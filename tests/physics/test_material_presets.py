"""Material presets: Material.preset(name, **overrides) and material = "<preset>" in scene files.

Each preset is checked against the textbook sag of a block standing under its own weight
(uniaxial, plane stress: it shortens by density * g * H / (2 E) of its height) and against
the others where the docs say they differ (rubber bounces, gummy and foam land with a thud).
"""

import warnings

import numpy as np
import pytest

import deforma
from deforma import scene as scenes
from deforma.physics.material import PRESETS

SIZE = 0.5


def block(material, drop=0.0, integrator="symplectic-euler"):
    """A 0.5 m block (detail 8) on a floor, ``drop`` m above it, under the default World."""
    w = deforma.World(dt=1 / 600, material=material, integrator=integrator)
    w.add_collider(deforma.Rect((0.0, -0.25), (4.0, 0.5), 0.0))
    h = SIZE / 2
    b = w.add_body(deforma.mesh.box(((-h, -h), (h, -h), (h, h), (-h, h)), detail=8), position=(0.0, h + drop + 1e-6))
    return w, b


def test_every_preset_is_a_valid_finite_element_material():
    assert list(PRESETS) == ["jelly", "gummy", "rubber", "foam", "wood", "cloth"]
    for name in PRESETS:
        m = deforma.Material.preset(name)
        assert m.is_fem and m.youngs_modulus > 0 and m.density > 0
    assert deforma.Material.preset("cloth").max_stretch == 1.05


@pytest.mark.parametrize("name", ["jelly", "gummy", "rubber", "foam"])
def test_a_preset_block_sags_by_its_textbook_share(name):
    m = deforma.Material.preset(name)
    w, b = block(m, integrator="implicit-euler")
    w.solve_static()
    sag = 1.0 - np.ptp(b.positions[:, 1]) / SIZE
    textbook = m.density * 9.81 * SIZE / (2.0 * m.youngs_modulus)  # rubber 0.13%, jelly 8.6%
    # the linear triangle, the floor's friction at the base and (jelly) a large strain: within 20%
    assert sag == pytest.approx(textbook, rel=0.2), (sag, textbook)


def _bounce(name):
    """How high the block's centre rises after landing from 0.5 m, as a share of the drop."""
    w, b = block(deforma.Material.preset(name))
    w.solve_static()
    resting = b.positions[:, 1].mean()
    w, b = block(deforma.Material.preset(name), drop=0.5)
    centres = []
    for _ in range(round(1.5 / w.dt)):
        w.step()
        centres.append(b.positions[:, 1].mean())
    centres = np.array(centres)
    landed = int(np.argmax(centres - resting < 0.01))
    low = landed + int(np.argmin(centres[landed:landed + 60]))
    return (centres[low:].max() - resting) / 0.5


def test_rubber_bounces_and_gummy_and_foam_land_with_a_thud():
    rubber, gummy, foam = _bounce("rubber"), _bounce("gummy"), _bounce("foam")
    assert rubber > 0.3  # measured 45% of the drop
    assert gummy < 0.5 * rubber and foam < 0.5 * rubber, (rubber, gummy, foam)


def test_overrides_replace_the_preset_values_and_are_checked():
    m = deforma.Material.preset("jelly", density=500.0, tear_strain=0.5)
    assert (m.model, m.youngs_modulus, m.density, m.tear_strain) == ("neo-hookean", 3e4, 500.0, 0.5)
    assert deforma.Material.preset("rubber", model="corotated").model == "corotated"
    with pytest.raises(ValueError, match=r"poisson_ratio must be in \(-1, 0.5\)"):
        deforma.Material.preset("jelly", poisson_ratio=0.7)


@pytest.mark.parametrize("call, message", [
    (lambda: deforma.Material.preset("jely"), r"unknown material preset 'jely': did you mean 'jelly'\? \(presets: "
                                               r"jelly, gummy, rubber, foam, wood, cloth\)"),
    (lambda: deforma.Material.preset(3), r"unknown material preset 3: \(presets: jelly"),
    (lambda: deforma.Material.preset("foam", densty=1.0), r"Material.preset\('foam'\) takes no 'densty': did you "
                                                          r"mean 'density'\?"),
])
def test_bad_preset_calls_are_one_line_errors(call, message):
    with pytest.raises(ValueError, match=message) as e:
        call()
    assert "\n" not in str(e.value)


SCENE = """
[physics]
material = "{world}"
{extra}
[[body]]
shape = "box"
corners = [[-0.25, -0.25], [0.25, -0.25], [0.25, 0.25], [-0.25, 0.25]]
detail = 4
position = [0.0, 1.0]
{body}
[[collider]]
center = [0.0, 0.0]
size = [4.0, 0.5]
"""


def _material(tmp_path, world="springs", extra="", body=""):
    p = tmp_path / "s.toml"
    p.write_text(SCENE.format(world=world, extra=extra, body=body))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        w = scenes.load(p).build()
    return w.bodies[0].material


def test_scene_files_name_presets_and_keys_beside_them_replace_its_values(tmp_path):
    assert _material(tmp_path, "jelly") == deforma.Material.preset("jelly")
    assert _material(tmp_path, body='material = "rubber"') == deforma.Material.preset("rubber")
    # a body's own key replaces its preset's value; the world's keys do not reach a body's preset
    own = _material(tmp_path, "corotated", "youngs_modulus = 1e5\npoisson_ratio = 0.3\ndensity = 10.0",
                    'material = "foam"\ndensity = 50.0')
    assert own == deforma.Material.preset("foam", density=50.0)
    # the world's keys replace the world's preset
    assert _material(tmp_path, "cloth", "youngs_modulus = 300.0") == deforma.Material.preset("cloth",
                                                                                             youngs_modulus=300.0)


def test_an_unknown_preset_in_a_scene_file_names_the_key_and_the_closest(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text(SCENE.format(world="springs", extra="", body='material = "rubbr"'))
    with pytest.raises(scenes.SceneError, match=r"body\[0\]\.material: unknown value 'rubbr'; did you mean 'rubber'\?"):
        scenes.load(p)

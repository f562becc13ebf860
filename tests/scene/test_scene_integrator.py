"""The ``integrator`` key of scene files: every registered name loads, runs and round-trips."""

import numpy as np
import pytest

from deforma import scene as scenes
from deforma.physics import available_integrators
from deforma.scene import SceneError

SCENE = """
[physics]
dt = 0.0166667
stiffness = 2000.0
integrator = "{name}"

[[body]]
shape = "box"
corners = [[-0.5, -0.25], [0.5, -0.25], [0.5, 0.25], [-0.5, 0.25]]
detail = 3
position = [0.0, 0.3]

[[collider]]
center = [0.0, -0.25]
size = [4.0, 0.5]
"""


@pytest.mark.parametrize("name", ["symplectic-euler", "implicit-euler", "xpbd"])
def test_integrator_from_a_scene_file_runs_and_round_trips(tmp_path, name):
    p = tmp_path / "s.toml"
    p.write_text(SCENE.format(name=name))
    if name == "symplectic-euler":
        p.write_text(SCENE.format(name=name).replace("dt = 0.0166667", "dt = 0.0005"))
    world = scenes.load_scene(p)
    assert world.integrator == name
    for _ in range(30):
        world.step()
    assert np.isfinite(world.bodies[0].positions).all()
    out = scenes.save_scene(world, tmp_path / "back.toml")
    assert scenes.load_scene(out).integrator == name


def test_unknown_integrator_lists_every_registered_name(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text(SCENE.format(name="implicit"))
    with pytest.raises(SceneError) as e:
        scenes.load_scene(p)
    msg = str(e.value)
    assert "physics.integrator: unknown value 'implicit'; did you mean 'implicit-euler' or 'implicit-bdf2'?" in msg
    for name in available_integrators():
        assert name in msg

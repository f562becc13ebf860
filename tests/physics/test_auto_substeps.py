"""substeps = "auto" under symplectic Euler, and the warning add_body gives when the step is
beyond the explicit limit: the README's bunny, which the default World (then one substep) blew up at
step 9."""

import math
import warnings

import numpy as np
import pytest

import deforma
from deforma.physics import SimulationUnstable


def bunny():
    return deforma.mesh.from_image("bunny", resolution=4, detect_edges=True, edge_step=2, scale=0.01)


def test_the_readme_bunny_runs_under_symplectic_euler_with_auto_substeps():
    w = deforma.World(dt=1 / 600, integrator="symplectic-euler")  # substeps = "auto" by default
    w.add_collider(deforma.Rect((0.0, -0.25), (6.0, 0.5), 0.0))
    m = bunny()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing to warn about
        b = w.add_body(m, position=(0.0, np.ptp(m.vertices[:, 1]) / 2 + 0.2))  # 20 cm above the floor
    assert w.auto_substeps and w.substeps == math.ceil(w.dt / w.stable_dt()) == 40
    for _ in range(1200):  # 2 s: landed
        w.step()
    landed = w.energy().total
    for _ in range(4800):  # 8 s more: the soft bunny sways on (its springs barely damp), and no
        w.step()           # energy comes from nowhere
    assert np.isfinite(b.positions).all() and w.energy().total <= landed * 1.001


def test_one_substep_beyond_the_limit_warns_at_add_body():
    w = deforma.World(dt=1 / 600, integrator="symplectic-euler", substeps=1)
    with pytest.warns(RuntimeWarning, match=r"exceeds the stable estimate .* set substeps = 40 \(or \"auto\"\)"):
        w.add_body(bunny())
    # "auto" would need 2380 substeps: said at once, in one line
    w = deforma.World(integrator="symplectic-euler", dt=0.1)
    with pytest.warns(RuntimeWarning, match=r"would need 2375 substeps .* more than 1000") as caught:
        w.add_body(bunny())
    assert "\n" not in str(caught[0].message)
    with pytest.raises(SimulationUnstable, match="more than 1000"):
        w.step()
    assert w.step_count == 0


def test_auto_follows_the_bodies_and_the_integrator():
    w = deforma.World(integrator="symplectic-euler", dt=1 / 60, stiffness=2000.0, substeps="auto")
    assert w.substeps == 1  # no body
    w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=4), position=(0, 3))
    w.step()
    first = w.substeps
    assert first == math.ceil(w.dt / w.stable_dt()) > 1
    w.stiffness = 8000.0  # four times stiffer: twice the frequency
    w.step()
    assert w.substeps == math.ceil(w.dt / w.stable_dt()) > first
    w.integrator = "implicit-euler"
    w.step()
    assert w.substeps == 1 and w.auto_substeps
    w.substeps = 3  # a number turns auto off
    assert not w.auto_substeps and w.substeps == 3


def test_auto_past_1000_substeps_is_refused_in_one_line_and_changes_nothing():
    w = deforma.World(integrator="symplectic-euler", dt=0.1, substeps=1)  # the bunny needs 2375 substeps of it
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        w.add_body(bunny())
    with pytest.raises(ValueError) as e:
        w.substeps = "auto"
    text = str(e.value)
    assert "\n" not in text and "more than 1000" in text and 'integrator="implicit-euler"' in text
    assert w.substeps == 1 and not w.auto_substeps
    # set while it was fine, then made stiffer: the step says so and changes nothing
    w = deforma.World(integrator="symplectic-euler", dt=0.05, stiffness=100.0, substeps="auto", gravity=(0.0, 0.0))
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=4), position=(0, 3))
    w.step()
    before = b.positions.copy()
    w.stiffness = 1e9
    with pytest.raises(SimulationUnstable, match="more than 1000"):
        w.step()
    assert np.array_equal(b.positions, before) and w.step_count == 1


def test_no_warning_when_the_step_is_within_the_limit_or_the_integrator_is_stable():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        deforma.World(integrator="implicit-euler").add_body(bunny())
        deforma.World(dt=1e-5).add_body(bunny())


@pytest.mark.parametrize("value", ["fast", 0, 1001, 2.5, True])
def test_bad_substeps_are_one_line(value):
    w = deforma.World()
    with pytest.raises(ValueError, match=r"^substeps must be an integer in \[1, 1000\] .* or \"auto\", got "):
        w.substeps = value
    assert w.substeps == 1


def test_a_scene_file_takes_auto_and_writes_it_back(tmp_path):
    p = tmp_path / "auto.toml"
    p.write_text('[physics]\nintegrator = "symplectic-euler"\ndt = 0.016666666666666666\nsubsteps = "auto"\n'
                 'stiffness = 2000.0\n'
                 '[[body]]\nshape = "box"\ncorners = [[-0.5, 0], [0.5, 0], [0.5, 1], [-0.5, 1]]\ndetail = 4\n')
    w = deforma.load_scene(p)
    assert w.auto_substeps and w.substeps == math.ceil(w.dt / w.stable_dt())
    w.step()
    out = tmp_path / "again.toml"
    deforma.save_scene(w, out)
    assert 'substeps = "auto"' in out.read_text() and deforma.load_scene(out).auto_substeps
    p.write_text('[physics]\nsubsteps = "many"\n')
    with pytest.raises(deforma.scene.SceneError, match=r'physics.substeps: expected an integer in \[1, 1000\] or '
                                                       r'"auto", got string \'many\''):
        deforma.load_scene(p)

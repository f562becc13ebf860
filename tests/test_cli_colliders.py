"""`deforma run --states`: the archive describes every collider shape, its pose per frame and at
the end (docs/cli.md)."""

import numpy as np

import deforma
from deforma.cli import main

SCENE = """
[run]
seconds = 0.3
fps = 10

[physics]
dt = 0.01
integrator = "implicit-euler"

[[body]]
corners = [[-0.25, -0.25], [0.25, -0.25], [0.25, 0.25], [-0.25, 0.25]]
detail = 2
position = [0.0, 2.0]

[[collider]]
center = [0.0, -0.2]
size = [8.0, 0.4]
angle = 5.0

[[collider]]
shape = "circle"
center = [2.0, 1.0]
radius = 0.3
angular_velocity = 90.0

[[collider]]
shape = "segment"
a = [-3.0, 1.0]
b = [-2.0, 1.0]
radius = 0.05
velocity = [1.0, 0.0]

[[collider]]
shape = "polygon"
points = [[3.0, 0.0], [4.0, 0.0], [3.5, 1.0]]

[[collider]]
shape = "image"
source = "donut"
scale = 0.004
position = [-5.0, 3.0]
"""


def test_states_describe_every_collider_shape(tmp_path, capsys):
    scene = tmp_path / "shapes.toml"
    scene.write_text(SCENE)
    states = tmp_path / "s.npz"
    assert main(["run", str(scene), "--states", str(states), "--quiet"]) == 0, capsys.readouterr().err
    d = np.load(states)  # no pickles: every array is plain
    world = deforma.load_scene(scene)
    k = len(world.colliders)
    assert k == 5
    assert d["collider_kind"].tolist() == ["rect", "circle", "segment", "polygon", "polygon"]
    # the rect row keeps its meaning: cx, cy, w, h, angle
    np.testing.assert_allclose(d["colliders"][0], [0.0, -0.2, 8.0, 0.4, 5.0])
    np.testing.assert_allclose(d["colliders"][1, 2:4], [0.6, 0.6])  # a circle's box: 2r x 2r
    np.testing.assert_allclose(d["colliders"][2, 2:4], [1.1, 0.1])  # a capsule's: length + 2r x 2r
    np.testing.assert_allclose(d["collider_radius"][:3], [np.nan, 0.3, 0.05])
    np.testing.assert_allclose(d["collider_velocity"][2], [1.0, 0.0])
    np.testing.assert_allclose(d["collider_angular_velocity"], [0, 90, 0, 0, 0])
    # outlines: NaN after each collider's last point; the triangle's three corners
    outline = d["collider_outline"]
    assert outline.shape[0] == k and outline.shape[2] == 2
    tri = outline[3][~np.isnan(outline[3, :, 0])]
    assert len(tri) == 3 and {tuple(p) for p in tri.round(9).tolist()} == {(3.0, 0.0), (4.0, 0.0), (3.5, 1.0)}
    assert (~np.isnan(outline[0, :, 0])).sum() == 4
    # the donut's hole comes along
    assert d["collider4_holes"].shape[0] == 1 and "collider3_holes" not in d
    # poses per frame: the segment travels at 1 m/s, the circle turns at 90 degrees/s
    pose = d["collider_pose"]
    assert pose.shape == (3, k, 3)
    np.testing.assert_allclose(pose[:, 2, 0] - pose[0, 2, 0], d["time"] - d["time"][0], atol=1e-9)
    np.testing.assert_allclose(pose[:, 1, 2], 90.0 * d["time"], atol=1e-9)
    # and the end pose is the last frame's
    np.testing.assert_allclose(d["colliders"][:, [0, 1, 4]], pose[-1])

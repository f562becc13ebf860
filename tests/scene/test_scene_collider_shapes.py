"""[[collider]] shapes in scene files: every shape loads, builds the right collider, saves and
loads back the same; keys of another shape and missing keys are one-line errors with the key
path; an image collider is its picture's polygons; the playground scene keeps bodies out."""

import numpy as np
import pytest
from PIL import Image

import deforma
from deforma import scene as scenes
from deforma.scene.schema import (CircleCollider, ColliderSpec, ImageCollider, PolygonCollider, SceneError,
                                  SegmentCollider, parse_scene)

L_SHAPE = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
SHAPES = {
    "rect": ({"center": [0, -1], "size": [4, 0.5], "angle": 10, "velocity": [0.2, 0]}, deforma.Rect, ColliderSpec),
    "circle": ({"shape": "circle", "center": [1, 2], "radius": 0.5, "angular_velocity": 30}, deforma.Circle,
               CircleCollider),
    "polygon": ({"shape": "polygon", "points": L_SHAPE, "holes": [[[0.2, 0.2], [0.6, 0.2], [0.6, 0.6]]],
                 "angle": 15, "friction": 0.1}, deforma.Polygon, PolygonCollider),
    "segment": ({"shape": "segment", "a": [-1, 3], "b": [1, 3.5], "radius": 0.1, "angular_velocity": -90,
                 "static_friction": 0.9}, deforma.Segment, SegmentCollider),
    "image": ({"shape": "image", "source": "ramp", "position": [4, 1], "tolerance": 2.0}, deforma.Polygon,
              ImageCollider),
}


def scene_with(*colliders, color="#123456"):
    return parse_scene({"collider": [{**c, "color": color} for c in colliders]})


@pytest.mark.parametrize("shape", list(SHAPES))
def test_each_shape_loads_builds_and_round_trips(shape, tmp_path):
    table, cls, spec_cls = SHAPES[shape]
    s = scene_with(table)
    assert type(s.collider[0]) is spec_cls and s.collider[0].shape == shape
    w = s.build()
    assert all(type(c) is cls for c in w.colliders) and w.colliders
    c = w.colliders[0]
    if shape != "image":
        assert c.velocity == tuple(map(float, table.get("velocity", (0, 0))))
        assert c.angular_velocity == table.get("angular_velocity", 0)
    path = deforma.save_scene(w, tmp_path / "s.toml")
    again = scenes.load(path)
    # an image is saved as its polygons, each with the image's colour
    want = "polygon" if shape == "image" else shape
    assert [x.shape for x in again.collider] == [want] * len(w.colliders)
    assert all(x.color == "#123456" for x in again.collider)
    w2 = again.build()
    for a, b in zip(w.colliders, w2.colliders):
        assert type(a) is type(b)
        np.testing.assert_allclose(a.outline(), b.outline(), atol=1e-8)
        assert (a.velocity, a.angular_velocity, a.friction, a.static_friction) == \
               (b.velocity, b.angular_velocity, b.friction, b.static_friction)
    # and once more: what was loaded writes the same file
    assert scenes.scene_of(w2).collider == again.collider


def test_a_file_without_shape_is_still_a_rect():
    s = parse_scene({"collider": [{"center": [1, 2], "size": [3, 0.5], "angle": 5}]})
    assert s.collider[0] == ColliderSpec(center=(1.0, 2.0), size=(3.0, 0.5), angle=5.0)
    (r,) = s.build().colliders
    assert isinstance(r, deforma.Rect) and r.size == (3.0, 0.5)


def test_polygon_angle_turns_it_about_its_centroid():
    (p,) = scene_with({"shape": "polygon", "points": [[0, 0], [2, 0], [2, 2], [0, 2]], "angle": 90}).build().colliders
    assert p.center == (1.0, 1.0) and p.angle == 90
    np.testing.assert_allclose(sorted(map(tuple, p.points.round(9))), [(0, 0), (0, 2), (2, 0), (2, 2)], atol=1e-9)


def test_moving_colliders_are_saved_where_they_started_and_set_ones_where_they_were_put(tmp_path):
    s = scene_with({"shape": "segment", "a": [0, 0], "b": [2, 0], "angular_velocity": 45},
                   {"shape": "polygon", "points": L_SHAPE, "velocity": [1, 0], "angular_velocity": 30},
                   {"size": [1, 1], "angular_velocity": 720})
    w = s.build()
    start = [c.outline() for c in w.colliders]
    for _ in range(int(round(0.6 / w.dt))):
        w.step()
    assert not np.allclose(w.colliders[1].outline(), start[1])  # it moved
    spec = scenes.scene_of(w).collider
    assert spec[0] == s.collider[0] and spec[1] == s.collider[1]  # a scene is a setup: where they started
    w2 = scenes.load(deforma.save_scene(w, tmp_path / "moved.toml")).build()
    for a, b, s0 in zip(w.colliders, w2.colliders, start):
        np.testing.assert_allclose(b.outline(), s0, atol=1e-7)
        assert b.angular_velocity == a.angular_velocity and b.velocity == a.velocity
    w.colliders[2].angle = 432.0  # put there by hand (the viewer's keys): written so, within +-360
    w.colliders[1].center = (5.0, 5.0)
    spec = scenes.scene_of(w).collider
    assert spec[2].angle == pytest.approx(72.0)
    assert spec[1].angle == 0 and spec[1].points != s.collider[1].points  # the corners moved
    w3 = scenes.load(deforma.save_scene(w, tmp_path / "set.toml")).build()
    assert w3.colliders[1].center == pytest.approx((5.0, 5.0))


def test_colliders_made_in_code_are_written_by_their_shape(tmp_path):
    w = deforma.World()
    w.add_collider(deforma.Circle((0, 0), 1.0))
    w.add_collider(deforma.Segment((0, 2), (1, 2)))
    w.add_collider(deforma.Polygon([[3, 0], [4, 0], [3, 1]], velocity=(0, 0.5)))
    spec = scenes.scene_of(w).collider
    assert [c.shape for c in spec] == ["circle", "segment", "polygon"]
    assert spec[2].velocity == (0.0, 0.5) and spec[1].radius == 0.0
    w2 = scenes.load_scene(deforma.save_scene(w, tmp_path / "code.toml"))
    assert [type(c).__name__ for c in w2.colliders] == ["Circle", "Segment", "Polygon"]


def test_image_collider_from_a_picture_next_to_the_scene(tmp_path):
    picture = np.zeros((40, 100), np.uint8)
    picture[30:, :] = 255          # a floor
    picture[5:20, 10:30] = 255     # and a block floating over it
    Image.fromarray(picture).save(tmp_path / "level.png")
    (tmp_path / "level.toml").write_text('[[collider]]\nshape = "image"\nsource = "level.png"\nscale = 0.05\n'
                                         'color = "#aa5500"\n')
    s = scenes.load(tmp_path / "level.toml")
    assert s.collider[0].source == str((tmp_path / "level.png").resolve())
    w = s.build()
    assert len(w.colliders) == 2 and all(isinstance(c, deforma.Polygon) for c in w.colliders)
    assert sorted(round(c.area, 6) for c in w.colliders) == [0.75, 2.5]  # 20 x 15 px, 100 x 10 px at 5 cm
    # the picture's path is written relative to the file when the scene itself is saved
    out = tmp_path / "sub"
    out.mkdir()
    text = deforma.save_scene(s, out / "copy.toml").read_text()
    assert 'source = "../level.png"' in text
    assert scenes.load(out / "copy.toml") == s


def test_image_collider_from_a_builtin_texture_keeps_its_hole():
    (donut,) = scene_with({"shape": "image", "source": "donut", "scale": 0.005}).build().colliders
    assert len(donut.holes) == 1


@pytest.mark.parametrize("table, message", [
    ({"radius": 1.0}, 'collider[1].radius: not a field of shape "rect"; its fields: shape, center, size, angle, '),
    ({"shape": "circle", "size": [1, 1], "radius": 1}, 'collider[1].size: not a field of shape "circle"'),
    ({"shape": "segment", "a": [0, 0], "b": [1, 0], "points": [[0, 0]]},
     'collider[1].points: not a field of shape "segment"'),
    ({"shape": "polygon"}, 'collider[1].points: missing: a "polygon" collider needs points'),
    ({"shape": "circle"}, 'collider[1].radius: missing: a "circle" collider needs radius'),
    ({"shape": "segment", "a": [0, 0]}, 'collider[1].b: missing: a "segment" collider needs b'),
    ({"shape": "image"}, 'collider[1].source: missing: a "image" collider needs source'),
    ({"shape": "circel", "radius": 1}, "collider[1].shape: unknown value 'circel'; did you mean 'circle'? allowed: rect, circle, "
                                             "polygon, segment, image"),
    ({"shape": "circle", "radius": 0}, "collider[1].radius: must be in (0, 1e+09] m, got 0"),
    ({"shape": "polygon", "points": [[0, 0], [1, 0]]}, "collider[1].points: expected at least three points"),
    ({"shape": "polygon", "points": [[0, 0], [1, 0], [0, 1]], "holes": [[[0, 0], [1, 1]]]},
     "collider[1].holes[0]: expected at least three points"),
    ({"shape": "image", "source": "nowhere"}, "collider[1].source: unknown picture 'nowhere'; allowed: a built-in "
                                              "picture (bumps, ramp, armadillo, bunny, donut) or an image file"),
    ({"shape": "rect", "colour": "#ffffff"}, "collider[1].colour: unknown key; did you mean 'color'?"),
    ({"shape": "segment", "a": [0, 0], "b": [1, 0], "angular_velocity": 1e7},
     "collider[1].angular_velocity: must be in [-1e+06, 1e+06] degrees/s"),
])
def test_bad_collider_keys_are_one_line_errors_with_the_key_path(table, message):
    with pytest.raises(SceneError) as e:
        parse_scene({"collider": [{}, table]}, source="s.toml")
    text = str(e.value)
    assert "\n" not in text and text.startswith("s.toml: " + message), text


@pytest.mark.parametrize("table, message", [
    ({"shape": "polygon", "points": [[0, 0], [2, 2], [2, 0], [0, 1]]}, "collider[1]: a polygon must be simple"),
    # a bow-tie whose two halves cancel has no area, but its fault is the crossing
    ({"shape": "polygon", "points": [[0, 0], [1, 1], [1, 0], [0, 1]]}, "collider[1]: a polygon must be simple: edge 0 "
                                                                        "crosses edge 2"),
    ({"shape": "polygon", "points": [[0, 0], [1, 0], [2, 0]]}, "collider[1]: a polygon's points must enclose an area"),
    ({"shape": "image", "source": "ramp", "min_area": 1e308}, "collider[1]: min_area = 1e+308 square px drops every "
                                                              "piece of the picture"),
    ({"shape": "polygon", "points": [[0, 0], [1, 0], [0, 1]], "holes": [[[5, 5], [6, 5], [5, 6]]]},
     "collider[1]: holes[0] must lie inside the polygon"),
    ({"shape": "segment", "a": [1, 1], "b": [1, 1]}, "collider[1]: a segment of radius 0 needs two different ends"),
    ({"velocity": [1e5, 0]}, "collider[1]: velocity must be within +-10000 m/s"),
])
def test_colliders_the_constructors_refuse_are_one_line_build_errors(table, message, tmp_path):
    p = tmp_path / "s.toml"
    import tomli_w

    p.write_text(tomli_w.dumps({"collider": [{}, table]}))
    with pytest.raises(SceneError) as e:
        scenes.load_scene(p)
    text = str(e.value)
    assert "\n" not in text and f": {message}" in text, text


def test_playground_has_every_shape_and_keeps_bodies_out_of_the_colliders():
    s = scenes.load("playground")
    assert {c.shape for c in s.collider} == {"rect", "circle", "polygon", "segment", "image"}
    assert any(c.angular_velocity for c in s.collider)
    w = s.build()
    for _ in range(int(round(1.0 / w.dt))):
        w.step()
    for b in w.bodies:
        assert np.isfinite(b.positions).all()
        for c in w.colliders:
            assert not c.contains(b.positions).any(), c
    # the rollers carried their box to the right, the paddle turned
    assert w.bodies[2].center_of_mass[0] > -0.3 + 0.1
    assert w.colliders[1].angle == pytest.approx(-90.0 * w.time)

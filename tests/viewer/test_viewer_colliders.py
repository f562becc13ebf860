"""Colliders of every shape in the viewer: added, edited, turned and removed, in the session
and through the panel and keys of the real (off-screen) window."""

import numpy as np
import pygame
import pygame_gui
import pytest

from deforma.viewer.app import SELECTED_COLLIDER_COLOR
from deforma.viewer.session import COLLIDER_FIELDS, COLLIDER_SHAPES, Session
from seed_scenes import seed
from test_viewer import key, post, run


def state(c):
    """Everything the session may change on a collider."""
    return (c._version, c.center, c.angle, c.velocity, c.angular_velocity, c.friction, c.static_friction,
            getattr(c, "size", None), getattr(c, "radius", None))


@pytest.fixture(scope="module")
def session():
    return Session(seed("demo"))


@pytest.mark.parametrize("shape", COLLIDER_SHAPES)
def test_session_adds_edits_turns_and_removes_each_shape(session, shape):
    s = session
    n = len(s.world.colliders)
    c = s.add_collider(shape, center=(1.0, 2.0))
    assert s.collider is c and s.collider_index == n and s.collider_shape == shape
    assert c.center == pytest.approx((1.0, 2.0))
    default = {"rect": ("size", (3.0, 0.3)), "circle": ("radius", 0.5), "segment": ("radius", 0.05)}
    if shape in default:
        assert getattr(c, default[shape][0]) == default[shape][1]
    if shape == "polygon":                        # a cup: concave, its notch open at the top
        assert c.contains([[1.0, 2.3]]).tolist() == [False] and 0.1 < c.area < 0.72
    if shape == "segment":
        assert c.length == pytest.approx(2.0)
    own = set(s.collider_params())
    assert {"collider_x", "collider_y", "collider_angle", "collider_vx", "collider_vy", "collider_angular_velocity",
            "collider_friction", "collider_static_friction"} <= own
    assert ("collider_width" in own) == (shape == "rect")
    assert ("collider_radius" in own) == (shape in ("circle", "segment"))
    for name in set(COLLIDER_FIELDS) - own:
        assert s.get_param(name) is None
    # every value the shape has, set and read back
    values = {"collider_x": -0.5, "collider_y": 3.0, "collider_angle": 30.0, "collider_vx": 0.5, "collider_vy": -0.25,
              "collider_angular_velocity": 45.0, "collider_friction": 0.8, "collider_static_friction": 1.1,
              "collider_width": 2.0, "collider_height": 0.5, "collider_radius": 0.3}
    for name in own:
        s.set_param(name, values[name])
        assert s.get_param(name) == pytest.approx(values[name]), name
    assert c.velocity == (0.5, -0.25) and c.angular_velocity == 45.0
    s.set_param("collider_friction", None)        # back to the world's
    assert c.friction is None
    # turning: about its centre, the angle kept in (-180, 180]
    centre = c.center
    assert s.rotate_collider(160.0) == pytest.approx(-170.0)
    assert c.center == pytest.approx(centre)
    # refused values change nothing, not even the change counter
    before = state(c)
    bad = [("collider_angle", 1000.0), ("collider_x", float("nan")), ("collider_vx", 1e9),
           ("collider_angular_velocity", "fast"), ("collider_friction", -1.0), ("collider_y", True)]
    bad += [(name, 1.0) for name in set(COLLIDER_FIELDS) - own]           # what this shape has not
    bad += {"rect": [("collider_width", 0.0), ("collider_height", -1.0)], "circle": [("collider_radius", 0.0)],
            "segment": [("collider_radius", -0.1)], "polygon": []}[shape]
    for name, value in bad:
        with pytest.raises(ValueError):
            s.set_param(name, value)
        assert state(c) == before, name
    if shape == "segment":  # radius 0: a wire, which has no inside but can still be picked near it
        s.set_param("collider_radius", 0.0)
        assert c.radius == 0.0
        mid = np.add(c.a, c.b) / 2
        s.select_collider(None)
        assert s.collider_at(mid + (0.0, 0.001)) is None
        assert s.collider_at(mid + (0.0, 0.001), radius=0.01) == n
        s.select_collider(n)
    s.move_collider((4.0, 4.0))
    assert c.center == (4.0, 4.0)
    x0, y0, x1, y1 = c.bounds()
    grid = np.stack(np.meshgrid(np.linspace(x0, x1, 15), np.linspace(y0, y1, 15)), -1).reshape(-1, 2)
    for p in grid[c.contains(grid)][:3]:        # a wire has no inside to click
        assert s.collider_at(p) == n
    s.remove_collider()
    assert len(s.world.colliders) == n and all(d is not c for d in s.world.colliders)


def test_an_unknown_shape_is_refused(session):
    n = len(session.world.colliders)
    with pytest.raises(ValueError, match="collider shape must be one of rect, circle, polygon, segment"):
        session.add_collider("triangle")
    assert len(session.world.colliders) == n


def world_pixel(v, point):
    col, row = v.to_pixel(point)
    return int(round(row)), int(round(col))


def test_panel_adds_each_shape_and_keys_turn_and_delete(demo):
    ins = demo.inspector
    s = demo.session
    selected = np.array([int(SELECTED_COLLIDER_COLOR[k:k + 2], 16) for k in (1, 3, 5)])
    s.camera_center, s.camera_size = (2.0, 2.0), (6.0, 3.4)    # open sky in the demo scene, zoomed in
    for shape in COLLIDER_SHAPES:
        n = len(s.world.colliders)
        post(pygame_gui.UI_DROP_DOWN_MENU_CHANGED, ui_element=ins.shape_menu, text=shape)
        post(pygame_gui.UI_BUTTON_PRESSED, ui_element=ins.add_collider)
        run(demo, 2)
        assert len(s.world.colliders) == n + 1 and s.collider_shape == shape
        c = s.collider
        assert ins.collider_label.text == f"{n + 1} of {n + 1}: {shape}"
        # rows of values the shape has not are greyed out
        assert ins.rows["collider_width"].entry.is_enabled == (shape == "rect")
        assert ins.rows["collider_radius"].entry.is_enabled == (shape in ("circle", "segment"))
        assert ins.rows["collider_vx"].entry.is_enabled
        # drawn, highlighted, where it is (the cup's solid bottom; the others' centre)
        probe = {"polygon": (0.0, -0.14), "circle": (0.0, 0.25)}.get(shape, (0.0, 0.0)) + np.array(c.center)
        img = demo.screenshot().astype(int)
        assert np.abs(img[world_pixel(demo, probe)] - selected).max() < 40, shape
        # Z turns it 5° counter-clockwise, Shift+X 1° back, Delete removes it
        angle = c.angle
        key(pygame.K_z)
        run(demo, 1)
        assert c.angle == pytest.approx(angle + 5.0)
        key(pygame.K_x, pygame.KMOD_SHIFT)
        run(demo, 1)
        assert c.angle == pytest.approx(angle + 4.0)
        assert ins.rows["collider_angle"].entry.get_text() == f"{c.angle:.4g}"
        key(pygame.K_DELETE)
        run(demo, 1)
        assert len(s.world.colliders) == n and all(d is not c for d in s.world.colliders)


def test_keys_leave_colliders_alone_until_one_is_picked(demo):
    s = demo.session
    angles = [c.angle for c in s.world.colliders]
    assert not s.collider_active
    key(pygame.K_z)
    key(pygame.K_DELETE)
    run(demo, 1)
    assert [c.angle for c in s.world.colliders] == angles
    assert "click a collider first" in demo.inspector.message


def test_a_moving_collider_moves_in_the_window(demo):
    ins = demo.inspector
    s = demo.session
    s.camera_center, s.camera_size = (2.0, 2.0), (6.0, 3.4)
    post(pygame_gui.UI_DROP_DOWN_MENU_CHANGED, ui_element=ins.shape_menu, text="circle")
    post(pygame_gui.UI_BUTTON_PRESSED, ui_element=ins.add_collider)
    run(demo, 1)
    c = s.collider
    entry = ins.rows["collider_vx"].entry
    entry.set_text("3")
    post(pygame_gui.UI_TEXT_ENTRY_FINISHED, ui_element=entry, text="3")
    start = c.center
    run(demo, 12)                                  # 0.2 s: 0.6 m to the right
    assert c.velocity == (3.0, 0.0) and c.center[0] == pytest.approx(start[0] + 0.6, abs=0.06)
    img = demo.screenshot().astype(int)
    selected = np.array([int(SELECTED_COLLIDER_COLOR[k:k + 2], 16) for k in (1, 3, 5)])
    assert np.abs(img[world_pixel(demo, (c.center[0], c.center[1] + 0.25))] - selected).max() < 40
    assert np.abs(img[world_pixel(demo, (start[0], start[1] + 0.25))] - selected).max() > 40


def test_reset_puts_a_moving_collider_back_where_it_started(session):
    c = session.add_collider("circle")
    c.velocity = (1.0, 0.0)
    start = c.center
    for _ in range(60):
        session.world.step()
    assert session.world.colliders[-1].center[0] > start[0] + 0.05
    session.reset()
    moved_back = session.world.colliders[-1]
    assert moved_back.center == pytest.approx(start) and moved_back.velocity == (1.0, 0.0)


def test_an_image_collider_of_several_pieces_keeps_the_colours_of_the_colliders_after_it(tmp_path):
    import deforma
    from deforma.scene import load

    picture = np.zeros((20, 40), np.uint8)
    picture[10:, :15] = picture[10:, 25:] = 255  # two pieces
    from PIL import Image
    Image.fromarray(picture).save(tmp_path / "two.png")
    (tmp_path / "s.toml").write_text(
        '[[collider]]\nshape = "image"\nsource = "two.png"\nscale = 0.05\ncolor = "#111111"\n\n'
        '[[collider]]\ncenter = [0.0, -3.0]\nsize = [4.0, 0.5]\ncolor = "#222222"\n')
    s = Session(load(tmp_path / "s.toml"))
    assert len(s.world.colliders) == 3 and isinstance(s.world.colliders[2], deforma.Rect)
    assert s.collider_colors == ["#111111", "#111111", "#222222"]

"""Every built-in scene runs headless, stays finite, keeps its vertices out of the colliders,
and draws its bodies where they are."""

import numpy as np
import pytest

from deforma import scene as scenes

NAMES = sorted(scenes.builtin_scenes())


def test_the_original_scenes_are_built_in():
    assert {"sample", "demo"} <= set(NAMES)


def test_sample_is_one_box_over_one_flat_plane():
    s = scenes.load("sample")
    assert [b.shape for b in s.body] == ["box"]
    assert len(s.collider) == 1 and s.collider[0].angle == 0


def test_demo_tumbles_a_textured_body_down_rotated_rectangles():
    s = scenes.load("demo")
    assert any(b.shape == "image" or b.texture is not None for b in s.body)
    assert sum(1 for c in s.collider if c.angle != 0) >= 3


@pytest.mark.parametrize("name", NAMES)
def test_builtin_scene_runs_finite_with_no_vertex_inside_a_collider(name):
    world = scenes.load_scene(name)
    seconds = 1.0
    steps = int(round(seconds / world.dt))
    for k in range(steps):
        world.step()
        if k % 20 == 0 or k == steps - 1:
            for b in world.bodies:
                x = b.positions
                assert np.isfinite(x).all() and np.isfinite(b.velocities).all()
                for c in world.colliders:
                    inside = c.contains(x)
                    assert not inside.any(), (name, k, c, x[inside][:3])
    # something happened: the bodies moved from where they started
    start = scenes.load_scene(name)
    moved = max(np.abs(b.positions - b0.positions).max() for b, b0 in zip(world.bodies, start.bodies))
    assert moved > 0.01


@pytest.mark.parametrize("name", NAMES)
def test_builtin_scene_frame_shows_each_body_where_it_is(gl_ctx, name):
    from deforma.render import Renderer, WorldView

    world = scenes.load_scene(name)
    for _ in range(60):
        world.step()
    r = Renderer(gl_ctx, (320, 180), samples=0)
    view = WorldView(r, world)
    view.wireframe = False
    img = view.draw().astype(int)
    # the same picture without bodies: the background and colliders alone
    r.render([], world.colliders, collider_colors=view.collider_colors)
    empty = r.read().astype(int)
    changed = np.abs(img - empty).sum(axis=-1) > 24
    for b in world.bodies:
        px = np.floor(r.camera.world_to_pixel(b.positions, r.size)).astype(int)
        onscreen = (px[:, 0] >= 2) & (px[:, 0] < 318) & (px[:, 1] >= 2) & (px[:, 1] < 178)
        if not onscreen.any():
            continue
        # around each vertex (3x3 pixels) the picture differs from the empty one: the body is there
        hits = [changed[r_ - 1 : r_ + 2, c - 1 : c + 2].any() for c, r_ in px[onscreen]]
        assert np.mean(hits) > 0.9, (name, np.mean(hits))
    # and far from every body nothing changed
    allpx = np.concatenate([r.camera.world_to_pixel(b.positions, r.size) for b in world.bodies])
    lo, hi = allpx.min(axis=0) - 4, allpx.max(axis=0) + 4
    cols, rows = np.meshgrid(np.arange(320), np.arange(180))
    outside = (cols < lo[0]) | (cols > hi[0]) | (rows < lo[1]) | (rows > hi[1])
    assert not changed[outside].any()
    r.release()


@pytest.mark.parametrize("name", [n for n in NAMES if n != "pile"])  # the pile: tests/physics/test_body_contact.py
def test_builtin_scene_comes_to_rest_with_no_triangle_inside_out(name):
    from deforma.physics.elements import signed_areas

    world = scenes.load_scene(name)
    seconds = max(6.0, scenes.load(name).run.seconds)
    for _ in range(int(round(seconds / world.dt))):
        world.step()
    for k, b in enumerate(world.bodies):
        area = signed_areas(b.positions, b.triangles)
        assert (area > 0).all(), (name, k, np.flatnonzero(area <= 0)[:5].tolist())


def test_sample_box_lands_flat_without_turning_or_drifting():
    world = scenes.load_scene("sample")
    b = world.bodies[0]
    x0, c0 = b.positions.copy(), b.center_of_mass
    for _ in range(int(round(4.0 / world.dt))):
        world.step()
    x, c = b.positions, b.center_of_mass
    u, _, vt = np.linalg.svd((x0 - c0).T @ (x - c))  # best-fit rotation (Kabsch)
    r = vt.T @ u.T
    assert abs(np.degrees(np.arctan2(r[1, 0], r[0, 0]))) < 1.0 and abs(c[0] - c0[0]) < 0.01
    assert abs(b.positions[:, 1].min() - 0.2) < 0.01  # on the plane, whose top is at y = 0.2

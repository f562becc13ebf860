"""Every built-in scene runs headless, stays finite, keeps its vertices out of the colliders,
and draws its bodies where they are."""

import numpy as np
import pytest

from deforma import scene as scenes
from deforma.physics.rigid.solver import SLOP

NAMES = sorted(scenes.builtin_scenes())
RESTING = [n for n in NAMES if n != "pile"]  # see test_builtin_scene_comes_to_rest
STANDING = {"pyramid"}  # scenes in which nothing is meant to move


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


# A scene without [[event]] or [[pull]] steps the same with or without its Script, bit for bit:
# the rest test below goes on from the world the first test leaves after its first second
# (when that test passed) instead of stepping that second again.
_AFTER_THE_FIRST_SECOND = {}


# the pile: tests/physics/test_body_contact.py steps it for 10 s with this check every 20 steps
@pytest.mark.parametrize("name", [n for n in NAMES if n != "pile"])
def test_builtin_scene_runs_finite_with_no_vertex_inside_a_collider(name):
    world = scenes.load_scene(name)
    # (sleep off: the solver's own contacts are measured, and the world goes on into the rest
    # test below; one of the slope's boxes falls asleep within this first second)
    world.sleep = False
    scene = scenes.load(name)
    script = scenes.Script(scene, world)  # as deforma run plays it (the tear's pull)
    seconds = 1.0
    steps = int(round(seconds / world.dt))
    for k in range(steps):
        script.apply()
        world.step()
        if k % 20 == 0 or k == steps - 1:
            for b in world.bodies:
                x = b.positions
                assert np.isfinite(x).all() and np.isfinite(b.velocities).all()
                for c in world.colliders:
                    inside = c.contains(x)
                    if b.material.is_rigid:
                        # the rigid solver lets a resting contact keep up to SLOP of overlap
                        # (Box2D's "linear slop"): no vertex deeper, whichever way out
                        for t in np.arange(8) * np.pi / 4:
                            inside &= c.contains(x + 1.5 * SLOP * np.array([np.cos(t), np.sin(t)]))
                    assert not inside.any(), (name, k, c, x[inside][:3])
    # something happened: the bodies moved from where they started (the pyramid's point is
    # that nothing does: its boxes, placed 1 mm apart, land and stand)
    start = scenes.load_scene(name)
    # (a tear keeps the vertex numbers and appends the copies)
    moved = max(np.abs(b.positions[:b0.n_vertices] - b0.positions).max() for b, b0 in zip(world.bodies, start.bodies))
    assert moved < 0.005 if name in STANDING else moved > 0.01
    if name in RESTING and not scene.event and not scene.pull:
        _AFTER_THE_FIRST_SECOND[name] = (world, steps)


@pytest.mark.parametrize("name", NAMES)
def test_builtin_scene_frame_shows_each_body_where_it_is(gl_ctx, name):
    from deforma.render import Renderer, WorldView
    from deforma.render.world_view import JOINT_DOT_PIXELS

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
    dots = r.camera.world_to_pixel(np.array([j.point for j in world.joints]).reshape(-1, 2), r.size)
    for b in world.bodies:
        px = np.floor(r.camera.world_to_pixel(b.positions, r.size)).astype(int)
        onscreen = (px[:, 0] >= 2) & (px[:, 0] < 318) & (px[:, 1] >= 2) & (px[:, 1] < 178)
        if world.joints:  # a joint's dot is drawn over the body, its light centre near the sky's colour
            onscreen &= np.linalg.norm(px[:, None, :] - dots[None], axis=2).min(axis=1) > JOINT_DOT_PIXELS
        if not onscreen.any():
            continue
        # around each vertex (3x3 pixels) the picture differs from the empty one: the body is there
        hits = [changed[r_ - 1 : r_ + 2, c - 1 : c + 2].any() for c, r_ in px[onscreen]]
        assert np.mean(hits) > 0.9, (name, np.mean(hits))
    # and far from every body (and every joint's dot) nothing changed
    allpx = np.concatenate([r.camera.world_to_pixel(b.positions, r.size) for b in world.bodies])
    lo, hi = allpx.min(axis=0) - 4, allpx.max(axis=0) + 4
    if world.joints:
        lo = np.minimum(lo, dots.min(axis=0) - JOINT_DOT_PIXELS - 2)
        hi = np.maximum(hi, dots.max(axis=0) + JOINT_DOT_PIXELS + 2)
    cols, rows = np.meshgrid(np.arange(320), np.arange(180))
    outside = (cols < lo[0]) | (cols > hi[0]) | (rows < lo[1]) | (rows > hi[1])
    assert not changed[outside].any()
    r.release()


# the pile: tests/physics/test_body_contact.py. dent: it rests tilted on the wedge's tip, hooked
# by its dent, with every element unfolded (under implicit Euler at its coarser mesh the four
# elements pressed over the tip stayed folded, and it was left out here).
@pytest.mark.parametrize("name", RESTING)
def test_builtin_scene_comes_to_rest_with_no_triangle_inside_out(name):
    from deforma.physics.elements.triangles import signed_areas

    seconds = max(6.0, scenes.load(name).run.seconds)
    world, done = _AFTER_THE_FIRST_SECOND.pop(name, (None, 0))  # see above
    if world is None:
        world = scenes.load_scene(name)
    world.sleep = False  # (sleep off: the scene's own rest is measured, not put to sleep)
    for _ in range(int(round(seconds / world.dt)) - done):
        world.step()
    for k, b in enumerate(world.bodies):
        area = signed_areas(b.positions, b.triangles)
        assert (area > 0).all(), (name, k, np.flatnonzero(area <= 0)[:5].tolist())
    if name == "demo":
        # issue 18: the video used to end as the bunny landed; now it lands by 8 s (when, the
        # rounding of a chaotic tumble down three ramps decides) and its free ear's wobble
        # dies down over the next seconds
        for _ in range(int(round(10.0 / world.dt))):
            world.step()
        assert np.abs(world.bodies[0].velocities).max() < 0.01


def test_demo_nudged_by_a_nanometre_rests_without_the_failsafe():
    # the bunny started 1e-9 m off (another rounding would do the same) took the path where it
    # rests with an ear on a ramp's corner; that corner had a solver row only every other
    # step, the fail-safe pushed it back out of the ear in the steps between (60 times in
    # 2 s), and the ear buzzed at 5 cm/s for good. Now the row stays.
    world = scenes.load_scene("demo")
    world.sleep = False  # (sleep off: the solver's own rest is measured)
    (b,) = world.bodies
    b.positions = b.positions + 1e-9 * np.random.default_rng(4).standard_normal(b.positions.shape)
    for _ in range(int(round(10.0 / world.dt))):
        world.step()
    before = world.integrator_stats["failsafe"]
    for _ in range(int(round(2.0 / world.dt))):
        world.step()
    assert world.integrator_stats["failsafe"] - before < 10


def test_sample_box_lands_flat_without_turning_or_drifting():
    world = scenes.load_scene("sample")
    world.sleep = False  # (sleep off: the solver's own rest is measured)
    b = world.bodies[0]
    x0, c0 = b.positions.copy(), b.center_of_mass
    for _ in range(int(round(4.0 / world.dt))):
        world.step()
    x, c = b.positions, b.center_of_mass
    u, _, vt = np.linalg.svd((x0 - c0).T @ (x - c))  # best-fit rotation (Kabsch)
    r = vt.T @ u.T
    assert abs(np.degrees(np.arctan2(r[1, 0], r[0, 0]))) < 1.0 and abs(c[0] - c0[0]) < 0.01
    assert abs(b.positions[:, 1].min() - 0.2) < 0.01  # on the plane, whose top is at y = 0.2


def test_explode_scene_box_lands_flat_and_bounces_straight():
    # thrown up by its scripted explosion (6 m/s), the box falls 1.8 m onto the flat floor and
    # bounces: it must neither turn nor wander (the springs under symplectic Euler it used to
    # run landed turned and tumbled, 125 degrees by 6 s)
    s = scenes.load("explode")
    w = s.build()
    w.sleep = False  # (sleep off: the solver's own rest is measured)
    (b,) = w.bodies
    script = scenes.Script(s, w)
    script.advance(1.4)  # settled on the floor, just before the explosion
    x0, c0 = b.positions.copy(), b.center_of_mass
    worst, top = 0.0, 0.0
    for k in range(15, 61):
        script.advance(0.1 * k)
        x, c = b.positions, b.center_of_mass
        u, _, vt = np.linalg.svd((x0 - c0).T @ (x - c))  # best-fit rotation (Kabsch)
        r = vt.T @ u.T
        worst = max(worst, abs(np.degrees(np.arctan2(r[1, 0], r[0, 0]))))
        top = max(top, c[1])
    assert top > c0[1] + 1.5  # it was thrown
    assert worst < 1.0 and abs(c[0] - c0[0]) < 0.01
    assert abs(c[1] - c0[1]) < 0.01 and np.abs(b.velocities).max() < 0.05  # back at rest where it was


def test_tear_scene_tears_in_two_under_its_scripted_pull():
    # deforma run plays the [[pull]]; the plain steps above only let the sheet hang
    from deforma.physics.elements.triangles import signed_areas

    s = scenes.load("tear")
    w = s.build()
    (b,) = w.bodies
    n = b.n_vertices
    scenes.Script(s, w).advance(2.0)
    assert b.n_vertices > n and b.pieces.max() + 1 >= 2
    assert np.isfinite(b.positions).all()
    # the grab holds its patch whole (it pinched it into a tangle of folded triangles when every
    # held vertex was pulled to one point); a torn flap may fold over as cloth does (1 triangle
    # now): a springs sheet has no area term to unfold it
    assert (signed_areas(b.positions, b.triangles) <= 0).sum() <= 2


def test_torn_sheet_is_drawn_with_its_texture_on_every_piece(gl_ctx, tmp_path):
    # the tear scene with a gradient picture for its cloth (red along u, green down the
    # picture), torn by its pull and drawn as deforma run draws it: along the torn edges of
    # every piece the pixels show the picture where that cloth was before the tear, so the
    # copies a tear makes carry their texture coordinates into the renderer
    from PIL import Image

    from deforma.render import Renderer, WorldView

    ramp = np.arange(64) * 4
    tex = np.zeros((64, 64, 4), np.uint8)
    tex[..., 0], tex[..., 1], tex[..., 2], tex[..., 3] = ramp[None, :], ramp[:, None], 128, 255
    Image.fromarray(tex, "RGBA").save(tmp_path / "ramp.png")
    text = (scenes.builtin_scenes()["tear"]).read_text().replace('texture = "cloth"', 'texture = "ramp.png"')
    assert 'texture = "ramp.png"' in text
    (tmp_path / "tear.toml").write_text(text)
    s = scenes.load(tmp_path / "tear.toml")
    w = s.build()
    (b,) = w.bodies
    scenes.Script(s, w).advance(2.5)
    assert b.pieces.max() + 1 >= 2
    r = Renderer(gl_ctx, (640, 360), samples=0)
    view = WorldView(r, w, s)
    view.wireframe = False
    img = view.draw().astype(int)
    # a box's uv is its rest position scaled into the unit square, and a copy keeps the rest
    # position of the vertex it was split from: the picture every point should show
    rest = b.topology.rest_positions
    corners = np.array(s.body[0].corners, float)
    lo, size = corners.min(axis=0), np.ptp(corners, axis=0)
    x, t, uv = b.positions, b.triangles, (rest - lo) / size
    e1, e2 = x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    # the vertices the tear split: an original and its copies share a rest position
    _, first, count = np.unique(rest.round(9), axis=0, return_inverse=True, return_counts=True)
    split = count[first] > 1
    for piece in range(int(b.pieces.max()) + 1):
        mine = np.flatnonzero((b.pieces[t[:, 0]] == piece) & split[t].any(axis=1))  # along its torn edge
        assert len(mine) >= 5, piece
        big = mine[np.argsort(-area[mine])[:5]]  # the largest: their centres far from other edges
        px = np.floor(r.camera.world_to_pixel(x[t[big]].mean(axis=1), r.size)).astype(int)
        u, v = uv[t[big]].mean(axis=1).T
        expected = np.c_[u * 256 - 2, (1 - v) * 256 - 2]  # texel centres: (k + 0.5) / 64 -> 4 k
        got = img[px[:, 1], px[:, 0], :2]
        match = np.abs(got - expected).max(axis=1) < 12
        assert match.sum() >= 4, (piece, got.tolist(), expected.round().tolist())
    r.release()


@pytest.mark.parametrize("sleep", [False, True])
def test_cards_stand_by_friction_until_the_wheel_comes(sleep):
    # fifteen rigid cards, leaning 18 degrees in pairs (friction 0.8 at their feet, where a
    # pair needs tan(18) / 2 = 0.16); the wheel reaches them after 2.5 s. Sleep off: the
    # friction that holds the cards is measured; on (the scene's default): asleep by then,
    # the house is woken for the step the wheel reaches it (else it stopped the wheel as a wall)
    world = scenes.load_scene("cards")
    world.sleep = sleep
    cards = world.bodies[:15]
    start = [(b.center_of_mass.copy(), b.angle) for b in cards]
    slept = False
    for _ in range(150):
        world.step()
        slept = slept or all(b.sleeping for b in cards)
    for b, (c, a) in zip(cards, start):
        assert np.abs(b.center_of_mass - c).max() < 0.01 and abs(b.angle - a) < 3.0
    assert slept == sleep  # the wheel comes to a house that fell asleep (measured: at 2.1-2.4 s)
    for _ in range(210):
        world.step()
    heights = sorted(b.center_of_mass[1] for b in cards)
    assert heights[-1] < start[-1][0][1] - 0.1  # the top storey came down
    assert heights[10] > 0.3  # the two below stand


@pytest.mark.xfail(strict=True, reason="avbd's row search takes a vertex behind an edge's line by up to the "
                   "widened thickness as in front of it, even past a thin body's far side (issue 48)")
def test_the_house_of_cards_stands_in_whole_steps_while_the_wheel_rolls():
    # reach = 0: no step is split. The wheel rolling at 1 m/s widens the rows' search to 1.7
    # cm, more than a card is thick; a card's foot resting on the flat card below then lies
    # within that of the flat card's underside (1.05 cm behind it) and is pulled down through
    # it: the house blows up in its first step (10.9 m/s, then 1.7e3 m/s by step 60). The
    # shipped scene hides it: every step is split in two or three parts there, since the
    # wheel's 1.2 mm edges lie g h^2 past the floor in the prediction (test_avbd.py,
    # test_a_body_resting_on_the_floor_is_not_split_by_its_weight).
    world = scenes.load_scene("cards")
    world.sleep = False  # (sleep off: the house's own stand is measured)
    world.integrator_options = {"reach": 0.0}
    cards = world.bodies[:15]
    start = [b.center_of_mass.copy() for b in cards]
    for _ in range(60):
        world.step()
    assert world.integrator_stats["split"] == 0
    assert max(np.abs(b.center_of_mass - c).max() for b, c in zip(cards, start)) < 0.01


def box_corners(b):
    """A rigid box's four corners now, anticlockwise: the vertices at the extremes of its mesh."""
    x, y = b.topology.rest_positions.T
    return b.positions[[np.argmin(x + y), np.argmax(x - y), np.argmax(x + y), np.argmax(y - x)]]


def quad_overlap(p, q):
    """How deep convex quads ``p`` and ``q`` (4 x 2, anticlockwise) overlap (m), by separating
    axes: the least overlap of their projections on the normals of their edges (<= 0: apart)."""
    depth = np.inf
    for poly in (p, q):
        for e in np.roll(poly, -1, axis=0) - poly:
            n = np.array([e[1], -e[0]]) / np.hypot(*e)
            a, b = p @ n, q @ n
            depth = min(depth, min(a.max(), b.max()) - max(a.min(), b.min()))
    return depth


def test_pyramid_of_210_boxes_stands_still():
    # twenty rows of 0.2 m rigid boxes, 2 mm apart, rows 1 mm apart, at its defaults (avbd at
    # 1/60 s) but with sleep off, so that the solve itself holds them (asleep from 1 s, every
    # box would pass): after the first second every box centre stays within 2 mm of where it
    # was for two more seconds (measured: 0.3 mm; a pyramid that sags into its 1 mm gaps
    # moves its top 19 mm), and at the end every box is slower than 1 mm/s (measured 0.16),
    # none tipped, none 1 mm into another
    world = scenes.load_scene("pyramid")
    world.sleep = False
    boxes = world.bodies
    assert len(boxes) == 210 and all(b.material.is_rigid for b in boxes) and world.integrator == "avbd"
    for _ in range(60):
        world.step()
    landed = np.array([b.center_of_mass for b in boxes])
    worst = 0.0
    for _ in range(120):
        world.step()
        worst = max(worst, np.hypot(*(np.array([b.center_of_mass for b in boxes]) - landed).T).max())
    assert worst < 2e-3
    assert all(np.hypot(*b.velocity) < 1e-3 for b in boxes)
    assert max(abs(b.angle) for b in boxes) < 0.5  # degrees
    corners = [box_corners(b) for b in boxes]
    centres = np.array([b.center_of_mass for b in boxes])
    deepest = max(quad_overlap(corners[i], corners[j]) for i in range(len(boxes)) for j in range(i)
                  if np.hypot(*(centres[i] - centres[j])) < 0.3)  # neighbours (0.2 m boxes)
    assert deepest < 1e-3  # measured: -0.9 mm, every pair of neighbours apart
    # (the check itself: a box moved 2 mm into its neighbour's place overlaps it by 2 mm)
    a, b = box_corners(boxes[0]), box_corners(boxes[1])
    assert abs(quad_overlap(a + (b.mean(axis=0) - a.mean(axis=0)) - (0.198, 0.0), b) - 0.002) < 1e-6


def test_dent_keeps_its_dent():
    from deforma.physics.elements.triangles import signed_areas

    w = scenes.load_scene("dent")
    w.sleep = False  # (sleep off: the solver's own rest is measured)
    (b,) = w.bodies
    rest0 = b.topology.rest_positions.copy()
    for _ in range(int(round(2.0 / w.dt))):
        w.step()
    x = b.positions
    # the middle of the bottom edge sits higher than its ends: bent over the corner, and staying.
    # 10.6 cm under avbd with the corner as a row (the block's mesh at 5 cm); 9.6 cm under
    # implicit Euler at a 10 cm mesh, whose corner tip sank into the block and made the notch.
    bottom = np.abs(rest0[:, 1] - rest0[:, 1].min()) < 1e-9
    xs = x[bottom]
    middle = xs[np.argsort(np.abs(rest0[bottom, 0]))[:3], 1].mean()
    ends = xs[np.argsort(-np.abs(rest0[bottom, 0]))[:4], 1].mean()
    assert middle - ends > 0.08
    assert b.center_of_mass[1] > 1.03  # resting on the tip (at y = 0.87), not sunk onto it
    assert (signed_areas(b.positions, b.triangles) <= 0).sum() <= 6  # only over the corner


def test_balloon_keeps_its_area_while_it_bounces():
    from deforma.physics.elements.triangles import signed_areas

    w = scenes.load_scene("balloon")
    (b,) = w.bodies
    for _ in range(int(round(0.2 / w.dt))):  # inflated in the air, before it lands
        w.step()
    inflated = signed_areas(b.positions, b.triangles).sum()
    areas = []
    for _ in range(int(round(1.8 / w.dt))):
        w.step()
        areas.append(signed_areas(b.positions, b.triangles).sum())
    assert min(areas) > 0.85 * inflated and max(areas) < 1.15 * inflated
    assert b.positions[:, 1].min() < 0.5 and b.pressure > 0  # it landed


def test_rope_of_soft_links_swings_its_weight_without_gaining_energy():
    # six soft links pinned end to end from a hook hold a rigid weight; released level, the
    # rope swings down: every pin holds, no link turns inside out, and the energy (kinetic
    # and gravitational; the elastic, >= 0, left out) never rises above the start
    from deforma.physics.elements.triangles import signed_areas

    w = scenes.load_scene("rope")
    links, weight = w.bodies[:6], w.bodies[6]
    assert [b.material.is_rigid for b in w.bodies] == [False] * 6 + [True] and len(w.joints) == 7

    def energy():
        return sum(0.5 * (b.vertex_masses * (b.velocities ** 2).sum(1)).sum()
                   + 9.81 * (b.vertex_masses * b.positions[:, 1]).sum() for b in w.bodies)

    e0, start = energy(), weight.center_of_mass.copy()
    for _ in range(180):
        w.step()
        assert energy() <= e0 + 1e-6
        # at every step (checked at the end only, the first link's corner, squeezed against
        # a hook face beside its pin, was inside out from step 147 to 178 and again later)
        for b in links:
            assert (signed_areas(b.positions, b.triangles) > 0).all(), w.step_count
    assert weight.center_of_mass[1] < start[1] - 0.5  # it swung down
    assert max(np.hypot(*(j._side_point(0) - j._side_point(1))) for j in w.joints) < 2e-3


def test_car_drives_its_level_on_squashing_tyres():
    # two soft tyres, each pinned on a rigid hub that a motor pin turns against the chassis:
    # it drives over the humps, up the ramp and across the plateau in 6 s, its tyres squashed
    # where they touch, no triangle turned inside out, every pin holding
    from deforma.physics.elements.triangles import signed_areas

    w = scenes.load_scene("car")
    chassis, tyres = w.bodies[0], (w.bodies[2], w.bodies[4])
    assert [b.material.is_rigid for b in w.bodies] == [True, True, False, True, False]
    start = chassis.center_of_mass.copy()
    lowest = np.inf
    for _ in range(360):
        w.step()
        lowest = min(lowest, min(np.ptp(t.positions[:, 1]) for t in tyres))
        for t in tyres:
            assert (signed_areas(t.positions, t.triangles) > 0).all()
    assert chassis.center_of_mass[0] - start[0] > 5.0  # 1 m/s or more, over humps and a ramp
    assert abs(chassis.angle) < 30.0  # on its wheels
    assert lowest < 0.49  # a 0.5 m tyre squashed by more than a centimetre
    for j in w.joints:
        if j.motor_speed is None:  # a tyre's pin: its triangle's point on the hub's
            assert np.hypot(*(j._side_point(0) - j._side_point(1))) < 3e-3

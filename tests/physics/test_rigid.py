"""Rigid bodies (``Material("rigid")``) against known answers, at the step people use (1/60 s)."""

import math

import numpy as np
import pytest

import deforma
from deforma.physics.rigid.bodies import triangle_inertia
from deforma.physics.rigid.stage import rigid_set

G = 9.81
RIGID = deforma.Material("rigid", density=100.0)


def disc(radius: float, k: int) -> deforma.mesh.Mesh:
    """A disc meshed with ``k`` outline points (a ring inside, and the centre)."""
    a = np.arange(k) * 2 * np.pi / k
    ring = np.column_stack([np.cos(a), np.sin(a)]) * radius
    inner = np.column_stack([np.cos(a[::2]), np.sin(a[::2])]) * radius * 0.5
    pts = np.vstack([ring, inner, [[0.0, 0.0]]])
    return deforma.mesh.Mesh(pts, deforma.delaunay(pts))


def test_the_rigid_material_takes_density_only():
    assert RIGID.is_rigid and RIGID.is_fem and RIGID.density == 100.0
    with pytest.raises(ValueError, match="takes density only, not youngs_modulus"):
        deforma.Material("rigid", density=1.0, youngs_modulus=1e5)
    with pytest.raises(ValueError, match="needs density"):
        deforma.Material("rigid")
    with pytest.raises(ValueError, match="density must be in"):
        deforma.Material("rigid", density=-1.0)


def test_mass_and_inertia_are_those_of_the_solid():
    m, c, i = triangle_inertia(*(lambda b: (b.vertices, b.triangles))(
        deforma.mesh.box(((0, 0), (0.4, 0), (0.4, 0.2), (0, 0.2)), detail=3)), 100.0)
    assert m == pytest.approx(8.0) and np.allclose(c, (0.2, 0.1))
    assert i == pytest.approx(8.0 * (0.4 ** 2 + 0.2 ** 2) / 12)


def test_a_spinning_rigid_body_keeps_its_spin_exactly():
    # a rigid rotor: no energy lost at any step (the soft integrators damp this, issue 34)
    w = deforma.World(gravity=(0, 0), dt=1 / 60)
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 0.3), (0, 0.3)), detail=3), material=RIGID,
                   angular_velocity=300.0, velocity=(1.0, 0.0))
    for _ in range(60):
        w.step()
    assert b.angular_velocity == pytest.approx(300.0, rel=1e-12)
    assert np.allclose(b.velocity, (1.0, 0.0), atol=1e-12)
    assert ((b.angle - 300.0 + 180.0) % 360.0 - 180.0) == pytest.approx(0.0, abs=1e-9)


def slope_run(angle_deg, mesh, *, friction=0.3, static_friction=0.5, seconds=1.0, turn=True):
    """Put ``mesh`` (rigid) on a slope at ``angle_deg``; return its fitted acceleration along
    the slope (m/s^2, downhill positive) and the body."""
    a = math.radians(angle_deg)
    # (sleep off: a box that sticks is held by the solver itself, not put to sleep)
    w = deforma.World(dt=1 / 60, friction=friction, static_friction=static_friction, sleep=False)
    w.add_collider(deforma.Rect((0, 0), (60, 1), angle_deg))
    n, t = np.array([-math.sin(a), math.cos(a)]), np.array([-math.cos(a), -math.sin(a)])
    half = np.ptp(mesh.vertices[:, 1]) / 2
    b = w.add_body(mesh, position=tuple(n * (0.5 + half + 0.001)), material=RIGID, angle=angle_deg if turn else 0)
    for _ in range(10):  # lands
        w.step()
    s0, t0, rows = b.center_of_mass @ t, w.time, []
    for _ in range(int(seconds * 60)):
        w.step()
        rows.append((w.time - t0, b.center_of_mass @ t - s0))
    tt, ss = np.array(rows).T
    coef = np.linalg.lstsq(np.column_stack([np.ones_like(tt), tt, tt ** 2 / 2]), ss, rcond=None)[0]
    return coef[2], b


@pytest.mark.parametrize("angle", [30.0, 40.0, math.degrees(math.atan(1.1 * 0.5))])  # the last: 1.1x the limit
def test_a_rigid_box_slides_down_a_slope_at_g_sin_minus_mu_cos(angle):
    box = deforma.mesh.box(((0, 0), (0.4, 0), (0.4, 0.2), (0, 0.2)), detail=3)
    acc, _ = slope_run(angle, box)
    a = math.radians(angle)
    assert acc == pytest.approx(G * (math.sin(a) - 0.3 * math.cos(a)), rel=0.03)


@pytest.mark.parametrize("share", [0.73, 0.95])
def test_a_rigid_box_sticks_below_the_static_limit(share):
    # tan a = share * static_friction; it lands from a millimetre above, coming in sliding
    # at 2.6 cm/s at 0.95 (the impact's static friction stops it)
    box = deforma.mesh.box(((0, 0), (0.4, 0), (0.4, 0.2), (0, 0.2)), detail=3)
    acc, b = slope_run(math.degrees(math.atan(share * 0.5)), box)
    assert abs(acc) < 1e-6 and np.abs(b.velocity).max() < 1e-6


@pytest.mark.parametrize("angle", [20.0, 30.0])
def test_a_rigid_disc_rolls_down_a_slope_at_two_thirds_g_sin(angle):
    # a 96-sided disc of 0.2 m (outline points 1.3 cm apart, as a traced picture would give):
    # a polygon rolls by pivoting on its corners, which costs a little at each one; within 5%
    # for the first second (the bound); faster, v^2 / R beyond g cos(a), it hops
    acc, b = slope_run(angle, disc(0.2, 96), turn=False)
    expect = 2 / 3 * G * math.sin(math.radians(angle))
    assert acc == pytest.approx(expect, rel=0.05)
    # rolling, not sliding: the spin matches the speed
    assert math.radians(abs(b.angular_velocity)) * 0.2 == pytest.approx(np.hypot(*b.velocity), rel=0.05)


def test_a_stack_of_ten_rigid_boxes_stands_for_ten_seconds():
    w = deforma.World(dt=1 / 60, sleep=False)  # (sleep off: the solver's own rest is measured)
    w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0))
    boxes = [w.add_body(deforma.mesh.box(((0, 0), (0.4, 0), (0.4, 0.2), (0, 0.2)), detail=2),
                        position=(0.01 * (i % 2), 0.1 + 0.201 * i), material=RIGID) for i in range(10)]
    for _ in range(60):
        w.step()
    settled = np.array([b.center_of_mass for b in boxes])
    assert np.all(np.diff(settled[:, 1]) > 0.19)  # stacked, not fallen
    for _ in range(600):
        w.step()
    now = np.array([b.center_of_mass for b in boxes])
    assert np.abs(now - settled).max() < 0.01
    assert max(abs(b.angle) for b in boxes) < 0.5


def drift_after(w, bodies, settle: int, watch: int) -> float:
    """Step ``settle`` steps, then ``watch`` more: the farthest any body's centre of mass got
    (m) from where it was after the first ones."""
    for _ in range(settle):
        w.step()
    settled = np.array([b.center_of_mass for b in bodies])
    most = 0.0
    for _ in range(watch):
        w.step()
        most = max(most, np.abs(np.array([b.center_of_mass for b in bodies]) - settled).max())
    return most


def test_avbd_holds_a_stack_of_ten_rigid_boxes_still():
    # the default integrator solves each rigid box as one block of its sweep: settled (3 s),
    # every box stays within a millimetre for ten seconds and ends slower than 1 mm/s (sleep
    # off: the solver's own rest is measured)
    w = deforma.World(dt=1 / 60, sleep=False)
    assert w.integrator == "avbd"
    w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0))
    boxes = [w.add_body(deforma.mesh.box(((0, 0), (0.4, 0), (0.4, 0.2), (0, 0.2)), detail=2),
                        position=(0.01 * (i % 2), 0.1 + 0.201 * i), material=RIGID) for i in range(10)]
    assert drift_after(w, boxes, 180, 600) < 1e-3
    assert max(np.hypot(*b.velocity) for b in boxes) < 1e-3
    assert max(abs(b.angle) for b in boxes) < 0.1
    assert w.integrator_stats["failsafe"] == 0


def test_avbd_holds_a_pyramid_of_rigid_boxes_still():
    # ten rows of 0.2 m boxes, 2 mm apart, rows 1 mm apart: settled (1 s), every box stays
    # within a millimetre for ten seconds (the 20-row one does too, 1.5 mm:
    # benchmarks/bench_rigid.py, 17 s a run); sleep off: the solver's own rest is measured
    w = deforma.World(dt=1 / 60, sleep=False)
    w.add_collider(deforma.Rect((0, -0.5), (40, 1), 0))
    boxes = [w.add_body(deforma.mesh.box(((0, 0), (0.2, 0), (0.2, 0.2), (0, 0.2)), detail=2),
                        position=((c - (10 - r - 1) / 2) * 0.202, 0.1 + r * 0.201), material=RIGID)
             for r in range(10) for c in range(10 - r)]
    assert drift_after(w, boxes, 60, 600) < 1e-3
    assert max(np.hypot(*b.velocity) for b in boxes) < 1e-3
    assert w.integrator_stats["failsafe"] == 0


def two_boxes_through(*integrators):
    """A rigid box resting on another, stepped half a second under each integrator in turn:
    the top box's heights (m) and its last angle (degrees)."""
    w = deforma.World(dt=1 / 60, sleep=False)  # (sleep off: the solvers' own rest is measured)
    w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0))
    box = lambda y: w.add_body(deforma.mesh.box(((0, 0), (0.4, 0), (0.4, 0.2), (0, 0.2)), detail=2),  # noqa: E731
                               position=(0.0, y), material=RIGID)
    box(0.1)
    top = box(0.301)
    heights = []
    for name in integrators:
        w.integrator = name
        for _ in range(30):
            w.step()
        heights.append(top.center_of_mass[1])
    return heights, top.angle


def test_rigid_bodies_change_hands_when_the_integrator_changes():
    # avbd moves rigid bodies in its sweep, the others in the rigid stage after each substep
    heights, angle = two_boxes_through("avbd", "implicit-euler")
    assert max(heights) - min(heights) < 5e-3 and min(heights) > 0.295 and abs(angle) < 0.1


def test_rigid_bodies_change_back_to_avbd():
    # the rigid stage leaves the boxes 0.02 mm into each other: avbd's rows hold such pairs out
    heights, angle = two_boxes_through("avbd", "implicit-euler", "avbd")
    assert max(heights) - min(heights) < 5e-3 and min(heights) > 0.295 and abs(angle) < 0.1


@pytest.mark.parametrize("offset", [0.0, 0.05, -0.1])
def test_a_rigid_box_dropped_on_another_lands_flat_on_it(offset):
    # landing at 2.5 m/s off-centre, it ended 0.03 mm into the lower box, its pairs were taken as
    # behind the edges from then on, and it sank in and tipped over: 28 degrees, a corner 4 cm in
    w = deforma.World(sleep=False)  # (sleep off: the solver's own rest is measured)
    w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0))
    box = lambda size: deforma.mesh.box(((0, 0), (size, 0), (size, size), (0, size)), detail=3, edges=True)  # noqa: E731
    wood = deforma.Material("rigid", density=600.0)
    w.add_body(box(0.4), position=(0, 0.22), material=wood)
    top = w.add_body(box(0.25), position=(offset, 0.9), material=wood)
    for _ in range(120):
        w.step()
    assert abs(top.angle) < 0.5 and abs(top.center_of_mass[1] - 0.525) < 3e-3
    assert abs(top.center_of_mass[0] - offset) < 0.01 and np.abs(top.velocities).max() < 1e-3


def test_a_jelly_block_stays_on_a_level_rigid_crate():
    # it slid off at 0.8 m/s under implicit Euler when the crate was a rigid stage's outline
    w = deforma.World(dt=1 / 60, sleep=False)  # (sleep off: the solver's own rest is measured)
    w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0))
    crate = w.add_body(deforma.mesh.box(((0, 0), (0.6, 0), (0.6, 0.4), (0, 0.4)), detail=2), position=(0, 0.2),
                       material=RIGID)
    jelly = w.add_body(deforma.mesh.box(((0, 0), (0.3, 0), (0.3, 0.2), (0, 0.2)), detail=6), position=(0.05, 0.55),
                       material=deforma.Material.preset("jelly"))
    for _ in range(240):
        w.step()
    assert abs(jelly.center_of_mass[0] - 0.05) < 5e-3 and 0.49 < jelly.center_of_mass[1] < 0.52
    assert np.hypot(*crate.velocity) < 1e-3 and np.abs(crate.center_of_mass - (0.0, 0.2)).max() < 1e-3


def test_a_jelly_block_on_a_rigid_crate_comes_to_rest_within_two_seconds():
    # its contact vertices buzzed at 5-80 mm/s until the soft vertices on the crate were swept
    # again after each pass over the rigid blocks
    w = deforma.World(dt=1 / 60, sleep=False)  # (sleep off: the solver's own rest is measured)
    w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0))
    w.add_body(deforma.mesh.box(((0, 0), (0.6, 0), (0.6, 0.4), (0, 0.4)), detail=2), position=(0, 0.2),
               material=RIGID)
    jelly = w.add_body(deforma.mesh.box(((0, 0), (0.3, 0), (0.3, 0.2), (0, 0.2)), detail=6), position=(0.05, 0.55),
                       material=deforma.Material.preset("jelly"))
    for _ in range(150):  # lands within half a second
        w.step()
    most = 0.0
    for _ in range(30):
        w.step()
        most = max(most, np.hypot(*jelly.velocities.T).max())
    assert most < 1e-3


@pytest.mark.parametrize("integrator", ["symplectic-euler", "implicit-euler", "implicit-bdf2", "xpbd"])
def test_a_soft_body_rests_on_a_rigid_box_under_every_integrator(integrator):
    w = deforma.World(dt=1 / 60, integrator=integrator, sleep=False)  # (sleep off: the solver's own rest is measured)
    w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0))
    crate = w.add_body(deforma.mesh.box(((0, 0), (0.6, 0), (0.6, 0.3), (0, 0.3)), detail=2), position=(0, 0.16),
                       material=RIGID)
    jelly = w.add_body(deforma.mesh.box(((0, 0), (0.3, 0), (0.3, 0.2), (0, 0.2)), detail=4), position=(0, 0.5),
                       material=deforma.Material.preset("jelly"))
    for _ in range(180):
        w.step()
    top = crate.positions[:, 1].max()
    assert jelly.positions[:, 1].min() > top - 0.01  # on it, not through it
    assert jelly.center_of_mass[1] < 0.5  # and it fell onto it
    assert np.abs(crate.center_of_mass - (0, 0.15)).max() < 0.01  # the crate carries it on the floor
    assert np.abs(jelly.velocity).max() < 0.05
    # world.contacts names the crate as a body, never as a collider past world.colliders
    c = w.contacts
    assert set(c.collider.tolist()) <= {-1, 0} and set(c.rigid_body.tolist()) <= {-1, 0}
    on_crate = c.vertex[c.rigid_body == 0]
    assert len(on_crate) and (on_crate >= jelly.vertex_slice.start).all()


def crate_and_ball(integrator: str, crate_density: float, ball: deforma.Material, speed: float = 3.0):
    """No gravity: a 74 kg soft ball at ``speed`` m/s into a 0.4 m rigid crate, hitting it
    below its centre (so it turns too)."""
    w = deforma.World(gravity=(0, 0), dt=1 / 60, integrator=integrator)
    crate = w.add_body(deforma.mesh.box(((0, 0), (0.4, 0), (0.4, 0.4), (0, 0.4)), detail=2), position=(0, 0),
                       material=deforma.Material("rigid", density=crate_density))
    jelly = w.add_body(disc(0.15, 40), position=(-0.6, 0.1), material=ball, velocity=(speed, 0.0))
    return w, crate, jelly


@pytest.mark.parametrize("integrator", ["symplectic-euler", "implicit-euler", "xpbd"])
def test_a_soft_body_pushes_a_rigid_one_keeping_linear_momentum(integrator):
    w, crate, ball = crate_and_ball(integrator, 100.0, deforma.Material.preset("jelly"))
    mass = rigid_set(w.model).mass[0]

    def momentum():
        return ball.vertex_masses @ ball.velocities + mass * crate.velocity

    p0 = momentum()
    for _ in range(60):
        w.step()
    assert crate.velocity[0] > 0.5  # it was pushed
    assert np.allclose(momentum(), p0, rtol=1e-9, atol=1e-9 * np.abs(p0).max())


UNDAMPED = deforma.Material("neo-hookean", youngs_modulus=3e4, poisson_ratio=0.45, density=1050.0)


@pytest.mark.parametrize("crate_density", [10.0, 100.0, 1000.0])  # a crate of 1.6, 16 and 160 kg
def test_angular_momentum_is_kept_and_energy_never_rises(crate_density):
    # symplectic Euler keeps a soft body's angular momentum exactly (its elastic forces have
    # no net torque at the positions they act from), so what the contact does shows alone;
    # the material is undamped because the corotated damping of a deformed, turning triangle
    # takes a little spin (2.5e-5 of a jelly disc's in a second)
    w, crate, ball = crate_and_ball("symplectic-euler", crate_density, UNDAMPED)
    rs = rigid_set(w.model)

    def cross(a, b):
        return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]

    def totals():
        center = rs.poses(w.model, w.state.x, w.state.v)[0][0]
        spin = math.radians(crate.angular_velocity)
        momentum = (ball.vertex_masses * cross(ball.positions, ball.velocities)).sum() \
            + rs.inertia[0] * spin + rs.mass[0] * cross(center, crate.velocity)
        e = w.energy(ball)
        energy = e.kinetic + e.elastic + 0.5 * rs.mass[0] * (crate.velocity @ crate.velocity) \
            + 0.5 * rs.inertia[0] * spin ** 2
        return momentum, energy

    l0, e0 = totals()
    most = e0
    for _ in range(120):
        w.step()
        l1, e1 = totals()
        most = max(most, e1)
    assert crate.velocity[0] > 0.5 and abs(crate.angular_velocity) > 10.0  # pushed and turned
    assert abs(l1 - l0) <= 1e-6 * abs(l0)
    assert most <= e0 * (1 + 1e-9)


@pytest.mark.parametrize("integrator,crate_density,gain", [
    pytest.param("implicit-euler", 10.0, 0.0, marks=pytest.mark.xfail(
        strict=False, reason="a 1.6 kg crate against a 74 kg ball under implicit Euler: +5.5 % on the machine CI "
                             "ran on at 116603c, none on another (the rounding of a hard contact; issue 35)")),
    ("implicit-euler", 100.0, 1e-9),
    ("implicit-euler", 1000.0, 0.01),  # +0.6 %: the contact penalty of the solve
    ("xpbd", 100.0, 1e-9),
    pytest.param("xpbd", 1000.0, 1e-9, marks=pytest.mark.xfail(strict=True, reason="XPBD gains 2 % here (issue 35)")),
])
def test_a_position_based_solver_gains_no_energy_from_a_rigid_body(integrator, crate_density, gain):
    # these meet rigid outlines between substeps, so "auto" takes them no longer than 1/240 s;
    # at one 1/60 s step the ball went 5 cm into the crate and bounced off with 22 % more energy
    w, crate, ball = crate_and_ball(integrator, crate_density, UNDAMPED)
    assert w.substeps == 4
    rs = rigid_set(w.model)

    def energy():
        e = w.energy(ball)
        return e.kinetic + e.elastic + 0.5 * rs.mass[0] * (crate.velocity @ crate.velocity) \
            + 0.5 * rs.inertia[0] * math.radians(crate.angular_velocity) ** 2

    e0 = most = energy()
    for _ in range(120):
        w.step()
        most = max(most, energy())
    assert most <= e0 * (1 + gain)


@pytest.mark.xfail(strict=False, reason=(
    "blows up at step 33 on this machine since before 602c4e3: the implicit solve's contact planes push a crate "
    "by its own inner vertices (rigid_plane_impulses) and recoil_planes counts only the touching vertices' mass, "
    "so the donut pinched under a crate kicks it to 5e3 m/s; the rigid side stage is retired by issue 49"))
def test_a_stiff_body_thrown_hard_into_rigid_crates_stays_whole():
    # a rubber donut at 5 m/s into the crates scene's pyramid, under implicit Euler: met only
    # after the solve, its front folded over the crates and ran away at step 89
    import dataclasses

    from deforma.physics.elements.triangles import signed_areas

    scene = deforma.scene.load("crates")
    donut = dataclasses.replace(scene.body[6], resolution=8, velocity=(5.0, 1.5), material="rubber")
    w = dataclasses.replace(scene, body=scene.body[:6] + (donut,)).build()
    for _ in range(240):
        w.step()
    body = w.bodies[-1]
    assert np.isfinite(body.positions).all()
    # a few slivers squeezed under the crates may stay folded, as against fixed boxes in their
    # place (2 there: implicit Euler's hard impacts are issue 34's); the 3438 others are not
    assert (signed_areas(body.positions, body.triangles) <= 0).sum() <= 3
    assert max(abs(c.center_of_mass[0] - s.position[0]) for c, s in zip(w.bodies[:6], scene.body)) > 0.3  # knocked


def test_force_and_impulse_move_a_rigid_body_as_a_whole():
    w = deforma.World(gravity=(0, 0), dt=0.01)
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2), material=RIGID)  # 100 kg
    b.apply_force((200.0, 0.0))
    w.step()
    assert np.allclose(b.velocity, (0.02, 0.0)) and abs(b.angular_velocity) < 1e-9
    b.apply_impulse((0.0, 100.0))
    assert np.allclose(b.velocity, (0.02, 1.0))
    # an impulse off the centre turns it: I = m (1 + 1) / 12, 10 N s at 0.5 m -> 5 N m s
    right = np.flatnonzero(np.isclose(b.positions[:, 0], b.center_of_mass[0] + 0.5)
                           & np.isclose(b.positions[:, 1], b.center_of_mass[1]))
    if len(right):
        b.apply_impulse([[0.0, 10.0]], indices=right[:1])
        assert b.angular_velocity == pytest.approx(math.degrees(5.0 / (100 * 2 / 12)), rel=1e-9)
    b.pin([0])  # held at one vertex, held whole
    assert np.abs(b.velocities).max() == 0.0
    w.gravity = (0.0, -9.81)
    b.apply_impulse((5.0, 0.0))
    before = b.positions.copy()
    w.step()
    assert np.allclose(b.positions, before, rtol=0, atol=1e-12)
    b.unpin()
    w.step()
    assert b.velocity[1] < 0.0


def test_a_scene_body_of_material_rigid_falls_and_lands_flat(tmp_path):
    p = tmp_path / "crate.toml"
    p.write_text("""
[physics]
dt = 0.016666666666666666
[[collider]]
center = [0, -0.5]
size = [10, 1]
[[body]]
detail = 2
material = "rigid"
density = 100
position = [0, 0.8]
angle = 30
""")
    w = deforma.load_scene(p)
    w.sleep = False  # (sleep off: the solver's own rest is measured)
    crate = w.bodies[0]
    assert crate.material.is_rigid and crate.angle == pytest.approx(30)
    for _ in range(180):
        w.step()
    assert abs(crate.angle) % 90 < 0.5 or abs(crate.angle) % 90 > 89.5  # on a face, not a corner
    assert np.abs(crate.velocity).max() < 1e-3


@pytest.mark.parametrize("body, message", [
    ('material = "rigid"\ndensity = 10\ntear_strain = 0.5',
     "body[0].tear_strain: the 'rigid' material takes density only, not tear_strain"),
    ('material = "rigid"\ndensity = 10\nyoungs_modulus = 1e5',
     "body[0].youngs_modulus: the 'rigid' material takes density only, not youngs_modulus"),
    ('material = "rigid"', "body[0]: the 'rigid' material needs density (kg/m^2)"),
])
def test_a_rigid_scene_body_with_deformation_keys_is_refused_in_one_line(tmp_path, body, message):
    p = tmp_path / "bad.toml"
    p.write_text(f"[[body]]\n{body}\n")
    with pytest.raises(deforma.scene.SceneError) as e:
        deforma.load_scene(p)
    assert message in str(e.value) and "\n" not in str(e.value)

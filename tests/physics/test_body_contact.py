"""Bodies touch each other and themselves: known answers, and the invariants checked at every step.

The invariants (no two outline segments cross; no vertex inside another body) are checked by
tests/physics/contact_checks.py, written apart from the contact stage, with exact
orientation signs where it matters.
"""

import math

import numpy as np
import pytest

import deforma
from deforma.physics.elements.triangles import signed_areas
from deforma.physics.contact import contacts
from contact_checks import crossings, vertices_inside_other_bodies
from physics_meshes import grid_mesh, head_on, slide_acceleration

G = 9.81
ALL = ["symplectic-euler", "implicit-euler", "xpbd"]


def ring_mesh(r_in, r_out, n):
    """An annulus of two rings of ``n`` vertices (a donut one triangle thick)."""
    ang = np.linspace(0, 2 * np.pi, n, endpoint=False)
    v = np.concatenate([np.c_[r * np.cos(ang), r * np.sin(ang)] for r in (r_in, r_out)])
    t = []
    for k in range(n):
        a, b, c, d = k, (k + 1) % n, n + (k + 1) % n, n + k
        t += [[a, b, c], [a, c, d]]
    return deforma.mesh.Mesh(v, t)


def assert_apart(world, where=""):
    pairs, n = crossings(world)
    assert n == 0, (where, "outline segments cross", pairs[:2].tolist())
    inside = vertices_inside_other_bodies(world)
    assert len(inside) == 0, (where, "vertices inside another body", inside[:5].tolist())


# -- resting on each other ---------------------------------------------------------------------
@pytest.mark.parametrize("name", ALL)
def test_a_box_dropped_on_another_comes_to_rest_on_top(name):
    # air drag for the slow sway, which spring damping hardly touches (see the stack below);
    # sleep off: the solver's own rest is measured
    w = deforma.World(dt=1 / 600, substeps=6, stiffness=6000.0, damping=5.0, air_drag=1.0, integrator=name,
                      sleep=False)
    w.add_collider(deforma.Rect((0, -0.5), (6, 1.0), 0.0))
    # checkerboard diagonals: a one-diagonal lattice shears and walks sideways under load (a
    # property of the springs, not of the contact, and what the FEM materials remove)
    low = w.add_body(grid_mesh(1.0, 1.0, 9, 9, alternate=True), position=(0.0, 0.5))
    high = w.add_body(grid_mesh(1.0, 1.0, 9, 9, alternate=True), position=(0.1, 1.8))
    for k in range(int(3.0 / w.dt)):
        w.step()
        if k % 10 == 0:
            assert_apart(w, k)
    gap = high.positions[:, 1].min() - low.positions[:, 1].max()
    assert -0.02 < gap < 0.02  # on it: not through it, not hovering (boxes sag under load)
    assert high.center_of_mass[1] == pytest.approx(low.center_of_mass[1] + 1.0, abs=0.03)
    # it landed 10 cm off centre: its overhang droops over the lower box's corner and presses on
    # its side, which pushes the two apart a little (on a frictionless floor they separate)
    assert abs(high.center_of_mass[0] - low.center_of_mass[0]) < 0.2
    assert np.hypot(*w.state.v.T).max() < 0.02  # every vertex: at rest


def test_a_stack_of_five_boxes_rests():
    # Spring damping acts along springs and grows with frequency, so it barely touches the
    # stack's slow sway; air drag (1/s) damps it, as a real tower's material damping would.
    # Sleep off: the solver's own rest is measured.
    w = deforma.World(integrator="symplectic-euler", dt=1 / 600, substeps=12, stiffness=6000.0, damping=5.0,
                      air_drag=1.0, sleep=False)
    w.add_collider(deforma.Rect((0, -0.5), (10, 1.0), 0.0))
    boxes = [w.add_body(grid_mesh(1.0, 1.0, 9, 9), position=(0.02 * (k % 2), 0.55 + 1.05 * k)) for k in range(5)]
    for k in range(int(5.0 / w.dt)):
        w.step()
        if k % 50 == 0:
            assert_apart(w, k)
    assert np.hypot(*w.state.v.T).max() < 0.02  # every vertex, after 5 s
    settled = np.mean([b.center_of_mass for b in boxes], axis=0)
    for _ in range(int(5.0 / w.dt)):
        w.step()
    assert np.linalg.norm(np.mean([b.center_of_mass for b in boxes], axis=0) - settled) < 0.01
    assert [math.floor(b.center_of_mass[1]) for b in boxes] == [0, 1, 2, 3, 4]  # still a stack
    assert_apart(w)


# -- collisions: momentum and energy ------------------------------------------------------------
@pytest.mark.parametrize("name", ALL)
def test_head_on_collision_keeps_momentum_and_never_gains_energy(name):
    w, a, b = head_on(name, dt=1 / 1000, substeps=2)
    m = w.model.vertex_mass[:, None]
    p0 = (m * w.state.v).sum(axis=0)
    scale = (m * np.abs(w.state.v)).sum()
    energy = [w.energy().total]
    touched = False
    for k in range(600):
        w.step()
        touched |= len(w.contacts) > 0
        p = (m * w.state.v).sum(axis=0)
        assert np.abs(p - p0).max() < 1e-9 * scale, k
        energy.append(w.energy().total)
        assert_apart(w, k)
    assert touched and a.center_of_mass[0] < b.center_of_mass[0]  # they met and bounced apart
    e = np.array(energy)
    # damped springs and inelastic contacts: the total never rises (beyond round-off)
    assert np.diff(e).max() < 1e-9 * e[0]


# -- friction between bodies ---------------------------------------------------------------------
def plank_and_block(angle, *, mu_s, mu_d, damping, integrator="symplectic-euler", dt=1 / 2000, substeps=3):
    """A 2 m plank held on a slope by a grippy collider, and a 20 x 10 cm block on the plank.
    Both bodies use the coefficients given, so their contact does too (sqrt(mu mu) = mu).
    (Sleep off: a block that sticks is held by the solver itself, not put to sleep.)"""
    a = math.radians(angle)
    n, t = np.array([-math.sin(a), math.cos(a)]), np.array([math.cos(a), math.sin(a)])
    w = deforma.World(integrator=integrator, dt=dt, substeps=substeps, stiffness=2e4, damping=damping,
                      friction=mu_d, static_friction=mu_s, sleep=False)
    w.add_collider(deforma.Rect(tuple(-0.5 * n), (20, 1.0), angle, friction=2.0, static_friction=3.0))
    plank = w.add_body(grid_mesh(2.0, 0.1, 41, 3, angle=angle, center=tuple(0.05 * n + 0.5 * t)), mass=4.0)
    gap = 1.01 * max(plank.contact_thickness, 0.0)
    block = w.add_body(grid_mesh(0.2, 0.1, 6, 3, angle=angle, center=tuple((0.15 + gap) * n + 0.8 * t)))
    return w, plank, block, n, t


@pytest.mark.parametrize("step", [{}, {"integrator": "avbd", "dt": 1 / 60, "substeps": 1}],
                         ids=["symplectic-euler", "avbd"])
@pytest.mark.parametrize("angle, mu_s, mu_d, gently", [(20.0, 0.6, 0.3, True), (15.0, 0.5, 0.3, False)])
def test_a_block_on_another_body_on_a_slope_sticks_below_static_friction(angle, mu_s, mu_d, gently, step):
    # avbd at one step a frame: with friction on one side of a face-to-face contact only, it
    # held with that side's share of the normal load and slid at 1.5 m/s^2 at 15 degrees
    w, plank, block, n, t = plank_and_block(angle, mu_s=mu_s, mu_d=mu_d, damping=20.0, **step)
    if gently:  # as for a collider: weight set down over 0.3 s, since here tan a > mu_d
        g = np.array([0.0, -G])
        while w.time < 0.3:
            lam = min(w.time / 0.3, 1.0)
            w.gravity = tuple((g @ n) * n + lam * (g @ t) * t)
            w.step()
        w.gravity = tuple(g)
    for _ in range(int(0.5 / w.dt)):
        w.step()
    s0, t0 = (block.center_of_mass - plank.center_of_mass) @ t, w.time
    for _ in range(int(1.0 / w.dt)):
        w.step()
    creep = abs((block.center_of_mass - plank.center_of_mass) @ t - s0) / (w.time - t0)
    assert creep < 1e-3  # m/s
    assert_apart(w)


@pytest.mark.parametrize("angle, mu_s, mu_d", [(35.0, 0.5, 0.3), (30.0, 0.4, 0.1), (25.0, 0.0, 0.0)])
def test_a_block_slides_down_another_body_at_g_sin_minus_mu_cos(angle, mu_s, mu_d):
    w, plank, block, n, t = plank_and_block(angle, mu_s=mu_s, mu_d=mu_d, damping=2.0)
    plank_start = plank.center_of_mass @ t
    accel, _ = slide_acceleration(w, block, t, steps=int(0.8 / w.dt), after=0.3)  # down the slope is -t
    a = math.radians(angle)
    assert accel == pytest.approx(G * (math.sin(a) - mu_d * math.cos(a)), rel=0.15)
    assert abs(plank.center_of_mass @ t - plank_start) < 1e-3  # the plank itself held
    assert_apart(w)


def test_two_bodies_mix_their_coefficients_as_the_geometric_mean():
    w = deforma.World(friction=0.3, static_friction=0.5)
    w.add_collider(deforma.Rect((0, -0.5), (6, 1.0), 0.0))
    w.add_body(grid_mesh(1.0, 0.2, 9, 3), position=(0.0, 0.1), friction=0.2, static_friction=0.9)
    w.add_body(grid_mesh(0.4, 0.2, 5, 3), position=(0.0, 0.31), friction=0.8, static_friction=0.4)
    for _ in range(100):
        w.step()
    c = w.contacts
    body = c.collider == -1
    assert body.any() and (~body).any()
    assert np.allclose(c.friction[body], math.sqrt(0.2 * 0.8))
    assert np.allclose(c.static_friction[body], math.sqrt(0.9 * 0.4))
    assert np.allclose(c.friction[~body], 0.3) and np.allclose(c.static_friction[~body], 0.5)  # colliders: theirs


# -- self contact ------------------------------------------------------------------------------
def test_a_soft_ring_squashed_flat_does_not_pass_through_itself():
    runs = {}
    for self_collision in (False, True):
        w = deforma.World(integrator="symplectic-euler", dt=1 / 1000, substeps=4, stiffness=200.0, damping=0.5)
        w.add_collider(deforma.Rect((0, -0.5), (10, 1.0), 0.0))
        b = w.add_body(ring_mesh(0.4, 0.5, 48), position=(0, 0.6), self_collision=self_collision)
        first = None
        for k in range(3000):
            w.step()
            if first is None and crossings(w)[1]:
                first = k
        runs[self_collision] = (first, np.ptp(b.positions[:, 1]))
    assert runs[False][0] is not None  # without self contact it does fold through itself ...
    assert runs[True][0] is None  # ... with it, never
    assert runs[True][1] > 0.19  # two layers (5 cm each) and a gap, stacked: not merged into one


# -- speed: no tunnelling ----------------------------------------------------------------------
@pytest.mark.parametrize("name", ALL)
def test_a_fast_body_does_not_pass_through_a_thin_one(name):
    w = deforma.World(dt=1 / 600, substeps=4, gravity=(0, 0), stiffness=3000.0, damping=1.0, integrator=name)
    wall = w.add_body(grid_mesh(0.02, 1.0, 2, 11), position=(0.0, 0.0), mass=5.0)
    ball = w.add_body(grid_mesh(0.1, 0.1, 3, 3), position=(-0.3, 0.05), mass=0.1)
    ball.velocities = (80.0, 0.0)  # 3.3 cm per substep: more than the wall's 2 cm
    for k in range(120):
        w.step()
        assert_apart(w, k)  # the wall bends around the ball like a sheet, but nothing crosses
    assert ball.velocities[:, 0].mean() < 5.0  # stopped by the wall, which carries it along
    assert wall.velocities[:, 0].mean() > 0.5


@pytest.mark.parametrize("name", ALL)
def test_a_fast_vertex_does_not_jump_a_thin_collider(name):
    w = deforma.World(dt=1 / 600, gravity=(0, 0), integrator=name)
    w.add_collider(deforma.Rect((0.0, 0.0), (10.0, 0.02), 0.0))  # 2 cm thick
    b = w.add_body(grid_mesh(0.1, 0.1, 3, 3), position=(0.0, 0.3))
    b.velocities = (0.0, -100.0)  # 17 cm per step
    for _ in range(30):
        w.step()
        assert b.positions[:, 1].min() > 0.0


# -- the pile --------------------------------------------------------------------------------
def test_pile_scene_never_crosses_and_no_vertex_enters_another_body():
    # as shipped: avbd at 1/60 s, one step a frame (implicit Euler at 2 substeps before; at
    # 1/600 s before that)
    w = deforma.load_scene("pile")
    w.sleep = False  # (sleep off: the heap's own rest is measured)
    assert len(w.bodies) >= 12
    assert w.integrator == "avbd" and w.dt == pytest.approx(1 / 60) and w.substeps == 1
    steps = int(round(10.0 / w.dt))  # poured, landed and at rest: the scene's length
    for k in range(steps):
        if k == steps - 120:
            failsafe = w.integrator_stats["failsafe"]
        w.step()
        seg, n = crossings(w)
        assert n == 0, (k, seg[:2].tolist())
        inside = vertices_inside_other_bodies(w)
        assert len(inside) == 0, (k, inside[:5].tolist())
        if k % 200 == 0:  # exact orientation signs at sampled steps
            assert crossings(w, exact=True)[1] == 0, k
        if k % 20 == 0 or k == steps - 1:  # tests/scene/test_builtin_scenes.py's check, for the pile
            for b in w.bodies:
                x = b.positions
                assert np.isfinite(x).all() and np.isfinite(b.velocities).all()
                for c in w.colliders:
                    inside = c.contains(x)
                    assert not inside.any(), (k, c, x[inside][:3])
    heights = [b.center_of_mass[1] for b in w.bodies]
    assert max(heights) < 2.5  # poured in and settled into a heap, not stuck in the air
    # at rest: 2 mm/s measured (implicit Euler at 2 substeps: 0.04 m/s at 6 s; avbd 0.12 m/s
    # at 6 s, still settling, 0.018 at 8 s)
    assert max(np.abs(b.velocities).max() for b in w.bodies) < 0.01
    # held by the rows, the fail-safe almost never acting (it acted in each of the last 120
    # steps while a loaded row sank past its line in every step: avbd.rows.BODY_SINK)
    assert w.integrator_stats["failsafe"] - failsafe < 5
    # finite elements: the bottom of the heap keeps its shape (springs left folded triangles)
    assert not any((signed_areas(b.positions, b.triangles) <= 0).any() for b in w.bodies)


def test_dragging_one_body_into_another_pushes_it_rather_than_passing_through():
    w = deforma.World(integrator="symplectic-euler", dt=1 / 600, substeps=4, stiffness=3000.0, damping=2.0)
    w.add_collider(deforma.Rect((0, -0.5), (10, 1.0), 0.0))
    below = w.add_body(grid_mesh(3.0, 0.5, 25, 5), position=(0.0, 0.25))  # too wide to slip off
    held = w.add_body(grid_mesh(0.4, 0.4, 5, 5), position=(0.0, 1.2))
    g = w.grab(tuple(held.center_of_mass), strength=50.0, radius=0.3)  # the viewer's mouse
    for k in range(300):  # the mouse moves down through the lower body and out below the floor
        w.drag(g, (0.0, 1.2 - 2.0 * k / 300))
        w.step()
        assert_apart(w, k)
    # the pull (50 N/m on 25 vertices, 2 m down) presses the box deep into the soft slab, whose
    # material flows aside; at no step did one pass through the other
    assert held.center_of_mass[1] < 0.8 and below.positions[:, 1].max() > 0.55


def test_a_contact_buffer_too_small_grows_and_the_step_runs_again_from_its_start():
    def world():
        w = deforma.World(integrator="symplectic-euler", dt=1 / 600, substeps=4, stiffness=3000.0, damping=2.0)
        w.add_collider(deforma.Rect((0, -0.5), (6, 1.0), 0.0))
        for k in range(3):
            w.add_body(grid_mesh(0.6, 0.3, 9, 5), position=(0.05 * k, 0.16 + 0.32 * k))
        return w
    roomy, tight = world(), world()
    tight._contacts.buffer = contacts.make_buffer(16, 16)  # far fewer than these stacked bodies need
    for _ in range(100):
        roomy.step()
        tight.step()
    assert len(tight._contacts.buffer.pair_vertex) > 16 and len(tight._contacts.buffer.vertex) > 16
    assert np.array_equal(tight.state.x, roomy.state.x)  # the same steps, bit for bit


# -- switches and bad input ---------------------------------------------------------------------
def test_collide_off_lets_a_body_pass_through_others():
    w = deforma.World(integrator="symplectic-euler", dt=1 / 600, gravity=(0, 0))
    a = w.add_body(grid_mesh(0.5, 0.5, 5, 5), position=(0.0, 0.0))
    ghost = w.add_body(grid_mesh(0.3, 0.3, 4, 4), position=(-1.0, 0.0), collide=False)
    ghost.velocities = (3.0, 0.0)
    for _ in range(400):
        w.step()
    assert ghost.center_of_mass[0] > 1.0 and abs(a.center_of_mass[0]) < 1e-9  # went through untouched


@pytest.mark.parametrize("value, message", [
    (-0.01, "contact_thickness must be > 0"), (float("nan"), "contact_thickness must be finite"),
    (float("inf"), "contact_thickness must be finite"), (0.2, "not below the shortest boundary edge of body 0"),
])
def test_bad_contact_thickness_is_refused_and_nothing_changes(value, message):
    w = deforma.World()
    w.add_body(grid_mesh(1.0, 1.0, 6, 6), position=(0, 0))  # edges of 0.2 m
    before = w.contact_thickness
    with pytest.raises(ValueError, match=message):
        w.contact_thickness = value
    assert w.contact_thickness == before
    with pytest.raises(ValueError, match=message.replace("body 0", "the new body")):
        deforma.World(contact_thickness=value).add_body(grid_mesh(1.0, 1.0, 6, 6))


def test_a_body_placed_overlapping_another_is_refused_and_nothing_changes():
    w = deforma.World()
    w.add_body(grid_mesh(1.0, 1.0, 5, 5), position=(0, 0))
    x = w.state.x.copy()
    with pytest.raises(ValueError, match=r"the new body \(1\) would overlap body 0"):
        w.add_body(grid_mesh(1.0, 1.0, 5, 5), position=(0.5, 0.5))
    with pytest.raises(ValueError, match="would overlap body 0"):  # inside it counts too
        w.add_body(grid_mesh(0.2, 0.2, 3, 3), position=(0, 0))
    assert len(w.bodies) == 1 and np.array_equal(w.state.x, x)
    ghost = w.add_body(grid_mesh(0.2, 0.2, 3, 3), position=(0, 0), collide=False)  # allowed: it passes through
    with pytest.raises(ValueError, match="would overlap body 0"):
        ghost.collide = True
    assert ghost.collide is False
    other = w.add_body(grid_mesh(0.2, 0.2, 3, 3), position=(2, 0))
    x = w.state.x.copy()
    with pytest.raises(ValueError, match="body 2 would overlap body 0"):  # moved into it by hand
        other.positions = other.positions - (2.0, 0.0)
    assert np.array_equal(w.state.x, x)
    other.positions = other.positions + (0.5, 0.0)  # clear of it: fine

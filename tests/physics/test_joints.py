"""Joints between rigid bodies and the world (``World.join``) against known answers, at 1/60 s."""

import math

import numpy as np
import pytest
from scipy.special import ellipk

import deforma
from physics_meshes import chain

G = 9.81
RIGID = deforma.Material("rigid", density=100.0)


def bar(w, x0, y0, length=1.0, width=0.05, material=RIGID):
    """A rigid bar from (x0, y0) along +x."""
    m = deforma.mesh.box(((0, 0), (length, 0), (length, width), (0, width)), detail=2)
    return w.add_body(m, position=(x0 + length / 2, y0), material=material)


def swing_period(w, body, seconds):
    """The mean period (s) of ``body``'s swing about hanging straight down (-90 degrees), from
    its upward crossings of it, and the swing (degrees from hanging) at every step."""
    t, a = [], []
    for _ in range(round(seconds / w.dt)):
        w.step()
        t.append(w.time)
        a.append(body.angle + 90.0)
    t, a = np.array(t), np.array(a)
    up = np.flatnonzero((a[:-1] < 0) & (a[1:] >= 0))
    cross = t[up] + (t[up + 1] - t[up]) * (-a[up]) / (a[up + 1] - a[up])
    return float(np.mean(np.diff(cross))), a


def pendulum_period(length, width, amplitude_deg):
    """A bar hinged at the middle of an end: the compound pendulum's period at this amplitude."""
    inertia = (length ** 2 + width ** 2) / 12 + (length / 2) ** 2  # per unit mass, about the hinge
    t0 = 2 * math.pi * math.sqrt(inertia / (G * length / 2))
    return t0 * 2 / math.pi * ellipk(math.sin(math.radians(amplitude_deg) / 2) ** 2)


@pytest.mark.parametrize("amplitude", [10.0, 60.0])
def test_a_bar_hinged_to_the_world_swings_as_a_compound_pendulum(amplitude):
    # a 1 m bar hinged at the middle of its end, let go at `amplitude` degrees from hanging
    w = deforma.World(dt=1 / 60)
    start = -90.0 + amplitude
    m = deforma.mesh.box(((0, -0.025), (1, -0.025), (1, 0.025), (0, 0.025)), detail=2)
    c, s = math.cos(math.radians(start)), math.sin(math.radians(start))
    body = w.add_body(m, position=(0.5 * c, 0.5 * s), angle=start, material=RIGID)
    hinge = w.join(body, None, at=(0.0, 0.0))
    period, angle = swing_period(w, body, 8.0)
    assert period == pytest.approx(pendulum_period(1.0, 0.05, amplitude), rel=0.02)
    assert np.abs(angle[-120:]).max() == pytest.approx(amplitude, rel=0.02)  # it keeps its swing
    assert np.hypot(*hinge.force) > 0


def test_two_rigid_bars_pinned_together_swing_as_a_compound_pendulum():
    w = deforma.World(dt=1 / 60)
    holder = bar(w, -1.03, 0.025)  # its end 3 cm short of the hinge, clear of the swinging bar's corners
    holder.pin([0])  # held whole
    m = deforma.mesh.box(((0, -0.025), (1, -0.025), (1, 0.025), (0, 0.025)), detail=2)
    start = -90.0 + 20.0
    c, s = math.cos(math.radians(start)), math.sin(math.radians(start))
    swinging = w.add_body(m, position=(0.5 * c, 0.025 + 0.5 * s), angle=start, material=RIGID)
    w.join(swinging, holder, at=(0.0, 0.025))
    period, _ = swing_period(w, swinging, 8.0)
    assert period == pytest.approx(pendulum_period(1.0, 0.05, 20.0), rel=0.02)
    assert np.allclose(holder.center_of_mass, (-0.53, 0.025))


def test_a_hanging_bar_at_rest_pulls_its_hinge_with_its_weight():
    w = deforma.World(dt=1 / 60, sleep=False)  # (sleep off: the solver's own rest is measured)
    m = deforma.mesh.box(((0, -0.025), (1, -0.025), (1, 0.025), (0, 0.025)), detail=2)
    body = w.add_body(m, position=(0.0, -0.5), angle=-90.0, material=RIGID)
    hinge = w.join(body, None, at=(0.0, 0.0))
    for _ in range(60):
        w.step()
    weight = body.mass * G
    assert hinge.force == pytest.approx((0.0, weight), rel=1e-3, abs=1e-6 * weight)
    assert abs(body.angle + 90.0) < 0.01


def test_a_weld_holds_a_cantilever_level_and_carries_its_moment():
    w = deforma.World(dt=1 / 60, sleep=False)  # (sleep off: the solver's own rest is measured)
    wall = bar(w, -0.2, -0.5, length=0.2, width=1.0)
    wall.pin([0])
    arm = bar(w, 0.001, 0.0)
    weld = w.join(arm, wall, at=(0.0, 0.0), kind="weld")
    for _ in range(120):
        w.step()
    assert abs(arm.angle) < 0.05 and np.abs(arm.center_of_mass - (0.501, 0.0)).max() < 1e-3
    weight = arm.mass * G
    assert weld.force == pytest.approx((0.0, weight), rel=1e-3, abs=1e-6 * weight)
    # the weld's torque and its force's moment about the arm's centre (0.501 m from the weld,
    # which pulls up there) hold the arm level: torque - 0.501 m * weight = 0
    assert weld.torque == pytest.approx(weight * 0.501, rel=0.02)


def test_a_motor_spins_a_wheel_at_its_speed_and_no_faster_than_its_torque_allows():
    w = deforma.World(gravity=(0, 0), dt=1 / 60)
    a = np.arange(48) * 2 * np.pi / 48
    pts = np.vstack([np.column_stack([np.cos(a), np.sin(a)]) * 0.3, [[0.0, 0.0]]])
    wheel = w.add_body(deforma.mesh.Mesh(pts, deforma.delaunay(pts)), position=None, material=RIGID)
    j = w.join(wheel, None, at=(0.0, 0.0), motor_speed=90.0)
    for _ in range(30):
        w.step()
    assert wheel.angular_velocity == pytest.approx(90.0, rel=1e-6)
    # a bounded torque accelerates at torque / inertia
    inertia = wheel.mass * 0.3 ** 2 / 2 * 0.99  # the 48-gon's is a little under the disc's
    j.max_torque = 0.5
    j.motor_speed = 1e4
    before = wheel.angular_velocity
    w.step()
    gain = math.radians(wheel.angular_velocity - before) / w.dt
    assert gain == pytest.approx(0.5 / inertia, rel=0.02)


def test_a_weight_on_a_spring_stretches_it_by_mg_over_k_and_bounces_at_its_frequency():
    w = deforma.World(dt=1 / 60)
    m = deforma.mesh.box(((0, 0), (0.2, 0), (0.2, 0.2), (0, 0.2)), detail=2)
    weight = w.add_body(m, position=(0.0, -0.1), material=RIGID)  # 4 kg, its top at the origin
    k = 400.0
    spring = w.join(weight, None, at=(0.0, 0.0), kind="spring", stiffness=k)
    y = []
    for _ in range(240):
        w.step()
        y.append(weight.center_of_mass[1])
    y = np.array(y)
    mass = weight.mass
    # the mean of the swing is the static stretch below the start
    assert np.mean(y[-120:]) + 0.1 == pytest.approx(-mass * G / k, rel=0.02)
    a = y - np.mean(y)
    up = np.flatnonzero((a[:-1] < 0) & (a[1:] >= 0))
    assert np.mean(np.diff(up)) * w.dt == pytest.approx(2 * math.pi * math.sqrt(mass / k), rel=0.03)
    assert np.hypot(*spring.force) > 0


def test_a_chain_of_twenty_links_holds_a_weight_of_a_thousand_links():
    # the mass ratio a block sweep finds hardest: 0.196 kg links, a 196 kg weight
    w = deforma.World(dt=1 / 60, sleep=False)  # (sleep off: the solver's own rest is measured)
    weight, joint = chain(w, 20, 1000.0, RIGID)
    assert weight.mass == pytest.approx(1000 * w.bodies[0].mass)
    top0 = weight.center_of_mass[1]
    stretch, force = [], []
    for _ in range(300):
        w.step()
        stretch.append((top0 - weight.center_of_mass[1]) / 2.0)  # of the chain's 2 m
        force.append(joint.force[1])
    assert np.abs(stretch).max() < 0.01
    assert abs(weight.center_of_mass[0]) < 0.01  # it hangs straight
    # the last joint carries the weight: over the last second on average (step by step it
    # varies by 8 %, the weight buzzing at 1.3 cm/s)
    assert np.mean(force[-60:]) == pytest.approx(weight.mass * G, rel=0.01)


def test_a_chain_of_twenty_equal_links_hangs_straight_and_carries_its_weight():
    w = deforma.World(dt=1 / 60, sleep=False)  # (sleep off: the solver's own rest is measured)
    weight, joint = chain(w, 20, 1.0, RIGID)
    y0 = weight.center_of_mass[1]
    for _ in range(300):
        w.step()
    assert abs(weight.center_of_mass[1] - y0) < 1e-4 and abs(weight.center_of_mass[0]) < 1e-6
    assert joint.force[1] == pytest.approx(weight.mass * G, rel=0.05)


def test_two_free_bodies_pinned_together_keep_their_momentum():
    # no gravity: what the pin moves between them is theirs; BDF2 (the bodies' scheme away
    # from contacts) keeps the linear momentum exactly and the angular within its error
    w = deforma.World(dt=1 / 60, gravity=(0, 0))
    m = deforma.mesh.box(((0, -0.025), (1, -0.025), (1, 0.025), (0, 0.025)), detail=2)
    a = w.add_body(m, position=(0.5, 0.0), material=RIGID, velocity=(0.0, 1.0))
    b = w.add_body(m, position=(-0.5, 0.0), angle=30.0, material=RIGID, angular_velocity=200.0, velocity=(0.3, -0.5))
    hinge = w.join(a, b, at=(0.0, 0.0))

    def momentum():
        from deforma.physics.rigid.stage import rigid_set  # the bodies' true moments of inertia
        inertia = rigid_set(w.model).inertia
        p, spin = np.zeros(2), 0.0
        for k, body in enumerate((a, b)):
            c, v = body.center_of_mass, np.asarray(body.velocity)
            p += body.mass * v
            spin += body.mass * (c[0] * v[1] - c[1] * v[0]) + inertia[k] * math.radians(body.angular_velocity)
        return p, spin

    p0, spin0 = momentum()
    for _ in range(300):
        w.step()
        p, spin = momentum()
        assert np.abs(p - p0).max() < 1e-6 * np.abs(p0).max()
        assert abs(spin - spin0) < 5e-3 * abs(spin0)
        assert np.hypot(*(hinge.point - b.center_of_mass)) == pytest.approx(0.5, abs=1e-4)  # held


@pytest.mark.parametrize("integrator", ["avbd", "implicit-euler"])
def test_a_joint_breaks_past_its_break_force_and_not_before(integrator):
    # a hanging bar pulls its hinge with its weight (4.9 N): a joint rated above it holds, one
    # rated below it breaks in the first step that pulls harder, and the bar falls (sleep off:
    # the held bar's rest is the solver's own)
    w = deforma.World(dt=1 / 60, integrator=integrator, sleep=False)
    m = deforma.mesh.box(((0, -0.025), (1, -0.025), (1, 0.025), (0, 0.025)), detail=2)
    strong = w.add_body(m, position=(0.0, -0.5), angle=-90.0, material=RIGID)
    weak = w.add_body(m, position=(2.0, -0.5), angle=-90.0, material=RIGID)
    weight = strong.mass * G
    holds = w.join(strong, None, at=(0.0, 0.0), break_force=1.2 * weight)
    breaks = w.join(weak, None, at=(2.0, 0.0), break_force=0.8 * weight)
    assert (holds.break_force, holds.broken) == (1.2 * weight, False)
    for _ in range(60):
        w.step()
    assert w.joints == [holds] and not holds.broken and breaks.broken
    assert abs(strong.center_of_mass[1] + 0.5) < 1e-3
    assert weak.center_of_mass[1] < -0.5 - 0.5 * G * 0.9 ** 2  # falling freely since the first steps
    with pytest.raises(ValueError, match="unknown joint"):
        w.remove_joint(breaks)


def test_a_scene_joint_keeps_its_break_force(tmp_path):
    p = tmp_path / "hinge.toml"
    p.write_text(SCENE + "[[joint]]\na = 0\nat = [0, 0]\nbreak_force = 250.5\n")
    (j,) = deforma.load_scene(p).joints
    assert j.break_force == 250.5
    (k,) = deforma.load_scene(deforma.scene.save_scene(deforma.load_scene(p), tmp_path / "again.toml")).joints
    assert k.break_force == 250.5


def test_removing_a_joint_or_a_body_lets_go():
    w = deforma.World(dt=1 / 60)
    b = bar(w, 0.0, 0.0)
    j = w.join(b, None, at=(0.0, 0.02))
    assert w.joints == [j]
    w.remove_joint(j)
    assert w.joints == []
    for _ in range(10):
        w.step()
    assert b.velocity[1] < -1.0  # falling freely
    j2 = w.join(b, None, at=tuple(b.center_of_mass))
    w.remove_body(b)
    assert w.joints == []
    with pytest.raises(ValueError, match="unknown joint"):
        w.remove_joint(j2)


@pytest.mark.parametrize("call, message", [
    (lambda w, a, b, s: w.join(a, b, at=(5.0, 5.0)), r"at = \(5.0, 5.0\) is not on body 0 or body 1"),
    (lambda w, a, b, s: w.join(a, a, at=(0.1, 0.02)), "a joint between body 0 and itself holds nothing"),
    (lambda w, a, b, s: w.join(s, None, at=(0.1, 3.0), kind="weld"),
     r"a weld holds a rigid body's turn, and a \(body 2\) is soft: join a soft body with pins or springs"),
    (lambda w, a, b, s: w.join(a, s, at=(0.1, 3.0), motor_speed=30.0),
     r"a motor holds a rigid body's turn, and b \(body 2\) is soft"),
    (lambda w, a, b, s: w.join(a, s, at=(0.1, 0.02)), r"at = \(0.1, 0.02\) is not on b \(body 2\), a soft body"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), kind="hinge"), "kind must be one of pin, weld, spring"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), kind="spring"), "a spring joint needs stiffness"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), kind="weld", motor_speed=10.0),
     "motor_speed is for a pin joint"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), max_torque=1.0), "max_torque needs motor_speed"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), stiffness=10.0), "stiffness is for kind='spring'"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, math.nan)), "at must be a pair of finite numbers"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), motor_speed=10.0, max_torque=-1.0),
     "max_torque must be"),
    (lambda w, a, b, s: w.join(a, None), "at must be the point"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), break_force=0.0), "break_force must be"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), break_force=math.inf), "break_force must be"),
    (lambda w, a, b, s: w.join(a, None, at=(10**400, 0)),
     "at must be a pair of finite numbers, got a number too large"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), kind="spring", stiffness=10**400),
     "stiffness must be finite, got an integer of 401 digits"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), kind="spring", stiffness=1.0, damping=10**400),
     "damping must be finite, got an integer of 401 digits"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), motor_speed=-10**400),
     "motor_speed must be finite, got an integer of 401 digits"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), motor_speed=10.0, max_torque=10**400),
     "max_torque must be finite, got an integer of 401 digits"),
    # past Python's int-to-str limit (4300 digits) the line still names the argument
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 0.02), kind="spring", stiffness=10**5000),
     "stiffness must be finite, got an integer of more than 4300 digits"),
    (lambda w, a, b, s: w.join(a, None, at=(0.1, 10**5000)), "at must be a pair of finite numbers"),
])
def test_bad_joints_are_refused_in_one_line_changing_nothing(call, message):
    w = deforma.World(dt=1 / 60)
    a = bar(w, 0.0, 0.0)
    b = bar(w, 0.0, 1.0)
    soft = bar(w, 0.0, 3.0, material=deforma.Material.preset("jelly"))
    with pytest.raises(ValueError, match=message) as e:
        call(w, a, b, soft)
    assert "\n" not in str(e.value) and w.joints == []


@pytest.mark.parametrize("name", ["motor_speed", "max_torque"])
def test_a_huge_motor_setting_is_refused_in_one_line_keeping_the_motor(name):
    w = deforma.World(dt=1 / 60)
    j = w.join(bar(w, 0.0, 0.0), None, at=(0.1, 0.02), motor_speed=10.0, max_torque=5.0)
    with pytest.raises(ValueError, match=f"{name} must be finite, got an integer of 401 digits") as e:
        setattr(j, name, 10**400)
    assert "\n" not in str(e.value) and (j.motor_speed, j.max_torque) == (10.0, 5.0)


SCENE = """
[physics]
dt = 0.016666666666666666
[[body]]
corners = [[0, 0], [1, 0], [1, 0.05], [0, 0.05]]
detail = 2
position = [0.5, 0]
material = "rigid"
density = 100
[[body]]
corners = [[0, 0], [0.3, 0], [0.3, 0.3], [0, 0.3]]
detail = 2
position = [0, 3]
"""


def test_a_scene_joint_hinges_its_bar_and_saves_with_the_scene(tmp_path):
    p = tmp_path / "hinge.toml"
    p.write_text(SCENE + "[[joint]]\na = 0\nat = [0, 0]\nmotor_speed = -30\nmax_torque = 1000\n")
    w = deforma.load_scene(p)
    (j,) = w.joints
    assert (j.kind, j.b, j.anchor, j.motor_speed, j.max_torque) == ("pin", None, (0.0, 0.0), -30.0, 1000.0)
    for _ in range(30):
        w.step()
    assert w.bodies[0].angular_velocity == pytest.approx(-30.0, rel=1e-6)  # the motor holds it against gravity
    saved = deforma.scene.save_scene(w, tmp_path / "again.toml")
    (k,) = deforma.load_scene(saved).joints
    assert (k.kind, k.b, k.anchor, k.motor_speed, k.max_torque) == ("pin", None, (0.0, 0.0), -30.0, 1000.0)


@pytest.mark.parametrize("joint, message", [
    ("at = [0, 0]", "joint[0].a: missing: the body the joint holds"),
    ("a = 0\nb = 5\nat = [0, 0]", "joint[0].b: there is no body 5: the scene has 2 [[body]] tables"),
    ("a = 0\nb = 0\nat = [0, 0]", "joint[0].b: a joint between body 0 and itself holds nothing"),
    ("a = 0", "joint[0].at: missing: the point both hold"),
    ("a = 0\nat = [3, 3]", r"joint[0]: at = (3.0, 3.0) is not on body 0"),
    ("a = 1\nat = [0, 3]\nkind = \"weld\"", "joint[0]: a weld holds a rigid body's turn, and a (body 1) is soft"),
    ("a = 0\nat = [0, 0]\nkind = \"hinge\"", "joint[0].kind"),
    ("a = 0\nat = [0, 0]\nkind = \"spring\"", "joint[0]: a spring joint needs stiffness"),
    # TOML integers are unbounded: one beyond any float is refused where it is read, not an OverflowError
    ("a = 0\nat = [1" + "0" * 400 + ", 0]", "joint[0].at[0]: expected a finite number, got an integer of 401 digits"),
    ("a = 0\nat = [0, 0]\nkind = \"spring\"\nstiffness = 1" + "0" * 400, "joint[0].stiffness: expected a finite"),
    ("a = 0\nat = [0, 0]\nkind = \"spring\"\nstiffness = 1\ndamping = -1" + "0" * 400,
     "joint[0].damping: expected a finite"),
    ("a = 0\nat = [0, 0]\nmotor_speed = 1" + "0" * 400, "joint[0].motor_speed: expected a finite"),
    ("a = 0\nat = [0, 0]\nmotor_speed = 1\nmax_torque = 1" + "0" * 400, "joint[0].max_torque: expected a finite"),
    ("a = 0\nat = [0, 0]\nbreak_force = -1", "joint[0].break_force"),
])
def test_a_bad_scene_joint_is_refused_in_one_line_naming_it(tmp_path, joint, message):
    p = tmp_path / "bad.toml"
    p.write_text(SCENE + "[[joint]]\n" + joint + "\n")
    with pytest.raises(deforma.scene.SceneError) as e:
        deforma.load_scene(p)
    assert message in str(e.value) and "\n" not in str(e.value)


def test_a_jointed_body_cannot_be_made_soft_where_its_joint_cannot_hold_it_soft():
    # a weld holds a turn (refused on a soft body), and under implicit Euler no joint holds one
    for kind, integrator in (("weld", "avbd"), ("pin", "implicit-euler")):
        w = deforma.World(dt=1 / 60, material=RIGID, integrator=integrator)
        b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 0.05), (0, 0.05)), detail=2), position=(0.5, 0.0))
        w.join(b, None, at=(0.0, 0.0), kind=kind)
        for change in (lambda: setattr(b, "material", deforma.Material.preset("jelly")),
                       lambda: setattr(w, "material", deforma.Material.preset("jelly")),
                       lambda: setattr(w, "material", None)):
            with pytest.raises(ValueError, match="is held by a joint .* cannot hold it soft: .* remove the joint "
                                                 "first") as e:
                change()
            assert "\n" not in str(e.value) and b.material == RIGID
        w.material = deforma.Material("rigid", density=50.0)  # rigid to rigid is fine
        w.remove_joint(w.joints[0])
        b.material = deforma.Material.preset("jelly")
        assert not b.material.is_rigid


def test_a_pinned_rigid_bar_made_soft_hangs_on_by_its_triangle():
    w = deforma.World(dt=1 / 60, material=RIGID)
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 0.05), (0, 0.05)), detail=4), position=(0.5, 0.0))
    j = w.join(b, None, at=(0.05, 0.0))
    for _ in range(10):
        w.step()
    b.material = deforma.Material("corotated", youngs_modulus=1e6, poisson_ratio=0.3, density=100.0)
    for _ in range(120):
        w.step()
    assert np.abs(j.point - (0.05, 0.0)).max() < 1e-3 and b.center_of_mass[1] < -0.3  # swung down, held


def test_the_picture_shows_a_dot_where_each_joint_is(gl_ctx):
    from deforma.render import Renderer, WorldView

    w = deforma.World(dt=1 / 60)
    b = bar(w, 0.0, 0.0)
    j = w.join(b, None, at=(0.0, 0.0))
    for _ in range(20):
        w.step()
    assert np.hypot(*j.point) < 1e-6  # the hinge stays at the origin as the bar swings
    r = Renderer(gl_ctx, (320, 180), samples=0)
    img = WorldView(r, w).draw().astype(int)
    col, row = np.floor(r.camera.world_to_pixel(j.point[None], r.size)[0]).astype(int)
    assert np.abs(img[row, col] - (0xF4, 0xF1, 0xDE)).max() < 16  # the light centre
    assert img[row, col + 4].max() < 80  # the dark rim (#1d2433, shaded as bodies are)
    r.release()

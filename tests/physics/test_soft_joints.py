"""Joints on soft bodies (``World.join`` with a soft side): a pin or a spring holds the
triangle under its point by its barycentric weights, as rows of avbd's sweep."""

import numpy as np
import pytest

import deforma
from deforma.mesh import box
from deforma.physics.elements.triangles import signed_areas

G = 9.81
LINK = deforma.Material("corotated", youngs_modulus=3e5, poisson_ratio=0.35, density=400.0, damping=0.02)
L, H = 0.3, 0.05


def link(w, x0, material=LINK):
    """A soft 0.3 m x 0.05 m link from (x0, 0) along +x, not colliding (links overlap at their pins)."""
    return w.add_body(box(((0, 0), (L, 0), (L, H), (0, H)), detail=6), position=(x0 + L / 2, 0.0),
                      material=material, collide=False)


def energy(w):
    """Kinetic plus gravitational energy (J) of every body (the elastic energy, >= 0, left out)."""
    return sum(0.5 * (b.vertex_masses * (b.velocities ** 2).sum(1)).sum()
               + G * (b.vertex_masses * b.positions[:, 1]).sum() for b in w.bodies)


def gap(j):
    """How far apart the joint's two sides hold it now (m)."""
    return float(np.hypot(*(j._side_point(0) - j._side_point(1))))


def test_a_jelly_hung_by_a_pin_hangs_there_and_the_pin_carries_its_weight():
    w = deforma.World(dt=1 / 60, sleep=False)  # (sleep off: the solver's own rest is measured)
    jelly = w.add_body(box(((0, 0), (0.2, 0), (0.2, 0.2), (0, 0.2)), detail=3), position=(0.0, 0.0),
                       material=deforma.Material.preset("jelly"))
    top = w.join(jelly, None, at=(0.0, 0.1))
    for _ in range(120):
        w.step()
    assert np.abs(top.point - (0.0, 0.1)).max() < 1e-4
    assert top.force == pytest.approx((0.0, jelly.mass * G), abs=1e-3 * jelly.mass * G)
    assert np.abs(jelly.velocities).max() < 1e-3  # at rest, hanging
    assert (signed_areas(jelly.positions, jelly.triangles) > 0).all()


def test_two_soft_links_swing_as_a_double_pendulum_without_gaining_energy():
    # released level: the hinge between them holds, the energy never rises above the start
    # (BE dissipates; an unconverged coupling of the two triangles gained 7-9 J here)
    w = deforma.World(dt=1 / 60)
    a, b = link(w, 0.0), link(w, 0.26)
    w.join(a, None, at=(0.02, 0.0))
    hinge = w.join(a, b, at=(0.28, 0.0))
    e0, gaps = energy(w), []
    for _ in range(300):
        w.step()
        assert energy(w) <= e0 + 1e-6
        gaps.append(gap(hinge))
    assert max(gaps) < 1e-3 and gaps[-1] < 1e-4
    assert energy(w) < e0 - 20.0  # it swung down (and its damping took some)
    assert np.hypot(*hinge.force) == pytest.approx(b.mass * G, rel=0.1)  # swinging slowly, hanging b
    for body in (a, b):
        assert (signed_areas(body.positions, body.triangles) > 0).all()


def test_a_soft_link_holds_a_rigid_weight_at_its_pin():
    w = deforma.World(dt=1 / 60)
    a = link(w, 0.0)
    w.join(a, None, at=(0.02, 0.0))
    crate = w.add_body(box(((0, 0), (0.25, 0), (0.25, 0.25), (0, 0.25)), detail=2), position=(0.385, 0.0),
                       material=deforma.Material("rigid", density=400.0), collide=False)
    pin = w.join(a, crate, at=(0.28, 0.0))
    e0 = energy(w)
    for _ in range(600):
        w.step()
        assert energy(w) <= e0 + 0.1  # (the rigid-soft pair trades a little with the link's stretch)
    assert gap(pin) < 1e-3
    assert pin.force[1] == pytest.approx(-crate.mass * G, rel=0.05)  # the crate hangs from a
    assert (signed_areas(a.positions, a.triangles) > 0).all()


def test_a_chain_of_soft_links_hangs_still():
    # six links hanging straight down from a hook, pinned end to end: still after 4 s (sleep
    # off: the solver's own rest is measured)
    w = deforma.World(dt=1 / 60, sleep=False)
    ov = 0.04
    links = [w.add_body(box(((0, 0), (H, 0), (H, L), (0, L)), detail=5), position=(0.0, -k * (L - ov) - L / 2),
                        material=LINK, collide=False) for k in range(6)]
    w.join(links[0], None, at=(0.0, -ov / 2))
    for k in range(5):
        w.join(links[k], links[k + 1], at=(0.0, -(k + 1) * (L - ov) - ov / 2))
    for _ in range(240):
        w.step()
    assert max(np.abs(b.velocities).max() for b in links) < 2e-3
    # the rope took the links' weight: each pin carries those below it
    for k, j in enumerate(w.joints):
        below = sum(b.mass for b in links[k:])
        assert np.hypot(*j.force) == pytest.approx(below * G, rel=0.01)


@pytest.mark.parametrize("call, message", [
    (lambda w, s, r: w.join(s, None, at=(0.1, 0.0), kind="weld"),
     r"a weld holds a rigid body's turn, and a \(body 0\) is soft"),
    (lambda w, s, r: w.join(r, s, at=(0.29, 0.0), motor_speed=10.0),
     r"a motor holds a rigid body's turn, and b \(body 0\) is soft"),
    (lambda w, s, r: w.join(r, s, at=(0.5, 0.1)), r"at = \(0.5, 0.1\) is not on b \(body 0\), a soft body"),
])
def test_what_a_soft_body_cannot_hold_is_refused_in_one_line(call, message):
    w = deforma.World(dt=1 / 60)
    soft = link(w, 0.0)
    rigid = w.add_body(box(((0, 0), (0.3, 0), (0.3, 0.3), (0, 0.3)), detail=2), position=(0.4, 0.0),
                       material=deforma.Material("rigid", density=100.0), collide=False)
    with pytest.raises(ValueError, match=message) as e:
        call(w, soft, rigid)
    assert "\n" not in str(e.value) and w.joints == []


def test_joints_on_soft_bodies_need_avbd_and_keep_it():
    w = deforma.World(dt=1 / 60, integrator="implicit-euler")
    soft = link(w, 0.0)
    with pytest.raises(ValueError, match="joints on soft bodies are solved by integrator='avbd'"):
        w.join(soft, None, at=(0.1, 0.0))
    w.integrator = "avbd"
    j = w.join(soft, None, at=(0.1, 0.0))
    with pytest.raises(ValueError, match="remove the joint first") as e:
        w.integrator = "xpbd"
    assert "\n" not in str(e.value) and w.integrator == "avbd" and w.joints == [j]


def test_joined_bodies_may_overlap_where_they_are_pinned():
    # two colliding links overlapping at their pin: refused unjoined, taken once joined
    w = deforma.World(dt=1 / 60)
    a = w.add_body(box(((0, 0), (L, 0), (L, H), (0, H)), detail=6), position=(L / 2, 0.0), material=LINK)
    b = w.add_body(box(((0, 0), (L, 0), (L, H), (0, H)), detail=6), position=(0.26 + L / 2, 0.0), material=LINK,
                   collide=False)
    with pytest.raises(ValueError, match="would overlap body 0"):
        b.collide = True
    w.join(a, b, at=(0.28, 0.0))
    b.collide = True
    assert b.collide


def test_removing_a_joint_lets_its_soft_bodies_collide_again():
    w = deforma.World(dt=1 / 60)
    a, b = link(w, 0.0), link(w, 0.26)
    j = w.join(a, b, at=(0.28, 0.0))
    assert list(w.model.contact.joined) == [1, 0]
    w.remove_joint(j)
    assert len(w.model.contact.joined) == 0

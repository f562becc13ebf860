"""Contact pairs, contact events and joint-break events (world.contact_pairs, contacts_between,
on_contact, on_joint_break), at the defaults a user steps with (avbd, 1/60 s)."""

import copy
import warnings

import numpy as np
import pytest

import deforma
from deforma.checks import CallbackWarning

G = 9.81


def _box(detail=2, size=1.0):
    return deforma.mesh.box(((0, 0), (size, 0), (size, size), (0, size)), detail=detail, edges=True)


def _floor(w):
    return w.add_collider(deforma.Rect((0, -0.5), (10, 1), 0.0))


def _run(w, seconds):
    for _ in range(round(seconds / w.dt)):
        w.step()


@pytest.mark.parametrize("material", [deforma.Material("rigid", density=10.0),
                                      deforma.Material.preset("jelly")], ids=["rigid", "jelly"])
def test_a_resting_body_takes_its_weight_times_dt_from_the_floor(material):
    w = deforma.World(sleep=False)  # (sleep off: the solver's own rest is measured)
    floor = _floor(w)
    body = w.add_body(_box(detail=4, size=0.3), position=(0, 0.17), material=material)
    _run(w, 3.0)
    assert np.abs(body.velocities).max() < 1e-3  # at rest
    weight = body.vertex_masses.sum() * G
    pair = w.contacts_between(body, floor)
    assert pair is not None and pair.a is body and pair.b is floor
    assert pair.normal_impulse == pytest.approx(weight * w.dt, rel=0.01)
    assert pair.impulse[1] == pytest.approx(weight * w.dt, rel=0.01)
    assert abs(pair.impulse[0]) < 1e-3 * weight * w.dt and pair.friction_impulse < 1e-3 * weight * w.dt
    np.testing.assert_allclose(pair.normal, [0.0, 1.0], atol=1e-9)
    # the points lie on the floor's top, under the body
    assert np.all(np.abs(pair.points[:, 1]) < 2e-3) and len(pair.points) >= 2
    seen_from_floor = w.contacts_between(floor, body)
    assert seen_from_floor.a is floor and seen_from_floor.b is body
    np.testing.assert_allclose(seen_from_floor.impulse, -pair.impulse)


def test_a_box_on_a_box_pushes_down_with_its_weight_and_the_floor_carries_both():
    w = deforma.World()
    floor = _floor(w)
    jelly = deforma.Material.preset("jelly")
    low = w.add_body(_box(detail=3, size=0.4), position=(0, 0.22), material=jelly)
    top = w.add_body(_box(detail=3, size=0.25), position=(0, 0.6), material=jelly)
    _run(w, 3.0)
    g_low, g_top = (b.vertex_masses.sum() * G * w.dt for b in (low, top))
    pairs = {(id(p.a), id(p.b)): p for p in w.contact_pairs()}
    assert set(pairs) == {(id(low), id(floor)), (id(low), id(top))}
    between = pairs[(id(low), id(top))]  # a is the lower index: the impulse on `low` from `top`
    assert between.impulse[1] == pytest.approx(-g_top, rel=0.01)
    np.testing.assert_allclose(between.normal, [0.0, -1.0], atol=1e-2)  # the jelly's top edge bends
    assert pairs[(id(low), id(floor))].impulse[1] == pytest.approx(g_low + g_top, rel=0.01)
    assert w.contacts_between(top, low).impulse[1] == pytest.approx(g_top, rel=0.01)
    assert w.contacts_between(top, floor) is None


def test_a_body_dropped_on_another_begins_once_and_ends_once_when_lifted_off():
    w = deforma.World()
    floor = _floor(w)
    foam = deforma.Material.preset("foam")  # dropped 2 cm: it lands without a bounce
    low = w.add_body(_box(detail=3, size=0.4), position=(0, 0.2), material=foam)
    top = w.add_body(_box(detail=3, size=0.25), position=(0.05, 0.545), material=foam)
    events = []
    w.on_contact(lambda e: events.append((e.kind, e.a, e.b, e.step)))
    _run(w, 3.0)
    on_top = [e for e in events if {id(e[1]), id(e[2])} == {id(low), id(top)}]
    assert [e[0] for e in on_top] == ["begin"]
    assert [e[0] for e in events if e[2] is floor] == ["begin"]
    assert on_top[0][3] > 1  # it fell first
    # lift the top box off: one end, no second begin while it flies
    top.apply_impulse((0.0, 3.0 * top.vertex_masses.sum()))
    _run(w, 0.3)
    on_top = [e for e in events if {id(e[1]), id(e[2])} == {id(low), id(top)}]
    assert [e[0] for e in on_top] == ["begin", "end"]
    assert w.contacts_between(low, top) is None
    assert w.contacts_between(low, floor) is not None


def test_a_listener_that_raises_is_reported_once_and_the_steps_complete():
    w = deforma.World()
    _floor(w)
    w.add_body(_box(), position=(0, 0.6))
    calls = []

    def broken_listener(event):
        calls.append(event.kind)
        raise KeyError("no such thing")

    later = []
    w.on_contact(broken_listener)
    w.on_contact(lambda e: later.append(e.kind))
    with pytest.warns(CallbackWarning, match="broken_listener raised KeyError") as caught:
        _run(w, 0.5)
        w.bodies[0].apply_impulse((0.0, 5.0))
        _run(w, 0.5)
    assert len([c for c in caught if issubclass(c.category, CallbackWarning)]) == 1
    assert calls == later and calls[:2] == ["begin", "end"]  # both called, every time
    assert w.step_count == 60
    w.remove_listener(broken_listener)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        w.bodies[0].apply_impulse((0.0, 5.0))
        _run(w, 1.0)


def test_bad_listeners_are_refused_in_one_line():
    w = deforma.World()
    for bad in (3, "f", None):
        with pytest.raises(ValueError, match=r"^on_contact takes a function to call, got .*$"):
            w.on_contact(bad)
        with pytest.raises(ValueError, match=r"^on_joint_break takes a function to call"):
            w.on_joint_break(bad)
    with pytest.raises(ValueError, match="is not a listener of this world"):
        w.remove_listener(print)
    assert not w._events.contact and not w._events.joint_break


def test_a_joint_past_its_break_force_calls_its_listener():
    w = deforma.World()
    rigid = deforma.Material("rigid", density=100.0)
    bar = w.add_body(_box(detail=2, size=0.2), position=(0, 1.0), material=rigid)
    j = w.join(bar, None, at=(0, 1.1), break_force=5.0)  # the bar weighs 39 N
    broken = []
    w.on_joint_break(broken.append)
    w.step()
    assert broken == [j] and j.broken and not w.joints


def test_pairs_under_an_integrator_without_contact_forces_have_no_impulses():
    w = deforma.World(integrator="implicit-euler")
    floor = _floor(w)
    body = w.add_body(_box(), position=(0, 0.6))
    _run(w, 1.0)
    pair = w.contacts_between(body, floor)
    assert pair is not None and np.isnan(pair.normal_impulse) and np.isnan(pair.impulse).all()
    np.testing.assert_allclose(pair.normal, [0.0, 1.0], atol=1e-6)


def test_no_pairs_before_a_step_or_after_a_body_is_added():
    w = deforma.World()
    _floor(w)
    assert w.contact_pairs() == []
    w.add_body(_box(), position=(0, 0.52))
    _run(w, 0.5)
    assert len(w.contact_pairs()) == 1
    w.add_body(_box(), position=(3, 0.52))
    assert w.contact_pairs() == []  # numbered for the world before it
    _run(w, 0.5)
    assert len(w.contact_pairs()) == 2


def test_a_copied_world_reports_its_own_events():
    w = deforma.World()
    _floor(w)
    w.add_body(_box(), position=(0, 0.52))
    events = []
    w.on_contact(events.append)
    _run(w, 0.5)
    assert [e.kind for e in events] == ["begin"]
    twin = copy.deepcopy(w)
    twin.bodies[0].apply_impulse((0.0, 5.0))
    _run(twin, 0.3)
    ends = [e for e in events if e.kind == "end"]
    assert len(ends) == 1 and ends[0].a is twin.bodies[0]  # the copy's listener list, the copy's bodies
    _run(w, 0.3)
    assert [e.kind for e in events] == ["begin", "end"]  # the original still rests: nothing new

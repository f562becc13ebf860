"""world.solve_static: static equilibrium against known answers, and one line for what it
cannot solve."""

import re

import numpy as np
import pytest

import deforma
from physics_meshes import Chain
from test_fem_validation import EXPECTED, RHO, E, L, NU, column


def hanging_spring(**kw):
    w = deforma.World(gravity=(0.0, -9.81), mass=2.0, stiffness=100.0, **kw)
    b = w.add_body(Chain([[0, 0], [0, -1]], [[0, 1]]), position=None)
    b.pin([0])
    return w, b


@pytest.mark.parametrize("model", ["corotated", "neo-hookean"])
def test_a_hanging_column_settles_to_its_elongation_in_one_call(model):
    w = deforma.World(dt=1 / 60, integrator="implicit-euler")
    m = column(4)
    b = w.add_body(m, material=deforma.Material(model, youngs_modulus=E, poisson_ratio=NU, density=RHO),
                   position=None)
    b.pin(np.flatnonzero(np.isclose(m.vertices[:, 1], 0.0)))
    steps = w.solve_static()
    bottom = np.isclose(m.vertices[:, 1], -L)
    assert -L - b.positions[bottom, 1].mean() == pytest.approx(EXPECTED, rel=0.01)
    assert 1 <= steps < 100
    assert w.time == 0.0 and w.step_count == 0 and not b.velocities.any()
    assert w.integrator == "implicit-euler" and w.dt == pytest.approx(1 / 60)  # the world's own, back


def test_an_applied_force_acts_throughout_and_then_goes():
    w, b = hanging_spring()
    b.apply_force([[3.0, 0.0]], indices=[1])  # 3 N sideways on the hanging 1 kg
    w.solve_static(tolerance=1e-9)
    # the spring points along the resultant of gravity and the force, stretched by it / k
    d = b.positions[1] - b.positions[0]
    pull = np.array([3.0, -9.81])
    np.testing.assert_allclose(d / np.linalg.norm(d), pull / np.linalg.norm(pull), atol=1e-6)
    assert np.linalg.norm(d) - 1.0 == pytest.approx(np.linalg.norm(pull) / 100.0, rel=1e-5)
    w.solve_static(tolerance=1e-9)  # the force is gone: straight down again
    assert b.positions[1, 0] == pytest.approx(0.0, abs=1e-6)


def test_a_block_comes_to_rest_on_the_floor():
    w = deforma.World(dt=1 / 60)
    w.add_collider(deforma.Rect((0.0, -0.25), (4.0, 0.5)))
    b = w.add_body(deforma.mesh.box(((0, 0), (0.4, 0), (0.4, 0.2), (0, 0.2)), detail=3, edges=True),
                   position=(0.0, 0.5), material=deforma.Material("corotated", youngs_modulus=1e5,
                                                                  poisson_ratio=0.3, density=100.0))
    w.solve_static(tolerance=1e-7)
    assert b.positions[:, 1].min() == pytest.approx(0.0, abs=2e-3)  # on the floor's top
    assert np.ptp(b.positions[:, 1]) == pytest.approx(0.2, rel=0.01)  # its own height, barely squeezed


@pytest.mark.parametrize("make, kwargs, message", [
    (lambda: deforma.World(), {}, None),  # no body: nothing to do
    (lambda: hanging_spring()[0], {"tolerance": 0.0}, "tolerance must be a distance > 0 m, got 0.0"),
    (lambda: hanging_spring()[0], {"tolerance": "small"}, "tolerance must be a number, got 'small'"),
    (lambda: hanging_spring()[0], {"max_iterations": 0}, "max_iterations must be an integer in [1, 100000], got 0"),
])
def test_bad_arguments_are_one_line(make, kwargs, message):
    w = make()
    if message is None:
        assert w.solve_static(**kwargs) == 0
        return
    with pytest.raises(ValueError) as e:
        w.solve_static(**kwargs)
    assert str(e.value) == message


def test_what_it_cannot_solve_is_refused_and_changes_nothing():
    free = deforma.World(dt=1 / 600, integrator="symplectic-euler")
    b = free.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2), position=(0, 3))
    with pytest.raises(ValueError, match=r"^solve_static: nothing holds the bodies .* add a collider under them$"):
        free.solve_static()
    tearing = deforma.World(dt=1 / 600, integrator="symplectic-euler",
                            material=deforma.Material("springs", tear_strain=0.5))
    tearing.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2)).pin([0])
    with pytest.raises(ValueError, match=r"^solve_static needs elastic bodies: body 0 tears"):
        tearing.solve_static()
    # a soft column that one relaxation step cannot settle: refused, and put back
    w = deforma.World(integrator="symplectic-euler", dt=1 / 60)
    m = column(4)
    c = w.add_body(m, material=deforma.Material("corotated", youngs_modulus=E, poisson_ratio=NU, density=RHO),
                   position=None)
    c.pin(np.flatnonzero(np.isclose(m.vertices[:, 1], 0.0)))
    before = c.positions.copy()
    with pytest.raises(ValueError, match=r"^solve_static did not settle within max_iterations = 1 relaxation steps"):
        w.solve_static(max_iterations=1)
    assert np.array_equal(c.positions, before) and w.integrator == "symplectic-euler" and w.step_count == 0
    assert np.array_equal(b.positions, free.bodies[0].positions)


# -- issue 51: statics that end: progress, a time bound, and what cannot settle named ----------
import time  # noqa: E402


def box_on_floor(floor=(10.0, 0.5), *, force=None, friction=0.0, sleep=True):
    """A small corotated block on a floor (frictionless by default), pushed sideways by ``force`` N."""
    w = deforma.World(friction=friction, static_friction=friction, sleep=sleep)
    w.add_collider(deforma.Rect((0.0, -0.25), floor))
    b = w.add_body(deforma.mesh.box(((0, 0), (0.4, 0), (0.4, 0.2), (0, 0.2)), detail=2), position=(0.0, 0.15),
                   material=deforma.Material("corotated", youngs_modulus=1e5, poisson_ratio=0.3, density=100.0))
    if force is not None:
        b.apply_force(force)
    return w, b


def refused(w, b, match, **kwargs):
    """solve_static raises one ValueError line matching ``match`` and leaves ``w`` as it was."""
    before, forces = b.positions.copy(), list(w._forces)
    seen = []
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=match) as e:
        w.solve_static(progress=seen.append, **kwargs)
    assert "\n" not in str(e.value)
    assert np.array_equal(b.positions, before) and not b.velocities.any() and w.step_count == 0 and w.time == 0.0
    assert w._forces == forces and w.integrator == "avbd" and w.sleep and not b.sleeping
    return e.value, seen, time.perf_counter() - t0


def test_a_tolerance_below_float64_is_refused_before_any_step():
    w, b = hanging_spring()
    e, seen, took = refused(w, b, r"^solve_static: tolerance 1e-300 m is below what float64 resolves at these "
                                  r"coordinates .*: give tolerance >= 3\.6e-15 m$", tolerance=1e-300,
                            max_iterations=100_000)
    assert seen == [] and took < 1.0


def test_a_body_that_slides_freely_is_named_not_relaxed_for_ever():
    # a frictionless floor holds nothing sideways: with sleeping on, the block fell asleep after
    # 5 steps and was "settled"; before that, it slid for max_iterations (minutes)
    w, b = box_on_floor(force=(0.05, 0.0))
    e, seen, took = refused(w, b, r"^solve_static stopped getting closer after 200 relaxation steps: body 0 keeps "
                                  r"moving one way .* along \(1\.00, -?0\.00\) .*: it slides freely, as the colliders "
                                  r"are frictionless and no wall stops it that way")
    assert [p.iteration for p in seen] == list(range(1, 201)) and took < 60


def test_a_body_that_slides_off_its_support_is_named_when_it_has_fallen_past_every_collider():
    w, b = box_on_floor((1.0, 0.5), force=(20.0, 0.0))
    e, seen, took = refused(w, b, r"^solve_static: body 0 fell past every collider at relaxation step \d+ \(now at "
                                  r".*\): it slid or rolled off its support")
    assert len(seen) < 60 and took < 30


def test_the_time_budget_bounds_a_solve_and_progress_is_reported():
    w, b = box_on_floor(force=(0.05, 0.0))
    e, seen, took = refused(w, b, r"^solve_static did not settle within max_seconds = 0\.3 s \(\d+ relaxation steps",
                            max_seconds=0.3)
    assert took < 3 and seen and seen[-1].elapsed > 0.3 and seen[-1].max_seconds == 0.3
    assert all(p.tolerance == 1e-6 and p.moved > 0 for p in seen)


def test_the_defaults_show_a_bar_on_a_terminal_and_bound_the_time(monkeypatch):
    # solve_static() with its defaults ran past 60 s on crates, balloon, pile and playground with
    # nothing shown: a bar on a terminal (tqdm, once a second has passed), and max_seconds = 60
    import inspect
    import io
    import sys

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    w, b = box_on_floor(force=(0.05, 0.0))
    assert inspect.signature(w.solve_static).parameters["max_seconds"].default == 60.0
    screen = Terminal()
    monkeypatch.setattr(sys, "stderr", screen)
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"^solve_static stopped getting closer after 200 relaxation steps") as e:
        w.solve_static()
    assert "\n" not in str(e.value)
    if time.perf_counter() - t0 > 1.5:  # the bar waits a second before it shows (8.9 s here)
        assert re.search(r"solve_static: +\d+%.*\d+/1000 .*step", screen.getvalue()), screen.getvalue()[-300:]
        assert screen.getvalue().endswith("\r")  # and is cleared when the solve ends (leave=False)


def test_an_exception_from_progress_stops_the_solve_and_puts_the_world_back():
    w, b = box_on_floor(force=(0.05, 0.0))
    before = b.positions.copy()

    def stop(p):
        if p.iteration == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        w.solve_static(progress=stop)
    assert np.array_equal(b.positions, before) and w.step_count == 0 and w._forces


def test_a_tolerance_below_the_solves_noise_is_named():
    w, b = box_on_floor(friction=0.5)
    e, seen, took = refused(w, b, r"^solve_static stopped getting closer after 200 relaxation steps: the moves stay "
                                  r"about .* m a step .* give a tolerance above .* m if that is close enough",
                            tolerance=1e-13)
    assert float(re.search(r"above (\S+) m", str(e)).group(1)) < 1e-8


@pytest.mark.parametrize("kwargs, message", [
    ({"max_seconds": 0}, "max_seconds must be a number of seconds > 0 (inf: no limit), got 0"),
    ({"max_seconds": float("nan")}, "max_seconds must be a number of seconds > 0 (inf: no limit), got nan"),
    ({"max_seconds": "1 min"}, "max_seconds must be a number of seconds > 0 (inf: no limit), got '1 min'"),
    ({"progress": "yes"}, "progress must be None (a bar on a terminal), False or a callable taking a "
                          "StaticProgress, got 'yes'"),
])
def test_bad_budgets_and_progress_are_one_line(kwargs, message):
    w, _ = hanging_spring()
    with pytest.raises(ValueError) as e:
        w.solve_static(**kwargs)
    assert str(e.value) == message


def test_a_settling_world_reports_progress_and_sleeps_again_after():
    w, b = box_on_floor(friction=0.5)
    seen = []
    steps = w.solve_static(progress=seen.append, max_seconds=float("inf"), tolerance=1e-7)
    assert [p.iteration for p in seen] == list(range(1, steps + 1)) and seen[-1].remaining <= 1e-7
    assert w.sleep and not b.velocities.any()

"""World API: interaction (explode, grab), safety (instability, validation), bookkeeping."""

import math

import numpy as np
import pytest

import deforma
from deforma.physics import available_integrators
from physics_meshes import Chain, grid_mesh


def test_explode_lifts_the_body():
    w = deforma.World(dt=1 / 1000)
    w.add_collider(deforma.Rect((0, -0.5), (10, 1.0), 0.0))
    b = w.add_body(grid_mesh(0.2, 0.1, 4, 3), position=(0, 0.05))
    for _ in range(200):
        w.step()
    y0 = b.center_of_mass[1]
    w.explode(3.0)
    assert b.velocities[:, 1].mean() == pytest.approx(3.0, abs=0.05)
    top = y0
    for _ in range(400):
        w.step()
        top = max(top, b.center_of_mass[1])
    assert top - y0 == pytest.approx(3.0 ** 2 / (2 * 9.81), rel=0.1)  # rises about v^2 / 2g


def test_radial_explosion_pushes_away_from_the_centre_and_keeps_momentum():
    w = deforma.World(gravity=(0, 0))
    b = w.add_body(grid_mesh(0.4, 0.4, 5, 5), position=(1.0, 1.0))
    w.explode(2.0, center=(1.0, 1.0))
    d = b.positions - (1.0, 1.0)
    radial = np.einsum("ij,ij->i", b.velocities, d)
    r = np.linalg.norm(d, axis=1)
    assert np.all(radial[r > 0] > 0)
    assert np.allclose(np.linalg.norm(b.velocities[r > 0], axis=1), 2.0)
    assert np.abs(b.velocities.sum(axis=0)).max() < 1e-9  # symmetric grid around the centre


def test_dragging_pulls_the_body_toward_the_target_and_release_stops_it():
    w = deforma.World(gravity=(0, 0), dt=1 / 1000, stiffness=2000.0, damping=2.0)
    b = w.add_body(grid_mesh(0.2, 0.2, 5, 5), position=(0, 0))
    g = w.grab((0.01, 0.01), strength=20.0, radius=0.06)
    assert g.body is b and 3 <= len(g.vertices) < b.n_vertices
    w.drag(g, (1.0, 0.0))
    for _ in range(300):
        w.step()
    com = b.center_of_mass
    assert com[0] > 0.05 and abs(com[1]) < 0.05 * com[0]  # along x (the held patch keeps its offsets)
    w.release(g)
    w.release(g)  # twice is harmless
    p0 = b.velocities.sum(axis=0).copy()
    for _ in range(100):
        w.step()
    assert np.abs(b.velocities.sum(axis=0) - p0).max() < 1e-9  # no pull any more
    with pytest.raises(ValueError, match="released"):
        w.drag(g, (0, 0))


def test_grab_picks_the_triangle_under_the_point_or_nothing():
    w = deforma.World()
    b = w.add_body(grid_mesh(1.0, 1.0, 3, 3), position=(0, 0))
    g = w.grab((0.1, 0.2))
    assert len(g.vertices) == 3 and g.body is b
    tri = b.positions[g.vertices]
    assert np.all(tri.min(axis=0) <= (0.1, 0.2)) and np.all(tri.max(axis=0) >= (0.1, 0.2))
    off = w.grab((3.0, 3.0), radius=0.5)
    assert off.body is None and len(off.vertices) == 0
    w.step()  # an empty grab does nothing and breaks nothing
    assert len(w.grab((0.0, 0.0), radius=10.0).vertices) == 9
    chain = w.add_body(Chain([[5, 0], [6, 0]], [[0, 1]]), position=None)
    assert len(w.grab((5.0, 0.0)).vertices) == 0  # no triangles: only a radius picks
    assert w.grab((5.0, 0.0), radius=0.1).body is chain


@pytest.mark.parametrize("integrator", available_integrators())
def test_a_wide_grab_moves_its_patch_without_squeezing_it(integrator):
    # a hand-sized grab dragged across: every held vertex follows the target with its own
    # offset, so the patch keeps its size and no triangle under it turns inside out (pulled
    # to one point, this patch shrank by 14-16% across; the tear scene's wider, stronger
    # pull crumpled its patch into folded triangles)
    mat = deforma.Material("corotated", youngs_modulus=2e4, poisson_ratio=0.3, density=10.0)
    w = deforma.World(gravity=(0, 0), dt=1 / 600, substeps=4, integrator=integrator, material=mat)
    b = w.add_body(deforma.mesh.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=12), position=None)
    g = w.grab((1.0, 0.5), radius=0.3, strength=2000.0)
    assert len(g.vertices) > 10 and np.allclose(b.positions[g.vertices] - (1.0, 0.5), g.offsets)
    spread = np.ptp(b.positions[g.vertices], axis=0)
    for k in range(300):
        w.drag(g, (1.0 + 0.5 * min(1.0, k / 150), 0.5))
        w.step()
    assert np.ptp(b.positions[g.vertices], axis=0) == pytest.approx(spread, rel=0.1)
    moved = (b.positions[g.vertices] - g.offsets).mean(axis=0) - (1.0, 0.5)
    assert moved == pytest.approx((0.5, 0.0), abs=0.1)  # the patch went where it was dragged
    assert deforma.physics.elements.triangles.signed_areas(b.positions, b.triangles).min() > 0


def test_absurd_dt_raises_and_keeps_the_state_before_the_failing_step():
    w = deforma.World(integrator="symplectic-euler", dt=0.05, substeps=1, stiffness=5000.0, gravity=(0, -9.81))
    b = w.add_body(grid_mesh(0.2, 0.1, 4, 3), position=(0, 0))
    b.positions[0] += 0.01
    with pytest.raises(deforma.SimulationUnstable) as info:
        for _ in range(1000):
            before_x, before_v = b.positions.copy(), b.velocities.copy()
            w.step()
    e = info.value
    assert e.body is b and e.step == w.step_count
    assert "dt" in str(e) and "stable estimate" in e.hint and "substeps" in e.hint
    assert np.array_equal(b.positions, before_x) and np.array_equal(b.velocities, before_v)
    # the world stays usable: reset the body, shorten the substeps below the estimate, go on
    w.substeps = math.ceil(w.dt / w.stable_dt())
    b.positions = b.topology.rest_positions
    b.velocities = (0.0, 0.0)
    for _ in range(20):
        w.step()
    assert np.all(np.isfinite(b.positions))


def test_a_step_limit_set_by_damping_is_named_in_the_hint():
    # the demo's Neo-Hookean bunny switched to symplectic Euler (as the viewer lets one do):
    # its material damping (0.01 s, stiffness-proportional) cuts the explicit step 250-fold,
    # and the hint says so rather than blaming the stiffness alone
    from deforma import scene as scenes

    w = scenes.load_scene("demo")
    w.integrator = "symplectic-euler"
    w.dt, w.substeps = 1 / 600, 1  # the demo's step under implicit Euler (with "auto" the substeps refuse first)
    with pytest.raises(deforma.SimulationUnstable) as info:
        for _ in range(20):
            w.step()
    assert "set by the damping" in info.value.hint and "material_damping" in info.value.hint
    # a springs body without much damping: the plain hint, no such clause
    w = deforma.World(integrator="symplectic-euler", dt=0.05, substeps=1, stiffness=5000.0)
    w.add_body(grid_mesh(0.2, 0.1, 4, 3), position=(0, 0))
    with pytest.raises(deforma.SimulationUnstable) as info:
        for _ in range(1000):
            w.step()
    assert "raise substeps" in info.value.hint and "damping" not in info.value.hint


def test_stable_dt_is_the_true_limit_for_two_masses_on_a_spring():
    # Gershgorin's bound is exact here: omega^2 = k / mu = 2 k / m_vertex
    w = deforma.World(dt=1 / 600, integrator="symplectic-euler", gravity=(0, 0), substeps=1, mass=2.0, stiffness=1e4,
                      damping=0.0, max_speed=1e6)
    b = w.add_body(Chain([[0, 0], [1, 0]], [[0, 1]]), position=None)
    assert w.stable_dt() == pytest.approx(2 / math.sqrt(2 * 1e4 / 1.0))
    for factor, stable in ((0.95, True), (1.05, False)):
        w.dt = factor * w.stable_dt()
        b.positions[:] = [[0, 0], [1.01, 0]]
        b.velocities[:] = 0
        try:
            for _ in range(3000):
                w.step()
            ok = True
        except deforma.SimulationUnstable:
            ok = False
        assert ok is stable


def test_positions_and_velocities_are_views_into_one_contiguous_state():
    w = deforma.World()
    a = w.add_body(grid_mesh(0.2, 0.1, 3, 2), position=(0, 0))
    b = w.add_body(grid_mesh(0.2, 0.1, 4, 2), position=(1, 0))
    assert np.shares_memory(a.positions, w.state.x) and np.shares_memory(b.velocities, w.state.v)
    assert (a.vertex_slice, b.vertex_slice) == (slice(0, 6), slice(6, 14))
    b.positions[0] = (5.0, 5.0)
    assert tuple(w.state.x[6]) == (5.0, 5.0)
    w.remove_body(a)
    assert w.bodies == [b] and b.index == 0 and tuple(b.positions[0]) == (5.0, 5.0)
    with pytest.raises(ValueError, match="unknown body"):
        w.remove_body(a)
    with pytest.raises(ValueError, match="removed"):
        a.positions


def test_body_parameters_follow_the_world_unless_overridden():
    w = deforma.World(mass=2.0, stiffness=100.0)
    a = w.add_body(grid_mesh(0.2, 0.1, 3, 2))
    b = w.add_body(grid_mesh(0.2, 0.1, 3, 2), position=(1.0, 0.0), stiffness=50.0, mass=6.0)
    w.stiffness = 300.0
    assert (a.stiffness, b.stiffness) == (300.0, 50.0)
    assert w.model.spring_stiffness[: a.n_springs].tolist() == [300.0] * a.n_springs
    assert w.model.vertex_mass[a.n_vertices:].tolist() == [1.0] * b.n_vertices
    b.stiffness = None
    assert b.stiffness == 300.0
    assert w.energy(a).kinetic == 0.0


def test_energy_components_have_the_textbook_values():
    w = deforma.World(gravity=(0, -10.0), mass=2.0, stiffness=100.0)
    b = w.add_body(Chain([[0, 1], [1, 1]], [[0, 1]]), position=None)
    b.positions[1] = (1.5, 1.0)
    b.velocities[:] = (3.0, 0.0)
    e = w.energy()
    assert (e.kinetic, e.spring, e.gravitational) == pytest.approx((9.0, 12.5, 20.0))
    assert e.total == pytest.approx(41.5)


@pytest.mark.parametrize("kwargs, match", [
    (dict(dt=0), "dt must be > 0"), (dict(dt=-1e-3), "dt must be > 0"), (dict(dt=float("nan")), "dt must be finite"),
    (dict(mass=-1), "mass must be > 0"), (dict(stiffness=-5), "stiffness must be >= 0"),
    (dict(damping="x"), "damping must be a number"), (dict(substeps=0), "substeps"),
    (dict(substeps=2.5), "substeps"), (dict(gravity=(0, float("nan"))), "gravity"),
    (dict(friction=-0.1), "friction must be >= 0"), (dict(max_speed=0), "max_speed"),
    (dict(integrator="rk4"), "unknown integrator 'rk4'; available: symplectic-euler"),
])
def test_world_arguments_are_validated(kwargs, match):
    with pytest.raises(ValueError, match=match) as info:
        deforma.World(**kwargs)
    assert "\n" not in str(info.value)


def test_other_arguments_are_validated():
    w = deforma.World()
    m = grid_mesh(0.2, 0.1, 3, 2)
    body = w.add_body(m)
    bad = [
        lambda: w.add_body(m, position=(0, float("nan"))),
        lambda: w.add_body(m, mass=-1.0),
        lambda: w.add_body("not a mesh"),
        lambda: w.add_body(Chain([[0, 0], [0, 0]], [[0, 1]])),
        lambda: w.add_collider((0, 0, 1, 1)),
        lambda: deforma.Rect((0, 0), (1, -1), 0.0),
        lambda: deforma.Rect((0, float("inf")), (1, 1), 0.0),
        lambda: deforma.Rect((0, 0), (1, 1), 0.0, friction=-1),
        lambda: w.energy(object()),
        lambda: w.explode(float("nan")),
        lambda: w.grab((0, 0), strength=0),
        lambda: w.grab((0, 0), radius=-1),
        lambda: w.drag(deforma.World().grab((0, 0)), (1, 1)),
        lambda: setattr(body, "positions", (0.0, 0.0)),
        lambda: setattr(body, "velocities", np.full((6, 2), np.nan)),
    ]
    for f in bad:
        with pytest.raises(ValueError) as info:
            f()
        assert "\n" not in str(info.value)
    with pytest.raises(ValueError, match="must be a deforma.Rect, Circle, Polygon or Segment"):
        w.add_collider("junk")
    with pytest.raises(AttributeError):
        w.colliders.append(deforma.Rect((0, 0), (1, 1)))  # a read-only view: add_collider is the way
    r = w.add_collider(deforma.Rect((0, -5), (1, 1)))
    with pytest.raises(ValueError, match="in the world already"):
        w.add_collider(r)
    w.remove_collider(r)
    with pytest.raises(ValueError, match="not in this world"):
        w.remove_collider(r)


def test_integrator_registry_names_the_choices():
    assert "symplectic-euler" in available_integrators()
    assert deforma.World(integrator="symplectic-euler").integrator == "symplectic-euler"


def test_spring_parameters_set_on_the_world_say_once_which_bodies_ignore_them():
    import warnings

    from deforma.checks import IgnoredSettingWarning

    box = deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2)
    w = deforma.World(material=deforma.Material("corotated", youngs_modulus=1e4, poisson_ratio=0.3, density=1.0))
    w.add_body(box)
    with pytest.warns(IgnoredSettingWarning, match=r"world.stiffness changes no body: body 0 \(corotated\) is made of "
                                                   r"finite elements, whose stiffness is set by youngs_modulus"):
        w.stiffness = 3000.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        w.stiffness = 4000.0  # said once
    w.add_body(box, position=(3, 0), material=deforma.Material("springs"))
    with pytest.warns(IgnoredSettingWarning, match=r"world.damping changes only the bodies made of springs: body 0"):
        w.damping = 2.0
    springs = deforma.World()
    springs.add_body(box)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        springs.stiffness = 3000.0  # every body reads it


def test_the_model_state_and_control_are_public_views_of_the_step():
    w = deforma.World(dt=1 / 60)
    a = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2), position=(0, 2))
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2), position=(3, 2))
    w.step()
    assert w.model.n_vertices == len(a.positions) + len(b.positions) == len(w.state.x)
    np.testing.assert_array_equal(w.state.x[b.vertex_slice], b.positions)
    np.testing.assert_array_equal(w.state.v[a.vertex_slice], a.velocities)
    assert w.control.n_vertices == w.model.n_vertices
    for name in ("model", "state", "control"):
        with pytest.raises(AttributeError):
            setattr(w, name, None)

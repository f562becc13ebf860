"""Finite-element materials: the element kernels against their energies, the API, and pins."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import deforma
from deforma.physics.elements import corotated, neo_hookean
from deforma.physics.elements import triangles as elements
from deforma.physics.material import KIND_COROTATED, KIND_NEO_HOOKEAN
from physics_meshes import grid_mesh

MODELS = ["corotated", "neo-hookean"]
INTEGRATORS = ["symplectic-euler", "implicit-euler", "xpbd"]


def material(model, e=1e4, nu=0.3, rho=10.0, damping=0.0):
    return deforma.Material(model, youngs_modulus=e, poisson_ratio=nu, density=rho, damping=damping)


# -- the material ------------------------------------------------------------------------------

def test_plane_stress_lame_parameters():
    mu, lam = material("corotated", e=2.6e5, nu=0.3).lame()
    assert math.isclose(mu, 1e5) and math.isclose(lam, 2.6e5 * 0.3 / (1 - 0.09))


@pytest.mark.parametrize("kwargs, needle", [
    (dict(model="rubber"), "material model must be one of"),
    (dict(model="corotated", youngs_modulus=1e5, poisson_ratio=0.3), "needs density"),
    (dict(model="neo-hookean", youngs_modulus=0.0, poisson_ratio=0.3, density=1.0), "youngs_modulus must be in"),
    (dict(model="neo-hookean", youngs_modulus=float("nan"), poisson_ratio=0.3, density=1.0), "youngs_modulus"),
    (dict(model="neo-hookean", youngs_modulus=1e5, poisson_ratio=0.5, density=1.0), "poisson_ratio must be in"),
    (dict(model="neo-hookean", youngs_modulus=1e5, poisson_ratio=-1.0, density=1.0), "(-1, 0.5)"),
    (dict(model="corotated", youngs_modulus=1e5, poisson_ratio=0.3, density=-2.0), "density must be in"),
    (dict(model="corotated", youngs_modulus=1e5, poisson_ratio=0.3, density=float("inf")), "density"),
    (dict(model="corotated", youngs_modulus=1e5, poisson_ratio=0.3, density=1.0, damping=-1.0), "damping"),
    (dict(model="corotated", youngs_modulus="stiff", poisson_ratio=0.3, density=1.0), "must be a number"),
    (dict(model="corotated", youngs_modulus=10**400, poisson_ratio=0.3, density=1.0),
     "youngs_modulus must be a finite number, got an integer of 401 digits"),
    (dict(model="springs", youngs_modulus=1e5), "takes no youngs_modulus"),
])
def test_bad_materials_are_refused_with_the_value_and_the_range(kwargs, needle):
    model = kwargs.pop("model")
    with pytest.raises(ValueError, match=None) as e:
        deforma.Material(model, **kwargs)
    assert needle in str(e.value) and "\n" not in str(e.value)


# -- the element kernels ------------------------------------------------------------------------

def random_gradients(rng, n, inverted=False):
    f = np.eye(2) + 0.4 * rng.normal(size=(n, 2, 2))
    if inverted:
        f[:, :, 0] *= -1.0  # mirror: det < 0
    return f


@pytest.mark.parametrize("module", [corotated, neo_hookean])
@pytest.mark.parametrize("inverted", [False, True])
def test_stress_is_the_derivative_of_the_energy(module, inverted):
    rng = np.random.default_rng(1)
    mu, lam = 3.0, 5.0
    for f in random_gradients(rng, 20, inverted):
        p = np.array(module.stress(*f.ravel(), mu, lam)).reshape(2, 2)
        eps = 1e-6
        num = np.zeros((2, 2))
        for r in range(2):
            for c in range(2):
                d = np.zeros((2, 2))
                d[r, c] = eps
                num[r, c] = (module.energy_density((f + d)[None], mu, lam)[0]
                             - module.energy_density((f - d)[None], mu, lam)[0]) / (2 * eps)
        assert np.allclose(p, num, atol=1e-6)


@pytest.mark.parametrize("module", [corotated, neo_hookean])
def test_energies_are_zero_at_rest_and_rotation_invariant_and_match_linear_elasticity(module):
    mu, lam = 2.0, 3.0
    rng = np.random.default_rng(2)
    for angle in rng.uniform(-np.pi, np.pi, 10):
        r = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
        assert abs(module.energy_density(r[None], mu, lam)[0]) < 1e-12
        f = random_gradients(rng, 1)[0]
        assert math.isclose(module.energy_density((r @ f)[None], mu, lam)[0],
                            module.energy_density(f[None], mu, lam)[0], rel_tol=1e-9)
    # small strains: mu |eps|^2 + lambda / 2 tr(eps)^2, the Lamé parameters as given
    h = 1e-4 * rng.normal(size=(2, 2))
    eps = 0.5 * (h + h.T)
    linear = mu * np.sum(eps * eps) + 0.5 * lam * np.trace(eps) ** 2
    assert math.isclose(module.energy_density((np.eye(2) + h)[None], mu, lam)[0], linear, rel_tol=1e-3)


@pytest.mark.parametrize("kind", [KIND_COROTATED, KIND_NEO_HOOKEAN])
def test_element_forces_are_minus_the_energy_gradient_and_sum_to_zero(kind):
    rng = np.random.default_rng(3)
    mesh = grid_mesh(1.0, 1.0, 4, 4)
    tris = mesh.triangles.astype(np.int32)
    b, area = elements.rest_geometry(mesh.vertices, tris)
    mu, lam = np.full(len(tris), 2.0), np.full(len(tris), 3.0)
    kinds = np.full(len(tris), kind, np.int32)
    x = mesh.vertices + 0.1 * rng.normal(size=mesh.vertices.shape)
    x[5] = x[0] + (x[0] - x[5])  # folds the triangles at vertex 5 over
    f = np.zeros_like(x)
    elements.element_forces(x, np.zeros_like(x), tris, b, area, mu, lam, np.zeros(len(tris)), kinds, False, f)
    assert np.allclose(f.sum(axis=0), 0.0, atol=1e-12)
    eps = 1e-6
    for v in range(len(x)):
        for c in range(2):
            d = np.zeros_like(x)
            d[v, c] = eps
            num = (elements.element_energy(x + d, tris, b, area, mu, lam, kinds).sum()
                   - elements.element_energy(x - d, tris, b, area, mu, lam, kinds).sum()) / (2 * eps)
            assert abs(f[v, c] + num) < 1e-5


def test_damping_resists_stretching_but_not_rigid_rotation():
    mesh = grid_mesh(1.0, 1.0, 3, 3)
    tris = mesh.triangles.astype(np.int32)
    b, area = elements.rest_geometry(mesh.vertices, tris)
    args = (tris, b, area, np.ones(len(tris)), np.ones(len(tris)), np.full(len(tris), 0.5),
            np.zeros(len(tris), np.int32))
    x = mesh.vertices.copy()
    spin = np.c_[-x[:, 1], x[:, 0]]  # rigid rotation about the origin
    f = np.zeros_like(x)
    elements.element_forces(x, spin, *args, True, f)
    assert np.abs(f).max() < 1e-12
    stretch = np.c_[x[:, 0], 0 * x[:, 1]]  # stretching along x
    elements.element_forces(x, stretch, *args, True, f)
    assert np.sum(f * stretch) < 0  # dissipates


def test_degenerate_triangle_is_refused():
    with pytest.raises(ValueError, match="triangle 0 .* has zero area"):
        elements.rest_geometry(np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]), np.array([[0, 1, 2]]))


# -- the world ----------------------------------------------------------------------------------

def test_fem_body_mass_is_density_times_area_lumped_on_the_vertices():
    w = deforma.World()
    b = w.add_body(grid_mesh(2.0, 1.0, 5, 3), material=material("neo-hookean", rho=7.0))
    assert math.isclose(b.mass, 14.0) and b.is_fem
    m = b.vertex_masses
    assert m[0] < m[6]  # a corner has fewer triangles around it than an inner vertex
    assert np.allclose(b.center_of_mass, m @ b.positions / m.sum())


def test_material_and_springs_parameters_do_not_mix():
    w = deforma.World()
    mesh = grid_mesh(1.0, 1.0, 3, 3)
    with pytest.raises(ValueError, match="do not pass mass"):
        w.add_body(mesh, material=material("corotated"), mass=2.0)
    assert not w.bodies
    b = w.add_body(mesh, material=material("corotated"))
    with pytest.raises(ValueError, match="no spring stiffness"):
        b.stiffness = 10.0
    with pytest.raises(ValueError, match="must be a deforma.Material"):
        b.material = "rubber"
    springs = w.add_body(mesh, position=(5, 0), material=deforma.Material("springs"), mass=3.0)
    assert springs.mass == 3.0 and not springs.is_fem


def test_fem_needs_triangles():
    chain = type("Chain", (), {"vertices": np.array([[0.0, 0.0], [1.0, 0.0]]), "edges": np.array([[0, 1]])})()
    w = deforma.World()
    with pytest.raises(ValueError, match="needs a mesh with triangles"):
        w.add_body(chain, material=material("corotated"))
    b = w.add_body(chain)
    with pytest.raises(ValueError, match="needs a mesh with triangles"):
        w.material = material("corotated")
    assert w.material is None and not b.is_fem


def test_switching_material_live_keeps_the_state_and_changes_the_model():
    w = deforma.World(dt=1e-3)
    b = w.add_body(grid_mesh(1.0, 1.0, 4, 4), position=(0, 2))
    for _ in range(10):
        w.step()
    x, v = b.positions.copy(), b.velocities.copy()
    b.material = material("neo-hookean")
    assert b.is_fem and w.model.n_springs == 0 and w.model.n_elements == len(b.triangles)
    assert np.array_equal(b.positions, x) and np.array_equal(b.velocities, v)
    b.material = None  # back to the world's: springs
    assert not b.is_fem and w.model.n_elements == 0


def test_elastic_energy_is_reported():
    w = deforma.World(gravity=(0, 0))
    b = w.add_body(grid_mesh(1.0, 1.0, 4, 4), material=material("corotated"))
    assert abs(w.energy().elastic) < 1e-12
    b.positions = b.positions * [1.1, 1.0]
    e = w.energy()
    assert e.elastic > 0 and math.isclose(e.total, e.kinetic + e.spring + e.gravitational + e.elastic)


@pytest.mark.parametrize("model", MODELS)
def test_free_fem_body_keeps_momentum(model):
    w = deforma.World(gravity=(0, 0), dt=1e-3)
    b = w.add_body(grid_mesh(1.0, 1.0, 6, 6), material=material(model, damping=1e-3))
    rng = np.random.default_rng(4)
    b.velocities = rng.normal(size=b.velocities.shape)
    m = b.vertex_masses
    p0 = m @ b.velocities
    for _ in range(200):
        w.step()
    assert np.allclose(m @ b.velocities, p0, atol=1e-9)


@pytest.mark.parametrize("model", MODELS)
def test_explicit_step_within_stable_dt_stays_bounded(model):
    w = deforma.World(dt=1 / 600, integrator="symplectic-euler", gravity=(0, 0))
    b = w.add_body(grid_mesh(1.0, 1.0, 8, 8), material=material(model, e=1e5, rho=1.0))
    rng = np.random.default_rng(5)
    b.positions = b.positions + 0.01 * rng.normal(size=b.positions.shape)
    w.dt = 0.95 * w.stable_dt()
    e0 = w.energy().total
    for _ in range(2000):
        w.step()
    assert w.energy().total < 1.5 * e0  # symplectic Euler: bounded, no growth


# -- pins -------------------------------------------------------------------------------------

@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("model", [None, "neo-hookean"])
def test_pinned_vertices_stay_put_under_every_integrator(integrator, model):
    w = deforma.World(integrator=integrator, dt=1 / 60 if integrator != "symplectic-euler" else 1e-3)
    b = w.add_body(grid_mesh(1.0, 0.2, 6, 3), position=(0, 2),
                   material=None if model is None else material(model, e=2e3, rho=1.0))
    if integrator == "symplectic-euler":
        w.dt = min(1e-3, 0.5 * w.stable_dt())
    left = np.flatnonzero(b.positions[:, 0] < b.positions[:, 0].min() + 1e-9)
    b.pin(left)
    held = b.positions[left].copy()
    g = w.grab(tuple(b.positions[left[0]]))  # pulling a pinned vertex does nothing either
    w.drag(g, (1.0, -3.0))
    for _ in range(60):
        w.step()
    assert np.array_equal(b.positions[left], held) and not b.velocities[left].any()
    assert b.positions[:, 1].min() < 1.9  # the rest hangs down
    b.unpin()
    assert not b.pinned.any()
    w.step()
    assert not np.array_equal(b.positions[left], held)


def test_bad_pins_are_refused_and_change_nothing():
    w = deforma.World()
    b = w.add_body(grid_mesh(1.0, 1.0, 3, 3))
    with pytest.raises(ValueError, match="vertex index 9 is out of range; body 0 has vertices 0..8"):
        b.pin([0, 9])
    with pytest.raises(ValueError, match="must be integers"):
        b.pin([0.5])
    with pytest.raises(ValueError, match=f"vertex index {2**70} is out of range; body 0 has vertices 0..8"):
        b.pin([0, 2**70])  # beyond int64
    assert not b.pinned.any()


@given(st.lists(st.integers(0, 8), max_size=9, unique=True))
@settings(max_examples=30, deadline=None)
def test_pin_mask_matches_the_indices(indices):
    w = deforma.World()
    b = w.add_body(grid_mesh(1.0, 1.0, 3, 3))
    b.pin(indices)
    assert sorted(np.flatnonzero(b.pinned).tolist()) == sorted(indices)
    assert (w.model.vertex_inv_mass[b.vertex_slice] == 0).tolist() == b.pinned.tolist()

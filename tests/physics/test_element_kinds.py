"""Element kinds as plug-ins: a kind written here, outside the package, runs under every
integrator; the built-in kinds' kernels agree with their energies; the integrators' loop over
the kinds gives what their compiled drivers give."""

import numpy as np
import pytest

import deforma
from deforma.physics.elements import springs as springs_module
from deforma.physics.elements import triangles as triangles_module
from deforma.physics.elements.kind import ElementKind, register_element_kind, unregister_element_kind
from deforma.physics.elements.triangles import deformation_gradients, rest_geometry

INTEGRATORS = ["symplectic-euler", "implicit-euler", "xpbd", "avbd"]


def area_shape(x, tris, b):
    """``J = A / A0`` (E,) of triangles ``tris`` (rest-shape inverses ``b``) and ``dJ/dx`` at
    their corners (E, 3, 2): the cofactor of ``F`` times each corner's shape-function gradient."""
    f = deformation_gradients(x, tris, b)
    j = f[:, 0, 0] * f[:, 1, 1] - f[:, 0, 1] * f[:, 1, 0]
    cof = np.stack([np.stack([f[:, 1, 1], -f[:, 1, 0]], 1), np.stack([-f[:, 0, 1], f[:, 0, 0]], 1)], 1)
    bb = b.reshape(-1, 2, 2)
    d = np.stack([-bb[:, 0] - bb[:, 1], bb[:, 0], bb[:, 1]], axis=1)  # D_i, D_j, D_k
    return j, np.einsum("erc,evc->evr", cof, d)


class AreaKind(ElementKind):
    """A toy kind: each triangle keeps its area, ``E = k/2 A0 (J - 1)^2`` with ``J = A / A0``
    (``k`` the material's Young's modulus, Pa); nothing resists shear."""

    name = "area"
    models = ("test-area",)

    def __init__(self, tris, b, area, k):
        self.vertices, self.b, self.area, self.k = tris, b, area, k
        self._lam = np.zeros(len(tris))

    @classmethod
    def build(cls, bodies):
        parts = []
        for body in bodies:
            t = np.asarray(body.topology.triangles, np.int64)
            b, area = rest_geometry(body.topology.rest_positions, t)
            parts.append((t + body.first_vertex, b, area, np.full(len(t), body.material.youngs_modulus)))
        return cls(*(np.concatenate(p) for p in zip(*parts)))

    def _shape(self, x):
        return area_shape(x, self.vertices, self.b)

    def energy(self, x):
        j, _ = self._shape(x)
        return 0.5 * self.k * self.area * (j - 1.0) ** 2

    def gradient_hessian(self, x):
        j, dj = self._shape(x)
        s = (self.k * self.area)[:, None, None]
        grad = s * (j - 1.0)[:, None, None] * dj
        g = dj.reshape(-1, 6)
        # J is bilinear in the corners: its Hessian is the constant cross term, projected below
        bb = self.b.reshape(-1, 2, 2)
        d = np.stack([-bb[:, 0] - bb[:, 1], bb[:, 0], bb[:, 1]], axis=1)
        hj = np.zeros((len(j), 6, 6))
        for v in range(3):
            for w in range(3):
                c = d[:, v, 0] * d[:, w, 1] - d[:, v, 1] * d[:, w, 0]  # d^2 J / dx_v dy_w
                hj[:, 2 * v, 2 * w + 1] = c
                hj[:, 2 * w + 1, 2 * v] = c
        hess = s * (g[:, :, None] * g[:, None, :] + (j - 1.0)[:, None, None] * hj)
        w, vec = np.linalg.eigh(hess)
        return grad, np.einsum("eij,ej,ekj->eik", vec, np.maximum(w, 0.0), vec)

    def begin_substep(self):
        self._lam[:] = 0.0

    def project(self, x, x_prev, inv_mass, h, sequence):
        for e in range(len(self.vertices)):  # Gauss-Seidel: one element after the other
            t = self.vertices[e]
            j, dj = (a[0] for a in area_shape(x, self.vertices[e:e + 1], self.b[e:e + 1]))
            w = inv_mass[t]
            alpha = 1.0 / (self.k[e] * self.area[e] * h * h)
            den = float(np.sum(w * np.einsum("vr,vr->v", dj, dj))) + alpha
            dlam = (-(j - 1.0) - alpha * self._lam[e]) / den
            self._lam[e] += dlam
            x[t] += w[:, None] * dj * dlam

    def matrix_weights(self, h):
        return 2.0 * h * h * self.k * self.area  # J's curvature bound at rest, |cof F|^2 = 2

    def matrix_entries(self, h, weights=None):
        w = self.matrix_weights(h) if weights is None else weights
        bb = self.b.reshape(-1, 2, 2)
        d = np.stack([-bb[:, 0] - bb[:, 1], bb[:, 0], bb[:, 1]], axis=1)
        dots = np.einsum("tvc,twc->tvw", d, d) * w[:, None, None]
        return np.repeat(self.vertices, 3, axis=1).ravel(), np.tile(self.vertices, (1, 3)).ravel(), dots.ravel()

    def stiffness_rows(self, n):
        bb = self.b.reshape(-1, 2, 2)
        d = np.stack([-bb[:, 0] - bb[:, 1], bb[:, 0], bb[:, 1]], axis=1)
        rows = np.abs(np.einsum("tvc,twc->tvw", d, d)).sum(axis=2) * (2.0 * self.k * self.area)[:, None]
        out = np.zeros(n)
        np.add.at(out, self.vertices.ravel(), rows.ravel())
        return out


@pytest.fixture
def area_kind():
    register_element_kind(AreaKind)
    yield AreaKind
    unregister_element_kind(AreaKind)


def squashed_area_body(integrator):
    """A 1 m square of the toy kind, squashed to 80% on each side (64% of its area), no gravity."""
    w = deforma.World(gravity=(0.0, 0.0), dt=1 / 120, integrator=integrator)
    mat = deforma.Material("test-area", youngs_modulus=200.0, poisson_ratio=0.3, density=1.0)
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=4, edges=True), material=mat,
                   position=(0, 0))
    b.positions[:] *= 0.8
    if integrator == "symplectic-euler":
        w.substeps = int(np.ceil(w.dt / (0.5 * w.stable_dt())))
    return w, b


def body_area(b):
    x, t = b.positions, b.triangles
    e1, e2 = x[t[:, 1]] - x[t[:, 0]], x[t[:, 2]] - x[t[:, 0]]
    return 0.5 * float(np.sum(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]))


@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_a_kind_written_outside_the_package_runs_under_every_integrator(area_kind, integrator):
    w, b = squashed_area_body(integrator)
    assert type(w.model.elements[-1]) is AreaKind and not w.model.fused
    assert b.mass == pytest.approx(1.0)  # density * area, as finite elements weigh
    a0 = body_area(b)
    largest = a0
    for _ in range(60):
        w.step()
        assert np.isfinite(b.positions).all()
        momentum = (b.vertex_masses[:, None] * b.velocities).sum(axis=0)
        assert np.abs(momentum).max() < 1e-9  # internal forces only
        largest = max(largest, body_area(b))
    assert a0 == pytest.approx(0.64)
    assert largest > 0.9  # pushed back out toward its rest area of 1 m^2
    assert w.energy().elastic >= 0.0


def test_a_material_of_an_unregistered_kind_is_refused_in_one_line():
    with pytest.raises(ValueError, match="material model must be one of 'springs', 'corotated', 'neo-hookean'"):
        deforma.Material("test-area", youngs_modulus=1.0, poisson_ratio=0.3, density=1.0)


def test_a_kind_may_not_take_a_built_in_model():
    class Copy(AreaKind):
        models = ("corotated",)

    with pytest.raises(ValueError, match="'corotated' is built in"):
        register_element_kind(Copy)


def finite_difference_check(kind, x, eps=1e-6, *, hessian=True):
    """The kind's gradient against central differences of its energy, and (``hessian``) its
    Hessian blocks against central differences of its gradient (where the projection leaves
    them alone)."""
    grad, hess = kind.gradient_hessian(x)
    verts = np.asarray(kind.vertices)
    k = verts.shape[1]
    num_g = np.zeros_like(grad)
    num_h = np.zeros_like(hess)
    for c in range(k):
        for r in range(2):
            for e in range(len(verts)):
                xp, xm = x.copy(), x.copy()
                xp[verts[e, c], r] += eps
                xm[verts[e, c], r] -= eps
                num_g[e, c, r] = (kind.energy(xp)[e] - kind.energy(xm)[e]) / (2 * eps)
                gp, gm = kind.gradient_hessian(xp)[0][e], kind.gradient_hessian(xm)[0][e]
                num_h[e, :, 2 * c + r] = (gp - gm).ravel() / (2 * eps)
    scale = max(1.0, np.abs(grad).max())
    np.testing.assert_allclose(grad, num_g, atol=1e-6 * scale, rtol=1e-5)
    if hessian:
        np.testing.assert_allclose(hess, num_h, atol=1e-5 * max(1.0, np.abs(hess).max()), rtol=1e-4)
    return hess


@pytest.mark.parametrize("law", ["corotated", "neo_hookean"])
def test_each_laws_stress_derivative_is_the_derivative_of_its_stress(law):
    from deforma.physics.elements import corotated, neo_hookean

    module = {"corotated": corotated, "neo_hookean": neo_hookean}[law]
    rng = np.random.default_rng(3)
    for f in [rng.normal(0, 1, 4) for _ in range(20)] + [np.array([1.1, 0.1, -0.2, 0.9]), np.array([-0.5, 0, 0, 1])]:
        h = np.zeros((4, 4))
        module.stress_derivative(*f, 2.0, 3.0, h)
        num = np.zeros((4, 4))
        for q in range(4):
            d = np.zeros(4)
            d[q] = 1e-6
            up, down = np.array(module.stress(*(f + d), 2.0, 3.0)), np.array(module.stress(*(f - d), 2.0, 3.0))
            num[:, q] = (up - down) / 2e-6
        np.testing.assert_allclose(h, num, atol=1e-6, rtol=1e-6)


@pytest.mark.parametrize("model", ["corotated", "neo-hookean"])
def test_triangle_gradients_and_hessians_match_their_energy(model):
    w = deforma.World(material=deforma.Material(model, youngs_modulus=1e3, poisson_ratio=0.3, density=1.0))
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2))
    rng = np.random.default_rng(1)
    x = b.positions @ np.array([[1.1, 0.05], [-0.03, 0.95]]) + rng.normal(0, 0.004, b.positions.shape)
    kind = w.model.triangles
    if model == "corotated":  # stretched, its Hessian needs no projection: all of it is checked
        finite_difference_check(kind, x)
    else:  # Neo-Hookean's turning mode sits at zero curvature and tips below it: the gradient only
        grad, _ = kind.gradient_hessian(x)
        verts = kind.vertices
        for e, c, r in [(0, 0, 0), (3, 1, 1), (7, 2, 0)]:
            xp, xm = x.copy(), x.copy()
            xp[verts[e, c], r] += 1e-6
            xm[verts[e, c], r] -= 1e-6
            assert grad[e, c, r] == pytest.approx((kind.energy(xp)[e] - kind.energy(xm)[e]) / 2e-6, rel=1e-5,
                                                  abs=1e-6)
    x = b.positions.copy()
    x[:, 0] *= -0.3  # inverted and crushed: the projection is at work
    _, hess = kind.gradient_hessian(x)
    assert np.linalg.eigvalsh(hess).min() >= -1e-9 * np.abs(hess).max()


def test_spring_gradients_and_hessians_match_their_energy():
    w = deforma.World(stiffness=300.0)
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=2))
    finite_difference_check(w.model.springs, b.positions * 1.2)  # every spring stretched
    _, hess = w.model.springs.gradient_hessian(b.positions * 0.7)  # compressed: projected
    assert np.linalg.eigvalsh(hess).min() >= -1e-9 * np.abs(hess).max()


def test_the_toy_kinds_gradient_matches_its_energy(area_kind):
    w, b = squashed_area_body("implicit-euler")
    x = b.positions / 0.8 * np.array([1.05, 0.97])
    # J is bilinear: stretched or squashed, its curvature has a negative part, which the
    # projection removes; the gradient is checked, the Hessian for being positive semi-definite
    hess = finite_difference_check(w.model.elements[-1], x, hessian=False)
    assert np.linalg.eigvalsh(hess).min() >= -1e-9 * np.abs(hess).max()


@pytest.mark.parametrize("model", ["springs", "corotated", "neo-hookean"])
def test_a_built_in_kinds_forces_are_minus_its_energy_gradient(model):
    material = None if model == "springs" else deforma.Material(model, youngs_modulus=1e3, poisson_ratio=0.3,
                                                                 density=1.0)
    w = deforma.World(material=material, damping=0.0)
    b = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=3))
    x = b.positions @ np.array([[1.1, 0.2], [0.0, 0.9]])
    for kind in w.model.elements:
        f = np.zeros_like(x)
        kind.forces(x, np.zeros_like(x), f)
        g = np.zeros_like(x)
        ElementKind.forces(kind, x, np.zeros_like(x), g)  # the default: minus the gradient
        np.testing.assert_allclose(f, g, atol=1e-9 * max(1.0, np.abs(f).max()))


def run_scene(name, integrator, steps, *, fused):
    from deforma import scene as scenes

    scene = scenes.load(name)
    w = scene.build()
    assert w.model.fused is fused
    w.integrator = integrator
    # (avbd's coarse level reads the built-in kinds' arrays itself: the loop over the kinds
    # runs without it, so both are compared without it)
    w.integrator_options = {"mode": "serial"} if integrator == "symplectic-euler" else \
        {"cluster_size": 0} if integrator == "avbd" else {}
    if integrator == "symplectic-euler":
        w.substeps = max(1, int(np.ceil(w.dt / w.stable_dt())))
    script = scenes.Script(scene, w)
    for _ in range(steps):
        script.apply()
        w.step()
    return np.concatenate([np.concatenate([b.positions, b.velocities], axis=1) for b in w.bodies])


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("scene", ["sample", "jelly", "tear"])
def test_the_loop_over_the_kinds_gives_what_the_compiled_drivers_give(monkeypatch, scene, integrator):
    fused = run_scene(scene, integrator, 60, fused=True)
    monkeypatch.setattr(springs_module.SpringKind, "fused", False)
    monkeypatch.setattr(triangles_module.TriangleKind, "fused", False)
    looped = run_scene(scene, integrator, 60, fused=False)
    if integrator == "implicit-euler":  # the matrix is merged kind by kind: summed in another order
        np.testing.assert_allclose(looped, fused, rtol=0, atol=1e-9 * max(1.0, np.abs(fused).max()))
    else:
        np.testing.assert_array_equal(looped, fused)


def test_a_registered_kind_is_a_material_of_scene_files_too(area_kind, tmp_path):
    path = tmp_path / "area.toml"
    path.write_text('[physics]\nmaterial = "test-area"\nyoungs_modulus = 200.0\npoisson_ratio = 0.3\ndensity = 1.0\n'
                    'gravity = [0.0, 0.0]\n\n[[body]]\nshape = "box"\ndetail = 3\n')
    w = deforma.load_scene(str(path))
    assert type(w.model.elements[-1]) is AreaKind and w.bodies[0].material.model == "test-area"
    w.step()
    unregister_element_kind(AreaKind)
    with pytest.raises(ValueError, match="physics.material: unknown value 'test-area'"):
        deforma.load_scene(str(path))

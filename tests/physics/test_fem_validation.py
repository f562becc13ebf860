"""Finite elements against known answers: a hanging column, flat landings, mesh independence,
and inverted triangles that recover under every integrator."""

import numpy as np
import pytest

import deforma
from deforma.physics.elements.triangles import signed_areas

MODELS = ["corotated", "neo-hookean"]
INTEGRATORS = ["symplectic-euler", "implicit-euler", "xpbd"]

# The column of the issue: 0.2 m x 2 m, E = 1e5 Pa, nu = 0.3, 100 kg/m^2, top row pinned.
E, NU, RHO, G, L, W = 1e5, 0.3, 100.0, 9.81, 2.0, 0.2


def column(nx):
    """The column as a grid of nx x 10 nx cells, top edge at y = 0."""
    ny = 10 * nx
    xs, ys = np.meshgrid(np.linspace(0, W, nx + 1), np.linspace(-L, 0, ny + 1))
    idx = np.arange((nx + 1) * (ny + 1)).reshape(ny + 1, nx + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    return deforma.mesh.Mesh(np.c_[xs.ravel(), ys.ravel()], np.r_[np.c_[a, b, c], np.c_[a, c, d]])


def hang(model, nx, integrator, *, substeps=1, plane="stress"):
    """Settled column: (elongation of the bottom edge, lateral strain at mid-height)."""
    # (sleep off: the solver's own rest is measured)
    w = deforma.World(integrator=integrator, air_drag=20.0, dt=1 / 60, substeps=substeps, sleep=False)
    m = column(nx)
    mat = deforma.Material(model, youngs_modulus=E, poisson_ratio=NU, density=RHO, plane=plane)
    b = w.add_body(m, material=mat, position=None)
    b.pin(np.flatnonzero(np.isclose(m.vertices[:, 1], 0.0)))
    if integrator == "symplectic-euler":
        w.dt = 0.9 * w.stable_dt()
    for _ in range(int(3.0 / w.dt)):
        w.step()
    assert np.abs(b.velocities).max() < 1e-3  # settled
    bottom = np.isclose(m.vertices[:, 1], -L)
    mid = np.isclose(m.vertices[:, 1], -L / 2)
    width = np.ptp(b.positions[mid, 0])
    return -L - b.positions[bottom, 1].mean(), (width - W) / W


EXPECTED = RHO * G * L * L / (2 * E)  # the bar's own weight: integral of rho g (L - y) / E


@pytest.mark.parametrize("model", MODELS)
def test_hanging_column_elongation_and_contraction_at_three_resolutions(model):
    for nx in (4, 8, 16):  # each twice as fine as the last
        elongation, lateral = hang(model, nx, "implicit-euler")
        assert abs(elongation / EXPECTED - 1) < 0.03, (nx, elongation, EXPECTED)
        axial = RHO * G * (L / 2) / E  # strain at mid-height
        assert abs(-lateral / axial / NU - 1) < 0.15, (nx, lateral, axial)


@pytest.mark.parametrize("model", MODELS)
def test_hanging_column_in_plane_strain(model):
    # the cross-section of a long body: it cannot strain along its length, so it is stiffer
    # in the plane by 1 / (1 - nu^2) and narrows by nu / (1 - nu) of its stretch
    for nx in (4, 8):
        elongation, lateral = hang(model, nx, "implicit-euler", plane="strain")
        assert abs(elongation / (EXPECTED * (1 - NU * NU)) - 1) < 0.03, (nx, elongation)
        axial = RHO * G * (L / 2) / E * (1 - NU * NU)
        assert abs(-lateral / axial / (NU / (1 - NU)) - 1) < 0.15, (nx, lateral, axial)


@pytest.mark.parametrize("model", MODELS)
def test_hanging_column_under_the_other_integrators(model):
    elongation, _ = hang(model, 4, "symplectic-euler")
    assert abs(elongation / EXPECTED - 1) < 0.03
    # XPBD converges to the same answer as its substeps shrink (docs/integrators.md)
    elongation, _ = hang(model, 4, "xpbd", substeps=200)
    assert abs(elongation / EXPECTED - 1) < 0.03


def landing(model, integrator, *, detail=8, e=3e3, seconds=4.0):
    """A 1.5 x 1 m box dropped flat from 2.5 m onto a flat floor: (turn in degrees, sideways
    drift, centroid height, inverted triangles at the end)."""
    w = deforma.World(integrator=integrator, dt=1 / 60, sleep=False)  # (sleep off: the solver's own rest is measured)
    w.add_collider(deforma.Rect((0, 0), (7, 0.4), 0))
    m = deforma.mesh.box(((-0.75, -0.5), (0.75, -0.5), (0.75, 0.5), (-0.75, 0.5)), detail=detail, edges=True)
    mat = deforma.Material(model, youngs_modulus=e, poisson_ratio=0.3, density=1.0, damping=0.01)
    b = w.add_body(m, position=(0, 2.5), material=mat)
    if integrator == "symplectic-euler":
        w.substeps = int(np.ceil(w.dt / (0.9 * w.stable_dt())))
    elif integrator == "xpbd":
        w.substeps = 20
    x0, c0 = b.positions.copy(), b.center_of_mass
    for _ in range(int(seconds / w.dt)):
        w.step()
    x, c = b.positions, b.center_of_mass
    u, _, vt = np.linalg.svd((x0 - c0).T @ (x - c))  # best-fit rotation (Kabsch)
    r = vt.T @ u.T
    turn = np.degrees(np.arctan2(r[1, 0], r[0, 0]))
    return turn, c[0] - c0[0], c[1], int((signed_areas(x, b.triangles) <= 0).sum())


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("model", MODELS)
def test_box_dropped_flat_lands_without_turning(model, integrator):
    turn, drift, height, inverted = landing(model, integrator)
    assert abs(turn) < 1.0 and abs(drift) < 0.01
    assert abs(height - 0.7) < 0.01 and inverted == 0  # resting on the floor (top at 0.2)


@pytest.mark.parametrize("model", MODELS)
def test_the_same_body_at_two_resolutions_rests_at_the_same_height(model):
    # soft enough to sag visibly (about 2.5 cm), so that a resolution-dependent stiffness would show
    heights = [landing(model, "implicit-euler", detail=d, e=200.0, seconds=6.0)[2] for d in (6, 12)]
    assert heights[0] < 0.7 - 0.01  # it does sag
    assert abs(heights[0] / heights[1] - 1) < 0.01, heights


@pytest.mark.parametrize("integrator", INTEGRATORS)
@pytest.mark.parametrize("model", MODELS)
def test_a_triangle_turned_inside_out_by_hand_recovers_within_a_second(model, integrator):
    w = deforma.World(integrator=integrator, gravity=(0, 0), dt=1 / 60, substeps=1 if integrator != "xpbd" else 10)
    m = deforma.mesh.box(((0, 0), (1, 0), (1, 1), (0, 1)), detail=4, edges=True)
    mat = deforma.Material(model, youngs_modulus=1e3, poisson_ratio=0.3, density=1.0, damping=0.01)
    b = w.add_body(m, material=mat, self_collision=False)
    if integrator == "symplectic-euler":
        w.substeps = int(np.ceil(w.dt / (0.9 * w.stable_dt())))
    # the triangle around the centre: move its first vertex across the opposite edge
    x = b.positions
    t = b.triangles[np.argmin(np.linalg.norm(x[b.triangles].mean(axis=1) - 0.5, axis=1))]
    p, q, r = x[t[0]], x[t[1]], x[t[2]]
    edge = r - q
    foot = q + edge * ((p - q) @ edge) / (edge @ edge)
    x[t[0]] = foot + 0.6 * (foot - p)  # mirrored across the edge, a bit closer to it
    assert (signed_areas(b.positions, b.triangles) <= 0).any()
    for _ in range(60):
        w.step()
    assert not (signed_areas(b.positions, b.triangles) <= 0).any()

"""A soft disc resting on a floor under its own weight against 2D Hertz contact.

A cylinder of radius R pressed on a rigid flat by a load P per unit length touches it over
a half-width ``a = sqrt(4 P R / (pi E*))`` (Johnson, Contact Mechanics, 4.2); for a sheet
in plane stress, deforma's default, ``E* = E``. Here the load is the disc's own weight,
``P = rho pi R^2 g``, and ``E`` is chosen so that ``a / R = sqrt(4 rho g R / E) = 0.15``:
small enough for Hertz's half-space, wide enough to span several mesh edges. The contact is
measured as half the spread of the vertices within 50 um of the floor, so it is quantised
by the outline's spacing ``h``: the last touching vertex lies up to one ``h`` inside ``a``
(0.91 of ``a`` at h = 2 cm and 1.4 cm, 0.97 at 1 cm, measured).

The answer does not depend on the step: the same within rounding at 1/60 s and 1/600 s,
under the default symplectic Euler (substeps="auto"), the converged implicit solvers and avbd.
Air drag lets the disc settle without changing where it rests.
"""

import math

import numpy as np
import pytest

import deforma

R, RHO, G = 0.5, 1000.0, 9.81
E = 4 * RHO * G * R / 0.15**2  # a / R = 0.15


def disc(h):
    """A disc of radius R: its outline at spacing h, a hexagonal lattice of spacing h inside,
    triangulated by deforma's own Delaunay."""
    n = int(round(2 * math.pi * R / h))
    t = np.arange(n) * 2 * math.pi / n
    rows = []
    for k, y in enumerate(np.arange(-R, R + h, h * math.sqrt(3) / 2)):
        x = np.arange(-R, R + h, h) + (h / 2 if k % 2 else 0.0)
        rows.append(np.c_[x, np.full_like(x, y)])
    inner = np.concatenate(rows)
    points = np.concatenate([np.c_[R * np.cos(t), R * np.sin(t)], inner[np.hypot(*inner.T) < R - 0.8 * h]])
    return deforma.mesh.Mesh(points, deforma.mesh.delaunay(points))


def half_width(h, dt, integrator, options=None):
    mat = deforma.Material("corotated", youngs_modulus=E, poisson_ratio=0.3, density=RHO)
    # (sleep off: the solver's own rest, and its jitter below, are measured)
    w = deforma.World(dt=dt, material=mat, integrator=integrator, air_drag=5.0, sleep=False,
                      **({"integrator_options": options} if options else {}))
    w.add_collider(deforma.Rect((0.0, -0.25), (4.0, 0.5), 0.0))
    b = w.add_body(disc(h), position=(0.0, R + 1e-6))  # touching the floor, at rest
    for _ in range(round(3.0 / dt)):
        w.step()
    # settled to within contact jitter: symplectic Euler's outline vertices keep a few mm/s
    # (measured 2-4.4 mm/s; the implicit solvers' 0.05-1.8 mm/s), a tremble that does not
    # move the patch
    assert np.abs(b.velocities).max() < 1e-2
    x = b.positions
    return 0.5 * np.ptp(x[x[:, 1] < 1e-4 * R, 0])


HERTZ = math.sqrt(4 * RHO * math.pi * R * R * G * R / (math.pi * E))  # 0.075 m


@pytest.mark.parametrize("h", [0.02, 0.014])
@pytest.mark.parametrize("dt", [1 / 60, 1 / 600])
def test_the_default_world_rests_a_disc_on_its_hertz_half_width_at_any_step(h, dt):
    assert half_width(h, dt, "symplectic-euler") == pytest.approx(HERTZ, rel=0.15)


@pytest.mark.parametrize("integrator, options", [("implicit-bdf2", None), ("implicit-euler", {"tolerance": 1e-3}),
                                                 ("avbd", None)])
def test_the_converged_implicit_solvers_rest_it_there_at_a_display_step(integrator, options):
    # (avbd at its default ten sweeps a step: 0.911 of a on both meshes, as the others)
    for h in (0.02, 0.014) if integrator == "avbd" else (0.02,):
        assert half_width(h, 1 / 60, integrator, options) == pytest.approx(HERTZ, rel=0.15)

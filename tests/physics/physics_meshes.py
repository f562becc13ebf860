"""Small meshes for the physics tests, built without deforma.mesh.box (not a dependency here),
and the setups and measurements several test files share."""

import math

import numpy as np

import deforma
from deforma.mesh import Mesh


def grid_mesh(width, height, nx, ny, *, angle=0.0, center=(0.0, 0.0), alternate=False):
    """A width x height (m) rectangle of nx x ny vertices, split into right triangles,
    rotated by ``angle`` degrees about its centre and centred on ``center``.

    With ``alternate`` the cells' diagonals alternate like a checkerboard, so the spring
    lattice is as stiff in one shear direction as in the other (one diagonal everywhere
    makes a square shear and turn under load)."""
    xs, ys = np.meshgrid(np.linspace(-width / 2, width / 2, nx), np.linspace(-height / 2, height / 2, ny))
    v = np.c_[xs.ravel(), ys.ravel()]
    idx = np.arange(nx * ny).reshape(ny, nx)
    a, b = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    c, d = idx[1:, 1:].ravel(), idx[1:, :-1].ravel()
    flip = (np.add.outer(np.arange(ny - 1), np.arange(nx - 1)).ravel() % 2 == 1) & alternate
    tris = np.r_[np.c_[a, b, np.where(flip, d, c)], np.c_[np.where(flip, b, a), c, d]]
    t = math.radians(angle)
    rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    return Mesh(v @ rot.T + np.asarray(center, float), tris)


class Chain:
    """Vertices joined by springs, without triangles (e.g. two masses on one spring)."""

    def __init__(self, vertices, edges):
        self.vertices = np.asarray(vertices, float)
        self.edges = np.asarray(edges, np.int32)


def random_body(world, seed, *, self_collision=True):
    """A 7 x 5-vertex body added to ``world``, its positions jittered by 3 cm and its
    velocities random (0.5 m/s scale), from ``seed``."""
    rng = np.random.default_rng(seed)
    b = world.add_body(grid_mesh(1.0, 0.6, 7, 5), position=(0, 0), self_collision=self_collision)
    b.positions[:] += rng.normal(scale=0.03, size=b.positions.shape)
    b.velocities[:] = rng.normal(scale=0.5, size=b.velocities.shape)
    return b


def slide_acceleration(world, body, along, *, steps, after):
    """Step ``world`` ``steps`` times; the acceleration (m/s^2) of ``body``'s centre of mass
    down the direction ``-along``, fitted as a parabola to the times past ``after`` s, and the
    positions along ``along`` at every step."""
    times, where = [], []
    for _ in range(steps):
        world.step()
        times.append(world.time)
        where.append(body.center_of_mass @ along)
    times, where = np.array(times), np.array(where)
    late = times > after
    return -2 * np.polyfit(times[late], where[late], 2)[0], where[late]


def head_on(name, *, dt, substeps):
    """Two bodies (2 kg and 0.5 kg) about to collide head-on, without gravity or colliders."""
    w = deforma.World(dt=dt, substeps=substeps, gravity=(0, 0), stiffness=3000.0, damping=2.0, integrator=name)
    a = w.add_body(grid_mesh(0.6, 0.4, 7, 5), position=(-0.5, 0.0), mass=2.0)
    b = w.add_body(grid_mesh(0.4, 0.6, 5, 7), position=(0.5, 0.1), mass=0.5)
    a.velocities, b.velocities = (2.0, 0.0), (-3.0, 0.5)
    return w, a, b


def chain(w, links, weight_ratio, material, length=0.1, width=0.02, gap=0.002):
    """``links`` links of ``length`` (m) and ``material`` (rigid) hanging from the world at the
    origin, each pinned ``gap`` below the top of the one above, and a square weight of
    ``weight_ratio`` links pinned under the last; returns the weight and its joint
    (tests/physics/test_joints.py, benchmarks/bench_joints.py)."""
    bodies = []
    for i in range(links):
        m = deforma.mesh.box(((0, 0), (width, 0), (width, length - gap), (0, length - gap)), detail=1)
        bodies.append(w.add_body(m, position=(0.0, -length / 2 - i * length), material=material))
    side = math.sqrt(weight_ratio * bodies[0].mass / material.density)
    m = deforma.mesh.box(((0, 0), (side, 0), (side, side), (0, side)), detail=1)
    weight = w.add_body(m, position=(0.0, -links * length - side / 2 - gap), material=material)
    w.join(bodies[0], None, at=(0.0, -gap))
    for i in range(1, links):
        w.join(bodies[i], bodies[i - 1], at=(0.0, -i * length - gap))
    return weight, w.join(weight, bodies[-1], at=(0.0, -links * length - 1.5 * gap))

"""The kernels against plain NumPy references, and the parallel paths against the serial ones."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import deforma
from deforma.physics.integrators import symplectic
from deforma.physics.integrators.driver import DriverChoice
from deforma.physics.colliders.shapes import Rect, pack_colliders
from deforma.physics.colliders.response import collide_point
from deforma.physics.elements.springs import spring_force
from physics_meshes import grid_mesh


def numpy_forces(x, v, mass, si, sj, rest, ks, kd, g):
    d = x[sj] - x[si]
    length = np.linalg.norm(d, axis=1)
    n = d / length[:, None]
    vij = np.einsum("ij,ij->i", v[sj] - v[si], n)
    fij = (ks * (length - rest) + kd * vij)[:, None] * n
    f = mass[:, None] * np.asarray(g)[None, :]
    np.add.at(f, si, fij)
    np.add.at(f, sj, -fij)
    return f


def perturbed_world(n=12):
    w = deforma.World(dt=1 / 600, integrator="symplectic-euler", stiffness=300.0, damping=0.7, mass=2.0)
    b = w.add_body(grid_mesh(1.0, 0.5, n, n // 2), position=(0, 0))
    rng = np.random.default_rng(0)
    b.positions = b.positions + rng.normal(scale=0.02, size=b.positions.shape)
    b.velocities = rng.normal(size=b.positions.shape)
    return w, b


def test_the_spring_force_matches_the_textbook_formula():
    w, b = perturbed_world()
    m, s = w.model, w.state
    f = np.zeros_like(s.x)
    for e in range(m.n_springs):
        i, j = m.spring_i[e], m.spring_j[e]
        fx, fy = spring_force(*s.x[i], *s.x[j], *s.v[i], *s.v[j], m.spring_rest_length[e], m.spring_stiffness[e],
                              m.spring_damping[e])
        f[i] += fx, fy
        f[j] -= fx, fy
    f += m.vertex_mass[:, None] * np.array([0.0, -9.81])
    ref = numpy_forces(s.x, s.v, m.vertex_mass, m.spring_i, m.spring_j, m.spring_rest_length,
                       m.spring_stiffness, m.spring_damping, (0.0, -9.81))
    assert np.allclose(f, ref, rtol=1e-12, atol=1e-9)


def test_one_step_matches_a_numpy_symplectic_euler_step():
    w, b = perturbed_world()
    m = w.model
    x, v = b.positions.copy(), b.velocities.copy()
    h = w.dt
    f = numpy_forces(x, v, m.vertex_mass, m.spring_i, m.spring_j, m.spring_rest_length, m.spring_stiffness,
                     m.spring_damping, w.gravity)
    v1 = v + h * f / m.vertex_mass[:, None]
    x1 = x + h * v1
    w.step()
    assert np.allclose(b.velocities, v1, rtol=1e-12, atol=1e-12)
    assert np.allclose(b.positions, x1, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("material", [None, "corotated", "neo-hookean"])
def test_parallel_and_serial_steps_agree_exactly(material):
    runs = []
    for kernel in (symplectic.symplectic_euler_serial, symplectic.symplectic_euler_parallel):
        w, b = perturbed_world(40)
        if material is not None:  # the same mesh as finite elements, with damping
            b.material = deforma.Material(material, youngs_modulus=100.0, poisson_ratio=0.3, density=4.0,
                                          damping=0.002)
        w.add_collider(Rect((0, -0.3), (3, 0.2), 10.0))
        w.add_collider(Rect((0.3, 0.0), (0.2, 0.2), 45.0))
        w.grab((0.0, 0.0), radius=0.1)
        h = min(1e-3, 0.5 * w.stable_dt())  # within the elements' stable step
        w._pack_colliders()
        w._rebuild_grabs()
        m, s, control, contacts = w.model, w.state, w.control, w._contacts
        fbuf = np.zeros((3, m.n_vertices, 2))  # the same 3 chunks of springs and elements for both
        chunks, elem_chunks, verts = symplectic.merged_chunks(m.spring_i, m.spring_j, m.elem, 3)
        for _ in range(50):
            kernel(s.x, s.v, fbuf, chunks, elem_chunks, verts, m.springs.arrays, m.triangles.arrays,
                   bool(m.elem_damping.any()), m.vertex_inv_mass, 0.0, -9.81, 1.0, control.force, control.has_force,
                   control.grab_slot, control.grab_pull, control.colliders, contacts.hits, m.contact,
                   contacts.scratch, contacts.buffer, h, 2, 1e6)
        assert not fbuf.any()  # scratch left zeroed
        assert np.isfinite(s.x).all()
        runs.append((s.x.copy(), s.v.copy()))
    assert np.array_equal(runs[0][0], runs[1][0]) and np.array_equal(runs[0][1], runs[1][1])


def test_collide_point_puts_a_point_on_the_face_it_came_through():
    r = Rect((0, 0), (2, 2), 30.0)
    packed = pack_colliders([r], friction=0.0, static_friction=0.0)
    u, wv = r.axes
    # a point coming down through the top face, slightly inside; frictionless: keeps sliding
    prev = 1.01 * wv + 0.2 * u
    x = (0.99 * wv + 0.3 * u)[None, :].copy()
    v = (-1.0 * wv + 5.0 * u)[None, :].copy()
    x[0, 0], x[0, 1], v[0, 0], v[0, 1], *_ = collide_point(*prev, *x[0], *v[0], packed, 0.02)
    assert not r.contains(x).any()
    assert abs(x[0] @ wv - 1.0) < 1e-8  # on the top face
    assert abs(x[0] @ u - 0.3) < 1e-12  # motion along the face kept
    assert abs(v[0] @ wv) < 1e-12 and abs(v[0] @ u - 5.0) < 1e-12


def test_world_results_do_not_depend_on_the_threading_mode():
    runs = []
    for mode in ("serial", "parallel", "auto"):
        w, b = perturbed_world(40)  # 800 vertices: above PARALLEL_MIN_VERTICES
        w.add_collider(Rect((0, -0.4), (3, 0.2), 10.0))  # clear of the body at the start, hit soon
        w.integrator_options = {"mode": mode}
        w.substeps = 4
        for _ in range(150):
            w.step()
        runs.append(b.positions.copy())
    assert np.array_equal(runs[0], runs[1]) and np.array_equal(runs[0], runs[2])


def test_avbd_results_do_not_depend_on_the_threading_mode():
    # its sweep runs each colour's vertices without contact rows in parallel, then those with
    # rows one by one: the same result as one thread, bit for bit
    runs = []
    for mode in ("serial", "parallel", "auto"):
        w, b = perturbed_world(40)
        w.integrator, w.dt, w.substeps = "avbd", 1 / 60, 1
        w.add_collider(Rect((0, -0.4), (3, 0.2), 10.0))
        w.integrator_options = {"mode": mode}
        for _ in range(40):
            w.step()
        assert w.integrator_stats["contacts"] > 0
        runs.append(b.positions.copy())
    assert np.array_equal(runs[0], runs[1]) and np.array_equal(runs[0], runs[2])


def test_auto_mode_uses_the_faster_driver_and_probes_the_other_less_while_it_loses():
    d = DriverChoice()
    d._samples = {"parallel": [1.0, 1.2, 0.9], "serial": [2.0, 2.1, 1.9]}
    d._estimate = {"parallel": 1.0, "serial": 2.0}
    picks = [d.choose() for _ in range(200)]
    assert picks[:15] == ["parallel"] * 15 and picks[15:17] == ["serial"] * 2  # probe: two calls
    assert picks.count("serial") < 12  # 16, 32, 64, 128: fewer and fewer probes
    d.reset()
    d._samples = {"parallel": [30.0] * 3, "serial": [1.0] * 3}  # threads starved by other work
    d._estimate = {"parallel": 30.0, "serial": 1.0}
    picks = [d.choose() for _ in range(1000)]
    assert picks.count("parallel") == 2  # one probe, then none for 4096 calls
    d._estimate["parallel"] = 0.5  # cores free again: the probe wins, parallel is used
    assert d.choose() == "parallel"


def test_the_implicit_matrix_assembly_matches_a_dense_sum():
    from deforma.physics.integrators.implicit.assembly import system_matrix, with_entries

    w = deforma.World(stiffness=300.0, damping=0.7)
    w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 0.5), (0, 0.5)), detail=3), position=(0, 1))  # springs
    rubber = deforma.Material("neo-hookean", youngs_modulus=1e3, poisson_ratio=0.3, density=1.0, damping=0.01)
    fem = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 0.5), (0, 0.5)), detail=2), position=(2, 1),
                     material=rubber)
    fem.pin([0, 3])
    m, h = w.model, 0.01
    n = m.n_vertices
    rng = np.random.default_rng(7)
    grab_slot = np.full(n, -1, np.int32)
    grab_slot[[2, 20]] = [0, 1]
    grab_pull = rng.uniform(1, 5, (2, 3))
    mass = m.vertex_mass * 1.01
    a, diag = system_matrix(m, grab_slot, grab_pull, h, mass)
    dense = np.diag(mass)
    dense[[2, 20], [2, 20]] += h * h * grab_pull[:, 0]
    ws = h * h * m.spring_stiffness + h * m.spring_damping
    for i, j, wk in zip(m.spring_i, m.spring_j, ws):
        dense[[i, j, i, j], [j, i, i, j]] += [-wk, -wk, wk, wk]
    for tri, b, we in zip(m.elem, m.elem_b, m.triangles.matrix_weights(h)):
        bb = b.reshape(2, 2)
        d = np.stack([-bb[0] - bb[1], bb[0], bb[1]])
        dense[np.ix_(tri, tri)] += we * d @ d.T
    assert np.allclose(diag, np.diag(dense), rtol=1e-14, atol=0)
    pinned = m.pinned
    assert pinned.sum() == 2
    dense[pinned] = 0.0
    dense[pinned, pinned] = 1.0
    assert a.has_canonical_format and np.allclose(a.toarray(), dense, rtol=0, atol=1e-12)
    off = a.indices != np.repeat(np.arange(n), np.diff(a.indptr))
    assert np.all(a.data[off] != 0.0)  # no stored zero off the diagonal
    assert (dense[~pinned] == 0.0).sum() > 0 and (a.toarray() != 0).sum() == (np.abs(dense) > 1e-12).sum()
    more_r, more_c, more_v = rng.integers(0, n, 80), rng.integers(0, n, 80), rng.normal(size=80)
    b = with_entries(a, more_r, more_c, more_v, pinned)
    keep = ~pinned[more_r]
    np.add.at(dense, (more_r[keep], more_c[keep]), more_v[keep])
    assert b.has_canonical_format and np.allclose(b.toarray(), dense, rtol=0, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 30), st.lists(st.tuples(st.integers(0, 29), st.integers(0, 29)), max_size=40))
def test_island_labels_are_scipys_connected_components(n, links):
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    from deforma.physics.sleeping import islands

    links = np.array([(a % n, b % n) for a, b in links], np.int64).reshape(-1, 2)
    graph = coo_matrix((np.ones(len(links)), (links[:, 0], links[:, 1])), shape=(n, n))
    np.testing.assert_array_equal(islands(n, links), connected_components(graph, directed=False)[1])


def _contacts_found(topo, x0, x1, margins):
    """The candidate pairs and the contacts (vertex, edge, kind) in order of the motion
    ``x0 -> x1`` under the ContactTopology ``topo`` with its margins replaced by ``margins``."""
    from deforma.physics.contact.broad_phase import build_grid, gather_start
    from deforma.physics.contact.contacts import make_buffer, make_scratch
    from deforma.physics.contact.narrow_phase import activate_vertices, check_pairs, narrow_phase

    t = topo._replace(margin=np.array(margins, float))
    scr = make_scratch(len(t.cv_vertex), len(t.ce_a), len(t.body_thickness))
    buf = make_buffer(20_000, 2_000_000)
    gather_start(x0, t, scr)
    activate_vertices(x1, t, scr)
    build_grid(x1, t, scr, t.margin[0])
    n = narrow_phase(x1, t, scr, buf)
    c = check_pairs(x1, t, scr, buf, 0, n, True, False)
    assert n >= 0 and c >= 0
    return n, list(zip(buf.vertex[:c].tolist(), buf.edge[:c].tolist(), buf.kind[:c].tolist()))


@settings(max_examples=25, deadline=None)
@given(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-0.3, 1.0), st.floats(-0.5, 0.5))
@example(0.5, 0.2, 0.0, 0.0).via("squeezed flat in flight")
@example(0.3, 0.2, -0.2, 0.2).via("turned inside out in flight")
@example(0.5, 0.2, 1.0, 0.0).via("a pure flight")
def test_a_bodys_own_pairs_listed_by_its_relative_motion_lose_no_contact(dx, dy, squeeze, turn):
    # a donut flies (dx, dy) in a step while its hole is squeezed shut (squeeze <= 0: its
    # outline crosses itself) and it turns: the pairs
    # of its outline with itself are listed by how it moves relative to itself (margin[1]: the
    # slack; 0, the tightest, for a search done once), and must give the same contacts, in the
    # same order, as every pair whose swept boxes overlap (margin[1] = inf)
    w = deforma.World()
    b = w.add_body(deforma.mesh.from_image("donut", resolution=12, scale=0.0012), position=(0.0, 0.0))
    topo = w.model.contact
    x0 = b.positions.copy()
    c = x0.mean(axis=0)
    r = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    x1 = (x0 - c) * [1.0, squeeze] @ r.T + c + [dx, dy]
    every_n, every = _contacts_found(topo, x0, x1, [topo.margin[0] + 2.0 * np.hypot(dx, dy), np.inf])
    own_n, own = _contacts_found(topo, x0, x1, [topo.margin[0] + 2.0 * np.hypot(dx, dy), 0.0])
    assert own == every
    assert own_n <= every_n
    if squeeze <= 0.0:  # the outline went through itself: contacts to find
        assert len(every) > 100
    if squeeze == 1.0 and turn == 0.0 and np.hypot(dx, dy) > 0.1:  # a pure flight lists almost nothing
        assert own_n < every_n / 10

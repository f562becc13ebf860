"""A torn body's incremental rebuild gives exactly what a rebuild from scratch gives.

A tear updates the body's topology and its tear check's edge table from the ones before the
tear (:func:`deforma.physics.behaviours.tearing.torn_topologies`) and reuses the triangles' rest
geometry; these tests tear sheets and compare every array, bit for bit, with
``BodyTopology.from_arrays`` / ``TearTopology.of`` of the torn mesh and with the Model those
make, and the split itself with the straightforward fan search it replaced.
"""

import numpy as np
import pytest

import deforma
from deforma.physics.behaviours import tearing
from deforma.physics.topology import BodyTopology, element_geometry, lengths, stable_order
from deforma.physics.model import Model

BODY_FIELDS = ("rest_positions", "springs", "spring_rest_length", "triangles", "boundary_edges",
               "boundary_vertices", "boundary_clearance", "mass_share")
TEAR_FIELDS = ("triangles", "pairs", "tri_pair", "inner", "boundary", "b", "area", "normal", "keys",
               "vertex_ptr", "vertex_tris", "tri_edge", "inner_tri")
MODEL_FIELDS = ("vertex_mass", "vertex_inv_mass", "spring_i", "spring_j", "spring_rest_length", "elem", "elem_b",
                "elem_area", "vertex_area", "pinned", "body_vertex_offsets", "body_spring_offsets",
                "body_elem_offsets")
CONTACT_FIELDS = ("cv_vertex", "cv_body", "vertex_cv", "body_outline", "body_interior", "tri", "body_tri", "ce_a",
                  "ce_b", "ce_body", "thick_other", "thick_self")


def same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b)


def reference_edges(n, t):
    """Edge pairs, their triangles and the triangles around each vertex, as NumPy's stable
    argsort orders them (what TearTopology.of computed before its faster sort)."""
    t = np.asarray(t, dtype=np.int64)
    half = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    owner = np.tile(np.arange(len(t)), 3)
    lo, hi = half.min(axis=1), half.max(axis=1)
    order = np.argsort(lo * n + hi, kind="stable")
    keys, owner, lo, hi = (lo * n + hi)[order], owner[order], lo[order], hi[order]
    first = np.ones(len(keys), bool)
    first[1:] = keys[1:] != keys[:-1]
    start = np.flatnonzero(first)
    two = np.diff(np.append(start, len(keys))) == 2
    tri_pair = np.full((len(start), 2), -1, np.int64)
    tri_pair[:, 0] = owner[start]
    tri_pair[two, 1] = owner[start[two] + 1]
    return np.stack([lo[start], hi[start]], axis=1), tri_pair, np.argsort(t.ravel(), kind="stable") // 3


def reference_tear(topo, x, limit, tips):
    """The tear as the fan search before the incremental rebuild found it (Python, per vertex),
    with the running cracks' ``tips`` (while there are any, only they advance; else one new
    crack starts) and no cut that leaves a chip (``tearing._chip``, a rule of its own)."""
    n = len(topo.boundary)
    strain = np.empty(len(topo.inner))
    tearing.opening_strain(x, topo.triangles, topo.b, topo.inner_tri, topo.normal, strain)
    over = np.flatnonzero(strain > limit)
    used, cut = np.zeros(n, bool), []
    for e in topo.inner[over[np.argsort(-strain[over], kind="stable")]]:
        a, b = topo.pairs[e]
        if used[a] or used[b] or not (topo.boundary[a] or topo.boundary[b]):
            continue
        if len(tips) and a not in tips and b not in tips:
            continue
        if not len(tips) and cut:
            break
        if tearing._chip(int(e), topo.tri_pair, topo.tri_edge):  # the rule against cutting off chips
            continue
        used[a] = used[b] = True
        cut.append(int(e))
    if not cut:
        return None
    is_cut = np.zeros(len(topo.pairs), bool)
    is_cut[cut] = True
    new_t, source, share = topo.triangles.copy(), list(range(n)), [1.0] * n
    for v in np.unique(topo.pairs[cut].ravel()):
        fan = [int(f) for f in topo.vertex_tris[topo.vertex_ptr[v]:topo.vertex_ptr[v + 1]]]
        parent = {f: f for f in fan}

        def find(f):
            while parent[f] != f:
                f = parent[f]
            return f
        for f in fan:
            for w in topo.triangles[f]:
                if w == v:
                    continue
                e = topo.edge(int(v), int(w))
                g = int(topo.tri_pair[e, 1] if topo.tri_pair[e, 0] == f else topo.tri_pair[e, 0])
                if g >= 0 and not is_cut[e]:
                    parent[find(f)] = find(g)
        groups = {}
        for f in fan:
            groups.setdefault(find(f), []).append(f)
        groups = list(groups.values())
        if len(groups) < 2:
            continue
        total = sum(topo.area[f] for g in groups for f in g)
        for k, members in enumerate(groups):
            part = sum(topo.area[f] for f in members) / total
            if k == 0:
                share[v] = part
                continue
            source.append(int(v))
            share.append(part)
            for f in members:
                new_t[f][new_t[f] == v] = len(source) - 1
    return new_t, np.array(source, np.int64), np.array(share)


def torn_sheet(model, integrator, steps, detail=12):
    """A sheet clamped at both sides, pulled until it tears; every tear checked on the way.

    Returns the world, the body and the number of tears checked."""
    if model == "springs":
        mat = deforma.Material("springs", tear_strain=0.2)
        w = deforma.World(gravity=(0.0, 0.0), integrator=integrator, material=mat, stiffness=100.0)
    else:
        mat = deforma.Material(model, youngs_modulus=2e4, poisson_ratio=0.3, density=2.0, tear_strain=0.2)
        w = deforma.World(gravity=(0.0, 0.0), integrator=integrator, material=mat)
    body = w.add_body(deforma.mesh.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=detail, edges=True), position=None)
    x = body.positions
    right = np.flatnonzero(x[:, 0] > 2.0 - 1e-9)
    body.pin(np.concatenate([np.flatnonzero(x[:, 0] < 1e-9), right]))
    checked = [0]
    apply = type(body)._apply_tear

    def checked_apply(self, cut):
        old, tt = self.topology, tearing.TearTopology.of(self.topology.rest_positions, self.topology.triangles)
        x = w.state.x[self.vertex_slice]
        tips = [int(v) for v in self._crack_tips()]
        ref = reference_tear(tt, x, mat.tear_strain, tips)
        assert ref is not None
        assert same(cut.triangles, ref[0]) and same(cut.source, ref[1]) and same(cut.mass_share, ref[2])
        ends = np.unique(tt.pairs[[tt.edge(int(a), int(b)) for a, b in cut.cut]].ravel())
        assert cut.tips.tolist() == [int(v) for v in ends if not tt.boundary[v]]  # where they ran to
        assert set(cut.tips.tolist()).isdisjoint(cut.source[old.n_vertices:].tolist())  # tips do not split
        apply(self, cut)
        rest = old.rest_positions[cut.source]
        tri = cut.triangles
        share = (np.full(old.n_vertices, 1.0 / old.n_vertices) if old.mass_share is None
                 else old.mass_share)[cut.source] * cut.mass_share
        edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        scratch = BodyTopology.from_arrays(rest, edges, tri, mass_share=share)
        for name in BODY_FIELDS:
            assert same(getattr(self.topology, name), getattr(scratch, name)), name
        kept = self._tear_topology
        assert kept[0] is self.topology
        fresh = tearing.TearTopology.of(rest, tri)
        for name in TEAR_FIELDS:
            assert same(getattr(kept[1], name), getattr(fresh, name)), name
        for name, a in zip(("pairs", "tri_pair", "vertex_tris"), reference_edges(len(rest), tri)):
            assert same(getattr(fresh, name), a), name
        if self.is_fem:
            for a, b in zip(element_geometry(self.topology), element_geometry(scratch)):
                assert same(a, b)
        checked[0] += 1

    type(body)._apply_tear = checked_apply
    try:
        for k in range(steps):
            x = body.positions
            x[right, 0] += 0.5 / 600 * (1 + k / 100)
            body.positions = x
            w.step()
    finally:
        type(body)._apply_tear = apply
    return w, body, checked[0]


@pytest.mark.parametrize("model, integrator", [("corotated", "implicit-euler"), ("springs", "implicit-euler"),
                                               ("corotated", "xpbd")])
def test_incremental_rebuild_equals_rebuild_from_scratch(model, integrator, patched_matrices, monkeypatch):
    from deforma.physics import topology as model_module

    patched = []  # the torn outline's clearances, patched (compared at every tear with from_arrays')
    torn_clearance = model_module._torn_clearance
    monkeypatch.setattr(model_module, "_torn_clearance", lambda *a: patched.append(1) or torn_clearance(*a))
    w, body, tears = torn_sheet(model, integrator, 300)
    assert tears >= 3 and body.pieces.max() >= 1
    assert len(patched) >= tears // 2
    # implicit Euler's matrix after each tear, patched where the tear changed the mesh: a few
    # columns assembled, not all
    assert len(patched_matrices) == (tears if integrator == "implicit-euler" else 0)
    assert all(fresh.sum() < len(fresh) / 10 for fresh in patched_matrices)
    # the world's Model, built from the incrementally torn topology, against one built from a
    # from-scratch topology of the same torn mesh
    t = body.topology
    edges = np.concatenate([t.triangles[:, [0, 1]], t.triangles[:, [1, 2]], t.triangles[:, [2, 0]]])
    scratch = BodyTopology.from_arrays(t.rest_positions, edges, t.triangles, mass_share=t.mass_share)
    args = dict(masses=[body._param("mass")], stiffness=[body.stiffness], damping=[body.damping],
                materials=[body.material], pinned=[body._pinned], contact=[w._contact_parameters(body)])
    a, b = w.model, Model([scratch], **args)
    # a torn body's elements keep their order, a new one's are sorted: the same rows of the
    # topology's triangles, with the same numbers
    rows_a, rows_b = np.argsort(a.elem_source), np.argsort(b.elem_source)
    for name in MODEL_FIELDS:
        got, want = getattr(a, name), getattr(b, name)
        if name.startswith("elem"):
            got, want = got[rows_a], want[rows_b]
        assert same(got, want), name
    for name in CONTACT_FIELDS:
        assert same(getattr(a.contact, name), getattr(b.contact, name)), name
    assert len(body.mesh.uv) == body.n_vertices and len(w.state.x) == body.n_vertices


def test_stable_order_is_numpys_stable_argsort():
    rng = np.random.default_rng(3)
    # small bounds take the counting sort, large ones the combined-key sort
    for n, m in ((1, 5), (7, 100), (1000, 5000), (10 ** 6, 100), (10 ** 8, 6000)):
        keys = rng.integers(0, n, m)
        assert same(stable_order(keys, n), np.argsort(keys, kind="stable"))
    assert same(stable_order(np.array([3, 1, 3, 0]), 2 ** 62), np.array([3, 1, 0, 2]))  # too big: argsort
    with pytest.raises(ValueError, match="outside"):  # the counting sort indexes by key: it checks them
        stable_order(np.array([0, 5]), 4)
    with pytest.raises(ValueError, match="outside"):
        tearing.edge_table(3, np.array([[0, 1, 3]]))


def reference_edge_table(n, t):
    """The edge table by NumPy's stable sort and ``unique``: what the compiled pass replaced."""
    t = np.asarray(t, np.int64)
    m = len(t)
    head, tail = t.T.ravel(), t[:, [1, 2, 0]].T.ravel()
    lo, hi = np.minimum(head, tail), np.maximum(head, tail)
    order = np.argsort(lo * n + hi, kind="stable")
    keys, first, inverse, count = np.unique((lo * n + hi)[order], return_index=True, return_inverse=True,
                                            return_counts=True)
    two = count == 2
    tri_pair = np.full((len(keys), 2), -1, np.int64)
    tri_pair[:, 0] = order[first] % m
    tri_pair[two, 1] = order[first[two] + 1] % m
    half_edge = np.empty(3 * m, np.int64)
    half_edge[order] = inverse.ravel()
    return keys, np.stack([keys // n, keys % n], axis=1), tri_pair, two, half_edge


def test_edge_table_equals_a_plain_numpy_one():
    from deforma.mesh.delaunay import delaunay

    rng = np.random.default_rng(5)
    for trial in range(30):
        pts = rng.random((int(rng.integers(3, 300)), 2))
        tris = np.asarray(delaunay(pts), np.int64)
        if trial % 3 == 0:  # an edge in three triangles (a triangle twice): not interior
            tris = np.r_[tris, tris[:1]]
        got, want = tearing.edge_table(len(pts), tris), reference_edge_table(len(pts), tris)
        assert all(same(a, b) for a, b in zip(got, want)), trial


def test_lengths_are_numpys_norm():
    x = np.random.default_rng(4).normal(size=(500, 2)) * [1e-3, 1e3]
    i, j = np.arange(499), np.arange(1, 500)
    assert same(lengths(x, i, j), np.linalg.norm(x[j] - x[i], axis=1))


def test_clearance_through_a_grid_equals_rest_clearance():
    from deforma.physics.contact.clearance import rest_clearance
    from deforma.physics.topology import _clearance

    # a wiggly ring, flattened: many vertices close to edges across from them
    rng = np.random.default_rng(5)
    for count in (700, 3000):
        angle = np.sort(rng.uniform(0, 2 * np.pi, count))
        radius = 1.0 + 0.05 * rng.standard_normal(count)
        x = np.stack([radius * np.cos(angle), 0.5 * radius * np.sin(angle)], axis=1)
        edges = np.stack([np.arange(count), (np.arange(count) + 1) % count], axis=1).astype(np.int32)
        for reach in (0.01, 0.05, 0.5):
            assert same(_clearance(x, edges, reach), rest_clearance(x, edges, reach))

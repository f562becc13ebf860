"""Implicit Euler's factor kept across tears, contact sets and grabs by a low-rank correction
(:mod:`deforma.physics.integrators.implicit.updated_factor`) solves what a fresh factorisation solves."""

import copy

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from hypothesis import given, settings, strategies as st

import deforma
from deforma.physics.integrators.implicit.updated_factor import UpdatedFactor


def spring_matrix(n, springs, w, mass, pinned=()):
    """``M + L_w`` (the implicit solve's matrix for springs), pinned rows the identity's."""
    i, j = springs[:, 0], springs[:, 1]
    rows = np.concatenate([np.arange(n), i, j, i, j])
    cols = np.concatenate([np.arange(n), j, i, i, j])
    vals = np.concatenate([mass, -w, -w, w, w])
    a = sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tolil()
    for p in pinned:
        a[p, :] = 0.0
        a[p, p] = 1.0
    return sp.csc_matrix(a)


def grid(side):
    idx = np.arange(side * side).reshape(side, side)
    springs = np.concatenate([np.stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()], 1),
                              np.stack([idx[:-1, :].ravel(), idx[1:, :].ravel()], 1),
                              np.stack([idx[:-1, :-1].ravel(), idx[1:, 1:].ravel()], 1)])
    return side * side, springs


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), splits=st.integers(0, 6), contacts=st.integers(0, 5),
       pins=st.integers(0, 2))
def test_split_vertices_and_changed_entries_solve_as_a_fresh_factor(seed, splits, contacts, pins):
    rng = np.random.default_rng(seed)
    n, springs = grid(12)
    w = rng.uniform(1.0, 50.0, len(springs))
    mass = rng.uniform(0.5, 2.0, n)
    pinned = rng.choice(n, pins, replace=False)
    f = UpdatedFactor(spring_matrix(n, springs, w, mass, pinned))
    # split vertices: a copy appended, some of the vertex's springs moved to it, its mass shared
    ref, springs, mass = np.arange(n), springs.copy(), mass.copy()
    for v in rng.choice(n, splits, replace=False):
        mine = np.flatnonzero((springs == v).any(axis=1))
        moved = mine[rng.random(len(mine)) < 0.5]
        copy_index = len(ref)
        springs[moved] = np.where(springs[moved] == v, copy_index, springs[moved])
        share = rng.uniform(0.1, 0.9)
        mass = np.append(mass, share * mass[v])
        mass[v] *= 1.0 - share
        ref = np.append(ref, v)
    m = len(ref)
    extra = np.zeros(m)
    extra[rng.choice(m, contacts, replace=False)] = rng.uniform(10.0, 500.0, contacts)  # contacts on the diagonal
    pin_now = np.flatnonzero(np.isin(ref, pinned))
    a = spring_matrix(m, springs, w, mass + extra, pin_now)
    f.max_share = 1.0
    assert f.update(a, ref)
    b = rng.normal(size=(m, 2))
    x = f.solve(b)
    expected = spla.splu(a).solve(b)
    assert np.abs(x - expected).max() <= 1e-10 * np.abs(expected).max()
    assert np.abs(f.solve(b[:, 0]) - expected[:, 0]).max() <= 1e-10 * np.abs(expected).max()  # one column too


def test_a_split_alone_adds_only_the_copies_columns():
    # splitting vertices moves entries onto copies; summed back they are the reference matrix
    n, springs = grid(10)
    w, mass = np.full(len(springs), 10.0), np.ones(n)
    f = UpdatedFactor(spring_matrix(n, springs, w, mass))
    v = 55
    moved = np.flatnonzero((springs == v).any(axis=1))[:3]
    springs = springs.copy()
    springs[moved] = np.where(springs[moved] == v, n, springs[moved])
    mass = np.append(mass, 0.4)
    mass[v] = 0.6
    f.max_share = 1.0
    assert f.update(spring_matrix(n + 1, springs, w, mass), np.append(np.arange(n), v))
    assert f.rank == 1 and f.solves == 1


class CountingFactor:
    """A SuperLU factor that counts the calls into it."""

    def __init__(self, lu):
        self.lu, self.calls = lu, 0

    def solve(self, b):
        self.calls += 1
        return self.lu.solve(b)


def test_update_solves_the_callers_right_side_with_its_new_columns():
    n, springs = grid(10)
    w, mass = np.full(len(springs), 10.0), np.ones(n)
    f = UpdatedFactor(spring_matrix(n, springs, w, mass))
    f.max_share = 1.0
    f._lu = counting = CountingFactor(f._lu)
    springs, mass, ref = split(n, springs, 55)
    a = spring_matrix(n + 1, springs, w, mass)
    b = np.random.default_rng(1).normal(size=(n + 1, 2))
    assert f.update(a, ref, rhs=b)
    assert f.solves == 1 and counting.calls == 1  # the copy's column and b: one call
    expected = spla.splu(a).solve(b)
    assert np.abs(f.solution - expected).max() <= 1e-12 * np.abs(expected).max()
    assert np.abs(f.solve(b) - f.solution).max() <= 1e-12 * np.abs(expected).max()  # as a solve after it
    # no new column: b alone; nothing to correct: the reference factor's own solve
    assert f.update(a, ref, rhs=b[:, 0]) and counting.calls == 3
    assert np.abs(f.solution - expected[:, 0]).max() <= 1e-12 * np.abs(expected).max()
    assert f.update(f._a, np.arange(n), rhs=b[:n]) and f.rank == 0
    assert np.array_equal(f.solution, counting.lu.solve(b[:n]))
    # declined (too many columns for max_rank): no solution, nothing solved
    f.max_rank = 0
    assert not f.update(a, ref, rhs=b) and f.solution is None


def split(n, springs, v, moved_count=3):
    """``springs`` with vertex ``v``'s first ``moved_count`` springs moved to a copy ``n``,
    the masses (v keeps 0.6) and the map to the reference rows."""
    moved = np.flatnonzero((springs == v).any(axis=1))[:moved_count]
    springs = springs.copy()
    springs[moved] = np.where(springs[moved] == v, n, springs[moved])
    mass = np.ones(n + 1)
    mass[v], mass[n] = 0.6, 0.4
    return springs, mass, np.append(np.arange(n), v)


def test_a_declined_update_leaves_the_correction_in_use_as_it_was(monkeypatch):
    import deforma.physics.integrators.implicit.updated_factor as updated

    n, springs = grid(10)
    w = np.full(len(springs), 10.0)
    f = UpdatedFactor(spring_matrix(n, springs, w, np.ones(n)))
    f.max_share = 1.0
    s1, m1, ref1 = split(n, springs, 55)
    a1 = spring_matrix(n + 1, s1, w, m1)
    assert f.update(a1, ref1)
    b = np.ones((n + 1, 2))
    before = f.solve(b)
    monkeypatch.setattr(updated, "MAX_CONDITION", 0.0)  # every correction now ill-conditioned
    s2, m2, ref2 = split(n, springs, 33)
    assert not f.update(spring_matrix(n + 1, s2, w, m2), ref2)  # its columns were solved, then declined
    assert np.array_equal(f.solve(b), before)


def test_a_large_change_is_declined_and_the_old_solve_kept():
    n, springs = grid(10)
    a = spring_matrix(n, springs, np.full(len(springs), 10.0), np.ones(n))
    f = UpdatedFactor(a)
    b = np.ones((n, 2))
    before = f.solve(b)
    assert not f.update(spring_matrix(n, springs, np.full(len(springs), 20.0), np.ones(n)), np.arange(n))
    assert np.array_equal(f.solve(b), before)  # nothing changed
    # split vertices and too many changed entries: declined too (it stops reading early)
    springs2 = springs.copy()
    springs2[springs2 == 5] = n
    springs2[springs2 == 7] = n + 1
    mass2 = np.concatenate([np.ones(n), [1.0, 1.0]])
    big = spring_matrix(n + 2, springs2, np.full(len(springs2), 30.0), mass2)
    ref = np.concatenate([np.arange(n), [5, 7]])
    assert not f.update(big, ref)
    f.max_share = 1.0
    f.max_rank = 4
    assert not f.update(big, ref)
    f.refactor(big)
    x = f.solve(np.ones((n + 2, 2)))
    assert np.allclose(big @ x, 1.0)
    with pytest.raises(ValueError, match="every row of the reference"):
        f.update(a[:n - 1, :n - 1].tocsc(), np.arange(n - 1))


def tearing_sheet(max_rank=None):
    mat = deforma.Material("corotated", youngs_modulus=2e4, poisson_ratio=0.3, density=2.0, tear_strain=0.2)
    w = deforma.World(gravity=(0.0, 0.0), integrator="implicit-euler", material=mat, dt=1 / 600)
    body = w.add_body(deforma.mesh.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=30, edges=True), position=None)
    x = body.positions
    right = np.flatnonzero(x[:, 0] > 2.0 - 1e-9)
    body.pin(np.concatenate([np.flatnonzero(x[:, 0] < 1e-9), right]))
    w.step()
    if max_rank is not None:
        w._integrator._factor.max_rank = max_rank
    return w, body, right


def pull(w, body, right, steps, start=0):
    for k in range(start, start + steps):
        x = body.positions
        x[right, 0] += 1.0 / 600 * (1 + k / 50)
        body.positions = x
        w.step()


def test_a_sheet_torn_under_implicit_euler_moves_as_with_a_factorisation_per_change():
    w, body, right = tearing_sheet()
    again, body2, _ = tearing_sheet(max_rank=0)  # every change factors again
    worst = 0.0
    for k in range(150):
        pull(w, body, right, 1, start=k)
        pull(again, body2, right, 1, start=k)
        if len(w.contacts.vertex) or len(again.contacts.vertex):
            # the torn edges touch: a contact decision is a threshold, which rounding can
            # tip either way (1e-14 m apart, the two sheets took different impulses)
            break
        assert body.n_vertices == body2.n_vertices
        worst = max(worst, np.abs(body.positions - body2.positions).max())
    i, j = w.integrator_stats, again.integrator_stats
    assert body.n_vertices > 1030  # it tore
    assert i["updates"] > 20 and i["factorizations"] < j["factorizations"] / 4
    assert j["updates"] == 0
    assert worst < 1e-10


def test_a_copy_of_a_world_with_an_updated_factor_steps_as_the_original():
    w, body, right = tearing_sheet()
    pull(w, body, right, 120)
    assert w._integrator._factor.rank > 0  # a correction is in use
    twin = copy.deepcopy(w)
    pull(w, body, right, 20, start=120)
    pull(twin, twin.bodies[0], right, 20, start=120)
    np.testing.assert_array_equal(body.positions, twin.bodies[0].positions)


def test_a_tear_in_the_first_of_two_bodies_keeps_the_second_bodys_rows(patched_matrices):
    # the copies are appended to the torn body, so every vertex of the bodies after it moves
    # down in the world's numbering: the map to the reference rows, and the patched matrix's
    # rows, must follow
    def world(max_rank):
        mat = deforma.Material("corotated", youngs_modulus=2e4, poisson_ratio=0.3, density=2.0, tear_strain=0.2)
        w = deforma.World(gravity=(0.0, -9.8), integrator="implicit-euler", material=mat, dt=1 / 600)
        sheet = w.add_body(deforma.mesh.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=20, edges=True), position=None)
        hanging = w.add_body(deforma.mesh.box(((0, 0), (1, 0), (1, 0.5), (0, 0.5)), detail=6), position=(1.0, 3.0),
                             material=deforma.Material("neo-hookean", youngs_modulus=5e3, poisson_ratio=0.3,
                                                       density=1.0))
        x = sheet.positions
        right = np.flatnonzero(x[:, 0] > 2.0 - 1e-9)
        sheet.pin(np.concatenate([np.flatnonzero(x[:, 0] < 1e-9), right]))
        hanging.pin([0, 1])  # it swings under gravity: its rows carry a motion of their own
        w.step()
        w._integrator._factor.max_rank = max_rank
        return w, sheet, hanging, right

    w, sheet, hanging, right = world(64)
    again, sheet2, hanging2, _ = world(0)
    n0 = sheet.n_vertices
    for k in range(120):
        pull(w, sheet, right, 1, start=k)
        pull(again, sheet2, right, 1, start=k)
        if len(w.contacts.vertex) or len(again.contacts.vertex):
            break
        assert np.abs(hanging.positions - hanging2.positions).max() < 1e-10
        assert np.abs(sheet.positions - sheet2.positions).max() < 1e-10
    assert sheet.n_vertices >= n0 + 10 and w.integrator_stats["updates"] >= 10  # it tore, and the factor was corrected
    assert len(patched_matrices) >= 10
    assert w.integrator_stats["factorizations"] == 1


def test_the_columns_implicit_euler_names_hold_every_change(monkeypatch):
    # After a tear or a new contact set, implicit Euler names the reference columns that may
    # have changed (those it assembled again, those of either contact set), and the update
    # compares only those: on a tearing sheet whose pieces touch, and on the pile, every
    # update finds exactly what a comparison of every column finds
    from deforma import scene as scenes
    from deforma.physics.integrators.implicit import updated_factor

    full = updated_factor._blocks
    named = [0]

    def checked(*args):
        out = full(*args)
        n0 = args[5]
        if len(args[-1]) < n0:
            everything = full(*args[:-1], np.arange(n0))
            stopped = len(out[3]) != len(args[4]) + 1  # past the limit: the update declines
            assert stopped == (len(everything[3]) != len(args[4]) + 1)
            if not stopped:
                for a, b in zip(out, everything):
                    np.testing.assert_array_equal(a, b)
            named[0] += 1
        return out

    monkeypatch.setattr(updated_factor, "_blocks", checked)
    w, body, right = tearing_sheet()
    pull(w, body, right, 200)
    assert body.pieces.max() >= 1 and named[0] > 20
    before = named[0]
    pile = scenes.load("pile").build()
    pile.integrator, pile.substeps = "implicit-euler", 2  # the pile as shipped before avbd
    for _ in range(60):
        pile.step()
    assert named[0] > before + 10

"""The element-kind seam: what holds a body together, as a plug-in every integrator runs.

An element kind owns a set of elements over a world's vertices (springs, triangles, or a
kind a user writes) and the kernels the integrators need, each over all its elements:

- :meth:`ElementKind.forces` (symplectic Euler): add the elements' forces, N;
- :meth:`ElementKind.energy`, :meth:`ElementKind.gradient_hessian`: the elastic energy (J)
  per element, its gradient per element corner and its Hessian block, projected to be
  positive semi-definite (what a Newton-type solver and, later, gradients need);
- :meth:`ElementKind.vertex_blocks` (avbd): per vertex, the gradient and the 2 x 2 Hessian
  block (damping included) of the elements around it;
- :meth:`ElementKind.begin_substep`, :meth:`ElementKind.project` (XPBD): one Gauss-Seidel
  sweep over its constraints, with multipliers that start each substep at zero;
- :meth:`ElementKind.matrix_weights`, :meth:`ElementKind.matrix_entries`,
  :meth:`ElementKind.rhs` (implicit Euler's local/global solve): its part of the constant
  matrix, and of the right-hand side for the current iterate;
- :meth:`ElementKind.stiffness_rows`, :meth:`ElementKind.damping_rows`: per vertex, bounds
  on its stiffness and damping rates, from which ``World.stable_dt`` bounds the explicit step.

An integrator loops over ``model.elements`` and calls these; it does not know the kinds'
names. The built-in kinds (:class:`~deforma.physics.elements.springs.SpringKind`,
:class:`~deforma.physics.elements.triangles.TriangleKind`) say ``fused = True``: each
integrator also has a compiled driver that runs them inside its own passes (measured faster
for small bodies, where a Python call per substep costs as much as the step), and takes the
loop over the kinds only when a kind that is not fused is present. The two paths give the
same numbers (``tests/physics/test_element_kinds.py``).

A new kind is a subclass registered with :func:`register_element_kind` for the material
models it serves: ``deforma.Material("<model>", youngs_modulus=..., poisson_ratio=...,
density=...)`` then makes it (a body's mass is ``density`` times its area, as for finite
elements), from the API and from scene files. The defaults below derive :meth:`forces` and
:meth:`rhs` from :meth:`gradient_hessian` and :meth:`matrix_entries`, so a kind needs only
those, :meth:`energy`, :meth:`project` and :meth:`build`.

Units: m, s, kg, N, J.
"""

from __future__ import annotations

from typing import ClassVar, NamedTuple

import numpy as np
from numba import njit

#: Colours of the XPBD sweep order's greedy colouring (one bit each in a uint64 per vertex).
COLOURS = 64
#: The material models of the built-in kinds (springs, triangles), which the Model makes itself.
BUILT_IN = ("springs", "corotated", "neo-hookean", "rigid")


class BodyElements(NamedTuple):
    """What :meth:`ElementKind.build` gets for each body whose material the kind serves."""

    index: int          # the body's index in the world
    topology: object    # its BodyTopology (rest positions, springs, triangles)
    material: object    # its Material
    first_vertex: int   # its first row in the world's arrays (its vertex i is global first_vertex + i)


class ElementKind:
    """A set of elements of one kind over a world's vertices, and their kernels.

    Attributes
    ----------
    name : str
        The kind's name.
    models : tuple of str
        Material models this kind makes elements for (class attribute).
    fused : bool
        True for the built-in kinds, which every integrator's compiled driver runs itself.
    vertices : (E, k) int array
        Each element's corners, global vertex indices.
    """

    name: ClassVar[str] = ""
    models: ClassVar[tuple[str, ...]] = ()
    fused: ClassVar[bool] = False

    vertices: np.ndarray

    @classmethod
    def build(cls, bodies: list[BodyElements]) -> "ElementKind":
        """The kind's elements for ``bodies`` (each a :class:`BodyElements`)."""
        raise NotImplementedError

    @property
    def n_elements(self) -> int:
        """How many elements."""
        return len(self.vertices)

    # -- energy --------------------------------------------------------------------------------
    def energy(self, x) -> np.ndarray:
        """Elastic energy of each element (E,) in J at positions ``x`` (N, 2)."""
        raise NotImplementedError

    def gradient_hessian(self, x) -> tuple[np.ndarray, np.ndarray]:
        """Gradient of each element's energy at its corners (E, k, 2), N, and its Hessian
        block (E, 2k, 2k), N/m, coordinates ordered corner by corner (x then y), projected to
        be positive semi-definite."""
        raise NotImplementedError

    def forces(self, x, v, f) -> None:
        """Add the elements' forces (N) at positions ``x`` and velocities ``v`` to ``f`` (N, 2).
        By default minus the energy's gradient (no damping)."""
        g, _ = self.gradient_hessian(x)
        np.subtract.at(f, self.vertices.ravel(), g.reshape(-1, 2))

    # -- vertex block descent (avbd) ----------------------------------------------------------
    def vertex_blocks(self, x, x_n, h: float, g, hb) -> None:
        """Add each vertex's share of the elements' energy gradient to ``g`` (N, 2), N, and
        of its diagonal Hessian block to ``hb`` (N, 3: xx, xy, yy), N/m, at positions ``x``
        (``x_n``: at the start of the step of ``h`` s, for damping).

        The fallback for a registered kind: the corners' gradients and diagonal blocks of
        :meth:`gradient_hessian` (already positive semi-definite), with no damping. The
        built-in kinds add their damping too."""
        grad, hess = self.gradient_hessian(x)
        vertices = np.asarray(self.vertices)
        k = vertices.shape[1]
        flat = vertices.ravel()
        np.add.at(g, flat, grad.reshape(-1, 2))
        c = np.arange(k)
        hxx = hess[:, 2 * c, 2 * c].ravel()
        hxy = 0.5 * (hess[:, 2 * c, 2 * c + 1] + hess[:, 2 * c + 1, 2 * c]).ravel()
        hyy = hess[:, 2 * c + 1, 2 * c + 1].ravel()
        np.add.at(hb, flat, np.stack([hxx, hxy, hyy], axis=1))

    # -- XPBD ----------------------------------------------------------------------------------
    def begin_substep(self) -> None:
        """Start of an XPBD substep: the accumulated multipliers go back to zero."""

    def project(self, x, x_prev, inv_mass, h: float, sequence) -> None:
        """One XPBD Gauss-Seidel sweep over the elements' constraints, in place on ``x``
        (``x_prev``: positions at the start of the substep; ``sequence``: an order of the
        ``COLOURS`` colours drawn for this step, for kinds that sweep colour by colour)."""
        raise NotImplementedError

    # -- implicit Euler's local/global solve ------------------------------------------------------
    def matrix_weights(self, h: float) -> np.ndarray:
        """Weight of each element in the constant matrix for substep ``h`` (E,), kg."""
        raise NotImplementedError

    def matrix_entries(self, h: float, weights=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The kind's part of implicit Euler's constant matrix as ``(rows, cols, vals)``
        (symmetric, positive semi-definite, kg; its rows sum to zero so that it keeps momentum);
        one N x N matrix serves both coordinates."""
        raise NotImplementedError

    def rhs(self, x, x_n, h: float, weights, b) -> None:
        """Add the kind's local step at the iterate ``x`` to the right-hand side ``b`` (N, 2):
        by default ``W x - h^2 grad E(x)`` with ``W`` its matrix part (``weights``: its
        :meth:`matrix_weights`), which makes the solve with the constant matrix a step along
        the exact gradient of the backward Euler objective (no damping)."""
        rows, cols, vals = self.matrix_entries(h, weights)
        np.add.at(b, rows, vals[:, None] * x[cols])
        g, _ = self.gradient_hessian(x)
        np.subtract.at(b, self.vertices.ravel(), (h * h) * g.reshape(-1, 2))

    # -- the explicit step's bound --------------------------------------------------------------------
    def stiffness_rows(self, n: int) -> np.ndarray:
        """Per vertex (n,), a bound on the row sums of the kind's stiffness matrix, N/m
        (Gershgorin: ``World.stable_dt`` divides it by the vertex's mass)."""
        raise NotImplementedError

    def damping_rows(self, n: int) -> np.ndarray:
        """Per vertex (n,), the same for its damping, N*s/m (none by default)."""
        return np.zeros(n)


_KINDS: dict[str, type] = {}


def register_element_kind(cls: type) -> type:
    """Class decorator: let ``deforma.Material(model)`` make ``cls``'s elements for every
    model in ``cls.models``.

    Examples
    --------
    >>> class Nothing(ElementKind):
    ...     name, models = "nothing", ("nothing-at-all",)
    >>> _ = register_element_kind(Nothing)
    >>> element_kind("nothing-at-all") is Nothing
    True
    >>> unregister_element_kind(Nothing)
    """
    if not (isinstance(cls, type) and issubclass(cls, ElementKind)) or not cls.models:
        raise ValueError("an element kind must be a subclass of ElementKind naming the material models it serves")
    taken = [m for m in cls.models if m in BUILT_IN]
    if taken:
        raise ValueError(f"material model {taken[0]!r} is built in; name the kind's models otherwise")
    for model in cls.models:
        if model in _KINDS and _KINDS[model] is not cls:
            raise ValueError(f"material model {model!r} is already served by {_KINDS[model].__name__}")
    for model in cls.models:
        _KINDS[model] = cls
    return cls


def unregister_element_kind(cls: type) -> None:
    """Take back what :func:`register_element_kind` did for ``cls``."""
    for model in cls.models:
        if _KINDS.get(model) is cls:
            del _KINDS[model]


def element_kind(model: str) -> type | None:
    """The kind registered for material model ``model``, or ``None``."""
    return _KINDS.get(model)


def registered_models() -> tuple[str, ...]:
    """Material models served by registered kinds, in registration order."""
    return tuple(_KINDS)


@njit(cache=True)
def sweep_order(items, n_vertices):
    """The Gauss-Seidel sweep's order of springs or elements ``items`` (M, k): coloured
    greedily so that no two of a colour share a vertex, colour after colour, in their own
    order within a colour.

    Returns ``(order, starts)``: the items (M,) int64 colour after colour, and where each of
    the ``COLOURS`` colours starts in ``order`` (``COLOURS + 1`` entries). XPBD sweeps the
    springs in this order, and the elements colour by colour in an order of colours drawn
    for each step (:func:`colour_sequence`), since any fixed order let a box dropped flat
    walk sideways as it landed (15 cm in the Model's order, 3 cm in this one; 0.6 cm drawn).

    Taken in the Model's order (sorted by first vertex, row after row of a mesh), one sweep
    carries a correction through the whole body along that order, and with velocities taken
    from the positions the substep as a whole amplified some motions: a 2500-vertex sheet of
    springs (2e6 N/m) stretched 2% between two clamps and let go, at 1/600 s with one
    substep, ran away in 36 steps. In colour order a correction crosses at most as many items
    as there are colours per sweep, and it stays near rest (``tests/physics/test_integrators.py``).
    The price is convergence: a stiff spinning block stretches its springs up to 3.0% where
    the Model's order kept 2%. A vertex with more than ``COLOURS`` colours around it puts the
    rest in the last colour: the order stays valid, only less spread.

    Examples
    --------
    >>> import numpy as np
    >>> order, starts = sweep_order(np.array([[0, 1], [1, 2], [2, 3], [3, 4]]), 5)
    >>> order.tolist(), starts[:3].tolist()  # colour 0: springs 0 and 2; colour 1: 1 and 3
    ([0, 2, 1, 3], [0, 2, 4])
    """
    m = items.shape[0]
    used = np.zeros(n_vertices, np.uint64)
    colour = np.empty(m, np.int64)
    count = np.zeros(COLOURS + 1, np.int64)
    for e in range(m):
        taken = np.uint64(0)
        for c in range(items.shape[1]):
            taken |= used[items[e, c]]
        k = 0
        while k < COLOURS - 1 and (taken >> np.uint64(k)) & np.uint64(1):
            k += 1
        colour[e] = k
        count[k + 1] += 1
        for c in range(items.shape[1]):
            used[items[e, c]] |= np.uint64(1) << np.uint64(k)
    for k in range(COLOURS):
        count[k + 1] += count[k]
    starts = count.copy()
    order = np.empty(m, np.int64)
    for e in range(m):
        order[count[colour[e]]] = e
        count[colour[e]] += 1
    return order, starts


@njit(cache=True, inline="always")
def colour_sequence(seed, out):
    """A permutation of ``range(len(out))`` into ``out``, a different one for each ``seed``
    (a Fisher-Yates shuffle driven by a 64-bit linear congruential generator)."""
    n = out.shape[0]
    for c in range(n):
        out[c] = c
    state = np.uint64(seed) * np.uint64(6364136223846793005) + np.uint64(1442695040888963407)
    for c in range(n - 1, 0, -1):
        state = state * np.uint64(6364136223846793005) + np.uint64(1442695040888963407)
        r = np.int64((state >> np.uint64(33)) % np.uint64(c + 1))
        out[c], out[r] = out[r], out[c]

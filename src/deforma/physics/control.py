"""What acts on the bodies in a step besides their own physics: grabs, applied forces and
the kinematic colliders, as the kernels read them.

The World fills a :class:`Control` from its handles (grabs, ``body.apply_force``, collider
objects) before each step and hands it to the integrator; the integrator reads it and
writes nothing in it but the packed colliders, which it moves substep by substep (the
World packs them again from the collider objects, so a failed step leaves no trace).

Units: m, N, N/m, s.
"""

from __future__ import annotations

import numpy as np

from .colliders.shapes import RECT_COLUMNS


class Control:
    """The step's grabs, applied forces and packed colliders.

    Attributes
    ----------
    grab_slot : (N,) int32
        Per vertex, its row in ``grab_pull``, or -1 if no grab holds it.
    grab_pull : (K, 3) float64
        Per held vertex, ``(S, S tx, S ty)``: the summed strength ``S`` (N/m) of the grabs
        holding it and ``S`` times its target (N): the pull ``S (target - x)``.
    force : (N, 2) float64
        Applied force on each vertex during this step (N), or an empty (0, 2) array when
        none is applied (``has_force`` False).
    colliders : (R, RECT_COLUMNS) float64
        The colliders packed (:func:`~deforma.physics.colliders.shapes.pack_colliders`),
        at their poses at the start of the step; an integrator moves them substep by substep.
    step : int
        Index of the step (``world.step_count``): what an integrator that draws an order
        for each step seeds it with, so that a step repeated after a failure draws the same.

    Examples
    --------
    >>> import numpy as np
    >>> c = Control(3)
    >>> c.hold([(np.array([1, 2]), 10.0, np.array([[0.0, 1.0], [2.0, 0.0]]))])
    >>> c.grab_slot.tolist(), c.grab_pull.tolist()
    ([-1, 0, 1], [[10.0, 0.0, 10.0], [10.0, 20.0, 0.0]])
    """

    def __init__(self, n_vertices: int):
        self.grab_slot = np.full(n_vertices, -1, np.int32)
        self.grab_pull = np.zeros((0, 3))
        self.force = np.zeros((0, 2))
        self.colliders = np.zeros((0, RECT_COLUMNS))
        self.step = 0

    @property
    def n_vertices(self) -> int:
        """Number of vertices this control is for."""
        return len(self.grab_slot)

    @property
    def has_force(self) -> bool:
        """Whether a force is applied this step."""
        return len(self.force) > 0

    def hold(self, grabs) -> None:
        """Set the grabs: ``grabs`` is a sequence of ``(vertices, strength, targets)``, global
        vertex indices (k,), N/m and one target per vertex (k, 2) m. A vertex held by several
        grabs feels the sum of their pulls."""
        slot = np.full(self.n_vertices, -1, np.int32)
        rows = [g for g in grabs if len(g[0])]
        if rows:
            idx = np.concatenate([np.asarray(r[0], np.int64) for r in rows])
            st = np.concatenate([np.full(len(r[0]), float(r[1])) for r in rows])
            tg = np.concatenate([np.asarray(r[2], np.float64).reshape(-1, 2) for r in rows])
            uniq, inv = np.unique(idx, return_inverse=True)
            pull = np.zeros((len(uniq), 3))
            np.add.at(pull[:, 0], inv, st)
            np.add.at(pull[:, 1], inv, st * tg[:, 0])
            np.add.at(pull[:, 2], inv, st * tg[:, 1])
            slot[uniq] = np.arange(len(uniq), dtype=np.int32)
        else:
            pull = np.zeros((0, 3))
        self.grab_slot = slot
        self.grab_pull = pull

    def add_force(self, vertices, forces) -> None:
        """Add ``forces`` (k, 2) N on the global ``vertices`` (k,) for this step."""
        if not self.has_force:
            self.force = np.zeros((self.n_vertices, 2))
        np.add.at(self.force, np.asarray(vertices, np.int64), np.asarray(forces, np.float64).reshape(-1, 2))

    def clear_force(self) -> None:
        """No applied force (after the step that used it)."""
        self.force = np.zeros((0, 2))

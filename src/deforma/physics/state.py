"""The changing part of a world: positions and velocities of every vertex of every body.

All bodies share one contiguous ``(N, 2)`` float64 positions array and one velocities array
(the Model's ``body_vertex_offsets`` say where each body starts), so one kernel call
advances every body. A step reads the State it starts from (``state_in``) and writes the
one it ends in (``state_out``); the World keeps both, so a failed step is undone by
keeping the first (:mod:`deforma.physics.stepper`).
"""

from __future__ import annotations

import numpy as np


class State:
    """Positions (m) and velocities (m/s) of all vertices, all bodies concatenated.

    Parameters
    ----------
    positions, velocities : (N, 2) array_like of float
        Copied into contiguous float64 arrays ``x`` and ``v``.

    Examples
    --------
    >>> import numpy as np
    >>> s = State(np.zeros((3, 2)), np.ones((3, 2)))
    >>> t = State.empty()
    >>> t.assign(s)  # t becomes a copy of s (its own arrays)
    >>> t.n_vertices, float(t.v.sum()), t.x is s.x
    (3, 6.0, False)
    """

    def __init__(self, positions, velocities):
        self.x = np.array(positions, dtype=np.float64, order="C").reshape(-1, 2)
        self.v = np.array(velocities, dtype=np.float64, order="C").reshape(-1, 2)

    @classmethod
    def empty(cls) -> "State":
        """A state with no vertices."""
        return cls(np.zeros((0, 2)), np.zeros((0, 2)))

    @property
    def n_vertices(self) -> int:
        """Number of vertices."""
        return len(self.x)

    def assign(self, other: "State") -> None:
        """Make this state equal to ``other``: in place where the sizes agree (the arrays,
        and every view of them, stay), else with new arrays."""
        if self.x.shape == other.x.shape:
            np.copyto(self.x, other.x)
            np.copyto(self.v, other.v)
        else:
            self.x = other.x.copy()
            self.v = other.v.copy()

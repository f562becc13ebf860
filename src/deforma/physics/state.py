"""The changing part of a world: positions and velocities of every vertex of every body.

All bodies share one contiguous ``(N, 2)`` float64 positions array and one velocities array
(``body_offsets`` says where each body starts), so one kernel call advances every body and
later body-body collision or batch runs need no redesign. ``x_start`` / ``v_start`` hold the
state at the start of the current step, written by the step kernel itself (no extra copy
pass), so a failing step can be undone.
"""

from __future__ import annotations

import numpy as np


class State:
    """Positions (m) and velocities (m/s) of all vertices, plus the pre-step backup.

    Parameters
    ----------
    positions, velocities : (N, 2) array_like of float
        Initial state, all bodies concatenated.
    body_offsets : (B + 1,) array_like of int
        Body ``b`` owns rows ``body_offsets[b]:body_offsets[b + 1]``.

    Examples
    --------
    >>> import numpy as np
    >>> s = State(np.zeros((3, 2)), np.ones((3, 2)), [0, 1, 3])
    >>> s.x[s.body_offsets[1]:s.body_offsets[2]].shape
    (2, 2)
    """

    def __init__(self, positions, velocities, body_offsets):
        self.x = np.ascontiguousarray(positions, dtype=np.float64).reshape(-1, 2)
        self.v = np.ascontiguousarray(velocities, dtype=np.float64).reshape(-1, 2)
        self.x_start = self.x.copy()
        self.v_start = self.v.copy()
        self.body_offsets = np.asarray(body_offsets, dtype=np.int64)

    @classmethod
    def empty(cls) -> "State":
        """A state with no vertices."""
        return cls(np.zeros((0, 2)), np.zeros((0, 2)), [0])

    def restore(self) -> None:
        """Put back the state saved at the start of the last step."""
        self.x[...] = self.x_start
        self.v[...] = self.v_start

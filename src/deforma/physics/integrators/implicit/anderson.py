"""Anderson acceleration of implicit Euler's local/global iteration, with a residual safeguard.

The local/global iteration is a fixed-point map ``x -> G(x) = A^-1 b(x)``: the local steps at
``x`` (spring directions, element rotations, contact projections) give the right-hand side,
the prefactored matrix the new positions. Its fixed point is the backward Euler step, and
``G(x) - x = -A^-1 grad E(x)`` is a gradient step on the step's objective preconditioned by
the constant matrix (Liu, Bouaziz and Kavan 2017). Plain iteration converges linearly, and
slowly where the matrix misses the motion: a stiff body's rotation is not in ``A`` (its
local step lags one iteration), so three iterations of a spinning block kept 2 % of its
angular momentum after one 1/60 s step.

Anderson acceleration (Anderson 1965; Walker and Ni 2011; for projective dynamics, Peng et
al. 2018) keeps the last ``depth`` iterates and their images and takes the combination of
images whose residuals ``f = G(x) - x`` combine to the smallest one: a multisecant
quasi-Newton step that needs nothing but ``G``. It is guarded: when the residual of the
accelerated iterate is ``GUARD`` times that of the iterate before it or more, the accelerated
iterate is dropped, the plain step from the last good iterate is taken instead and the
history starts again. The residual of the iteration may rise on the way (even unaccelerated):
a guard at 1x dropped a sixth of the iterates of a spinning block of 1e7 Pa and took 113
iterations per step, one at 10x none and 30 (the same answer; depth 5, 10 or 20 made no
difference). (An energy guard, as in Peng et al., needs the step's objective; the damping along
current directions, the Neo-Hookean blend far from rest and Coulomb's clamp are local steps
that are not gradients of one potential, so the residual is the guard.)

Units: m (positions and residuals).
"""

from __future__ import annotations

import numpy as np

#: An accelerated iterate whose residual is this many times its predecessor's is dropped.
GUARD = 10.0


class AndersonMixing:
    """Anderson acceleration of a fixed-point iteration ``x -> G(x)`` over (N, 2) arrays.

    Feed it each iterate and its image with :meth:`next`; it returns the next iterate.

    Parameters
    ----------
    depth : int
        How many earlier iterates are combined (``m`` of Anderson(m)).

    Examples
    --------
    A linear map whose plain iteration converges slowly (rate 0.99 and 0.5):

    >>> import numpy as np
    >>> a = np.array([[0.99, 0.0], [0.0, 0.5]])
    >>> g = lambda x: x @ a.T + np.array([0.01, 0.5])  # fixed point (1, 1)
    >>> mix, x = AndersonMixing(3), np.zeros((1, 2))
    >>> for _ in range(6):
    ...     x = mix.next(x, g(x))
    >>> bool(np.abs(x - 1.0).max() < 1e-9)  # plain iteration: 0.94 away after 6 steps
    True
    """

    def __init__(self, depth: int = 5):
        self.depth = int(depth)
        self.rejected = 0  # accelerated iterates dropped by the guard (for the stats)
        self.reset()

    def reset(self) -> None:
        """Forget the history (a new substep, or a new map)."""
        self._df: list[np.ndarray] = []
        self._dg: list[np.ndarray] = []
        self._f = None  # the last accepted iterate's residual and image
        self._g = None
        self._norm = np.inf
        self._accelerated = False

    def next(self, x: np.ndarray, g: np.ndarray) -> np.ndarray:
        """The next iterate after ``x``, whose image under the map is ``g`` (both (N, 2), m)."""
        f = g - x
        norm = float(np.sqrt(np.vdot(f, f)))
        if self._accelerated and norm > GUARD * self._norm:
            # the accelerated iterate made the residual worse: take the plain step from the
            # iterate before it (its image is known) and start the history again
            self.rejected += 1
            self._df.clear()
            self._dg.clear()
            self._accelerated = False
            return self._g.copy()
        if self._f is not None:
            self._df.append((f - self._f).ravel())
            self._dg.append((g - self._g).ravel())
            if len(self._df) > self.depth:
                del self._df[0], self._dg[0]
        self._f, self._g, self._norm = f, g.copy(), norm
        if not self._df:
            self._accelerated = False
            return g.copy()
        df = np.stack(self._df, axis=1)
        # theta = argmin |f - dF theta|: a least-squares problem of depth columns
        theta, *_ = np.linalg.lstsq(df, f.ravel(), rcond=1e-10)
        self._accelerated = True
        return (g.ravel() - np.stack(self._dg, axis=1) @ theta).reshape(g.shape)

"""Union-find over an array of parents, shared by the contact fail-safe's impact zones and
tearing's pieces.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def find_root(parent, k):
    """The root of ``k`` in the union-find forest ``parent``, halving the path on the way."""
    while parent[k] != k:
        parent[k] = parent[parent[k]]
        k = parent[k]
    return k

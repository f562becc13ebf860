"""Union-find over an array of parents, shared by the contact fail-safe's impact zones,
tearing's pieces and sleeping's islands.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def find_root(parent, k):
    """The root of ``k`` in the union-find forest ``parent``, halving the path on the way."""
    while parent[k] != k:
        parent[k] = parent[parent[k]]
        k = parent[k]
    return k


@njit(cache=True)
def component_labels(n, links):
    """Each of ``n`` nodes' component (n,) int64 under the undirected ``links`` (L, 2) int64,
    numbered in the order of each component's first node (as SciPy's ``connected_components``
    numbers them; 0.6-0.8 us for 2-14 bodies against SciPy's 106-118 us with its sparse matrix,
    made every step)."""
    parent = np.arange(n)
    for e in range(links.shape[0]):
        a, b = find_root(parent, links[e, 0]), find_root(parent, links[e, 1])
        if a != b:
            parent[max(a, b)] = min(a, b)
    label = np.empty(n, np.int64)
    count = 0
    for k in range(n):
        r = find_root(parent, k)
        if r == k:
            label[k] = count
            count += 1
        else:
            label[k] = label[r]
    return label

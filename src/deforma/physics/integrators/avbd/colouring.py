"""Vertex colouring for block descent: no two vertices of a colour share an element.

Vertices that share no spring and no triangle have independent blocks, so a colour is
swept as one Jacobi step, in any order or in parallel, and the sweep is deterministic. The
colouring is greedy over the vertex graph, made once per Model (a tear makes a new Model,
which is coloured again).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def colour_vertices(n_vertices, tri_start, tri_item, elem, spring_start, spring_item, spring_i, spring_j):
    """Greedy colouring of the vertices: ``(order, starts)``, the vertices (N,) int64 colour
    after colour and where each colour starts (``n_colours + 1`` entries).

    ``tri_start, tri_item`` and ``spring_start, spring_item`` are the vertices' incident
    triangles and springs (:func:`~deforma.physics.integrators.avbd.blocks.incidence`).

    Examples
    --------
    >>> import numpy as np
    >>> from deforma.physics.integrators.avbd.blocks import incidence
    >>> springs = np.array([[0, 1], [1, 2], [2, 3]])
    >>> s_start, s_item, _ = incidence(springs, 4)
    >>> t_start, t_item, _ = incidence(np.zeros((0, 3), np.int32), 4)
    >>> order, starts = colour_vertices(4, t_start, t_item, np.zeros((0, 3), np.int32), s_start, s_item,
    ...                                 springs[:, 0], springs[:, 1])
    >>> order.tolist(), starts.tolist()  # a chain: every other vertex
    ([0, 2, 1, 3], [0, 2, 4])
    """
    colour = np.full(n_vertices, -1, np.int64)
    mark = np.full(n_vertices + 1, -1, np.int64)  # mark[c] == v: colour c is taken next to v
    n_colours = 0
    for v in range(n_vertices):
        for p in range(tri_start[v], tri_start[v + 1]):
            e = tri_item[p]
            for c in range(3):
                u = elem[e, c]
                if colour[u] >= 0:
                    mark[colour[u]] = v
        for p in range(spring_start[v], spring_start[v + 1]):
            s = spring_item[p]
            u = spring_j[s] if spring_i[s] == v else spring_i[s]
            if colour[u] >= 0:
                mark[colour[u]] = v
        c = 0
        while mark[c] == v:
            c += 1
        colour[v] = c
        n_colours = max(n_colours, c + 1)
    starts = np.zeros(n_colours + 1, np.int64)
    for v in range(n_vertices):
        starts[colour[v] + 1] += 1
    for c in range(n_colours):
        starts[c + 1] += starts[c]
    fill = starts[:-1].copy()
    order = np.empty(n_vertices, np.int64)
    for v in range(n_vertices):
        order[fill[colour[v]]] = v
        fill[colour[v]] += 1
    return order, starts

"""Box meshes: a convex quadrilateral filled with an even (bilinear) grid of points."""

from __future__ import annotations

import operator
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..checks import MAX_COORDINATE, MAX_DETAIL, check_box_points  # noqa: F401  (MAX_DETAIL: public here too)
from .delaunay import delaunay
from .mesh import Mesh


def box(corners: ArrayLike, *, detail: int = 8, edges: bool = True) -> Mesh:
    """A quadrilateral ("box") mesh filled evenly with points, as in the original's Square.

    Parameters
    ----------
    corners : (4, 2) array_like of float
        The corners in metres, in order around the outline (counter-clockwise or clockwise),
        forming a convex quadrilateral: a rectangle, a parallelogram, a kite, any convex quad.
        A crossed (self-intersecting), concave or degenerate quad (coinciding corners, three
        corners on a line) raises ``ValueError``.
    detail : int, keyword-only
        ``n``: ``n * n`` interior points at the bilinear positions ``(i/(n+1), j/(n+1))``,
        ``i, j = 1..n``, between the corners. 0 gives the bare quad (two triangles). At
        least 0, and at most what keeps the box within ``checks.MAX_BODY_POINTS``
        (100,000) points: 314 with edges, ``MAX_DETAIL`` (316) without; more is refused
        from the count before anything is built (a step of a million points took 29 s).
    edges : bool, keyword-only
        Also put ``n`` points on each of the four sides at the same parameters, so the points
        form a full ``(n+2) x (n+2)`` grid and the triangles along the sides are as good as
        those inside. On by default (as in scene files, ``deforma mesh box`` and the viewer):
        without it the sides are single long edges and the outermost triangles are thin
        (minimum angle about ``atan(1/(n+1))``), the original's point set.

    Returns
    -------
    Mesh
        ``n*n + 4`` vertices (``+ 4n`` with ``edges``): the four corners first, in the given
        order, then the interior points row by row, then the side points. ``uv`` is the
        bilinear parameter: ``u`` runs from ``corners[0]`` to ``corners[1]``, ``v`` from
        ``corners[0]`` to ``corners[3]``. Its area equals the quad's area (up to rounding).

    Notes
    -----
    Side points are computed as ``a + s (b - a)`` so that points on an axis-aligned side
    share its coordinate exactly; where rounding still moves one off the line, Delaunay
    makes a near-zero-area triangle of three points on one side. Those triangles are
    dropped (they lie outside the quad or have no area), so no triangle is degenerate.

    Examples
    --------
    >>> import deforma
    >>> m = deforma.mesh.box(((0, 0), (2, 0), (2, 1), (0, 1)), detail=8, edges=True)
    >>> len(m.vertices), round(m.area, 12), len(m.boundary)
    (100, 2.0, 1)
    """
    c = _check_corners(corners)
    n = _check_detail(detail)
    if not isinstance(edges, (bool, np.bool_)):
        raise ValueError(f"edges must be True or False, got {edges!r}")
    check_box_points(n, bool(edges))  # from the count, before a point is made

    a, b, cc, d = c
    s = np.arange(1, n + 1, dtype=np.float64) / (n + 1)
    # interior: the bilinear map of the unit square, (s, t) -> a + s(b-a) + t(d-a) + st(a-b+c-d)
    ss, tt = np.meshgrid(s, s)
    ss, tt = ss.ravel(), tt.ravel()  # type: ignore[assignment]  # 2-d grids to 1-d
    twist = a - b + cc - d
    interior = a + ss[:, None] * (b - a) + tt[:, None] * (d - a) + (ss * tt)[:, None] * twist
    points: Any = [c, interior]  # lists of pieces, then arrays
    uv: Any = [np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]), np.stack([ss, tt], axis=1)]
    side_of: Any = [np.full(4, -1), np.full(n * n, -1)]
    if edges and n > 0:
        z, o = np.zeros(n), np.ones(n)
        for k, (p, q, uvs) in enumerate(
            ((a, b, (s, z)), (b, cc, (o, s)), (d, cc, (s, o)), (a, d, (z, s)))
        ):
            points.append(p + s[:, None] * (q - p))
            uv.append(np.stack(uvs, axis=1))
            side_of.append(np.full(n, k))
    points = np.concatenate(points)
    uv = np.concatenate(uv)
    side_of = np.concatenate(side_of)

    tris = delaunay(points)
    if edges and n > 0:
        # A triangle with all three corners on one side (corners count on both of theirs)
        # is a rounding sliver along the hull: drop it.
        on_side = np.zeros((len(points), 4), dtype=bool)
        on_side[side_of >= 0, side_of[side_of >= 0]] = True
        for k, (i, j) in enumerate(((0, 1), (1, 2), (3, 2), (0, 3))):
            on_side[[i, j], k] = True
        flat = np.zeros(len(tris), dtype=bool)
        for k in range(4):
            flat |= on_side[tris, k].all(axis=1)
        tris = tris[~flat]
        tris = _symmetric_ties(points, uv, tris, n)
    return Mesh(points, tris, uv=uv)


def _symmetric_ties(points, uv, tris, n):
    """Re-split the grid cells whose four corners are cocircular so that the diagonals mirror
    about the box's centre lines (a "union jack": each quarter's diagonals point at the centre).

    A rectangle's grid cells are cocircular, so both diagonals are Delaunay and the
    triangulation's tie-break alone picked one: every cell the same way, a lattice that is
    stiffer in one shear direction than the other. A square of springs dropped flat then
    lands turning (17.6 degrees measured) and finite elements on it drift sideways as the
    impact's ripples bounce (16 cm after 4 s). Either split is still Delaunay, so the mesh
    stays a Delaunay triangulation; cells of a non-rectangular quad are not cocircular and
    keep Delaunay's unique choice.
    """
    from .predicates import incircle_signs

    m = n + 1  # cells per side
    grid = np.rint(uv * m).astype(np.int64)
    at = np.full((m + 1, m + 1), -1, np.int64)
    at[grid[:, 0], grid[:, 1]] = np.arange(len(points))
    g = np.take(grid, tris, axis=0)  # (T, 3, 2); np.take: ~10x faster than grid[tris]
    lo = g.min(axis=1)
    one_cell = (g.max(axis=1) - lo <= 1).all(axis=1)
    cell_id = lo[:, 0] * m + lo[:, 1]
    ids, counts = np.unique(cell_id[one_cell], return_counts=True)
    # every cell at once: one Python pass per cell, with a scan of all triangles in each,
    # took minutes at detail = 1000 (quadratic: 18 s at 300, before any run started)
    cells = ids[counts == 2]
    i, j = np.divmod(cells, m)
    p00, p10, p11, p01 = at[i, j], at[i + 1, j], at[i + 1, j + 1], at[i, j + 1]
    q = [np.take(points, p, axis=0) for p in (p00, p10, p11, p01)]
    # the cell's corners in counter-clockwise order for the in-circle test
    cw = ((q[1][:, 0] - q[0][:, 0]) * (q[2][:, 1] - q[0][:, 1])
          - (q[1][:, 1] - q[0][:, 1]) * (q[2][:, 0] - q[0][:, 0])) < 0
    q = [np.where(cw[:, None], q[3 - k], q[k]) for k in range(4)]
    tie = incircle_signs(*(np.ascontiguousarray(v) for v in q)) == 0.0
    if not tie.any():
        return tris
    cells, i, j, p00, p10, p11, p01 = (v[tie] for v in (cells, i, j, p00, p10, p11, p01))
    side = (2 * i + 1 - m) * (2 * j + 1 - m)  # sign: which quarter (0 on a middle row or column)
    rising = (side > 0) | ((side == 0) & ((i + j) % 2 == 0))
    retied = np.zeros((m + 1) * (m + 1), bool)  # cell_id of a triangle off the grid cells is below this too
    retied[cells] = True
    keep = ~(one_cell & retied[cell_id])
    # two triangles per cell, in the cells' order: diagonal p00-p11 (rising) or p10-p01
    first = np.where(rising[:, None], np.c_[p00, p10, p11], np.c_[p00, p10, p01])
    second = np.where(rising[:, None], np.c_[p00, p11, p01], np.c_[p10, p11, p01])
    new = np.stack([first, second], axis=1).reshape(-1, 3).astype(tris.dtype)
    # np.take: gathers (N, 2) rows ~10x faster than points[new[:, k]]
    a, b, c = (np.take(points, new[:, k], axis=0) for k in range(3))
    cw = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
    new[cw] = new[cw][:, [0, 2, 1]]
    return np.concatenate([tris[keep], new])


def _check_corners(corners) -> np.ndarray:
    try:
        c = np.array(corners, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"corners must be four (x, y) pairs of numbers, got {corners!r}") from None
    if c.shape != (4, 2):
        raise ValueError(f"corners must be four (x, y) pairs, shape (4, 2), got shape {c.shape}")
    if not np.all(np.isfinite(c)):
        raise ValueError("corners must be finite numbers (no NaN or inf)")
    if np.abs(c).max() > MAX_COORDINATE:
        raise ValueError(f"corners must lie within +-{MAX_COORDINATE:g} m, got {np.abs(c).max():g}")
    size = float(np.ptp(c, axis=0).max())
    if size == 0.0:
        raise ValueError("corners are all the same point; they must span a convex quadrilateral")
    e = np.roll(c, -1, axis=0) - c
    lengths = np.hypot(e[:, 0], e[:, 1])
    if lengths.min() <= 1e-12 * size:
        raise ValueError("two neighbouring corners coincide; the four corners must be distinct")
    # cross product at each corner, relative to the two sides' lengths: sin of the turn
    turn = (e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0])
    sin_turn = turn / (lengths * np.roll(lengths, -1))
    if np.abs(sin_turn).min() < 1e-9:
        raise ValueError(
            "three corners lie on a line (degenerate quad); corners must form a convex "
            "quadrilateral with no straight angle"
        )
    positive = int((sin_turn > 0).sum())
    if positive == 2:
        raise ValueError(
            "corners form a self-intersecting (crossed) quad; give them in order around the "
            "outline, counter-clockwise or clockwise"
        )
    if positive in (1, 3):
        raise ValueError(
            "corners form a concave quad; only a convex quadrilateral is allowed (every "
            "corner turning the same way)"
        )
    return c


def _check_detail(detail) -> int:
    """An integer >= 0; its upper bound is the box's point count (``check_box_points``)."""
    if isinstance(detail, (bool, np.bool_)):
        raise ValueError(f"detail must be an integer >= 0, got {detail!r}")
    try:
        n = operator.index(detail)
    except TypeError:
        raise ValueError(f"detail must be an integer >= 0, got {detail!r}") from None
    if n < 0:
        raise ValueError(f"detail must be an integer >= 0, got {n}")
    return n

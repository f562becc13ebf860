"""Outlines of pictures: the foreground as simple polygons with holes, in metres.

The geometry behind level pictures: a level drawn in any paint program becomes a few
polygons (one per connected piece of foreground, with its holes) that static colliders can
be made of. A mesh (:func:`deforma.mesh.from_image`) wants a dense, even outline; a collider
wants as few corners as follow the shape, so here the outline is simplified.

How it works:

1. **Foreground.** The picture is read and its foreground decided exactly as
   :func:`deforma.mesh.from_image` does it (same loader, ``background``, ``threshold``,
   transparency wins, specks and pin-holes dropped), so a body meshed from a picture and the
   picture's outline describe the same pixels.
2. **Contours.** Marching squares (:func:`skimage.measure.find_contours`) on the mask,
   padded with background so every contour closes, at level 0.5: each contour point is the
   middle of a pixel edge between foreground and background. Foreground pieces are
   side-connected (4-connected), as in the mesher, so two pieces meeting at a corner are two
   regions. Each contour separates one foreground piece from the background; the piece's
   largest contour is its outer loop, the others are its holes. A piece inside a hole (an
   island) is a region of its own.
3. **Simplification.** Ramer-Douglas-Peucker on each closed loop, to ``tolerance`` pixels:
   every contour point stays within ``tolerance`` of the simplified loop. Tolerance 0 only
   drops points in the middle of straight runs, so the staircase stays exact.
4. **Simple polygons.** A simplified loop may cross itself or a neighbouring loop (a narrow
   neck, a hole close to the edge), may collapse to under three corners, or may leave a hole
   outside its outer loop. Every loop involved has its tolerance halved and is simplified
   again, down to the unsimplified contour, which is simple by construction. The checks run
   in pixel units, where every corner is a multiple of half a pixel, so the orientation tests
   are exact in floating point.
5. **Metres.** ``x = (x_img - cx) * scale``, ``y = (cy - y_img) * scale``, y up, with
   ``(cx, cy)`` the centre of the contours' bounding box: the placement of
   :func:`deforma.mesh.from_image`, whose vertices are centred on their bounding box, so the
   outline of a picture lies on the mesh of the same picture and scale (to within a pixel:
   the mesher follows the alpha contour of antialiased pictures, a fraction of a pixel from
   the mask's). Outer loops run counter-clockwise, holes clockwise.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..checks import non_negative, positive
from .image import Background, ImageSource, _check_foreground, _clean, _load

# px: a loop still bad when halved to here goes to 0 (straight runs only), then unsimplified
_MIN_TOLERANCE = 1.0 / 16.0
# candidate segment pairs tested at once by the crossing check (bounds its memory)
_PAIR_CHUNK = 2_000_000


def outline(
    source: ImageSource,
    *,
    scale: float = 0.01,
    tolerance: float = 1.0,
    background: Background = "black",
    threshold: float | None = None,
    min_area: float = 4.0,
) -> list[tuple[np.ndarray, list[np.ndarray]]]:
    """The foreground of a picture as simple polygons with holes, in metres.

    Parameters
    ----------
    source : str, os.PathLike, PIL.Image.Image or array_like
        As for :func:`deforma.mesh.from_image`: a built-in texture name (``"bunny"``,
        ``"donut"``, ``"armadillo"``), a path, a Pillow image or an ``(H, W)``,
        ``(H, W, 3)`` or ``(H, W, 4)`` array.
    scale : float, keyword-only
        Metres per pixel, > 0.
    tolerance : float, keyword-only
        How far, in pixels, the simplified outline may stray from the traced one, >= 0.
        0 keeps every corner of the pixel staircase; larger gives fewer corners. Where
        simplifying would make a loop cross itself or another loop, that loop is
        simplified less.
    background : str or tuple of int, keyword-only
        As for :func:`deforma.mesh.from_image`: ``"black"``, ``"white"``, ``"auto"``, or a
        colour ``"#rrggbb"`` / ``(r, g, b)``. Ignored for pictures with transparency.
    threshold : float, optional, keyword-only
        As for :func:`deforma.mesh.from_image`, in [0, 1).
    min_area : float, keyword-only
        Loops enclosing less than this many square pixels are dropped (a dropped outer
        loop takes its holes with it), >= 0. Specks and pin-holes under 9 pixels are
        already gone, as in the mesher.

    Returns
    -------
    list of (outer, holes)
        One entry per connected piece of foreground, in the order of their topmost,
        then leftmost, pixel. ``outer`` is a ``(K, 2)`` float64 array of corners in metres,
        counter-clockwise, not closed (the first corner is not repeated); ``holes`` is a
        list of such arrays, clockwise. No loop crosses or touches itself or another loop,
        and each hole lies inside its outer loop.

    Raises
    ------
    ValueError
        On a bad ``source``, ``background`` or ``threshold`` (as :func:`from_image`), a
        ``scale``, ``tolerance`` or ``min_area`` out of range, or a picture with no
        foreground or nothing but foreground.

    Examples
    --------
    A 40 x 20 px rectangle at 1 cm per pixel is one 0.4 x 0.2 m polygon with four corners:

    >>> import numpy as np
    >>> import deforma
    >>> picture = np.zeros((40, 60), np.uint8)
    >>> picture[10:30, 10:50] = 255
    >>> [(outer, holes)] = deforma.mesh.outline(picture, scale=0.01)
    >>> len(outer), len(holes), np.ptp(outer, axis=0).round(2).tolist()
    (4, 0, [0.4, 0.2])

    The built-in donut keeps its hole:

    >>> [(outer, holes)] = deforma.mesh.outline("donut", tolerance=2.0)
    >>> len(holes)
    1
    """
    scale = positive(scale, "scale", "m per pixel")
    tolerance = non_negative(tolerance, "tolerance", "px")
    min_area = non_negative(min_area, "min_area", "square px")
    pic = _load(source, background, threshold)
    raw = pic.field > pic.level
    mask = _clean(raw)
    _check_foreground(pic, mask, raw)

    xy, sizes, piece = _contours(mask)
    cx, cy = 0.5 * (xy.min(axis=0) + xy.max(axis=0))
    loops = _split(xy, sizes)
    size = np.abs(_loop_areas(xy, sizes))
    # a piece's outer loop encloses its holes, so it is its largest
    regions: list[Any] = []  # (outer, holes) as traced loops in image units
    order = np.lexsort((-size, piece))
    first = np.r_[True, piece[order][1:] != piece[order][:-1]]
    for k, is_outer in zip(order, first):
        if is_outer:
            dropped = size[k] < min_area  # a dropped outer loop takes its holes along
            if not dropped:
                regions.append((loops[k], []))
        elif not dropped and size[k] >= min_area:
            regions[-1][1].append(loops[k])

    if not regions:
        raise ValueError(f"min_area = {min_area:g} square px drops every piece of the picture (the largest is "
                         f"{float(size.max()):.0f} square px): lower it")
    out = []
    for outer, holes in _simplify_regions(regions, tolerance):
        out.append((_to_metres(outer, cx, cy, scale, True), [_to_metres(h, cx, cy, scale, False) for h in holes]))
    return out


def _contours(mask):
    """The closed outlines of ``mask``'s pieces, in image units (see :func:`_staircase`).

    Returns the corners of all loops one after another (no loop closed), each loop's
    number of corners, and each loop's foreground piece (``ndimage.label`` of the mask).
    """
    from scipy import ndimage  # imported where used: 0.3 s that a run without pictures never needs
    from skimage.measure import find_contours

    padded = np.pad(mask, 1).astype(np.float64)
    pieces, _ = ndimage.label(np.pad(mask, 1))  # side-connected, as find_contours' "high" side
    traced = []
    for c in find_contours(padded, 0.5):
        traced.append(c[:-1] if len(c) > 1 and np.array_equal(c[0], c[-1]) else c)
    sizes = np.array([len(c) for c in traced])
    rc = np.concatenate(traced)
    # each point is the middle of a pixel edge (values 0 and 1, level 0.5): one of the two
    # pixels it separates is foreground, and names the piece the loop bounds
    r, q = rc[np.r_[0, np.cumsum(sizes)[:-1]]].T
    piece = np.maximum(
        pieces[np.floor(r).astype(np.int64), np.floor(q).astype(np.int64)],
        pieces[np.ceil(r).astype(np.int64), np.ceil(q).astype(np.int64)],
    )
    xy, sizes = _staircase(np.c_[rc[:, 1] - 0.5, rc[:, 0] - 0.5], sizes, padded)  # -> image x, y
    return xy, sizes, piece


def _staircase(xy, sizes, padded):
    """The pixel borders that marching-squares loops of a mask cut across: the exact outline.

    Marching squares joins the middles of pixel edges, so it cuts every corner of the
    staircase by a diagonal: a square would come out an octagon, its area short by an
    eighth of a pixel per corner. Where a loop turns from a vertical pixel border to a
    horizontal one the corner of the pixels is put back. Not at a saddle (two pixels of the
    same kind meeting at a corner only): there the corner is shared by two stretches of
    outline, and the diagonal keeps them apart, so every loop stays simple.
    """
    nxt = np.take(xy, _next_index(sizes), axis=0)  # np.take: rows ~10x faster than xy[...]
    on_vertical = xy[:, 0] == np.round(xy[:, 0])  # x on a pixel border: a vertical edge
    turn = on_vertical != (nxt[:, 0] == np.round(nxt[:, 0]))
    corner = np.where(on_vertical[:, None], np.c_[xy[:, 0], nxt[:, 1]], np.c_[nxt[:, 0], xy[:, 1]])
    # the 2 x 2 pixels around each corner (image (x, y) -> padded (row, col) of the top left)
    cx, cy = corner[:, 0].astype(np.int64), corner[:, 1].astype(np.int64)
    tl, tr = padded[cy, cx], padded[cy, cx + 1]
    bl, br = padded[cy + 1, cx], padded[cy + 1, cx + 1]
    add = turn & ~((tl == br) & (tr == bl) & (tl != tr))
    both = np.stack([xy, corner], axis=1).reshape(-1, 2)
    added = np.add.reduceat(add.astype(np.int64), np.r_[0, np.cumsum(sizes)[:-1]])
    return both[np.c_[np.ones(len(xy), bool), add].ravel()], sizes + added


def _next_index(sizes):
    """For loops stored one after another, the index of each point's successor in its loop."""
    start = np.repeat(np.r_[0, np.cumsum(sizes)[:-1]], sizes)
    return start + (np.arange(int(np.sum(sizes))) - start + 1) % np.repeat(sizes, sizes)


def _loop_areas(xy, sizes):
    """Signed shoelace areas of loops stored one after another (> 0: counter-clockwise in x, y)."""
    nxt = np.take(xy, _next_index(sizes), axis=0)  # np.take: rows ~10x faster than xy[...]
    twice = xy[:, 0] * nxt[:, 1] - xy[:, 1] * nxt[:, 0]
    return 0.5 * np.add.reduceat(twice, np.r_[0, np.cumsum(sizes)[:-1]])


def _split(xy, sizes):
    return np.split(xy, np.cumsum(sizes)[:-1])


def _to_metres(xy, cx, cy, scale, ccw):
    m = np.c_[(xy[:, 0] - cx) * scale, (cy - xy[:, 1]) * scale]
    if (_loop_areas(m, [len(m)])[0] > 0) != ccw:
        m = m[::-1]
    return np.ascontiguousarray(m, dtype=np.float64)


# ---- simplification ------------------------------------------------------------------------


def simplify_loop(xy: np.ndarray, tolerance: float) -> np.ndarray:
    """Ramer-Douglas-Peucker on a closed loop: the corners kept, as a subset of ``xy``.

    Every point of ``xy`` lies within ``tolerance`` of the returned loop (of the segment
    between the two kept corners around it). The loop is cut at its leftmost point and the
    point farthest from it, both kept, and both halves are split at once, one level of the
    recursion per numpy pass (:func:`_simplify` does many loops in the same passes).

    Parameters
    ----------
    xy : (N, 2) array_like
        The loop, not closed (first point not repeated), N >= 3.
    tolerance : float
        Largest distance allowed, in the units of ``xy``, >= 0. At 0 only points on the
        straight segment between their neighbouring kept corners go.

    Returns
    -------
    (K, 2) ndarray
        The kept corners in their order along ``xy``, starting at the leftmost; K >= 2 (a
        loop thinner than ``tolerance`` may collapse to a segment: the caller checks).

    Examples
    --------
    >>> square = [(0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
    >>> simplify_loop(square, 0.0).tolist()
    [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
    """
    xy = np.asarray(xy, dtype=np.float64)
    kept, _ = _simplify(xy, np.array([len(xy)]), np.array([float(tolerance)]))
    return kept


def _simplify(xy, sizes, tolerances):
    """:func:`simplify_loop` for loops stored one after another; returns corners and sizes."""
    n_loops = len(sizes)
    offset = np.r_[0, np.cumsum(sizes)[:-1]]
    loop = np.repeat(np.arange(n_loops), sizes)
    # each loop's leftmost (then lowest) point, and the point farthest from it
    order = np.lexsort((xy[:, 1], xy[:, 0], loop))
    start = order[np.r_[0, np.cumsum(sizes)[:-1]]] - offset
    # np.take: gathers (N, 2) rows ~10x faster than fancy indexing
    d = np.hypot(*(xy - np.take(xy[offset + start], loop, axis=0)).T)
    order = np.lexsort((-d, loop))
    far = order[np.r_[0, np.cumsum(sizes)[:-1]]] - offset
    # each loop as an open path from its start back to it: sizes + 1 points
    plen = sizes + 1
    pstart = np.r_[0, np.cumsum(plen)[:-1]]
    ploop = np.repeat(np.arange(n_loops), plen)
    j = np.arange(int(plen.sum())) - pstart[ploop]  # position along the path
    path = np.take(xy, offset[ploop] + (start[ploop] + j) % sizes[ploop], axis=0)
    keep = (j == 0) | (j == sizes[ploop]) | (j == (far - start)[ploop] % sizes[ploop])
    tol = np.asarray(tolerances, dtype=np.float64)[ploop]
    everything = np.arange(len(path))
    while True:
        ends = np.flatnonzero(keep)
        seg = np.minimum(np.searchsorted(ends, everything, side="right") - 1, len(ends) - 2)
        # np.take: the segments' ends ~5x faster than path[ends[seg]], once per pass
        dist = _point_segment_distance(path, np.take(path, ends[seg], axis=0), np.take(path, ends[seg + 1], axis=0))
        dist[keep] = -1.0
        worst = np.maximum.reduceat(dist, ends[:-1])
        # a "segment" from one path's end to the next path's start holds no point: never split
        split = (worst > tol[ends[:-1]])[seg]
        if not split.any():
            break
        # the first point of each segment where its largest distance is reached
        at = np.flatnonzero(split & (dist == worst[seg]))
        first = np.r_[True, seg[at][1:] != seg[at][:-1]]
        keep[at[first]] = True
    keep &= j < sizes[ploop]  # the closing copy of each start
    return path[keep], np.bincount(ploop[keep], minlength=n_loops)


def _point_segment_distance(p, a, b):
    ab = b - a
    ab2 = np.einsum("ij,ij->i", ab, ab)
    t = np.einsum("ij,ij->i", p - a, ab) / np.where(ab2 > 0, ab2, 1.0)
    t = np.clip(np.where(ab2 > 0, t, 0.0), 0.0, 1.0)
    return np.hypot(*(p - a - t[:, None] * ab).T)


def _simplify_regions(regions, tolerance):
    """Simplify every loop, less where the result is not a set of simple, nested polygons."""
    traced = [loop for outer, holes in regions for loop in (outer, *holes)]
    count = np.array([1 + len(holes) for _, holes in regions])
    owner = np.repeat(np.arange(len(regions)), count)
    outer_of = np.r_[0, np.cumsum(count)[:-1]]
    xy, sizes = np.concatenate(traced), np.array([len(loop) for loop in traced])
    # beyond a loop's size every tolerance gives the same collapsed loop: start there, so
    # halving reaches a usable one in a few rounds whatever the caller asked
    extent = np.array([np.hypot(*np.ptp(loop, axis=0)) for loop in traced])
    tol = np.minimum(float(tolerance), extent)
    traced_area = _loop_areas(xy, sizes)
    done = [None] * len(traced)
    todo = np.arange(len(traced))
    while True:
        # below zero: the traced loop itself (simple by construction: marching-squares
        # loops never cross or touch, nor do the staircases made of them)
        simplify = todo[tol[todo] >= 0]
        for k in todo[tol[todo] < 0]:
            done[k] = traced[k]
        if len(simplify):
            part = np.concatenate([traced[k] for k in simplify])
            kept, kept_sizes = _simplify(part, sizes[simplify], tol[simplify])
            for k, loop in zip(simplify, _split(kept, kept_sizes)):
                done[k] = loop
        bad = _bad_loops(done, traced_area, owner, outer_of)
        if not bad.any():
            break
        todo = np.flatnonzero(bad)
        if np.all(tol[todo] < 0):  # traced loops cannot be bad; never loop forever
            raise RuntimeError(f"outline loops {todo.tolist()} are not simple even unsimplified")
        tol[todo] = np.where(tol[todo] > _MIN_TOLERANCE, 0.5 * tol[todo], np.where(tol[todo] > 0, 0.0, -1.0))
    out, k = [], 0
    for c in count:
        out.append((done[k], done[k + 1 : k + c]))
        k += c
    return out


def _bad_loops(loops, traced_area, owner, outer_of):
    """True for each loop that is degenerate, crosses a loop, or is a hole outside its outer."""
    from skimage.measure import points_in_poly

    sizes = np.array([len(loop) for loop in loops])
    area = _loop_areas(np.concatenate(loops), sizes)
    bad = (sizes < 3) | (area == 0) | ((area > 0) != (traced_area > 0))
    for i, j in _crossing_loops(loops):
        bad[i] = bad[j] = True
    for k in range(len(loops)):
        outer = outer_of[owner[k]]
        if k != outer and not bad[k] and not bad[outer]:
            if not points_in_poly(loops[k][:1], loops[outer])[0]:
                bad[k] = bad[outer] = True
    return bad


def _crossing_loops(loops):
    """Pairs (i, j) of loop indices whose segments cross or touch (i == j: itself).

    Segments that share a corner in their loop count only if they fold back over each
    other. Candidates come from a sweep along x (sorted by their left end, each paired
    with those that start before it ends), so the work grows with the overlaps, not n^2.
    """
    sizes = np.array([len(xy) for xy in loops])
    a = np.concatenate(loops)
    b = a[_next_index(sizes)]
    loop = np.repeat(np.arange(len(loops)), sizes)
    pos = np.arange(len(a)) - np.repeat(np.r_[0, np.cumsum(sizes)][:-1], sizes)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    order = np.argsort(lo[:, 0], kind="stable")
    a, b, loop, pos, lo, hi = a[order], b[order], loop[order], pos[order], lo[order], hi[order]
    stop = np.searchsorted(lo[:, 0], hi[:, 0], side="right")
    count = np.maximum(stop - np.arange(len(a)) - 1, 0)

    found = []
    begin = 0
    total = np.cumsum(count)
    while begin < len(a):
        base = total[begin - 1] if begin else 0
        end = max(int(np.searchsorted(total, base + _PAIR_CHUNK, side="right")), begin + 1)
        i = np.repeat(np.arange(begin, end), count[begin:end])
        j = i + 1 + np.arange(len(i)) - np.repeat(np.cumsum(count[begin:end]) - count[begin:end], count[begin:end])
        begin = end
        near = (lo[j, 1] <= hi[i, 1]) & (lo[i, 1] <= hi[j, 1])
        i, j = i[near], j[near]
        if len(i) == 0:
            continue
        same = loop[i] == loop[j]
        gap = np.abs(pos[i] - pos[j])
        adjacent = same & ((gap == 1) | (gap == sizes[loop[i]] - 1))
        hit = np.where(adjacent, _folds_back(a, b, i, j), _segments_meet(a[i], b[i], a[j], b[j]))
        found.append(np.c_[loop[i][hit], loop[j][hit]])
    return np.concatenate(found) if found else np.zeros((0, 2), dtype=np.int64)


def _cross(o, p, q):
    # exact: corners lie on a half-pixel grid, so each product is a whole number of quarter
    # pixels no larger than about the picture's pixel count, far within a double's 53 bits
    return (p[:, 0] - o[:, 0]) * (q[:, 1] - o[:, 1]) - (p[:, 1] - o[:, 1]) * (q[:, 0] - o[:, 0])


def _on_segment(a, b, p):
    """For points known to be on line ab: within the segment's box."""
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    return np.all((lo <= p) & (p <= hi), axis=1)


def _segments_meet(a, b, c, d):
    """Closed segments ab and cd cross or touch."""
    d1, d2 = _cross(a, b, c), _cross(a, b, d)
    d3, d4 = _cross(c, d, a), _cross(c, d, b)
    proper = (np.sign(d1) * np.sign(d2) < 0) & (np.sign(d3) * np.sign(d4) < 0)
    touch = ((d1 == 0) & _on_segment(a, b, c)) | ((d2 == 0) & _on_segment(a, b, d))
    touch |= ((d3 == 0) & _on_segment(c, d, a)) | ((d4 == 0) & _on_segment(c, d, b))
    return proper | touch


def _folds_back(a, b, i, j):
    """Neighbouring segments (sharing a corner) that overlap along a line: a spike."""
    # order each pair so that segment i ends where segment j starts
    swap = ~np.all(b[i] == a[j], axis=1)
    first, second = np.where(swap, j, i), np.where(swap, i, j)
    p, q, r = a[first], b[first], b[second]
    turn = _cross(p, q, r)
    back = np.einsum("ij,ij->i", p - q, r - q) > 0
    return (turn == 0) & back

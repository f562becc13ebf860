"""Placeholder during development: replaced by the Bowyer-Watson kernel."""
import numpy as np
from scipy.spatial import Delaunay as _D


def delaunay(points):
    pts = np.asarray(points, dtype=np.float64)
    t = _D(pts).simplices.astype(np.int32)
    a, b, c = pts[t[:, 0]], pts[t[:, 1]], pts[t[:, 2]]
    cw = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
    t[cw] = t[cw][:, [0, 2, 1]]
    return t

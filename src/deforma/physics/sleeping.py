"""Sleeping: bodies at rest stop being stepped until something disturbs them.

Bodies form *islands*: two bodies touching (a contact pair of the last step,
:func:`~deforma.physics.contact.pairs.group_pairs`) or joined by a joint are in one island;
colliders join nothing. After each step every body's fastest vertex is measured; a body
slower than :data:`SLEEP_SPEED` for :data:`SLEEP_TIME` on end is *still*. An island whose
bodies are all still, and which the world holds (one of its bodies pinned, joined to the
world or touching a collider: not a body drifting slowly through space, whose momentum
sleep would take), falls asleep as a whole: its velocities become zero and its vertices
are held as pins are (infinite mass) until it wakes, so the bodies awake meet it as a fixed
shape. When every body sleeps the step costs no integration at all.

An island wakes when an awake body may reach one of its bodies within the step (checked
before the step, on bounding boxes grown by the awake body's reach, :func:`body_boxes`,
:func:`touching_boxes`: woken after it, the island would meet the impact held, as a wall),
when one of its bodies is touched by an awake body, is pushed, pulled,
dragged, pinned or unpinned, gets a joint or loses one, touches a moving collider, or has
a parameter set; a change to the world's own parameters, its colliders or its bodies wakes
every island. Box2D does the same (islands over contacts and joints, a time below speed
thresholds); its thresholds are 5 cm/s and 2 deg/s for game units, ours one speed for any
vertex, so that a turn counts by the speed it gives the body's far side.

Units: m/s, s.
"""

from __future__ import annotations

import numpy as np

from .union_find import component_labels

#: A body whose every vertex is slower than this (m/s) is still.
SLEEP_SPEED = 5e-3
#: An island whose bodies have all been still this long (s) falls asleep.
SLEEP_TIME = 0.5


def fastest_vertex(v: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Per body, the speed of its fastest vertex (m/s): ``v`` (N, 2) m/s, bodies' vertices
    ``offsets[b]:offsets[b + 1]``.

    Examples
    --------
    >>> fastest_vertex(np.array([[3.0, 4.0], [0.0, 1.0], [0.0, 0.0]]), np.array([0, 2, 3]))
    array([5., 0.])
    """
    speed = np.hypot(v[:, 0], v[:, 1])
    out = np.zeros(len(offsets) - 1)
    filled = np.diff(offsets) > 0
    out[filled] = np.maximum.reduceat(speed, offsets[:-1][filled]) if len(speed) else 0.0
    return out


def body_boxes(x: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per body, the corners ``(lo, hi)`` (B, 2) of its bounding box (m): vertices ``x`` (N, 2)
    m, bodies' vertices ``offsets[b]:offsets[b + 1]`` (an empty body's box is empty: lo = inf,
    hi = -inf).

    Examples
    --------
    >>> lo, hi = body_boxes(np.array([[0.0, 0.0], [1.0, 2.0], [5.0, 5.0]]), np.array([0, 2, 3]))
    >>> lo.tolist(), hi.tolist()
    ([[0.0, 0.0], [5.0, 5.0]], [[1.0, 2.0], [5.0, 5.0]])
    """
    b = len(offsets) - 1
    lo, hi = np.full((b, 2), np.inf), np.full((b, 2), -np.inf)
    filled = np.diff(offsets) > 0
    if filled.any():
        lo[filled] = np.minimum.reduceat(x, offsets[:-1][filled])
        hi[filled] = np.maximum.reduceat(x, offsets[:-1][filled])
    return lo, hi


def touching_boxes(lo_a: np.ndarray, hi_a: np.ndarray, lo_b: np.ndarray, hi_b: np.ndarray) -> np.ndarray:
    """Which of the boxes ``b`` (corners (M, 2)) overlap any of the boxes ``a`` ((K, 2)): (M,)
    bool.

    Examples
    --------
    >>> touching_boxes(np.array([[0.0, 0.0]]), np.array([[1.0, 1.0]]),
    ...                np.array([[0.5, 0.5], [2.0, 0.0]]), np.array([[3.0, 3.0], [3.0, 1.0]])).tolist()
    [True, False]
    """
    overlap = ((lo_a[:, None, :] <= hi_b[None, :, :]) & (lo_b[None, :, :] <= hi_a[:, None, :])).all(axis=2)
    return overlap.any(axis=0)


def islands(n_bodies: int, links: np.ndarray) -> np.ndarray:
    """Each body's island label (B,): bodies linked (``links`` (L, 2) body indices, by contact
    or joint) directly or through others share one.

    Examples
    --------
    >>> islands(4, np.array([[0, 2], [2, 3]])).tolist()
    [0, 1, 0, 0]
    """
    links = np.ascontiguousarray(links, np.int64).reshape(-1, 2)
    if not len(links):
        return np.arange(n_bodies, dtype=np.int64)
    return component_labels(n_bodies, links)


def sleep_changes(asleep: np.ndarray, still: np.ndarray, speed: np.ndarray, label: np.ndarray,
                  kept_awake: np.ndarray, dt: float, held: np.ndarray | None = None):
    """One step of the rule (module docstring) over B bodies: ``(fall_asleep, wake, still)``,
    masks of the bodies that fall asleep and that wake now, and the time each has been still
    (s).

    Parameters
    ----------
    asleep : (B,) bool
        Asleep before this step.
    still : (B,) float64
        How long each has been still (s), before this step.
    speed : (B,) float64
        Its fastest vertex after this step (m/s; an asleep body's is 0).
    label : (B,) int64
        Island labels (:func:`islands`).
    kept_awake : (B,) bool
        Bodies something keeps awake this step (grabbed, pushed, on a moving collider).
    dt : float
        The step (s).
    held : (B,) bool, optional
        Bodies the world holds: pinned, joined to the world, or touching a collider. An
        island falls asleep only with one of them in it (or a body asleep already); None:
        every body counts as held.

    Examples
    --------
    Two bodies resting on each other for 0.6 s and a third one moving:

    >>> f, w, s = sleep_changes(np.zeros(3, bool), np.array([0.6, 0.6, 0.6]), np.array([0.0, 0.001, 1.0]),
    ...                         np.array([0, 0, 1]), np.zeros(3, bool), 1 / 60, np.array([True, False, False]))
    >>> f.tolist(), w.tolist()
    ([True, True, False], [False, False, False])

    The same two drifting slowly in space, touching nothing that holds them, stay awake:

    >>> f, w, s = sleep_changes(np.zeros(3, bool), np.array([0.6, 0.6, 0.6]), np.array([0.0, 0.001, 1.0]),
    ...                         np.array([0, 0, 1]), np.zeros(3, bool), 1 / 60, np.zeros(3, bool))
    >>> f.tolist()
    [False, False, False]
    """
    still = np.where((speed < SLEEP_SPEED) & ~kept_awake, still + dt, 0.0)
    still[asleep] = SLEEP_TIME  # an asleep body counts as still
    n = int(label.max()) + 1 if len(label) else 0
    # an island wakes whole if any of its bodies is awake and not still (or kept awake) while
    # another sleeps; it sleeps whole once every body in it has been still long enough
    restless = np.bincount(label, weights=(~asleep & ((still < SLEEP_TIME) | kept_awake)).astype(float),
                           minlength=n) > 0
    wake = asleep & restless[label]
    fall_asleep = ~asleep & ~restless[label]
    if held is not None:
        # a body drifting slowly through space keeps its momentum: an island sleeps only
        # where the world holds it (Box2D lets any slow island sleep, which stops a body
        # drifting at 4 mm/s in zero gravity)
        supported = np.bincount(label, weights=(held | asleep).astype(float), minlength=n) > 0
        fall_asleep &= supported[label]
    still[wake] = 0.0
    return fall_asleep, wake, still

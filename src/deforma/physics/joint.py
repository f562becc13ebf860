"""Handles onto a world's joints: what :meth:`World.join` returns.

A :class:`Joint` holds a point of one body on a point of another, or on the world: a
``"pin"`` (a hinge, optionally driven by a motor), a ``"weld"`` (no relative turning
either) or a ``"spring"`` (a zero-length spring and damper). Welds and motors hold rigid
bodies; pins and springs hold soft ones too, by the triangle under the point. avbd solves
them as rows of its sweep (:mod:`deforma.physics.integrators.avbd.joints`), the other
integrators' rigid stage those of rigid bodies (:mod:`deforma.physics.rigid.joints`); the
handle keeps what the user gave, the anchors in the bodies' frames, the warm-start
impulses, and the force of the last step.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..checks import non_negative as _non_negative
from ..checks import number as _number
from ..checks import pair as _pair
from ..checks import positive as _positive
from . import rigid_motion
from .rigid.joints import KINDS

if TYPE_CHECKING:
    from .body import Body
    from .model import Model
    from .world import World

#: Largest motor speed (degrees/s) a joint takes, as a collider's spin.
MAX_MOTOR_SPEED = 1e6


class Joint:
    """A joint of a world (see :meth:`World.join`).

    Attributes
    ----------
    a, b : Body, Body or None
        The bodies it joins (``b`` None: the world), rigid or (a pin or a spring) soft.
    kind : str
        ``"pin"``, ``"weld"`` or ``"spring"``.
    anchor : (float, float)
        Where it was made (m), the point both bodies hold.
    stiffness, damping : float or None
        A spring's N/m and N s/m (None on a pin or weld).
    break_force : float or None
        N: the force past which a step breaks it (None: never).
    """

    def __init__(self, world: World, a: Body, b: Body | None, kind: str, anchor: tuple[float, float], local: ArrayLike,
                 reference: float, stiffness: float | None, damping: float | None, motor_speed: float | None,
                 max_torque: float | None, frame: tuple[Any, ...] | None = None,
                 break_force: float | None = None) -> None:
        self._world = world
        self.a, self.b, self.kind = a, b, kind
        self.anchor = anchor
        self._local = np.asarray(local, np.float64)   # a's anchor, b's (or the world point), body frames
        self._reference = float(reference)            # a weld's angle_a - angle_b (rad)
        self.stiffness, self.damping = stiffness, damping
        self._motor_speed = motor_speed
        self._max_torque = max_torque
        self._acc = np.zeros(4)                        # warm starts (see rigid.joints)
        self._impulse = np.zeros(3)                    # over the step so far: point (N s), angle (N m s)
        self._force = np.zeros(3)                      # the last step's, per second
        # avbd's rows (integrators.avbd.joints): per side its point as a rigid body carries
        # it and as a soft body does (see frame_rows), the frames' reference angle, and the
        # rows' warm start
        self._frame: Any = frame
        self.break_force = break_force
        self._broken = False
        self._lam = np.zeros(4)
        self._pen = np.zeros(4)

    @property
    def point(self) -> np.ndarray:
        """Where ``a`` holds the joint now (m): its anchor carried with it since the joint
        was made (``b``'s point is there too, up to the solver's drift); on a soft body, the
        point of the triangle it was made on."""
        a = self.a
        if not a.material.is_rigid:
            return self._side_point(0)
        x, m = a.positions, a.vertex_masses
        center = rigid_motion.center_of_mass(x, m)
        angle = rigid_motion.fit_angle(a.topology.rest_positions, x, m)
        c, s = math.cos(angle), math.sin(angle)
        lx, ly = self._local[0], self._local[1]
        return np.array([center[0] + c * lx - s * ly, center[1] + s * lx + c * ly])

    def _side_point(self, side: int) -> np.ndarray:
        """Where side ``side`` (0: ``a``, 1: ``b``) holds the joint now (m), as avbd's rows
        read it: a rigid body's point on its frame of two vertices, a soft body's on the
        triangle it was made on, the world's at the anchor. The two sides' points differ by
        what the solver left of the joint's error."""
        body = self.a if side == 0 else self.b
        if body is None:
            return np.array(self.anchor, np.float64)
        x = body.positions
        if not body.material.is_rigid:
            return self._frame[2][side] @ x[self._frame[1][side]]
        i0, i1, alpha, beta = self._frame[0][side]
        d = x[i1] - x[i0]
        return x[i0] + alpha * d + beta * np.array([-d[1], d[0]])

    @property
    def force(self) -> np.ndarray:
        """The force (N, x and y) the joint put on ``a`` over the last step, on average (``b``
        took the opposite)."""
        return self._force[:2].copy()

    @property
    def broken(self) -> bool:
        """Whether a step broke it (its force past ``break_force``): it has left the world."""
        return self._broken

    @property
    def torque(self) -> float:
        """The torque (N m, counter-clockwise) a weld or motor put on ``a`` over the last step,
        on average, besides the moment of :attr:`force`."""
        return float(self._force[2])

    @property
    def motor_speed(self) -> float | None:
        """A pin's motor: the spin of ``a`` relative to ``b`` it drives towards (degrees/s,
        counter-clockwise), or None for no motor."""
        return self._motor_speed

    @motor_speed.setter
    def motor_speed(self, value: float | None) -> None:
        self._motor_speed = motor(self.kind, value, self._max_torque)[0]
        self._world._disturb(self.a)  # a sleeping car wakes when driven

    @property
    def max_torque(self) -> float | None:
        """The most torque the motor gives (N m); None: as much as it takes."""
        return self._max_torque

    @max_torque.setter
    def max_torque(self, value: float | None) -> None:
        self._max_torque = motor(self.kind, self._motor_speed, value)[1]
        self._world._disturb(self.a)

    def _pack(self) -> tuple[int, np.ndarray, bool]:
        """``(kind code, param row, motor on)`` for the rigid solver."""
        speed = self._motor_speed
        torque = math.inf if self._max_torque is None else self._max_torque
        param = np.array([self._reference, 0.0 if speed is None else math.radians(speed), torque,
                          self.stiffness or 0.0, self.damping or 0.0])
        return KINDS[self.kind], param, speed is not None

    def _rows(self) -> tuple[np.ndarray, bool]:
        """``(param (6,), motor on)`` for avbd's rows: as :meth:`_pack`, with the frames'
        reference angle first (and the substep's length, set by the solver, last)."""
        _, param, on = self._pack()
        param[0] = self._frame[3]
        return np.append(param, 0.0), on

    def __repr__(self) -> str:
        b = "the world" if self.b is None else f"body {self.b._index}"
        return f"Joint({self.kind} of body {self.a._index} and {b} at {self.anchor})"


def motor(kind: str, speed: float | None, max_torque: float | None) -> tuple[float | None, float | None]:
    """A motor's ``(speed deg/s, max_torque N m)`` checked: a pin's only, the torque bound
    only with a speed."""
    if speed is None:
        if max_torque is not None:
            raise ValueError("max_torque needs motor_speed: a motor bounds its torque (N m) while it drives at a "
                             "speed (degrees/s)")
        return None, None
    if kind != "pin":
        raise ValueError(f"motor_speed is for a pin joint (a driven hinge), not a {kind}")
    s = _number(speed, "motor_speed")
    if abs(s) > MAX_MOTOR_SPEED:
        raise ValueError(f"motor_speed must be within +-{MAX_MOTOR_SPEED:g} degrees/s, got {speed!r}")
    return s, None if max_torque is None else _positive(max_torque, "max_torque", "N m")


def spring(kind: str, stiffness: float | None, damping: float | None) -> tuple[float | None, float | None]:
    """A joint's ``(stiffness N/m, damping N s/m)`` checked: a spring's, and only a spring's."""
    if kind != "spring":
        for name, value in (("stiffness", stiffness), ("damping", damping)):
            if value is not None:
                raise ValueError(f"{name} is for kind='spring'; a {kind} holds rigidly")
        return None, None
    if stiffness is None:
        raise ValueError("a spring joint needs stiffness (N/m, > 0)")
    return (_positive(stiffness, "stiffness", "N/m"),
            0.0 if damping is None else _non_negative(damping, "damping", "N*s/m"))


def pack_rows(joints: list[Joint], model: Model, bodies: np.ndarray) -> Any:
    """The joints as avbd's rows (:class:`~deforma.physics.integrators.avbd.joints.JointRows`)
    of ``model``, whose rigid bodies are ``bodies`` (body indices, in block order), warm-started
    from each joint's last step; None without joints. A side on a rigid body is its frame
    (two vertices), on a soft body its triangle (its weights), on the world its point."""
    if not joints:
        return None
    from .integrators.avbd.joints import make_joint_rows

    n = len(joints)
    where = {int(b): k for k, b in enumerate(bodies)}
    block = np.full((n, 2), -1, np.int64)
    fv, fw, param = np.full((n, 6), -1, np.int64), np.zeros((n, 6)), np.zeros((n, 6))
    kind, motor_on = np.zeros(n, np.int64), np.zeros(n, np.bool_)
    lam, pen = np.zeros((n, 4)), np.zeros((n, 4))
    off = model.body_vertex_offsets
    for i, j in enumerate(joints):
        param[i], motor_on[i] = j._rows()
        kind[i] = KINDS[j.kind]
        frames, tris, weights = j._frame[0], j._frame[1], j._frame[2]
        fw[i, 3:5] = j.anchor  # the world's point, unless b is a body
        for side, body in enumerate((j.a, j.b)):
            if body is None:
                continue
            c = slice(3 * side, 3 * side + 3)
            if body.material.is_rigid:
                block[i, side] = where[body._index]
                i0, i1, alpha, beta = frames[side]
                fv[i, c] = off[body._index] + i0, off[body._index] + i1, -1
                fw[i, c] = alpha, beta, 0.0
            else:
                fv[i, c] = off[body._index] + tris[side]
                fw[i, c] = weights[side]
        lam[i], pen[i] = j._lam, j._pen
    return make_joint_rows(block, fv, fw, kind, param, motor_on, lam, pen, len(bodies), model.n_vertices)


def read_rows(joints: list[Joint], rows: Any, dt: float) -> None:
    """After a step of ``dt`` s: each joint's force and torque (the rows' totals over the
    step, per second) and its rows' warm start for the next."""
    from .integrators.avbd.joints import LAM, PEN, TOTAL

    for i, j in enumerate(joints):
        j._force[...] = rows.jf[i, TOTAL:TOTAL + 3] / dt
        j._lam[...] = rows.jf[i, LAM:LAM + 4]
        j._pen[...] = rows.jf[i, PEN:PEN + 4]


def frame(x: np.ndarray, point: ArrayLike) -> tuple[int, int, float, float, float]:
    """Two of a rigid body's vertices ``x`` (body-local indices) and the point's ``(alpha,
    beta)`` on them (``point = x_0 + alpha d + beta perp(d)``, ``d = x_1 - x_0``), and the
    angle of ``d`` (rad): the point carried exactly as the body moves. The two are the
    first vertex and the farthest from it (the best-conditioned pair)."""
    d2 = ((x - x[0]) ** 2).sum(axis=1)
    i1 = int(np.argmax(d2))
    d = x[i1] - x[0]
    w = np.asarray(point, np.float64) - x[0]
    n2 = float(d @ d)
    return 0, i1, float(w @ d) / n2, float(-w[0] * d[1] + w[1] * d[0]) / n2, math.atan2(d[1], d[0])


def triangle_weights(x: np.ndarray, triangles: np.ndarray, point: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The triangle of a soft body (vertices ``x``, ``triangles``) that holds ``point`` and
    the point's barycentric weights on it, ``(vertices (3,), weights (3,))``: of the
    triangles under the point (on a shared edge or vertex, several) the one whose least
    weight is largest, the point deepest inside. A point off the body (within rounding of
    its outline) takes the nearest triangle's weights clipped to it."""
    a, b, c = x[triangles[:, 0]], x[triangles[:, 1]], x[triangles[:, 2]]
    p = np.asarray(point, np.float64)
    e1, e2, q = b - a, c - a, p - a
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    u = (q[:, 0] * e2[:, 1] - q[:, 1] * e2[:, 0]) / det
    v = (e1[:, 0] * q[:, 1] - e1[:, 1] * q[:, 0]) / det
    w = np.stack([1.0 - u - v, u, v], axis=1)
    best = int(np.argmax(w.min(axis=1)))
    weights = np.clip(w[best], 0.0, None)
    return triangles[best].astype(np.int64), weights / weights.sum()


def anchor(value: ArrayLike) -> tuple[float, float]:
    """The joint point ``at`` checked (m)."""
    return _pair(value, "at")

"""The inspector's parameters, grouped as in the original Unity inspector.

Plain data (no GUI): :mod:`deforma.viewer.inspector` makes a row of widgets for each
:class:`Param`, and :meth:`deforma.viewer.session.Session.set_param` applies values by name.
Slider ranges are what is comfortable to drag; the text box beside each slider accepts any
value the session accepts (it refuses the others with a message).

The rows of the integrators' options are not fixed data but read from the integrator registry
(:func:`integrator_params`), as the Integrator drop-down's names are, so that an integrator
registered by the user shows its options too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..physics.integrators import available_integrators, make_integrator

if TYPE_CHECKING:
    from ..physics.integrators.base import Option

__all__ = ["GROUPS", "INTEGRATOR_PREFIX", "PARAMS", "Param", "format_value", "integrator_params", "option_param",
           "parse_value"]


@dataclass(frozen=True)
class Param:
    """One inspector row.

    ``kind`` is ``float``, ``int``, ``bool`` or ``choice`` (a drop-down of ``choices``);
    ``lo``/``hi`` the slider's range and ``log`` whether it moves in equal ratios (stiffness
    from 10 to 100000 N/m needs that).
    ``rebuild`` marks values that rebuild the body (the original's mesh settings).
    ``optional`` marks values that may be off (``None``: a material behaviour that is not
    used, a body without gas, a collider's friction that follows the world's): an empty text
    box shows ``off_text`` and sets None.
    """

    name: str
    label: str
    kind: str = "float"
    lo: float = 0.0
    hi: float = 1.0
    log: bool = False
    unit: str = ""
    rebuild: bool = False
    tip: str = ""
    optional: bool = False
    off_text: str = "off"
    choices: tuple = ()

    def to_slider(self, value: float) -> float:
        """Slider position in [0, 1] for ``value`` (clamped)."""
        if self.log:
            v = max(float(value), self.lo)
            t = math.log(v / self.lo) / math.log(self.hi / self.lo)
        else:
            t = (float(value) - self.lo) / (self.hi - self.lo)
        return min(1.0, max(0.0, t))

    def from_slider(self, t: float) -> float | int:
        """The value at slider position ``t`` in [0, 1], rounded to what reads well."""
        t = min(1.0, max(0.0, float(t)))
        v = self.lo * (self.hi / self.lo) ** t if self.log else self.lo + t * (self.hi - self.lo)
        if self.kind == "int":
            return int(round(v))
        return float(f"{v:.3g}")


GROUPS: tuple[tuple[str, tuple[Param, ...]], ...] = (
    ("Square", (
        Param("detail", "Detail", "int", 0, 40, tip="n: n*n points inside the box", rebuild=True),
        Param("edges", "Set edges", "bool", tip="points on the four sides too", rebuild=True),
    )),
    ("Texture", (
        Param("scale", "Scale", "float", 0.001, 0.02, log=True, unit="m/px", tip="metres per pixel", rebuild=True),
        Param("resolution", "Resolution", "int", 3, 40, unit="px",
              tip="sample every n-th pixel; smaller gives more points", rebuild=True),
        Param("detect_edges", "Detect edges", "bool", tip="points along the outline", rebuild=True),
        Param("edge_step", "Edge step", "int", 1, 20, unit="px", tip="every n-th outline pixel", rebuild=True),
    )),
    ("Physics", (
        Param("dt", "Dt", "float", 1e-4, 0.05, log=True, unit="s", tip="seconds per step"),
        Param("substeps", "Substeps", "int", 1, 20, tip="integration substeps per step"),
        Param("gravity_x", "Gravity x", "float", -20, 20, unit="m/s²"),
        Param("gravity_y", "Gravity y", "float", -20, 20, unit="m/s²"),
        Param("damping", "Damping", "float", 0.0, 10.0, unit="N·s/m", tip="spring damping kd"),
        Param("air_drag", "Air drag", "float", 0.0, 5.0, unit="1/s", tip="velocities decay as -air_drag v"),
        Param("sleep", "Sleep", "bool", tip="bodies at rest fall asleep (drawn darker) until disturbed"),
        Param("mass", "Mass", "float", 0.1, 20.0, log=True, unit="kg", tip="total mass of a body"),
        Param("stiffness", "Stiffness", "float", 10.0, 20000.0, log=True, unit="N/m", tip="spring constant ks"),
        Param("static_friction", "Static friction", "float", 0.0, 2.0),
        Param("friction", "Friction", "float", 0.0, 2.0),
        Param("explosive_force", "Explosive force", "float", 0.0, 30.0, unit="m/s", tip="the space key"),
    )),
    # the world's material; the model is a drop-down above these rows (see the inspector)
    ("Material", (
        Param("youngs_modulus", "Young's E", "float", 1e2, 1e8, log=True, unit="Pa",
              tip="stiffness of the finite elements: a gel ~1e4, rubber ~1e6"),
        Param("poisson_ratio", "Poisson ratio", "float", 0.0, 0.49,
              tip="how much a stretched body narrows (below 0.5)"),
        Param("density", "Density", "float", 0.1, 1e4, log=True, unit="kg/m²", tip="mass per area"),
        Param("material_damping", "Damping", "float", 0.0, 0.1, unit="s",
              tip="viscous damping of the elements (stiffens the explicit step limit)"),
        # the behaviours of the selected body's material (any model); empty = off
        Param("tear_strain", "Tear strain", "float", 0.02, 2.0, log=True, optional=True,
              tip="the mesh splits where stretched beyond this strain (0.3 = 30%); empty: never tears"),
        Param("yield_strain", "Yield strain", "float", 0.005, 1.0, log=True, optional=True,
              tip="strain beyond this moves the rest shape, so dents stay; empty: elastic"),
        Param("plastic_rate", "Plastic rate", "float", 0.01, 1.0,
              tip="share of the strain beyond yield made permanent per step (1: perfectly plastic)"),
        Param("max_stretch", "Max stretch", "float", 1.01, 3.0, log=True, optional=True,
              tip="no spring or element ends a step longer than this ratio (1.05 = 5%); empty: no limit"),
        Param("pressure", "Pressure", "float", 1.0, 1e4, log=True, unit="N/m", optional=True,
              tip="gas in the selected body's outline (needs a closed outline); empty: no gas"),
    )),
    ("Contact", (
        Param("contact_thickness", "Thickness", "float", 1e-4, 0.05, log=True, unit="m",
              tip="how far apart touching bodies stay"),
        Param("collide", "Collide", "bool", tip="the selected body touches other bodies"),
        Param("self_collision", "Self collision", "bool", tip="the selected body touches itself"),
    )),
    # the selected collider; rows its shape does not have are greyed out (see the inspector)
    ("Collision", (
        Param("collider_x", "Center x", "float", -20, 20, unit="m"),
        Param("collider_y", "Center y", "float", -10, 20, unit="m"),
        Param("collider_angle", "Angle", "float", -90, 90, unit="°", tip="Z / X turn it by 5°"),
        Param("collider_width", "Width", "float", 0.05, 30, log=True, unit="m", tip="rectangles"),
        Param("collider_height", "Height", "float", 0.05, 10, log=True, unit="m", tip="rectangles"),
        Param("collider_radius", "Radius", "float", 0.01, 5, log=True, unit="m",
              tip="circles and segments; type 0 for a segment that is a thin wire"),
        Param("collider_vx", "Velocity x", "float", -5, 5, unit="m/s", tip="the world moves it every step"),
        Param("collider_vy", "Velocity y", "float", -5, 5, unit="m/s", tip="the world moves it every step"),
        Param("collider_angular_velocity", "Spin", "float", -360, 360, unit="°/s",
              tip="angular velocity about its centre, counter-clockwise"),
        Param("collider_friction", "Friction", "float", 0.0, 2.0, optional=True, off_text="world",
              tip="its own dynamic friction; empty: the world's"),
        Param("collider_static_friction", "Static friction", "float", 0.0, 2.0, optional=True, off_text="world",
              tip="its own static friction; empty: the world's"),
    )),
    ("Mouse", (
        Param("mouse_strength", "Mouse strength", "float", 1.0, 2000.0, log=True, unit="N/m",
              tip="pull per held vertex"),
    )),
)

PARAMS: dict[str, Param] = {p.name: p for _, group in GROUPS for p in group}

#: The rows of integrator options are named by this prefix and the option's name:
#: ``integrator_iterations`` is the ``iterations`` of the integrator in force.
INTEGRATOR_PREFIX = "integrator_"


def option_param(option: Option) -> Param:
    """The inspector row of an integrator option
    (:class:`deforma.physics.integrators.base.Option`).

    A choice is a drop-down of its choices; a number has a slider from a hundredth to a
    hundred times its default (log-scaled; linear, from default - 1 to default + 1, for a
    default <= 0), within what the option allows, and a text box that takes anything the
    integrator accepts.

    Examples
    --------
    >>> from deforma.physics.integrators.base import Option
    >>> p = option_param(Option("contact_weight", 10.0, "float", low=0.0, high=1e12))
    >>> p.name, p.label, p.lo, p.hi, p.log
    ('integrator_contact_weight', 'Contact weight', 0.1, 1000.0, True)
    """
    name, label = INTEGRATOR_PREFIX + option.name, option.name.replace("_", " ").capitalize()
    if option.kind == "choice":
        return Param(name, label, "choice", choices=tuple(option.choices), tip=option.doc)
    default = float(option.default)
    if default > 0:
        lo, hi = max(default / 100, option.low), min(default * 100, option.high)
    else:
        lo, hi = max(default - 1, option.low), min(default + 1, option.high)
    return Param(name, label, option.kind, float(lo), float(hi), log=lo > 0, tip=option.doc)


def integrator_params() -> tuple[Param, ...]:
    """The rows of every registered integrator's options, in registry order, one per option
    name: a name several integrators take (``iterations``) is one row, which shows and sets
    the option of the integrator in force (its slider is the first integrator's).

    Examples
    --------
    >>> [p.name for p in integrator_params()][:3]
    ['integrator_mode', 'integrator_iterations', 'integrator_tolerance']
    """
    rows: dict[str, Param] = {}
    for integrator in available_integrators():
        for option in type(make_integrator(integrator)).OPTIONS:
            rows.setdefault(option.name, option_param(option))
    return tuple(rows.values())


def format_value(param: Param, value: Any) -> str:
    """Text for the value box: integers plain, floats with up to 4 significant digits."""
    if value is None:
        return ""
    if param.kind == "int":
        return str(int(value))
    return f"{float(value):.4g}"


def parse_value(param: Param, text: str) -> float | int | None:
    """The number typed in a value box; for an optional parameter, ``None`` (off) when the box
    is empty or says ``off``, ``none`` or its ``off_text``.

    Raises
    ------
    ValueError
        Not a number (or not a whole number for an integer parameter); one line.

    Examples
    --------
    >>> parse_value(PARAMS["stiffness"], " 2.5e3 ")
    2500.0
    >>> parse_value(PARAMS["detail"], "7.5")
    Traceback (most recent call last):
    ...
    ValueError: Detail must be a whole number, got '7.5'
    >>> parse_value(PARAMS["tear_strain"], "") is None
    True
    """
    s = text.strip().replace(",", ".")
    if param.optional and s.lower() in ("", "off", "none", param.off_text):
        return None
    try:
        v = float(s)
    except ValueError:
        raise ValueError(f"{param.label} must be a number, got {text.strip()!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{param.label} must be finite, got {text.strip()!r}")
    if param.kind == "int":
        if not v.is_integer():
            raise ValueError(f"{param.label} must be a whole number, got {text.strip()!r}")
        return int(v)
    return v

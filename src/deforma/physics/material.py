"""Materials: what a body is made of, in SI units.

A :class:`Material` names a constitutive model and its parameters. ``"springs"`` is the
original's mass-spring model (one spring per mesh edge, with the world's or the body's
``stiffness``, ``damping`` and ``mass``). ``"corotated"`` and ``"neo-hookean"`` are finite
elements: every triangle of the mesh is a linear (constant-strain) element of an elastic
sheet with Young's modulus ``E``, Poisson ratio ``nu`` and areal density ``rho``, so the
same object meshed finer is the same object.

Units. The world is 2D: a body is a slab of unit thickness seen from its face.
``youngs_modulus`` is in Pa (N/m^2, i.e. N/m per metre of thickness), ``density`` in
kg/m^2 (mass per area: a body weighs ``density * area``). ``plane`` says what the slab is:
``"stress"`` (the default), a thin sheet free to thin out of its plane, with the Lamé
parameters

    mu = E / (2 (1 + nu)),    lambda = E nu / (1 - nu^2),

so that a strip pulled along its length contracts across by ``nu`` times its stretch; or
``"strain"``, a cross-section of a long body that cannot strain along its length (a dam, a
tunnel lining, a long rubber seal), with

    mu = E / (2 (1 + nu)),    lambda = E nu / ((1 + nu) (1 - 2 nu)),

stiffer the nearer ``nu`` is to 0.5 (its in-plane Poisson ratio is ``nu / (1 - nu)``).

Damping (``damping``, seconds) is stiffness-proportional (Rayleigh, Kelvin-Voigt): a
viscous stress equal to the elastic stress of the strain *rate*, times ``damping``. A
vibration of angular frequency ``omega`` then has damping ratio ``damping * omega / 2``:
fine ripples die at once, the slow sway of the whole body lives on. Rigid motion (moving,
turning) is never damped.

Examples
--------
>>> rubber = Material("neo-hookean", youngs_modulus=1e6, poisson_ratio=0.45, density=1100.0)
>>> mu, lam = rubber.lame()
>>> round(mu), round(lam)
(344828, 564263)
"""

from __future__ import annotations

import math
from dataclasses import KW_ONLY, dataclass
from typing import Any

from .elements.kind import BUILT_IN, registered_models

MODELS = BUILT_IN  # more come from registered element kinds (material_models)
#: What a finite-element body's slab is: a thin sheet or the cross-section of a long body.
PLANES = ("stress", "strain")
# Element kind codes stored per triangle in the Model (springs bodies have no elements).
KIND_COROTATED = 0
KIND_NEO_HOOKEAN = 1
KIND_CODES = {"corotated": KIND_COROTATED, "neo-hookean": KIND_NEO_HOOKEAN}


#: Named materials (:meth:`Material.preset`, ``material = "jelly"`` in scene files): real-world
#: values in SI for a slab of unit thickness (density in kg/m^2 is then the 3D density in
#: kg/m^3). ``damping`` (s) sets how fast a body stops ringing: a mode of angular frequency
#: ``omega`` gets damping ratio ``damping * omega / 2``.
PRESETS: dict[str, dict] = {
    # gelatin dessert: E of a few 10 kPa, nearly incompressible, rings for about a second
    "jelly": dict(model="neo-hookean", youngs_modulus=3e4, poisson_ratio=0.45, density=1050.0, damping=0.005),
    # gummy candy: ten times stiffer than jelly and lossy, so it lands with a thud
    "gummy": dict(model="neo-hookean", youngs_modulus=3e5, poisson_ratio=0.45, density=1200.0, damping=0.02),
    # natural rubber: a few MPa, little loss, bounces
    "rubber": dict(model="neo-hookean", youngs_modulus=2e6, poisson_ratio=0.45, density=1100.0, damping=0.0005),
    # open-cell foam: light, compressible (small Poisson ratio) and strongly damped
    "foam": dict(model="corotated", youngs_modulus=2e4, poisson_ratio=0.1, density=30.0, damping=0.05),
    # softwood across the grain: stiff for its weight; at display steps take an implicit integrator
    "wood": dict(model="corotated", youngs_modulus=1e9, poisson_ratio=0.3, density=600.0, damping=1e-5),
    # a fabric-like sheet: light and soft, its stretch limited to 5%, so a strip hangs and folds
    "cloth": dict(model="corotated", youngs_modulus=100.0, poisson_ratio=0.3, density=0.3, damping=0.02,
                  max_stretch=1.05),
}


def material_models() -> tuple[str, ...]:
    """The material models ``Material`` takes: the built-in ones, then those of the element
    kinds registered with :func:`~deforma.physics.elements.kind.register_element_kind`.

    Examples
    --------
    >>> material_models()[:4]
    ('springs', 'corotated', 'neo-hookean', 'rigid')
    """
    return MODELS + tuple(m for m in registered_models() if m not in MODELS)


def _number(value, name: str) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    except OverflowError:  # an integer beyond any float (10**400)
        raise ValueError(f"{name} must be a finite number, got an integer of {len(str(abs(value)))} digits") from None
    if isinstance(value, bool):
        raise ValueError(f"{name} must be a number, got {value!r}")
    return v


@dataclass(frozen=True)
class Material:
    """A constitutive model with its parameters (immutable; assign a new one to change).

    Parameters
    ----------
    model : {"springs", "corotated", "neo-hookean", "rigid"}
        ``"springs"``: the original's mass-spring model (takes none of the keywords below;
        the body's ``stiffness``, ``damping`` and ``mass`` apply). ``"corotated"``: linear
        elasticity in each triangle's rotated frame (cheapest element, exact for small
        strains at any rotation). ``"neo-hookean"``: stable Neo-Hookean (Smith et al.
        2018), stiffer than corotated in large compression and defined for inverted
        triangles, which it pushes back out. ``"rigid"``: a rigid body of the mesh's shape
        (three degrees of freedom: position and angle, :mod:`deforma.physics.rigid`); it
        takes ``density`` only.
    youngs_modulus : float
        E in Pa (> 0, finite). Rubber ~1e6, a soft gel ~1e4.
    poisson_ratio : float
        nu in (-1, 0.5): how much a stretched sheet narrows (0.5 would be incompressible).
    density : float
        kg/m^2 (> 0, finite): mass per area of the sheet.
    damping : float, optional
        Stiffness-proportional viscous damping in seconds (>= 0, finite; default 0): a mode
        of angular frequency ``omega`` gets damping ratio ``damping * omega / 2``.
    tear_strain : float, optional
        Tearing (any model; the body needs triangles): where the material is stretched by
        more than this strain (0.5 = 50% longer) across a mesh edge, the mesh splits along
        that edge (:mod:`deforma.physics.behaviours.tearing`). A springs body without triangles snaps
        the spring instead. ``None`` (default): never tears. In (0, 100].
    yield_strain : float, optional
        Plasticity: strain beyond this in any direction moves the rest shape, so dents stay
        (:mod:`deforma.physics.behaviours.plasticity`). ``None`` (default): elastic. In (0, 100].
    plastic_rate : float, optional
        Share of the strain beyond ``yield_strain`` that becomes permanent at each step, in
        (0, 1]; 1 (default) is perfectly plastic (independent of the step), smaller values
        let the rest shape creep after the deformation over several steps.
    max_stretch : float, optional
        Strain limit: no spring or element ends a step stretched beyond this ratio of its
        rest length in any direction (1.05 = at most 5% longer), however hard it is pulled
        (:mod:`deforma.physics.behaviours.strain_limit`). ``None`` (default): no limit. In (1, 100].
    plane : {"stress", "strain"}, optional
        Finite elements: a thin sheet (``"stress"``, default) or the cross-section of a long
        body (``"strain"``); see the module docstring for the Lamé parameters of each.

    Raises
    ------
    ValueError
        Unknown model, a missing or out-of-range parameter, or FEM keywords given to
        ``"springs"``; the message names the value and the allowed range.

    Examples
    --------
    >>> Material("corotated", youngs_modulus=1e5, poisson_ratio=0.3, density=100.0).is_fem
    True
    >>> Material("springs").is_fem
    False
    >>> Material("springs", max_stretch=1.1).max_stretch  # behaviours work for springs too
    1.1
    """

    model: str
    _: KW_ONLY
    youngs_modulus: float | None = None
    poisson_ratio: float | None = None
    density: float | None = None
    damping: float = 0.0
    tear_strain: float | None = None
    yield_strain: float | None = None
    plastic_rate: float = 1.0
    max_stretch: float | None = None
    plane: str = "stress"

    def __post_init__(self):
        models = material_models()
        if self.model not in models:
            raise ValueError(f"material model must be one of {', '.join(repr(m) for m in models)}, "
                             f"got {self.model!r}")
        self._check_behaviours()
        given = [k for k in ("youngs_modulus", "poisson_ratio", "density") if getattr(self, k) is not None]
        if not (isinstance(self.plane, str) and self.plane in PLANES):
            raise ValueError(f"plane must be 'stress' or 'strain', got {self.plane!r}")
        if self.model == "springs":
            if given or self.damping != 0.0 or self.plane != "stress":
                extra = ", ".join(given + (["damping"] if self.damping != 0.0 else [])
                                  + (["plane"] if self.plane != "stress" else []))
                raise ValueError(f"the 'springs' material takes no {extra}: its springs use the body's "
                                 f"stiffness (N/m), damping (N*s/m) and mass (kg)")
            return
        if self.model == "rigid":
            extra = [k for k in ("youngs_modulus", "poisson_ratio") if getattr(self, k) is not None]
            extra += [k for k in ("tear_strain", "yield_strain", "max_stretch") if getattr(self, k) is not None]
            extra += (["damping"] if self.damping != 0.0 else []) + (["plane"] if self.plane != "stress" else [])
            if extra:
                raise ValueError(f"the 'rigid' material takes density only, not {', '.join(extra)}: a rigid body "
                                 f"does not deform")
            if self.density is None:
                raise ValueError("the 'rigid' material needs density (kg/m^2): the body weighs density * area")
            rho = _number(self.density, "density")
            if not (math.isfinite(rho) and 0.0 < rho <= 1e12):
                raise ValueError(f"density must be in (0, 1e12] kg/m^2, got {self.density!r}")
            object.__setattr__(self, "density", rho)
            return
        missing = [k for k in ("youngs_modulus", "poisson_ratio", "density") if getattr(self, k) is None]
        if missing:
            raise ValueError(f"the {self.model!r} material needs {', '.join(missing)} "
                             f"(E in Pa, nu in (-1, 0.5), density in kg/m^2)")
        e = _number(self.youngs_modulus, "youngs_modulus")
        nu = _number(self.poisson_ratio, "poisson_ratio")
        rho = _number(self.density, "density")
        d = _number(self.damping, "damping")
        if not (math.isfinite(e) and 0.0 < e <= 1e15):
            raise ValueError(f"youngs_modulus must be in (0, 1e15] Pa, got {self.youngs_modulus!r}")
        if not (math.isfinite(nu) and -1.0 < nu < 0.5):
            raise ValueError(f"poisson_ratio must be in (-1, 0.5), got {self.poisson_ratio!r}")
        if not (math.isfinite(rho) and 0.0 < rho <= 1e12):
            raise ValueError(f"density must be in (0, 1e12] kg/m^2, got {self.density!r}")
        if not (math.isfinite(d) and 0.0 <= d <= 1e6):
            raise ValueError(f"damping must be in [0, 1e6] s, got {self.damping!r}")
        object.__setattr__(self, "youngs_modulus", e)
        object.__setattr__(self, "poisson_ratio", nu)
        object.__setattr__(self, "density", rho)
        object.__setattr__(self, "damping", d)

    @classmethod
    def preset(cls, name: str, **overrides: Any) -> "Material":
        """A named material with real-world parameters (SI; see :data:`PRESETS`), any of them
        replaced by ``overrides`` (the keywords of :class:`Material`).

        The look of a body under gravity depends on its size as well as its material: a
        block of height ``H`` sags by about ``density * g * H / (2 E)`` and rings at about
        ``wave_speed() / (2 H)``. ``docs/physics.md`` ("Material presets") gives each
        preset's sag, bounce and wobble measured on a 0.5 m block.

        Parameters
        ----------
        name : str
            One of ``jelly``, ``gummy``, ``rubber``, ``foam``, ``wood``, ``cloth``.
        **overrides
            Keywords of :class:`Material` that replace the preset's (``model`` too).

        Raises
        ------
        ValueError
            An unknown name (with the closest one), an unknown keyword, or a value the
            Material refuses; one line.

        Examples
        --------
        >>> Material.preset("rubber").youngs_modulus
        2000000.0
        >>> Material.preset("jelly", density=500.0).density
        500.0
        >>> Material.preset("jely")
        Traceback (most recent call last):
        ...
        ValueError: unknown material preset 'jely': did you mean 'jelly'? (presets: jelly, gummy, rubber, foam, wood, cloth)
        """
        import difflib
        from dataclasses import fields

        if not isinstance(name, str) or name not in PRESETS:
            close = difflib.get_close_matches(name, list(PRESETS), n=1) if isinstance(name, str) else []
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise ValueError(f"unknown material preset {name!r}: {hint}(presets: {', '.join(PRESETS)})")
        allowed = [f.name for f in fields(cls) if f.name != "_"]
        unknown = [k for k in overrides if k not in allowed]
        if unknown:
            close = difflib.get_close_matches(unknown[0], allowed, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise ValueError(f"Material.preset({name!r}) takes no {unknown[0]!r}: {hint}(keywords: "
                             f"{', '.join(allowed)})")
        return cls(**{**PRESETS[name], **overrides})

    def _check_behaviours(self) -> None:
        for name in ("tear_strain", "yield_strain"):
            value = getattr(self, name)
            if value is not None:
                v = _number(value, name)
                if not (math.isfinite(v) and 0.0 < v <= 100.0):
                    raise ValueError(f"{name} must be a strain in (0, 100] (0.5 = 50% stretch) or None, got {value!r}")
                object.__setattr__(self, name, v)
        r = _number(self.plastic_rate, "plastic_rate")
        if not (math.isfinite(r) and 0.0 < r <= 1.0):
            raise ValueError(f"plastic_rate must be in (0, 1] (1 = perfectly plastic), got {self.plastic_rate!r}")
        object.__setattr__(self, "plastic_rate", r)
        if self.max_stretch is not None:
            m = _number(self.max_stretch, "max_stretch")
            if not (math.isfinite(m) and 1.0 < m <= 100.0):
                raise ValueError(f"max_stretch must be a stretch ratio in (1, 100] (1.05 = at most 5% longer) "
                                 f"or None, got {self.max_stretch!r}")
            object.__setattr__(self, "max_stretch", m)

    @property
    def has_behaviours(self) -> bool:
        """True if the material tears, yields or limits its stretch."""
        return self.tear_strain is not None or self.yield_strain is not None or self.max_stretch is not None

    @property
    def is_fem(self) -> bool:
        """True for the finite-element models (``"corotated"``, ``"neo-hookean"``, and those of
        registered element kinds) and ``"rigid"``: the body weighs ``density * area``."""
        return self.model != "springs"

    @property
    def is_rigid(self) -> bool:
        """True for ``"rigid"``: the body keeps its shape and moves as one."""
        return self.model == "rigid"

    @property
    def kind(self) -> int:
        """The element kind code the kernels read (``KIND_COROTATED`` / ``KIND_NEO_HOOKEAN``)."""
        if self.model not in KIND_CODES:
            raise ValueError(f"the {self.model!r} material has no triangle elements of a built-in kind")
        return KIND_CODES[self.model]

    def lame(self) -> tuple[float, float]:
        """Lamé parameters ``(mu, lambda)`` in Pa, of plane stress or plane strain (``plane``).

        Examples
        --------
        >>> Material("corotated", youngs_modulus=2.6, poisson_ratio=0.3, density=1.0).lame()
        (1.0, 0.8571428571428571)
        >>> Material("corotated", youngs_modulus=2.6, poisson_ratio=0.3, density=1.0, plane="strain").lame()
        (1.0, 1.5)
        """
        if not self.is_fem or self.is_rigid:
            raise ValueError(f"the {self.model!r} material has no Lamé parameters")
        e, nu = self.youngs_modulus, self.poisson_ratio
        assert e is not None and nu is not None  # set for every FEM model (__post_init__)
        if self.plane == "strain":
            return e / (2.0 * (1.0 + nu)), e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
        return e / (2.0 * (1.0 + nu)), e * nu / (1.0 - nu * nu)

    def wave_speed(self) -> float:
        """Speed of the fastest (dilatational) wave in the sheet, m/s: ``sqrt((lambda + 2 mu) / rho)``."""
        mu, lam = self.lame()
        return math.sqrt((lam + 2.0 * mu) / self.density)  # type: ignore[operator]  # lame() checked the model

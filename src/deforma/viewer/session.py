"""What the viewer edits, without any window: the world, its scene and the inspector's values.

A :class:`Session` owns the live :class:`deforma.World` and knows how it was made (through
``deforma.scene.scene_of``), so that

- physics values are set on the running world at once;
- mesh values (the original's Square and Texture settings and "Selected") rebuild the world
  from its current scene with the edited body's recipe replaced: the bodies start again from
  their starting positions, every other setting is kept;
- the world's material (springs or finite elements, with E, nu, density, damping) is
  switched on the running world, raising substeps where the explicit integrator needs it;
- the integrator is switched, and its options (``integrator_iterations``, ...) set, on the
  running world;
- the selected body's material behaviours (tearing, plasticity, stretch limit) and its gas
  pressure are set on the running world;
- vertices are pinned and unpinned where the pointer is;
- colliders are added, removed and edited in place;
- :meth:`Session.save` writes a scene file that ``deforma run`` renders the same way.

Everything here is testable without pygame; :mod:`deforma.viewer.app` only forwards input.
"""

from __future__ import annotations

import copy
import math
import os
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any, TypedDict

import numpy as np
from numpy.typing import ArrayLike

from ..checks import IgnoredSettingWarning
from ..physics import Body, Circle, Collider, Material, Polygon, Rect, Segment, available_integrators
from ..physics.diagnostics import xpbd_advice
from ..physics.integrators.base import unknown_option
from ..physics.joint import Joint
from ..scene import BoxBody, ImageBody, MeshBody, Scene, SceneError, build, load, scene_of
from ..scene.assets import builtin_textures
from ..scene.construct import pin_mask
from ..physics.material import material_models
from ..physics.topology import triangles_under
from ..scene.tables import MATERIAL_MODELS, BodyPhysics, PhysicsSettings
from .params import INTEGRATOR_PREFIX, integrator_params

#: A ``[[body]]`` of a scene, as ``Scene.body`` holds them.
BodySpec = BoxBody | ImageBody | MeshBody

def _builtin_texture_names() -> tuple:
    """The built-in textures the Selected menu offers, in the original's order where it has them
    (bunny, donut, armadillo), any others after them."""
    from ..mesh.image import builtin_textures as textures

    names = list(textures())
    first = [n for n in ("bunny", "donut", "armadillo") if n in names]
    return tuple(first + sorted(n for n in names if n not in first))


__all__ = ["BEHAVIOURS", "COLLIDER_FIELDS", "COLLIDER_SHAPES", "MATERIAL_DEFAULTS", "MATERIAL_MODELS", "MESH_LIMITS",
           "OBJECTS", "MeshSettings", "Session"]

#: What a finite-element model starts with when the scene gives no value: a soft gel of
#: 1 kg/m^2 (a 1.5 m box weighs 2.25 kg), undamped: stiffness-proportional damping shrinks
#: symplectic Euler's stable step with the square of the finest element's frequency (0.01 s
#: made the demo's bunny need ~65000 substeps instead of 74), so it is a choice, not a
#: default. E in Pa, density in kg/m^2, damping in s.
MATERIAL_DEFAULTS = {"youngs_modulus": 1e4, "poisson_ratio": 0.3, "density": 1.0, "material_damping": 0.0}
# the inspector's material names and the Material keywords they set
_MATERIAL_KEYWORD = {"youngs_modulus": "youngs_modulus", "poisson_ratio": "poisson_ratio", "density": "density",
                     "material_damping": "damping"}
#: The material behaviours the inspector edits (``deforma.Material`` keywords of the same
#: names; every model has them). None of the three strains means "off".
BEHAVIOURS = ("tear_strain", "yield_strain", "plastic_rate", "max_stretch")
_SPRINGS = Material("springs")  # what a world without a material (None) is made of

#: The original's "Selected" choices, in the order of the number keys 1-4.
OBJECTS = (*_builtin_texture_names(), "box")

#: The collider shapes the inspector adds, in the order of its menu, and their classes.
COLLIDER_SHAPES = ("rect", "circle", "polygon", "segment")
_SHAPE_CLASSES = {"rect": Rect, "circle": Circle, "polygon": Polygon, "segment": Segment}
#: A new polygon: a small cup (1.2 m wide, 0.6 m high, walls 0.1 m), concave on purpose, so
#: that it can hold something; its centroid goes where it is added.
CUP = ((-0.6, -0.3), (0.6, -0.3), (0.6, 0.3), (0.5, 0.3), (0.5, -0.2), (-0.5, -0.2), (-0.5, 0.3), (-0.6, 0.3))
#: The collider values the inspector edits: name -> (attribute, component or None, the shapes
#: that have it). Angles in degrees, angular velocity in degrees/s; a friction of None
#: follows the world's.
COLLIDER_FIELDS = {
    "collider_x": ("center", 0, COLLIDER_SHAPES),
    "collider_y": ("center", 1, COLLIDER_SHAPES),
    "collider_angle": ("angle", None, COLLIDER_SHAPES),
    "collider_width": ("size", 0, ("rect",)),
    "collider_height": ("size", 1, ("rect",)),
    "collider_radius": ("radius", None, ("circle", "segment")),
    "collider_vx": ("velocity", 0, COLLIDER_SHAPES),
    "collider_vy": ("velocity", 1, COLLIDER_SHAPES),
    "collider_angular_velocity": ("angular_velocity", None, COLLIDER_SHAPES),
    "collider_friction": ("friction", None, COLLIDER_SHAPES),
    "collider_static_friction": ("static_friction", None, COLLIDER_SHAPES),
}


def collider_shape_name(c: Collider) -> str:
    """``rect``, ``circle``, ``polygon`` or ``segment``: what the inspector calls a collider's shape."""
    for name, cls in _SHAPE_CLASSES.items():
        if isinstance(c, cls):
            return name
    raise ValueError(f"colliders must be deforma.Rect, Circle, Polygon or Segment, found {type(c).__name__}")


def _boundary_distance(c: Collider, point: np.ndarray) -> float:
    """Metres from ``point`` to the nearest edge of a collider's boundary (its holes' too);
    a wire's boundary is the wire."""
    loops = c.loops if isinstance(c, Polygon) else [c.outline()]
    a = np.concatenate([p if len(p) > 2 else p[:1] for p in loops])
    b = np.concatenate([np.roll(p, -1, axis=0) if len(p) > 2 else p[1:] for p in loops])
    d = b - a
    t = np.clip(np.einsum("ij,ij->i", point - a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    return float(np.hypot(*(a + t[:, None] * d - point).T).min())


#: Ranges the inspector accepts for mesh values. Tighter than the scene schema on purpose:
#: a live window must rebuild in a fraction of a second and still run at 60 frames/s, and
#: detail 100 or resolution 3 already give about ten thousand points (``deforma run`` takes
#: the schema's full range).
MESH_LIMITS = {"detail": (0, 100), "resolution": (3, 64), "edge_step": (1, 64), "scale": (1e-4, 0.1)}

# Used when a body switches kind and has no value of the other kind yet: a 1.5 m object
# either way, with a few hundred to a thousand points.
class _ImageDefaults(TypedDict):
    resolution: int
    detect_edges: bool
    edge_step: int
    scale: float


_IMAGE_DEFAULTS: _ImageDefaults = {"resolution": 10, "detect_edges": True, "edge_step": 5, "scale": 0.004}
_BOX_HALF = 0.75
#: Substeps a mesh change may raise on its own (beyond, the unstable hint explains what to do).
MAX_AUTO_SUBSTEPS = 64


@dataclass(frozen=True)
class MeshSettings:
    """The inspector's mesh values of one body (both kinds, so switching back keeps them)."""

    selected: str = "box"
    detail: int = 8
    edges: bool = True
    corners: tuple = ((-_BOX_HALF, -_BOX_HALF), (_BOX_HALF, -_BOX_HALF), (_BOX_HALF, _BOX_HALF),
                      (-_BOX_HALF, _BOX_HALF))
    resolution: int = _IMAGE_DEFAULTS["resolution"]
    detect_edges: bool = _IMAGE_DEFAULTS["detect_edges"]
    edge_step: int = _IMAGE_DEFAULTS["edge_step"]
    scale: float = _IMAGE_DEFAULTS["scale"]

    @classmethod
    def from_spec(cls, spec: BodySpec | None) -> MeshSettings:
        """The settings a body spec implies; ``selected`` is the texture name, ``box`` or ``mesh``."""
        if isinstance(spec, BoxBody):
            return cls(selected="box", detail=spec.detail, edges=spec.edges, corners=spec.corners)
        if isinstance(spec, ImageBody):
            name = spec.source if spec.source in builtin_textures() else Path(spec.source).stem
            return cls(selected=name, resolution=spec.resolution, detect_edges=spec.detect_edges,
                       edge_step=spec.edge_step, scale=spec.scale)
        return cls(selected="mesh")


def _check_int(value: Any, name: str) -> int:
    lo, hi = MESH_LIMITS[name]
    if isinstance(value, bool) or not float(value).is_integer():
        raise ValueError(f"{name} must be a whole number in [{lo}, {hi}], got {value!r}")
    v = int(value)
    if not lo <= v <= hi:
        raise ValueError(f"{name} must be in [{lo}, {hi}] in the viewer, got {v}")
    return v


#: Degrees/s the arrow keys drive a motor at whose own speed is zero (:meth:`Session.drive`).
DRIVE_SPEED = 300.0


class Session:
    """The live world, the scene it came from, and the inspector's selection.

    Parameters
    ----------
    scene : deforma.scene.Scene or str
        A scene, a built-in scene name or a ``.toml`` path.

    Examples
    --------
    >>> s = Session("demo")
    >>> s.set_param("stiffness", 3000.0); s.world.stiffness
    3000.0
    >>> s.select_object("box"); s.mesh.selected, type(s.body_spec).__name__
    ('box', 'BoxBody')
    >>> s.set_param("detail", 1000)
    Traceback (most recent call last):
    ...
    ValueError: detail must be in [0, 100] in the viewer, got 1000
    """

    def __init__(self, scene: Scene | str | os.PathLike[str]) -> None:
        if not isinstance(scene, Scene):
            scene = load(scene)
        self.world = build(scene)
        self._drive_speeds: dict[int, float] = {}  # a motor's speed when first driven (drive)
        self.explosive_force = float(scene.interaction.explosive_force)
        self.camera_center = tuple(scene.camera.center)
        self.camera_size = tuple(scene.camera.size)
        #: The body the camera keeps in the middle (its index, ``[camera] follow``); None once
        #: the view is panned.
        self.follow = scene.camera.follow
        self.wireframe = bool(scene.camera.wireframe)
        # one colour per collider of the world (an image collider is several polygons)
        self.collider_colors = [c.color for c in scene_of(self.world).collider]
        self.collider_index = 0 if self.world.colliders else None
        #: True once a collider was picked, added or edited: the window then highlights it.
        self.collider_active = False
        self.body_index = 0
        self.mesh = MeshSettings.from_spec(scene.body[0]) if scene.body else MeshSettings()
        #: Bumped on every rebuild, so a window knows to re-upload meshes.
        self.generation = 0
        #: A remark about the last change (e.g. substeps raised), for the panel to show.
        self.note = ""
        #: True when :attr:`note` warns of trouble ahead (shown in red).
        self.note_is_warning = False
        self._xpbd_note()  # a scene run under XPBD with too few substeps: say so from the start
        #: E, nu, density and damping of the finite-element models: the world's while it has
        #: one; kept while it is springs, so switching back restores them.
        self.material_values = self._initial_material_values(scene.physics)
        # the option rows there are, read once: the registry is not walked for every frame's read
        self._option_rows = tuple(p.name for p in integrator_params())

    def _initial_material_values(self, physics: PhysicsSettings) -> dict[str, float]:
        m = self.world.material
        if m is not None and m.is_fem:
            return {name: float(getattr(m, kw)) for name, kw in _MATERIAL_KEYWORD.items()}
        # a springs world whose scene holds finite-element defaults for its bodies starts from them
        values = dict(MATERIAL_DEFAULTS)
        given = {k: getattr(physics, k) for k in ("youngs_modulus", "poisson_ratio", "density")}
        values.update((k, float(v)) for k, v in given.items() if v is not None)
        if any(v is not None for v in given.values()):
            values["material_damping"] = float(physics.material_damping)
        return values

    def follow_camera(self) -> None:
        """Put the camera's centre on the followed body's centre of mass (:attr:`follow`; a
        body index no longer in the world follows nothing).

        Examples
        --------
        >>> s = Session("car")
        >>> s.follow_camera(); s.camera_center == tuple(s.world.bodies[s.follow].center_of_mass)
        True
        """
        if self.follow is not None and self.follow < len(self.world.bodies):
            self.camera_center = tuple(map(float, self.world.bodies[self.follow].center_of_mass))

    # -- what the inspector reads --------------------------------------------------------------
    @property
    def scene(self) -> Scene:
        """The current setup as a scene (starting positions, current parameters, camera, colliders)."""
        s = scene_of(self.world)
        colliders = tuple(replace(c, color=self.collider_colors[i] if i < len(self.collider_colors) else None)
                          for i, c in enumerate(s.collider))
        camera = replace(s.camera, center=tuple(map(float, self.camera_center)),
                         size=tuple(map(float, self.camera_size)), wireframe=bool(self.wireframe), follow=self.follow)
        return replace(s, collider=colliders, camera=camera,
                       interaction=replace(s.interaction, explosive_force=float(self.explosive_force)))

    @property
    def body_spec(self) -> BodySpec | None:
        """The scene spec of the body the mesh values edit (None without bodies)."""
        bodies = scene_of(self.world).body
        return bodies[self.body_index] if bodies else None

    @property
    def collider(self) -> Collider | None:
        """The collider the inspector edits (a Rect, Circle, Polygon or Segment), or None."""
        if self.collider_index is None:
            return None
        return self.world.colliders[self.collider_index]

    # -- parameters ----------------------------------------------------------------------------
    def get_param(self, name: str) -> Any:
        """Current value of an inspector parameter by name (see :data:`deforma.viewer.params.PARAMS`)."""
        w = self.world
        if name in ("gravity_x", "gravity_y"):
            return w.gravity[0 if name == "gravity_x" else 1]
        if name in ("dt", "substeps", "damping", "mass", "stiffness", "friction", "static_friction", "air_drag",
                    "sleep"):
            return getattr(w, name)
        if name == "contact_thickness":  # the world's, or the selected body's automatic one
            if w.contact_thickness is not None or not w.bodies:
                return w.contact_thickness
            return w.bodies[self.body_index].contact_thickness
        if name in ("collide", "self_collision"):
            return getattr(w.bodies[self.body_index], name) if w.bodies else None
        if name == "explosive_force":
            return self.explosive_force
        if name in _MATERIAL_KEYWORD:
            return self.material_values[name]
        if name in BEHAVIOURS:
            m = w.bodies[self.body_index].material if w.bodies else (w.material or _SPRINGS)
            return getattr(m, name)
        if name == "pressure":
            return w.bodies[self.body_index].pressure if w.bodies else None
        if name == "mouse_strength":
            return w.grab_strength
        if name in ("detail", "edges", "resolution", "detect_edges", "edge_step", "scale"):
            return getattr(self.mesh, name)
        if name in COLLIDER_FIELDS:
            c = self.collider
            attr, part, shapes = COLLIDER_FIELDS[name]
            if c is None or collider_shape_name(c) not in shapes:
                return None
            value = getattr(c, attr)
            return value if part is None else value[part]
        if name in self._option_rows:  # None: an option the integrator in force does not take
            return w.integrator_options.get(name.removeprefix(INTEGRATOR_PREFIX))
        raise KeyError(f"unknown parameter {name!r}")

    def set_param(self, name: str, value: Any) -> None:
        """Set an inspector parameter; physics applies at once, mesh values rebuild the body.

        Raises
        ------
        ValueError
            One line naming the parameter and what is allowed; nothing changes then.
        """
        w = self.world
        self.note, self.note_is_warning = "", False
        if name in ("gravity_x", "gravity_y"):
            g = list(w.gravity)
            g[0 if name == "gravity_x" else 1] = value
            w.gravity = g
        elif name == "substeps":
            if isinstance(value, float) and value.is_integer():
                value = int(value)
            w.substeps = value
        elif name in ("dt", "damping", "mass", "stiffness", "friction", "static_friction", "air_drag",
                      "contact_thickness"):
            with warnings.catch_warnings(record=True) as said:  # a spring value finite elements ignore:
                warnings.simplefilter("always", IgnoredSettingWarning)  # the panel says so
                setattr(w, name, value)
            for warning in said:
                if issubclass(warning.category, IgnoredSettingWarning):
                    self.note, self.note_is_warning = str(warning.message), True
                else:
                    warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
        elif name == "sleep":
            w.sleep = bool(value)
        elif name in ("collide", "self_collision"):
            if w.bodies:
                setattr(w.bodies[self.body_index], name, bool(value))
        elif name == "explosive_force":
            v = float(value)
            if not (np.isfinite(v) and v >= 0):
                raise ValueError(f"explosive_force must be a finite number >= 0 m/s, got {value!r}")
            self.explosive_force = v
        elif name == "mouse_strength":
            w.grab_strength = value
        elif name in _MATERIAL_KEYWORD:
            self._set_material_value(name, value)
        elif name in BEHAVIOURS:
            self._set_behaviour(name, value)
        elif name == "pressure":
            if not w.bodies:
                raise ValueError("the scene has no body to fill with gas")
            if isinstance(value, bool):
                raise ValueError(f"pressure must be a number in N/m or None, got {value!r}")
            # the body checks it (>= 0, finite, a closed outline) and changes nothing if not
            w.bodies[self.body_index].pressure = value
        elif name in ("detail", "resolution", "edge_step"):
            self._set_mesh(**{name: _check_int(value, name)})
        elif name in ("edges", "detect_edges"):
            self._set_mesh(**{name: bool(value)})
        elif name == "scale":
            lo, hi = MESH_LIMITS["scale"]
            v = float(value)
            if not lo <= v <= hi:
                raise ValueError(f"scale must be in [{lo:g}, {hi:g}] m/px in the viewer, got {value!r}")
            self._set_mesh(scale=v)
        elif name in COLLIDER_FIELDS:
            self._edit_collider(name, value)
        elif name in self._option_rows:
            self.set_integrator_option(name.removeprefix(INTEGRATOR_PREFIX), value)
        else:
            raise KeyError(f"unknown parameter {name!r}")
        if name in ("substeps", "dt", "gravity_x", "gravity_y"):
            self._xpbd_note()  # what XPBD needs follows the substep and gravity

    # -- material -----------------------------------------------------------------------------
    @property
    def material_model(self) -> str:
        """The world's material model: ``"springs"``, ``"corotated"`` or ``"neo-hookean"``."""
        m = self.world.material
        return "springs" if m is None else m.model

    def _material(self, model: str, values: dict[str, float]) -> Material | None:
        # a new model or elastic value keeps the world's behaviours (tearing, ...)
        if model == "springs":
            material = Material("springs", **self._world_behaviours())
            return None if material == _SPRINGS else material  # the seed's plain springs
        if model == "rigid":  # density alone: a rigid body does not deform, tear or yield
            return Material("rigid", density=values["density"])
        plane = getattr(self.world.material, "plane", "stress")  # kept, as the behaviours are
        return Material(model, **{kw: values[name] for name, kw in _MATERIAL_KEYWORD.items()}, plane=plane,
                        **self._world_behaviours())

    def _world_behaviours(self) -> dict[str, Any]:
        return {k: getattr(self.world.material or _SPRINGS, k) for k in BEHAVIOURS}

    def set_material(self, model: str) -> None:
        """Make the world's bodies (those without a material of their own) ``model``.

        A finite-element model takes :attr:`material_values` (the scene's, or
        :data:`MATERIAL_DEFAULTS`). Under the explicit integrator, substeps are raised to what
        the new material needs, as after a mesh change; beyond what the viewer raises on its
        own, :attr:`note` says what to do instead.

        Raises
        ------
        ValueError
            An unknown model, or a body that cannot be made of elements (a chain of springs
            without triangles); one line, and nothing changes.
        """
        models = material_models()  # a registered element kind's model too
        if model not in models:
            raise ValueError(f"material model must be one of {', '.join(models)}, got {model!r}")
        self.note, self.note_is_warning = "", False
        material = self._material(model, self.material_values)
        self.world.material = material  # refuses (changing nothing) a body without triangles
        self._keep_stable(f"the {model} material")

    def _set_material_value(self, name: str, value: Any) -> None:
        if isinstance(value, bool):
            raise ValueError(f"{name} must be a number, got {value!r}")
        values = dict(self.material_values)
        try:
            values[name] = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be a number, got {value!r}") from None
        model = self.material_model
        # checked by the Material itself (ranges and units in its message), also while springs
        kept = model == "springs" or (model == "rigid" and name != "density")
        material = self._material("corotated" if kept else model, values)
        if kept:
            self.note = f"{name} is kept for when the model is corotated or neo-hookean"
        else:
            self.world.material = material
            self._keep_stable(f"the {model} material")
        self.material_values = values

    def _follows_world(self, body: Body) -> bool:
        """True if ``body`` has no material of its own (it is made of the world's)."""
        m, wm = body.material, self.world.material
        # a body following a world without a material gets a fresh Material("springs")
        return m is wm if wm is not None else m == _SPRINGS

    def _set_behaviour(self, name: str, value: Any) -> None:
        """Set tear_strain, yield_strain, plastic_rate or max_stretch of the selected body's
        material: the world's when the body follows it (then every body following the world
        gets it), else the body's own; state is kept."""
        if isinstance(value, bool):
            raise ValueError(f"{name} must be a number, got {value!r}")
        w = self.world
        body = w.bodies[self.body_index] if w.bodies else None
        if body is not None and not self._follows_world(body):
            body.material = replace(body.material, **{name: value})  # the Material checks it
            return
        new = replace(w.material or _SPRINGS, **{name: value})  # refuses a bad value, changing nothing
        w.material = None if new == _SPRINGS else new
        if body is not None and getattr(body.material, name) != getattr(new, name):
            # a body whose own material equals the world's plain springs: it is what was meant
            body.material = replace(body.material, **{name: value})

    # -- pins ---------------------------------------------------------------------------------
    def vertex_at(self, point: ArrayLike, *, radius: float = 0.0) -> tuple[int, int] | None:
        """``(body index, vertex index)`` of the vertex nearest ``point`` on the body under it.

        The body under the point is the topmost (last added) one with a triangle containing
        it; failing that (the point just off an outline, or a chain without triangles), the
        nearest vertex of any body within ``radius`` metres. None if there is neither.
        """
        p = np.asarray(point, dtype=np.float64)
        bodies = self.world.bodies
        for k in range(len(bodies) - 1, -1, -1):
            x, t = bodies[k].positions, bodies[k].triangles
            if not len(t):
                continue
            if triangles_under(x, t, p).any():
                return k, int(np.argmin(np.linalg.norm(x - p, axis=1)))
        best = None
        for k, body in enumerate(bodies):
            d = np.linalg.norm(body.positions - p, axis=1)
            i = int(np.argmin(d)) if len(d) else -1
            if i >= 0 and d[i] <= radius and (best is None or d[i] <= best[0]):
                best = (float(d[i]), k, i)
        return None if best is None else (best[1], best[2])

    def drive(self, direction: int) -> str:
        """The arrow keys: every motor of the world forward (``direction`` 1: clockwise, which
        rolls a wheel on the ground to the right), back (-1) or braked (0, held at no spin
        relative to what it is joined to), at the speed it had when first driven (or
        :data:`DRIVE_SPEED`). Returns what the status line says.

        Examples
        --------
        >>> s = Session("car")
        >>> s.drive(-1)
        'driving back: 2 motors at 300 degrees/s'
        >>> [j.motor_speed for j in s.world.joints if j.motor_speed is not None]
        [300.0, 300.0]
        """
        motors = [j for j in self.world.joints if j.motor_speed is not None]
        if not motors:
            return "no motor to drive: join a wheel with motor_speed (docs/physics.md, Joints)"
        speeds = set()
        for j in motors:
            base = self._drive_speeds.setdefault(id(j), abs(j.motor_speed) or DRIVE_SPEED)
            j.motor_speed = -direction * base
            speeds.add(base)
        what = {1: "driving forward", -1: "driving back", 0: "braking"}[direction]
        return f"{what}: {len(motors)} motor{'s' if len(motors) > 1 else ''} at " + (
            "no spin" if direction == 0 else f"{'/'.join(f'{v:g}' for v in sorted(speeds))} degrees/s")

    def toggle_pin(self, point: ArrayLike, *, radius: float = 0.0) -> tuple[int, int, bool] | None:
        """Pin the vertex nearest ``point`` (metres) on the body under it, or free it if pinned.

        Returns
        -------
        (int, int, bool) or None
            Body index, vertex index and whether it is pinned now; None if no body is there.
        """
        hit = self.vertex_at(point, radius=radius)
        if hit is None:
            return None
        k, i = hit
        body = self.world.bodies[k]
        if body.pinned[i]:
            body.unpin([i])
        else:
            body.pin([i])
        return k, i, bool(body.pinned[i])

    def join(self, first: Sequence[float], second: ArrayLike) -> Joint:
        """Hinge the body under ``first`` (metres) at that point to the body under ``second``,
        or to the world when ``second`` is on no body or on the same one: the J key and two
        clicks. Returns the :class:`deforma.Joint`.

        Raises
        ------
        ValueError
            No body under ``first``, or what ``World.join`` refuses (a soft body, ...); one
            line, nothing changed.
        """
        hit = self.vertex_at(first)
        if hit is None:
            raise ValueError("no body under the first click: click a rigid body where the hinge goes")
        a = self.world.bodies[hit[0]]
        other = self.vertex_at(second)
        b = None if other is None or other[0] == hit[0] else self.world.bodies[other[0]]
        return self.world.join(a, b, at=(float(first[0]), float(first[1])))

    def unpin_all(self) -> int:
        """Free every pinned vertex of every body; returns how many were pinned."""
        n = 0
        for body in self.world.bodies:
            n += int(body.pinned.sum())
            body.unpin()
        return n

    # -- integrator ---------------------------------------------------------------------------
    @property
    def integrator(self) -> str:
        """Name of the running world's time integrator."""
        return self.world.integrator

    def set_integrator(self, name: str) -> None:
        """Switch the running world to another integrator (state and every value kept).

        Raises
        ------
        ValueError
            ``name`` is not in ``deforma.physics.available_integrators()``; one line.
        """
        names = available_integrators()
        if name not in names:
            raise ValueError(f"integrator must be one of {', '.join(names)}, got {name!r}")
        self.world.integrator = name
        self.note, self.note_is_warning = "", False
        self._xpbd_note()
        stable = self.world.stable_dt()
        h = self.world.dt / self.world.substeps
        if h > stable:
            # switching back to the explicit method with stiff settings is a legitimate
            # experiment (watch it blow up); say beforehand what will happen
            self.note = (f"dt/substeps {h:.2g} s exceeds the explicit stable estimate {stable:.2g} s: "
                         f"expect a blow-up unless you raise substeps")

    @property
    def integrator_options(self) -> dict[str, Any]:
        """The running world's integrator options by name (a new dict; ``docs/integrators.md``)."""
        return self.world.integrator_options

    def integrator_params(self) -> tuple[str, ...]:
        """Names of the option rows the integrator in force takes (the others are greyed out)."""
        taken = self.world.integrator_options
        return tuple(n for n in self._option_rows if n.removeprefix(INTEGRATOR_PREFIX) in taken)

    def set_integrator_option(self, name: str, value: Any) -> None:
        """Set one option of the running world's integrator; its other options keep their values.

        Parameters
        ----------
        name : str
            The option's name (``"iterations"``, ``"contact_weight"``, ``"mode"``: the
            integrator in force's, see ``docs/integrators.md``).
        value : int, float or str
            What the option takes; a whole float is taken for an integer option (a slider's 5.0).

        Raises
        ------
        ValueError
            A name the integrator does not take (saying which integrator does, or the nearest
            of its own) or a value it does not allow; one line, and nothing changes.

        Examples
        --------
        >>> s = Session("demo")  # avbd, the default
        >>> s.set_integrator_option("order", 2); s.integrator_options["order"]
        2
        >>> s.set_integrator_option("iterations", 0)
        Traceback (most recent call last):
        ...
        ValueError: avbd option iterations must be an integer in [1, 10000], got 0
        """
        w = self.world
        options = w.integrator_options
        if name not in options:
            raise ValueError(unknown_option(name, w.integrator))
        if isinstance(options[name], int) and isinstance(value, float) and value.is_integer():
            value = int(value)
        options[name] = value
        w.integrator_options = options  # checks every value first: a bad one changes nothing
        self.note, self.note_is_warning = "", False
        self._xpbd_note()  # the substeps XPBD needs follow its iterations

    # -- mesh ---------------------------------------------------------------------------------
    def select_object(self, name: str) -> None:
        """Switch the edited body to ``bunny``, ``donut``, ``armadillo`` or ``box`` (rebuilds)."""
        if name not in OBJECTS:
            raise ValueError(f"object must be one of {', '.join(OBJECTS)}, got {name!r}")
        self._set_mesh(selected=name)

    def select_body(self, index: int) -> None:
        """Make body ``index`` the one the mesh values edit."""
        n = len(self.world.bodies)
        if not 0 <= index < n:
            raise ValueError(f"body index must be in [0, {n - 1}], got {index}")
        self.body_index = index
        self.mesh = MeshSettings.from_spec(self.body_spec)

    def _set_mesh(self, **changes: Any) -> None:
        new = replace(self.mesh, **changes)
        spec = self.body_spec
        if spec is None:
            raise ValueError("the scene has no body to change")
        if new.selected == "mesh":
            raise ValueError("this body was given as a mesh in the scene: choose bunny, donut, armadillo or box first")
        position = spec.position
        if position is None:  # keep the body where it is when the new mesh has other coordinates
            rest = self.world.bodies[self.body_index].topology.rest_positions
            position = tuple(float(v) for v in (rest.min(axis=0) + rest.max(axis=0)) / 2)
        # every per-body physics value stays (material, friction, contacts); vertex numbers
        # mean nothing in the new mesh, so its pins go, except a pin box that still holds some
        common = {f.name: getattr(spec, f.name) for f in fields(BodyPhysics) if f.name not in ("pin", "pin_vertices")}
        common["position"] = position
        pinned_before = bool(self.world.bodies[self.body_index].pinned.any())
        body: BoxBody | ImageBody
        if new.selected == "box":
            color = spec.color if isinstance(spec, BoxBody) else None
            texture = spec.texture if isinstance(spec, BoxBody) else None
            body = BoxBody(corners=new.corners, detail=new.detail, edges=new.edges, color=color, texture=texture,
                           **common)
        else:
            source = new.selected
            if isinstance(spec, ImageBody) and MeshSettings.from_spec(spec).selected == new.selected:
                source = spec.source  # an image file given by path keeps its path
            same = spec if isinstance(spec, ImageBody) and source == spec.source else None
            keep = same is not None
            # the same picture keeps how its shape is cut from its background
            cut: dict[str, Any] = {} if same is None else dict(background=same.background, threshold=same.threshold)
            body = ImageBody(source=source, resolution=new.resolution, detect_edges=new.detect_edges,
                             edge_step=new.edge_step, scale=new.scale,
                             color=spec.color if keep else None, texture=spec.texture if keep else None, **cut,
                             **common)
        kept = False
        if spec.pin is not None:
            from ..scene import make_mesh

            # where the new mesh will be: what build() places, to test the box on
            x = np.array(make_mesh(body).vertices, dtype=np.float64)
            x += np.asarray(position) - (x.min(axis=0) + x.max(axis=0)) / 2
            try:
                pin_mask(replace(body, pin=spec.pin), x)
                body = replace(body, pin=spec.pin)
                kept = True
            except ValueError:
                pass
        with warnings.catch_warnings():  # add_body's warning of a step beyond the explicit limit:
            warnings.simplefilter("ignore", RuntimeWarning)  # _keep_stable acts on it and says so
            self._rebuild(body)
        self.mesh = new
        self._keep_stable()
        if pinned_before and not kept:
            self.note = "; ".join(n for n in (self.note, "pins cleared (the new mesh has other vertices)") if n)

    def _keep_stable(self, what: str = "the finer mesh") -> None:
        # mass per vertex is mass / N (the original's rule), so a finer mesh needs smaller
        # substeps, and a finite-element material its own; raise them to what the world's own
        # estimate asks rather than let the body blow up on its first frame
        w = self.world
        stable = w.stable_dt()
        need = math.ceil(w.dt / stable) if stable > 0 else w.substeps
        if w.substeps < need <= MAX_AUTO_SUBSTEPS:
            w.substeps = need
            self.note = f"substeps raised to {need} so {what} stays stable (stable dt {stable:.2g} s)"
        elif need > max(w.substeps, MAX_AUTO_SUBSTEPS):
            # more than a live window can afford: say so before the first step blows up
            self.note_is_warning = True
            self.note = (f"{what} needs {need} substeps under {w.integrator} (stable dt {stable:.2g} s): "
                         f"switch the integrator to implicit-euler or xpbd, or soften it (lower stiffness, E "
                         f"or material damping)")
        self._xpbd_note()

    def _xpbd_note(self) -> None:
        # XPBD never blows up, but with too few substeps a body sinks into itself: say so
        # (World.xpbd_substeps says why) rather than raise substeps behind the user's back
        advice = xpbd_advice(self.world)
        if advice:
            self.note_is_warning = True
            self.note = advice

    def _rebuild(self, body_spec: BodySpec | None = None) -> None:
        self.note, self.note_is_warning = "", False
        scene = self.scene
        if body_spec is not None:
            bodies = list(scene.body)
            bodies[self.body_index] = body_spec
            scene = replace(scene, body=tuple(bodies))
        try:
            world = build(scene)
        except SceneError as e:
            # the message starts with the scene file's name, which says nothing in a panel
            raise ValueError(str(e).split(": ", 1)[-1]) from None
        self.world = world
        self._drive_speeds.clear()  # keyed by the old world's joints
        self.generation += 1

    def reset(self) -> None:
        """Start again: every body back at its starting position, at rest, time zero."""
        self._rebuild()

    # -- colliders ----------------------------------------------------------------------------
    @property
    def collider_shape(self) -> str | None:
        """Shape of the selected collider (see :data:`COLLIDER_SHAPES`), or None."""
        c = self.collider
        return None if c is None else collider_shape_name(c)

    def collider_params(self) -> tuple[str, ...]:
        """Names of the collider values the selected collider has (none without a selection)."""
        shape = self.collider_shape
        return tuple(n for n, (_, _, shapes) in COLLIDER_FIELDS.items() if shape in shapes)

    def add_collider(self, shape: str = "rect", *, center: Iterable[float] | None = None, angle: float = 0.0,
                     size: tuple[float, float] = (3.0, 0.3), radius: float | None = None) -> Collider:
        """Add a collider at ``center`` (default: the camera centre) and select it.

        Parameters
        ----------
        shape : str
            ``rect`` (``size``, default 3 m x 0.3 m), ``circle`` (``radius``, default 0.5 m),
            ``polygon`` (a small concave cup, :data:`CUP`) or ``segment`` (2 m long, ``radius``
            default 0.05 m; 0 makes a wire).
        center : (float, float), optional
            Metres; for a polygon, where its centroid goes.
        angle : float
            Degrees, counter-clockwise.

        Returns
        -------
        the new collider

        Examples
        --------
        >>> s = Session("demo")
        >>> c = s.add_collider("circle", center=(1.0, 2.0))
        >>> c.radius, s.collider_shape, s.get_param("collider_width") is None
        (0.5, 'circle', True)
        """
        if shape not in COLLIDER_SHAPES:
            raise ValueError(f"collider shape must be one of {', '.join(COLLIDER_SHAPES)}, got {shape!r}")
        cx, cy = (float(v) for v in (self.camera_center if center is None else center))
        c: Collider
        if shape == "rect":
            c = Rect((cx, cy), size, angle)
        elif shape == "circle":
            c = Circle((cx, cy), 0.5 if radius is None else radius)
        elif shape == "polygon":
            c = Polygon(np.asarray(CUP) + (cx, cy))
        else:
            c = Segment((cx - 1.0, cy), (cx + 1.0, cy), radius=0.05 if radius is None else radius)
        if shape != "rect" and angle:
            c.angle = c.angle + angle
        if shape == "polygon":
            c.center = (cx, cy)  # the cup's centroid is low in it: put the centroid where asked
        self.world.add_collider(c)
        self.collider_active = True
        self.collider_colors.append(None)
        self.collider_index = len(self.world.colliders) - 1
        return c

    def remove_collider(self) -> None:
        """Remove the selected collider."""
        if self.collider_index is None:
            raise ValueError("there is no collider to remove")
        i = self.collider_index
        self.world.remove_collider(self.world.colliders[i])
        if i < len(self.collider_colors):
            del self.collider_colors[i]
        n = len(self.world.colliders)
        self.collider_index = None if n == 0 else min(i, n - 1)

    def select_collider(self, index: int | None) -> None:
        """Make collider ``index`` the one the inspector edits (None for none)."""
        n = len(self.world.colliders)
        if index is not None and not 0 <= index < n:
            raise ValueError(f"collider index must be in [0, {n - 1}], got {index}")
        self.collider_index = index
        self.collider_active = index is not None

    def move_collider(self, center: Iterable[float]) -> None:
        """Put the selected collider's centre at ``center`` (metres): mouse dragging."""
        c = self.collider
        if c is None:
            raise ValueError("there is no collider selected")
        self._change_collider(center=tuple(float(v) for v in center))

    def rotate_collider(self, degrees: float) -> float:
        """Turn the selected collider about its centre by ``degrees`` (counter-clockwise);
        its angle stays in (-180, 180]. Returns the new angle."""
        c = self.collider
        if c is None:
            raise ValueError("there is no collider selected: click one first")
        angle = (float(c.angle) + float(degrees)) % 360.0
        angle = angle - 360.0 if angle > 180.0 else angle
        self._change_collider(angle=round(angle, 9))
        return c.angle

    def _edit_collider(self, name: str, value: Any) -> None:
        c = self.collider
        if c is None:
            raise ValueError("there is no collider selected: add one first")
        attr, part, shapes = COLLIDER_FIELDS[name]
        shape = collider_shape_name(c)
        if shape not in shapes:
            raise ValueError(f"a {shape} has no {name.removeprefix('collider_').replace('_', ' ')}")
        if isinstance(value, bool):
            raise ValueError(f"{name} must be a number, got {value!r}")
        if value is None:
            if attr not in ("friction", "static_friction"):
                raise ValueError(f"{name} must be a number, got None")
        else:
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise ValueError(f"{name} must be a number, got {value!r}") from None
        if attr == "angle" and not -360.0 <= value <= 360.0:
            raise ValueError(f"collider angle must be in [-360, 360] degrees, got {value!r}")
        if part is not None:
            whole = list(getattr(c, attr))
            whole[part] = value
            value = tuple(whole)
        self._change_collider(**{attr: value})

    def _change_collider(self, **changes: Any) -> None:
        """Set attributes of the selected collider, all or none: each is set on a copy first,
        whose setters check it, so a refused value leaves the collider as it was."""
        c = self.collider
        trial = copy.copy(c)
        for attr, value in changes.items():
            setattr(trial, attr, value)
        for attr, value in changes.items():
            setattr(c, attr, value)
        self.collider_active = True

    def collider_at(self, point: ArrayLike, *, radius: float = 0.0) -> int | None:
        """Index of the topmost collider containing ``point`` (metres); failing that, of the
        collider whose boundary passes nearest it within ``radius`` metres (a wire has no
        inside to click, a thin slab little); None if there is neither."""
        p = np.asarray([point], dtype=np.float64)
        colliders = self.world.colliders
        for i in range(len(colliders) - 1, -1, -1):
            if bool(colliders[i].contains(p)[0]):
                return i
        best = None
        for i, c in enumerate(colliders):
            d = _boundary_distance(c, p[0])
            if d <= radius and (best is None or d <= best[0]):
                best = (d, i)
        return None if best is None else best[1]

    # -- files --------------------------------------------------------------------------------
    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the current setup as a scene file; returns the path written.

        Raises
        ------
        ValueError
            The name does not end in ``.toml`` or its folder does not exist.
        """
        from ..scene import save_scene

        return save_scene(self.scene, path)

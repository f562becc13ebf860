"""The tables of a scene file: one frozen dataclass per TOML table, mapping one-to-one onto it.

Each field carries its kind, allowed range, unit and a sentence of documentation in its
metadata (:func:`spec`), which :func:`deforma.scene.schema.parse_scene` validates a file
against and ``docs/scenes.md`` lists. The whole file, :class:`deforma.scene.schema.Scene`, is
made of these tables: ``[scene]``, ``[run]``, ``[camera]``, ``[physics]``, ``[interaction]``
and the arrays ``[[body]]``, ``[[collider]]``, ``[[event]]``, ``[[pull]]``.

Colliders: ``shape`` is "rect" (the default), "circle", "polygon", "segment" or "image"; each
has its own keys (:data:`COLLIDER_KINDS`) and they share ``velocity``, ``angular_velocity``,
``friction``, ``static_friction`` and ``color`` (:class:`ColliderCommon`). An image collider is
built as one polygon per piece of its picture, and written back as those polygons.

Materials: ``[physics] material`` (with ``youngs_modulus``, ``poisson_ratio``, ``density``,
``material_damping`` and the behaviours ``tear_strain``, ``yield_strain``, ``plastic_rate``,
``max_stretch``, and ``plane``) is the world's default; the same ten keys on a ``[[body]]`` give it its
own material, each key it leaves out taken from ``[physics]``. :func:`material_settings`
says what a table means and refuses the combinations that mean nothing (finite-element
parameters on springs, spring mass on finite elements, a finite-element model without E).

Integrator options: ``[physics.integrator_options]`` holds the settings of ``[physics]
integrator`` by name (``iterations = 5``); what names and values it takes is the integrator's
own (``deforma.physics.integrators``), so :func:`deforma.scene.schema.parse_scene` checks them
against it, and :class:`PhysicsSettings` keeps them as ``(name, value)`` pairs.

Examples
--------
>>> BoxBody(detail=4).corners
((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5))
>>> material_settings(PhysicsSettings(), BoxBody(tear_strain=0.5))
{'model': 'springs', 'tear_strain': 0.5}
"""

from __future__ import annotations

from dataclasses import MISSING, dataclass, field
from typing import Any

# an image body's background: the names of deforma.mesh.from_image itself
from ..mesh.image import BACKGROUND_NAMES
from ..physics.material import MODELS, PLANES, PRESETS, material_models

__all__ = [
    "BEHAVIOUR_KEYS", "BODY_KINDS", "COLLIDER_KINDS", "COLLIDER_SHAPES", "FEM_DEFAULT", "FEM_KEYWORD", "MATERIAL_KEYS",
    "MATERIAL_MODELS", "BodyPhysics", "BoxBody", "CameraSettings", "CircleCollider", "ColliderCommon", "ColliderSpec",
    "Event", "ImageBody", "ImageCollider", "InteractionSettings", "JointSpec", "MaterialKeyError", "MeshBody",
    "PhysicsSettings",
    "PolygonCollider", "Pull", "RectCollider", "RunSettings", "SceneError", "SceneInfo", "SegmentCollider",
    "material_settings", "spec",
]

#: Material models a scene may name (``deforma.Material``'s; kept here so that reading a file
#: needs no physics import).
MATERIAL_MODELS = MODELS  # built in; material_models() adds those of registered element kinds


def material_names() -> tuple[str, ...]:
    """What a ``material`` key takes: a model (:func:`~deforma.physics.material.material_models`)
    or a preset (:data:`~deforma.physics.material.PRESETS`).

    Examples
    --------
    >>> material_names()[-6:]
    ('jelly', 'gummy', 'rubber', 'foam', 'wood', 'cloth')
    """
    return material_models() + tuple(PRESETS)
#: The behaviour keys of a material (``deforma.Material``'s keywords of the same names), for
#: every model; ``plastic_rate`` matters only with ``yield_strain``.
BEHAVIOUR_KEYS = ("tear_strain", "yield_strain", "plastic_rate", "max_stretch")
_BEHAVIOUR_DEFAULT = {"tear_strain": None, "yield_strain": None, "plastic_rate": 1.0, "max_stretch": None}
#: The keys that describe a material, on ``[physics]`` and on a ``[[body]]``.
MATERIAL_KEYS = ("material", "youngs_modulus", "poisson_ratio", "density", "material_damping",
                 "plane") + BEHAVIOUR_KEYS
#: The finite-element keys and the :class:`deforma.Material` keyword each one sets.
FEM_KEYWORD = {"youngs_modulus": "youngs_modulus", "poisson_ratio": "poisson_ratio", "density": "density",
               "material_damping": "damping", "plane": "plane"}
#: The finite-element keys whose default in [physics] is a value, not None.
FEM_DEFAULT = {"material_damping": 0.0, "plane": "stress"}
_FEM_NEEDS = ("youngs_modulus", "poisson_ratio", "density")
_SPRING_KEYS = ("mass", "stiffness", "damping")


class SceneError(ValueError):
    """A scene file or name that cannot be used; the message names the file, the key and what is allowed."""


def spec(kind: str, default: Any = MISSING, *, lo=None, hi=None, lo_open=False, hi_open=False, choices=None,
         unit="", doc="") -> Any:
    """A dataclass field with what the validator and the docs need to know about it.

    ``kind`` is one of float, int, bool, str, vec2, size2, quad, color, colors2, file, points,
    loops (a list of point lists), triangles, box2 (two corners of an axis-aligned box), indices
    (a list of integers >= 0), background (one of ``choices`` or a colour '#rrggbb'), picture
    (an image collider's source: a built-in level or texture name, or an image path), options
    (a sub-table of name = value, kept as ``(name, value)`` pairs: the integrator's options,
    whose names and values the integrator itself checks).
    substeps (an integer or "auto").
    ``lo``/``hi`` bound numbers (``lo_open``/``hi_open`` make a bound exclusive). ``choices``
    may be a function giving them when a file is read (the material models: a registered
    element kind adds its own).
    """
    meta = dict(kind=kind, lo=lo, hi=hi, lo_open=lo_open, hi_open=hi_open, choices=choices, unit=unit, doc=doc)
    if default is MISSING:
        return field(metadata=meta)
    return field(default=default, metadata=meta)


@dataclass(frozen=True)
class SceneInfo:
    """``[scene]``: what the scene is."""

    name: str = spec("str", "", doc="Short name, shown by `deforma scenes` and in window titles.")
    description: str = spec("str", "", doc="One sentence on what the scene shows.")


@dataclass(frozen=True)
class RunSettings:
    """``[run]``: how long `deforma run` simulates and how many frames per second it records."""

    seconds: float = spec("float", 5.0, lo=0.0, hi=3600.0, lo_open=True, unit="s",
                          doc="Simulated time to run (`--seconds` overrides).")
    fps: float = spec("float", 30.0, lo=1.0, hi=240.0, unit="frames/s",
                      doc="Frames per second of videos and state files (`--fps` overrides).")


@dataclass(frozen=True)
class CameraSettings:
    """``[camera]``: the part of the world in the picture."""

    center: tuple = spec("vec2", (0.0, 2.0), unit="m", doc="World point at the centre of the picture.")
    size: tuple = spec("size2", (16.0, 9.0), unit="m",
                       doc="Width and height that must be visible; the view grows along one axis to "
                           "match the picture's aspect ratio.")
    wireframe: bool = spec("bool", False, doc="Draw every spring over the bodies.")
    follow: int | None = spec("int", None, lo=0,
                              doc="A body the camera keeps in the middle (its centre of mass), by its place among "
                                  "the [[body]] tables (from 0), as a side-scroller does; the viewer stops following "
                                  "once you pan.")
    background: tuple = spec("colors2", ("#dbe8f5", "#f7f2e8"),
                             doc="Top and bottom colours of the background gradient.")


@dataclass(frozen=True)
class PhysicsSettings:
    """``[physics]``: the world's parameters (the original inspector's Physics Settings)."""

    dt: float = spec("float", 1 / 60, lo=0.0, hi=0.1, lo_open=True, unit="s",
                     doc="Time advanced per step; smaller is more accurate and slower.")
    substeps: int | str = spec("substeps", "auto", lo=1, hi=1000,
                               doc="Integration substeps per step, each dt/substeps long; \"auto\": as many as the "
                                   "explicit integrator's stable step asks, chosen again as the bodies change.")
    gravity: tuple = spec("vec2", (0.0, -9.81), unit="m/s^2", doc="Acceleration of gravity.")
    damping: float = spec("float", 0.5, lo=0.0, unit="N*s/m", doc="Spring damping kd.")
    mass: float = spec("float", 1.0, lo=0.0, lo_open=True, unit="kg",
                       doc="Total mass of a body; each vertex weighs mass / N.")
    stiffness: float = spec("float", 1000.0, lo=0.0, unit="N/m", doc="Spring constant ks.")
    friction: float = spec("float", 0.3, lo=0.0,
                           doc="Dynamic Coulomb friction coefficient of colliders, and of bodies against each "
                               "other unless they set their own.")
    static_friction: float = spec("float", 0.5, lo=0.0,
                                  doc="Static Coulomb friction coefficient of colliders, and of bodies against "
                                      "each other unless they set their own.")
    max_speed: float = spec("float", 1000.0, lo=0.0, lo_open=True, unit="m/s",
                            doc="A vertex faster than this means the simulation became unstable.")
    integrator: str = spec("str", "avbd",
                           doc="Time integrator by name: avbd (augmented vertex block descent, stable and at "
                               "rest at one step a frame), symplectic-euler (explicit, the original's), "
                               "implicit-euler, implicit-bdf2 (second order) or xpbd (all four stable at any dt; "
                               "see docs/integrators.md).")
    integrator_options: tuple = spec("options", (),
                                     doc="The integrator's own settings, a sub-table [physics.integrator_options] "
                                         "of name = value: tolerance, max_iterations, iterations and contact_weight of "
                                         "implicit-euler and implicit-bdf2, "
                                         "iterations of xpbd, mode of symplectic-euler (docs/integrators.md, "
                                         "Options). Each is checked against integrator; one left out has its "
                                         "default.")
    contact_thickness: float | None = spec("float", None, lo=0.0, lo_open=True, unit="m",
                                           doc="How far apart touching bodies stay; below every colliding body's "
                                               "shortest outline edge. Omit for 5% of each body's median outline "
                                               "edge.")
    air_drag: float = spec("float", 0.0, lo=0.0, unit="1/s",
                           doc="Every velocity decays as dv/dt = -air_drag v; a little lets stacks and heaps come "
                               "to rest.")
    sleep: bool = spec("bool", True, doc="Bodies at rest fall asleep: an island of bodies touching or joined, "
                                          "all slower than 5 mm/s for 0.5 s, stops being stepped until something "
                                          "disturbs it (docs/physics.md, Sleeping).")
    material: str = spec("str", "springs", choices=material_names,
                         doc="What bodies are made of unless they say: springs (the original's springs on the mesh "
                             "edges, with mass, stiffness, damping), or finite elements on the triangles: corotated "
                             "or neo-hookean (need youngs_modulus, poisson_ratio, density; see deforma.Material), "
                             "or a preset (jelly, gummy, rubber, foam, wood, cloth: deforma.Material.preset), whose "
                             "values the material keys set beside it replace.")
    youngs_modulus: float | None = spec("float", None, lo=0.0, hi=1e15, lo_open=True, unit="Pa",
                                        doc="Young's modulus E of finite-element bodies: rubber ~1e6, a soft gel "
                                            "~1e4.")
    poisson_ratio: float | None = spec("float", None, lo=-1.0, hi=0.5, lo_open=True, hi_open=True,
                                       doc="Poisson ratio nu of finite-element bodies: how much a stretched sheet "
                                           "narrows (0.5 would be incompressible).")
    density: float | None = spec("float", None, lo=0.0, hi=1e12, lo_open=True, unit="kg/m^2",
                                 doc="Mass per area of finite-element bodies: a body weighs density * area.")
    material_damping: float = spec("float", 0.0, lo=0.0, hi=1e6, unit="s",
                                   doc="Viscous damping of finite-element bodies: a vibration of angular frequency "
                                       "w gets damping ratio material_damping * w / 2.")
    plane: str = spec("str", "stress", choices=PLANES,
                      doc="What a finite-element body's slab is: stress (a thin sheet, free to thin out of its "
                          "plane) or strain (the cross-section of a long body, stiffer in the plane).")
    tear_strain: float | None = spec("float", None, lo=0.0, hi=100.0, lo_open=True,
                                     doc="Tearing (any material): where a body is stretched by more than this strain "
                                         "(0.5 = 50% longer) across a mesh edge, the mesh splits there. Omit: never "
                                         "tears.")
    yield_strain: float | None = spec("float", None, lo=0.0, hi=100.0, lo_open=True,
                                      doc="Plasticity (any material): strain beyond this moves the rest shape, so "
                                          "dents stay. Omit: elastic.")
    plastic_rate: float = spec("float", 1.0, lo=0.0, hi=1.0, lo_open=True,
                               doc="Share of the strain beyond yield_strain made permanent per step; 1 is perfectly "
                                   "plastic, smaller values creep.")
    max_stretch: float | None = spec("float", None, lo=1.0, hi=100.0, lo_open=True,
                                     doc="Strain limit (any material): no spring or element ends a step longer than "
                                         "this ratio of its rest length (1.05 = 5% longer). Omit: no limit.")


@dataclass(frozen=True)
class InteractionSettings:
    """``[interaction]``: the space key and the mouse."""

    explosive_force: float = spec("float", 5.0, lo=0.0, unit="m/s",
                                  doc="Upward speed the space key (or an `explode` event) adds to every vertex.")
    mouse_strength: float = spec("float", 50.0, lo=0.0, lo_open=True, unit="N/m",
                                 doc="Pull toward the pointer per held vertex.")


_BODY_COMMON_DOC = {
    "position": "Where the mesh's bounding-box centre is placed; omit to keep the mesh's own coordinates.",
    "color": "Flat colour, '#rrggbb' or '#rrggbbaa'; with a texture it tints it.",
    "texture": "A picture mapped with the mesh's uv: a built-in texture name or an image path "
               "(relative to the scene file).",
}


@dataclass(frozen=True)
class BodyPhysics:
    """The keys every ``[[body]]`` shares: per-body physics overrides and contact switches."""

    mass: float | None = spec("float", None, lo=0.0, lo_open=True, unit="kg", doc="Overrides physics.mass.")
    stiffness: float | None = spec("float", None, lo=0.0, unit="N/m", doc="Overrides physics.stiffness.")
    damping: float | None = spec("float", None, lo=0.0, unit="N*s/m", doc="Overrides physics.damping.")
    material: str | None = spec("str", None, choices=material_names,
                                doc="Overrides physics.material: any of the ten material keys (material to "
                                    "max_stretch, and plane) gives the body its own material, the others taken from "
                                    "[physics].")
    youngs_modulus: float | None = spec("float", None, lo=0.0, hi=1e15, lo_open=True, unit="Pa",
                                        doc="Overrides physics.youngs_modulus.")
    poisson_ratio: float | None = spec("float", None, lo=-1.0, hi=0.5, lo_open=True, hi_open=True,
                                       doc="Overrides physics.poisson_ratio.")
    density: float | None = spec("float", None, lo=0.0, hi=1e12, lo_open=True, unit="kg/m^2",
                                 doc="Overrides physics.density.")
    material_damping: float | None = spec("float", None, lo=0.0, hi=1e6, unit="s",
                                          doc="Overrides physics.material_damping.")
    plane: str | None = spec("str", None, choices=PLANES, doc="Overrides physics.plane.")
    tear_strain: float | None = spec("float", None, lo=0.0, hi=100.0, lo_open=True,
                                     doc="Overrides physics.tear_strain.")
    yield_strain: float | None = spec("float", None, lo=0.0, hi=100.0, lo_open=True,
                                      doc="Overrides physics.yield_strain.")
    plastic_rate: float | None = spec("float", None, lo=0.0, hi=1.0, lo_open=True,
                                      doc="Overrides physics.plastic_rate.")
    max_stretch: float | None = spec("float", None, lo=1.0, hi=100.0, lo_open=True,
                                     doc="Overrides physics.max_stretch.")
    pressure: float | None = spec("float", None, lo=0.0, hi=1e12, unit="N/m",
                                  doc="Gas inside the body's outer outline pushing it out with pressure * A0 / A (A0 "
                                      "its rest area), like a balloon. A tear lets the gas out.")
    collide: bool = spec("bool", True, doc="Touch other bodies (both must have it on).")
    self_collision: bool = spec("bool", True, doc="Touch itself: its outline cannot fold through itself.")
    friction: float | None = spec("float", None, lo=0.0,
                                  doc="Overrides physics.friction against other bodies and itself; two bodies "
                                      "use sqrt(a * b) of theirs.")
    static_friction: float | None = spec("float", None, lo=0.0,
                                         doc="Overrides physics.static_friction against other bodies and itself.")
    angle: float = spec("float", 0.0, lo=-1e6, hi=1e6, unit="deg",
                        doc="Turn the mesh by this many degrees (counter-clockwise) about its bounding-box centre "
                            "before placing it.")
    velocity: tuple = spec("vec2", (0.0, 0.0), unit="m/s", doc="Initial velocity of its centre of mass.")
    angular_velocity: float = spec("float", 0.0, lo=-1e9, hi=1e9, unit="deg/s",
                                   doc="Initial spin about its centre of mass, counter-clockwise.")
    pin: tuple | None = spec("box2", None, unit="m",
                             doc="Pin every vertex inside this box, [[x0, y0], [x1, y1]] in world coordinates after "
                                 "the body is placed: they stay where they are.")
    pin_vertices: tuple | None = spec("indices", None,
                                      doc="Pin these vertices, [i, j, ...] (the body's own vertex numbers; what "
                                          "save_scene writes for pins no box describes).")


@dataclass(frozen=True)
class BoxBody(BodyPhysics):
    """``[[body]]`` with ``shape = "box"``: a quadrilateral filled with points (the original's Square)."""

    shape: str = spec("str", "box", choices=("box", "image", "mesh"), doc="Which kind of body.")
    corners: tuple = spec("quad", ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)), unit="m",
                          doc="Four corners in order around a convex quadrilateral.")
    # at most what keeps the box within checks.MAX_BODY_POINTS points, checked with edges (schema._body)
    detail: int = spec("int", 8, lo=0, doc="n: n*n points inside, spread evenly; the box at most 100,000 points "
                                           "(314 with edges, 316 without).")
    edges: bool = spec("bool", True, doc="Also put n points on each side (on by default, as in mesh.box: "
                                         "without them the triangles along the sides are thin).")
    position: tuple | None = spec("vec2", None, unit="m", doc=_BODY_COMMON_DOC["position"])
    color: str | None = spec("color", None, doc=_BODY_COMMON_DOC["color"])
    texture: str | None = spec("file", None, doc=_BODY_COMMON_DOC["texture"])


@dataclass(frozen=True)
class ImageBody(BodyPhysics):
    """``[[body]]`` with ``shape = "image"``: a body traced from a picture (the original's textures)."""

    shape: str = spec("str", "image", choices=("box", "image", "mesh"), doc="Which kind of body.")
    source: str = spec("file", "bunny", doc="Built-in texture name (bunny, donut, armadillo) or an image path.")
    resolution: int = spec("int", 4, lo=1, hi=10000, unit="px",
                           doc="Sample every n-th pixel; smaller gives more points (at most 100,000, counted when "
                               "the picture is read: the message names the resolution that fits).")
    detect_edges: bool = spec("bool", True, doc="Add points along the outline so the mesh follows the picture.")
    edge_step: int = spec("int", 2, lo=1, hi=10000, unit="px", doc="Take every n-th outline pixel.")
    scale: float = spec("float", 0.01, lo=0.0, lo_open=True, unit="m/px", doc="Metres per pixel.")
    background: str = spec("background", "black", choices=BACKGROUND_NAMES,
                           doc="What the shape is on, for pictures without transparency (transparency always "
                               "decides when present): black (the seed's rule), white, auto (the colour of the "
                               "picture's border) or a colour '#rrggbb'.")
    threshold: float | None = spec("float", None, lo=0.0, hi=1.0, hi_open=True,
                                   doc="How far a pixel's colour must be from the background to be the shape, as a "
                                       "fraction of full scale in the channel that differs most (default 0.06, "
                                       "about 15 of 255); for pictures with transparency, the alpha level instead "
                                       "(default 0.5).")
    position: tuple | None = spec("vec2", None, unit="m", doc=_BODY_COMMON_DOC["position"])
    color: str | None = spec("color", None, doc=_BODY_COMMON_DOC["color"])
    texture: str | None = spec("file", None, doc="A different picture to draw; by default the source itself.")


@dataclass(frozen=True)
class MeshBody(BodyPhysics):
    """``[[body]]`` with ``shape = "mesh"``: any mesh given by its arrays (what save_scene writes for
    bodies that were not made from a box or an image)."""

    shape: str = spec("str", "mesh", choices=("box", "image", "mesh"), doc="Which kind of body.")
    vertices: tuple = spec("points", (), unit="m", doc="Vertex positions, [[x, y], ...].")
    triangles: tuple = spec("triangles", (), doc="Vertex indices per triangle, [[i, j, k], ...].")
    uv: tuple | None = spec("points", None, doc="Texture coordinates in [0, 1], one per vertex.")
    position: tuple | None = spec("vec2", None, unit="m", doc=_BODY_COMMON_DOC["position"])
    color: str | None = spec("color", None, doc=_BODY_COMMON_DOC["color"])
    texture: str | None = spec("file", None, doc=_BODY_COMMON_DOC["texture"])


BODY_KINDS = {"box": BoxBody, "image": ImageBody, "mesh": MeshBody}


#: The values of a ``[[collider]]``'s ``shape`` key (the first, "rect", is the default).
COLLIDER_SHAPES = ("rect", "circle", "polygon", "segment", "image")


@dataclass(frozen=True)
class ColliderCommon:
    """The keys every ``[[collider]]`` shares: motion, friction and colour."""

    velocity: tuple = spec("vec2", (0.0, 0.0), unit="m/s",
                           doc="Kinematic motion: the collider moves by this every substep (a moving platform) "
                               "and carries what rests on it by friction.")
    angular_velocity: float = spec("float", 0.0, lo=-1e6, hi=1e6, unit="degrees/s",
                                   doc="Kinematic rotation, counter-clockwise, about its centre (a polygon's "
                                       "centroid, a segment's midpoint): a paddle, a roller.")
    friction: float | None = spec("float", None, lo=0.0, doc="Overrides physics.friction for this collider.")
    static_friction: float | None = spec("float", None, lo=0.0,
                                         doc="Overrides physics.static_friction for this collider.")
    color: str | None = spec("color", None, doc="Fill colour, '#rrggbb'.")


@dataclass(frozen=True)
class ColliderSpec(ColliderCommon):
    """``[[collider]]`` with ``shape = "rect"`` (the default): a rotated rectangle (the original's
    Collision Settings)."""

    shape: str = spec("str", "rect", choices=COLLIDER_SHAPES, doc="Which kind of collider.")
    center: tuple = spec("vec2", (0.0, 0.0), unit="m", doc="Centre of the rectangle.")
    size: tuple = spec("size2", (10.0, 0.5), unit="m", doc="Width and height before rotation.")
    angle: float = spec("float", 0.0, lo=-360.0, hi=360.0, unit="degrees", doc="Counter-clockwise rotation.")


#: The rectangle's spec by the name of its shape (``ColliderSpec`` is its older name).
RectCollider = ColliderSpec


@dataclass(frozen=True)
class CircleCollider(ColliderCommon):
    """``[[collider]]`` with ``shape = "circle"``: a disc (turning, it is a roller or a wheel)."""

    shape: str = spec("str", "circle", choices=COLLIDER_SHAPES, doc="Which kind of collider.")
    center: tuple = spec("vec2", (0.0, 0.0), unit="m", doc="Centre of the disc.")
    radius: float | None = spec("float", None, lo=0.0, hi=1e9, lo_open=True, unit="m", doc="Radius (required).")


@dataclass(frozen=True)
class PolygonCollider(ColliderCommon):
    """``[[collider]]`` with ``shape = "polygon"``: any simple polygon, concave allowed, with holes
    (what save_scene writes for the pieces of an image collider)."""

    shape: str = spec("str", "polygon", choices=COLLIDER_SHAPES, doc="Which kind of collider.")
    points: tuple = spec("points", (), unit="m",
                         doc="The outline (required), [[x, y], ...], at least three corners in either order, "
                             "not crossing itself.")
    holes: tuple = spec("loops", (), unit="m", doc="Outlines of holes inside it, [[[x, y], ...], ...].")
    angle: float = spec("float", 0.0, lo=-360.0, hi=360.0, unit="degrees",
                        doc="Counter-clockwise rotation of points and holes about the polygon's centroid.")


@dataclass(frozen=True)
class SegmentCollider(ColliderCommon):
    """``[[collider]]`` with ``shape = "segment"``: a capsule (a segment with a radius), or a wire
    (radius 0) that bodies cannot cross."""

    shape: str = spec("str", "segment", choices=COLLIDER_SHAPES, doc="Which kind of collider.")
    a: tuple | None = spec("vec2", None, unit="m", doc="First end (required).")
    b: tuple | None = spec("vec2", None, unit="m", doc="Second end (required).")
    radius: float = spec("float", 0.0, lo=0.0, hi=1e9, unit="m", doc="Half the thickness; 0 is a wire.")


@dataclass(frozen=True)
class ImageCollider(ColliderCommon):
    """``[[collider]]`` with ``shape = "image"``: a level drawn as a picture, its foreground made into
    one polygon collider per connected piece (``deforma.colliders_from_image``)."""

    shape: str = spec("str", "image", choices=COLLIDER_SHAPES, doc="Which kind of collider.")
    source: str | None = spec("picture", None,
                              doc="The picture (required): a built-in picture name (the levels, e.g. ramp, or the "
                                  "textures) or an image path (relative to the scene file).")
    scale: float = spec("float", 0.01, lo=0.0, hi=1000.0, lo_open=True, unit="m/px", doc="Metres per pixel.")
    position: tuple = spec("vec2", (0.0, 0.0), unit="m", doc="Where the picture's centre goes (the centre of its foreground's bounding box).")
    tolerance: float = spec("float", 1.0, lo=0.0, hi=1000.0, unit="px",
                            doc="How far the simplified outline may stray from the traced one; larger gives fewer "
                                "corners.")
    background: str = spec("background", "black", choices=BACKGROUND_NAMES,
                           doc="What the level is drawn on, as for an image body: black, white, auto or "
                               "'#rrggbb'.")
    threshold: float | None = spec("float", None, lo=0.0, hi=1.0, hi_open=True,
                                   doc="How far a pixel must differ from the background to be solid, as for an "
                                       "image body.")
    min_area: float = spec("float", 4.0, lo=0.0, unit="px^2", doc="Pieces and holes smaller than this are dropped.")


COLLIDER_KINDS = {"rect": ColliderSpec, "circle": CircleCollider, "polygon": PolygonCollider,
                  "segment": SegmentCollider, "image": ImageCollider}


@dataclass(frozen=True)
class Event:
    """``[[event]]``: something that happens at a moment of a headless run (the keys a person would press)."""

    time: float = spec("float", 1.0, lo=0.0, unit="s", doc="When, in simulated seconds from the start.")
    action: str = spec("str", "explode", choices=("explode",), doc="What happens: `explode` is the space key.")
    strength: float | None = spec("float", None, unit="m/s",
                                  doc="Speed added; by default interaction.explosive_force.")


@dataclass(frozen=True)
class Pull:
    """``[[pull]]``: the mouse, scripted for a headless run: grab a body at a point, move the pull
    target in a straight line, let go."""

    at: tuple | None = spec("vec2", None, unit="m",
                            doc="Where the body is grabbed (required): the vertices of the triangle under this "
                                "point, as a mouse press picks them, plus those within radius.")
    to: tuple | None = spec("vec2", None, unit="m",
                            doc="Where the pull target ends up; omit to hold the grab where it started.")
    start: float = spec("float", 0.0, lo=0.0, unit="s", doc="When the grab happens, in simulated seconds.")
    end: float | None = spec("float", None, lo=0.0, unit="s",
                             doc="When the target reaches `to`, moving at constant speed from `at` from start on; "
                                 "omit (or = start) to put it there at once.")
    release: float | None = spec("float", None, lo=0.0, unit="s",
                                 doc="When the grab lets go (>= end); omit to hold it to the end of the run.")
    radius: float | None = spec("float", None, lo=0.0, lo_open=True, unit="m",
                                doc="Also hold every vertex of the grabbed body within this distance of `at`.")
    strength: float | None = spec("float", None, lo=0.0, lo_open=True, unit="N/m",
                                  doc="Pull per held vertex toward the target; by default "
                                      "interaction.mouse_strength.")


@dataclass(frozen=True)
class JointSpec:
    """``[[joint]]``: two bodies, or a body and the world, held together at a point
    (``World.join``): rigid bodies, or soft ones by a pin or a spring."""

    a: int | None = spec("int", None, lo=0, doc="The body it holds (required): its place among the [[body]] "
                                                 "tables, from 0; rigid, or soft with a pin or a spring.")
    b: int | None = spec("int", None, lo=0, doc="The other body's place; omit to hold `a` to the world.")
    at: tuple | None = spec("vec2", None, unit="m",
                            doc="The point both hold (required), on `a` or `b` where the scene places them, "
                                "and on each soft body it joins.")
    kind: str = spec("str", "pin", choices=("pin", "weld", "spring"),
                     doc="pin: a hinge; weld: no turning either (rigid bodies); spring: a zero-length spring "
                         "and damper.")
    stiffness: float | None = spec("float", None, lo=0.0, lo_open=True, unit="N/m",
                                   doc="A spring's stiffness (required with kind = \"spring\", only then).")
    damping: float | None = spec("float", None, lo=0.0, unit="N*s/m", doc="A spring's damping; default 0.")
    motor_speed: float | None = spec("float", None, lo=-1e6, hi=1e6, unit="deg/s",
                                     doc="A pin's motor (rigid bodies): the spin of `a` relative to `b` it drives "
                                         "towards, counter-clockwise; omit for a free hinge.")
    max_torque: float | None = spec("float", None, lo=0.0, lo_open=True, unit="N*m",
                                    doc="The most torque the motor gives; omit for as much as it takes.")
    break_force: float | None = spec("float", None, lo=0.0, lo_open=True, unit="N",
                                     doc="A step that pulls harder breaks the joint; omit for one that never breaks.")


class MaterialKeyError(ValueError):
    """A material key that cannot be used with the others; ``key`` names it (None: the table)."""

    def __init__(self, key, message: str):
        super().__init__(message)
        self.key = key


def material_settings(physics: PhysicsSettings, body: BodyPhysics | None = None) -> dict | None:
    """The :class:`deforma.Material` keywords that ``[physics]`` (and a body's overrides) describe.

    Without ``body``: the world's default material. With ``body``: ``None`` when the body sets
    none of :data:`MATERIAL_KEYS` (it follows the world's), else its own material, with model
    and each parameter the body's or, where it leaves them out, ``[physics]``'s. A springs
    material takes no parameters (the finite-element keys that ``[physics]`` holds then
    matter only to bodies that choose a finite-element model).

    Returns
    -------
    dict or None
        ``{"model": ...}`` plus ``youngs_modulus``, ``poisson_ratio``, ``density`` and
        ``damping`` for the finite-element models, plus each of :data:`BEHAVIOUR_KEYS` that
        is set (not its default), for every model; ``Material(**settings)`` builds it.

    Raises
    ------
    MaterialKeyError
        A finite-element model without E, nu or density; finite-element keys on the body of
        a springs material; spring mass/stiffness/damping on a finite-element body. ``key``
        is the offending key.

    Examples
    --------
    >>> p = PhysicsSettings(youngs_modulus=1e5, poisson_ratio=0.3, density=10.0)
    >>> material_settings(p)
    {'model': 'springs'}
    >>> material_settings(p, BoxBody(material="corotated"))["youngs_modulus"]
    100000.0
    >>> material_settings(p, BoxBody()) is None
    True
    >>> material_settings(p, BoxBody(tear_strain=0.4))
    {'model': 'springs', 'tear_strain': 0.4}
    """
    if body is None:
        model, own = physics.material, {}
    else:
        own = {k: getattr(body, k) for k in MATERIAL_KEYS if getattr(body, k) is not None}
        model = own.get("material", physics.material)
    preset = PRESETS.get(model)
    if preset is not None:
        model = preset["model"]
    springs = [k for k in _SPRING_KEYS if body is not None and getattr(body, k) is not None]
    if model != "springs" and springs:
        where = "" if "material" in own else " (physics.material)"
        if model == "rigid":  # no elasticity to speak of: a rigid body's mass is all it has
            raise MaterialKeyError(springs[0], f"the body is 'rigid'{where}, whose mass is density * area and which "
                                               f"does not deform: remove {springs[0]}, or set material = \"springs\"")
        raise MaterialKeyError(springs[0], f"the body is made of {model!r} finite elements{where}, whose mass is "
                                           f"density * area and whose elasticity is youngs_modulus and "
                                           f"poisson_ratio: remove {springs[0]}, or set material = \"springs\"")
    if body is not None and not own:
        return None
    if model == "springs":
        fem = [k for k in FEM_KEYWORD if k in own]
        if fem:
            raise MaterialKeyError(fem[0], f"the 'springs' material takes no {fem[0]} (its springs use mass, "
                                           f"stiffness and damping): set material = \"corotated\" or "
                                           f"\"neo-hookean\" too, or remove {fem[0]}")
        return {"model": "springs", **_behaviour_settings(physics, own)}
    if model == "rigid":
        return _rigid_settings(physics, own)
    values = {k: _with_preset(k, own, physics, preset, FEM_DEFAULT.get(k)) for k in FEM_KEYWORD}
    missing = [k for k in _FEM_NEEDS if values[k] is None]
    if missing:
        where = "on the body or in [physics]" if body is not None else "in [physics]"
        raise MaterialKeyError(None, f"the {model!r} material needs {', '.join(missing)} (E in Pa, nu in (-1, 0.5), "
                                     f"density in kg/m^2): set {'it' if len(missing) == 1 else 'them'} {where}")
    out = {"model": model}
    out.update((FEM_KEYWORD[k], v if k == "plane" else float(v)) for k, v in values.items())
    out.update(_behaviour_settings(physics, own, preset))
    return out


def _rigid_settings(physics: PhysicsSettings, own: dict) -> dict:
    """A rigid body's material: its density (the body's, else ``[physics]``'s) and nothing
    else; a deformation key on the body itself is refused (``[physics]``'s are the other
    bodies' and stay theirs)."""
    extra = [k for k in (*FEM_KEYWORD, *BEHAVIOUR_KEYS) if k in own and k != "density"]
    if extra:
        raise MaterialKeyError(extra[0], f"the 'rigid' material takes density only, not {extra[0]}: a rigid "
                                         f"body does not deform; remove {extra[0]}")
    density = own.get("density", physics.density)
    if density is None:
        raise MaterialKeyError(None, "the 'rigid' material needs density (kg/m^2): set it on the body or in "
                                     "[physics]")
    return {"model": "rigid", "density": float(density)}


def _with_preset(key: str, own: dict, physics: PhysicsSettings, preset: dict | None, default):
    """A material key's value: the body's own; then, for a preset the body names, the preset's
    before ``[physics]``'s, and for the world's preset ``[physics]``'s before the preset's (a
    value equal to the key's default counts as unset)."""
    if key in own:
        return own[key]
    name = FEM_KEYWORD.get(key, key)
    if preset is None or name not in preset:
        return getattr(physics, key)
    v = None if "material" in own else getattr(physics, key)
    return preset[name] if v is None or v == default else v


def _behaviour_settings(physics: PhysicsSettings, own: dict, preset: dict | None = None) -> dict:
    """The behaviour keywords that are set (the body's, else ``[physics]``'s, else the preset's),
    defaults left out."""
    out = {}
    for k in BEHAVIOUR_KEYS:
        v = _with_preset(k, own, physics, preset, _BEHAVIOUR_DEFAULT[k])
        if v is not None and v != _BEHAVIOUR_DEFAULT[k]:
            out[k] = float(v)
    return out

"""The scene file format: frozen dataclasses that map one-to-one onto TOML tables.

Each field carries its kind, allowed range, unit and a sentence of documentation in its
metadata; :func:`parse_scene` validates a TOML document against them and
:func:`scene_to_dict` writes one back. ``docs/scenes.md`` describes every key.

A file looks like::

    [scene]
    name = "sample"

    [run]
    seconds = 4.0
    fps = 30

    [camera]
    center = [0.0, 1.5]
    size = [8.0, 4.5]

    [physics]
    dt = 0.0016667
    stiffness = 1000.0

    [[body]]
    shape = "box"
    corners = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]
    detail = 6
    position = [0.0, 2.5]
    color = "#e07a5f"

    [[collider]]
    center = [0.0, 0.0]
    size = [8.0, 0.4]

    [[collider]]
    shape = "circle"
    center = [1.5, 1.0]
    radius = 0.3
    angular_velocity = -90.0

Colliders: ``shape`` is "rect" (the default), "circle", "polygon", "segment" or "image"; each
has its own keys (:data:`COLLIDER_KINDS`) and they share ``velocity``, ``angular_velocity``,
``friction``, ``static_friction`` and ``color`` (:class:`ColliderCommon`). An image collider is
built as one polygon per piece of its picture, and written back as those polygons.

Materials: ``[physics] material`` (with ``youngs_modulus``, ``poisson_ratio``, ``density``,
``material_damping`` and the behaviours ``tear_strain``, ``yield_strain``, ``plastic_rate``,
``max_stretch``) is the world's default; the same nine keys on a ``[[body]]`` give it its
own material, each key it leaves out taken from ``[physics]``. :func:`material_settings`
says what a table means and refuses the combinations that mean nothing (finite-element
parameters on springs, spring mass on finite elements, a finite-element model without E).
"""

from __future__ import annotations

import difflib
import math
import os
from dataclasses import MISSING, dataclass, field, fields
from pathlib import Path
from typing import Any

from ..checks import MAX_DETAIL

# an image body's background: the names and the rule of deforma.mesh.from_image itself
from ..mesh.image import BACKGROUND_NAMES, check_background

__all__ = [
    "BodyPhysics", "BoxBody", "CameraSettings", "CircleCollider", "ColliderCommon", "ColliderSpec", "Event", "ImageBody",
    "ImageCollider", "InteractionSettings", "MeshBody", "PolygonCollider", "RectCollider", "SegmentCollider",
    "MaterialKeyError", "PhysicsSettings", "Pull", "RunSettings", "Scene", "SceneError", "SceneInfo", "material_settings",
    "parse_scene",
    "scene_to_dict",
]

#: Material models a scene may name (``deforma.Material``'s; kept here so that reading a file
#: needs no physics import).
MATERIAL_MODELS = ("springs", "corotated", "neo-hookean")
#: The behaviour keys of a material (``deforma.Material``'s keywords of the same names), for
#: every model; ``plastic_rate`` matters only with ``yield_strain``.
BEHAVIOUR_KEYS = ("tear_strain", "yield_strain", "plastic_rate", "max_stretch")
_BEHAVIOUR_DEFAULT = {"tear_strain": None, "yield_strain": None, "plastic_rate": 1.0, "max_stretch": None}
#: The keys that describe a material, on ``[physics]`` and on a ``[[body]]``.
MATERIAL_KEYS = ("material", "youngs_modulus", "poisson_ratio", "density", "material_damping") + BEHAVIOUR_KEYS
# the finite-element keys and the Material keyword each one sets
_FEM_KEYWORD = {"youngs_modulus": "youngs_modulus", "poisson_ratio": "poisson_ratio", "density": "density",
                "material_damping": "damping"}
_FEM_NEEDS = ("youngs_modulus", "poisson_ratio", "density")
_SPRING_KEYS = ("mass", "stiffness", "damping")


class SceneError(ValueError):
    """A scene file or name that cannot be used; the message names the file, the key and what is allowed."""


class _Problem(Exception):
    """Internal: a problem at a key path, turned into one SceneError by parse_scene."""

    def __init__(self, path: str, message: str):
        super().__init__(message)
        self.path = path
        self.message = message


def spec(kind: str, default: Any = MISSING, *, lo=None, hi=None, lo_open=False, hi_open=False, choices=None,
         unit="", doc="") -> Any:
    """A dataclass field with what the validator and the docs need to know about it.

    ``kind`` is one of float, int, bool, str, vec2, size2, quad, color, colors2, file, points,
    loops (a list of point lists), triangles, box2 (two corners of an axis-aligned box), indices
    (a list of integers >= 0), background (one of ``choices`` or a colour '#rrggbb'), picture
    (an image collider's source: a built-in level or texture name, or an image path).
    ``lo``/``hi`` bound numbers (``lo_open``/``hi_open`` make a bound exclusive).
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
    background: tuple = spec("colors2", ("#dbe8f5", "#f7f2e8"),
                             doc="Top and bottom colours of the background gradient.")


@dataclass(frozen=True)
class PhysicsSettings:
    """``[physics]``: the world's parameters (the original inspector's Physics Settings)."""

    dt: float = spec("float", 1 / 600, lo=0.0, hi=0.1, lo_open=True, unit="s",
                     doc="Time advanced per step; smaller is more accurate and slower.")
    substeps: int = spec("int", 1, lo=1, hi=1000, doc="Integration substeps per step, each dt/substeps long.")
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
    integrator: str = spec("str", "symplectic-euler",
                           doc="Time integrator by name: symplectic-euler (explicit, the original's), "
                               "implicit-euler or xpbd (both stable at any dt; see docs/integrators.md).")
    contact_thickness: float | None = spec("float", None, lo=0.0, lo_open=True, unit="m",
                                           doc="How far apart touching bodies stay; below every colliding body's "
                                               "shortest outline edge. Omit for 5% of each body's median outline "
                                               "edge.")
    air_drag: float = spec("float", 0.0, lo=0.0, unit="1/s",
                           doc="Every velocity decays as dv/dt = -air_drag v; a little lets stacks and heaps come "
                               "to rest.")
    material: str = spec("str", "springs", choices=MATERIAL_MODELS,
                         doc="What bodies are made of unless they say: springs (the original's springs on the mesh "
                             "edges, with mass, stiffness, damping), or finite elements on the triangles: corotated "
                             "or neo-hookean (need youngs_modulus, poisson_ratio, density; see deforma.Material).")
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
    material: str | None = spec("str", None, choices=MATERIAL_MODELS,
                                doc="Overrides physics.material: any of the nine material keys (material to "
                                    "max_stretch) gives the body its own material, the others taken from [physics].")
    youngs_modulus: float | None = spec("float", None, lo=0.0, hi=1e15, lo_open=True, unit="Pa",
                                        doc="Overrides physics.youngs_modulus.")
    poisson_ratio: float | None = spec("float", None, lo=-1.0, hi=0.5, lo_open=True, hi_open=True,
                                       doc="Overrides physics.poisson_ratio.")
    density: float | None = spec("float", None, lo=0.0, hi=1e12, lo_open=True, unit="kg/m^2",
                                 doc="Overrides physics.density.")
    material_damping: float | None = spec("float", None, lo=0.0, hi=1e6, unit="s",
                                          doc="Overrides physics.material_damping.")
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
    detail: int = spec("int", 8, lo=0, hi=MAX_DETAIL, doc="n: n*n points inside, spread evenly.")
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
    resolution: int = spec("int", 4, lo=1, hi=10000, unit="px", doc="Sample every n-th pixel; smaller gives more points.")
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
# each shape's required keys and what to say when one is missing
_COLLIDER_NEEDS = {
    "circle": {"radius": "the disc's radius in metres"},
    "polygon": {"points": "the outline [[x, y], ...] in metres"},
    "segment": {"a": "the first end [x, y] in metres", "b": "the second end [x, y] in metres"},
    "image": {"source": "a built-in picture name or an image path"},
}


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
class Scene:
    """A whole scene file. Build the world with :meth:`build`.

    ``path`` is where it was read from (None for a scene made in code), used to resolve
    relative texture paths; it is not written to the file.
    """

    scene: SceneInfo = SceneInfo()
    run: RunSettings = RunSettings()
    camera: CameraSettings = CameraSettings()
    physics: PhysicsSettings = PhysicsSettings()
    interaction: InteractionSettings = InteractionSettings()
    body: tuple = ()
    collider: tuple = ()
    event: tuple = ()
    pull: tuple = ()
    path: str | None = field(default=None, compare=False)

    def build(self):
        """A new :class:`deforma.World` with this scene's bodies and colliders (see ``deforma.scene.build``)."""
        from .build import build

        return build(self)


SECTIONS = {"scene": SceneInfo, "run": RunSettings, "camera": CameraSettings, "physics": PhysicsSettings,
            "interaction": InteractionSettings}
ARRAYS = {"body": None, "collider": None, "event": Event, "pull": Pull}


# -- validation --------------------------------------------------------------------------------
def _suggest(key: str, allowed) -> str:
    close = difflib.get_close_matches(key, list(allowed), n=1, cutoff=0.6)
    hint = f"did you mean {close[0]!r}? " if close else ""
    return f"unknown key; {hint}allowed: {', '.join(allowed)}"


def _number(value, path, *, integer=False):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _Problem(path, f"expected {'an integer' if integer else 'a number'}, got {_show(value)}")
    if integer and not isinstance(value, int):
        if isinstance(value, float) and value.is_integer():
            return int(value)
        raise _Problem(path, f"expected an integer, got {_show(value)}")
    if not math.isfinite(value):
        raise _Problem(path, f"expected a finite number, got {_show(value)}")
    return value if integer else float(value)


def _show(value) -> str:
    kind = {bool: "boolean", int: "integer", float: "number", str: "string", list: "array", dict: "table"}
    name = kind.get(type(value), type(value).__name__)
    text = repr(value)
    if len(text) > 40:
        text = text[:37] + "..."
    return f"{name} {text}"


def _range_text(meta) -> str:
    lo, hi = meta["lo"], meta["hi"]
    unit = f" {meta['unit']}" if meta["unit"] else ""
    if lo is not None and hi is not None:
        return f"in {'(' if meta['lo_open'] else '['}{lo:g}, {hi:g}{')' if meta['hi_open'] else ']'}{unit}"
    if lo is not None:
        return f"{'>' if meta['lo_open'] else '>='} {lo:g}{unit}"
    if hi is not None:
        return f"{'<' if meta['hi_open'] else '<='} {hi:g}{unit}"
    return ""


def _check_range(x, meta, path):
    lo, hi = meta["lo"], meta["hi"]
    bad = (lo is not None and (x <= lo if meta["lo_open"] else x < lo)) or \
        (hi is not None and (x >= hi if meta["hi_open"] else x > hi))
    if bad:
        raise _Problem(path, f"must be {_range_text(meta)}, got {x:g}")


def _pair(value, path, what):
    if not isinstance(value, list) or len(value) != 2:
        raise _Problem(path, f"expected {what} [x, y], got {_show(value)}")
    return tuple(_number(v, f"{path}[{i}]") for i, v in enumerate(value))


def _color(value, path):
    ok = isinstance(value, str) and value.startswith("#") and len(value) in (7, 9)
    if ok:
        try:
            int(value[1:], 16)
        except ValueError:
            ok = False
    if not ok:
        raise _Problem(path, f"expected a colour '#rrggbb' or '#rrggbbaa', got {_show(value)}")
    return value.lower()


def _convert(value, meta, path, ctx):
    kind = meta["kind"]
    if kind in ("float", "int"):
        x = _number(value, path, integer=kind == "int")
        _check_range(x, meta, path)
        return x
    if kind == "bool":
        if not isinstance(value, bool):
            raise _Problem(path, f"expected true or false, got {_show(value)}")
        return value
    if kind == "str":
        if not isinstance(value, str):
            raise _Problem(path, f"expected a string, got {_show(value)}")
        if meta["choices"] and value not in meta["choices"]:
            close = difflib.get_close_matches(value, meta["choices"], n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise _Problem(path, f"unknown value {value!r}; {hint}allowed: {', '.join(meta['choices'])}")
        return value
    if kind == "vec2":
        return _pair(value, path, "two numbers")
    if kind == "size2":
        p = _pair(value, path, "two numbers")
        if min(p) <= 0:
            raise _Problem(path, f"both must be > 0 {meta['unit']}, got [{p[0]:g}, {p[1]:g}]")
        return p
    if kind == "quad":
        if not isinstance(value, list) or len(value) != 4:
            raise _Problem(path, f"expected four corners [[x, y], ...], got {_show(value)}")
        return tuple(_pair(v, f"{path}[{i}]", "two numbers") for i, v in enumerate(value))
    if kind == "points":
        if not isinstance(value, list) or len(value) < 3:
            raise _Problem(path, f"expected at least three points [[x, y], ...], got {_show(value)}")
        return tuple(_pair(v, f"{path}[{i}]", "two numbers") for i, v in enumerate(value))
    if kind == "loops":
        if not isinstance(value, list):
            raise _Problem(path, f"expected a list of outlines [[[x, y], ...], ...], got {_show(value)}")
        return tuple(_convert(v, {**meta, "kind": "points"}, f"{path}[{i}]", ctx) for i, v in enumerate(value))
    if kind == "triangles":
        if not isinstance(value, list) or len(value) < 1:
            raise _Problem(path, f"expected triangles [[i, j, k], ...], got {_show(value)}")
        out = []
        for i, t in enumerate(value):
            if not isinstance(t, list) or len(t) != 3:
                raise _Problem(f"{path}[{i}]", f"expected three vertex indices, got {_show(t)}")
            out.append(tuple(_number(v, f"{path}[{i}][{k}]", integer=True) for k, v in enumerate(t)))
        return tuple(out)
    if kind == "box2":
        if not isinstance(value, list) or len(value) != 2:
            raise _Problem(path, f"expected two corners [[x0, y0], [x1, y1]], got {_show(value)}")
        a, b = (_pair(v, f"{path}[{i}]", "two numbers") for i, v in enumerate(value))
        if a[0] == b[0] or a[1] == b[1]:
            raise _Problem(path, f"the box must have a width and a height, got [[{a[0]:g}, {a[1]:g}], "
                                 f"[{b[0]:g}, {b[1]:g}]]")
        return (a, b)
    if kind == "indices":
        if not isinstance(value, list):
            raise _Problem(path, f"expected vertex indices [i, j, ...], got {_show(value)}")
        out = tuple(_number(v, f"{path}[{i}]", integer=True) for i, v in enumerate(value))
        for i, v in enumerate(out):
            if v < 0:
                raise _Problem(f"{path}[{i}]", f"vertex indices must be >= 0, got {v}")
        return out
    if kind == "color":
        return _color(value, path)
    if kind == "background":
        # a file names colours as strings only ('#rrggbb'), as its other colour keys do
        name = value.strip().lower() if isinstance(value, str) else None
        try:
            if name is not None and check_background(name):
                return name
        except ValueError:
            pass
        close = difflib.get_close_matches(name or "", meta["choices"], n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise _Problem(path, f"unknown value {_show(value)}; {hint}allowed: {', '.join(meta['choices'])} or a colour "
                             f"'#rrggbb'")
    if kind == "colors2":
        if not isinstance(value, list) or len(value) != 2:
            raise _Problem(path, f"expected two colours ['#rrggbb', '#rrggbb'], got {_show(value)}")
        return tuple(_color(v, f"{path}[{i}]") for i, v in enumerate(value))
    if kind == "file":
        if not isinstance(value, str) or not value:
            raise _Problem(path, f"expected a built-in texture name or an image path, got {_show(value)}")
        return ctx["resolve"](value, path)
    if kind == "picture":
        if not isinstance(value, str) or not value:
            raise _Problem(path, f"expected a built-in picture name or an image path, got {_show(value)}")
        return ctx["resolve_picture"](value, path)
    raise AssertionError(kind)  # pragma: no cover


def _table(cls, data, path, ctx, *, skip=()):
    if not isinstance(data, dict):
        raise _Problem(path, f"expected a table, got {_show(data)}")
    known = {f.name: f for f in fields(cls) if f.metadata}
    for key in data:
        if key not in known and key not in skip:
            raise _Problem(f"{path}.{key}" if path else key, _suggest(key, list(known)))
    values = {}
    for name, f in known.items():
        if name in data:
            values[name] = _convert(data[name], f.metadata, f"{path}.{name}", ctx)
    return cls(**values)


def _kind(data, path, kinds: dict, default: str):
    """The shape a ``[[body]]`` or ``[[collider]]`` table names (``default`` if none) and its spec class."""
    if not isinstance(data, dict):
        raise _Problem(path, f"expected a table, got {_show(data)}")
    shape = data.get("shape", default)
    if shape not in kinds:
        close = difflib.get_close_matches(str(shape), list(kinds), n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise _Problem(f"{path}.shape", f"unknown value {shape!r}; {hint}allowed: {', '.join(kinds)}")
    return shape, kinds[shape]


def _body(data, path, ctx):
    _, cls = _kind(data, path, BODY_KINDS, "box")
    body = _table(cls, data, path, ctx)
    if isinstance(body, MeshBody):
        n = len(body.vertices)
        if n == 0 or not body.triangles:
            raise _Problem(path, "a mesh body needs vertices and triangles")
        for i, t in enumerate(body.triangles):
            if min(t) < 0 or max(t) >= n:
                raise _Problem(f"{path}.triangles[{i}]", f"indices must lie in [0, {n - 1}], got {list(t)}")
        if body.uv is not None and len(body.uv) != n:
            raise _Problem(f"{path}.uv", f"expected one (u, v) per vertex ({n}), got {len(body.uv)}")
    return body


def _collider(data, path, ctx):
    shape, cls = _kind(data, path, COLLIDER_KINDS, "rect")
    shared = [f.name for f in fields(ColliderCommon)]
    own = [f.name for f in fields(cls) if f.name not in shared] + shared
    for key in data:
        # a key of another shape is most likely a shape left out or mistyped: say whose it is not
        if key not in own and any(key in {f.name for f in fields(other)} for other in COLLIDER_KINDS.values()):
            raise _Problem(f"{path}.{key}", f'not a field of shape "{shape}"; its fields: {", ".join(own)}')
    collider = _table(cls, data, path, ctx)
    for key, what in _COLLIDER_NEEDS.get(shape, {}).items():
        if getattr(collider, key) in (None, ()):
            raise _Problem(f"{path}.{key}", f'missing: a "{shape}" collider needs {key}, {what}')
    return collider


class MaterialKeyError(ValueError):
    """A material key that cannot be used with the others; ``key`` names it (None: the table)."""

    def __init__(self, key, message: str):
        super().__init__(message)
        self.key = key


def with_springs(scene: "Scene") -> "Scene":
    """The same scene with every body made of the original's springs (its model and
    finite-element keys dropped; ``[physics]``'s stiffness, damping and mass, or the body's
    own, apply; tearing, plasticity and the stretch limit stay, as springs have them too).

    The switch behind ``deforma run --springs`` and ``deforma view --springs``.

    Examples
    --------
    >>> from deforma.scene import load
    >>> s = with_springs(load("sample"))
    >>> s.physics.material, s.body[0].material
    ('springs', None)
    """
    from dataclasses import replace

    physics = replace(scene.physics, material="springs", youngs_modulus=None, poisson_ratio=None, density=None,
                      material_damping=0.0)
    # the behaviours (tearing, plasticity, stretch limit) work for springs too: they stay
    model_keys = [k for k in MATERIAL_KEYS if k not in BEHAVIOUR_KEYS]
    bodies = tuple(replace(b, **dict.fromkeys(model_keys)) for b in scene.body)
    return replace(scene, physics=physics, body=bodies)


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
    springs = [k for k in _SPRING_KEYS if body is not None and getattr(body, k) is not None]
    if model != "springs" and springs:
        where = "" if "material" in own else " (physics.material)"
        raise MaterialKeyError(springs[0], f"the body is made of {model!r} finite elements{where}, whose mass is "
                                           f"density * area and whose elasticity is youngs_modulus and "
                                           f"poisson_ratio: remove {springs[0]}, or set material = \"springs\"")
    if body is not None and not own:
        return None
    if model == "springs":
        fem = [k for k in _FEM_KEYWORD if k in own]
        if fem:
            raise MaterialKeyError(fem[0], f"the 'springs' material takes no {fem[0]} (its springs use mass, "
                                           f"stiffness and damping): set material = \"corotated\" or "
                                           f"\"neo-hookean\" too, or remove {fem[0]}")
        return {"model": "springs", **_behaviour_settings(physics, own)}
    values = {k: own.get(k, getattr(physics, k)) for k in _FEM_KEYWORD}
    missing = [k for k in _FEM_NEEDS if values[k] is None]
    if missing:
        where = "on the body or in [physics]" if body is not None else "in [physics]"
        raise MaterialKeyError(None, f"the {model!r} material needs {', '.join(missing)} (E in Pa, nu in (-1, 0.5), "
                                     f"density in kg/m^2): set {'it' if len(missing) == 1 else 'them'} {where}")
    out = {"model": model}
    out.update((_FEM_KEYWORD[k], float(v)) for k, v in values.items())
    out.update(_behaviour_settings(physics, own))
    return out


def _behaviour_settings(physics: PhysicsSettings, own: dict) -> dict:
    """The behaviour keywords that are set (the body's, else ``[physics]``'s), defaults left out."""
    out = {}
    for k in BEHAVIOUR_KEYS:
        v = own.get(k, getattr(physics, k))
        if v is not None and v != _BEHAVIOUR_DEFAULT[k]:
            out[k] = float(v)
    return out


def _check_materials(values: dict) -> None:
    """Refuse material keys that mean nothing together (see :func:`material_settings`)."""
    physics = values.get("physics", PhysicsSettings())
    try:
        material_settings(physics)
    except MaterialKeyError as e:
        raise _Problem("physics" if e.key is None else f"physics.{e.key}", str(e)) from None
    fem_bodies = 0
    for i, body in enumerate(values.get("body", ())):
        try:
            own = material_settings(physics, body)
        except MaterialKeyError as e:
            raise _Problem(f"body[{i}]" if e.key is None else f"body[{i}].{e.key}", str(e)) from None
        fem_bodies += own is not None and own["model"] != "springs"
    if physics.material == "springs" and not fem_bodies:
        # finite-element defaults that no body uses are most likely a forgotten material key
        unused = [k for k in _FEM_KEYWORD if getattr(physics, k) not in (None, 0.0)]
        if unused:
            raise _Problem(f"physics.{unused[0]}", "no body is made of finite elements to use it (physics.material "
                                                   "is 'springs'): set material = \"corotated\" or \"neo-hookean\" "
                                                   "here or on a body, or remove it")


def _check_pull(pull: Pull, path: str) -> None:
    """A pull's keys that only mean something together: where it grabs, and times in order."""
    if pull.at is None:
        raise _Problem(f"{path}.at", "missing: where the pull grabs the body, [x, y] in metres")
    end = pull.start if pull.end is None else pull.end
    if end < pull.start:
        raise _Problem(f"{path}.end", f"must be >= start ({pull.start:g} s), got {end:g}")
    if pull.end is not None and pull.end > pull.start and pull.to is None:
        raise _Problem(f"{path}.to", "missing: where the target moves by end, [x, y] in metres (or remove end)")
    if pull.release is not None and pull.release < end:
        raise _Problem(f"{path}.release", f"must be >= {'end' if pull.end is not None else 'start'} ({end:g} s), "
                                          f"got {pull.release:g}")


def _check_integrator(name: str, path: str) -> None:
    # the registry, not a fixed list: an integrator registered by the user is allowed too
    from ..physics import available_integrators

    names = available_integrators()
    if name not in names:
        close = difflib.get_close_matches(name, names, n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise _Problem(path, f"unknown value {name!r}; {hint}allowed: {', '.join(names)}")


def parse_scene(data: dict, *, source: str = "<scene>", base_dir=None) -> Scene:
    """Validate a TOML document (as a dict) and make a :class:`Scene`.

    Parameters
    ----------
    data : dict
        What ``tomllib`` read.
    source : str, keyword-only
        The file name used in error messages.
    base_dir : path, keyword-only
        Folder that relative texture paths are resolved against; default the current folder.

    Raises
    ------
    SceneError
        On the first problem: ``"<source>: <key path>: <what is wrong>; allowed: ..."``.

    Examples
    --------
    >>> s = parse_scene({"physics": {"dt": 0.001}, "collider": [{"size": [4, 1]}]})
    >>> s.physics.dt, s.collider[0].size
    (0.001, (4.0, 1.0))
    >>> parse_scene({"physics": {"stifness": 10}}, source="my.toml")
    Traceback (most recent call last):
    ...
    deforma.scene.schema.SceneError: my.toml: physics.stifness: unknown key; did you mean 'stiffness'? allowed: dt, ...
    """
    from .assets import resolve_picture, resolve_texture

    base = Path(base_dir) if base_dir is not None else Path.cwd()

    def resolver(function):
        def resolve(value, path):
            try:
                return function(value, base_dir=base)
            except ValueError as e:
                raise _Problem(path, str(e)) from None
        return resolve

    ctx = {"resolve": resolver(resolve_texture), "resolve_picture": resolver(resolve_picture)}
    try:
        if not isinstance(data, dict):
            raise _Problem("", f"expected a table, got {_show(data)}")
        allowed = list(SECTIONS) + list(ARRAYS)
        for key in data:
            if key not in allowed:
                raise _Problem(key, _suggest(key, allowed))
        values = {}
        for name, cls in SECTIONS.items():
            if name in data:
                values[name] = _table(cls, data[name], name, ctx)
        if "physics" in values:
            _check_integrator(values["physics"].integrator, "physics.integrator")
        for name, cls in ARRAYS.items():
            if name in data:
                items = data[name]
                if not isinstance(items, list):
                    raise _Problem(name, f"expected an array of tables ([[{name}]]), got {_show(items)}")
                out = []
                for i, item in enumerate(items):
                    p = f"{name}[{i}]"
                    if name == "body":
                        out.append(_body(item, p, ctx))
                    elif name == "collider":
                        out.append(_collider(item, p, ctx))
                    else:
                        out.append(_table(cls, item, p, ctx))
                    if name == "pull":
                        _check_pull(out[-1], p)
                values[name] = tuple(out)
        _check_materials(values)
    except _Problem as e:
        where = f"{e.path}: " if e.path else ""
        raise SceneError(f"{source}: {where}{e.message}") from None
    return Scene(**values, path=None)


# -- writing -----------------------------------------------------------------------------------
def _plain(value):
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


def _record(obj, *, base_dir, always=()) -> dict:
    from .assets import picture_reference, texture_reference

    out = {}
    defaults = type(obj)()
    for f in fields(obj):
        if not f.metadata:
            continue
        v = getattr(obj, f.name)
        if v is None:
            continue
        if f.name not in always and v == getattr(defaults, f.name):
            continue
        if f.metadata["kind"] == "file":
            v = texture_reference(v, base_dir=base_dir)
        elif f.metadata["kind"] == "picture":
            v = picture_reference(v, base_dir=base_dir)
        out[f.name] = _plain(v)
    return out


def scene_to_dict(scene: Scene, *, base_dir=None, full: bool = True) -> dict:
    """The TOML document for ``scene`` (a dict for ``tomli_w``).

    With ``full`` every key is written, defaults included, so a file states everything; else
    only what differs from the defaults. Relative texture paths are written relative to
    ``base_dir`` (the folder of the file being written).
    """
    base = Path(base_dir) if base_dir is not None else Path.cwd()
    doc = {}
    for name in SECTIONS:
        section = getattr(scene, name)
        keep = [f.name for f in fields(section)] if full else ()
        rec = _record(section, base_dir=base, always=keep)
        if rec:
            doc[name] = rec
    for name in ARRAYS:
        items = getattr(scene, name)
        if items:
            recs = []
            for it in items:
                keep = [f.name for f in fields(it)] if full else ()
                rec = _record(it, base_dir=base, always=keep)
                common = next((c for c in (BodyPhysics, ColliderCommon) if isinstance(it, c)), None)
                if common is not None:  # shape, the kind's own keys, then the shared ones
                    shared = [f.name for f in fields(common)]
                    rec = {"shape": it.shape, **{k: v for k, v in rec.items() if k != "shape" and k not in shared},
                           **{k: rec[k] for k in shared if k in rec}}
                recs.append(rec)
            doc[name] = recs
    return doc


def relative_path(target: str, base_dir: Path) -> str:
    """``target`` relative to ``base_dir`` when that is short and sensible, else absolute."""
    try:
        rel = os.path.relpath(target, base_dir)
    except ValueError:  # different drives on Windows
        return target
    return rel if rel.count("..") <= 3 else target

"""A World from a Scene: its bodies' meshes, materials and pins, and its colliders.

The world does not know where its meshes came from, so the scene layer remembers it: each
world built here is registered (weakly) with its scene and the spec of every body and
collider (:func:`build_record`). :func:`deforma.scene.scene_of` then reads the world's current
parameters and puts them together with what only the scene knows (mesh recipes, colours,
camera, run length).

Examples
--------
>>> from deforma.scene import load
>>> world = build(load("sample"))
>>> len(world.bodies), build_record(world).scene.scene.name
(1, 'sample')
"""

from __future__ import annotations

import os
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .assets import builtin_patterns, picture_file
from .tables import (BoxBody, CircleCollider, ColliderSpec, ImageBody, ImageCollider, MaterialKeyError, MeshBody,
                     PolygonCollider, SceneError, SegmentCollider, material_settings)

if TYPE_CHECKING:  # a Scene builds its world with this module
    from .schema import Scene

__all__ = ["BuildRecord", "box_mask", "build", "build_record", "make_colliders", "make_mesh", "pin_mask"]


@dataclass
class BuildRecord:
    """What a world built by :func:`build` was built from, which the world itself does not know."""

    scene: Scene
    bodies: list      # [(weakref to Body, body spec)]
    colliders: list   # [(collider, its spec, (center, angle) as built)]; an image spec once per polygon


_REGISTRY: "weakref.WeakKeyDictionary[object, BuildRecord]" = weakref.WeakKeyDictionary()


def build_record(world) -> BuildRecord | None:
    """The record of ``world`` if :func:`build` made it (None for a world made in code)."""
    return _REGISTRY.get(world)


def make_mesh(spec):
    """The :class:`deforma.mesh.Mesh` a body spec describes (before it is placed)."""
    from .. import mesh as meshes

    if isinstance(spec, BoxBody):
        return meshes.box(spec.corners, detail=spec.detail, edges=spec.edges)
    if isinstance(spec, ImageBody):
        if spec.source in builtin_patterns():
            raise ValueError(f"source {spec.source!r} is a pattern, a picture with no shape to mesh: draw it with "
                             f"texture = {spec.source!r} on a body; source takes one of "
                             f"{', '.join(map(repr, meshes.image.BUILTIN_TEXTURES))} or an image file")
        # a built-in name or an absolute path: from_image takes either
        return meshes.from_image(spec.source, resolution=spec.resolution, detect_edges=spec.detect_edges,
                                 edge_step=spec.edge_step, scale=spec.scale, background=spec.background,
                                 threshold=spec.threshold)
    if isinstance(spec, MeshBody):
        return meshes.Mesh(np.array(spec.vertices, float), np.array(spec.triangles, np.int32),
                           uv=None if spec.uv is None else np.array(spec.uv, float))
    raise TypeError(f"not a body spec: {spec!r}")


def _material(settings, *, world=False):
    from ..physics import Material

    if settings is None or (world and settings == {"model": "springs"}):
        return None  # a body following the world; a world of the seed's plain springs
    return Material(**settings)


def box_mask(box, positions) -> np.ndarray:
    """(N,) bool: the ``positions`` inside ``box``, two opposite corners ``((x0, y0), (x1, y1))``
    in metres, edges included (a ``pin`` box).

    Examples
    --------
    >>> box_mask(((1, 1), (0, 0)), np.array([[0.5, 0.5], [1.0, 0.2], [2.0, 0.5]])).tolist()
    [True, True, False]
    """
    (x0, y0), (x1, y1) = box
    x, y = positions[:, 0], positions[:, 1]
    return (x >= min(x0, x1)) & (x <= max(x0, x1)) & (y >= min(y0, y1)) & (y <= max(y0, y1))


def pin_mask(spec, positions) -> np.ndarray:
    """(N,) bool: the vertices a body spec pins (its ``pin`` box and its ``pin_vertices``).

    Parameters
    ----------
    spec : BoxBody, ImageBody or MeshBody
    positions : (N, 2) array
        The body's vertices where the scene places them, metres.

    Raises
    ------
    ValueError
        A ``pin`` box holding no vertex, or a ``pin_vertices`` index past the last vertex;
        the message starts with the key (``pin: ...``).

    Examples
    --------
    >>> import numpy as np
    >>> pin_mask(BoxBody(pin=((-1, -1), (0, 1))), np.array([[-0.5, 0.0], [0.5, 0.0]])).tolist()
    [True, False]
    """
    x = np.asarray(positions, dtype=np.float64)
    mask = np.zeros(len(x), bool)
    if spec.pin is not None:
        inside = box_mask(spec.pin, x)
        if not inside.any():
            (x0, y0), (x1, y1) = spec.pin
            lo, hi = x.min(axis=0), x.max(axis=0)
            raise ValueError(f"pin: the box [[{x0:g}, {y0:g}], [{x1:g}, {y1:g}]] holds no vertex of the body, which "
                             f"spans x {lo[0]:.3g}..{hi[0]:.3g} m, y {lo[1]:.3g}..{hi[1]:.3g} m once placed: move "
                             f"the box over the part to hold")
        mask |= inside
    if spec.pin_vertices:
        # the range first, on Python's integers: 10**30 would overflow an int64 array
        outside = [int(i) for i in spec.pin_vertices if not 0 <= i < len(x)]
        if outside:
            bad = outside[0]
            raise ValueError(f"pin_vertices: vertex index {bad} is out of range; the body has vertices "
                             f"0..{len(x) - 1}")
        mask[np.asarray(spec.pin_vertices, dtype=np.int64)] = True
    return mask


def build(scene: Scene):
    """A new :class:`deforma.World` holding the scene's bodies and colliders.

    Raises
    ------
    SceneError
        If the world or a mesh rejects a value (e.g. a concave box); the message names the
        scene file and the body.
    """
    from ..physics import World

    source = _shown(scene.path)
    p = scene.physics
    try:
        world = World(gravity=p.gravity, dt=p.dt, substeps=p.substeps, mass=p.mass, stiffness=p.stiffness,
                      damping=p.damping, friction=p.friction, static_friction=p.static_friction,
                      grab_strength=scene.interaction.mouse_strength, max_speed=p.max_speed,
                      integrator=p.integrator, contact_thickness=p.contact_thickness, air_drag=p.air_drag,
                      sleep=p.sleep,
                      material=_material(material_settings(p), world=True))
    except MaterialKeyError as e:
        raise SceneError(f"{source}: physics{'' if e.key is None else '.' + e.key}: {e}") from None
    except ValueError as e:
        raise SceneError(f"{source}: physics: {e}") from None
    if p.integrator_options:
        # a file's options were checked when it was read; a Scene made in code is checked here
        try:
            world.integrator_options = dict(p.integrator_options)
        except ValueError as e:  # the message names the option and what it allows
            raise SceneError(f"{source}: physics.integrator_options: {e}") from None
    bodies = []
    # bodies a joint holds to another may overlap it (the links of a chain, at their pins):
    # they join the world without collisions, and take them once their joints are made
    joined = {k for j in scene.joint if j.a is not None and j.b is not None for k in (j.a, j.b)}
    for i, spec in enumerate(scene.body):
        try:
            material = _material(material_settings(p, spec))
            m = make_mesh(spec)
            b = world.add_body(m, position=spec.position, material=material, mass=spec.mass,
                               stiffness=spec.stiffness, damping=spec.damping,
                               collide=spec.collide and i not in joined,
                               self_collision=spec.self_collision, friction=spec.friction,
                               static_friction=spec.static_friction, angle=spec.angle, velocity=spec.velocity,
                               angular_velocity=spec.angular_velocity)
        except MaterialKeyError as e:
            raise SceneError(f"{source}: body[{i}]{'' if e.key is None else '.' + e.key}: {e}") from None
        except ValueError as e:
            raise SceneError(f"{source}: body[{i}]: {e}") from None
        if spec.pressure is not None:
            try:
                b.pressure = spec.pressure
            except ValueError as e:  # e.g. an outline that is not one closed loop
                raise SceneError(f"{source}: body[{i}].pressure: {e}") from None
        try:
            mask = pin_mask(spec, b.positions)
        except ValueError as e:  # the message starts with the key: body[i].pin: ...
            raise SceneError(f"{source}: body[{i}].{e}") from None
        if mask.any():
            b.pin(mask)
        bodies.append((weakref.ref(b), spec))
    colliders = []
    for i, c in enumerate(scene.collider):
        try:
            made = make_colliders(c)
        except ValueError as e:  # the constructors' messages start with the key: "radius must be ..."
            raise SceneError(f"{source}: collider[{i}]: {e}") from None
        for r in made:
            world.add_collider(r)
            colliders.append((r, c, (r.center, r.angle)))
    made = world.bodies
    for i, j in enumerate(scene.joint):
        try:
            world.join(made[j.a], None if j.b is None else made[j.b], at=j.at, kind=j.kind, stiffness=j.stiffness,
                       damping=j.damping, motor_speed=j.motor_speed, max_torque=j.max_torque,
                       break_force=j.break_force)
        except (ValueError, IndexError, TypeError) as e:  # a scene made in code is checked here
            raise SceneError(f"{source}: joint[{i}]: {e}") from None
    for i, spec in enumerate(scene.body):
        if spec.collide and i in joined:
            try:
                made[i].collide = True
            except ValueError as e:  # it overlaps a body no joint holds it to
                raise SceneError(f"{source}: body[{i}]: {e}") from None
    _REGISTRY[world] = BuildRecord(scene, bodies, colliders)
    return world


def make_colliders(spec) -> list:
    """The colliders a ``[[collider]]`` spec describes: one, or for ``shape = "image"`` one
    :class:`deforma.Polygon` per connected piece of the picture.

    Raises
    ------
    ValueError
        What the collider's constructor refuses (a polygon that crosses itself, a picture
        with no foreground), in one line.

    Examples
    --------
    >>> from deforma.scene.schema import SegmentCollider
    >>> make_colliders(SegmentCollider(a=(0.0, 0.0), b=(2.0, 0.0), radius=0.1, angular_velocity=90.0))
    [Segment(a=(0.0, 0.0), b=(2.0, 0.0), radius=0.1, angular_velocity=90)]
    """
    from ..physics import Circle, Polygon, Rect, Segment, colliders_from_image

    common = dict(friction=spec.friction, static_friction=spec.static_friction)
    motion = dict(velocity=spec.velocity, angular_velocity=spec.angular_velocity)
    if isinstance(spec, ColliderSpec):
        return [Rect(spec.center, spec.size, spec.angle, **common, **motion)]
    if isinstance(spec, CircleCollider):
        return [Circle(spec.center, spec.radius, **common, **motion)]
    if isinstance(spec, SegmentCollider):
        return [Segment(spec.a, spec.b, radius=spec.radius, **common, **motion)]
    if isinstance(spec, PolygonCollider):
        p = Polygon(spec.points, holes=spec.holes, **common, **motion)
        p.angle = spec.angle  # about its centroid, the point it was built around
        return [p]
    if isinstance(spec, ImageCollider):
        pieces = colliders_from_image(str(picture_file(spec.source)), scale=spec.scale, position=spec.position,
                                      tolerance=spec.tolerance, background=spec.background,
                                      threshold=spec.threshold, min_area=spec.min_area, **common)
        for p in pieces:
            p.velocity, p.angular_velocity = spec.velocity, spec.angular_velocity
        return pieces
    raise TypeError(f"not a collider spec: {spec!r}")


def _shown(path) -> str:
    """A scene file's path for messages: relative to the working folder when it is inside it
    (as a user types it; the Scene keeps the absolute path to find its pictures), else as is."""
    if path is None:
        return "<scene>"
    try:
        rel = os.path.relpath(path)
    except ValueError:  # another drive (Windows)
        return str(path)
    return str(path) if rel.split(os.sep, 1)[0] == os.pardir else rel  # outside it ("..foo.toml" is inside)

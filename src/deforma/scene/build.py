"""Scene files and worlds: load a scene (:func:`load`, :func:`load_scene`), read the scene of a
(changed) world back (:func:`scene_of`) and save it (:func:`save_scene`).

The world itself is made by :func:`deforma.scene.construct.build` (``scene.build()``), which
remembers what each world was built from; :func:`scene_of` reads that record.
"""

from __future__ import annotations

import math
import re
import sys
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .assets import scene_path
from .construct import box_mask, build, build_record, pin_mask
from .schema import Scene, parse_scene, scene_to_dict
from .tables import (BEHAVIOUR_KEYS, MATERIAL_KEYS, CircleCollider, ColliderSpec, InteractionSettings, JointSpec,
                     MeshBody, PhysicsSettings, PolygonCollider, SceneError, SegmentCollider, material_settings)

if TYPE_CHECKING:
    import os

    from ..physics import Collider, World
    from .tables import BoxBody, ImageBody

try:  # Python >= 3.11
    import tomllib
except ImportError:  # pragma: no cover - Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

__all__ = ["body_specs", "build", "collider_spec", "load", "load_scene", "save_scene", "scene_of"]


#: Deepest nesting of arrays and tables a scene needs (a polygon collider's holes are
#: [[collider]] > holes > [[x, y], ...] > [x, y]); only named when a file is nested past what
#: the reader handles.
SCENE_MAX_NESTING = 5


def load(name_or_path: str | os.PathLike[str]) -> Scene:
    """Read and validate a scene: a built-in name (``deforma scenes`` lists them) or a ``.toml`` path.

    Raises
    ------
    SceneError
        Unknown name, unreadable file, invalid TOML or an invalid value; one line naming the
        file, the key and what is allowed.

    Examples
    --------
    >>> import deforma.scene
    >>> s = deforma.scene.load("sample")
    >>> s.scene.name, len(s.body), len(s.collider)
    ('sample', 1, 1)
    """
    try:
        path = scene_path(name_or_path)
    except ValueError as e:
        raise SceneError(str(e)) from None
    shown = str(name_or_path)
    try:
        text = path.read_bytes().decode("utf-8")
    except OSError as e:
        raise SceneError(f"{shown}: cannot read the file ({e.strerror or e})") from None
    except UnicodeDecodeError:
        raise SceneError(f"{shown}: not a text file (a scene is TOML in UTF-8)") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{shown}: invalid TOML: {e}") from None
    except ValueError:  # an integer past Python's 4300 digits: the reader's int() refuses it
        raise SceneError(f"{shown}: invalid TOML: an integer of more than {sys.get_int_max_str_digits()} digits "
                         f"(every number in a scene is far smaller)") from None
    except RecursionError:
        # arrays or tables nested hundreds deep: the TOML reader recurses once per level
        raise SceneError(f"{shown}: invalid TOML: arrays or tables nested too deep for the reader "
                         f"(a scene needs at most {SCENE_MAX_NESTING} levels)") from None
    try:
        scene = parse_scene(data, source=shown, base_dir=path.resolve().parent)
    except RecursionError:
        raise SceneError(f"{shown}: values nested too deep (a scene needs at most {SCENE_MAX_NESTING} "
                         f"levels)") from None
    return replace(scene, path=str(path.resolve()))


def load_scene(name_or_path: str | os.PathLike[str]) -> World:
    """A :class:`deforma.World` from a built-in scene name or a ``.toml`` file.

    Parameters
    ----------
    name_or_path : str or path
        ``"sample"``, ``"demo"``, ... (``deforma scenes`` lists them) or a scene file.

    Returns
    -------
    World
        Ready to step; :func:`deforma.scene.scene_of` gives its camera, colours and run length.

    Raises
    ------
    SceneError
        A ``ValueError`` naming the file, the key path and what is allowed.

    Examples
    --------
    >>> import deforma
    >>> world = deforma.load_scene("sample")
    >>> len(world.bodies), len(world.colliders)
    (1, 1)
    """
    return build(load(name_or_path))


def _integrator_option_keys(world) -> tuple:
    """``[physics.integrator_options]`` for the world as it is now: the options that differ
    from the integrator's defaults (a saved scene states only what was chosen)."""
    from ..physics.integrators import make_integrator

    defaults = make_integrator(world.integrator).options
    return tuple((k, v) for k, v in world.integrator_options.items() if v != defaults[k])


def _material_keys(world, recorded: PhysicsSettings) -> dict:
    """``[physics]``'s material keys for the world as it is now."""
    m = world.material
    behaviours = _behaviour_keys(m)
    if m is not None and m.is_rigid:  # density alone ([physics]'s elastic keys are no body's)
        return dict(material="rigid", youngs_modulus=None, poisson_ratio=None, density=m.density,
                    material_damping=0.0, plane="stress", **behaviours)
    if m is not None and m.is_fem:
        return dict(material=m.model, youngs_modulus=m.youngs_modulus, poisson_ratio=m.poisson_ratio,
                    density=m.density, material_damping=m.damping, plane=m.plane, **behaviours)
    # A springs world: finite-element keys in [physics] are defaults for bodies that choose a
    # finite-element model. The world does not hold them, so keep the scene's while some body
    # is made of elements (a file must not hold defaults that no body uses: load refuses it).
    keep = any(b.is_fem for b in world.bodies)
    return dict(material="springs",
                youngs_modulus=recorded.youngs_modulus if keep else None,
                poisson_ratio=recorded.poisson_ratio if keep else None,
                density=recorded.density if keep else None,
                material_damping=recorded.material_damping if keep else 0.0,
                plane=recorded.plane if keep else "stress", **behaviours)


def _behaviour_keys(material) -> dict:
    """The behaviour keys (tear_strain, ...) of ``material`` (None: the seed's plain springs)."""
    if material is None:
        return dict(tear_strain=None, yield_strain=None, plastic_rate=1.0, max_stretch=None)
    return {k: getattr(material, k) for k in BEHAVIOUR_KEYS}


def _expected_material(physics: PhysicsSettings, spec):
    """The material ``spec`` gives its body under ``physics`` (None if the spec cannot be used)."""
    from ..physics import Material

    try:
        own = material_settings(physics, spec)
        settings = own if own is not None else material_settings(physics)
        return Material(**settings)  # type: ignore[arg-type]  # material_settings(physics) is a table
    except ValueError:
        return None


def _body_material_keys(material) -> dict:
    """A body spec's material keys that give it exactly ``material`` whatever [physics] says."""
    behaviours = _behaviour_keys(material)
    if material.is_rigid:
        return dict(material="rigid", youngs_modulus=None, poisson_ratio=None, density=material.density,
                    material_damping=None, plane=None, **dict.fromkeys(behaviours))
    if not material.is_fem:
        return dict(material="springs", youngs_modulus=None, poisson_ratio=None, density=None,
                    material_damping=None, plane=None, **behaviours)
    return dict(material=material.model, youngs_modulus=material.youngs_modulus,
                poisson_ratio=material.poisson_ratio, density=material.density, material_damping=material.damping,
                plane=material.plane, **behaviours)


def _pin_keys(spec, body) -> dict:
    """The spec's pin keys for the body's pins now: the spec's own if they still say it, else
    its ``pin`` box alone if that does, else the pinned vertices by number."""
    mask = body.pinned
    rest = body.topology.rest_positions  # where the scene placed the body: what a box is tested on
    try:
        if np.array_equal(mask, pin_mask(spec, rest)):
            return {}
    except ValueError:  # the spec's pins do not fit this body (e.g. a mesh made in code)
        pass
    if spec.pin is not None and np.array_equal(mask, box_mask(spec.pin, rest)):
        return dict(pin_vertices=None)
    pinned = tuple(int(i) for i in np.flatnonzero(mask))
    return dict(pin=None, pin_vertices=pinned or None)


def scene_of(world: World) -> Scene:
    """The scene of ``world`` as it is now: its current parameters, bodies and colliders.

    Bodies made from a scene keep their recipe (box or image parameters, colour, texture);
    other bodies are written as ``shape = "mesh"`` with their rest vertices. Positions are
    the starting positions: a scene describes a setup, not a moment of a run.

    Materials: the world's material goes to ``[physics]``; a body whose material differs from
    what its spec and ``[physics]`` give it gets all ten material keys of its own (so a body
    whose own material equals the world's is written as following the world). A
    finite-element body has no spring mass, stiffness or damping to write. Pins: the spec's
    ``pin`` box is kept while the body's pinned vertices are exactly those inside it;
    otherwise they are written as ``pin_vertices``. Integrator options: those that differ from
    the integrator's defaults (``physics.integrator_options``; none when all are defaults).

    Examples
    --------
    >>> import deforma
    >>> w = deforma.World(integrator="implicit-euler", integrator_options={"iterations": 5})
    >>> scene_of(w).physics.integrator_options
    (('iterations', 5),)
    """
    rec = build_record(world)
    scene = rec.scene if rec is not None else Scene()
    physics = PhysicsSettings(
        dt=float(world.dt), substeps="auto" if world.auto_substeps else int(world.substeps),
        gravity=tuple(float(g) for g in world.gravity),
        damping=float(world.damping), mass=float(world.mass), stiffness=float(world.stiffness),
        friction=float(world.friction), static_friction=float(world.static_friction),
        max_speed=float(world.max_speed), integrator=world.integrator,
        contact_thickness=None if world.contact_thickness is None else float(world.contact_thickness),
        air_drag=float(world.air_drag), sleep=bool(world.sleep), integrator_options=_integrator_option_keys(world),
        **_material_keys(world, scene.physics),
    )
    interaction = InteractionSettings(explosive_force=scene.interaction.explosive_force,
                                      mouse_strength=float(world.grab_strength))
    known = {}
    if rec is not None:
        for ref, spec in rec.bodies:
            b = ref()
            if b is not None:
                known[id(b)] = spec
    bodies = []
    for b in world.bodies:
        spec = known.get(id(b))
        if spec is None:
            m = b.mesh
            uv = getattr(m, "uv", None)
            spec = MeshBody(vertices=tuple(map(tuple, b.topology.rest_positions.tolist())),
                            triangles=tuple(map(tuple, np.asarray(b.triangles).tolist())),
                            uv=None if uv is None else tuple(map(tuple, np.asarray(uv).tolist())))
        overrides: dict[str, Any] = {}
        fem = b.is_fem
        for name in ("mass", "stiffness", "damping", "friction", "static_friction"):
            if fem and name in ("mass", "stiffness", "damping"):
                # elements take their mass from the density and have no springs
                if getattr(spec, name) is not None:
                    overrides[name] = None
                continue
            expected = getattr(spec, name)
            expected = getattr(world, name) if expected is None else expected
            actual = float(getattr(b, name))
            if actual != expected:
                overrides[name] = actual
        for name in ("collide", "self_collision", "pressure"):
            if getattr(b, name) != getattr(spec, name):
                overrides[name] = getattr(b, name)
        spec = replace(spec, **overrides) if overrides else spec
        if _expected_material(physics, spec) != b.material:
            following = replace(spec, **dict.fromkeys(MATERIAL_KEYS))
            # a body that now has the world's material is written as following it
            keys = MATERIAL_KEYS if _expected_material(physics, following) == b.material else ()
            spec = replace(spec, **(dict.fromkeys(keys) or _body_material_keys(b.material)))
        pins = _pin_keys(spec, b)
        bodies.append(replace(spec, **pins) if pins else spec)
    built = {id(r): (spec, pose) for r, spec, pose in (rec.colliders if rec is not None else [])}
    colliders = tuple(collider_spec(r, *built.get(id(r), (None, None))) for r in world.colliders)
    joints = tuple(JointSpec(a=j.a._index, b=None if j.b is None else j.b._index, at=tuple(j.anchor), kind=j.kind,
                             stiffness=j.stiffness, damping=j.damping if j.kind == "spring" else None,
                             motor_speed=j.motor_speed, max_torque=j.max_torque, break_force=j.break_force)
                   for j in world.joints)
    return replace(scene, physics=physics, interaction=interaction, body=tuple(bodies), collider=colliders,
                   joint=joints)


def _xy(p, digits=None) -> tuple:
    return tuple(float(v) if digits is None else round(float(v), digits) for v in p)


def _loop(points) -> tuple:
    # nanometres: corners computed from a pose (or traced from pixels) carry float noise
    # (3.1799999999999997) that would only make the file harder to read
    return tuple(_xy(p, 9) for p in np.asarray(points).tolist())


def collider_spec(collider: Collider, spec: ColliderSpec | None = None,
                  pose: tuple[Any, float] | None = None
                  ) -> ColliderSpec | CircleCollider | SegmentCollider | PolygonCollider:
    """The ``[[collider]]`` spec of ``collider``: its motion and friction now, at its
    :attr:`~deforma.physics.colliders.shapes.Collider.origin` (where it was put, before its own motion
    moved it: a saved moving collider starts where it started, as bodies do).

    One spec per collider: the pieces of an image collider are written as polygons (with the
    image's colour), so that a saved file needs no picture and lists the colliders as the
    world does. ``spec`` and ``pose`` (``(center, angle)`` when built) are what the scene said:
    a segment or polygon still at the pose it was built at keeps the spec's own points (a polygon
    its ``angle``); one given another pose is written there (corners turned, ``angle = 0``).

    Examples
    --------
    >>> import deforma
    >>> collider_spec(deforma.Circle((1.0, 2.0), 0.5, angular_velocity=30.0))
    CircleCollider(velocity=(0.0, 0.0), angular_velocity=30.0, friction=None, static_friction=None, color=None, \
shape='circle', center=(1.0, 2.0), radius=0.5)
    """
    from ..physics import Circle, Polygon, Rect, Segment

    collider = collider.at_origin()
    common: dict[str, Any] = dict(velocity=_xy(collider.velocity), angular_velocity=float(collider.angular_velocity),
                                  friction=collider.friction, static_friction=collider.static_friction,
                                  color=None if spec is None else spec.color)
    still = pose is not None and (collider.center, collider.angle) == pose
    if isinstance(collider, Rect):
        # a turning rect's angle grows without end; a file takes [-360, 360]
        angle = float(collider.angle)
        return ColliderSpec(center=_xy(collider.center), size=_xy(collider.size),
                            angle=angle if abs(angle) <= 360 else math.fmod(angle, 360.0), **common)
    if isinstance(collider, Circle):
        return CircleCollider(center=_xy(collider.center), radius=float(collider.radius), **common)
    if isinstance(collider, Segment):
        if still and isinstance(spec, SegmentCollider):
            return replace(spec, radius=float(collider.radius), **common)
        return SegmentCollider(a=_xy(collider.a, 9), b=_xy(collider.b, 9), radius=float(collider.radius), **common)
    if isinstance(collider, Polygon):
        if still and isinstance(spec, PolygonCollider):
            return replace(spec, **common)
        return PolygonCollider(points=_loop(collider.points), holes=tuple(_loop(h) for h in collider.holes),
                               **common)
    raise TypeError(f"cannot write a collider of type {type(collider).__name__} to a scene")


def body_specs(world: World) -> list[BoxBody | ImageBody | MeshBody]:
    """The scene spec of each of ``world.bodies`` (a MeshBody for bodies not made from a scene)."""
    return list(scene_of(world).body)


# an array as tomli_w writes it, one element per line ending in a comma, whose elements are
# each on one line (scalars, or arrays already put on one line)
_SCALAR_ARRAY = re.compile(r"\[\n((?:[ ]+[^ \]\n][^\n]*,\n)+)[ ]*\]")  # (an element never starts with ])


def _inline_short_arrays(text: str) -> str:
    r"""Put arrays on one line, innermost first, while the line stays within 80 characters
    (``center = [0.0, 3.6]``, a box's four corners; a mesh's vertices one ``[x, y]`` per line).

    Examples
    --------
    >>> print(_inline_short_arrays("c = [\n    0.0,\n    3.6,\n]\n"))
    c = [0.0, 3.6]
    <BLANKLINE>
    """
    def inline(m):
        items = [line.strip().rstrip(",") for line in m.group(1).splitlines()]
        one = "[" + ", ".join(items) + "]"
        return one if len(one) <= 80 else m.group(0)

    while True:
        new = _SCALAR_ARRAY.sub(inline, text)
        if new == text:
            return text
        text = new


def save_scene(world: World | Scene, path: str | os.PathLike[str]) -> Path:
    """Write ``world`` (or a :class:`Scene`) to a TOML scene file that :func:`load_scene` reads back.

    Every key is written, defaults included, except integrator options, of which only those
    that differ from the integrator's defaults are (``[physics.integrator_options]``, left out
    when there are none). The file appears whole or not at all (it is written beside the target
    and renamed).

    Parameters
    ----------
    world : World or Scene
    path : str or path
        Target ``.toml`` file; its folder must exist.

    Returns
    -------
    Path
        The file written.

    Examples
    --------
    >>> import deforma, tempfile, os
    >>> w = deforma.load_scene("sample")
    >>> w.stiffness = 2000.0
    >>> p = deforma.save_scene(w, os.path.join(tempfile.mkdtemp(), "stiff.toml"))
    >>> deforma.load_scene(p).stiffness
    2000.0
    """
    import tomli_w

    from ..files import failed_write, write_atomic
    from ..physics import World

    if not isinstance(world, (Scene, World)):
        raise TypeError(f"save_scene saves a deforma.World or a deforma.scene.Scene, got {type(world).__name__}")
    scene = world if isinstance(world, Scene) else scene_of(world)
    target = Path(path)
    if target.suffix.lower() != ".toml":
        raise ValueError(f"{path}: a scene file must end in .toml")
    if not target.parent.is_dir():
        raise ValueError(f"{path}: the folder {str(target.parent)!r} does not exist")
    if target.is_dir():
        raise ValueError(f"{path}: is a folder; give the scene file's name, ending in .toml")
    doc = scene_to_dict(scene, base_dir=target.parent.resolve())
    text = "# deforma scene: see docs/scenes.md for every key\n" + _inline_short_arrays(tomli_w.dumps(doc))
    try:  # whole or not at all: a full or read-only disk keeps the earlier file, and says which
        write_atomic(target, lambda f: f.write(text.encode("utf-8")))
    except OSError as e:
        if str(path) in str(e):
            raise
        raise failed_write(path, e) from None
    return target

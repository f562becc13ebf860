"""The scene file format: a :class:`Scene`, read from a TOML document and written back.

A scene is made of tables, the frozen dataclasses of :mod:`deforma.scene.tables` (each field
with its kind, allowed range, unit and a sentence of documentation); :func:`parse_scene`
validates a TOML document against them and :func:`scene_to_dict` writes one back.
``docs/scenes.md`` describes every key.

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
    integrator = "implicit-euler"

    [physics.integrator_options]    # the integrator's own settings; left out: its defaults
    iterations = 5

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
"""

from __future__ import annotations

import difflib
import math
import sys
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

# an image body's background: the rule of deforma.mesh.from_image itself
from ..checks import LIMITS, MAX_COORDINATE, check_box_points, check_option_numbers, digit_count
from ..mesh.image import check_background
from .assets import picture_reference, resolve_picture, resolve_texture, texture_reference
from .construct import build
from .tables import (BEHAVIOUR_KEYS, BODY_KINDS, COLLIDER_KINDS, FEM_DEFAULT, FEM_KEYWORD, MATERIAL_KEYS,
                     MATERIAL_MODELS, BodyPhysics, BoxBody, CameraSettings, CircleCollider, ColliderCommon,
                     ColliderSpec, Event, ImageBody, ImageCollider, InteractionSettings, JointSpec, MaterialKeyError,
                     MeshBody,
                     PhysicsSettings, PolygonCollider, Pull, RectCollider, RunSettings, SceneError, SceneInfo,
                     SegmentCollider, material_settings)

# the tables are part of the file format: they are named here too (deforma.scene.schema.BoxBody)
__all__ = [
    "BEHAVIOUR_KEYS", "MATERIAL_KEYS", "MATERIAL_MODELS", "BodyPhysics", "BoxBody", "CameraSettings",
    "CircleCollider", "ColliderCommon", "ColliderSpec", "Event", "ImageBody", "ImageCollider", "InteractionSettings",
    "JointSpec",
    "MaterialKeyError", "MeshBody", "PhysicsSettings", "PolygonCollider", "Pull", "RectCollider", "RunSettings",
    "Scene", "SceneError", "SceneInfo", "SegmentCollider", "material_settings", "parse_scene", "scene_to_dict",
    "with_springs",
]


class _Problem(Exception):
    """Internal: a problem at a key path, turned into one SceneError by parse_scene."""

    def __init__(self, path: str, message: str):
        super().__init__(message)
        self.path = path
        self.message = message


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
    joint: tuple = ()
    path: str | None = field(default=None, compare=False)

    def build(self):
        """A new :class:`deforma.World` with this scene's bodies and colliders (see :func:`deforma.scene.build`)."""
        return build(self)


SECTIONS = {"scene": SceneInfo, "run": RunSettings, "camera": CameraSettings, "physics": PhysicsSettings,
            "interaction": InteractionSettings}
ARRAYS = {"body": None, "collider": None, "event": Event, "pull": Pull, "joint": JointSpec}

# each shape's required keys and what to say when one is missing
_COLLIDER_NEEDS = {
    "circle": {"radius": "the disc's radius in metres"},
    "polygon": {"points": "the outline [[x, y], ...] in metres"},
    "segment": {"a": "the first end [x, y] in metres", "b": "the second end [x, y] in metres"},
    "image": {"source": "a built-in picture name or an image path"},
}


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
    if isinstance(value, int) and abs(value) > sys.float_info.max:
        # TOML integers have no bound here: 10**400 overflows math.isfinite, the ranges and the physics
        raise _Problem(path, f"expected a finite number, got an integer of {digit_count(value)} digits, "
                             f"too large for a float")
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
    if kind == "substeps":  # an integer, or "auto" (as many as the stable step asks)
        if value == "auto":
            return value
        if isinstance(value, str):
            raise _Problem(path, f"expected an integer in [{meta['lo']:g}, {meta['hi']:g}] or \"auto\", "
                                 f"got {_show(value)}")
        x = _number(value, path, integer=True)
        _check_range(x, meta, path)
        return x
    if kind == "bool":
        if not isinstance(value, bool):
            raise _Problem(path, f"expected true or false, got {_show(value)}")
        return value
    if kind == "str":
        if not isinstance(value, str):
            raise _Problem(path, f"expected a string, got {_show(value)}")
        choices = meta["choices"]() if callable(meta["choices"]) else meta["choices"]
        if choices and value not in choices:
            close = difflib.get_close_matches(value, choices, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise _Problem(path, f"unknown value {value!r}; {hint}allowed: {', '.join(choices)}")
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
    if kind == "options":
        # names and values are the integrator's to check (_check_integrator_options), once
        # the table's integrator is known
        if not isinstance(value, dict):
            raise _Problem(path, f"expected a table of name = value ([{path}]), got {_show(value)}")
        return tuple(value.items())
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
    if not isinstance(shape, str):  # an array or a table is no name (and cannot be looked up: unhashable)
        raise _Problem(f"{path}.shape", f"expected a string, got {_show(shape)}; allowed: {', '.join(kinds)}")
    if shape not in kinds:
        close = difflib.get_close_matches(str(shape), list(kinds), n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise _Problem(f"{path}.shape", f"unknown value {shape!r}; {hint}allowed: {', '.join(kinds)}")
    return shape, kinds[shape]


def _body(data, path, ctx):
    _, cls = _kind(data, path, BODY_KINDS, "box")
    body = _table(cls, data, path, ctx)
    if isinstance(body, BoxBody):
        try:  # the box's point count, from detail and edges, before anything is built
            check_box_points(body.detail, body.edges)
        except ValueError as e:
            raise _Problem(f"{path}.detail", str(e)) from None
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


def with_springs(scene: Scene) -> Scene:
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
    physics = replace(scene.physics, material="springs", youngs_modulus=None, poisson_ratio=None, density=None,
                      material_damping=0.0, plane="stress")
    # the behaviours (tearing, plasticity, stretch limit) work for springs too: they stay
    model_keys = [k for k in MATERIAL_KEYS if k not in BEHAVIOUR_KEYS]
    bodies = tuple(replace(b, **dict.fromkeys(model_keys)) for b in scene.body)
    return replace(scene, physics=physics, body=bodies)


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
        unused = [k for k in FEM_KEYWORD if getattr(physics, k) not in (None, FEM_DEFAULT.get(k, 0.0))]
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
    # what World.grab refuses, said here with the key's path, before the run
    for key in ("at", "to"):
        value = getattr(pull, key)
        if value is not None and max(abs(value[0]), abs(value[1])) > MAX_COORDINATE:
            raise _Problem(f"{path}.{key}", f"must lie within +-{MAX_COORDINATE:g} m, got [{value[0]:g}, {value[1]:g}]")
    for key in ("radius", "strength"):
        value, (lo, hi) = getattr(pull, key), LIMITS[key]
        if value is not None and not lo <= value <= hi:
            raise _Problem(f"{path}.{key}", f"must be in [{lo:g}, {hi:g}] {'m' if key == 'radius' else 'N/m'}, "
                                            f"got {value:g}")


def _check_joint(joint: JointSpec, path: str, n_bodies: int) -> None:
    """A joint's bodies exist and differ, and its point is given ([[body]] comes before
    [[joint]] in ARRAYS, so the bodies are read)."""
    for key in ("a", "b"):
        i = getattr(joint, key)
        if i is None:
            if key == "a":
                raise _Problem(f"{path}.a", "missing: the body the joint holds, its place among the [[body]] tables "
                                            "(from 0)")
            continue
        if i >= n_bodies:
            raise _Problem(f"{path}.{key}", f"there is no body {i}: the scene has {n_bodies} [[body]] table"
                                            f"{'' if n_bodies == 1 else 's'}")
    if joint.a == joint.b:
        raise _Problem(f"{path}.b", f"a joint between body {joint.a} and itself holds nothing: name another body, "
                                    f"or omit b to hold it to the world")
    if joint.at is None:
        raise _Problem(f"{path}.at", "missing: the point both hold, [x, y] in metres")


def _check_integrator(name: str, path: str) -> None:
    # the registry, not a fixed list: an integrator registered by the user is allowed too
    from ..physics import available_integrators

    names = available_integrators()
    if name not in names:
        # every name the text begins ("implicit": both implicit integrators), else the nearest
        close = [n for n in names if isinstance(name, str) and name and n.startswith(name)] \
            or difflib.get_close_matches(name, names, n=1)
        hint = f"did you mean {' or '.join(repr(n) for n in close)}? " if close else ""
        raise _Problem(path, f"unknown value {name!r}; {hint}allowed: {', '.join(names)}")


def _check_integrator_options(physics: PhysicsSettings, path: str) -> PhysicsSettings:
    """``physics`` with its integrator options checked against its integrator and kept as it
    keeps them (an int, a float, a choice), in the order the integrator lists them."""
    from ..physics.integrators import make_integrator
    from ..physics.integrators.base import unknown_option

    name = physics.integrator
    integrator = make_integrator(name)
    options = {o.name: o for o in type(integrator).OPTIONS}
    given = {}
    for key, value in physics.integrator_options:
        if key not in options:
            raise _Problem(f"{path}.{key}", unknown_option(key, name))
        if options[key].kind == "int" and isinstance(value, float) and value.is_integer():
            value = int(value)  # as for the file's other integer keys (substeps = 2.0)
        try:
            check_option_numbers({key: value}, integrator)  # 10**400: said, not an OverflowError
            given[key] = options[key].check(value, name)
        except ValueError as e:
            raise _Problem(f"{path}.{key}", str(e)) from None
    return replace(physics, integrator_options=tuple((k, given[k]) for k in options if k in given))


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
    deforma.scene.tables.SceneError: my.toml: physics.stifness: unknown key; did you mean 'stiffness'? allowed: dt, ...
    """
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
            values["physics"] = _check_integrator_options(values["physics"], "physics.integrator_options")
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
                    if name == "joint":
                        _check_joint(out[-1], p, len(values.get("body", ())))
                values[name] = tuple(out)
        _check_materials(values)
        # what World(grab_strength=) refuses, said by this file's key
        strength = values["interaction"].mouse_strength if "interaction" in values else None
        lo, hi = LIMITS["grab_strength"]
        if strength is not None and not lo <= strength <= hi:
            raise _Problem("interaction.mouse_strength", f"must be in [{lo:g}, {hi:g}] N/m, got {strength:g}")
        follow = values["camera"].follow if "camera" in values else None
        if follow is not None and follow >= len(values.get("body", ())):
            n = len(values.get("body", ()))
            raise _Problem("camera.follow", f"there is no body {follow}: the scene has {n} [[body]] table"
                                            f"{'' if n == 1 else 's'}")
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
        if f.metadata["kind"] == "options":
            if not v:  # no table rather than an empty one: every option has its default
                continue
            v = dict(v)
        elif f.metadata["kind"] == "file":
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

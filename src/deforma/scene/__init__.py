"""Scene files (TOML) <-> worlds; built-in scenes and textures.

A scene holds everything needed to reproduce a run: the bodies and how their meshes were
made, the physics parameters, the colliders, the camera and how long to run. See
``docs/scenes.md`` for every key.

The modules, each importing only ones listed before it: ``assets`` (built-in scenes and
pictures, references to them), ``tables`` (the file's tables as frozen dataclasses),
``construct`` (a World from a Scene), ``schema`` (the :class:`Scene`, read from TOML and written
back), ``build`` (load a scene, read a world's scene back, save it), ``script`` (events and
pulls), ``recording`` (a run's states as an NPZ) and ``playback`` (the frame loop of every
headless runner).

Examples
--------
>>> import deforma
>>> world = deforma.load_scene("demo")           # a built-in name or a path to a .toml file
>>> scene = deforma.scene.scene_of(world)        # camera, colours, run length, ...
>>> scene.run.seconds > 0
True
"""

from .assets import builtin_levels, builtin_patterns, builtin_scenes, builtin_textures, load_texture
from .build import body_specs, collider_spec, load, load_scene, save_scene, scene_of
from .construct import build, make_colliders, make_mesh
from .schema import Scene, parse_scene, with_springs
from .script import Script
from .tables import (BoxBody, CameraSettings, CircleCollider, ColliderSpec, Event, ImageBody, ImageCollider,
                     InteractionSettings, JointSpec, MeshBody, PhysicsSettings, PolygonCollider, Pull, RectCollider,
                     RunSettings,
                     SceneError, SceneInfo, SegmentCollider)

__all__ = [
    "BoxBody", "CameraSettings", "CircleCollider", "ColliderSpec", "Event", "ImageBody", "ImageCollider",
    "InteractionSettings", "JointSpec", "MeshBody", "PhysicsSettings", "PolygonCollider", "Pull", "RectCollider",
    "RunSettings",
    "Scene", "SceneError", "SceneInfo", "Script", "SegmentCollider", "body_specs", "build", "builtin_levels",
    "builtin_patterns", "builtin_scenes", "builtin_textures", "collider_spec", "load", "load_scene", "load_texture", "make_colliders",
    "make_mesh", "parse_scene", "save_scene", "scene_of", "with_springs",
]

"""docs/scenes.md stays true: its example loads and runs, and it documents every key."""

import re
from dataclasses import fields
from pathlib import Path

import numpy as np

from deforma import scene as scenes
from deforma.scene import schema

DOC = Path(__file__).resolve().parents[2] / "docs" / "scenes.md"


def test_the_example_file_loads_and_runs(tmp_path):
    text = DOC.read_text()
    example = re.search(r"```toml\n(.*?)```", text, re.S).group(1)
    p = tmp_path / "drop.toml"
    p.write_text(example)
    world = scenes.load_scene(p)
    assert [b.n_vertices > 0 for b in world.bodies] == [True, True]
    for _ in range(300):
        world.step()
    assert all(np.isfinite(b.positions).all() for b in world.bodies)


def test_every_key_is_documented():
    text = DOC.read_text()
    classes = [schema.SceneInfo, schema.RunSettings, schema.CameraSettings, schema.PhysicsSettings,
               schema.InteractionSettings, schema.BoxBody, schema.ImageBody, schema.MeshBody,
               schema.ColliderSpec, schema.Event]
    for cls in classes:
        for f in fields(cls):
            if f.metadata:
                assert f"| `{f.name}` |" in text, (cls.__name__, f.name)
    for name in scenes.builtin_scenes():
        assert f"| `{name}` |" in text, name

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


SECTIONS = {
    schema.SceneInfo: "### `[scene]`", schema.RunSettings: "### `[run]`", schema.CameraSettings: "### `[camera]`",
    schema.PhysicsSettings: "### `[physics]`", schema.InteractionSettings: "### `[interaction]`",
    schema.BoxBody: '### `[[body]]` with `shape = "box"`', schema.ImageBody: '### `[[body]]` with `shape = "image"`',
    schema.MeshBody: '### `[[body]]` with `shape = "mesh"`',
    schema.ColliderSpec: '### `[[collider]]` with `shape = "rect"`',
    schema.CircleCollider: '### `[[collider]]` with `shape = "circle"`',
    schema.PolygonCollider: '### `[[collider]]` with `shape = "polygon"`',
    schema.SegmentCollider: '### `[[collider]]` with `shape = "segment"`',
    schema.ImageCollider: '### `[[collider]]` with `shape = "image"`',
    schema.Event: "### `[[event]]`", schema.Pull: "### `[[pull]]`", schema.JointSpec: "### `[[joint]]`",
}


def section(text, heading):
    start = text.index(heading)
    end = text.find("\n#", start + len(heading))
    return text[start:] if end < 0 else text[start:end]


def test_every_key_is_documented():
    text = DOC.read_text()
    for cls, heading in SECTIONS.items():
        table = section(text, heading)  # in its own table: a key of another table does not count
        for f in fields(cls):
            if f.metadata:
                assert f"| `{f.name}` |" in table, (cls.__name__, f.name)
    for name in scenes.builtin_scenes():
        assert f"| `{name}` |" in text, name


def test_every_toml_snippet_loads(tmp_path):
    blocks = re.findall(r"```toml\n(.*?)```", DOC.read_text(), re.S)
    assert len(blocks) >= 2
    for k, block in enumerate(blocks):
        p = tmp_path / f"snippet{k}.toml"
        p.write_text(block)
        world = scenes.load_scene(p)
        for _ in range(300):  # half a second: stable as written
            world.step()
        assert all(np.isfinite(b.positions).all() for b in world.bodies)

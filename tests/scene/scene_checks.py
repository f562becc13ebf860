"""Shared helpers of the scene-file tests: write a file, check a refusal."""

import textwrap

import pytest

from deforma import scene as scenes
from deforma.scene import SceneError


def write(tmp_path, text, name="s.toml"):
    """Write ``text`` (dedented) to ``tmp_path / name``; returns the path."""
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return p


def assert_refused(path, message):
    """Loading ``path`` fails with one line that starts with the file and contains ``message``."""
    with pytest.raises(SceneError) as e:
        scenes.load_scene(path)
    msg = str(e.value)
    assert "\n" not in msg
    assert msg.startswith(f"{path}:") or msg.startswith(f"{path.resolve()}:")
    assert message in msg

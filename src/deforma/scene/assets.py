"""Built-in scenes and textures (package data under ``deforma/assets/``) and image loading."""

from __future__ import annotations

from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

__all__ = ["builtin_scenes", "builtin_textures", "load_texture", "resolve_texture", "scene_path",
           "texture_reference"]

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".gif", ".tif", ".tiff", ".webp")


def _assets() -> Path:
    return Path(str(resources.files("deforma") / "assets"))


def builtin_scenes() -> dict[str, Path]:
    """Built-in scene names and their files, sorted by name."""
    folder = _assets() / "scenes"
    return {p.stem: p for p in sorted(folder.glob("*.toml"))} if folder.is_dir() else {}


def builtin_textures() -> dict[str, Path]:
    """Built-in texture names (``bunny``, ``donut``, ``armadillo``) and their image files."""
    folder = _assets() / "textures"
    if not folder.is_dir():
        return {}
    return {p.stem: p for p in sorted(folder.iterdir()) if p.suffix.lower() in IMAGE_SUFFIXES}


def scene_path(name_or_path) -> Path:
    """The file of a built-in scene name or a path to a ``.toml`` file.

    Raises
    ------
    ValueError
        For an unknown name (listing the built-ins) or a missing file.
    """
    s = str(name_or_path)
    scenes = builtin_scenes()
    if s in scenes:
        return scenes[s]
    p = Path(s)
    if p.suffix.lower() == ".toml" or "/" in s or p.exists():
        if not p.is_file():
            raise ValueError(f"{s}: no such scene file")
        return p
    import difflib

    close = difflib.get_close_matches(s, list(scenes), n=1)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise ValueError(f"unknown scene {s!r}; {hint}built-in scenes: {', '.join(scenes)} (or give a path to a .toml file)")


def resolve_texture(value: str, *, base_dir) -> str:
    """A built-in texture name as is, or an image path made absolute (relative to ``base_dir``).

    Raises
    ------
    ValueError
        If it is neither a built-in name nor an existing image file.
    """
    textures = builtin_textures()
    if value in textures:
        return value
    p = Path(value).expanduser()
    if not p.is_absolute():
        p = Path(base_dir) / p
    if p.is_file():
        return str(p.resolve())
    allowed = f"a built-in texture ({', '.join(textures) or 'none installed'}) or an image file"
    if "/" not in value and "." not in value:
        import difflib

        close = difflib.get_close_matches(value, list(textures), n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise ValueError(f"unknown texture {value!r}; {hint}allowed: {allowed}")
    raise ValueError(f"no such file {str(p)!r}; allowed: {allowed}")


def texture_reference(value: str, *, base_dir) -> str:
    """What to write in a file for a resolved texture: the name, or a path relative to ``base_dir``."""
    if value in builtin_textures():
        return value
    from .schema import relative_path

    return relative_path(value, Path(base_dir).resolve())


def texture_file(value: str) -> Path:
    """The image file of a resolved texture reference."""
    return builtin_textures().get(value) or Path(value)


@lru_cache(maxsize=32)
def _load_rgba(path: str, mtime: float) -> np.ndarray:
    from PIL import Image

    with Image.open(path) as im:
        has_alpha = im.mode in ("RGBA", "LA", "PA") or (im.mode == "P" and "transparency" in im.info)
        rgba = np.array(im.convert("RGBA"))
    if not has_alpha or rgba[..., 3].min() == 255:
        # the original's rule for pictures without transparency: black pixels are not the
        # object, so they must not be drawn either (no dark fringe around the body)
        rgba[..., 3] = np.where(rgba[..., :3].max(axis=2) > 16, 255, 0).astype(np.uint8)
    rgba.setflags(write=False)
    return rgba


def load_texture(value: str) -> np.ndarray:
    """The picture of a texture reference as an (H, W, 4) uint8 RGBA array, row 0 on top.

    Pictures without an alpha channel are made transparent where they are black, the
    original's rule for what belongs to the object. The array is shared and read-only.

    Raises
    ------
    ValueError
        If the file cannot be read as an image.
    """
    path = texture_file(value)
    try:
        return _load_rgba(str(path), path.stat().st_mtime)
    except (OSError, ValueError) as e:
        raise ValueError(f"{path}: cannot read the image ({e})") from None

"""Built-in scenes (package data under ``deforma/assets/``) and the textures, patterns and level pictures scenes name.

Pictures are read by one loader, :func:`deforma.mesh.image.load_rgba`, and the built-in
textures are listed in one place, :func:`deforma.mesh.image.builtin_textures`; this module
resolves scene references to them and caches the pictures a renderer draws.
"""

from __future__ import annotations

import os
from functools import lru_cache
from importlib import resources
from pathlib import Path

import numpy as np

from ..mesh.image import builtin_textures

__all__ = ["builtin_levels", "builtin_patterns", "builtin_scenes", "builtin_textures", "load_texture", "picture_file",
           "picture_reference", "resolve_picture", "resolve_texture", "scene_path", "texture_reference"]


def _assets() -> Path:
    return Path(str(resources.files("deforma") / "assets"))


def builtin_scenes() -> dict[str, Path]:
    """Built-in scene names and their files, sorted by name."""
    folder = _assets() / "scenes"
    return {p.stem: p for p in sorted(folder.glob("*.toml"))} if folder.is_dir() else {}


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
        if p.is_dir():
            raise ValueError(f"{s}: is a folder, not a scene file; give a .toml file in it or a built-in scene name")
        if not p.is_file():
            raise ValueError(f"{s}: no such scene file")
        return p
    import difflib

    close = difflib.get_close_matches(s, list(scenes), n=1)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise ValueError(f"unknown scene {s!r}; {hint}built-in scenes: {', '.join(scenes)} (or give a path to a .toml file)")


def builtin_patterns() -> dict[str, Path]:
    """Pictures shipped in ``deforma/assets/patterns`` to draw on a body: name -> file.

    A pattern (the ``tear`` scene's ``cloth``) is a ``texture`` only: it has no shape to mesh,
    so it is kept apart from the textures, which are pictures of bodies (``source``, ``deforma
    mesh``, the viewer's objects to drop). A scene names it, and a saved scene writes the name
    back rather than a path into the installed package.

    Examples
    --------
    >>> "cloth" in builtin_patterns()
    True
    """
    return _pictures("patterns")


def _pictures(kind: str) -> dict[str, Path]:
    """The PNG pictures in ``deforma/assets/<kind>``, by name (sorted)."""
    folder = _assets() / kind
    return {p.stem: p for p in sorted(folder.glob("*.png"))} if folder.is_dir() else {}


def _drawn() -> dict[str, Path]:
    """Every built-in picture a ``texture =`` may name: the textures and the patterns."""
    return {**builtin_textures(), **builtin_patterns()}


def builtin_levels() -> dict[str, Path]:
    """Pictures of levels shipped in ``deforma/assets/levels`` for image colliders: name -> file.

    Kept apart from the textures, which are pictures of bodies (the viewer offers those as
    objects to drop).

    Examples
    --------
    >>> "ramp" in builtin_levels()
    True
    """
    return _pictures("levels")


def _resolve(value: str, names: dict, what: str, base_dir) -> str:
    if value in names:
        return value
    p = Path(value).expanduser()
    if not p.is_absolute():
        p = Path(base_dir) / p
    if p.is_file():
        from ..mesh.image import check_picture

        check_picture(p)  # an unreadable picture is refused here, where the error can name its key
        return str(p.resolve())
    allowed = f"a built-in {what} ({', '.join(names) or 'none installed'}) or an image file"
    if "/" not in value and "." not in value:
        import difflib

        close = difflib.get_close_matches(value, list(names), n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise ValueError(f"unknown {what} {value!r}; {hint}allowed: {allowed}")
    raise ValueError(f"no such file {str(p)!r}; allowed: {allowed}")


def resolve_texture(value: str, *, base_dir) -> str:
    """A built-in texture or pattern name as is, or an image path made absolute (relative to
    ``base_dir``).

    Raises
    ------
    ValueError
        If it is neither a built-in name nor an existing image file.
    """
    return _resolve(value, _drawn(), "texture", base_dir)


def resolve_picture(value: str, *, base_dir) -> str:
    """An image collider's source: a built-in level or texture name as is, or an image path made
    absolute (relative to ``base_dir``).

    Raises
    ------
    ValueError
        If it is neither a built-in name nor an existing image file.

    Examples
    --------
    >>> resolve_picture("ramp", base_dir=".")
    'ramp'
    """
    return _resolve(value, {**builtin_levels(), **builtin_textures()}, "picture", base_dir)


def picture_file(value: str) -> Path:
    """The image file of a resolved picture reference (:func:`resolve_picture`)."""
    return builtin_levels().get(value) or texture_file(value)


def picture_reference(value: str, *, base_dir) -> str:
    """What to write in a file for a resolved picture: the name, or a path relative to ``base_dir``."""
    if value in builtin_levels():
        return value
    return texture_reference(value, base_dir=base_dir)


def texture_reference(value: str, *, base_dir) -> str:
    """What to write in a file for a resolved texture: the name, or a path relative to ``base_dir``."""
    if value in _drawn():
        return value
    return relative_path(value, Path(base_dir).resolve())


def relative_path(target: str, base_dir: Path) -> str:
    """``target`` relative to ``base_dir`` when that is short and sensible, else absolute."""
    try:
        rel = os.path.relpath(target, base_dir)
    except ValueError:  # different drives on Windows
        return target
    return rel if rel.count("..") <= 3 else target


def texture_file(value: str) -> Path:
    """The image file of a resolved texture reference."""
    return _drawn().get(value) or Path(value)


@lru_cache(maxsize=32)
def _load_rgba(path: str, mtime: float, background, threshold) -> np.ndarray:
    from ..mesh.image import load_rgba

    rgba = load_rgba(path, background=background, threshold=threshold)
    rgba.setflags(write=False)  # shared between every body that draws it
    return rgba


def load_texture(value: str, *, background="black", threshold=None) -> np.ndarray:
    """The picture of a texture reference as an (H, W, 4) uint8 RGBA array, row 0 on top.

    Read as :func:`deforma.mesh.from_image` reads pictures
    (:func:`deforma.mesh.image.load_rgba`): a picture without transparency is made
    transparent where it shows the background (black unless ``background`` says otherwise),
    so the drawn body has no fringe of it. The array is shared and read-only.

    Parameters
    ----------
    value : str
        A built-in texture name or an image path (as :func:`resolve_texture` returns it).
    background, threshold : keyword-only
        As for :func:`deforma.mesh.from_image`.

    Raises
    ------
    ValueError
        If the file cannot be read as an image, or on a bad ``background``/``threshold``.

    Examples
    --------
    >>> rgba = load_texture("donut")
    >>> rgba.shape, rgba.dtype.name, rgba.flags.writeable
    ((384, 384, 4), 'uint8', False)
    """
    from ..mesh.image import check_background, check_threshold

    path = texture_file(value)
    # checked before the cache, whose key they are: (r, g, b) or "auto", a float or None
    background, threshold = check_background(background), check_threshold(threshold)
    try:
        mtime = path.stat().st_mtime
    except OSError as e:
        raise ValueError(f"{path}: cannot read the image ({e.strerror or e})") from None
    # the loader's messages name the file already
    return _load_rgba(str(path), mtime, background, threshold)

"""Where Numba keeps deforma's compiled kernels: a folder named by a hash of deforma's sources.

Numba's ``cache=True`` checks a cached kernel against its own source file only: a kernel
that calls a helper in another module keeps its compiled code after the helper changed
(measured here: a step kernel went on using an old collider test, with a wrong answer,
until its ``__pycache__`` was deleted by hand). Users who upgrade get new files everywhere,
but a developer who edits one module, or switches branches, does not.

So on import, deforma points Numba's cache (``numba.config.CACHE_DIR``) at
``<cache home>/deforma/kernels-<hash>``, the hash taken over every ``.py`` file of the
package's ``physics`` and ``mesh`` and of every other file that uses Numba (what a kernel
can call or read: constants too, which compiled code keeps; editing the CLI, the scenes or
the viewer keeps the cache): any edit of them, upgrade or checkout compiles afresh once, and an
unchanged install reuses its cache. Older folders are deleted, keeping the three most recently used (installs side by
side). ``NUMBA_CACHE_DIR`` set by the user wins; where no folder can be made (a read-only
home), Numba's default (``__pycache__`` beside the sources) stays. Hashing the sources takes
a few milliseconds per import.
"""

from __future__ import annotations

import hashlib
import os
import shutil
from pathlib import Path

__all__ = ["KEEP", "cache_home", "kernel_folder", "source_key", "use_source_keyed_cache"]

KEEP = 3  # kernel folders kept: the current one and the most recently used others

_PACKAGE = Path(__file__).resolve().parent


def source_key(root: Path = _PACKAGE) -> str:
    """A hash (16 hex digits) of the ``.py`` files under ``root`` that kernels may depend on
    (``physics/``, ``mesh/``, and any other that uses Numba), names and contents.

    Examples
    --------
    >>> len(source_key()), source_key() == source_key()
    (16, True)
    """
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py")):
        name = f.relative_to(root).as_posix()
        text = f.read_bytes()
        if not name.startswith(("physics/", "mesh/")) and b"numba" not in text:
            continue
        h.update(name.encode())
        h.update(b"\0")
        h.update(text)
    return h.hexdigest()[:16]


def cache_home() -> Path:
    """The user's cache folder: ``$XDG_CACHE_HOME``, else ``~/.cache`` (``%LOCALAPPDATA%`` on Windows)."""
    if os.environ.get("XDG_CACHE_HOME"):
        return Path(os.environ["XDG_CACHE_HOME"])
    if os.name == "nt" and os.environ.get("LOCALAPPDATA"):
        return Path(os.environ["LOCALAPPDATA"])
    return Path.home() / ".cache"


def use_source_keyed_cache() -> Path | None:
    """Point Numba's cache at this source tree's own folder (see the module docstring).

    Returns the folder, or None where the user's ``NUMBA_CACHE_DIR`` or an unwritable cache
    home leaves Numba's choice in place. Call before any kernel is defined.
    """
    import numba

    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    try:
        base = cache_home() / "deforma"
        folder = base / f"kernels-{source_key()}"
        folder.mkdir(parents=True, exist_ok=True)
        os.utime(folder)  # used now: what the clean-up below keeps
    except OSError:
        return None
    numba.config.CACHE_DIR = str(folder)
    _forget_old(base, folder)
    return folder


def _forget_old(base: Path, current: Path) -> None:
    try:
        others = sorted((p for p in base.glob("kernels-*") if p != current and p.is_dir()),
                        key=lambda p: p.stat().st_mtime, reverse=True)
    except OSError:
        return
    for old in others[KEEP - 1:]:
        shutil.rmtree(old, ignore_errors=True)  # another process may be using it: best effort


def kernel_folder() -> Path | None:
    """The folder Numba caches this process's compiled kernels in (this module's, or the
    user's ``NUMBA_CACHE_DIR``), or None where Numba keeps them beside the sources."""
    import numba

    folder = numba.config.CACHE_DIR
    return Path(folder) if folder else None

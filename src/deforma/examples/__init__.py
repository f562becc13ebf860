"""Runnable examples, shipped with the package: ``python -m deforma.examples`` lists them and
``python -m deforma.examples NAME [options]`` runs one (``NAME --help`` for its options).

Each example is a module of this package with a ``main(argv)`` function; the first line of its
docstring is what the listing shows. They print what they measure and, with ``--output
PATH.png``, draw a picture of the end state (Pillow only: no window, no OpenGL), so they run
the same on a desktop, in CI and over SSH. ``integrators`` and ``notebook`` render through
OpenGL (headless EGL where there is no display) and need the ``render`` extra.

``tools/gallery.py`` runs every example with ``--output`` to draw the pictures of
``docs/gallery.md``.

Examples
--------
>>> from deforma.examples import NAMES, summary
>>> NAMES[0], summary("meshes").startswith("Meshes")
('meshes', True)
"""

from __future__ import annotations

import ast
import difflib
import importlib
import sys
from importlib import resources

__all__ = ["NAMES", "main", "summary"]

#: Every example, in the order the listing shows them: from a mesh to a sweep of many runs.
NAMES = ("meshes", "materials", "contact", "tearing", "colliders", "rigid", "integrators", "sweeps", "notebook")

PROG = "python -m deforma.examples"


def summary(name: str) -> str:
    """The first line of example ``name``'s docstring, read without importing it (listing every
    example would otherwise import the physics and the renderer)."""
    source = resources.files(__name__).joinpath(f"{name}.py").read_text(encoding="utf-8")
    doc = ast.get_docstring(ast.parse(source)) or ""
    return doc.strip().splitlines()[0] if doc.strip() else ""


def listing() -> str:
    """One line per example: its name and what it shows."""
    width = max(map(len, NAMES))
    lines = [f"examples ({PROG} NAME; NAME --help for its options):"]
    lines += [f"  {name:<{width}}  {summary(name)}" for name in NAMES]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """List the examples (no argument, ``-h``, ``--help``, ``--list``) or run one by name.

    Parameters
    ----------
    argv : list of str, optional
        ``[NAME, *options]``; default ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit code: 0, the example's own, 2 for a name that is not an example (one line on
        stderr that lists the names), 1 for a file it cannot write (one line naming it).
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv or argv[0] in ("-h", "--help", "--list"):
        print(listing())
        return 0
    name, rest = argv[0], argv[1:]
    if name not in NAMES:
        close = difflib.get_close_matches(name, NAMES, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        print(f"{PROG}: no example {name!r}{hint} (examples: {', '.join(NAMES)})", file=sys.stderr)
        return 2
    module = importlib.import_module(f"{__name__}.{name}")
    try:
        code = module.main(rest)
    except OSError as e:  # an output that cannot be written: say which, without a traceback
        print(f"{PROG} {name}: {e}", file=sys.stderr)
        return 1
    return int(code or 0)

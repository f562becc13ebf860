"""How much of deforma's public API is fully annotated: every parameter and the return.

Counts the public functions and methods (no leading underscore; ``__init__`` counted apart,
see below) of the modules behind the public API (``MODULES``), read with :mod:`ast` (nothing
is imported). A function is fully annotated when every parameter but a method's ``self`` /
``cls`` has an annotation (``*args`` and ``**kwargs`` too) and it has a return annotation.
Methods of private classes, nested functions and Numba kernels (decorated ``njit`` / ``jit``:
Numba ignores hints) are not counted. ``__init__`` is reported on its own line: its
parameters are public API (``World(...)``), but its name has a leading underscore; it is
fully annotated with or without ``-> None`` (as mypy sees it).

    python tools/typing_coverage.py            # the table and the totals
    python tools/typing_coverage.py --missing  # and the names still missing annotations
"""

from __future__ import annotations

import argparse
import ast
import sys
from dataclasses import dataclass, field
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "deforma"

# the modules behind deforma's public API and the physics seams
MODULES = [
    "__init__.py",
    "mesh/__init__.py", "mesh/box.py", "mesh/delaunay.py", "mesh/export.py", "mesh/image.py", "mesh/mesh.py",
    "mesh/outline.py",
    "physics/__init__.py", "physics/world.py", "physics/body.py", "physics/material.py", "physics/joint.py",
    "physics/colliders/shapes.py", "physics/integrators/__init__.py", "physics/integrators/base.py",
    "scene/__init__.py", "scene/build.py",
    "sweeps.py",
]
# and every module of the drawing and the viewer (typed whole, as mypy checks them)
MODULES += sorted(str(p.relative_to(Path(__file__).resolve().parents[1] / "src" / "deforma"))
                  for folder in ("render", "viewer")
                  for p in (Path(__file__).resolve().parents[1] / "src" / "deforma" / folder).glob("*.py"))


@dataclass
class Tally:
    total: int = 0
    typed: int = 0
    init_total: int = 0
    init_typed: int = 0
    missing: list[str] = field(default_factory=list)


def _is_kernel(node: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    for d in node.decorator_list:
        target = d.func if isinstance(d, ast.Call) else d
        name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
        if name in ("njit", "jit", "vectorize", "guvectorize", "generated_jit"):
            return True
    return False


def _is_static(node: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    return any(isinstance(d, ast.Name) and d.id == "staticmethod" for d in node.decorator_list)


def fully_annotated(node: ast.FunctionDef | ast.AsyncFunctionDef, method: bool) -> bool:
    """True when every parameter (but a method's first) and the return are annotated."""
    a = node.args
    params = [*a.posonlyargs, *a.args]
    if method and not _is_static(node):
        params = params[1:]
    params += a.kwonlyargs
    params += [p for p in (a.vararg, a.kwarg) if p is not None]
    if any(p.annotation is None for p in params):
        return False
    if node.name == "__init__":
        return node.returns is not None or bool(params)
    return node.returns is not None


def tally_module(path: Path, tally: Tally, rel: str) -> None:
    tree = ast.parse(path.read_text(), filename=str(path))

    def visit(node: ast.AST, owner: str | None) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.ClassDef):
                if owner is None and not child.name.startswith("_"):
                    visit(child, child.name)
            elif isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                if _is_kernel(child):
                    continue
                name = f"{rel}:{owner + '.' if owner else ''}{child.name}"
                ok = fully_annotated(child, method=owner is not None)
                if child.name == "__init__" and owner is not None:
                    tally.init_total += 1
                    tally.init_typed += ok
                elif not child.name.startswith("_"):
                    tally.total += 1
                    tally.typed += ok
                else:
                    continue
                if not ok:
                    tally.missing.append(name)
            elif isinstance(child, (ast.If, ast.Try)):  # e.g. definitions under `if TYPE_CHECKING`
                visit(child, owner)

    visit(tree, None)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--missing", action="store_true", help="list the functions not fully annotated")
    args = parser.parse_args(argv)
    grand = Tally()
    print(f"{'module':40s} {'typed':>6s} {'public':>6s} {'share':>6s}")
    for rel in MODULES:
        t = Tally()
        tally_module(SRC / rel, t, rel)
        share = f"{100 * t.typed / t.total:5.0f}%" if t.total else "    -"
        print(f"{rel:40s} {t.typed:6d} {t.total:6d} {share}")
        grand.total += t.total
        grand.typed += t.typed
        grand.init_total += t.init_total
        grand.init_typed += t.init_typed
        grand.missing += t.missing
    print(f"\npublic functions and methods fully annotated: {grand.typed}/{grand.total} "
          f"({100 * grand.typed / max(grand.total, 1):.1f}%)")
    print(f"__init__ of public classes fully annotated:   {grand.init_typed}/{grand.init_total}")
    both_t, both_n = grand.typed + grand.init_typed, grand.total + grand.init_total
    print(f"together:                                     {both_t}/{both_n} ({100 * both_t / max(both_n, 1):.1f}%)")
    if args.missing:
        print("\nnot fully annotated:")
        for name in grand.missing:
            print("  " + name)
    return 0


if __name__ == "__main__":
    sys.exit(main())

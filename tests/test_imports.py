"""No module under ``src/deforma`` imports another that imports it back (issue 33).

Every import statement counts, wherever it is: at the top of a module, inside a function or a
method (a lazy import still makes the two modules depend on each other; it only hides the
circle from Python), under ``try``. Only imports under ``if TYPE_CHECKING:`` do not count: they
never run. ``from .x import name`` depends on the module ``x.name`` when there is one (a
submodule), else on ``x`` (a name defined in it). A package does not depend on its modules,
nor a module on its package, unless one imports the other.
"""

from __future__ import annotations

import ast
import textwrap
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"


def module_files(root: Path, package: str) -> dict[str, Path]:
    """Dotted module name -> file, for every ``.py`` file of ``package`` under ``root``."""
    out = {}
    for path in sorted((root / package).rglob("*.py")):
        parts = path.relative_to(root).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _is_type_checking(test: ast.expr) -> bool:
    """``if TYPE_CHECKING:`` or ``if typing.TYPE_CHECKING:``."""
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def import_nodes(tree: ast.AST):
    """Every ``import`` and ``from ... import`` in ``tree``, at any depth, except those in the
    body of an ``if TYPE_CHECKING:`` (its ``else`` runs, so it counts)."""
    stack = [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend(node.orelse)
        else:
            stack.extend(ast.iter_child_nodes(node))


def imported_modules(name: str, path: Path, modules) -> dict[str, int]:
    """The modules of ``modules`` that module ``name`` (file ``path``) imports -> the line of the
    first such import."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    is_package = path.name == "__init__.py"
    out: dict[str, int] = {}

    def add(target: str, line: int) -> None:
        if target in modules and target != name:
            out.setdefault(target, line)

    for node in import_nodes(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                # `import a.b.c` binds a and runs a.b.c: the module named (or the deepest one of
                # ours on its way, for a name outside the package)
                parts = alias.name.split(".")
                for k in range(len(parts), 0, -1):
                    if ".".join(parts[:k]) in modules:
                        add(".".join(parts[:k]), node.lineno)
                        break
            continue
        if node.level:
            # `.` is the package this module is in (a package's __init__ is in itself)
            here = name.split(".") if is_package else name.split(".")[:-1]
            keep = len(here) - (node.level - 1)
            assert keep > 0, f"{path}:{node.lineno}: relative import beyond the top-level package"
            base = ".".join(here[:keep] + ([node.module] if node.module else []))
        else:
            base = node.module
        for alias in node.names:
            sub = f"{base}.{alias.name}"
            add(sub if alias.name != "*" and sub in modules else base, node.lineno)
    return out


def import_graph(root: Path, package: str) -> dict[str, dict[str, tuple[Path, int]]]:
    """module -> {module it imports: (file, line of the import)} for every module of ``package``."""
    files = module_files(root, package)
    return {name: {target: (path, line) for target, line in imported_modules(name, path, files).items()}
            for name, path in files.items()}


def strongly_connected(graph) -> list[list[str]]:
    """The groups of modules that import each other, round about (Tarjan), largest first;
    groups of one module are left out."""
    index, low, on_stack, stack, groups = {}, {}, set(), [], []
    counter = [0]

    def visit(v):
        # iterative, so a deep chain of imports cannot hit the recursion limit
        work = [(v, iter(sorted(graph[v])))]
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        while work:
            node, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    break
                if w in on_stack:
                    low[node] = min(low[node], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    group = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        group.append(w)
                        if w == node:
                            break
                    if len(group) > 1:
                        groups.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(groups, key=lambda g: (-len(g), g))


def a_cycle(graph, group: list[str]) -> list[str]:
    """One shortest circle through the first module of ``group``: [a, b, ..., a]."""
    start, members = group[0], set(group)
    came_from = {start: None}
    frontier = [start]
    while frontier:
        following = []
        for v in frontier:
            for w in sorted(graph[v]):
                if w == start:
                    path = [v]
                    while came_from[path[-1]] is not None:
                        path.append(came_from[path[-1]])
                    return [start, *reversed(path[:-1]), start] if len(path) > 1 else [start, v, start]
                if w in members and w not in came_from:
                    came_from[w] = v
                    following.append(w)
        frontier = following
    raise AssertionError(f"no circle through {start}")  # pragma: no cover - a group always has one


def describe(graph, root: Path, group: list[str]) -> str:
    """A group of modules that import each other, and one circle among them with each import's place."""
    circle = a_cycle(graph, group)
    steps = []
    for a, b in zip(circle, circle[1:]):
        path, line = graph[a][b]
        steps.append(f"  {a} imports {b} ({path.relative_to(root).as_posix()}:{line})")
    return f"{', '.join(group)}:\n" + "\n".join(steps)


def test_no_module_imports_one_that_imports_it_back():
    graph = import_graph(SRC, "deforma")
    assert len(graph) > 50 and "deforma.cli" in graph  # the walk found the package
    groups = strongly_connected(graph)
    assert not groups, "modules that import each other, round about:\n" + "\n".join(
        describe(graph, SRC.parent, g) for g in groups)


# -- the walker itself, on a package made for it -----------------------------------------------------
PACKAGE = {
    "pkg/__init__.py": "from .a import f\n",
    "pkg/a.py": """
        from typing import TYPE_CHECKING

        if TYPE_CHECKING:
            from .c import C           # never runs: no dependency
        else:
            from . import sub          # runs
        def f():
            from .b import g           # inside a function: counts
            return g
        """,
    "pkg/b.py": "import pkg.sub.deep as deep\ndef g():\n    pass\n",
    "pkg/c.py": "from .a import f\n",
    "pkg/sub/__init__.py": "from .. import b\n",
    "pkg/sub/deep.py": "from ..sub import deep2\nfrom ..a import *\n",
    "pkg/sub/deep2.py": "import os\nfrom .. import a as first\n",
}


@pytest.fixture
def package(tmp_path):
    for rel, text in PACKAGE.items():
        path = tmp_path / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
    return tmp_path


def test_the_walker_resolves_every_kind_of_import(package):
    graph = import_graph(package, "pkg")
    assert {m: sorted(t) for m, t in graph.items()} == {
        "pkg": ["pkg.a"],
        "pkg.a": ["pkg.b", "pkg.sub"],            # not pkg.c: under TYPE_CHECKING
        "pkg.b": ["pkg.sub.deep"],
        "pkg.c": ["pkg.a"],
        "pkg.sub": ["pkg.b"],                     # `from .. import b`: the module pkg.b
        "pkg.sub.deep": ["pkg.a", "pkg.sub.deep2"],
        "pkg.sub.deep2": ["pkg.a"],               # `from .. import a`: the module pkg.a
    }
    assert graph["pkg.a"]["pkg.b"][1] == 9        # the line of the import inside f


def test_the_walker_reports_each_circle_with_where_it_imports(package):
    graph = import_graph(package, "pkg")
    groups = strongly_connected(graph)
    assert groups == [["pkg.a", "pkg.b", "pkg.sub", "pkg.sub.deep", "pkg.sub.deep2"]]
    text = describe(graph, package, groups[0])
    assert text.splitlines()[1:] == [
        "  pkg.a imports pkg.b (pkg/a.py:9)",
        "  pkg.b imports pkg.sub.deep (pkg/b.py:1)",
        "  pkg.sub.deep imports pkg.a (pkg/sub/deep.py:2)",
    ]

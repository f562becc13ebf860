"""The docstring examples of every deforma module run and show what they claim (issue 18).

One pytest case per docstring that has examples, id = its dotted name
(``deforma.physics.world.World.step``). Each runs like ``python -m doctest`` would: in a
copy of its module's globals, with ``ELLIPSIS`` (error messages that list every allowed key
end in ``...``; whitespace stays exact: an example that needs more says so with its own
``# doctest: +FLAG``), from a fresh temporary folder as the current directory so an
example that writes a file writes it there.

``deforma.render`` and ``deforma.viewer`` draw with OpenGL: their examples run when a
headless context can be made (it can wherever the rest of the suite passes: tests/render
and tests/viewer never skip) and are skipped with the reason otherwise. The core modules'
examples always run.

Why a test module instead of ``--doctest-modules``: CI runs ``python -m pytest`` with
``testpaths = ["tests"]``, and the GL skip needs a probe that a plain doctest collector has
no place for.
"""

import doctest
import importlib
import pkgutil
import re
from pathlib import Path

import pytest

import deforma

GL_PACKAGES = ("deforma.render", "deforma.viewer")
FLAGS = doctest.ELLIPSIS
SRC = Path(deforma.__file__).resolve().parent


def module_names():
    names = ["deforma"]
    for info in pkgutil.walk_packages(deforma.__path__, "deforma."):
        if info.name.endswith("__main__"):
            continue  # running it is running the command, not a module to import
        names.append(info.name)
    return sorted(names)


def needs_gl(name):
    return any(name == p or name.startswith(p + ".") for p in GL_PACKAGES)


def find(module):
    """The docstrings with examples of one module, each docstring once.

    One docstring can belong to several objects (forces.py compiles one Python function into
    a serial and a parallel kernel, both carrying its text): its examples run once, under the
    first name.
    """
    tests = doctest.DocTestFinder(exclude_empty=True).find(module, module.__name__)
    out, seen = [], set()
    for t in sorted(tests, key=lambda t: t.name):
        if t.examples and t.docstring not in seen:
            seen.add(t.docstring)
            out.append(t)
    return out


def collect():
    """(module name, docstring name) pairs; a GL module whose extra is missing still gets a case."""
    cases = []
    for name in module_names():
        try:
            module = importlib.import_module(name)
        except ImportError:
            if not needs_gl(name):
                raise  # the core must import without any GL package: never hide that
            cases.append((name, name))  # the case skips with the import error
            continue
        cases.extend((name, t.name) for t in find(module))
    return cases


CASES = collect()


@pytest.fixture(scope="module")
def gl_missing():
    """None when a headless OpenGL 3.3 context can be made, otherwise why not.

    The probe context is released at once: a standalone context left alive keeps a pygame-ce
    window opened later in the process (the viewer examples, tests/viewer) from getting its own.
    """
    try:
        from deforma.render import create_headless_context

        create_headless_context().release()
    except (ImportError, RuntimeError) as e:
        return f"no headless OpenGL context: {e}"
    return None


@pytest.fixture
def offscreen(monkeypatch, tmp_path):
    # a window opened by an example (the viewer) must be off-screen, as in tests/viewer
    monkeypatch.setenv("SDL_VIDEODRIVER", "offscreen")
    monkeypatch.setenv("SDL_AUDIODRIVER", "dummy")
    monkeypatch.chdir(tmp_path)


def test_every_module_is_searched():
    # a package that stops being found (a missing __init__.py) would drop its examples silently
    files = {p.relative_to(SRC).with_suffix("").as_posix().replace("/__init__", "")
             for p in SRC.rglob("*.py") if p.name != "__main__.py"}
    found = {n.removeprefix("deforma").lstrip(".").replace(".", "/") for n in module_names()}
    assert {f if f != "__init__" else "" for f in files} == found


def test_every_example_in_the_source_is_collected():
    """Each ``>>>`` line in src/deforma belongs to an example that a case runs.

    DocTestFinder skips docstrings it cannot see (a Numba-compiled function, a nested function,
    an object re-exported from another module): their examples would never run unnoticed.
    """
    in_source = sum(len(re.findall(r"^\s*>>>", p.read_text(encoding="utf-8"), re.M)) for p in SRC.rglob("*.py"))
    collected = 0
    for name in module_names():
        try:
            module = importlib.import_module(name)
        except ImportError:
            pytest.skip(f"{name} cannot be imported (render extra missing): cannot count its examples")
        collected += sum(len(t.examples) for t in find(module))
    assert collected == in_source


@pytest.mark.parametrize(("module_name", "test_name"), CASES, ids=[c[1] for c in CASES])
def test_docstring_examples(module_name, test_name, gl_missing, offscreen):
    if needs_gl(module_name) and gl_missing:
        pytest.skip(gl_missing)
    try:
        module = importlib.import_module(module_name)
    except ImportError as e:
        pytest.skip(f"{module_name} needs the render extra: {e}")
    # found again here, not at collection: DocTestRunner clears a test's globals after a run
    (test,) = [t for t in find(module) if t.name == test_name]
    # +SKIP would be the docstring's way to hide an example that does not run: rewrite it instead
    skipped = [e.source.strip() for e in test.examples if e.options.get(doctest.SKIP)]
    assert not skipped, f"{test_name}: examples marked +SKIP never run: {skipped}"
    report = []
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    result = runner.run(test, out=report.append)
    assert result.failed == 0, "".join(report)
    assert result.attempted > 0

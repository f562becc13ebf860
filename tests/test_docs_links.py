"""Links and file names in README.md and docs/*.md point at things that exist (issue 50).

What is checked, outside fenced code blocks:

- Every relative Markdown link or picture, ``[text](path)``, ``[text](path#anchor)`` or
  ``[text](#anchor)``: the path exists relative to the file that links it, and the anchor is
  the slug of a heading in the target file, made by GitHub's rule (see :func:`slug`).
  ``http(s)://`` and ``mailto:`` links are not followed.
- Every repository path to a Python file in backticks (``deforma/physics/statics.py``,
  ``src/deforma/cli.py``, ``physics/elements/springs.py``, ``mesh/outline.py``,
  ``tests/physics/test_rigid.py``, ``tools/heap.py``, also inside a command such as
  ``python benchmarks/run.py --only fem``): the file exists. Paths of the package
  (``deforma/...``, or ``physics/``, ``mesh/``, ... as the docs write them) are looked up in
  ``src/deforma/``; ``tests/``, ``tools/``, ``benchmarks/``, ``examples/`` and ``src/`` from
  the repository root. A bare file name (``friction.py``) names no folder and is not checked.

Standard library and pytest only; the whole file runs in well under a second.
"""

import re
import sys
from collections import Counter
from pathlib import Path
from urllib.parse import unquote

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOC_FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

FENCE = re.compile(r"^[ \t]*(`{3,}|~{3,})")
HEADING = re.compile(r"^ {0,3}(#{1,6})[ \t]+(.*?)(?:[ \t]+#+)?[ \t]*$")
CODE_SPAN = re.compile(r"(`+)(.+?)(?<!`)\1(?!`)")
# [text](target) or ![alt](target), with an optional "title"; the text may hold code spans
LINK = re.compile(r"!?\[(?P<text>(?:[^\[\]]|\[[^\[\]]*\])*)\]\(\s*(?P<target><[^>]*>|[^)\s]+)(?:\s+\"[^\"]*\")?\s*\)")
# a path to a Python file: the package's own folders from src/deforma, the rest from the root
PACKAGE_DIRS = ("physics", "mesh", "scene", "render", "viewer", "assets")
ROOT_DIRS = ("tests", "tools", "benchmarks", "examples", "src")
SOURCE_PATH = re.compile(r"(?<![\w/.<>-])(?P<path>(?:[\w.-]+/)+[\w.-]+\.py)(?![\w/])")
EXTERNAL = re.compile(r"^[a-z][a-z0-9+.-]*:", re.IGNORECASE)  # http:, https:, mailto:, ...


def slug(heading: str) -> str:
    """GitHub's anchor for a heading: its text as shown (code spans keep their text, links
    their label, emphasis marks go), lower case, every character that is not a letter, a
    digit, ``_``, ``-`` or a space dropped, and every space a hyphen."""
    text = re.sub(r"!?\[((?:[^\[\]]|\[[^\[\]]*\])*)\]\([^)]*\)", r"\1", heading)  # links: their label
    text = re.sub(r"<[^>]+>", "", text)  # inline HTML tags
    text = text.strip().lower()
    text = "".join(c for c in text if c.isalnum() or c in "_- ")
    return text.replace(" ", "-")


def prose_lines(path: Path):
    """(line number, text) of every line outside fenced code blocks."""
    fence = None
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        m = FENCE.match(line)
        if fence is None:
            if m:
                fence = m.group(1)
                continue
            yield number, line
        elif m and m.group(1)[0] == fence[0] and len(m.group(1)) >= len(fence) and not line.strip(" \t`~"):
            fence = None


_anchor_cache: dict[Path, set[str]] = {}


def anchors(path: Path) -> set[str]:
    """The anchors of a Markdown file's headings; the second heading with the same slug gets
    ``-1``, the third ``-2``, and so on, as on GitHub."""
    if path not in _anchor_cache:
        seen: Counter = Counter()
        found = set()
        for _, line in prose_lines(path):
            m = HEADING.match(line)
            if not m:
                continue
            base = slug(m.group(2))
            name = base if seen[base] == 0 else f"{base}-{seen[base]}"
            seen[base] += 1
            found.add(name)
        _anchor_cache[path] = found
    return _anchor_cache[path]


def code_spans(line: str):
    """(start, end, content) of the inline code spans of one line."""
    return [(m.start(), m.end(), m.group(2)) for m in CODE_SPAN.finditer(line)]


def links(path: Path):
    """(line number, target) of every link outside code blocks and code spans."""
    for number, line in prose_lines(path):
        spans = code_spans(line)
        for m in LINK.finditer(line):
            if any(a <= m.start() < b for a, b, _ in spans):
                continue  # written as code, not a link
            yield number, m.group("target").strip("<>")


def link_problem(path: Path, target: str) -> str | None:
    """Why a link target is broken, or None if it is fine (or not followed)."""
    if EXTERNAL.match(target) or target.startswith("//"):
        return None
    file_part, _, anchor = target.partition("#")
    file_part = unquote(file_part.split("?")[0])
    goal = (path.parent / file_part).resolve() if file_part else path
    if not goal.exists():
        return f"no such file: {file_part}"
    if anchor:
        if goal.is_dir() or goal.suffix.lower() != ".md":
            return f"an anchor into a file that is not Markdown: {target}"
        if unquote(anchor) not in anchors(goal):
            return f"no heading in {goal.relative_to(ROOT).as_posix()} has the anchor #{anchor}"
    return None


def source_paths(path: Path):
    """(line number, path) of every repository path to a Python file in a code span."""
    for number, line in prose_lines(path):
        for _, _, content in code_spans(line):
            for m in SOURCE_PATH.finditer(content):
                yield number, m.group("path")


def source_problem(written: str) -> str | None:
    """Why a backticked path to a Python file is wrong, or None if it exists (or is not a
    repository path the docs could mean)."""
    first = written.split("/", 1)[0]
    if first == "deforma":
        candidates = [ROOT / "src" / written]
    elif first in PACKAGE_DIRS:
        candidates = [ROOT / "src" / "deforma" / written]
    elif first in ROOT_DIRS:
        candidates = [ROOT / written]
    else:
        return None  # relative to something the sentence names (implicit/anderson.py): not checked
    if any(c.is_file() for c in candidates):
        return None
    return f"no such file: {candidates[0].relative_to(ROOT).as_posix()}"


def doc_id(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


@pytest.mark.parametrize("doc", DOC_FILES, ids=doc_id)
def test_relative_links_point_at_files_and_headings_that_exist(doc):
    broken = [f"{doc_id(doc)}:{n}: ({t}) {why}" for n, t in links(doc) if (why := link_problem(doc, t))]
    assert not broken, "\n".join(broken)


@pytest.mark.parametrize("doc", DOC_FILES, ids=doc_id)
def test_source_files_named_in_backticks_exist(doc):
    broken = [f"{doc_id(doc)}:{n}: `{p}` {why}" for n, p in source_paths(doc) if (why := source_problem(p))]
    assert not broken, "\n".join(broken)


# -- the checker itself ----------------------------------------------------------------------

@pytest.mark.parametrize("heading, expected", [
    ("Outlines for levels (`mesh.outline`, `mesh/outline.py`)", "outlines-for-levels-meshoutline-meshoutlinepy"),
    ("avbd: vertex block descent", "avbd-vertex-block-descent"),
    ("Second order (option `order`)", "second-order-option-order"),
    ("Material behaviours (`benchmarks/bench_behaviours.py`)", "material-behaviours-benchmarksbench_behaviourspy"),
    ("Beyond elasticity: tearing, plasticity, a stretch limit, gas pressure",
     "beyond-elasticity-tearing-plasticity-a-stretch-limit-gas-pressure"),
    ("Materials: finite elements in physical units", "materials-finite-elements-in-physical-units"),
    ("A [linked](other.md) *word* -- twice", "a-linked-word----twice"),
])
def test_slug_follows_githubs_rule(heading, expected):
    assert slug(heading) == expected


def test_checker_finds_what_is_broken(tmp_path, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    (tmp_path / "docs").mkdir()
    (tmp_path / "src" / "deforma" / "physics").mkdir(parents=True)
    (tmp_path / "src" / "deforma" / "physics" / "here.py").touch()
    other = tmp_path / "docs" / "other.md"
    other.write_text("# Top\n\n## Part\n\n## Part\n\n```\n## Not a heading\n```\n", encoding="utf-8")
    page = tmp_path / "docs" / "page.md"
    page.write_text(
        "# Page\n"
        "[ok](other.md#part-1) [ok](other.md) [ok](#page) [ok](https://example.com/x#y) [ok](mailto:a@b.c)\n"
        "[bad](other.md#part-2) [bad](missing.md) [bad](other.md#not-a-heading) [bad](#nowhere)\n"
        "`[not a link](missing.md)` [code text `x`](missing-too.md)\n"
        "```\n[in a block](missing.md)\n```\n"
        "`deforma/physics/gone.py` `python tools/gone.py --x` `physics/gone.py` `friction.py`\n"
        "`deforma/physics/here.py` `src/deforma/physics/here.py` `physics/here.py: f`\n",
        encoding="utf-8")
    _anchor_cache.clear()
    try:
        bad = [t for _, t in links(page) if link_problem(page, t)]
        assert bad == ["other.md#part-2", "missing.md", "other.md#not-a-heading", "#nowhere", "missing-too.md"]
        missing = [p for _, p in source_paths(page) if source_problem(p)]
        assert missing == ["deforma/physics/gone.py", "tools/gone.py", "physics/gone.py"]
        assert len(list(source_paths(page))) == 6  # the three that exist were seen too
    finally:
        _anchor_cache.clear()

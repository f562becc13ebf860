"""Every ```python block in README.md and docs/*.md runs (issue 18, "Docs that run").

How blocks run:

- One pytest case per block, id ``file:line`` (the line of the opening fence).
- The blocks of one Markdown file share one namespace and run in the order they appear, like
  the cells of a notebook: a later block may use names an earlier one defined, as a reader
  who goes through the page would. Every file starts from a fresh, empty namespace, so no
  page can lean on another. A case that is run on its own (``-k``, a single id) first runs the
  blocks above it in its file, so selecting one case gives the same answer as the whole file.
- The current directory is a fresh temporary folder for each file (blocks may write files;
  nothing may land in the repository) and ``SDL_VIDEODRIVER=offscreen`` is set, so anything
  that opens a window gets a real off-screen one.
- A block that is an illustration only and cannot run (an interactive window that waits for a
  person) is marked in the Markdown by ``<!-- not-run: reason -->`` on the line(s) right
  before its fence. The case then checks a reason is given and skips with it; its names are
  not defined for later blocks. Slow blocks are made smaller in the docs instead.
- Only ```python fences run; ```bash, ```toml and bare fences are not Python.
- A block fails if it raises, if it leaves a new file anywhere in the repository, or if it
  takes more than 10 s besides Numba compiling (a cold cache compiles for about a minute).

An output shown in a comment (``print(body.mass)  # 100 kg``) is not compared here; a block
that claims a value should ``assert`` it or the docs must keep it true by hand.
"""

import os
import re
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from numba.core import event as numba_event

ROOT = Path(__file__).resolve().parents[1]
DOC_FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

# An opening fence: up to three spaces or a list item's indent, then ``` or ~~~ and the info
# string; the closing fence is the same character, at least as long, nothing after it.
FENCE = re.compile(r"^(?P<indent>[ \t]*)(?P<fence>`{3,}|~{3,})[ \t]*(?P<info>[^`\n]*)$")
NOT_RUN = re.compile(r"^\s*<!--\s*not-run\s*(?::\s*(?P<reason>.*?))?\s*-->\s*$")
# A block slower than this is a sign the example should be made smaller (fewer steps, a
# coarser mesh): the whole docs suite must stay well under a minute.
SLOW_BLOCK_SECONDS = 10.0


def repo_files():
    """Every file in the working tree except what tools keep there on their own."""
    skip = {".git", ".venv", "__pycache__", ".pytest_cache", ".hypothesis", ".ruff_cache"}
    out = set()
    for folder, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if d not in skip and not d.endswith(".egg-info")]
        out.update(os.path.join(folder, f) for f in files)
    return out


@dataclass
class Block:
    path: Path
    line: int  # 1-based line of the opening fence
    code: str
    not_run: str | None = None  # None: runs; otherwise the marker's reason ("" if missing)

    @property
    def id(self):
        return f"{self.path.relative_to(ROOT).as_posix()}:{self.line}"


def python_blocks(path):
    """The fenced Python blocks of one Markdown file, in order."""
    lines = path.read_text(encoding="utf-8").splitlines()
    blocks, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        fence, indent = m["fence"], len(m["indent"])
        lang = m["info"].split()[0].lower() if m["info"].strip() else ""
        body, j = [], i + 1
        while j < len(lines):
            close = lines[j].strip()
            if close and set(close) == {fence[0]} and len(close) >= len(fence):
                break
            # strip the fence's own indent (blocks inside list items), as Markdown does
            line = lines[j]
            body.append(line[min(indent, len(line) - len(line.lstrip())):])
            j += 1
        if lang in ("python", "py", "python3"):
            # the marker may be on the line right before the fence (blank lines allowed)
            k = i - 1
            while k >= 0 and not lines[k].strip():
                k -= 1
            marker = NOT_RUN.match(lines[k]) if k >= 0 else None
            not_run = (marker["reason"] or "") if marker else None
            blocks.append(Block(path, i + 1, "\n".join(body) + "\n", not_run))
        i = j + 1
    return blocks


BLOCKS = [b for p in DOC_FILES for b in python_blocks(p)]


@dataclass
class Page:
    """The notebook state of one Markdown file: its namespace and how far it has run."""

    namespace: dict = field(default_factory=lambda: {"__name__": "__doc_block__"})
    workdir: Path | None = None
    next_index: int = 0  # index into blocks_of(path) of the next block to run
    failed: str | None = None  # id of a block that raised: later ones cannot be trusted


PAGES: dict[Path, Page] = {}


def blocks_of(path):
    return [b for b in BLOCKS if b.path == path]


def execute(block, page):
    # compiled under the Markdown file's name, padded so a traceback gives the line in the .md
    source = "\n" * block.line + block.code
    code = compile(source, str(block.path), "exec")
    exec(code, page.namespace)


@pytest.fixture(scope="module")
def doc_env():
    """A temporary folder for the pages, and an off-screen SDL driver (put back after)."""
    with pytest.MonkeyPatch.context() as mp, tempfile.TemporaryDirectory(prefix="deforma-docs-") as tmp:
        mp.setenv("SDL_VIDEODRIVER", "offscreen")  # a window a block opens is real but unseen
        mp.setenv("SDL_AUDIODRIVER", "dummy")
        mp.setenv("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        yield Path(tmp)


def test_the_docs_have_python_blocks():
    # a broken fence pattern would otherwise make every case below silently disappear
    files = {b.path.name for b in BLOCKS}
    assert {"README.md", "mesh.md", "physics.md", "scenes.md"} <= files, files
    assert len(BLOCKS) >= 8


def test_every_not_run_marker_is_on_a_python_block():
    # a marker before prose or a bash block (or one misspelt) would silently mark nothing
    markers = sum(bool(NOT_RUN.match(line)) for p in DOC_FILES for line in p.read_text(encoding="utf-8").splitlines())
    loose = sum("not-run" in line for p in DOC_FILES for line in p.read_text(encoding="utf-8").splitlines())
    assert markers == loose, "a not-run marker does not match <!-- not-run: reason -->"
    assert markers == sum(b.not_run is not None for b in BLOCKS), "a not-run marker is not right before a python block"


@pytest.mark.parametrize("block", BLOCKS, ids=[b.id for b in BLOCKS])
def test_doc_block_runs(block, doc_env, monkeypatch):
    if block.not_run is not None:
        assert block.not_run.strip(), f"{block.id}: a <!-- not-run: reason --> marker must give its reason"
        pytest.skip(f"not-run: {block.not_run}")

    page = PAGES.setdefault(block.path, Page())
    if page.workdir is None:
        page.workdir = doc_env / block.path.stem
        page.workdir.mkdir()
    monkeypatch.chdir(page.workdir)  # relative paths in a block land here, never in the repo

    siblings = blocks_of(block.path)
    index = siblings.index(block)
    if page.next_index > index:  # the page ran past this block (a rerun): start it afresh
        page = PAGES[block.path] = Page(workdir=page.workdir)
    # the blocks above this one, if they have not run yet (this case selected on its own)
    for earlier in siblings[page.next_index:index]:
        if page.failed:
            break
        if earlier.not_run is None:
            try:
                execute(earlier, page)
            except BaseException:
                page.failed = earlier.id
                raise
        page.next_index += 1
    if page.failed:
        pytest.fail(f"{block.id} runs after {page.failed}, which failed: its names may be missing or wrong")
    assert page.next_index == index, "blocks of a file must run in order"

    before = repo_files()
    compile_seconds = []
    start = time.perf_counter()
    try:
        # Numba compiling (or loading its cache) on first use is not the example's cost: on a
        # cold cache the first block to step a world compiles for about a minute
        with numba_event.install_timer("numba:compile", compile_seconds.append):
            execute(block, page)
    except BaseException:
        page.failed = block.id
        raise
    finally:
        page.next_index = index + 1
    elapsed = time.perf_counter() - start - sum(compile_seconds)
    # a block that writes with an absolute path (or next to a module) would litter the checkout
    new_files = sorted(os.path.relpath(f, ROOT) for f in repo_files() - before)
    assert not new_files, f"{block.id} wrote into the repository: {new_files}"
    assert elapsed < SLOW_BLOCK_SECONDS, (
        f"{block.id} took {elapsed:.1f} s besides compiling: make the example smaller (fewer steps, a coarser mesh)")

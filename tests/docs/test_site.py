"""The docs site (MkDocs Material, ``mkdocs.yml``) builds with no warning, and every link and anchor of
docs/*.md resolves on it (issue 50).

Two parts:

- Checks that need nothing installed: every page of docs/ is in the nav and every nav entry is a
  page; every relative link of a page stays inside docs/ (the site holds only docs/, so a link to
  ``../src/...`` that works on GitHub is dead on the site) and reaches a file; every ``#anchor``
  names a heading of its page by the site's rule: GitHub's slug (``mkdocs.yml`` sets the toc
  extension's ``slugify`` to ``pymdownx.slugs.slugify(case="lower")``), but the second heading
  with the same slug gets ``_1`` where GitHub gives ``-1``, so a link to a repeated heading
  cannot work in both places and fails here. The gallery shows every built-in scene and every
  example, each picture a small PNG. ``tests/test_docs_links.py`` checks the same links by
  GitHub's rule, and README.md too; its Markdown reader is reused here.
- ``mkdocs build --strict`` (warnings are errors: ``mkdocs.yml`` also turns dead anchors into
  warnings), skipped with the reason when mkdocs is not installed (``pip install -e '.[docs]'``).
"""

import importlib.util
import re
import subprocess
import sys
from collections import Counter
from pathlib import Path
from urllib.parse import unquote

import pytest
from PIL import Image

from test_docs_links import EXTERNAL, HEADING, links, prose_lines, slug  # tests/ is on sys.path (conftest)

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.md"))
GALLERY_MAX_BYTES = 60_000
GALLERY_MAX_SIZE = (480, 270)
#: a nav entry: ``- Title: page.md`` or ``- page.md``
NAV_ENTRY = re.compile(r"^\s*-\s*(?:[^:\n]+:\s*)?(?P<page>[^\s:]+\.md)\s*$")


def nav_pages(config: Path = ROOT / "mkdocs.yml") -> list[str]:
    """The pages the nav of ``mkdocs.yml`` names, in order (read as text: no YAML parser needed)."""
    text = config.read_text(encoding="utf-8")
    nav = re.search(r"^nav:\n((?:[ \t]+.*\n|\n)*)", text, re.M)
    assert nav, "mkdocs.yml has no nav"
    return [m.group("page") for line in nav.group(1).splitlines() if (m := NAV_ENTRY.match(line))]


_site_anchors: dict[Path, set[str]] = {}


def site_anchors(page: Path) -> set[str]:
    """The ids of a page's headings on the site: GitHub's slug, repeats numbered ``_1``, ``_2``."""
    if page not in _site_anchors:
        seen: Counter = Counter()
        found = set()
        for _, line in prose_lines(page):
            m = HEADING.match(line)
            if m:
                base = slug(m.group(2))
                found.add(base if seen[base] == 0 else f"{base}_{seen[base]}")
                seen[base] += 1
        _site_anchors[page] = found
    return _site_anchors[page]


def site_link_problem(page: Path, target: str, docs: Path = DOCS) -> str | None:
    """Why a link of ``page`` is dead on the site, or None."""
    if EXTERNAL.match(target) or target.startswith("//"):
        return None
    file_part, _, anchor = target.partition("#")
    goal = (page.parent / unquote(file_part.split("?")[0])).resolve() if file_part else page
    if not goal.is_relative_to(docs.resolve()):
        return "leaves docs/: the site holds only docs/ (name the file in backticks instead)"
    if not goal.exists():
        return f"no such file: {file_part}"
    if anchor and goal.suffix == ".md" and unquote(anchor) not in site_anchors(goal):
        return f"no heading of {goal.name} has the id #{anchor} on the site"
    return None


def test_the_nav_lists_every_page_once_and_only_pages_that_exist():
    nav = nav_pages()
    assert len(nav) == len(set(nav)), nav
    assert sorted(nav) == sorted(p.name for p in PAGES)
    assert nav[0] == "index.md"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_link_and_anchor_resolves_on_the_site(page):
    dead = [f"docs/{page.name}:{n}: ({t}) {why}" for n, t in links(page) if (why := site_link_problem(page, t))]
    assert not dead, "\n".join(dead)


def test_the_site_checker_finds_dead_links(tmp_path):
    docs = tmp_path / "docs"
    docs.mkdir()
    (tmp_path / "outside.md").write_text("# Outside\n", encoding="utf-8")
    (docs / "other.md").write_text("# Top\n\n## Part\n\n## Part\n", encoding="utf-8")
    page = docs / "page.md"
    page.write_text("# Page\n[a](other.md#part_1) [b](other.md#part-1) [c](../outside.md) [d](#page) "
                    "[e](missing.md) [f](https://example.com/#x)\n", encoding="utf-8")
    dead = [t for _, t in links(page) if site_link_problem(page, t, docs)]
    assert dead == ["other.md#part-1", "../outside.md", "missing.md"]


def test_the_gallery_shows_every_scene_and_every_example_as_a_small_picture():
    from deforma.examples import NAMES
    from deforma.scene import builtin_scenes

    page = DOCS / "gallery.md"
    pictures = [t for _, t in links(page) if t.endswith(".png")]
    expected = [f"gallery/scene-{n}.png" for n in builtin_scenes()] + [f"gallery/example-{n}.png" for n in NAMES]
    missing = sorted(set(expected) - set(pictures))
    assert not missing, f"not in docs/gallery.md (python tools/gallery.py remakes it): {missing}"
    for target in pictures:
        path = DOCS / target
        assert path.stat().st_size < GALLERY_MAX_BYTES, f"{target}: {path.stat().st_size} bytes"
        with Image.open(path) as im:
            assert im.format == "PNG", target
            assert im.size[0] <= GALLERY_MAX_SIZE[0] and im.size[1] <= GALLERY_MAX_SIZE[1], (target, im.size)
    text = page.read_text(encoding="utf-8")
    assert "tools/gallery.py" in text  # the page says how its pictures are made


def test_mkdocs_build_strict_has_no_warning(tmp_path):
    if importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("material") is None:
        pytest.skip("mkdocs-material is not installed: pip install -e '.[docs]'")
    out = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                         cwd=ROOT, capture_output=True, text=True, timeout=300,
                         env={**__import__("os").environ, "NO_MKDOCS_2_WARNING": "1"})
    log = out.stdout + out.stderr
    assert out.returncode == 0, log
    assert "WARNING" not in log, log
    site = tmp_path / "site"
    assert (site / "index.html").is_file() and (site / "gallery" / "index.html").is_file()
    assert all((site / p.stem / "index.html").is_file() for p in PAGES if p.name != "index.md")

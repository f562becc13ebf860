"""The kernel cache is keyed by the sources kernels depend on (issue 18: no stale kernels)."""

import os

import numba
import pytest

from deforma import kernel_cache


def tree(tmp_path, files):
    for name, text in files.items():
        p = tmp_path / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return tmp_path


def test_the_key_follows_the_kernels_sources_and_nothing_else(tmp_path):
    root = tree(tmp_path, {"physics/a.py": "X = 1\n", "mesh/b.py": "Y = 2\n", "cli.py": "print(1)\n",
                           "render/k.py": "import numba\n"})
    key = kernel_cache.source_key(root)
    (root / "cli.py").write_text("print(2)\n")           # the CLI: kernels do not read it
    assert kernel_cache.source_key(root) == key
    (root / "physics/a.py").write_text("X = 3\n")        # a constant a kernel may have compiled in
    changed = kernel_cache.source_key(root)
    assert changed != key
    (root / "render/k.py").write_text("import numba  # edited\n")  # any file that uses Numba
    assert kernel_cache.source_key(root) != changed


@pytest.fixture
def restore_numba_cache_dir():
    before = numba.config.CACHE_DIR
    yield
    numba.config.CACHE_DIR = before


def test_numba_caches_in_a_folder_of_this_source_tree_and_old_ones_are_cleared(tmp_path, monkeypatch,
                                                                               restore_numba_cache_dir):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    base = tmp_path / "deforma"
    for k in range(5):  # folders of other source trees, used at different times
        (base / f"kernels-old{k}").mkdir(parents=True)
        os.utime(base / f"kernels-old{k}", (k, k))
    folder = kernel_cache.use_source_keyed_cache()
    assert folder == base / f"kernels-{kernel_cache.source_key()}" and folder.is_dir()
    assert numba.config.CACHE_DIR == str(folder)
    kept = sorted(p.name for p in base.iterdir())
    assert len(kept) == kernel_cache.KEEP and "kernels-old4" in kept and "kernels-old3" in kept


def test_the_users_numba_cache_dir_wins(tmp_path, monkeypatch, restore_numba_cache_dir):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "home"))
    assert kernel_cache.use_source_keyed_cache() is None
    assert not (tmp_path / "home").exists()

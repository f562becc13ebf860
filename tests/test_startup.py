"""Start-up (issue 18): a cold Numba cache is announced when compiling starts, and counted."""

from __future__ import annotations

import importlib.util
import sys
import time

import pytest

from deforma import startup
from deforma.cli import main

KERNELS = '''
from numba import njit


@njit(cache=True)
def cached_kernel(x):
    return x * 2.0 + 1.0


@njit
def uncached_helper(x):
    return x - 1.0
'''


def fresh_kernels(tmp_path, monkeypatch, name):
    """A module of never-compiled kernels whose cache lives in an empty NUMBA_CACHE_DIR."""
    import numba.core.config

    monkeypatch.setattr(numba.core.config, "CACHE_DIR", str(tmp_path / "numba-cache"))
    path = tmp_path / f"{name}.py"
    path.write_text(KERNELS)
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, name, mod)
    spec.loader.exec_module(mod)
    return mod


def test_a_cached_kernel_compiling_is_announced_once_and_timed(tmp_path, monkeypatch):
    mod = fresh_kernels(tmp_path, monkeypatch, "startup_kernels_a")
    said = []
    with startup.CompileWatch(on_first=lambda: said.append("compiling")) as watch:
        assert mod.cached_kernel(1.0) == 3.0
        assert mod.cached_kernel(2) == 5.0  # a second specialisation: still one message
    assert said == ["compiling"] and watch.compiled == 2 and watch.seconds > 0
    assert startup.is_cached_kernel(mod.cached_kernel) and not startup.is_cached_kernel(mod.uncached_helper)


def test_a_helper_without_cache_and_a_cache_hit_say_nothing(tmp_path, monkeypatch):
    mod = fresh_kernels(tmp_path, monkeypatch, "startup_kernels_b")
    mod.cached_kernel(1.0)  # compiled and written to the cache
    again = fresh_kernels(tmp_path, monkeypatch, "startup_kernels_b")  # a new process, in effect
    said = []
    with startup.CompileWatch(on_first=lambda: said.append("compiling")) as watch:
        assert again.cached_kernel(1.0) == 3.0  # loaded from the cache: no compile event
        assert again.uncached_helper(1.0) == 0.0  # compiles, but every process does: not a cold cache
    assert said == [] and watch.compiled == 0
    mod.cached_kernel(5.0)  # after the block: nothing is listening
    assert watch.compiled == 0


def test_deforma_run_says_it_is_compiling_and_counts_it(tmp_path, monkeypatch, capsys):
    from deforma import scene as scenes

    mod = fresh_kernels(tmp_path, monkeypatch, "startup_kernels_c")
    load = scenes.load

    def load_and_compile(name):  # as a cold cache would: a kernel compiles while the scene loads
        mod.cached_kernel(1.0)
        return load(name)

    monkeypatch.setattr(scenes, "load", load_and_compile)
    code = main(["run", "sample", "--seconds", "0.1", "--quiet"])
    out, err = capsys.readouterr()
    assert code == 0
    assert err.count(startup.COMPILE_MESSAGE) == 1
    assert "s compiling kernels, first run only; " in out and "s start-up; frames " in out
    # warm: nothing said, and the wall time still counts the whole command (a second of
    # simulation, so that the frames' time does not print as 0.00 s on a fast machine)
    assert main(["run", "sample", "--seconds", "1.0", "--quiet"]) == 0
    out, err = capsys.readouterr()
    assert "compiling" not in err + out
    wall = float(out.split(" s simulated in ")[1].split(" s wall")[0])
    startup_s = float(out.split("wall (")[1].split(" s start-up")[0])
    frames_s = float(out.split("; frames ")[1].split(" s,")[0])
    assert 0 < frames_s <= wall and startup_s + frames_s == pytest.approx(wall, abs=0.02)


def test_seconds_since_process_start_counts_the_interpreter_start():
    age = startup.seconds_since_process_start()
    # this test process imported pytest, numpy and deforma first: well over 0.1 s
    assert 0.1 < age < 24 * 3600


def test_a_process_that_began_as_a_shell_counts_from_deformas_import(monkeypatch):
    # bash -c "pip install ... && deforma run demo" runs deforma in the shell's own process,
    # which started before pip: its age is not Python's start-up (it said 48.61 s for about 5)
    since_import = time.perf_counter() - startup._IMPORTED
    monkeypatch.setattr(startup, "_process_age", lambda: since_import + startup.EXEC_AGE + 40.0)
    assert startup.seconds_since_process_start() == pytest.approx(since_import, abs=1.0)
    monkeypatch.setattr(startup, "_process_age", lambda: since_import + 0.5)  # Python from the start
    assert startup.seconds_since_process_start() == pytest.approx(since_import + 0.5, abs=0.1)


def test_a_run_without_a_terminal_does_not_import_tqdm(tmp_path):
    """tqdm draws only on a terminal; importing it anyway cost 65 ms of every start-up."""
    import subprocess

    code = ("import sys; from deforma.cli import main; "
            f"code = main(['run', 'sample', '--seconds', '0.05', '-o', {str(tmp_path) + '/'!r}]); "
            "print(code, 'tqdm' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert out.stdout.split()[-2:] == ["0", "False"], out.stderr

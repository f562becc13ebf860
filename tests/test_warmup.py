"""One compile for every scene (issue 50): the first run that compiles warms up the others'
kernels in a second process; ``deforma warmup`` does it in the foreground."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from deforma import startup, warmup
from deforma.cli import main


@pytest.fixture
def allowed(monkeypatch, tmp_path):
    """The warm-up allowed (the suite turns it off), with the kernel folder ``tmp_path``."""
    monkeypatch.setenv("DEFORMA_WARMUP", "1")
    monkeypatch.delenv(warmup.WORKER_ENV, raising=False)
    monkeypatch.setattr("deforma.kernel_cache.kernel_folder", lambda: tmp_path)
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    started = []
    real = subprocess.Popen

    def popen(args, **kw):
        started.append((args, kw))
        return real([sys.executable, "-c", "pass"])

    monkeypatch.setattr(subprocess, "Popen", popen)
    return started


def test_the_background_warm_up_starts_once_per_kernel_folder(allowed, tmp_path):
    job = warmup.start_background("demo")
    assert job is not None and len(allowed) == 1
    args, kw = allowed[0]
    assert args[1:] == ["-m", "deforma.warmup", "--folder", str(tmp_path), "--last", "demo"]
    # the worker compiles into the same folder, and does not start a warm-up of its own
    assert kw["env"]["NUMBA_CACHE_DIR"] == str(tmp_path) and kw["env"][warmup.WORKER_ENV] == "1"
    job.process.wait()
    (tmp_path / "warmup.pid").write_text(str(os.getpid()))  # one is running: not a second
    assert warmup.start_background("demo") is None
    (tmp_path / "warmup.pid").write_text("999999999")  # a stale pid: it died, start again
    assert warmup.start_background(None) is not None
    (tmp_path / "warmup.done").write_text("1 s\n")  # it has run for these sources
    assert warmup.start_background("demo") is None
    assert len(allowed) == 2


@pytest.mark.parametrize("why", ["turned off", "one core", "inside a warm-up", "no folder"])
def test_the_background_warm_up_is_not_started_where_it_would_not_help(allowed, monkeypatch, why):
    if why == "turned off":
        monkeypatch.setenv("DEFORMA_WARMUP", "0")
    elif why == "one core":
        monkeypatch.setattr(os, "cpu_count", lambda: 1)  # it would slow the run it is meant to help
    elif why == "inside a warm-up":
        monkeypatch.setenv(warmup.WORKER_ENV, "1")
    else:
        monkeypatch.setattr("deforma.kernel_cache.kernel_folder", lambda: None)
    assert warmup.start_background("demo") is None and allowed == []


def test_the_worker_marks_its_folder_done_or_keeps_what_failed(tmp_path, monkeypatch):
    seen = []

    def fake(last=None):
        seen.append((last, (tmp_path / "warmup.pid").read_text()))
        return 1.5

    monkeypatch.setattr(warmup, "warm_up", fake)
    assert warmup._worker(["--folder", str(tmp_path), "--last", "jelly"]) == 0
    assert seen == [("jelly", str(os.getpid()))]  # a pid file while it runs...
    assert (tmp_path / "warmup.done").read_text() == "1.5 s\n" and not (tmp_path / "warmup.pid").exists()

    def broken(last=None):
        raise RuntimeError("scene X broke")

    (tmp_path / "warmup.done").unlink()
    monkeypatch.setattr(warmup, "warm_up", broken)
    assert warmup._worker(["--folder", str(tmp_path)]) == 1
    assert "scene X broke" in (tmp_path / "warmup.log").read_text()  # ...and the next run tries again
    assert not (tmp_path / "warmup.done").exists() and not (tmp_path / "warmup.pid").exists()


def test_deforma_run_starts_the_warm_up_when_it_compiles_and_waits_for_it(tmp_path, monkeypatch, capsys):
    """A cold cache (a kernel compiling as the scene loads, as in tests/test_startup.py): the
    run starts the warm-up with its own scene last, says it waits for it, and returns only
    once it has ended."""
    from deforma import scene as scenes
    from test_startup import fresh_kernels

    mod = fresh_kernels(tmp_path, monkeypatch, "warmup_kernels_a")
    load = scenes.load

    def load_and_compile(name):
        mod.cached_kernel(1.0)
        return load(name)

    monkeypatch.setattr(scenes, "load", load_and_compile)
    jobs, flag = [], tmp_path / "said"

    def start(running):  # a warm-up that runs until the run says it waits for it
        p = subprocess.Popen([sys.executable, "-c", "import os, sys, time\n"
                              "while not os.path.exists(sys.argv[1]): time.sleep(0.02)", str(flag)])
        jobs.append((running, warmup.Background(p, 0.0)))
        return jobs[-1][1]

    def warn(message):
        print(message, file=sys.stderr)
        if "other built-in scenes" in message:
            flag.write_text("")

    monkeypatch.setattr(warmup, "start_background", start)
    monkeypatch.setattr(startup, "warn", warn)
    assert main(["run", "slope", "--seconds", "0.05", "--quiet"]) == 0
    err = capsys.readouterr().err
    assert err.count(startup.COMPILE_MESSAGE) == 1
    assert [r for r, _ in jobs] == ["slope"] and not jobs[0][1].running()
    assert "deforma: compiling the other built-in scenes' kernels (once;" in err


def test_the_warm_up_takes_every_built_in_scene_and_the_running_one_last():
    from deforma.scene.assets import builtin_scenes

    order = warmup._scene_order("demo")
    assert sorted(order) == sorted(builtin_scenes()) and order[-1] == "demo"
    assert order[:len(warmup.ORDER)] == list(warmup.ORDER)


def test_a_tear_later_in_a_run_compiles_nothing_after_the_warm_up(tmp_path):
    """The warm-up reaches what a scene runs only later: ``tear`` tears 1 s in. On a copy of
    the suite's kernel cache without the tearing kernels, the warm-up of ``tear`` compiles
    them again (its grabs tear the sheet), and a second process running the scene's whole
    script, tear included, then compiles none of them. (Only the tearing kernels are
    checked: what else the copy lacks depends on the tests run before. Measured over every
    built-in scene on a cold cache: after the whole warm-up, 8 s of each compiled nothing.)"""
    import shutil

    from deforma.kernel_cache import kernel_folder

    cache = tmp_path / "kernels"
    def copy(src, dst):  # another test worker may rename or replace a cache file meanwhile
        try:
            shutil.copy2(src, dst)
        except FileNotFoundError:
            pass

    shutil.copytree(kernel_folder(), cache, copy_function=copy)
    for p in cache.rglob("tearing.*"):
        p.unlink()
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    r = subprocess.run([sys.executable, "-c", "from deforma.warmup import warm_up; warm_up(['tear'])"], env=env,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr

    def tearing():
        return {p.name: p.stat().st_mtime_ns for p in cache.rglob("tearing.*")}

    warmed = tearing()
    assert any(name.endswith(".nbc") for name in warmed)
    check = textwrap.dedent("""
        from deforma import scene as scenes
        from deforma.scene.playback import Playback
        scene = scenes.load("tear")
        world = scene.build()
        n = len(world.bodies[0].positions)
        for _ in Playback(scene, world, fps=scene.run.fps).frames(int(scene.run.seconds * scene.run.fps)):
            pass
        print(len(world.bodies[0].positions) - n)
    """)
    r = subprocess.run([sys.executable, "-c", check], env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert int(r.stdout) > 0  # it tore
    assert tearing() == warmed  # and compiled no tearing kernel of its own


def test_deforma_warmup_runs_the_warm_up_and_says_what_it_did(monkeypatch, capsys):
    seen = []

    def fake(names=None, *, last=None, steps=3, progress=None):
        for name in ("slope", "jelly"):
            seen.append(name)
            progress(name)
        return 2.5

    monkeypatch.setattr(warmup, "warm_up", fake)
    assert main(["warmup"]) == 0
    out = capsys.readouterr().out
    assert seen == ["slope", "jelly"]
    assert out.startswith("warm-up: 2 built-in scenes in 2.5 s (every kernel was already compiled)")


def test_a_run_that_fails_stops_the_warm_up_instead_of_waiting(tmp_path, monkeypatch, capsys):
    from deforma import scene as scenes
    from test_startup import fresh_kernels

    mod = fresh_kernels(tmp_path, monkeypatch, "warmup_kernels_b")

    def compile_then_fail(name):
        mod.cached_kernel(1.0)
        raise ValueError("a scene that cannot be read")

    monkeypatch.setattr(scenes, "load", compile_then_fail)
    jobs = []

    def start(running):  # a warm-up that would run for ten minutes
        jobs.append(warmup.Background(subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"]), 0.0))
        return jobs[-1]

    monkeypatch.setattr(warmup, "start_background", start)
    assert main(["run", "slope", "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "a scene that cannot be read" in err and "other built-in scenes" not in err
    assert len(jobs) == 1 and not jobs[0].running()

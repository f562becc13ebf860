"""``python benchmarks/run.py`` shows each row as soon as its case is measured (issue 18)."""

from __future__ import annotations

import importlib.util
import io
import sys
import types
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def load_run_module():
    spec = importlib.util.spec_from_file_location("deforma_benchmarks_run", BENCH / "run.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)  # puts benchmarks/ on sys.path, so `common` is importable
    return mod


def test_each_row_is_printed_when_made_and_the_table_at_the_end(monkeypatch):
    run = load_run_module()
    import common

    progress = io.StringIO()
    seen_while_running = []

    def fake_run(quick):
        first = common.Row("fake", "first case", 1.5, "s")
        seen_while_running.append(progress.getvalue())  # printed before the topic returns
        return [first, common.Row("fake", "second case", 2.0, "ms", goal="<= 3 ms", met=True)]

    monkeypatch.setitem(sys.modules, "bench_fake", types.SimpleNamespace(run=fake_run))
    rows = run.run_topics(["fake"], quick=True, progress=progress)

    assert "fake..." in seen_while_running[0]
    assert "| fake | first case | 1.5 s |" in seen_while_running[0]
    lines = progress.getvalue().splitlines()
    assert len(lines) == 3 and lines[-1].endswith("| fake | second case | 2 ms |  | <= 3 ms | yes |")
    assert common.row_listeners == []  # nothing printed for rows made after the run
    table = common.format_table(rows)
    assert table.splitlines()[2:] == [line.split("] ", 1)[1] for line in lines[1:]]


def test_unknown_topic_is_refused(capsys):
    run = load_run_module()
    with pytest.raises(SystemExit) as e:
        run.main(["--only", "no-such-topic"])
    assert e.value.code == 2
    assert "unknown topic" in capsys.readouterr().err


def test_bench_video_reads_the_runs_figures_and_refuses_an_unfinished_run():
    load_run_module()  # benchmarks/ on sys.path
    import bench_video

    line = "demo: 300 frames, 9.97 s simulated in 5.10 s wall (0.5 s start-up; ...) -> demo.mp4\nBENCH_WALL 4.25\n"
    assert bench_video.parse_run(line) == (9.97, 4.25)
    with pytest.raises(RuntimeError, match="not a finished deforma run"):
        bench_video.parse_run("deforma: error: something\nBENCH_WALL 0.2\n")
    assert set(bench_video.GOALS) == {"mp4", "gif"} and "physics" in bench_video.CASES

"""Run every benchmark module and print one Markdown table.

Usage: ``python benchmarks/run.py [--quick] [--only delaunay,physics,...]``

A full run takes minutes: each row is printed to stderr as soon as its case is measured
(with the time since the start), and the whole table goes to stdout at the end, so
``python benchmarks/run.py > table.md`` still writes a clean table.
"""

from __future__ import annotations

import argparse
import importlib
import platform
import sys
import time
from pathlib import Path
from typing import Callable, TextIO

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import common  # noqa: E402
from common import Row, format_row, format_table  # noqa: E402


def machine() -> str:
    import os

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, {platform.system()}"


def progress_printer(stream: TextIO, start: float) -> Callable[[Row], None]:
    """A row listener that writes each row as a table line, prefixed by seconds since ``start``."""

    def show(row: Row) -> None:
        print(f"[{time.perf_counter() - start:6.1f} s] {format_row(row)}", file=stream, flush=True)

    return show


def run_topics(topics: list[str], *, quick: bool, progress: TextIO | None = None) -> list[Row]:
    """Rows of every topic's ``bench_<topic>.run``, each shown on ``progress`` as it is made."""
    start = time.perf_counter()
    listener = progress_printer(progress, start) if progress is not None else None
    if listener is not None:
        common.row_listeners.append(listener)
    try:
        rows = []
        for t in topics:
            if progress is not None:
                print(f"[{time.perf_counter() - start:6.1f} s] {t}...", file=progress, flush=True)
            mod = importlib.import_module(f"bench_{t}")
            rows += mod.run(quick=quick)
        return rows
    finally:
        if listener is not None:
            common.row_listeners.remove(listener)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--quick", action="store_true", help="smaller sizes and fewer repeats")
    p.add_argument("--only", default="", help="comma-separated topics, e.g. delaunay,physics")
    a = p.parse_args(argv)
    topics = sorted(f.stem[len("bench_"):] for f in HERE.glob("bench_*.py"))
    if a.only:
        wanted = a.only.split(",")
        unknown = sorted(set(wanted) - set(topics))
        if unknown:
            p.error(f"unknown topic(s) {unknown}; available: {', '.join(topics)}")
        topics = [t for t in topics if t in wanted]
    print(f"machine: {machine()}\n", flush=True)
    rows = run_topics(topics, quick=a.quick, progress=sys.stderr)
    print(format_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())

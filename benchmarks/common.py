"""Shared helpers for the benchmark modules: median timing and one table format.

Every ``benchmarks/bench_*.py`` module exposes ``run(quick: bool) -> list[Row]``;
``python benchmarks/run.py`` calls them all and prints one table. Peers are always
measured in the same run as deforma, so ratios compare like with like on a noisy machine.
A full run takes minutes, so run.py also prints each row the moment a module makes it
(``row_listeners``): a Row is made when its case has been measured.
"""

from __future__ import annotations

import gc
import statistics
import time
from dataclasses import dataclass
from typing import Callable

# Called with each Row as it is made (run.py prints it); the bench modules need not know.
row_listeners: list[Callable[["Row"], None]] = []


@dataclass
class Row:
    """One line of the benchmark table.

    ``value`` is the measured figure (median) in ``unit``; ``goal`` says in words what the
    issue asks and ``met`` whether this run met it (None when the row is informational).
    """

    topic: str
    case: str
    value: float
    unit: str
    ratio: str = ""
    goal: str = ""
    met: bool | None = None

    def __post_init__(self) -> None:
        for listener in row_listeners:
            listener(self)


def median_seconds(fn: Callable[[], object], *, repeat: int = 5, warmup: int = 1) -> float:
    """Median wall time of ``fn()`` in seconds over ``repeat`` runs after ``warmup`` runs."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        gc.collect()
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def format_row(r: Row) -> str:
    """One row as a line of the Markdown table that ``format_table`` renders."""
    met = "" if r.met is None else ("yes" if r.met else "**no**")
    return f"| {r.topic} | {r.case} | {r.value:.4g} {r.unit} | {r.ratio} | {r.goal} | {met} |"


def format_table(rows: list[Row]) -> str:
    """Render rows as a GitHub-flavoured Markdown table."""
    head = "| topic | case | median | ratio | goal | met |\n| --- | --- | ---: | --- | --- | --- |"
    return "\n".join([head] + [format_row(r) for r in rows])


def interleaved_medians(candidates: dict, repeat: int) -> dict:
    """Median seconds per call of each candidate, timed in turns (a shared machine's load
    then weighs on all alike); one untimed warm-up call each first."""
    for f in candidates.values():
        f()
    times = {k: [] for k in candidates}
    for _ in range(repeat):
        for k, f in candidates.items():
            t0 = time.perf_counter()
            f()
            times[k].append(time.perf_counter() - t0)
    return {k: statistics.median(v) for k, v in times.items()}

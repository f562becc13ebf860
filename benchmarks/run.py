"""Run every benchmark module and print one Markdown table.

Usage: ``python benchmarks/run.py [--quick] [--only delaunay,physics,...]``
"""

from __future__ import annotations

import argparse
import importlib
import platform
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from common import format_table  # noqa: E402


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
    rows = []
    for t in topics:
        mod = importlib.import_module(f"bench_{t}")
        rows += mod.run(quick=a.quick)
    print(format_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())

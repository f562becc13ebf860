"""Compare the benchmark rows of two source trees, measured alternately in one run.

A change that should not cost speed (a refactor) is measured against the tree before it:
each round runs ``benchmarks/run.py`` in one tree, then in the other (the order flips every
round, so neither always runs on a warmer or quieter machine), each tree with its own
sources and benchmarks. Every row's median over the rounds is printed with the ratio of
the new tree's figure to the base's (for rows in seconds or milliseconds: above 1 is
slower). The machine is shared: quote medians, and rerun a row that looks off.

Usage::

    git worktree add /tmp/base <commit>
    python tools/ab_speed.py /tmp/base --rounds 5 --only physics,contacts,integrators,fem,behaviours

The new tree is the one this file is in. Each tree's Numba cache is its own (kernels are
keyed by their sources), so the first round compiles in both; it is not counted unless
``--keep-first``.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
ROW = re.compile(r"^\| (?P<topic>[^|]+) \| (?P<case>[^|]+) \| (?P<value>[-+0-9.einf]+) (?P<unit>[^|]*?) \|")


def run_tree(tree: Path, only: str, quick: bool) -> dict[str, tuple[float, str]]:
    """``{topic | case: (value, unit)}`` of one run of ``tree``'s benchmarks."""
    env = dict(os.environ, PYTHONPATH=str(tree / "src"))
    cmd = [sys.executable, str(tree / "benchmarks" / "run.py"), "--only", only] + (["--quick"] if quick else [])
    out = subprocess.run(cmd, cwd=tree, env=env, capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(f"{tree}: benchmarks failed:\n{out.stderr[-2000:]}")
    rows = {}
    for line in out.stdout.splitlines():
        m = ROW.match(line)
        if m:
            rows[f"{m['topic'].strip()} | {m['case'].strip()}"] = (float(m["value"]), m["unit"].strip())
    return rows


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("base", type=Path, help="the tree to compare with (a git worktree of the commit before)")
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--only", default="physics,contacts,integrators,fem,behaviours")
    p.add_argument("--quick", action="store_true")
    p.add_argument("--keep-first", action="store_true", help="count the first round (which compiles)")
    a = p.parse_args(argv)
    trees = {"base": a.base.resolve(), "new": HERE}
    got = {"base": [], "new": []}
    for r in range(a.rounds + (0 if a.keep_first else 1)):
        order = ["base", "new"] if r % 2 == 0 else ["new", "base"]
        for name in order:
            rows = run_tree(trees[name], a.only, a.quick)
            if r > 0 or a.keep_first:
                got[name].append(rows)
            print(f"round {r} {name}: {len(rows)} rows", file=sys.stderr, flush=True)
    print("| row | base | new | new / base |\n| --- | --- | --- | --- |")
    for key in got["new"][0]:
        if not all(key in rows for rows in got["base"] + got["new"]):
            continue
        unit = got["new"][0][key][1]
        b = statistics.median(rows[key][0] for rows in got["base"])
        n = statistics.median(rows[key][0] for rows in got["new"])
        ratio = n / b if b else float("nan")
        print(f"| {key} | {b:.4g} {unit} | {n:.4g} {unit} | {ratio:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())

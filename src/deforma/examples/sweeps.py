"""Sweeps: one scene run for several stiffnesses at once on a local Ray cluster, a table row per run.

A sweep file names a scene, the simulated seconds and the scene keys to vary; ``deforma.sweep``
runs every combination on Ray's workers and writes one Parquet row per run (status, metrics,
parameters). Needs the ``sweep`` extra (``pip install 'deforma[sweep]'``); Ray takes about
10 s to start its local cluster. ``deforma sweep FILE -o DIR`` does the same from a shell
(``docs/sweeps.md``).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import deforma

from ._common import PICTURE_SIZE, parser, save_picture

#: The sweep file: the built-in ``sample`` scene (a soft box dropped on a plane), three stiffnesses.
SPEC = """\
scene = "sample"
seconds = 3.0
mode = "grid"

[parameters]
"physics.youngs_modulus" = [500.0, 1500.0, 5000.0]
"""
KEY = "physics.youngs_modulus"


def main(argv: list[str] | None = None) -> int:
    """Run the sweep into a folder; print each run's stiffness, status and where the box's centre rests."""
    p = parser("sweeps", __doc__)
    p.add_argument("--outdir", default=None,
                   help="folder for the sweep file and results.parquet (default: a temporary folder, removed)")
    p.add_argument("--workers", type=int, default=2, help="Ray workers (default 2)")
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="deforma-sweep-example-") as tmp:
        folder = Path(args.outdir or tmp)
        folder.mkdir(parents=True, exist_ok=True)
        spec = folder / "stiffness.toml"
        spec.write_text(SPEC, encoding="utf-8")
        try:
            result = deforma.sweep(spec, folder / "out", workers=args.workers)
        except deforma.sweeps.SweepError as e:
            p.exit(1, f"{p.prog}: {e}\n")
        from deforma.sweeps import read_results

        rows = sorted(read_results(folder / "out").to_pylist(), key=lambda r: r[KEY])
    print(f"{result.total} runs: {result.ok} ok, {result.unstable} unstable, {result.error} error")
    print(f"{'E (Pa)':>8s} {'status':8s} {'centre height m':>15s} {'at rest from s':>14s}")
    heights = []
    for row in rows:
        height = row["centroid"][0][1] if row["centroid"] else float("nan")
        heights.append(height)
        print(f"{row[KEY]:8.0f} {row['status']:8s} {height:15.3f} {row['time_to_rest_s']:14.2f}")
    if args.output:
        save_picture(bar_chart([f"E = {row[KEY]:.0f} Pa" for row in rows], heights, "centre height (m)"),
                     args.output)
    return 0


def bar_chart(labels: list[str], values: list[float], title: str):
    """A small horizontal bar chart (a Pillow image), so the example needs no plotting library."""
    from PIL import Image, ImageDraw

    width, bar, gap = PICTURE_SIZE, 40, 16
    image = Image.new("RGB", (width, gap + (bar + gap) * len(values) + 24), "#f4f1ea")
    draw = ImageDraw.Draw(image)
    draw.text((gap, 6), title, fill="#1d2433")
    top = max((v for v in values if v == v), default=1.0) or 1.0
    for k, (label, value) in enumerate(zip(labels, values)):
        y = 24 + gap + k * (bar + gap)
        length = 0 if value != value else round((width - 4 * gap - 160) * value / top)  # NaN: no bar
        draw.rectangle((120 + gap, y, 120 + gap + length, y + bar), fill="#e07a5f")
        draw.text((gap, y + bar // 2 - 6), label, fill="#1d2433")
        draw.text((min(120 + 2 * gap + length, width - 48), y + bar // 2 - 6), f"{value:.3f}", fill="#1d2433")
    return image

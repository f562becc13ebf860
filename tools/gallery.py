"""Draw the docs site's gallery: a picture of every built-in scene and every example, and the page.

Usage (from the repository root; needs the ``render`` extra for the scenes)::

    python tools/gallery.py                        # every picture, then docs/gallery.md
    python tools/gallery.py --only demo tearing    # just these scenes or examples, then the page
    python tools/gallery.py --page                 # only docs/gallery.md, from the pictures there

A scene is played by its own script (events, pulls) up to the moment named in
:data:`SCENE_SECONDS` (default: the end of its run) and drawn as ``deforma run`` draws it,
480x270 pixels, with its camera; an example runs as ``python -m deforma.examples NAME
--output docs/gallery/example-NAME.png`` in its own process (the sweep starts Ray, the notebook
an OpenGL context). Pictures are palette PNGs under :data:`MAX_BYTES` (60 KB), checked here and
by ``tests/docs/test_site.py``, which also checks that the page lists every scene and example.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "gallery"
PAGE = ROOT / "docs" / "gallery.md"
SIZE = (480, 270)
MAX_BYTES = 60_000
#: Scenes shown at a telling moment rather than at the end of their run (simulated seconds).
SCENE_SECONDS = {"explode": 1.8, "balloon": 1.0, "crates": 1.2, "chain": 3.0, "demo": 4.0}
#: Options an example needs to draw its gallery picture instead of ``--output PATH``.
EXAMPLE_ARGS = {
    # the energy plot is the picture; a short run keeps it quick
    "integrators": lambda path: ["--seconds", "2", "--video", "", "--plot", str(path)],
}


def save_small(image, path: Path) -> int:
    """Save a Pillow image as a palette PNG no wider or taller than :data:`SIZE`; its size in bytes."""
    image = image.convert("RGB")
    image.thumbnail(SIZE)
    path.parent.mkdir(parents=True, exist_ok=True)
    image.quantize(256).save(path, format="PNG", optimize=True)
    return path.stat().st_size


def scene_picture(name: str) -> Path:
    """Play built-in scene ``name`` to its moment and draw it into ``docs/gallery/scene-NAME.png``."""
    from PIL import Image

    from deforma.render import Renderer, WorldView
    from deforma.scene import load
    from deforma.scene.playback import Playback, frame_count

    scene = load(name)
    world = scene.build()
    seconds = SCENE_SECONDS.get(name, scene.run.seconds)
    Playback(scene, world, fps=scene.run.fps).play(frame_count(seconds, scene.run.fps) + 1)
    renderer = Renderer.headless(SIZE)
    try:
        frame = WorldView(renderer, world, scene).draw()
    finally:
        renderer.release()
    path = OUT / f"scene-{name}.png"
    save_small(Image.fromarray(frame), path)
    return path


def example_picture(name: str) -> Path:
    """Run example ``name`` in its own process and keep its picture as ``docs/gallery/example-NAME.png``."""
    from PIL import Image

    path = OUT / f"example-{name}.png"
    with tempfile.TemporaryDirectory() as tmp:
        raw = Path(tmp) / "picture.png"
        args = EXAMPLE_ARGS.get(name, lambda p: ["--output", str(p)])(raw)
        subprocess.run([sys.executable, "-m", "deforma.examples", name, *args], cwd=tmp, check=True,
                       stdout=subprocess.DEVNULL)
        with Image.open(raw) as im:
            save_small(im, path)
    return path


def page() -> str:
    """The Markdown of ``docs/gallery.md``: a section per scene and per example, with its command."""
    from deforma import examples
    from deforma.scene import builtin_scenes, load

    lines = ["# Gallery", "",
             "Every built-in scene and every example, as a picture. The pictures are made by",
             "`python tools/gallery.py` (480x270 at most, headless); run it again after a scene or an",
             "example changes.", "",
             "## Scenes", "",
             "`deforma run NAME -o NAME.mp4` renders a scene to a video, `deforma view NAME` opens it in",
             "the viewer ([the command](cli.md), [scene files](scenes.md)).", ""]
    for name in builtin_scenes():
        scene = load(name)
        seconds = SCENE_SECONDS.get(name, scene.run.seconds)
        lines += [f"### {name}", "", f"![the {name} scene at t = {seconds:g} s](gallery/scene-{name}.png)", "",
                  f"{scene.scene.description} At t = {seconds:g} s; `deforma run {name}`.", ""]
    lines += ["## Examples", "",
              "`python -m deforma.examples` lists the examples and `python -m deforma.examples NAME` runs",
              "one; `--output PATH.png` draws the picture shown here, `NAME --help` lists its options. Their",
              "sources are in `src/deforma/examples/`.", ""]
    for name in examples.NAMES:
        lines += [f"### {name}", "", f"![the {name} example](gallery/example-{name}.png)", "",
                  f"{examples.summary(name)} `python -m deforma.examples {name}`.", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Draw the pictures asked for, then write the page."""
    from deforma import examples
    from deforma.scene import builtin_scenes

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--only", nargs="+", metavar="NAME", help="only these scenes or examples")
    p.add_argument("--page", action="store_true", help="only write docs/gallery.md")
    args = p.parse_args(argv)
    scenes, names = list(builtin_scenes()), list(examples.NAMES)
    if args.only:
        unknown = [n for n in args.only if n not in scenes and n not in names]
        if unknown:
            p.error(f"not a scene or an example: {', '.join(unknown)} (scenes: {', '.join(scenes)}; "
                    f"examples: {', '.join(names)})")
        scenes = [n for n in scenes if n in args.only]
        names = [n for n in names if n in args.only]
    if args.page:
        scenes = names = []
    too_big, failed = [], []
    for kind, todo, draw in (("scene", scenes, scene_picture), ("example", names, example_picture)):
        for name in todo:
            t0 = time.perf_counter()
            try:
                path = draw(name)
            except Exception as e:  # noqa: BLE001 - one broken scene must not stop the others' pictures
                print(f"{kind:7s} {name:12s} failed: {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")
                failed.append(name)
                continue
            size = path.stat().st_size
            print(f"{kind:7s} {name:12s} {size / 1000:5.1f} KB  {time.perf_counter() - t0:5.1f} s  "
                  f"-> {path.relative_to(ROOT)}")
            if size > MAX_BYTES:
                too_big.append(path.name)
    PAGE.write_text(page(), encoding="utf-8")
    print(f"wrote {PAGE.relative_to(ROOT)}")
    if too_big:
        print(f"over {MAX_BYTES // 1000} KB: {', '.join(too_big)}", file=sys.stderr)
    if failed:
        print(f"no new picture (the old one, if any, stays): {', '.join(failed)}", file=sys.stderr)
    return 1 if too_big or failed else 0


if __name__ == "__main__":
    sys.exit(main())

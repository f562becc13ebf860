"""What the examples share: their command line and the picture they write."""

from __future__ import annotations

import argparse
from pathlib import Path

#: The longer side of an example's picture in pixels: the gallery's width, and small files.
PICTURE_SIZE = 480


def parser(name: str, doc: str | None) -> argparse.ArgumentParser:
    """The example's options: ``--output PATH.png`` for a picture of what it ends with.

    Parameters
    ----------
    name : str
        The example's name, for its usage line.
    doc : str
        The example module's docstring: its first line is the description, the rest the epilog.
    """
    first, _, rest = (doc or "").strip().partition("\n")
    p = argparse.ArgumentParser(prog=f"python -m deforma.examples {name}", description=first,
                                epilog=rest.strip() or None, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("-o", "--output", metavar="PATH.png", default=None,
                   help="also write a picture of the end state to this PNG file")
    return p


def save_picture(image, output: str | None) -> None:
    """Write a Pillow image to ``output`` as PNG (nothing when ``output`` is None).

    Palette PNGs: flat-shaded triangles have few colours, so 256 of them keep the picture and
    make the file several times smaller than RGB (the gallery keeps every picture under 60 KB).
    """
    if not output:
        return
    path = Path(output)
    path.parent.mkdir(parents=True, exist_ok=True)
    image.convert("RGB").quantize(256).save(path, format="PNG", optimize=True)
    print(f"wrote {path}")


def save_world(world, output: str | None) -> None:
    """Write a picture of ``world`` as it is now to ``output`` (see :func:`save_picture`)."""
    if output:
        from ..mesh.picture import world_picture

        save_picture(world_picture(world, size=PICTURE_SIZE), output)


def step_for(world, seconds: float) -> None:
    """Step ``world`` on by ``seconds`` of simulated time (whole steps of ``world.dt``)."""
    for _ in range(round(seconds / world.dt)):
        world.step()

"""Draw deforma's built-in textures (bunny, donut, armadillo) and patterns (the tear scene's cloth).

Each picture is made here from hand-made outlines (coordinate lists on a 100 x 100 grid,
y down, smoothed by closed Catmull-Rom splines) and drawn with Pillow: flat colours,
gradients for shading, outlines, eyes and details, on a transparent background. Drawing
happens at 4x the final size and is scaled down, which antialiases the edges (the alpha
channel then gives the mesher smooth sub-pixel outlines).

No detail is pure black: a picture flattened onto black must keep its silhouette (the
mesher treats black as background when there is no alpha).

Run from the repository root::

    python tools/make_textures.py            # writes src/deforma/assets/textures/*.png
                                             # and src/deforma/assets/patterns/cloth.png
    python tools/make_textures.py --size 512 --out /tmp/textures
"""

from __future__ import annotations

import argparse
import math
import random
from pathlib import Path

import numpy as np
from PIL import Image, ImageChops, ImageDraw, ImageFilter

SUPERSAMPLE = 4
DEFAULT_SIZE = 384
OUT = Path(__file__).resolve().parents[1] / "src" / "deforma" / "assets" / "textures"


# ---- helpers ---------------------------------------------------------------------------------


def smooth(points, samples=10, closed=True):
    """Closed (or open) Catmull-Rom spline through hand-placed control points."""
    p = np.asarray(points, float)
    n = len(p)
    out = []
    rng = range(n) if closed else range(n - 1)
    for i in rng:
        p0 = p[(i - 1) % n] if closed or i > 0 else p[0]
        p1, p2 = p[i], p[(i + 1) % n]
        p3 = p[(i + 2) % n] if closed or i + 2 < n else p[-1]
        for t in np.linspace(0, 1, samples, endpoint=False):
            t2, t3 = t * t, t * t * t
            out.append(
                0.5
                * (
                    2 * p1
                    + (-p0 + p2) * t
                    + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t2
                    + (-p0 + 3 * p1 - 3 * p2 + p3) * t3
                )
            )
    if not closed:
        out.append(p[-1])
    return np.array(out)


def ellipse_outline(cx, cy, rx, ry, n=64, start=0.0):
    a = start + np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[cx + rx * np.cos(a), cy + ry * np.sin(a)]


class Canvas:
    """An RGBA picture addressed in 0..100 units (y down), drawn at SUPERSAMPLE x size."""

    def __init__(self, size):
        self.size = size
        self.px = size * SUPERSAMPLE
        self.img = Image.new("RGBA", (self.px, self.px), (0, 0, 0, 0))

    def xy(self, pts):
        k = self.px / 100.0
        return [(float(x) * k, float(y) * k) for x, y in pts]

    def w(self, units):
        return max(1, int(round(units * self.px / 100.0)))

    def mask(self, pts):
        m = Image.new("L", (self.px, self.px), 0)
        ImageDraw.Draw(m).polygon(self.xy(pts), fill=255)
        return m

    def _draw(self, colour):
        """A drawing context: straight onto the picture for opaque colours; through a
        composited layer for translucent ones (ImageDraw replaces pixels, alpha included,
        so drawing a translucent colour directly would punch see-through holes)."""
        if colour[3] == 255:
            return ImageDraw.Draw(self.img), None
        layer = Image.new("RGBA", self.img.size, (0, 0, 0, 0))
        return ImageDraw.Draw(layer), layer

    def _done(self, layer):
        if layer is not None:
            self.img.alpha_composite(layer)

    def fill(self, pts, colour, outline=None, width=0.8):
        d, layer = self._draw(colour)
        d.polygon(self.xy(pts), fill=colour)
        self._done(layer)
        if outline is not None:
            self.line(np.vstack([pts, pts[:1]]), outline, width)

    def line(self, pts, colour, width=0.8):
        d, layer = self._draw(colour)
        xy = self.xy(pts)
        d.line(xy, fill=colour, width=self.w(width), joint="curve")
        r = self.w(width) / 2
        for x, y in (xy[0], xy[-1]):  # round caps
            d.ellipse((x - r, y - r, x + r, y + r), fill=colour)
        self._done(layer)

    def disc(self, cx, cy, r, colour, outline=None, width=0.6):
        self.fill(ellipse_outline(cx, cy, r, r), colour, outline, width)

    def shade(self, region, top, bottom, *, angle=90.0, within=None):
        """Paint a linear gradient (top colour -> bottom colour) inside a polygon mask.

        ``angle`` is the gradient direction in degrees (90 = downwards); ``within`` an
        optional extra mask (for example the silhouette) the paint is clipped to.
        """
        mask = region if isinstance(region, Image.Image) else self.mask(region)
        if within is not None:
            mask = ImageChops.multiply(mask, within)
        yy, xx = np.mgrid[0 : self.px, 0 : self.px] / self.px
        a = math.radians(angle)
        t = xx * math.cos(a) + yy * math.sin(a)
        box = np.array(mask.getbbox() or (0, 0, self.px, self.px)) / self.px
        corners = [(box[0], box[1]), (box[2], box[1]), (box[0], box[3]), (box[2], box[3])]
        proj = [cx * math.cos(a) + cy * math.sin(a) for cx, cy in corners]
        t = np.clip((t - min(proj)) / max(max(proj) - min(proj), 1e-9), 0, 1)[..., None]
        c0, c1 = np.array(top, float), np.array(bottom, float)
        rgba = (c0 * (1 - t) + c1 * t).astype(np.uint8)
        layer = Image.fromarray(rgba, "RGBA")
        self.img.paste(layer, (0, 0), ImageChops.multiply(mask, layer.getchannel("A")))

    def soft(self, pts, colour, blur=2.0, within=None):
        """A blurred blob of colour (highlights, cheeks, shadows) clipped to ``within``."""
        m = self.mask(pts).filter(ImageFilter.GaussianBlur(self.w(blur)))
        if within is not None:
            m = ImageChops.multiply(m, within)
        # the colour's alpha only weakens the mask: the paint itself is opaque, so the
        # picture's own alpha (its silhouette) is left alone
        layer = Image.new("RGBA", self.img.size, tuple(colour[:3]) + (255,))
        m = m.point(lambda v: v * colour[3] // 255)
        self.img.paste(layer, (0, 0), m)

    def layer(self):
        """A blank canvas of the same size, to draw details that are then clipped."""
        return Canvas(self.size)

    def paste(self, other, mask):
        """Paint ``other`` (a canvas from :meth:`layer`) onto this one, clipped to ``mask``."""
        self.img.paste(other.img, (0, 0), ImageChops.multiply(mask, other.img.getchannel("A")))

    def result(self):
        small = self.img.convert("RGBa").resize((self.size, self.size), Image.LANCZOS)
        return small.convert("RGBA")


# ---- bunny -----------------------------------------------------------------------------------

# A brown rabbit sitting, facing right. Ears well apart so the mesh keeps them apart.
BUNNY_BODY = [(22, 93), (12, 84), (10, 70), (16, 56), (28, 46), (44, 42), (58, 46),
              (68, 56), (72, 70), (72, 84), (66, 93), (44, 95)]
BUNNY_HEAD = [(56, 38), (58, 27), (66, 21), (77, 21), (86, 28), (90, 38), (87, 46),
              (78, 51), (66, 51), (58, 46)]
BUNNY_EAR_BACK = [(59, 27), (52, 18), (45, 8), (43, 3), (47, 2), (54, 8), (62, 18), (66, 23)]
BUNNY_EAR_FRONT = [(71, 22), (73, 12), (77, 4), (82, 2), (84, 5), (83, 13), (79, 22), (76, 25)]
BUNNY_EAR_BACK_IN = [(58, 23), (51, 14), (47, 6), (50, 6), (56, 13), (62, 21)]
BUNNY_EAR_FRONT_IN = [(74, 21), (76, 12), (79, 6), (81, 6), (81, 13), (78, 21)]
BUNNY_TAIL = ellipse_outline(12, 80, 7.5, 7.5, 40)
BUNNY_PAW = [(62, 86), (70, 83), (80, 86), (82, 91), (76, 95), (64, 95)]
BUNNY_HIND = [(22, 80), (30, 70), (42, 70), (48, 80), (50, 92), (40, 96), (26, 95)]


def draw_bunny(size):
    c = Canvas(size)
    fur, fur_dark, fur_light = (176, 122, 80, 255), (122, 78, 50, 255), (222, 180, 132, 255)
    line = (86, 52, 34, 255)
    body, head = smooth(BUNNY_BODY), smooth(BUNNY_HEAD)
    ear_b, ear_f = smooth(BUNNY_EAR_BACK), smooth(BUNNY_EAR_FRONT)

    c.fill(ear_b, fur_dark, line)
    c.fill(smooth(BUNNY_EAR_BACK_IN), (214, 140, 150, 255))
    c.fill(body, fur, line)
    c.shade(body, (205, 155, 105, 255), (130, 84, 52, 255), angle=110)
    c.soft(smooth([(40, 60), (60, 58), (66, 74), (60, 90), (46, 88), (40, 74)]), (238, 214, 180, 230),
           blur=3, within=c.mask(body))  # light belly
    hind = smooth(BUNNY_HIND)
    c.fill(hind, (160, 106, 68, 255), line)
    c.shade(hind, (190, 138, 92, 255), (128, 82, 52, 255), angle=80)
    c.fill(ear_f, fur, line)
    c.shade(ear_f, (200, 150, 104, 255), (160, 108, 70, 255), angle=80)
    c.fill(smooth(BUNNY_EAR_FRONT_IN), (236, 160, 170, 255))
    c.soft(smooth([(77, 10), (80, 7), (80, 18), (77, 19)]), (250, 196, 204, 200), blur=1.2)
    c.fill(head, fur, line)
    c.shade(head, (214, 168, 120, 255), (150, 100, 64, 255), angle=100)
    c.soft(smooth([(76, 38), (86, 36), (88, 44), (80, 49), (72, 46)]), fur_light, blur=2.5,
           within=c.mask(head))  # muzzle
    c.soft(ellipse_outline(70, 44, 4, 3), (230, 140, 140, 150), blur=2, within=c.mask(head))  # cheek
    c.fill(BUNNY_TAIL, (246, 240, 232, 255), (190, 170, 150, 255), 0.5)
    c.soft(ellipse_outline(10, 78, 3, 3), (255, 255, 255, 255), blur=1.5)
    c.fill(smooth(BUNNY_PAW), fur_light, line, 0.6)
    for x in (70, 75):
        c.line([(x, 91), (x + 1, 94.5)], line, 0.4)
    # eye: iris, pupil, highlight
    c.disc(76, 32, 4.0, (70, 42, 26, 255), (60, 36, 24, 255), 0.5)
    c.disc(76.6, 32.4, 2.6, (36, 24, 20, 255))
    c.disc(75.2, 30.8, 1.1, (255, 255, 255, 255))
    c.line([(72, 27.5), (75, 26.6), (79, 27.5)], line, 0.5)  # brow
    # nose, mouth, whiskers
    c.fill(smooth([(87.5, 38), (90, 38.5), (89, 40.8)], 6), (226, 110, 126, 255))
    c.line(smooth([(88.5, 41), (87.5, 43.5), (85, 44.5)], 6, closed=False), line, 0.45)
    c.line(smooth([(88.5, 41), (89.2, 43.8), (88.6, 45)], 6, closed=False), line, 0.45)
    # whiskers end inside the head: a hair-thin spur outside would be a sliver of foreground
    for dy in (-1.6, 0.0, 1.6):
        c.line([(82, 42.5 + dy * 0.4), (88.5, 43 + dy)], (110, 80, 60, 255), 0.3)
    return c.result()


# ---- donut -----------------------------------------------------------------------------------


def draw_donut(size):
    c = Canvas(size)
    cx = cy = 50
    outer = ellipse_outline(cx, cy, 47, 47, 160)
    hole = ellipse_outline(cx, cy, 16, 16, 96)
    ring = ImageChops.subtract(c.mask(outer), c.mask(hole))
    # dough, darker towards the rim, with a baked band
    c.shade(ring, (226, 168, 92, 255), (168, 102, 46, 255), angle=60)
    c.soft(ellipse_outline(cx - 4, cy - 6, 34, 30), (240, 196, 120, 200), blur=6, within=ring)
    # wavy pink icing (hand-placed radii around the ring)
    icing_out_r = [41, 43, 38, 42, 44, 40, 37, 42, 43, 39, 41, 44, 38, 40, 43, 41]
    icing_in_r = [21, 20, 22, 20.5, 21.5, 20, 22, 21, 20.5, 22, 20, 21.5, 20.5, 22, 21, 20]
    a_out = np.linspace(0, 2 * np.pi, len(icing_out_r), endpoint=False)
    a_in = np.linspace(0, 2 * np.pi, len(icing_in_r), endpoint=False) + 0.2
    ic_out = smooth([(cx + r * math.cos(a), cy + r * math.sin(a)) for r, a in zip(icing_out_r, a_out)], 12)
    ic_in = smooth([(cx + r * math.cos(a), cy + r * math.sin(a)) for r, a in zip(icing_in_r, a_in)], 10)
    icing = ImageChops.subtract(c.mask(ic_out), c.mask(ic_in))
    c.shade(icing, (250, 150, 196, 255), (214, 80, 146, 255), angle=60)
    c.line(np.vstack([ic_out, ic_out[:1]]), (188, 64, 122, 255), 0.6)
    c.line(np.vstack([ic_in, ic_in[:1]]), (188, 64, 122, 255), 0.5)
    # glossy highlight on the icing
    c.soft(smooth([(26, 30), (36, 20), (48, 15), (50, 19), (38, 25), (30, 34)]), (255, 236, 246, 210),
           blur=1.5, within=icing)
    # sprinkles: short rounded sticks in six colours, seeded so the picture never changes
    rng = random.Random(7)
    colours = [(255, 240, 90, 255), (90, 200, 255, 255), (120, 230, 120, 255),
               (255, 255, 255, 255), (255, 140, 40, 255), (160, 100, 230, 255)]
    placed = []
    while len(placed) < 70:
        a = rng.uniform(0, 2 * math.pi)
        r = rng.uniform(24.5, 36.5)
        x, y = cx + r * math.cos(a), cy + r * math.sin(a)
        if any((x - px) ** 2 + (y - py) ** 2 < 16 for px, py in placed):
            continue
        placed.append((x, y))
        t = rng.uniform(0, math.pi)
        dx, dy = 1.6 * math.cos(t), 1.6 * math.sin(t)
        c.line([(x - dx + 0.25, y - dy + 0.35), (x + dx + 0.25, y + dy + 0.35)], (150, 40, 90, 120), 1.1)
        c.line([(x - dx, y - dy), (x + dx, y + dy)], rng.choice(colours), 1.1)
    # rim lines
    c.line(np.vstack([outer, outer[:1]]), (130, 74, 34, 255), 0.7)
    c.line(np.vstack([hole, hole[:1]]), (130, 74, 34, 255), 0.7)
    img = c.img
    # cut the hole (drawing above may have spilled into it)
    alpha = ImageChops.multiply(img.getchannel("A"), ImageChops.invert(c.mask(ellipse_outline(cx, cy, 15.6, 15.6, 96))))
    img.putalpha(alpha)
    return c.result()


# ---- armadillo -------------------------------------------------------------------------------

# Nine-banded armadillo walking right: domed shell, banded middle, pointed snout, long tail.
ARM_SHELL = [(14, 64), (16, 50), (24, 38), (36, 30), (50, 27), (64, 30), (75, 38), (81, 50),
             (82, 64), (70, 67), (48, 68), (26, 67)]
ARM_HEAD = [(76, 42), (84, 40), (90, 46), (97, 57), (98, 61), (94, 62), (84, 62), (77, 60)]
ARM_EAR = [(78, 42), (79, 33), (83, 30), (85, 35), (83, 43)]
ARM_TAIL = [(18, 58), (10, 66), (5, 76), (3, 86), (5, 86), (9, 76), (16, 68), (22, 64)]
# Feet stay apart: touching feet would close a hole of background between two legs.
ARM_LEGS = [
    [(22, 62), (30, 62), (30, 78), (31.5, 81), (20.5, 81), (22, 76)],
    [(35, 63), (42, 63), (42, 77), (43.5, 80), (34, 80), (35, 75)],
    [(57, 63), (65, 63), (65, 78), (66.5, 81), (55.5, 81), (57, 76)],
    [(71, 62), (78, 61), (78, 77), (79.5, 80), (70, 80), (71, 75)],
]


def draw_armadillo(size):
    c = Canvas(size)
    skin, skin_dark = (214, 168, 146, 255), (164, 116, 98, 255)
    shell_top, shell_bottom = (176, 150, 124, 255), (118, 94, 74, 255)
    line = (80, 62, 50, 255)
    tail = smooth(ARM_TAIL, 8)
    c.fill(tail, (170, 140, 114, 255), line, 0.6)
    for k in range(6):  # tail rings
        t = 0.12 + 0.14 * k
        i = int(t * len(tail) / 2)
        j = len(tail) - 1 - i
        c.line([tuple(tail[i]), tuple(tail[j])], (120, 96, 78, 255), 0.5)
    for far, leg in enumerate(ARM_LEGS):
        pts = np.array(leg, float)
        c.fill(pts, skin_dark if far in (1, 3) else skin, line, 0.5)
        x0, y0 = pts[4]
        for k in range(3):  # claws, kept inside the foot
            c.line([(x0 + 2.5 + 2.8 * k, 78.2), (x0 + 2.0 + 2.8 * k, 79.6)], (240, 230, 210, 255), 0.7)
    head = smooth(ARM_HEAD, 8)
    c.fill(head, skin, line, 0.6)
    c.shade(head, (226, 186, 164, 255), (170, 122, 104, 255), angle=100)
    c.fill(smooth(ARM_EAR, 8), skin_dark, line, 0.5)
    c.fill(smooth([(80, 40), (81, 34), (83, 33), (83, 40)], 6), (226, 150, 150, 255))
    shell = smooth(ARM_SHELL, 10)
    shell_mask = c.mask(shell)
    c.fill(shell, shell_top)
    c.shade(shell, shell_top, shell_bottom, angle=90)
    c.soft(smooth([(30, 38), (44, 31), (58, 31), (54, 37), (40, 40)]), (222, 204, 178, 200), blur=3,
           within=shell_mask)  # sheen
    # the nine bands: curved stripes across the middle of the shell (clipped to it)
    detail = c.layer()
    for k in range(9):
        x = 34 + 3.6 * k
        band = smooth([(x - 1.3, 29), (x + 1.3, 29), (x + 2.2, 48), (x + 1.3, 68), (x - 1.3, 68), (x - 0.4, 48)], 6)
        detail.fill(band, (150, 118, 94, 255) if k % 2 else (196, 170, 140, 255))
        detail.line(smooth([(x - 1.3, 26), (x - 0.4, 48), (x - 1.3, 68)], 8, closed=False), (96, 74, 58, 255), 0.45)
    # scale pattern on the front and back shields
    for x0, x1 in ((12, 34), (66, 84)):
        for y in range(30, 66, 5):
            for x in np.arange(x0 + (y % 10) / 4, x1, 4.2):
                detail.fill(ellipse_outline(x, y, 1.5, 1.2, 12), (202, 178, 150, 255), (110, 86, 68, 255), 0.3)
    c.paste(detail, shell_mask)
    c.line(np.vstack([shell, shell[:1]]), line, 0.8)
    # skirt of the shell over the legs
    c.line(smooth([(14, 64), (26, 67), (48, 68), (70, 67), (82, 64)], 8, closed=False), (92, 70, 54, 255), 1.0)
    # eye, nostril, mouth
    c.disc(87, 49.5, 1.9, (60, 40, 34, 255))
    c.disc(86.5, 49, 0.6, (255, 255, 255, 255))
    c.disc(96.4, 58.8, 0.6, (120, 70, 70, 255))
    c.line(smooth([(97, 61), (93, 61.2), (89, 60.5)], 6, closed=False), line, 0.4)
    return c.result()


def draw_cloth(size):
    """A tartan for the ``tear`` scene's sheet: a square sett, the same across and down.

    Each thread has one colour (the same sequence across and down, as in a tartan), and a
    pixel shows the mean of its vertical and horizontal thread: the stripes and their
    crossings, without a pixel-wide twill (with one, `deforma run tear -o tear.gif` wrote
    11.8 MB; without, 4.7 MB; the flat-coloured sheet 1.2 MB). Opaque, and no thread is
    black, so that the picture is all cloth whichever rule reads it.
    """
    navy, blue, green, cream, red = (40, 58, 104), (61, 126, 166), (46, 110, 82), (236, 226, 196), (176, 52, 48)
    # the sett: (colour, threads); repeated twice across the picture, mirrored about its end
    sett = [(navy, 24), (blue, 6), (navy, 4), (blue, 20), (cream, 2), (blue, 20), (green, 24), (red, 4), (green, 8)]
    half = [c for c, n in sett for _ in range(n)]
    repeat = half + half[::-1]
    scale = size / (2 * len(repeat))
    idx = (np.arange(size) / scale).astype(int) % len(repeat)
    colours = np.array(repeat, np.float64)[idx]  # (size, 3): the thread colour at each column (and row)
    rgb = np.rint(0.5 * (colours[None, :, :] + colours[:, None, :])).astype(np.uint8)
    alpha = np.full((size, size, 1), 255, np.uint8)
    return Image.fromarray(np.concatenate([rgb, alpha], axis=2), "RGBA")


TEXTURES = {"bunny": draw_bunny, "donut": draw_donut, "armadillo": draw_armadillo}
# patterns: pictures only drawn on a body (no shape to mesh), in assets/patterns
PATTERNS = {"cloth": draw_cloth}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=DEFAULT_SIZE, help="output side in pixels (256-512)")
    parser.add_argument("--out", type=Path, default=OUT, help="output folder")
    args = parser.parse_args(argv)
    if not 256 <= args.size <= 512:
        parser.error(f"--size must be in [256, 512], got {args.size}")
    args.out.mkdir(parents=True, exist_ok=True)
    patterns = args.out.parent / "patterns" if args.out == OUT else args.out
    patterns.mkdir(parents=True, exist_ok=True)
    for folder, pictures in ((args.out, TEXTURES), (patterns, PATTERNS)):
        for name, draw in pictures.items():
            path = folder / f"{name}.png"
            draw(args.size).save(path, optimize=True)
            print(f"wrote {path}")


if __name__ == "__main__":
    main()

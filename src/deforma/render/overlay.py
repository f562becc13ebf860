"""A time and scale overlay for video frames: ``t = 1.25 s`` at the top left, a scale bar at the bottom left.

Drawn with Pillow onto the frame read back from OpenGL (no font files or GL text needed), and
only into the two small corner regions it covers, so a 1280x720 frame costs well under a
millisecond more than without it. The text has a light outline so it reads on the pale default
background as well as on a dark scene or a textured body passing behind it.
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = ["draw_overlay", "format_length", "overlay_insets", "scale_bar_length"]

TEXT_COLOR = (25, 28, 34)
OUTLINE_COLOR = (255, 255, 255)
#: The scale bar is the largest 1, 2 or 5 times a power of ten metres no longer than this
#: share of the picture's width: long enough to read, short enough to stay in its corner.
SCALE_BAR_MAX_SHARE = 0.2

_fonts: dict[int, object] = {}


def _font(size: int):
    """Pillow's built-in font at ``size`` pixels (cached: loading it costs a few ms)."""
    from PIL import ImageFont

    font = _fonts.get(size)
    if font is None:
        try:
            font = ImageFont.load_default(size=size)
        except TypeError:  # Pillow < 10.1: only the small bitmap font, at its own size
            font = ImageFont.load_default()
        _fonts[size] = font
    return font


def scale_bar_length(metres_per_pixel: float, width: int) -> float:
    """The scale bar's length in metres: 1, 2 or 5 times a power of ten, at most a fifth of ``width``.

    Parameters
    ----------
    metres_per_pixel : float
        The picture's scale, metres per pixel (> 0).
    width : int
        The picture's width in pixels.

    Examples
    --------
    >>> scale_bar_length(0.01, 800)     # 8 m across: at most 1.6 m
    1.0
    >>> scale_bar_length(0.05, 1280)    # 64 m across: at most 12.8 m
    10.0
    >>> scale_bar_length(0.0004, 640)   # 0.256 m across
    0.05
    """
    longest = SCALE_BAR_MAX_SHARE * width * metres_per_pixel
    power = 10.0 ** math.floor(math.log10(longest))
    for step in (5.0, 2.0, 1.0):
        if step * power <= longest * (1 + 1e-9):
            return float(f"{step * power:.12g}")  # 0.05, not 0.05000000000000001
    return power  # pragma: no cover - 1 * power <= longest by the choice of power


def format_length(metres: float) -> str:
    """A scale bar's label: metres, or centimetres/millimetres/kilometres where they read better.

    Examples
    --------
    >>> format_length(1.0), format_length(0.05), format_length(0.002), format_length(2000.0)
    ('1 m', '5 cm', '2 mm', '2 km')
    """
    for unit, size in (("km", 1e3), ("m", 1.0), ("cm", 1e-2), ("mm", 1e-3)):
        if metres >= size * (1 - 1e-9):
            return f"{metres / size:.12g} {unit}"
    return f"{metres * 1e6:.12g} µm"


def _metrics(h: int) -> tuple[int, int, int, int, int]:
    """Text size, margin, outline, bar thickness and tick height (pixels) for a picture ``h`` high:
    everything follows the picture's height, so a thumbnail and a 4K frame look alike."""
    size = max(9, round(h / 30))
    return size, max(3, size // 2), max(1, size // 10), max(2, size // 8), max(3, size // 3)


#: Every character a label can hold (the time's and the scale bar's), for the rows they can reach.
_LABEL_CHARS = "t = -0123456789.s kmcµ"


@functools.lru_cache(maxsize=16)  # asked at every frame a view draws with its overlay on (75 us a call)
def overlay_insets(height: int) -> tuple[int, int]:
    """Rows ``(top, bottom)`` of a picture ``height`` pixels high that the overlay's text may use.

    The time's label lies in the top rows, the scale bar and its label in the bottom rows, each
    with a gap of half a margin toward the picture. :class:`deforma.render.WorldView` frames the
    world between them (:func:`deforma.render.framing.fit_camera`) when its overlay is on, so the
    overlay never covers what the scene shows at its start.

    Examples
    --------
    >>> overlay_insets(720)
    (45, 39)
    """
    from PIL import Image, ImageDraw

    size, margin, stroke, thick, tick = _metrics(int(height))
    font = _font(size)
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    box = probe.textbbox((0, 0), _LABEL_CHARS, font=font, stroke_width=stroke)
    t, b = math.floor(box[1]), math.ceil(box[3])
    gap = max(2, margin // 2)
    top = margin + b + 1 + gap                               # the time: drawn at (margin, margin)
    bar = margin + thick + tick + stroke                     # the bar's ticks and outline
    label = margin + b - t                                   # its label ends level with the bar
    return top, max(bar, label) + gap


def draw_overlay(frame: np.ndarray, *, time: float, metres_per_pixel: float) -> np.ndarray:
    """Write the simulated time (top left) and a scale bar (bottom left) onto a frame, in place.

    Parameters
    ----------
    frame : (H, W, 3) ndarray of uint8
        The picture, row 0 on top (what :meth:`Renderer.read` returns). Changed in place.
    time : float
        Simulated time in seconds, shown as ``t = 1.25 s``.
    metres_per_pixel : float
        The picture's scale (:meth:`Camera.metres_per_pixel`), for the bar's length in pixels.

    Returns
    -------
    ndarray
        ``frame``, for chaining.

    Raises
    ------
    ValueError
        If ``frame`` is not an (H, W, 3) uint8 array, or ``time`` or ``metres_per_pixel`` is
        not finite (``metres_per_pixel`` must be > 0).

    Examples
    --------
    >>> import numpy as np
    >>> frame = np.full((180, 320, 3), 200, np.uint8)
    >>> _ = draw_overlay(frame, time=1.25, metres_per_pixel=0.025)   # 8 m across: a 1 m bar
    >>> bool((frame[:30, :100] != 200).any()), bool((frame[-30:, :100] != 200).any())
    (True, True)
    >>> bool((frame[40:140] != 200).any())      # the middle of the picture is untouched
    False
    """
    from PIL import Image, ImageDraw

    if not (isinstance(frame, np.ndarray) and frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3):
        got = f"{frame.dtype} {frame.shape}" if isinstance(frame, np.ndarray) else type(frame).__name__
        raise ValueError(f"frame must be an (H, W, 3) uint8 array, got {got}")
    if not math.isfinite(time):
        raise ValueError(f"time must be a finite number of seconds, got {time!r}")
    if not (math.isfinite(metres_per_pixel) and metres_per_pixel > 0):
        raise ValueError(f"metres_per_pixel must be a finite number > 0, got {metres_per_pixel!r}")
    h, w = frame.shape[:2]
    size, margin, stroke, thick, tick = _metrics(h)
    font = _font(size)

    def region(x0, y0, x1, y1, paint):
        # draw only into the corner's pixels: converting a whole frame costs more than the text
        x0, y0, x1, y1 = max(0, x0), max(0, y0), min(w, x1), min(h, y1)
        if x1 <= x0 or y1 <= y0:
            return
        im = Image.fromarray(frame[y0:y1, x0:x1])
        paint(ImageDraw.Draw(im), x0, y0)
        frame[y0:y1, x0:x1] = np.asarray(im)

    label = f"t = {time:.2f} s"
    probe = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    l, t, r, b = probe.textbbox((margin, margin), label, font=font, stroke_width=stroke)
    region(l, t, r + 1, b + 1, lambda d, x0, y0: d.text((margin - x0, margin - y0), label, font=font,
                                                          fill=TEXT_COLOR, stroke_width=stroke,
                                                          stroke_fill=OUTLINE_COLOR))

    length = scale_bar_length(metres_per_pixel, w)
    bar_px = max(1, round(length / metres_per_pixel))
    text = format_length(length)
    bar_y = h - margin - thick  # the bar's top row
    l, t, r, b = probe.textbbox((0, 0), text, font=font, stroke_width=stroke)
    text_x = margin + bar_px + margin // 2
    text_y = bar_y + thick - b  # the label's baseline box ends level with the bar's bottom

    def paint_bar(d, x0, y0):
        x, y = margin - x0, bar_y - y0
        # an outlined bar with end ticks: reads on light and dark alike
        for colour, grow in ((OUTLINE_COLOR, stroke), (TEXT_COLOR, 0)):
            d.rectangle([x - grow, y - grow, x + bar_px - 1 + grow, y + thick - 1 + grow], fill=colour)
            for tx in (x, x + bar_px - thick):
                d.rectangle([tx - grow, y - tick - grow, tx + thick - 1 + grow, y + thick - 1 + grow], fill=colour)
        d.text((text_x - x0, text_y - y0), text, font=font, fill=TEXT_COLOR, stroke_width=stroke,
               stroke_fill=OUTLINE_COLOR)

    top = min(bar_y - tick - stroke, text_y + t)
    region(margin - stroke, top, text_x + r + 1, h, paint_bar)
    return frame

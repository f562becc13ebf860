"""Pygame surfaces (panel, status line, help) drawn over the OpenGL picture as textured quads,
and markers (pinned vertices) as small squares.

The window is an OpenGL window, so pygame cannot blit into it; instead each surface is
uploaded to a texture (only when it changed) and drawn as a quad at a pixel rectangle.
Markers are one instanced draw of squares at pixel centres: only their centres are uploaded.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import moderngl
import numpy as np
import pygame
from numpy.typing import ArrayLike

__all__ = ["PIN_MARK", "Overlay", "OverlayLayer"]

_VS = """
#version 330
uniform vec4 u_rect;      // x, y, w, h in pixels, y down from the window's top
uniform vec2 u_window;
out vec2 v_uv;
void main() {
    vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1);
    vec2 px = u_rect.xy + corner * u_rect.zw;
    v_uv = vec2(corner.x, 1.0 - corner.y);
    gl_Position = vec4(px.x / u_window.x * 2.0 - 1.0, 1.0 - px.y / u_window.y * 2.0, 0.0, 1.0);
}
"""

_FS = """
#version 330
uniform sampler2D u_tex;
in vec2 v_uv;
out vec4 f_color;
void main() { f_color = texture(u_tex, v_uv); }
"""


_MARK_VS = """
#version 330
uniform vec2 u_window;
uniform float u_size;     // side of the square in pixels
in vec2 in_center;        // per instance: pixels, y down from the window's top
void main() {
    vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1) - 0.5;
    vec2 px = in_center + corner * u_size;
    gl_Position = vec4(px.x / u_window.x * 2.0 - 1.0, 1.0 - px.y / u_window.y * 2.0, 0.0, 1.0);
}
"""

_MARK_FS = """
#version 330
uniform vec4 u_color;
out vec4 f_color;
void main() { f_color = u_color; }
"""

#: Pinned-vertex markers: a dark square in a light frame, visible on dark textures and on the
#: pale background alike. (side in pixels, RGBA in [0, 1]), drawn in this order.
PIN_MARK = ((9.0, (0.96, 0.97, 0.98, 1.0)), (5.0, (0.09, 0.11, 0.15, 1.0)))


class OverlayLayer:
    """One surface's texture; :meth:`upload` copies the surface's pixels when they changed."""

    # ctx is a moderngl.Context, typed Any as in deforma.render.Renderer: moderngl's stubs type a
    # program's members as a union (uniform, attribute, ...) that every ``prog[name].value = ...``
    # would have to narrow
    def __init__(self, ctx: Any, size: Sequence[float]) -> None:
        self.ctx = ctx
        self.size: tuple[int, int] = (int(size[0]), int(size[1]))
        self.texture = ctx.texture(self.size, 4)
        self.texture.filter = (moderngl.NEAREST, moderngl.NEAREST)

    def upload(self, surface: pygame.Surface) -> None:
        if surface.get_size() != self.size:
            self.texture.release()
            self.size = surface.get_size()
            self.texture = self.ctx.texture(self.size, 4)
            self.texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        # flipped: texture row 0 is the bottom in OpenGL
        self.texture.write(pygame.image.tobytes(surface, "RGBA", True))

    def release(self) -> None:
        self.texture.release()


class Overlay:
    """Draws :class:`OverlayLayer` textures at pixel rectangles of the window's framebuffer."""

    def __init__(self, ctx: Any) -> None:  # a moderngl.Context (see OverlayLayer)
        self.ctx = ctx
        self.program = ctx.program(vertex_shader=_VS, fragment_shader=_FS)
        self.vao = ctx.vertex_array(self.program, [])
        self.mark_program = ctx.program(vertex_shader=_MARK_VS, fragment_shader=_MARK_FS)
        self._mark_capacity = 64
        self.mark_vbo = ctx.buffer(reserve=self._mark_capacity * 8)
        self.mark_vao = ctx.vertex_array(self.mark_program, [(self.mark_vbo, "2f/i", "in_center")])

    def draw_marks(self, centers: ArrayLike, window_size: tuple[int, int], *,
                   style: Sequence[tuple[float, Sequence[float]]] = PIN_MARK) -> None:
        """Draw a square marker centred on each pixel of ``centers`` ((N, 2), y down).

        Parameters
        ----------
        centers : (N, 2) array
            Window pixels (column, row from the top); rounded so the squares sit on whole pixels.
        window_size : (int, int)
        style : sequence of (side, rgba)
            Squares drawn one over the other at each centre (default :data:`PIN_MARK`).
        """
        c = np.round(np.asarray(centers, dtype=np.float32).reshape(-1, 2))
        n = len(c)
        if not n:
            return
        if n > self._mark_capacity:
            self._mark_capacity = max(n, 2 * self._mark_capacity)
            self.mark_vao.release()
            self.mark_vbo.release()
            self.mark_vbo = self.ctx.buffer(reserve=self._mark_capacity * 8)
            self.mark_vao = self.ctx.vertex_array(self.mark_program, [(self.mark_vbo, "2f/i", "in_center")])
        self.mark_vbo.write(np.ascontiguousarray(c, dtype=np.float32).tobytes())
        ctx = self.ctx
        ctx.viewport = (0, 0, *window_size)
        ctx.disable(moderngl.BLEND)
        self.mark_program["u_window"].value = (float(window_size[0]), float(window_size[1]))
        for side, color in style:
            self.mark_program["u_size"].value = float(side)
            self.mark_program["u_color"].value = tuple(float(v) for v in color)
            self.mark_vao.render(moderngl.TRIANGLE_STRIP, vertices=4, instances=n)

    def layer(self, size: Sequence[float]) -> OverlayLayer:
        return OverlayLayer(self.ctx, size)

    def draw(self, layer: OverlayLayer, pos: Sequence[float], window_size: tuple[int, int], *,
             blend: bool = True) -> None:
        """Draw ``layer`` with its top-left corner at pixel ``pos`` (y down) of the window."""
        ctx = self.ctx
        ctx.viewport = (0, 0, *window_size)
        if blend:
            ctx.enable(moderngl.BLEND)
            # pygame surfaces are not premultiplied: the usual "over"
            ctx.blend_func = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA, moderngl.ONE,
                              moderngl.ONE_MINUS_SRC_ALPHA)
        else:
            ctx.disable(moderngl.BLEND)
        self.program["u_rect"].value = (float(pos[0]), float(pos[1]), float(layer.size[0]), float(layer.size[1]))
        self.program["u_window"].value = (float(window_size[0]), float(window_size[1]))
        layer.texture.use(0)
        self.program["u_tex"].value = 0
        self.vao.render(moderngl.TRIANGLE_STRIP, vertices=4)

    def release(self) -> None:
        self.mark_vao.release()
        self.mark_vbo.release()
        self.mark_program.release()
        self.vao.release()
        self.program.release()


def rounded_box(size: tuple[int, int], color: tuple[int, ...], radius: int = 8) -> pygame.Surface:
    """A translucent rounded rectangle to put text on."""
    s = pygame.Surface(size, pygame.SRCALPHA)
    pygame.draw.rect(s, color, s.get_rect(), border_radius=radius)
    return s


def as_rgb_array(raw: bytes, size: tuple[int, int]) -> np.ndarray:
    """Bytes read from the framebuffer (rows bottom-up) as an (H, W, 3) array, row 0 on top."""
    w, h = size
    return np.frombuffer(raw, dtype=np.uint8).reshape(h, w, 3)[::-1].copy()

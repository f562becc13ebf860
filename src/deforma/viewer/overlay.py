"""Pygame surfaces (panel, status line, help) drawn over the OpenGL picture as textured quads.

The window is an OpenGL window, so pygame cannot blit into it; instead each surface is
uploaded to a texture (only when it changed) and drawn as a quad at a pixel rectangle.
"""

from __future__ import annotations

import moderngl
import numpy as np
import pygame

__all__ = ["Overlay", "OverlayLayer"]

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


class OverlayLayer:
    """One surface's texture; :meth:`upload` copies the surface's pixels when they changed."""

    def __init__(self, ctx, size):
        self.ctx = ctx
        self.size = (int(size[0]), int(size[1]))
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

    def __init__(self, ctx):
        self.ctx = ctx
        self.program = ctx.program(vertex_shader=_VS, fragment_shader=_FS)
        self.vao = ctx.vertex_array(self.program, [])

    def layer(self, size) -> OverlayLayer:
        return OverlayLayer(self.ctx, size)

    def draw(self, layer: OverlayLayer, pos, window_size, *, blend: bool = True) -> None:
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
        self.vao.release()
        self.program.release()


def rounded_box(size, color, radius: int = 8) -> pygame.Surface:
    """A translucent rounded rectangle to put text on."""
    s = pygame.Surface(size, pygame.SRCALPHA)
    pygame.draw.rect(s, color, s.get_rect(), border_radius=radius)
    return s


def as_rgb_array(raw: bytes, size) -> np.ndarray:
    """Bytes read from the framebuffer (rows bottom-up) as an (H, W, 3) array, row 0 on top."""
    w, h = size
    return np.frombuffer(raw, dtype=np.uint8).reshape(h, w, 3)[::-1].copy()

"""Draw soft bodies, colliders and a background with moderngl (OpenGL 3.3).

The same :class:`Renderer` draws into a window (give it the window's context and
``target=ctx.screen``) or headless into its own off-screen framebuffer (use
:meth:`Renderer.headless`, which opens an EGL standalone context: no display needed).
It only reads arrays: nothing here knows about the physics.

moderngl is imported lazily so that ``import deforma`` works without it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Iterable, Sequence

import numpy as np

from .collider_mesh import FLOATS_PER_VERTEX, ColliderGeometry, collider_corners, collider_shape

if TYPE_CHECKING:
    import moderngl  # imported lazily at run time (see above)
    from numpy.typing import ArrayLike

__all__ = ["Camera", "MeshHandle", "Renderer", "collider_corners"]

# Colours are linear RGBA floats in [0, 1]; the palette is chosen to read well on video:
# a pale sky-to-sand background, slate colliders, bodies in their own texture or colour.
BACKGROUND_TOP = (0.86, 0.91, 0.96)
BACKGROUND_BOTTOM = (0.97, 0.95, 0.91)
GRID_COLOR = (0.45, 0.52, 0.62, 0.18)
COLLIDER_FILL = (0.36, 0.40, 0.47, 1.0)
COLLIDER_EDGE = (0.20, 0.23, 0.28, 1.0)
WIREFRAME_COLOR = (0.10, 0.12, 0.16, 0.55)
DEFAULT_BODY_COLOR = (0.89, 0.48, 0.37, 1.0)


@dataclass(frozen=True)
class Camera:
    """What part of the world the picture shows.

    Parameters
    ----------
    center : (float, float)
        World point at the middle of the picture, metres.
    size : (float, float)
        Width and height in metres that must be visible. The picture keeps square pixels,
        so the view grows along one axis to match the output's aspect ratio.

    Examples
    --------
    >>> cam = Camera(center=(0.0, 2.0), size=(16.0, 9.0))
    >>> cam.extent((1280, 720))
    (8.0, 4.5)
    >>> cam.extent((720, 720))   # square output: the 16 m width stays visible
    (8.0, 8.0)
    """

    center: tuple[float, float] = (0.0, 0.0)
    size: tuple[float, float] = (16.0, 9.0)

    def __post_init__(self):
        c = tuple(float(v) for v in self.center)
        s = tuple(float(v) for v in self.size)
        if len(c) != 2 or not all(np.isfinite(c)):
            raise ValueError(f"camera center must be two finite numbers (metres), got {self.center!r}")
        if len(s) != 2 or not all(np.isfinite(s)) or min(s) <= 0:
            raise ValueError(f"camera size must be two positive numbers (metres), got {self.size!r}")
        object.__setattr__(self, "center", c)
        object.__setattr__(self, "size", s)

    def extent(self, viewport: tuple[int, int]) -> tuple[float, float]:
        """Half width and half height in metres actually visible in a ``viewport`` of pixels."""
        w, h = viewport
        aspect = w / h
        vw, vh = self.size
        if vw / vh < aspect:
            vw = vh * aspect
        else:
            vh = vw / aspect
        return (vw / 2.0, vh / 2.0)

    def metres_per_pixel(self, viewport: tuple[int, int]) -> float:
        """The picture's scale in a ``viewport`` of pixels: metres per pixel (pixels are square).

        Examples
        --------
        >>> Camera(center=(0.0, 2.0), size=(16.0, 9.0)).metres_per_pixel((1280, 720))
        0.0125
        """
        hx, _ = self.extent(viewport)
        return 2.0 * hx / viewport[0]

    def world_to_pixel(self, points: ArrayLike, viewport: tuple[int, int]) -> np.ndarray:
        """Map world points (..., 2) in metres to pixel coordinates (column, row), row 0 on top."""
        p = np.asarray(points, dtype=np.float64)
        hx, hy = self.extent(viewport)
        w, h = viewport
        col = (p[..., 0] - self.center[0] + hx) / (2 * hx) * w
        row = (self.center[1] + hy - p[..., 1]) / (2 * hy) * h
        return np.stack([col, row], axis=-1)

    def pixel_to_world(self, pixels: ArrayLike, viewport: tuple[int, int]) -> np.ndarray:
        """Inverse of :meth:`world_to_pixel` (a mouse position to metres)."""
        q = np.asarray(pixels, dtype=np.float64)
        hx, hy = self.extent(viewport)
        w, h = viewport
        x = q[..., 0] / w * (2 * hx) + self.center[0] - hx
        y = self.center[1] + hy - q[..., 1] / h * (2 * hy)
        return np.stack([x, y], axis=-1)


#: What a dimmed body's colour is multiplied by (a sleeping body in the viewer).
DIM = 0.6


def _as_rgba(color: str | Sequence[float]) -> tuple[float, float, float, float]:
    """A colour as RGBA floats: accepts '#rrggbb', '#rrggbbaa', or 3/4 numbers in [0, 1]."""
    if isinstance(color, str):
        s = color.lstrip("#")
        if len(s) not in (6, 8) or any(ch not in "0123456789abcdefABCDEF" for ch in s):
            raise ValueError(f"colour must be '#rrggbb' or '#rrggbbaa', got {color!r}")
        vals = [int(s[i : i + 2], 16) / 255.0 for i in range(0, len(s), 2)]
    else:
        vals = [float(v) for v in color]
    if len(vals) == 3:
        vals.append(1.0)
    if len(vals) != 4 or not all(0.0 <= v <= 1.0 for v in vals):
        raise ValueError(f"colour must be 3 or 4 numbers in [0, 1] or a hex string, got {color!r}")
    return tuple(vals)  # type: ignore[return-value]  # four values, checked above


_BACKGROUND_VS = """
#version 330
uniform vec3 u_top;
uniform vec3 u_bottom;
out vec3 v_color;
void main() {
    // one triangle that covers the screen, no vertex buffer needed; the gradient is
    // interpolated per vertex because per-pixel work is what costs on a software rasteriser
    vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);
    v_color = mix(u_bottom, u_top, p.y * 0.5 + 0.5);
    gl_Position = vec4(p, 0.0, 1.0);
}
"""

_BACKGROUND_FS = """
#version 330
in vec3 v_color;
out vec4 f_color;
void main() { f_color = vec4(v_color, 1.0); }
"""

_WORLD_VS = """
#version 330
uniform vec2 u_center;
uniform vec2 u_half;
in vec2 in_pos;
in vec2 in_uv;
out vec2 v_uv;
void main() {
    v_uv = in_uv;
    gl_Position = vec4((in_pos - u_center) / u_half, 0.0, 1.0);
}
"""

_BODY_FS = """
#version 330
uniform sampler2D u_tex;
uniform bool u_textured;
uniform vec4 u_color;
in vec2 v_uv;
out vec4 f_color;
void main() {
    vec4 c = u_textured ? texture(u_tex, v_uv) * u_color : u_color;
    if (c.a < 0.02) discard;
    f_color = c;
}
"""

_FLAT_FS = """
#version 330
uniform vec4 u_color;
in vec2 v_uv;
out vec4 f_color;
void main() { f_color = u_color; }
"""

_COLLIDER_VS = """
#version 330
uniform vec2 u_center;
uniform vec2 u_half;
uniform vec2 u_pixel;   // normalised device units per pixel: 2 / viewport
in vec2 in_pos;
in vec2 in_offset;      // pixels, along world axes: an outline's width does not follow the zoom
in vec4 in_color;
out vec4 v_color;
void main() {
    v_color = in_color;
    gl_Position = vec4((in_pos - u_center) / u_half + in_offset * u_pixel, 0.0, 1.0);
}
"""

_COLLIDER_FS = """
#version 330
in vec4 v_color;
out vec4 f_color;
void main() { f_color = v_color; }
"""


def _blend():
    import moderngl

    # colour: the usual "over"; alpha: keep the picture opaque where it was opaque
    return (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA, moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA)


_IMAGE_VS = """
#version 330
uniform vec4 u_rect;   // x0, y0, x1, y1 in normalised device coordinates
out vec2 v_uv;
void main() {
    vec2 t = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
    v_uv = vec2(t.x, 1.0 - t.y);
    gl_Position = vec4(mix(u_rect.xy, u_rect.zw, t), 0.0, 1.0);
}
"""

_IMAGE_FS = """
#version 330
uniform sampler2D u_tex;
in vec2 v_uv;
out vec4 f_color;
void main() { f_color = texture(u_tex, v_uv); }
"""


class MeshHandle:
    """GPU buffers of one body: constant triangles, UVs and texture, positions updated per frame.

    Made by :meth:`Renderer.add_mesh`; pass it to :meth:`Renderer.draw_mesh`.
    """

    def __init__(self, renderer: "Renderer", triangles: ArrayLike, uv: np.ndarray | Sequence[Sequence[float]] | None,
                 texture: ArrayLike | None, color: str | Sequence[float] | None, edges: ArrayLike | None) -> None:
        ctx = renderer.ctx
        tris = np.ascontiguousarray(triangles, dtype=np.int32)
        if tris.ndim != 2 or tris.shape[1] != 3 or len(tris) == 0:
            raise ValueError(f"triangles must be an (M, 3) integer array with M >= 1, got shape {tris.shape}")
        self.vertex_count = int(tris.max()) + 1 if uv is None else len(uv)
        if uv is None:
            uv = np.zeros((self.vertex_count, 2))
        uv = np.ascontiguousarray(uv, dtype=np.float32)
        if uv.ndim != 2 or uv.shape[1] != 2:
            raise ValueError(f"uv must be an (N, 2) array, got shape {uv.shape}")
        if tris.min() < 0 or tris.max() >= len(uv):
            raise ValueError(f"triangle indices must lie in [0, {len(uv) - 1}] (one uv per vertex)")
        self.triangle_count = len(tris)
        self.color = _as_rgba(color if color is not None else (1.0, 1.0, 1.0, 1.0) if texture is not None else DEFAULT_BODY_COLOR)
        self._pos = ctx.buffer(reserve=len(uv) * 8, dynamic=True)
        self._uv = ctx.buffer(uv.tobytes())
        self._ibo = ctx.buffer(tris.tobytes())
        self._scratch = np.empty((len(uv), 2), dtype=np.float32)
        self.body_vao = ctx.vertex_array(
            renderer._body_prog, [(self._pos, "2f", "in_pos"), (self._uv, "2f", "in_uv")], self._ibo
        )
        if edges is None:
            e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
            e.sort(axis=1)
            edges = np.unique(e, axis=0)
        edges = np.ascontiguousarray(edges, dtype=np.int32)
        self._edge_ibo = ctx.buffer(edges.tobytes())
        self.wire_vao = ctx.vertex_array(renderer._flat_prog, [(self._pos, "2f", "in_pos")], self._edge_ibo)
        # the outline (edges of exactly one triangle) gives a flat-coloured body a crisp border
        e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
        uniq, counts = np.unique(e, axis=0, return_counts=True)
        outline = np.ascontiguousarray(uniq[counts == 1], dtype=np.int32)
        self._outline_ibo = ctx.buffer(outline.tobytes()) if len(outline) else None
        self.outline_vao = None if self._outline_ibo is None else ctx.vertex_array(
            renderer._flat_prog, [(self._pos, "2f", "in_pos")], self._outline_ibo)
        self.texture: moderngl.Texture | None = None
        self.mipmapped: bool | None = None
        opaque_texture = True
        if texture is not None:
            self.texture = renderer._make_texture(texture)
            img = np.asarray(texture)
            opaque_texture = img.shape[2] == 3 or bool(img[..., 3].min() == 255)
            # texels the mesh spans, to tell at draw time whether the picture is shrunk
            span = uv.max(axis=0) - uv.min(axis=0)
            self._texels = (float(span[0]) * img.shape[1], float(span[1]) * img.shape[0])
        # opaque bodies skip blending: a measurable share of the frame on a software rasteriser
        self.opaque = opaque_texture and self.color[3] >= 1.0

    def upload(self, positions: ArrayLike) -> None:
        p = np.asarray(positions)
        if p.shape != self._scratch.shape:
            raise ValueError(f"positions must have shape {self._scratch.shape} (one per vertex), got {p.shape}")
        # float64 state to float32 vertices without allocating a new array each frame
        np.copyto(self._scratch, p, casting="same_kind")
        self._pos.write(self._scratch)

    def release(self) -> None:
        for obj in (self.body_vao, self.wire_vao, self.outline_vao, self._pos, self._uv, self._ibo,
                    self._edge_ibo, self._outline_ibo, self.texture):
            if obj is not None:
                obj.release()


class Renderer:
    """Draws bodies, colliders and a background into a framebuffer.

    Parameters
    ----------
    ctx : moderngl.Context
        An OpenGL 3.3 context: a window's (``moderngl.create_context()`` after opening a
        pygame-ce OpenGL window) or a standalone one (see :meth:`headless`).
    size : (int, int), optional
        Picture width and height in pixels.
    samples : int, optional
        Multisampling for smooth edges (0 or 1 turns it off). Only used off-screen; capped
        at what the driver allows.
    target : moderngl.Framebuffer, optional
        Where to draw, e.g. ``ctx.screen`` for a window. By default the renderer owns an
        off-screen framebuffer and :meth:`read` returns its pixels.
    camera : Camera, optional
        The view; change it any time through the ``camera`` attribute.

    Examples
    --------
    >>> import numpy as np
    >>> from deforma.render import Renderer, Camera
    >>> r = Renderer.headless((64, 48), camera=Camera((0, 0), (4, 3)))
    >>> h = r.add_mesh([[0, 1, 2]], uv=[[0, 0], [1, 0], [0, 1]], color="#ff0000")
    >>> r.clear(); r.draw_background(); r.draw_mesh(h, [[-1, -1], [1, -1], [-1, 1]])
    >>> img = r.read()
    >>> img.shape, img[30, 25].tolist()        # a pixel inside the red triangle
    ((48, 64, 3), [255, 0, 0])
    >>> r.release()
    """

    _img_tex_key: tuple[int, int, int]  # set with _img_tex (draw_image)

    # ctx is a moderngl.Context, typed Any: moderngl's stubs type a program's members as a union
    # (uniform, attribute, ...) that every ``prog[name].value = ...`` would have to narrow
    def __init__(self, ctx: Any, size: tuple[int, int] = (1280, 720), *, samples: int = 4,
                 target: moderngl.Framebuffer | None = None, camera: Camera | None = None) -> None:
        self.ctx = ctx
        self.camera = camera if camera is not None else Camera()
        self.background_top = BACKGROUND_TOP
        self.background_bottom = BACKGROUND_BOTTOM
        self.grid_color = GRID_COLOR
        self._bg_prog = ctx.program(vertex_shader=_BACKGROUND_VS, fragment_shader=_BACKGROUND_FS)
        self._bg_vao = ctx.vertex_array(self._bg_prog, [])
        self._body_prog = ctx.program(vertex_shader=_WORLD_VS, fragment_shader=_BODY_FS)
        self._flat_prog = ctx.program(vertex_shader=_WORLD_VS, fragment_shader=_FLAT_FS)
        self._coll_prog = ctx.program(vertex_shader=_COLLIDER_VS, fragment_shader=_COLLIDER_FS)
        self._grid_vbo = ctx.buffer(reserve=4096, dynamic=True)
        self._grid_vao = ctx.vertex_array(self._flat_prog, [(self._grid_vbo, "2f", "in_pos")])
        self._img_prog = ctx.program(vertex_shader=_IMAGE_VS, fragment_shader=_IMAGE_FS)
        self._img_vao = ctx.vertex_array(self._img_prog, [])
        self._img_tex: moderngl.Texture | None = None
        self._coll_vbo: moderngl.Buffer | None = None
        self._coll_vao: moderngl.VertexArray | None = None
        self._coll_capacity = 0
        self._coll_count = 0
        self._coll_key: tuple | None = None     # what the collider buffer holds (see draw_colliders)
        # id(collider) -> (collider, _version, ColliderGeometry)
        self._coll_cache: dict[int, tuple[Any, Any, ColliderGeometry]] = {}
        self._white: moderngl.Texture | None = None
        self._meshes: list[MeshHandle] = []
        self._owns_ctx = False
        self._target = target
        self._owns_fbo = target is None
        self._msaa: moderngl.Framebuffer | None = None
        self._resolve: moderngl.Framebuffer | None = None
        # off-screen (msaa or None, resolve) pairs; the current is _msaa/_resolve
        self._buffers: list[tuple[moderngl.Framebuffer | None, moderngl.Framebuffer]] = []
        self._buffer = 0
        self.size = (0, 0)
        self._samples = 0
        if self._owns_fbo:
            max_samples = int(ctx.info.get("GL_MAX_SAMPLES", 0) or 0)
            self._samples = min(int(samples), max_samples) if samples and samples > 1 else 0
        self.resize(size)

    @classmethod
    def headless(cls, size: tuple[int, int] = (1280, 720), *, samples: int = 4,
                 camera: Camera | None = None) -> "Renderer":
        """A renderer on its own standalone OpenGL context, no window or display needed.

        Uses EGL (Mesa's llvmpipe software rasteriser when there is no GPU). On Debian the
        packages ``libegl1 libegl-mesa0 libgl1 libgl1-mesa-dri`` provide it.

        Raises
        ------
        RuntimeError
            If no OpenGL 3.3 context can be created, naming the packages to install.
        """
        ctx = create_headless_context()
        r = cls(ctx, size, samples=samples, camera=camera)
        r._owns_ctx = True
        return r

    # -- framebuffer ---------------------------------------------------------------------
    def resize(self, size: tuple[int, int]) -> None:
        """Change the picture size in pixels (re-creates the off-screen framebuffer)."""
        w, h = (int(v) for v in size)
        if w < 1 or h < 1 or w > 16384 or h > 16384:
            raise ValueError(f"size must be two integers in [1, 16384] pixels, got {size!r}")
        if (w, h) == self.size:
            return
        self.size = (w, h)
        if not self._owns_fbo:
            return
        self._release_buffers()
        self._buffers = [self._make_buffer()]
        self._buffer = 0
        self._msaa, self._resolve = self._buffers[0]
        self._readbuf = bytearray(w * h * 3)

    def _make_buffer(self):
        ctx, (w, h) = self.ctx, self.size
        resolve = ctx.framebuffer(color_attachments=[ctx.renderbuffer((w, h), 4)])
        msaa = None
        if self._samples:
            msaa = ctx.framebuffer(color_attachments=[ctx.renderbuffer((w, h), 4, samples=self._samples)])
        return msaa, resolve

    def _release_buffers(self):
        for pair in self._buffers:
            for fb in pair:
                if fb is not None:
                    for a in fb.color_attachments:
                        a.release()
                    fb.release()
        self._buffers = []
        self._msaa = self._resolve = None

    @property
    def framebuffer(self) -> moderngl.Framebuffer:
        """The framebuffer drawn into."""
        if self._target is not None:
            return self._target
        return self._msaa if self._msaa is not None else self._resolve  # type: ignore[return-value]  # until release()

    # -- resources -----------------------------------------------------------------------
    def _make_texture(self, image):
        img = np.asarray(image)
        if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] not in (3, 4):
            raise ValueError(f"texture must be an (H, W, 3 or 4) uint8 array, got {img.dtype} {img.shape}")
        # row 0 of an image is its top; OpenGL's t = 0 is the bottom, which matches uv with y up
        data = np.ascontiguousarray(img[::-1])
        tex = self.ctx.texture((img.shape[1], img.shape[0]), img.shape[2], data.tobytes())
        tex.build_mipmaps()
        import moderngl

        # nearest mip level, bilinear within it: no shimmer when shrunk, and cheaper than
        # trilinear on a software rasteriser
        tex.filter = (moderngl.LINEAR_MIPMAP_NEAREST, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        return tex

    def add_mesh(self, triangles: ArrayLike, uv: np.ndarray | Sequence[Sequence[float]] | None = None, *,
                 texture: ArrayLike | None = None, color: str | Sequence[float] | None = None,
                 edges: ArrayLike | None = None) -> MeshHandle:
        """Upload a body's constant data once; draw it each frame with :meth:`draw_mesh`.

        Parameters
        ----------
        triangles : (M, 3) array_like of int
            Vertex indices per triangle.
        uv : (N, 2) array_like of float, optional
            Texture coordinates in [0, 1]; (0, 0) is the image's bottom-left corner.
            Needed with ``texture``.
        texture : (H, W, 3 or 4) uint8 array, optional
            The picture, row 0 on top. Transparent texels (alpha near 0) are not drawn.
        color : str or sequence of float, optional
            Flat colour ('#rrggbb' or RGB(A) in [0, 1]); with a texture it tints it.
        edges : (E, 2) array_like of int, optional
            The springs to draw as wireframe; by default the triangles' edges.

        Returns
        -------
        MeshHandle
        """
        if texture is not None and uv is None:
            raise ValueError("a textured mesh needs uv coordinates (one (u, v) per vertex)")
        h = MeshHandle(self, triangles, uv, texture, color, edges)
        self._meshes.append(h)
        return h

    def remove_mesh(self, handle: MeshHandle) -> None:
        """Free a mesh's GPU buffers."""
        self._meshes.remove(handle)
        handle.release()

    # -- drawing -------------------------------------------------------------------------
    def _set_camera(self, prog):
        hx, hy = self.camera.extent(self.size)
        prog["u_center"].value = self.camera.center
        prog["u_half"].value = (hx, hy)

    def clear(self) -> None:
        """Bind the target framebuffer and clear it to the background's bottom colour."""
        fb = self.framebuffer
        fb.use()
        self.ctx.viewport = (0, 0, *self.size)
        fb.clear(*self.background_bottom, 1.0)

    def draw_background(self) -> None:
        """A vertical gradient with a faint one-metre grid (scale, and motion you can read)."""
        import moderngl

        ctx = self.ctx
        ctx.disable(moderngl.BLEND | moderngl.DEPTH_TEST | moderngl.CULL_FACE)
        p = self._bg_prog
        p["u_top"].value = self.background_top
        p["u_bottom"].value = self.background_bottom
        self._bg_vao.render(moderngl.TRIANGLES, vertices=3)
        if self.grid_color[3] <= 0:
            return
        # grid lines as geometry: a handful of lines instead of per-pixel work
        hx, hy = self.camera.extent(self.size)
        cx, cy = self.camera.center
        if max(hx, hy) > 200:  # too dense to help; skip rather than draw thousands of lines
            return
        xs = np.arange(np.ceil(cx - hx), np.floor(cx + hx) + 1)
        ys = np.arange(np.ceil(cy - hy), np.floor(cy + hy) + 1)
        seg = np.empty((2 * (len(xs) + len(ys)), 2), dtype=np.float32)
        seg[0 : 2 * len(xs) : 2] = np.c_[xs, np.full_like(xs, cy - hy)]
        seg[1 : 2 * len(xs) : 2] = np.c_[xs, np.full_like(xs, cy + hy)]
        k = 2 * len(xs)
        seg[k::2] = np.c_[np.full_like(ys, cx - hx), ys]
        seg[k + 1 :: 2] = np.c_[np.full_like(ys, cx + hx), ys]
        if seg.nbytes > self._grid_vbo.size:
            self._grid_vao.release()
            self._grid_vbo.release()
            self._grid_vbo = ctx.buffer(reserve=2 * seg.nbytes, dynamic=True)
            self._grid_vao = ctx.vertex_array(self._flat_prog, [(self._grid_vbo, "2f", "in_pos")])
        self._grid_vbo.write(seg.tobytes())
        f = self._flat_prog
        self._set_camera(f)
        f["u_color"].value = self.grid_color
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = _blend()
        self._grid_vao.render(moderngl.LINES, vertices=len(seg))

    def draw_colliders(self, colliders: Iterable, *, colors: Sequence | None = None) -> None:
        """Every collider filled and bordered, in its pose now.

        ``colliders`` holds ``deforma`` colliders (Rect, Circle, Polygon with holes, Segment:
        a capsule, or a wire drawn a few pixels wide), objects with ``.center .size .angle``,
        or ``(center, size, angle_degrees)`` tuples of rectangles; ``colors`` optionally one
        fill colour each (None: the default slate).

        A collider's triangles and border are rebuilt only when it changed (its ``_version``
        counter, which moving it also raises) and the buffer is written only when one did or
        a colour changed: a still scene costs one draw call.
        """
        import moderngl

        items = list(colliders)
        if colors is not None and len(colors) != len(items):
            raise ValueError(f"colors must give one colour per collider ({len(items)}), got {len(colors)}")
        if not items:
            return
        fills = [COLLIDER_FILL if colors is None or colors[i] is None else _as_rgba(colors[i])
                 for i in range(len(items))]
        key = (tuple(self._collider_key(c) for c in items), tuple(fills))
        if key != self._coll_key:
            self._upload_colliders(items, fills)
            self._coll_key = key
        if not self._coll_count:
            return
        p = self._coll_prog
        self._set_camera(p)
        p["u_pixel"].value = (2.0 / self.size[0], 2.0 / self.size[1])
        self.ctx.enable(moderngl.BLEND)
        self.ctx.blend_func = _blend()
        # _coll_vao is made with the first colliders (_coll_count > 0)
        self._coll_vao.render(moderngl.TRIANGLES, vertices=self._coll_count)  # type: ignore[union-attr]

    @staticmethod
    def _collider_key(c):
        """What identifies a collider's look now: its identity and change counter, or its values."""
        version = getattr(c, "_version", None)
        if version is not None:
            return (id(c), version)
        if isinstance(c, (tuple, list)):
            center, size, angle = c
            return (tuple(map(float, center)), tuple(map(float, size)), float(angle))
        return (id(c), tuple(map(float, c.center)), tuple(map(float, c.size)), float(c.angle))

    def _upload_colliders(self, items, fills) -> None:
        cache: dict[int, tuple[Any, Any, ColliderGeometry]] = {}
        rows: list[np.ndarray] = []
        for c, fill in zip(items, fills):
            version = getattr(c, "_version", None)
            old = self._coll_cache.get(id(c))
            if version is not None and old is not None and old[0] is c and old[1] == version:
                geometry = old[2]
            else:
                # the triangles of the collider's last pose usually still fit (it only moved)
                previous = old[2].triangles if old is not None and old[0] is c else None
                geometry = ColliderGeometry(collider_shape(c), previous)
            if version is not None:
                cache[id(c)] = (c, version, geometry)   # holding c keeps its id from being reused
            geometry.vertices(fill, COLLIDER_EDGE, rows)
        self._coll_cache = cache
        data = np.ascontiguousarray(np.concatenate(rows) if rows else np.zeros((0, FLOATS_PER_VERTEX)),
                                    dtype=np.float32)
        self._coll_count = len(data)
        if data.nbytes > self._coll_capacity:
            if self._coll_vao is not None:
                self._coll_vao.release()
                self._coll_vbo.release()  # type: ignore[union-attr]  # made with _coll_vao
            self._coll_capacity = max(data.nbytes, 2 * self._coll_capacity)
            self._coll_vbo = self.ctx.buffer(reserve=self._coll_capacity, dynamic=True)
            self._coll_vao = self.ctx.vertex_array(
                self._coll_prog, [(self._coll_vbo, "2f 2f 4f", "in_pos", "in_offset", "in_color")])
        if len(data):
            self._coll_vbo.write(data.tobytes())  # type: ignore[union-attr]  # made above

    def _choose_filter(self, handle: MeshHandle) -> None:
        """Mipmaps only when the picture is drawn smaller than it is (they cost ~10% of a frame)."""
        import moderngl

        p = handle._scratch
        hx, hy = self.camera.extent(self.size)
        w_px = float(p[:, 0].max() - p[:, 0].min()) * self.size[0] / (2 * hx)
        h_px = float(p[:, 1].max() - p[:, 1].min()) * self.size[1] / (2 * hy)
        shrink = max(handle._texels[0] / max(w_px, 1.0), handle._texels[1] / max(h_px, 1.0))
        # a little shrinking is fine with bilinear filtering; beyond it texels would shimmer
        mip = shrink > 1.25
        if mip != handle.mipmapped:
            # only a textured handle comes here (draw_mesh)
            handle.texture.filter = ((moderngl.LINEAR_MIPMAP_NEAREST if mip else moderngl.LINEAR),  # type: ignore[union-attr]
                                     moderngl.LINEAR)
            handle.mipmapped = mip

    def draw_mesh(self, handle: MeshHandle, positions: ArrayLike, *, wireframe: bool = False,
                  wire_color: str | Sequence[float] | None = None,
                  dim: bool = False) -> None:
        """Draw one body at ``positions`` (N, 2) metres: textured or flat, optionally its springs;
        ``dim`` darkens it (the viewer's sleeping bodies)."""
        import moderngl

        handle.upload(positions)
        ctx = self.ctx
        if handle.opaque:
            ctx.disable(moderngl.BLEND)
        else:
            ctx.enable(moderngl.BLEND)
            ctx.blend_func = _blend()
        p = self._body_prog
        self._set_camera(p)
        r, g, b, a = handle.color
        shade = DIM if dim else 1.0
        p["u_color"].value = (shade * r, shade * g, shade * b, a)
        p["u_textured"].value = handle.texture is not None
        if handle.texture is not None:
            self._choose_filter(handle)
            handle.texture.use(0)
            p["u_tex"].value = 0
        handle.body_vao.render(moderngl.TRIANGLES)
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = _blend()
        f = self._flat_prog
        if wireframe:
            self._set_camera(f)
            f["u_color"].value = _as_rgba(wire_color) if wire_color is not None else WIREFRAME_COLOR
            handle.wire_vao.render(moderngl.LINES)
        elif handle.texture is None and handle.outline_vao is not None:
            self._set_camera(f)
            f["u_color"].value = (0.6 * shade * r, 0.6 * shade * g, 0.6 * shade * b, a)
            handle.outline_vao.render(moderngl.LINES)

    def draw_image(self, image: ArrayLike, position: tuple[int, int] = (0, 0)) -> None:
        """Draw a picture in pixel coordinates over what is drawn, e.g. an inspector panel.

        Parameters
        ----------
        image : (H, W, 4) or (H, W, 3) uint8 array
            Row 0 on top; alpha blends it over the scene (straight, not premultiplied).
        position : (int, int)
            Column and row of its top-left corner in the picture, pixels.
        """
        import moderngl

        img = np.asarray(image)
        if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] not in (3, 4):
            raise ValueError(f"image must be an (H, W, 3 or 4) uint8 array, got {img.dtype} {img.shape}")
        h, w = img.shape[:2]
        key = (w, h, img.shape[2])
        if self._img_tex is None or self._img_tex_key != key:
            if self._img_tex is not None:
                self._img_tex.release()
            self._img_tex = self.ctx.texture((w, h), img.shape[2])
            self._img_tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self._img_tex_key = key
        # uploaded as is (row 0 first), so t = 0 is the image's top row; the shader flips v
        self._img_tex.write(np.ascontiguousarray(img).tobytes())
        W, H = self.size
        x, y = position
        rect = (2 * x / W - 1, 1 - 2 * (y + h) / H, 2 * (x + w) / W - 1, 1 - 2 * y / H)
        self._img_prog["u_rect"].value = rect
        self._img_tex.use(0)
        self._img_prog["u_tex"].value = 0
        self.ctx.enable(moderngl.BLEND)
        self.ctx.blend_func = _blend()
        self._img_vao.render(moderngl.TRIANGLE_STRIP, vertices=4)

    def finish(self) -> None:
        """Resolve multisampling into the readable framebuffer (called by :meth:`read`)."""
        if self._owns_fbo and self._msaa is not None:
            self.ctx.copy_framebuffer(self._resolve, self._msaa)

    def read(self, *, components: int = 3) -> np.ndarray:
        """The picture as an (H, W, 3) or (H, W, 4) uint8 array, row 0 on top."""
        if components not in (3, 4):
            raise ValueError(f"components must be 3 (RGB) or 4 (RGBA), got {components!r}")
        if not self._owns_fbo:
            fb = self._target
        else:
            self.finish()
            fb = self._resolve
        return self._read_framebuffer(fb, components)

    def _read_framebuffer(self, fb, components: int = 3) -> np.ndarray:
        w, h = self.size
        if components == 3 and self._owns_fbo:
            fb.read_into(self._readbuf, components=3)
            raw = self._readbuf
        else:
            raw = fb.read(components=components, viewport=(0, 0, w, h))
        img = np.frombuffer(raw, dtype=np.uint8).reshape(h, w, components)
        # OpenGL rows run bottom-up; copy so the caller owns the array (the buffer is reused)
        return img[::-1].copy()

    # -- frames in flight (headless: see render/recorder.py) -------------------------------
    # The software rasteriser (Mesa's llvmpipe) draws in threads of its own once work is
    # flushed, and waits only where the pixels are needed: drawing frame k into one buffer
    # while frame k - 1 is still being drawn into another lets the simulation of the next
    # frame run meanwhile (render/recorder.py).
    @property
    def buffer(self) -> int:
        """The off-screen buffer drawn into and read by :meth:`read` (0 unless :meth:`use_buffer` chose another)."""
        return self._buffer

    def use_buffer(self, index: int) -> None:
        """Draw into off-screen buffer ``index`` from now on; buffers beyond 0 are made, with
        the same size and multisampling, on first use (each costs the memory of buffer 0).
        :meth:`read` and :meth:`finish` work on this buffer.

        Raises
        ------
        ValueError
            If the renderer draws into a given ``target`` (a window) or ``index`` is not 0 to 7.
        """
        if not self._owns_fbo:
            raise ValueError("a renderer drawing into a given target has no off-screen buffers")
        if not (isinstance(index, int) and 0 <= index < 8):
            raise ValueError(f"buffer index must be an integer in [0, 8), got {index!r}")
        while len(self._buffers) <= index:
            self._buffers.append(self._make_buffer())
        self._buffer = index
        self._msaa, self._resolve = self._buffers[index]

    def resolve_buffer(self, index: int) -> None:
        """Queue the multisampling resolve of buffer ``index`` (nothing without multisampling).

        It waits for the buffer's drawing to be done, but not for the resolve itself: call
        :meth:`flush` to start it, and :meth:`read_buffer` reads the result."""
        msaa, resolve = self._buffers[index]
        if msaa is not None:
            self.ctx.copy_framebuffer(resolve, msaa)

    def read_buffer(self, index: int) -> np.ndarray:
        """The picture of buffer ``index`` after :meth:`resolve_buffer`: (H, W, 3) uint8, row 0 on top.

        Read a buffer before queueing more work for the rasteriser where you can: a read waits
        for all the work queued before it."""
        return self._read_framebuffer(self._buffers[index][1])

    def flush(self) -> None:
        """Start the work queued so far (``glFlush``) without waiting for it.

        Drivers that draw in threads of their own (llvmpipe) begin drawing only when work is
        flushed or waited for; where ``glFlush`` cannot be found this does nothing (the work
        then starts at the next wait, which is correct, only later)."""
        fn = _gl_flush()
        if fn is not None:
            fn()

    def render(self, bodies: Iterable = (), colliders: Iterable = (), *, wireframe: bool = False,
               collider_colors: Sequence | None = None) -> None:
        """One whole frame: background, colliders, then each ``(handle, positions)`` or ``(handle,
        positions, dim)`` body (:meth:`draw_mesh`)."""
        # the background covers every pixel, so binding is enough: a clear would be a wasted pass
        self.framebuffer.use()
        self.ctx.viewport = (0, 0, *self.size)
        self.draw_background()
        self.draw_colliders(colliders, colors=collider_colors)
        for handle, positions, *dim in bodies:
            self.draw_mesh(handle, positions, wireframe=wireframe, dim=bool(dim and dim[0]))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()
        return False

    def release(self) -> None:
        """Free every GPU resource this renderer made, and the context if :meth:`headless` made it.

        Release a headless renderer when done: a standalone EGL context left current in the
        process keeps a window opened later (pygame-ce) from finding its own OpenGL context.
        """
        for h in list(self._meshes):
            self.remove_mesh(h)
        self._coll_cache = {}   # it holds the colliders last drawn
        self._coll_key = None
        for obj in (self._img_tex, self._img_vao, self._img_prog, self._coll_vao, self._coll_vbo,
                    self._grid_vao, self._grid_vbo, self._bg_vao, self._bg_prog, self._body_prog,
                    self._flat_prog, self._coll_prog):
            if obj is not None:
                obj.release()
        if self._owns_fbo:
            self._release_buffers()
        if self._owns_ctx:
            self.ctx.release()
            self._owns_ctx = False


_GL_FLUSH: list = []  # [glFlush or None], looked up once


def _gl_flush():
    """``glFlush`` of the process's OpenGL library (the one moderngl's context loads), or None.

    moderngl has no flush of its own; the library's entry point goes to the context current in
    this thread, as moderngl's own calls do."""
    if not _GL_FLUSH:
        fn = None
        try:
            import ctypes
            import ctypes.util

            name = ctypes.util.find_library("GL")
            if name:
                fn = ctypes.CDLL(name).glFlush
                fn.restype, fn.argtypes = None, []
        except (OSError, AttributeError):  # no such library or symbol: flushing is an optimisation
            fn = None
        _GL_FLUSH.append(fn)
    return _GL_FLUSH[0]


_HEADLESS_HELP = (
    "cannot open a headless OpenGL 3.3 context ({err}); install moderngl (pip install 'deforma[render]') "
    "and Mesa's EGL (Debian/Ubuntu: apt-get install libegl1 libegl-mesa0 libgl1 libgl1-mesa-dri)"
)


def create_headless_context() -> moderngl.Context:
    """A standalone OpenGL 3.3 context: EGL first (no display), then the platform default."""
    try:
        import moderngl
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise RuntimeError(_HEADLESS_HELP.format(err=e)) from None
    errors: list[str] = []
    for kwargs in ({"backend": "egl"}, {}):
        try:
            return moderngl.create_standalone_context(require=330, **kwargs)  # type: ignore[arg-type]  # backend=
        except Exception as e:  # noqa: BLE001 - glcontext raises plain Exceptions
            errors.append(f"{kwargs.get('backend', 'default')}: {e}")
    raise RuntimeError(_HEADLESS_HELP.format(err="; ".join(errors)))

"""Meshes out of deforma and back: Wavefront OBJ, JSON and SVG.

A deformed body is a :class:`~deforma.mesh.Mesh` of its current shape
(:meth:`deforma.physics.body.Body.to_mesh`); ``deforma run SCENE --export DIR --format
obj|json|svg`` writes one file per frame holding every body. The files are made for other
tools: OBJ for game engines and 3D packages (``z = 0``, texture coordinates, one object per
body, and a material library naming each body's texture picture), JSON for scripts and
plotting, SVG for pictures in papers. OBJ and JSON keep every coordinate exactly (shortest
round-trip decimals), so :func:`read_meshes` gives back what was written.

Examples
--------
>>> import tempfile
>>> from pathlib import Path
>>> from deforma.mesh import Mesh
>>> m = Mesh([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]])
>>> folder = Path(tempfile.mkdtemp())
>>> write_meshes([m, m], folder / "two.obj")
>>> [len(x.vertices) for x in read_meshes(folder / "two.obj")]
[3, 3]
>>> read_meshes(folder / "two.obj")[1].vertices.tolist() == m.vertices.tolist()
True
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from .mesh import Mesh

__all__ = ["FORMATS", "read_meshes", "write_materials", "write_meshes"]

#: The formats :func:`write_meshes` writes (its file name's suffix, without the dot).
FORMATS = ("obj", "json", "svg")


#: What an object's name may hold: it becomes an OBJ object's name (no spaces or line
#: breaks), an SVG element's id (no quotes) and a picture's file name (no folders).
NAME = re.compile(r"[A-Za-z0-9_-][A-Za-z0-9_.-]*")


def _meshes_and_names(meshes, names, where) -> tuple[list, list[str]]:
    """``meshes`` as a list (one Mesh alone is a list of one) and their names, checked: one
    per mesh, each matching :data:`NAME` (else ``ValueError`` in one line, nothing written)."""
    meshes = [meshes] if isinstance(meshes, Mesh) else list(meshes)
    # a list once: a generator would be used up by the count
    names = list(names) if names is not None else [f"body{k}" for k in range(len(meshes))]
    if len(names) != len(meshes):
        # zip() would drop the meshes past the last name without a word
        raise ValueError(f"{where}: names has {len(names)} entries for {len(meshes)} meshes; give one name "
                         f"per mesh, or none (body0, body1, ...)")
    for k, n in enumerate(names):
        if not isinstance(n, str) or not NAME.fullmatch(n):
            raise ValueError(f"{where}: names[{k}] = {n!r}: a name is letters, digits, '_', '-' and '.' (not "
                             f"first), as it names an OBJ object, an SVG id and a picture file")
    return meshes, names


def _num(x: float) -> str:
    return repr(float(x))  # the shortest decimal that reads back to the same float


def obj_text(meshes: Sequence[Mesh], names: Sequence[str], materials: str | None = None,
             textured: Sequence[bool] = ()) -> str:
    """Wavefront OBJ of ``meshes`` (one ``o`` object each, named by ``names``); with
    ``materials`` (an ``.mtl`` file name), each textured mesh uses the material of its name."""
    out = ["# deforma: one object per body, z = 0"]
    if materials:
        out.append(f"mtllib {materials}")
    base = 1
    for k, (m, name) in enumerate(zip(meshes, names)):
        out.append(f"o {name}")
        out.extend(f"v {_num(x)} {_num(y)} 0" for x, y in m.vertices)
        out.extend(f"vt {_num(u)} {_num(v)}" for u, v in m.uv)
        if materials and k < len(textured) and textured[k]:
            out.append(f"usemtl {name}")
        t = m.triangles + base
        out.extend(f"f {a}/{a} {b}/{b} {c}/{c}" for a, b, c in t)
        base += len(m.vertices)
    return "\n".join(out) + "\n"


def json_data(meshes: Sequence[Mesh], names: Sequence[str], **extra: Any) -> dict:
    """A JSON-ready dict: ``extra`` (frame, time, ...) and ``bodies``, each with ``name``,
    ``vertices`` (m), ``triangles`` (vertex indices, counter-clockwise) and ``uv``."""
    return {**extra, "bodies": [{"name": name, "vertices": m.vertices.tolist(), "triangles": m.triangles.tolist(),
                                 "uv": m.uv.tolist()} for m, name in zip(meshes, names)]}


def svg_text(meshes: Sequence[Mesh], names: Sequence[str], colors: Sequence[str] = (), *,
             width: int = 800) -> str:
    """SVG of ``meshes`` filled with ``colors`` (CSS colours; grey by default), every triangle
    outlined thinly, y up as in the world; ``width`` pixels wide, the height following (no
    meshes: an empty square picture)."""
    if len(meshes) == 0:
        # nothing to frame (a scene of colliders only): an empty picture, as OBJ and JSON write
        # no objects; the bounds below would be NumPy's "need at least one array" instead
        return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{width}" '
                f'viewBox="0 0 {width} {width}">\n</svg>\n')
    pts = np.concatenate([m.vertices for m in meshes])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = np.maximum(hi - lo, 1e-9)
    pad = 0.02 * float(span.max())
    lo, span = lo - pad, span + 2 * pad
    scale = width / float(span[0])
    height = max(1, round(float(span[1]) * scale))
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}">']
    for k, (m, name) in enumerate(zip(meshes, names)):
        xy = np.c_[(m.vertices[:, 0] - lo[0]) * scale, (lo[1] + span[1] - m.vertices[:, 1]) * scale]
        path = " ".join("M{:.2f} {:.2f}L{:.2f} {:.2f}L{:.2f} {:.2f}Z".format(*xy[t].ravel()) for t in m.triangles)
        fill = colors[k] if k < len(colors) and colors[k] else "#9aa5b1"
        out.append(f'<path id="{name}" d="{path}" fill="{fill}" stroke="#20242c" stroke-width="0.3" '
                   f'stroke-linejoin="round"/>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


def write_meshes(meshes: Sequence[Mesh], path: str | Path, *, names: Sequence[str] | None = None,
                 colors: Sequence[str] = (), materials: str | None = None, **extra: Any) -> None:
    """Write ``meshes`` to ``path`` in the format its suffix names (``.obj``, ``.json``, ``.svg``).

    Parameters
    ----------
    meshes : sequence of Mesh, or one Mesh
        Written in order, one object each (none: a file without objects, an empty picture).
    path : str or Path
        The file; its folder must exist.
    names : sequence of str, optional
        Object names (default ``body0``, ``body1``, ...): letters, digits, ``_``, ``-`` and
        ``.`` (not first).
    colors : sequence of str, optional
        SVG fill colours, one per mesh.
    materials : str, optional
        OBJ: the ``.mtl`` file (:func:`write_materials`) whose material of each textured
        mesh's name it uses.
    **extra
        JSON: more top-level fields (``frame``, ``time``).

    Raises
    ------
    ValueError
        A suffix other than those of :data:`FORMATS`, or ``names`` not one per mesh or not
        names (:data:`NAME`; nothing is written).
    """
    path = Path(path)
    fmt = path.suffix[1:].lower()
    meshes, names = _meshes_and_names(meshes, names, path)
    if fmt == "obj":
        text = obj_text(meshes, names, materials, [m.texture is not None for m in meshes])
    elif fmt == "json":
        text = json.dumps(json_data(meshes, names, **extra))
    elif fmt == "svg":
        text = svg_text(meshes, names, colors)
    else:
        raise ValueError(f"{path}: meshes are written as {', '.join('.' + f for f in FORMATS)}; got {path.suffix!r}")
    path.write_text(text)


def write_materials(meshes: Sequence[Mesh], folder: str | Path, *, names: Sequence[str] | None = None,
                    name: str = "materials.mtl") -> str | None:
    """Write each textured mesh's picture as ``NAME.png`` into ``folder`` and a material
    library ``name`` naming them (OBJ's ``map_Kd``); returns ``name``, or ``None`` (nothing
    written) when no mesh has a texture. ``names`` as :func:`write_meshes` takes them (a
    name with a folder in it would write outside ``folder``: refused)."""
    from PIL import Image

    folder = Path(folder)
    meshes, names = _meshes_and_names(meshes, names, folder)
    lines = []
    for m, n in zip(meshes, names):
        if m.texture is not None:
            # uv has v up, a picture's rows run down: the picture is stored as it looks
            Image.fromarray(m.texture, "RGBA").save(folder / f"{n}.png")
            lines += [f"newmtl {n}", "Kd 1 1 1", f"map_Kd {n}.png", ""]
    if not lines:
        return None
    (folder / name).write_text("\n".join(lines))
    return name


def read_meshes(path: str | Path) -> list[Mesh]:
    """The meshes of an OBJ or JSON file written by :func:`write_meshes` (or ``deforma run
    --export``), one per object, in order, exactly as written (a deformed shape's turned-over
    triangles stay as they are; no texture picture).

    Raises
    ------
    ValueError
        A file that is not such an OBJ or JSON, in one line naming it.
    """
    path = Path(path)
    fmt = path.suffix[1:].lower()
    try:
        if fmt == "json":
            data = json.loads(path.read_text())
            return [_as_written(b["vertices"], b["triangles"], b["uv"]) for b in data["bodies"]]
        if fmt == "obj":
            return _read_obj(path.read_text())
    except (KeyError, TypeError, IndexError, ValueError, UnicodeDecodeError, RecursionError) as e:
        # RecursionError: JSON nested deeper than Python's parser goes is no mesh file either
        raise ValueError(f"{path}: not a mesh file deforma wrote ({type(e).__name__}: {e})") from None
    raise ValueError(f"{path}: meshes are read from .obj or .json; got {path.suffix!r}")


def _as_written(vertices, triangles, uv) -> Mesh:
    """A mesh exactly as a file holds it: a deformed body's shape may have triangles turned
    over or squashed flat, which :class:`Mesh` would re-order or refuse, so only the shapes,
    the indices and finiteness are checked."""
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    if v.ndim != 2 or v.shape[1] != 2 or not np.isfinite(v).all():
        raise TypeError(f"vertices must be finite (N, 2), got shape {v.shape}")
    if t.ndim != 2 or t.shape[1] != 3 or len(t) == 0 or t.min() < 0 or t.max() >= len(v):
        raise IndexError(f"triangles must be (M, 3) indices into {len(v)} vertices")
    if uv is None:
        lo, hi = v.min(axis=0), v.max(axis=0)
        uv = (v - lo) / np.where(hi > lo, hi - lo, 1.0)
    uv = np.asarray(uv, dtype=np.float64)
    if uv.shape != v.shape:
        raise TypeError(f"uv must have the vertices' shape {v.shape}, got {uv.shape}")
    return Mesh._trusted(v, t.astype(np.int32), uv, None)


def _read_obj(text: str) -> list[Mesh]:
    meshes: list[Mesh] = []
    v: list[Any] = []
    vt: list[Any] = []
    f: list[Any] = []
    base = 0

    def close():
        nonlocal base, v, vt, f
        if v:
            meshes.append(_as_written(v, np.array(f, dtype=np.int64) - base, vt if vt else None))
            base += len(v)
        v, vt, f = [], [], []

    for line in text.splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "o":
            close()
        elif parts[0] == "v":
            v.append([float(parts[1]), float(parts[2])])
        elif parts[0] == "vt":
            vt.append([float(parts[1]), float(parts[2])])
        elif parts[0] == "f":
            f.append([int(p.split("/")[0]) - 1 for p in parts[1:4]])
    close()
    return meshes

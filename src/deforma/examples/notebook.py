"""Notebook: the bundled Jupyter notebook (pictures of meshes and worlds, deforma.show) run as a script.

The notebook ships with the package: ``--copy DIR`` writes it into DIR to open in Jupyter
(``jupyter lab DIR/notebook.ipynb``). Without Jupyter this example runs its code cells in
order in one namespace, as a kernel would, and prints what each cell's last line shows;
``--output PATH.png`` saves the last picture a cell showed. ``deforma.show`` needs the
``render`` extra (OpenGL 3.3, headless through EGL where there is no display).
"""

from __future__ import annotations

import ast
import io
import json
import shutil
from importlib import resources
from pathlib import Path

from ._common import parser, save_picture

NOTEBOOK = "notebook.ipynb"


def code_cells() -> list[str]:
    """The source of every code cell of the bundled notebook, in order."""
    nb = json.loads(resources.files(__package__).joinpath(NOTEBOOK).read_text(encoding="utf-8"))
    return ["".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"]


def run_cell(source: str, namespace: dict, name: str):
    """Run one cell's code in ``namespace``; the value of its last line if that is an expression
    (what a notebook shows under the cell), else None."""
    tree = ast.parse(source, filename=name)
    last = tree.body.pop() if tree.body and isinstance(tree.body[-1], ast.Expr) else None
    exec(compile(tree, name, "exec"), namespace)
    return eval(compile(ast.Expression(last.value), name, "eval"), namespace) if last else None


def main(argv: list[str] | None = None) -> int:
    """Copy the notebook out, or run its cells and print what each shows."""
    p = parser("notebook", __doc__)
    p.add_argument("--copy", metavar="DIR", default=None, help=f"write {NOTEBOOK} into DIR and stop")
    args = p.parse_args(argv)
    if args.copy:
        target = Path(args.copy) / NOTEBOOK
        target.parent.mkdir(parents=True, exist_ok=True)
        with resources.as_file(resources.files(__package__).joinpath(NOTEBOOK)) as source:
            shutil.copyfile(source, target)
        print(f"wrote {target}; open it with: jupyter lab {target}")
        return 0
    namespace: dict = {"__name__": "__notebook__"}
    picture = None
    for k, source in enumerate(code_cells(), 1):
        value = run_cell(source, namespace, f"<cell {k}>")
        if value is None:
            continue
        shown = " ".join(repr(value).split())
        print(f"[{k}] {shown[:100]}{' ...' if len(shown) > 100 else ''}")
        if hasattr(value, "_repr_png_"):
            picture = value._repr_png_()  # a Mesh, a World or an Animation's last frame
    if args.output and picture is not None:
        from PIL import Image

        save_picture(Image.open(io.BytesIO(picture)), args.output)
    return 0

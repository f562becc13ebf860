"""Keys and mouse buttons of the viewer: one table for the code, the help overlay and the docs.

Key names are pygame's (``pygame.key.key_code(name)`` turns them into codes), so this
module imports nothing from pygame.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["KEYS", "MOUSE", "help_rows", "key_label"]

#: (key names, action, what it does). The first name is the one shown.
KEYS: tuple[tuple[tuple[str, ...], str, str], ...] = (
    (("space",), "explode", "explosion: every vertex gets the explosive force upward"),
    (("p",), "pause", "pause / resume"),
    (("n", "."), "step", "one step while paused"),
    (("r",), "reset", "reset the bodies to their start"),
    (("w",), "wireframe", "springs on / off"),
    (("f",), "pin", "pin / unpin the vertex under the pointer (fix it in place)"),
    (("u",), "unpin", "unpin every vertex"),
    (("j",), "join", "join: click a rigid body where the hinge goes, then another body (or the background)"),
    (("right",), "drive:1", "drive: every motor forward (clockwise, as the car's wheels roll right)"),
    (("left",), "drive:-1", "drive: every motor back"),
    (("down",), "drive:0", "brake: every motor held at no spin"),
    (("z",), "rotate:5", "turn the selected collider 5° counter-clockwise (with Shift: 1°)"),
    (("x",), "rotate:-5", "turn the selected collider 5° clockwise (with Shift: 1°)"),
    (("delete",), "remove_collider", "remove the selected collider"),
    (("1",), "object:bunny", "bunny"),
    (("2",), "object:donut", "donut"),
    (("3",), "object:armadillo", "armadillo"),
    (("4",), "object:box", "box (the original's Square)"),
    (("tab",), "panel", "inspector panel on / off"),
    (("f2",), "screenshot", "screenshot to deforma-NNN.png"),
    (("h", "f1"), "help", "this help on / off"),
    (("escape", "q"), "quit", "quit"),
)

#: (button, what it does).
MOUSE: tuple[tuple[str, str], ...] = (
    ("left drag on a body", "pull it toward the pointer (mouse strength)"),
    ("left drag on a collider", "move it (and select it in the panel); a wire is picked within 10 px"),
    ("shift+left click on a body", "pin / unpin the vertex nearest the pointer"),
    ("right drag", "pan the view"),
    ("wheel", "zoom"),
)


def key_label(names: Iterable[str]) -> str:
    """How a key is written for people: ``("escape", "q")`` -> ``"Escape / Q"``."""
    return " / ".join(n.capitalize() if len(n) > 1 else n.upper() for n in names)


def help_rows() -> list[tuple[str, str]]:
    """The help overlay's rows: (key or mouse action, what it does).

    Examples
    --------
    >>> help_rows()[0]
    ('Space', 'explosion: every vertex gets the explosive force upward')
    """
    rows = [(key_label(names), text) for names, _action, text in KEYS]
    rows.append(("Ctrl+S", "save the scene (file named in the panel)"))
    rows.extend((button.capitalize(), text) for button, text in MOUSE)
    return rows

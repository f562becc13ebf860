"""The inspector panel: pygame_gui widgets drawn to a surface that the window shows as a texture.

Rows follow the original Unity inspector's groups (Square, Texture, Physics, Collision,
Mouse), plus Material (the world's model and its finite-element parameters, the selected
body's behaviours and gas pressure) and Contact. Under the Integrator drop-down are the
options of the integrator in force (a drop-down for a choice, slider and text box for a
number); the rows of the options it does not take are hidden, and the rows below move up or
down when another integrator takes more or fewer.
Each number has a slider (a comfortable range, log-scaled where values span decades) and a
text box (any value the session accepts; Enter applies it). A value that may be off (a
material behaviour, a body's gas pressure) shows "off" in its otherwise empty box: emptying
the box (or typing ``off``) turns it off, typing a number or moving the slider turns it on.
A refused value leaves everything as it was and shows the reason in red at the bottom of
the panel.

The panel has its own :class:`pygame_gui.UIManager` sized to the panel, so mouse events are
translated into panel coordinates and the mouse position comes from the events (which also
makes the panel drivable by posted events in tests, where there is no real pointer).
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import pygame
import pygame_gui
from pygame_gui.core import ObjectID, UIElement
from pygame_gui.elements import (UIButton, UICheckBox, UIDropDownMenu, UIHorizontalSlider, UILabel, UIPanel,
                                 UIScrollingContainer, UITextBox, UITextEntryLine)

from ..physics import available_integrators
from .params import GROUPS, Param, format_value, integrator_params, parse_value
from ..physics.material import material_models
from .session import COLLIDER_FIELDS, COLLIDER_SHAPES, OBJECTS

if TYPE_CHECKING:
    from .session import Session

__all__ = ["PANEL_WIDTH", "Inspector"]

PANEL_WIDTH = 340
ROW = 26            # row pitch in pixels
TOP = 104           # buttons and the save-file box above the scrolling rows
MESSAGE_HEIGHT = 64
REDRAW_INTERVAL = 0.2   # seconds between redraws of an untouched panel

ACCENT = "#3d6fb6"
THEME = {
    "defaults": {
        "colours": {
            "normal_bg": "#e9edf3", "hovered_bg": "#dde4ee", "disabled_bg": "#f1f2f4", "selected_bg": "#cfdcf0",
            "active_bg": "#c3d3ec", "dark_bg": "#f7f8fa", "disabled_dark_bg": "#eef0f3",
            "normal_text": "#1f2a37", "hovered_text": "#111827", "selected_text": "#111827",
            "active_text": "#111827", "disabled_text": "#9aa3ad",
            "normal_border": "#c4ccd6", "hovered_border": "#8fa6c6", "disabled_border": "#dde1e6",
            "selected_border": ACCENT, "active_border": ACCENT,
            "text_cursor": "#1f2a37", "link_text": ACCENT, "link_hover": ACCENT, "link_selected": ACCENT,
            "filled_bar": ACCENT, "unfilled_bar": "#d5dbe3",
        },
        "font": {"name": "noto_sans", "size": "13"},
        "misc": {"shape": "rounded_rectangle", "shape_corner_radius": "4", "border_width": "1",
                 "shadow_width": "0"},
    },
    "panel": {"colours": {"dark_bg": "#f7f8fa", "normal_border": "#c4ccd6"},
              "misc": {"shape": "rectangle", "border_width": "0", "shadow_width": "0"}},
    "scrolling_container": {"colours": {"dark_bg": "#f7f8fa"}, "misc": {"border_width": "0", "shadow_width": "0"}},
    "label": {"colours": {"dark_bg": "#00000000", "normal_text": "#2b3846"},
              "misc": {"text_horiz_alignment": "left"}},
    "@header": {"colours": {"normal_text": ACCENT}, "font": {"name": "noto_sans", "size": "14", "bold": "1"}},
    "@title": {"colours": {"normal_text": "#111827"}, "font": {"name": "noto_sans", "size": "17", "bold": "1"}},
    "@dim": {"colours": {"normal_text": "#6b7785"}},
    "horizontal_slider": {"colours": {"dark_bg": "#d5dbe3"},
                          "misc": {"enable_arrow_buttons": "0", "sliding_button_width": "14"}},
    "horizontal_slider.#sliding_button": {"colours": {"normal_bg": ACCENT, "hovered_bg": "#2f5a98",
                                                      "active_bg": "#28508a", "normal_border": "#2f5a98"},
                                          "misc": {"shape": "rounded_rectangle", "shape_corner_radius": "5"}},
    "text_entry_line": {"colours": {"dark_bg": "#ffffff", "selected_bg": "#cfdcf0"}},
    "text_box": {"colours": {"dark_bg": "#f7f8fa", "normal_border": "#f7f8fa"},
                 "misc": {"border_width": "0", "padding": "2,2"}},
    "@primary": {"colours": {"normal_bg": ACCENT, "hovered_bg": "#2f5a98", "active_bg": "#28508a",
                             "normal_text": "#ffffff", "hovered_text": "#ffffff", "active_text": "#ffffff",
                             "normal_border": "#2f5a98"}},
}


class _PanelManager(pygame_gui.UIManager):
    """A UIManager whose mouse position is set from events (in panel coordinates)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.pointer: tuple[int, int] = (-1, -1)
        super().__init__(*args, **kwargs)

    def _update_mouse_position(self) -> None:
        self.mouse_position = self.pointer


class _Row:
    """The widgets of one parameter."""

    def __init__(self, param: Param) -> None:
        self.param = param
        self.slider: UIHorizontalSlider | None = None
        self.entry: UITextEntryLine | None = None
        self.check: UICheckBox | None = None
        self.menu: UIDropDownMenu | None = None  # a choice's drop-down, and the value it was made showing
        self.menu_rect: pygame.Rect | None = None
        self.menu_made_for: Any = None
        self.label: UILabel | None = None
        self.top = 0               # y of the row in the scrolling area, pixels
        self.shown: Any = object()  # value last shown, to touch widgets only on change
        self.slider_value: float | None = None  # slider position last set by us; a different one was the user

    def widgets(self) -> list[UIElement]:
        """The row's widgets, its label first."""
        return [w for w in (self.label, self.slider, self.entry, self.check, self.menu) if w is not None]


class Inspector:
    """The panel: builds the widgets, applies edits to a session, shows refusals.

    Parameters
    ----------
    session : deforma.viewer.session.Session
    height : int
        Panel height in pixels (the window's).
    save_path : str, keyword-only
        Initial file name in the "save scene" box.
    """

    def __init__(self, session: Session, height: int, *, save_path: str = "scene.toml",
                 actions: Mapping[str, Callable[[], object]] | None = None) -> None:
        self.session = session
        self.height = int(height)
        self.actions = actions if actions is not None else {}
        self.manager = _PanelManager((PANEL_WIDTH, self.height), theme_path=THEME,
                                     enable_live_theme_updates=False)
        self.surface = pygame.Surface((PANEL_WIDTH, self.height), pygame.SRCALPHA)
        self.rows: dict[str, _Row] = {}
        self.message = ""
        self.message_is_error = False
        self._message_shown: tuple[str, bool] | None = None
        self._save_path = save_path
        #: The shape the Add button makes (the menu beside it).
        self.new_shape = COLLIDER_SHAPES[0]
        self.dirty = True
        self._since_draw = 0.0
        self._build()
        self.refresh(force=True)

    # -- layout ----------------------------------------------------------------------------
    def _build(self) -> None:
        m = self.manager
        h = self.height
        self.background = UIPanel(pygame.Rect(0, 0, PANEL_WIDTH, h), manager=m, starting_height=0)
        UILabel(pygame.Rect(12, 6, 200, 26), "deforma inspector", m, object_id=ObjectID(class_id="@title"))
        self.title_hint = UILabel(pygame.Rect(200, 8, PANEL_WIDTH - 212, 22), "Tab hides", m,
                                  object_id=ObjectID(class_id="@dim"))
        bw, gap, x = 74, 6, 12
        self.pause_button = UIButton(pygame.Rect(x, 38, bw, 26), "Pause", m, tool_tip_text="P")
        self.step_button = UIButton(pygame.Rect(x + (bw + gap), 38, bw, 26), "Step", m, tool_tip_text="N")
        self.reset_button = UIButton(pygame.Rect(x + 2 * (bw + gap), 38, bw, 26), "Reset", m, tool_tip_text="R")
        self.wire_button = UIButton(pygame.Rect(x + 3 * (bw + gap), 38, bw, 26), "Wires", m, tool_tip_text="W")
        self.save_entry = UITextEntryLine(pygame.Rect(12, 70, PANEL_WIDTH - 24 - 100, 28), m,
                                          initial_text=self._save_path)
        self.save_button = UIButton(pygame.Rect(PANEL_WIDTH - 12 - 94, 70, 94, 28), "Save scene", m,
                                    object_id=ObjectID(class_id="@primary"), tool_tip_text="Ctrl+S")
        scroll_h = h - TOP - MESSAGE_HEIGHT
        self.scroll = UIScrollingContainer(pygame.Rect(0, TOP, PANEL_WIDTH, scroll_h), m, allow_scroll_x=False)
        c = self.scroll
        y = 4
        for group, params in GROUPS:
            UILabel(pygame.Rect(10, y, 200, 22), group, m, container=c, object_id=ObjectID(class_id="@header"))
            y += ROW - 2
            if group == "Texture":
                UILabel(pygame.Rect(14, y, 108, 24), "Selected", m, container=c)
                self._menu_rect = pygame.Rect(124, y, 188, 24)
                self._make_menu()
                y += ROW
            if group == "Physics":
                UILabel(pygame.Rect(14, y, 108, 24), "Integrator", m, container=c)
                self._integrator_rect = pygame.Rect(124, y, 188, 24)
                self._make_integrator_menu()
                y += ROW
                # a row for every integrator's options (read from the registry, as the
                # menu's names are), indented under it; _place_option_rows() then shows those
                # of the integrator in force and closes the gap the others leave
                self._options_top = y
                self._option_rows = tuple(p.name for p in integrator_params())
                for p in integrator_params():
                    self.rows[p.name] = self._row(p, y, indent=10)
                    y += ROW
            if group == "Material":
                UILabel(pygame.Rect(14, y, 108, 24), "Model", m, container=c)
                self._material_rect = pygame.Rect(124, y, 188, 24)
                self._make_material_menu()
                y += ROW
            if group == "Collision":
                self.prev_collider = UIButton(pygame.Rect(14, y, 26, 24), "<", m, container=c,
                                              tool_tip_text="previous collider")
                self.collider_label = UILabel(pygame.Rect(42, y, 124, 24), "", m, container=c)
                self.next_collider = UIButton(pygame.Rect(168, y, 26, 24), ">", m, container=c,
                                              tool_tip_text="next collider (or click one in the world)")
                self.remove_collider = UIButton(pygame.Rect(222, y, 90, 24), "Remove", m, container=c,
                                                tool_tip_text="remove the selected collider (Delete)")
                y += ROW
                self._shape_rect = pygame.Rect(14, y, 180, 24)
                self._make_shape_menu()
                self.add_collider = UIButton(pygame.Rect(222, y, 90, 24), "Add", m, container=c,
                                             tool_tip_text="a new collider of the chosen shape at the view's centre")
                y += ROW
            for p in params:
                self.rows[p.name] = self._row(p, y)
                y += ROW
            y += 6
        self._scroll_height = y + 4
        c.set_scrollable_area_dimensions((PANEL_WIDTH - 20, self._scroll_height))
        self._all_option_rows = self._option_rows
        self._place_option_rows()
        self.message_box = UITextBox("", pygame.Rect(8, h - MESSAGE_HEIGHT + 2, PANEL_WIDTH - 16,
                                                     MESSAGE_HEIGHT - 6), m)

    def _row(self, p: Param, y: int, *, indent: int = 0) -> _Row:
        m, c = self.manager, self.scroll
        row = _Row(p)
        # the unit when it fits; docs/viewer.md lists them all
        label = p.label + (f" ({p.unit})" if p.unit and len(p.label) + len(p.unit) <= 13 else "")
        row.top = y
        row.label = UILabel(pygame.Rect(12 + indent, y, 113 - indent, 24), label, m, container=c)
        if p.kind == "bool":
            row.check = UICheckBox(pygame.Rect(124, y + 3, 18, 18), "", m, container=c)
        elif p.kind == "choice":
            row.menu_rect = pygame.Rect(124, y, 188, 24)
            self._make_choice_menu(row, p.choices[0])
        else:
            row.slider = UIHorizontalSlider(pygame.Rect(124, y + 3, 112, 18), 0.0, (0.0, 1.0), m, container=c,
                                            click_increment=0.02)
            row.entry = UITextEntryLine(pygame.Rect(240, y, 72, 24), m, container=c,
                                        placeholder_text=p.off_text if p.optional else None)
        return row

    def _make_choice_menu(self, row: _Row, shown: str) -> None:
        assert row.menu_rect is not None  # a choice's row has one (_row)
        row.menu_made_for = shown
        choices: list[str | tuple[str, str]] = list(row.param.choices)
        row.menu = UIDropDownMenu(choices, shown, row.menu_rect, self.manager, container=self.scroll,
                                  expansion_height_limit=len(row.param.choices) * 26)

    def _make_menu(self) -> None:
        self._menu_made_for = self._selected_text()
        objects: list[str | tuple[str, str]] = list(OBJECTS)
        self.selected_menu = UIDropDownMenu(objects, self._menu_made_for, self._menu_rect, self.manager,
                                            container=self.scroll, expansion_height_limit=4 * 26)

    def _make_shape_menu(self) -> None:
        self.shape_menu = UIDropDownMenu(list(COLLIDER_SHAPES), self.new_shape, self._shape_rect, self.manager,
                                         container=self.scroll, expansion_height_limit=len(COLLIDER_SHAPES) * 26)

    def _make_integrator_menu(self) -> None:
        # the registry: a user-registered integrator shows too
        names: list[str | tuple[str, str]] = list(available_integrators())
        self._integrator_menu_made_for = self.session.integrator
        self.integrator_menu = UIDropDownMenu(names, self._integrator_menu_made_for, self._integrator_rect,
                                              self.manager, container=self.scroll,
                                              expansion_height_limit=len(names) * 26)

    def _make_material_menu(self) -> None:
        self._material_menu_made_for = self.session.material_model
        models = material_models()  # a registered element kind's model too
        self.material_menu = UIDropDownMenu(list(models), self._material_menu_made_for,
                                            self._material_rect, self.manager, container=self.scroll,
                                            expansion_height_limit=len(models) * 26)

    def _selected_text(self) -> str:
        sel = self.session.mesh.selected
        return sel if sel in OBJECTS else OBJECTS[0]

    # -- input -----------------------------------------------------------------------------
    @property
    def typing(self) -> bool:
        """True while a text box has the keyboard (shortcut keys must then go to it)."""
        focus = self.manager.get_focus_set()
        return any(isinstance(e, UITextEntryLine) and e.is_focused for e in (focus or ()))

    def process_event(self, event: pygame.event.Event) -> bool:
        """Feed one event (mouse positions already in panel coordinates); True if the panel used it."""
        if event.type in (pygame.MOUSEMOTION, pygame.MOUSEBUTTONDOWN, pygame.MOUSEBUTTONUP):
            self.manager.pointer = (int(event.pos[0]), int(event.pos[1]))
        self.dirty = True
        used = self.manager.process_events(event)
        t = event.type
        if t == pygame_gui.UI_BUTTON_PRESSED:
            self._button(event.ui_element)
            used = True
        elif t == pygame_gui.UI_TEXT_ENTRY_FINISHED:
            self._entry(event.ui_element)
            used = True
        elif t in (pygame_gui.UI_CHECK_BOX_CHECKED, pygame_gui.UI_CHECK_BOX_UNCHECKED):
            for name, row in self.rows.items():
                if row.check is event.ui_element:
                    self.apply(name, t == pygame_gui.UI_CHECK_BOX_CHECKED)
            used = True
        elif t == pygame_gui.UI_DROP_DOWN_MENU_CHANGED and event.ui_element is self.selected_menu:
            self.apply_object(event.text)
            used = True
        elif t == pygame_gui.UI_DROP_DOWN_MENU_CHANGED and event.ui_element is self.shape_menu:
            self.new_shape = event.text
            self.say(f"Add puts a {event.text} at the view's centre")
            used = True
        elif t == pygame_gui.UI_DROP_DOWN_MENU_CHANGED and event.ui_element is self.integrator_menu:
            self.apply_integrator(event.text)
            used = True
        elif t == pygame_gui.UI_DROP_DOWN_MENU_CHANGED and event.ui_element is self.material_menu:
            self.apply_material(event.text)
            used = True
        elif t == pygame_gui.UI_DROP_DOWN_MENU_CHANGED:
            for name, row in self.rows.items():
                if row.menu is event.ui_element:
                    self.apply(name, event.text)
                    used = True
        return bool(used)

    def _button(self, el: UIButton) -> None:
        s = self.session
        if el is self.save_button:
            self.save()
        elif el in (self.pause_button, self.step_button, self.reset_button, self.wire_button):
            name = {self.pause_button: "pause", self.step_button: "step", self.reset_button: "reset",
                    self.wire_button: "wireframe"}[el]
            if name in self.actions:
                self.actions[name]()
        elif el is self.add_collider:
            if self._try(lambda: s.add_collider(self.new_shape)):
                assert s.collider_index is not None  # add_collider selects the new collider
                self.say(f"added a {self.new_shape} (collider {s.collider_index + 1}); drag it, turn it with Z / X "
                         f"or type its values")
        elif el is self.remove_collider:
            self._try(s.remove_collider)
        elif el in (self.prev_collider, self.next_collider) and s.world.colliders:
            n = len(s.world.colliders)
            i = s.collider_index if s.collider_index is not None else 0
            s.select_collider((i + (1 if el is self.next_collider else -1)) % n)
        self.refresh()

    def _entry(self, el: UITextEntryLine) -> None:
        if el is self.save_entry:
            self.save()
            return
        for name, row in self.rows.items():
            if row.entry is el:
                try:
                    value = parse_value(row.param, el.get_text())
                except ValueError as e:
                    self.say(str(e), error=True)
                    row.shown = object()  # show the current value again
                    return
                self.apply(name, value)
                return

    def apply(self, name: str, value: Any) -> bool:
        """Set a parameter through the session; a refusal becomes the panel's message. True if applied."""
        try:
            unchanged = self.session.get_param(name) == value
        except (TypeError, ValueError):
            unchanged = False
        if unchanged:  # e.g. the event a checkbox posts when refresh() sets it: no rebuild
            self.rows[name].shown = object()
            return True
        ok = self._try(lambda: self.session.set_param(name, value))
        row = self.rows[name]
        if ok and row.param.rebuild:
            self.say(self._mesh_summary(), error=self.session.note_is_warning)
        elif ok and self.session.note:  # e.g. substeps raised for a stiffer material
            self.say(self.session.note, error=self.session.note_is_warning)
        elif ok and self.message_is_error:
            self.say("")
        row.shown = object()
        # a refused choice: its drop-down shows what was clicked, so it is made anew
        self.refresh(force=not ok and row.menu is not None)
        return ok

    def apply_object(self, name: str) -> bool:
        """Switch the edited body to a built-in object (the original's "Selected")."""
        if name == self.session.mesh.selected:
            return True
        ok = self._try(lambda: self.session.select_object(name))
        if ok:
            self.say(self._mesh_summary(), error=self.session.note_is_warning)
        self.refresh(force=True)
        return ok

    def apply_integrator(self, name: str) -> bool:
        """Switch the running world's integrator (the drop-down in the Physics group)."""
        if name == self.session.integrator:
            return True
        ok = self._try(lambda: self.session.set_integrator(name))
        if ok:
            note = self.session.note
            self.say(f"integrator: {name}" + (f"; {note}" if note else ""), error=bool(note))
        self.refresh(force=True)
        return ok

    def apply_material(self, model: str) -> bool:
        """Switch the world's material model (the drop-down in the Material group).

        A body that cannot be made of finite elements (a chain without triangles) refuses
        it: the panel then shows why in red and the menu goes back to the model in force.
        """
        if model == self.session.material_model:
            return True
        ok = self._try(lambda: self.session.set_material(model))
        if ok:
            note = self.session.note
            self.say(f"material: {model}" + (f"; {note}" if note else ""), error=self.session.note_is_warning)
        self.refresh(force=True)
        return ok

    def _mesh_summary(self) -> str:
        s = self.session
        b = s.world.bodies[s.body_index]
        text = f"rebuilt {s.mesh.selected}: {b.n_vertices} vertices, {len(b.triangles)} triangles"
        return f"{text}; {s.note}" if s.note else text

    def save(self) -> bool:
        """Write the scene to the file named in the save box."""
        path = self.save_entry.get_text().strip()
        if not path:
            self.say("type a file name ending in .toml first", error=True)
            return False
        ok = self._try(lambda: self.session.save(path))
        if ok:
            self.say(f"saved {path}; deforma run {path} renders it")
        return ok

    def _try(self, fn: Callable[[], object]) -> bool:
        try:
            fn()
        except (ValueError, OSError) as e:  # a refused value never reaches the world
            self.say(str(e), error=True)
            return False
        return True

    def say(self, text: str, *, error: bool = False) -> None:
        """Show ``text`` at the bottom of the panel (red when ``error``)."""
        self.message = text
        self.message_is_error = error
        self.dirty = True

    # -- per frame -------------------------------------------------------------------------
    def poll_sliders(self) -> None:
        """Apply sliders the user moved since the last call (dragging posts no event we can rely on)."""
        for name, row in self.rows.items():
            s = row.slider
            if s is None or row.slider_value is None:
                continue
            v = s.get_current_value()
            if v != row.slider_value:
                row.slider_value = v
                value = row.param.from_slider(v)
                current = self.session.get_param(name)
                # an optional value that is off (None) is turned on by its slider
                if (current is not None or row.param.optional) and value != current:
                    self.apply(name, value)

    def refresh(self, *, force: bool = False) -> None:
        """Make the widgets show the session's current values (only widgets whose value changed)."""
        s = self.session
        if s.integrator_params() != self._option_rows:  # switched here, by a key or in code
            self._place_option_rows()
            force = True
        for name, row in self.rows.items():
            value = s.get_param(name)
            if not force and value == row.shown:
                continue
            row.shown = value
            self.dirty = True
            if row.menu is not None:
                if value is not None:  # None: a hidden row, an option the integrator does not take
                    self._refresh_choice(row, value, force)
                continue
            if row.check is not None:
                if row.check.get_state() != bool(value):
                    row.check.set_state(bool(value))
                continue
            if row.entry is not None and not row.entry.is_focused:
                row.entry.set_text(format_value(row.param, value))
            if row.slider is not None and (value is not None or row.param.optional):
                dragging = row.slider.sliding_button is not None and row.slider.sliding_button.held
                if not dragging:
                    # an optional value that is off rests at the slider's left end
                    t = 0.0 if value is None else row.param.to_slider(value)
                    row.slider.set_current_value(t, warn=False)
                row.slider_value = row.slider.get_current_value()
        n = len(s.world.colliders)
        text = "none" if s.collider_index is None else f"{s.collider_index + 1} of {n}: {s.collider_shape}"
        if self.collider_label.text != text:
            self.collider_label.set_text(text)
        # the rows of values the selected collider's shape does not have are greyed out
        has = set(s.collider_params())
        for name in COLLIDER_FIELDS:
            field_row = self.rows.get(name)
            if field_row is None:
                continue
            for widget in (field_row.slider, field_row.entry):
                if widget is not None and widget.is_enabled != (name in has):
                    widget.enable() if name in has else widget.disable()
                    self.dirty = True
        # A drop-down has no setter, so one the session changed behind it (a number key, a
        # loaded scene) is made anew. Compare with what the menu was made for, not with what it
        # shows: a choice just clicked shows before its event reaches apply_*(), and remaking
        # the menu then would drop that event. After a refused choice (force), the menu is put
        # back to the value in force.
        sel = self._selected_text()
        if sel != self._menu_made_for or (force and self.selected_menu.selected_option[0] != sel):
            self.selected_menu.kill()
            self._make_menu()
            self.dirty = True
        integ = self.session.integrator
        if integ != self._integrator_menu_made_for or (force and self.integrator_menu.selected_option[0] != integ):
            self.integrator_menu.kill()
            self._make_integrator_menu()
            self.dirty = True
        model = self.session.material_model
        if model != self._material_menu_made_for or (force and self.material_menu.selected_option[0] != model):
            self.material_menu.kill()
            self._make_material_menu()
            self.dirty = True
        if self._message_shown != (self.message, self.message_is_error):
            self._message_shown = (self.message, self.message_is_error)
            colour = "#c0392b" if self.message_is_error else "#2b3846"
            safe = self.message.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
            self.message_box.set_text(f'<font color="{colour}">{safe}</font>')

    def _place_option_rows(self) -> None:
        """Show the option rows of the integrator in force, in order under the Integrator
        drop-down, and hide (and disable) the others; the widgets below move up or down to
        close or open the gap. Widgets are moved, not made anew, so that a reference to one
        stays good across a switch."""
        taken = self.session.integrator_params()
        top = self._options_top
        rows = [self.rows[name] for name in self._all_option_rows]
        dy = (len(taken) - len(self._option_rows)) * ROW
        if dy:
            mine = {id(w) for row in rows for w in row.widgets()}
            self._shift_below(top + len(self._option_rows) * ROW, dy, skip=mine)
            self._scroll_height += dy
            self.scroll.set_scrollable_area_dimensions((PANEL_WIDTH - 20, self._scroll_height))
        for row in rows:
            shown = row.param.name in taken
            y = top + taken.index(row.param.name) * ROW if shown else top
            for w in row.widgets():
                w.set_relative_position((w.relative_rect.left, w.relative_rect.top + y - row.top))
                # disabled too: a hidden widget must not take a click meant for the row shown there
                if shown:
                    w.show()
                    w.enable()
                else:
                    w.hide()
                    w.disable()
            if row.menu_rect is not None:
                row.menu_rect.move_ip(0, y - row.top)
            row.top = y
        self._option_rows = taken
        self.dirty = True

    def _shift_below(self, top: int, dy: int, *, skip: Collection[int] = frozenset()) -> None:
        """Move every widget of the scrolling area from ``top`` down by ``dy`` pixels (up if
        negative), and the places where drop-downs are made anew, except the widgets in ``skip``."""
        elements = self.scroll.scrollable_container.elements
        # a slider keeps its buttons in a container beside it, which it moves itself
        owned = {id(getattr(e, "button_container", None)) for e in elements}
        for e in list(elements):
            r = e.get_relative_rect()
            if r.top >= top and id(e) not in owned and id(e) not in skip:
                e.set_relative_position((r.left, r.top + dy))
        for rect in (self._menu_rect, self._integrator_rect, self._material_rect, self._shape_rect):
            if rect.top >= top:
                rect.move_ip(0, dy)

    def _refresh_choice(self, row: _Row, shown: Any, force: bool) -> None:
        # as the other drop-downs (see refresh): made anew when the value changed behind it
        assert row.menu is not None  # called for the rows of a choice only
        if shown != row.menu_made_for or (force and row.menu.selected_option[0] != shown):
            row.menu.kill()
            self._make_choice_menu(row, shown)
            self.dirty = True

    def set_paused(self, paused: bool) -> None:
        """Label the pause button for the current state."""
        text = "Resume" if paused else "Pause"
        if self.pause_button.text != text:
            self.pause_button.set_text(text)

    def update(self, frame_time: float) -> pygame.Surface | None:
        """Advance the widgets by ``frame_time`` seconds; returns the redrawn panel surface, or None
        when nothing changed.

        Drawing the panel and uploading it as a texture costs about as much as drawing the
        world on a software rasteriser, so it is done only after input, a changed value, or
        every :data:`REDRAW_INTERVAL` seconds (tooltips, the text cursor's blink).
        """
        self.poll_sliders()
        self.refresh()
        self.manager.update(frame_time)
        self._since_draw += frame_time
        if not (self.dirty or self._since_draw >= REDRAW_INTERVAL):
            return None
        self.dirty = False
        self._since_draw = 0.0
        self.manager.draw_ui(self.surface)
        return self.surface

    def contains(self, panel_pos: Sequence[float]) -> bool:
        """True if ``panel_pos`` (panel coordinates) is on the panel."""
        x, y = panel_pos
        return 0 <= x < PANEL_WIDTH and 0 <= y < self.height

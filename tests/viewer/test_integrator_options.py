"""The integrator's options in the viewer: the session sets them by name and refuses a bad one
in one line, changing nothing; the panel shows the rows of the integrator in force under its
drop-down, and they follow a switch (drop-down, code or a loaded scene)."""

import pygame_gui
import pytest

import deforma
from deforma.physics.integrators import make_integrator
from deforma.viewer.inspector import ROW
from deforma.viewer.params import INTEGRATOR_PREFIX, PARAMS, integrator_params
from deforma.viewer.session import Session
from seed_scenes import seed
from test_viewer import choose_from_menu, post, run

ROWS = {"symplectic-euler": ["integrator_mode"],
        "implicit-euler": ["integrator_iterations", "integrator_tolerance", "integrator_max_iterations",
                           "integrator_contact_weight"],
        "xpbd": ["integrator_iterations"],
        "implicit-bdf2": ["integrator_iterations", "integrator_tolerance", "integrator_max_iterations",
                          "integrator_contact_weight"],
        "avbd": ["integrator_mode", "integrator_iterations", "integrator_tolerance", "integrator_reach",
                 "integrator_order",
                 "integrator_cluster_size", "integrator_start",
                 "integrator_chebyshev",
                 "integrator_penalty_start", "integrator_penalty_ramp", "integrator_penalty_max",
                 "integrator_rigid_passes"]}


def test_every_registered_option_has_a_row_apart_from_the_fixed_ones():
    rows = {p.name: p for p in integrator_params()}
    assert list(rows) == ["integrator_mode", "integrator_iterations", "integrator_tolerance",
                          "integrator_max_iterations", "integrator_contact_weight", "integrator_reach",
                          "integrator_order", "integrator_cluster_size", "integrator_start",
                          "integrator_chebyshev", "integrator_penalty_start", "integrator_penalty_ramp",
                          "integrator_penalty_max", "integrator_rigid_passes"]
    assert not set(rows) & set(PARAMS)
    mode = rows["integrator_mode"]
    assert mode.kind == "choice" and mode.choices == ("auto", "serial", "parallel")
    assert rows["integrator_iterations"].kind == "int" and rows["integrator_iterations"].log
    assert (rows["integrator_contact_weight"].lo, rows["integrator_contact_weight"].hi) == (0.1, 1000.0)
    # implicit Euler's tolerance (default 0, a fixed number of iterations): a linear slider
    # from 0 to 1 m/s; the text box takes any value the option allows
    assert (rows["integrator_tolerance"].lo, rows["integrator_tolerance"].hi, rows["integrator_tolerance"].log) \
        == (0.0, 1.0, False)


def implicit_demo():
    """The demo in a session, switched to implicit Euler (whose options these tests set)."""
    s = Session("demo")
    s.set_integrator("implicit-euler")
    return s


def test_the_session_sets_an_option_by_name_and_keeps_the_others(tmp_path):
    s = implicit_demo()
    world = s.world
    s.set_param("integrator_contact_weight", 20.0)
    s.set_param("integrator_iterations", 6.0)  # a whole float, as a slider gives it
    assert s.world is world  # set on the running world, no rebuild
    assert world.integrator_options == {"iterations": 6, "tolerance": 0.0, "max_iterations": 500,
                                       "contact_weight": 20.0}
    assert s.get_param("integrator_iterations") == 6 and s.get_param("integrator_mode") is None
    s.set_integrator_option("contact_weight", 15.0)
    assert s.integrator_options == {"iterations": 6, "tolerance": 0.0, "max_iterations": 500, "contact_weight": 15.0}
    s.reset()  # starting again keeps every value, the options too
    assert s.world.integrator_options == {"iterations": 6, "tolerance": 0.0, "max_iterations": 500,
                                         "contact_weight": 15.0}
    path = s.save(tmp_path / "options.toml")
    assert deforma.load_scene(path).integrator_options == {"iterations": 6, "tolerance": 0.0, "max_iterations": 500,
                                                          "contact_weight": 15.0}


BAD = [
    ("integrator_iterations", 0, "implicit-euler option iterations must be an integer in [1, 10000], got 0"),
    ("integrator_iterations", 2.5, "implicit-euler option iterations must be an integer in [1, 10000], got 2.5"),
    ("integrator_contact_weight", -1.0,
     "implicit-euler option contact_weight must be a number in (0, 1e+12), got -1.0"),
    ("integrator_contact_weight", "x",
     "implicit-euler option contact_weight must be a number in (0, 1e+12), got 'x'"),
    ("integrator_mode", "serial",
     "'mode' is an option of symplectic-euler and avbd, not of implicit-euler "
     "(implicit-euler takes iterations, tolerance, max_iterations, contact_weight)"),
]


@pytest.mark.parametrize("name, value, message", BAD, ids=[f"{n}={v!r}" for n, v, _ in BAD])
def test_a_bad_option_is_refused_in_one_line_and_changes_nothing(name, value, message):
    s = implicit_demo()
    s.set_param("integrator_iterations", 5)
    before = s.world.integrator_options
    with pytest.raises(ValueError) as e:
        s.set_param(name, value)
    assert str(e.value) == message and "\n" not in str(e.value)
    assert s.world.integrator_options == before


def test_a_misspelt_option_says_what_was_meant():
    s = implicit_demo()
    with pytest.raises(ValueError, match=r"^unknown implicit-euler option 'iteratons' \(did you mean 'iterations'\?\)"):
        s.set_integrator_option("iteratons", 4)
    with pytest.raises(KeyError):
        s.set_param("integrator_iteratons", 4)  # not a row of the panel


def test_the_rows_taken_follow_the_integrator():
    s = Session(seed("demo"))
    for name, rows in ROWS.items():
        s.set_integrator(name)  # every option back to the new integrator's defaults
        assert list(s.integrator_params()) == rows
        for p in integrator_params():
            value = s.get_param(p.name)
            option = p.name.removeprefix(INTEGRATOR_PREFIX)
            assert value == (make_integrator(name).options[option] if p.name in rows else None)


def test_xpbd_iterations_change_how_many_substeps_hold_the_bodies(tmp_path):
    p = tmp_path / "stand.toml"
    p.write_text('[physics]\ndt = 0.016666666666666666\nintegrator = "xpbd"\n'
                 '[[body]]\nshape = "box"\ncorners = [[-0.5, 0], [0.5, 0], [0.5, 1], [-0.5, 1]]\ndetail = 28\n'
                 '[[collider]]\ncenter = [0, -0.2]\nsize = [3, 0.4]\n')
    s = Session(str(p))
    assert s.note_is_warning and "raise substeps to 22" in s.note
    s.set_param("integrator_iterations", 30)  # more sweeps per substep carry the support further
    assert s.note_is_warning and "raise substeps to 4" in s.note


# -- the panel ----------------------------------------------------------------------------------
def shown_rows(ins):
    return [name for name in ROWS["implicit-euler"] + ROWS["symplectic-euler"] if ins.rows[name].label.visible]


def test_the_rows_follow_an_integrator_switch_in_the_panel(demo):
    ins = demo.inspector
    assert demo.session.integrator == "symplectic-euler"
    assert shown_rows(ins) == ["integrator_mode"]
    dt, stiffness = ins.rows["dt"], ins.rows["stiffness"].slider
    dt_top, menu_top = dt.label.relative_rect.top, ins.integrator_menu.relative_rect.top
    assert ins.rows["integrator_mode"].label.relative_rect.top == menu_top + ROW
    choose_from_menu(demo, ins.integrator_menu, "implicit-euler")
    assert demo.session.world.integrator == "implicit-euler"
    assert shown_rows(ins) == ROWS["implicit-euler"]
    assert [ins.rows[n].label.relative_rect.top for n in shown_rows(ins)] == [menu_top + k * ROW for k in (1, 2, 3, 4)]
    assert ins.rows["integrator_iterations"].entry.get_text() == "3"
    assert ins.rows["integrator_tolerance"].entry.get_text() == "0"
    assert ins.rows["integrator_max_iterations"].entry.get_text() == "500"
    assert ins.rows["integrator_contact_weight"].entry.get_text() == "10"
    assert not ins.rows["integrator_mode"].menu.is_enabled  # hidden rows take no clicks
    # what is below moved down by three rows, the same widgets
    assert dt.label.relative_rect.top == dt_top + 3 * ROW and ins.rows["stiffness"].slider is stiffness
    assert dt.slider.relative_rect.top == dt.label.relative_rect.top + 3
    choose_from_menu(demo, ins.integrator_menu, "xpbd")
    assert shown_rows(ins) == ["integrator_iterations"]
    assert ins.rows["integrator_iterations"].entry.get_text() == "1"  # xpbd's own default
    assert dt.label.relative_rect.top == dt_top
    demo.session.set_integrator("symplectic-euler")  # in code: the panel follows at its next frame
    run(demo, 1)
    assert shown_rows(ins) == ["integrator_mode"] and dt.label.relative_rect.top == dt_top


def test_typed_option_applies_and_a_bad_one_shows_one_line_and_changes_nothing(demo):
    ins = demo.inspector
    demo.session.set_integrator("implicit-euler")
    run(demo, 1)
    entry = ins.rows["integrator_iterations"].entry
    entry.set_text("6")
    post(pygame_gui.UI_TEXT_ENTRY_FINISHED, ui_element=entry, text="6")
    run(demo, 1)
    assert demo.session.world.integrator_options == {"iterations": 6, "tolerance": 0.0, "max_iterations": 500,
                                                    "contact_weight": 10.0}
    entry.set_text("0")
    post(pygame_gui.UI_TEXT_ENTRY_FINISHED, ui_element=entry, text="0")
    run(demo, 2)
    assert demo.session.world.integrator_options == {"iterations": 6, "tolerance": 0.0, "max_iterations": 500,
                                                    "contact_weight": 10.0}
    assert ins.message_is_error
    assert ins.message == "implicit-euler option iterations must be an integer in [1, 10000], got 0"
    assert entry.get_text() == "6"  # the box shows the value in force again
    weight = ins.rows["integrator_contact_weight"].entry
    weight.set_text("many")
    post(pygame_gui.UI_TEXT_ENTRY_FINISHED, ui_element=weight, text="many")
    run(demo, 2)
    assert ins.message_is_error and ins.message == "Contact weight must be a number, got 'many'"
    assert demo.session.world.integrator_options["contact_weight"] == 10.0


def test_the_mode_drop_down_picks_the_symplectic_driver(demo):
    ins = demo.inspector
    choose_from_menu(demo, ins.rows["integrator_mode"].menu, "serial")
    assert demo.session.world.integrator_options == {"mode": "serial"}
    assert ins.rows["integrator_mode"].menu.selected_option[0] == "serial"
    demo.session.set_integrator_option("mode", "parallel")  # set behind the menu: it follows
    run(demo, 1)
    assert ins.rows["integrator_mode"].menu.selected_option[0] == "parallel"


def test_a_loaded_scene_shows_its_integrator_options(demo, tmp_path):
    p = tmp_path / "xpbd.toml"
    p.write_text('[physics]\ndt = 0.005\nintegrator = "xpbd"\n\n[physics.integrator_options]\niterations = 4\n\n'
                 '[[body]]\nposition = [0.0, 1.0]\n\n[[collider]]\ncenter = [0.0, 0.0]\nsize = [6.0, 0.4]\n')
    demo.load(str(p))
    run(demo, 1)
    ins = demo.inspector
    assert shown_rows(ins) == ["integrator_iterations"]
    assert ins.rows["integrator_iterations"].entry.get_text() == "4"
    assert demo.session.world.integrator_options == {"iterations": 4}

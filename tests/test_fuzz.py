"""Fuzz: hostile scene values and small random pictures get a clear one-line error or a
sound result, never another exception (issue 17: the next class of bad input is found by the
suite, not by a user)."""

import math

import numpy as np
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import deforma
from deforma.physics.elements.triangles import signed_areas
from deforma.scene.build import build
from deforma.scene.schema import SceneError, parse_scene

PHYSICS_KEYS = ["dt", "substeps", "gravity", "damping", "mass", "stiffness", "friction", "static_friction",
                "max_speed", "integrator", "contact_thickness", "air_drag", "material", "youngs_modulus",
                "poisson_ratio", "density", "material_damping", "tear_strain", "yield_strain", "plastic_rate",
                "max_stretch"]
BODY_KEYS = ["mass", "stiffness", "damping", "tear_strain", "yield_strain", "max_stretch", "pressure", "collide",
             "self_collision", "friction", "pin", "detail", "edges", "position", "corners"]
COLLIDER_KEYS = ["center", "size", "angle", "friction"]

hostile = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**20, 10**20),
                    st.sampled_from([0, -1, 1e-300, 1e300, 1e-7, 2, 10**9]), st.booleans(), st.text(max_size=6))
sane = st.one_of(st.floats(1e-3, 1e3), st.integers(1, 12), st.sampled_from([0.0, 0.3, 0.5, 1.05, 1 / 600]))
pairs = st.lists(st.one_of(sane, st.floats(-5, 5)), min_size=2, max_size=2)
names = st.sampled_from(["springs", "corotated", "neo-hookean", "xpbd", "implicit-euler", "symplectic-euler"])
PAIR_KEYS = {"gravity", "position", "center", "size"}
NAME_KEYS = {"integrator", "material"}
SWITCH_KEYS = {"collide", "self_collision", "edges"}


@st.composite
def settings_for(draw, keys, most):
    """Up to ``most`` of ``keys``, each with a value of its kind, or (one time in four) a hostile one."""
    out = {}
    for key in draw(st.lists(st.sampled_from(keys), max_size=most, unique=True)):
        if draw(st.integers(0, 3)) == 0:
            out[key] = draw(st.one_of(hostile, st.lists(hostile, max_size=3)))
        elif key in PAIR_KEYS:
            out[key] = draw(pairs)
        elif key in NAME_KEYS:
            out[key] = draw(names)
        elif key in SWITCH_KEYS:
            out[key] = draw(st.booleans())
        else:
            out[key] = draw(sane)
    return out


def one_line(e: Exception) -> None:
    text = str(e)
    assert text and "\n" not in text and "Traceback" not in text, text


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(physics=settings_for(PHYSICS_KEYS, 3), body=settings_for(BODY_KEYS, 2),
       collider=settings_for(COLLIDER_KEYS, 1))
def test_hostile_scene_values_are_refused_in_one_line_or_run(physics, body, collider):
    data = {"physics": physics, "body": [{"shape": "box", "detail": 2, **body}],
            "collider": [{"center": [0.0, -0.5], "size": [4.0, 1.0], **collider}]}
    try:
        scene = parse_scene(data, source="fuzz.toml")
    except SceneError as e:
        event("refused by the loader")
        one_line(e)
        return
    try:
        world = build(scene)
    except ValueError as e:  # checks that need the built bodies (overlaps, meshes)
        event("refused when built")
        one_line(e)
        return
    try:
        for _ in range(5):
            world.step()
    except deforma.SimulationUnstable as e:
        event("reported unstable")
        one_line(e)
        assert e.hint and np.isfinite(world.state.x).all()  # put back as it was
        return
    event("ran")
    assert np.isfinite(world.state.x).all()


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(1, 8), st.integers(1, 8), st.integers(1, 6), st.integers(0, 2**32 - 1), st.floats(0.05, 0.95),
       st.sampled_from(["black", "white", "auto"]))
def test_small_random_pictures_mesh_into_a_manifold_or_a_clear_error(h, w, cell, seed, fill, background):
    # random blocks of cell x cell pixels: blobs, bars, holes, pinches and specks
    rng = np.random.default_rng(seed)
    ink = np.kron(rng.random((h, w)) < fill, np.ones((cell, cell), bool))
    ink = np.pad(ink, 1)  # a border of background (a picture whose border is ink is its own case)
    base, pen = (255, 0) if background == "white" else (0, 255)
    grey = np.where(ink, pen, base).astype(np.uint8)
    rgb = np.repeat(grey[:, :, None], 3, axis=2)
    try:
        m = deforma.mesh.from_image(rgb, resolution=1, scale=0.01, background=background)
    except ValueError as e:
        event("picture refused")
        one_line(e)
        return
    event("meshed")
    t = m.triangles
    assert (signed_areas(m.vertices, t) > 0).all()
    # every edge in one or two triangles; every boundary vertex on exactly one outline run
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    assert counts.max() <= 2
    b = m.boundary_edges
    assert np.array_equal(np.bincount(b[:, 0], minlength=len(m.vertices)),
                          np.bincount(b[:, 1], minlength=len(m.vertices)))
    assert np.bincount(b[:, 0], minlength=len(m.vertices)).max() <= 1
    assert math.isfinite(m.area) and m.area > 0

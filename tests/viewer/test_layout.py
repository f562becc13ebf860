"""The viewer's layout: every scene framed in the area the panel and the status line leave, and
an invisible window refused rather than run until killed (issue 50)."""

import os
import subprocess
import sys

import numpy as np
import pygame
import pytest

from deforma.scene.assets import builtin_scenes
from deforma.viewer.app import STATUS_MARGIN


def outline_pixels(v):
    """Window pixels of every collider's outline and of every body's vertices, as two arrays."""
    s = v.session
    colliders = np.concatenate([c.outline(96) for c in s.world.colliders]) if s.world.colliders else np.zeros((0, 2))
    bodies = np.concatenate([b.positions for b in s.world.bodies])
    return np.array([v.to_pixel(p) for p in colliders]).reshape(-1, 2), np.array([v.to_pixel(p) for p in bodies])


def inside(px, rect, *, rows_only=False):
    left, top, right, bottom = rect
    ok = (px[:, 1] >= top - 0.5) & (px[:, 1] <= bottom + 0.5)
    if not rows_only:
        ok &= (px[:, 0] >= left - 0.5) & (px[:, 0] <= right + 0.5)
    return ok


@pytest.mark.parametrize("name", sorted(builtin_scenes()))
def test_every_scene_is_framed_whole_beside_the_panel_and_above_the_status_line(viewer, name):
    viewer.load(name)
    viewer.help_visible = False
    pygame.event.clear()
    follows = viewer.session.follow is not None
    for panel in (True, False):
        viewer.panel_visible = panel
        viewer.frame(0.0)  # draws without stepping: the scene as it starts
        rect = viewer.free_rect()
        w, h = viewer.world_size
        # the status line lies below the free area, the free area left of the panel
        status_top = viewer.window_size[1] - viewer.status_layer.size[1] - STATUS_MARGIN
        assert rect[3] < status_top and rect[2] < w and rect[1] > 0 and rect[0] > 0
        colliders, bodies = outline_pixels(viewer)
        assert inside(bodies, rect).all(), f"{name} (panel {panel}): a body is outside {rect}"
        # a camera that follows a body is a side-scroller: its level runs on past the sides
        ok = inside(colliders, rect, rows_only=follows)
        assert ok.all(), f"{name} (panel {panel}): collider points {colliders[~ok][:3]} outside {rect}"


def test_zoom_and_pan_still_move_the_framed_camera(demo):
    before = demo.renderer.camera
    demo.pointer = (300, 300)
    at = demo.to_world(demo.pointer)
    demo._zoom(2)  # two wheel clicks in, about the pointer
    demo.frame(0.0)
    assert demo.renderer.camera.size[0] < before.size[0]
    np.testing.assert_allclose(demo.to_world(demo.pointer), at, atol=1e-9)  # the point under it stays


def display_env(tmp_path, **extra):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER")}
    # libwayland's probe says a line of its own without a runtime folder; a person's session has one
    env.update(XDG_RUNTIME_DIR=str(tmp_path), **extra)
    return env


@pytest.mark.parametrize("variables", [{"DISPLAY": ":4242"}, {"SDL_VIDEODRIVER": "x11,offscreen"}],
                         ids=["no-x-server", "driver-list"])
def test_view_that_falls_back_to_an_invisible_window_stops_with_one_line(tmp_path, variables):
    # the environment names a display, none opens, and SDL falls back to its off-screen driver
    # without a word: that window ran until it was killed
    r = subprocess.run([sys.executable, "-m", "deforma.cli", "view", "demo"], capture_output=True, text=True,
                       env=display_env(tmp_path, **variables), timeout=60)
    assert r.returncode == 4 and r.stderr.count("\n") == 1, r.stderr
    assert "--frames N" in r.stderr and "deforma run" in r.stderr and "offscreen" in r.stderr

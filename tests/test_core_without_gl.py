"""The core (meshes, physics, scenes) must import and run with no GL or window package."""

import subprocess
import sys
import textwrap


def test_core_runs_with_gl_and_window_packages_blocked():
    code = textwrap.dedent(
        """
        import sys
        # a None entry makes "import X" raise ImportError, as if X were not installed
        for name in ("moderngl", "glcontext", "pygame", "pygame_gui", "imageio", "imageio_ffmpeg"):
            sys.modules[name] = None
        import numpy as np
        import deforma
        tris = deforma.delaunay(np.random.default_rng(0).random((100, 2)))
        m = deforma.mesh.from_image("donut", resolution=16)
        world = deforma.load_scene("sample")
        world.step()
        loaded = [k for k in sys.modules if k.split(".")[0] in ("moderngl", "pygame", "pygame_gui")
                  and sys.modules[k] is not None]
        assert not loaded, loaded
        print("ok", len(tris), len(m.triangles))
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("ok")

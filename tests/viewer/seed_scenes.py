"""Built-in scenes as the seed shipped them: the original's springs under symplectic Euler.

Several viewer tests are about springs, substeps and the explicit integrator's limits (a
stiffness raised past the stable step, the hint, the integrator drop-down); the shipped
``demo`` and ``sample`` are now finite elements, so those tests run on these instead.
"""

from dataclasses import replace

from deforma import scene as scenes

_SUBSTEPS = {"demo": 6, "sample": 4}
_DT = 1 / 600  # s: the seed's step (the shipped scenes now take the default, 1/60 s)


def seed(name: str):
    """The built-in scene ``name`` with springs, symplectic Euler and the seed's step and substeps."""
    s = scenes.with_springs(scenes.load(name))
    return replace(s, physics=replace(s.physics, integrator="symplectic-euler", dt=_DT, substeps=_SUBSTEPS[name]))

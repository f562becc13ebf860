"""The material behaviours that run around a step: gas pressure before it, the stretch limit
and plasticity after it (tearing, which changes a body's mesh, is the World's:
:mod:`deforma.physics.behaviours.tearing`).

Each reads the bodies' materials from the :class:`~deforma.physics.model.Model` and works on
the body's own slice of the arrays, so a world whose materials have none of them pays one
check per body per step.
"""

from __future__ import annotations

from .plasticity import yield_elements, yield_springs
from .pressure import pressure_kick
from .strain_limit import project_stretch

#: The stretch limit stops when no constraint is more than this (strain) over.
LIMIT_TOLERANCE = 1e-4


def apply_pressure(model, state, dt: float) -> bool:
    """Kick the velocities of the bodies that hold a gas by ``dt`` of its force; True if any."""
    any_gas = False
    for b in range(len(model.topologies)):
        p = model.body_pressure[b]
        if p <= 0.0:
            continue
        any_gas = True
        e0, e1 = model.body_pressure_offsets[b], model.body_pressure_offsets[b + 1]
        pressure_kick(state.x, state.v, model.vertex_inv_mass, model.pressure_a[e0:e1], model.pressure_b[e0:e1],
                      float(p), float(model.body_pressure_area[b]), float(dt))
    return any_gas


def limit_and_yield(model, state_in, state_out, dt: float) -> None:
    """After a step of ``dt`` s from ``state_in`` to ``state_out``: limit each body's stretch
    (in ``state_out``), then let its plastic strain flow (in the Model's rest shape)."""
    for b, mat in enumerate(model.materials):
        if mat is None or (mat.max_stretch is None and mat.yield_strain is None):
            continue
        s0, s1 = model.body_spring_offsets[b], model.body_spring_offsets[b + 1]
        t0, t1 = model.body_elem_offsets[b], model.body_elem_offsets[b + 1]
        if mat.max_stretch is not None:
            v0, v1 = model.body_vertex_offsets[b], model.body_vertex_offsets[b + 1]
            anchors = model.attachments(b) if model.pinned[v0:v1].any() else None
            project_stretch(state_out.x[v0:v1], state_out.v[v0:v1], state_in.x[v0:v1], model.vertex_inv_mass[v0:v1],
                            model.spring_i[s0:s1] - v0, model.spring_j[s0:s1] - v0, model.spring_rest_length[s0:s1],
                            model.elem[t0:t1] - v0, model.elem_b[t0:t1], mat.max_stretch, dt, anchors=anchors,
                            tolerance=LIMIT_TOLERANCE)
        if mat.yield_strain is not None:
            if s1 > s0:
                yield_springs(state_out.x, model.spring_i[s0:s1], model.spring_j[s0:s1],
                              model.spring_rest_length[s0:s1],
                              model.spring_rest_length0[s0:s1], mat.yield_strain, mat.plastic_rate)
            if t1 > t0 and yield_elements(state_out.x, model.elem[t0:t1], model.elem_b[t0:t1], model.elem_area[t0:t1],
                                          model.elem_b0[t0:t1], model.elem_area0[t0:t1], mat.yield_strain,
                                          mat.plastic_rate):
                model.version += 1

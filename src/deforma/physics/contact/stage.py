"""The contact stage, once per substep: collide, solve, verify, fail-safe, colliders last
(steps 0-5 of :mod:`deforma.physics.contact`).
"""

from __future__ import annotations

from numba import njit

from .broad_phase import index_pairs
from .contacts import CONTACT_ITERATIONS, VERIFY_ROUNDS
from .failsafe import impact_zones
from .narrow_phase import check_pairs, collide_outlines, refresh_pairs
from .response import collider_pass, solve_contacts


@njit(cache=True)
def contact_stage(x, v, inv_mass, topo, scr, out, rects, hits, h, follow=True):
    """Collide, solve and verify the body contacts of one substep (see the module docstring).

    Call it after the integrator has moved the vertices, with ``scr.xp`` holding the
    collision vertices' positions at the start of the substep (:func:`gather_start`).
    Updates ``x`` and ``v`` in place. Returns the number of contacts found, or -1 if
    ``out`` was too small (``scr.status.needed[0]`` / ``[ST_PAIRS_NEEDED]`` then say how
    many are needed; the substep is incomplete).

    ``follow`` (default True): a velocity impulse also moves its three vertices by ``h``
    times their velocity change, as if it had acted before the substep's positions were
    updated (symplectic Euler's order; a stuck vertex then does not creep). Implicit Euler
    passes False: it solves for the positions of the whole body at once, contacts included,
    and derives velocities from them, so moving the contact's vertices alone, after its
    solve, displaced them from the rest of their body by up to the substep's approach (7 cm
    for two bodies meeting at 5 m/s at 1/60 s, which folded them and raised the energy from
    6.3 J to 50 J); without it the impulse changes only their velocities, and the next solve
    carries the change through the body.
    """
    status = scr.status
    status.stamp[0] += 1
    status.contacts[0] = 0
    status.pairs[0] = 0
    status.dirty[0] = 0
    status.touched[0] = 0
    n0, n_pairs = collide_outlines(x, topo, scr, out)
    if n0 < 0:
        return -1
    status.contacts[0] = n0
    status.pairs[0] = n_pairs
    if n0 == 0:
        return 0  # no contact and no crossing (a crossing is a contact too): nothing moved
    index_pairs(topo, scr, out, n_pairs)
    solve_contacts(x, v, inv_mass, topo, scr, out, 0, n0, rects, h, CONTACT_ITERATIONS, follow)
    end, n_pairs = _verify(x, v, inv_mass, topo, scr, out, n0, n_pairs, rects, h, follow)
    if end < 0:
        return -1
    # colliders have the last word (infinite mass): put back outside any vertex the response
    # pushed into one, then make sure that opened no crossing (a zone that would enter a
    # collider stays where it started, outside)
    if collider_pass(x, v, topo, scr, rects, hits, h):
        r = impact_zones(x, v, inv_mass, topo, scr, out, end, n_pairs, rects, h)
        if r < 0:
            return -1
        if r > 0:
            status.failsafe[0] += 1
    return n0


@njit(cache=True)
def _verify(x, v, inv_mass, topo, scr, out, n0, n_pairs, rects, h, follow):
    """Step 4 of the module docstring; returns the end of the contacts stored (-1 if they did
    not fit) and the number of candidate pairs (which a rebuilt grid changes)."""
    status = scr.status
    margin = topo.margin[0]
    # Crossings left after the solve are solved again, together with those of earlier rounds:
    # two that hold each other (each corner against the other's edge) converge only together.
    end = n0
    for _ in range(VERIFY_ROUNDS):
        n_pairs, rebuilt = refresh_pairs(x, topo, scr, out, margin, n_pairs)
        if n_pairs < 0:
            status.pairs_needed[0] = -n_pairs
            return -1, n_pairs
        n = check_pairs(x, topo, scr, out, end, n_pairs, rebuilt, True)
        if n < 0:
            status.needed[0] = -n
            return -1, n_pairs
        if n == end:
            return end, n_pairs
        end = n
        solve_contacts(x, v, inv_mass, topo, scr, out, n0, end, rects, h, CONTACT_ITERATIONS, follow)
    r = impact_zones(x, v, inv_mass, topo, scr, out, end, n_pairs, rects, h)
    if r < 0:
        return -1, n_pairs
    if r > 0:
        status.failsafe[0] += 1
    return end, n_pairs

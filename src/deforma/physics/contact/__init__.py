"""Body-body and self contacts: collide (broad + narrow phase), then solve, then make sure.

One module per stage: :mod:`~deforma.physics.contact.contacts` (the data),
:mod:`~deforma.physics.contact.broad_phase` (steps 0-1), :mod:`~deforma.physics.contact.narrow_phase`
(step 2), :mod:`~deforma.physics.contact.response` (step 3), :mod:`~deforma.physics.contact.failsafe`
(step 4), :mod:`~deforma.physics.contact.stage` (the stage in order), :mod:`~deforma.physics.contact.friction`
(the Coulomb rule every contact uses) and :mod:`~deforma.physics.contact.clearance` (outlines at rest).

Every body with triangles has an *outline*: the mesh edges used by one triangle, directed so
that the body is on their left (outer outlines counter-clockwise, holes clockwise). A
contact is a vertex ``p`` against an outline edge ``(a, b)``: an outline vertex against the
outline of another body, or of its own body (self contact) if ``p`` is not one of the
edge's ends; and a vertex off the outline against another body's outline, where its body
is folded (below). The stage runs once per substep, after the integrator has moved every
vertex from ``x_prev`` to ``x``; the motion in between is taken as a straight line.

0. **Which vertices.** Every outline vertex of a body with contacts on; and, of a colliding
   body, every other vertex whose swept box meets another colliding body's. Self contact
   keeps an outline from crossing itself, and a body whose triangles all keep their
   orientation lies inside its outline, so only a folded body can carry a vertex off its
   outline into another body; but a folded flap carries vertices of triangles that are not
   turned over too, and the response can fold a body after the test, so all such vertices
   are tested (measured: testing only the vertices of turned-over triangles let the `pile`
   at 1/60 s x 2 put a vertex inside another body within 2 s). They get a hair of
   thickness, so their contacts are crossings only.
1. **Broad phase.** The swept box of every outline edge (its ends at both times, grown by
   a margin: ``SPECULATIVE`` times the largest contact thickness) goes into a uniform grid
   hashed into a table twice as long as there are edges, with cells about the mean box
   size. Each vertex looks up the cells its own swept box (grown the same way by its own
   thickness) covers; a pair is listed once, in the cell of the low corner of the two
   boxes' overlap. Built anew every substep: linear in the number of outline vertices, and
   nothing can go stale. (Keeping the pairs over several substeps in boxes grown by a
   slack, as Box2D's fat boxes do, was measured and dropped: a heap of 200 bodies always
   has a vertex that leaves its slack within a substep or two, and the stage per body grew
   4x from the extra pairs.)
2. **Narrow phase.** ``d`` is the signed distance of ``p`` from the edge's line (positive in
   front, outside the edge's body) and ``s`` where its foot lies on the edge (0 at ``a``,
   1 at ``b``), at the start (``d0``) and end (``d1``, ``s1``) of the substep. The side
   ``p`` starts on is the exact sign of ``d0``. A pair is a contact if ``p`` started in
   front and ended within ``SPECULATIVE`` thicknesses in front, with its foot on the segment
   (``PROXIMITY``), or if its straight-line motion crossed the segment itself
   (``CROSSING``: continuous collision detection; the time at which ``p`` and the moving
   edge are collinear is a root of a quadratic, found by bisection on its sign change, and
   ``s`` at that time must lie in [0, 1]; a point on the same side at both ends may still
   have crossed twice, which the quadratic's extremum tells, and the first of the two
   crossings that passes through the segment counts). Pairs are watched from both sides:
   bodies start apart (the world refuses an overlap), so a vertex behind an edge lies
   beyond a part of that edge's body (across a thin limb, or a folded flap whose outline
   runs backwards) and must stay there. Two outlines use the larger of their
   bodies' thicknesses, so that both sides of a pair agree on the gap.
3. **Solve** (Gauss-Seidel over the contacts). Velocities first, once: the relative
   velocity ``v_p - (1 - s) v_a - s v_b`` may approach the edge by what is left of the gap
   to the target in the next substep, no more (a *speculative* contact: a loaded pair's
   support never lapses, where it would pop out and back in); the excess goes, with
   Coulomb friction (:func:`deforma.physics.contact.friction.coulomb`, the rule colliders use),
   through one impulse split by inverse mass (``w_p``, ``(1 - s) w_a``, ``s w_b``), so that
   linear momentum is kept exactly. Every vertex also moves by ``h`` times its velocity
   change, so that a stuck vertex does not creep (the collider response's rule; not under
   implicit Euler, see :func:`contact_stage`). Then
   positions, in ``CONTACT_ITERATIONS`` sweeps: a vertex closer than its target is pushed
   out to it, split by inverse mass the same way (positions only: no velocity, no
   momentum). A vertex this moves into (or through) a collider meets the collider at once
   (:func:`~deforma.physics.colliders.response.collide_point`; colliders have infinite mass). A
   proximity contact's target is the thickness. A crossing goes back to the distance it
   started at, at most the thickness (and a hair off the line): every pair had its start
   distance at once, so these targets never contradict each other, while two corners that
   meet level cannot both be a thickness in front of the other's edge.
4. **Verify.** Crossings are looked for again, among the candidate pairs of the vertices
   the response moved (a pair it left alone keeps its answer; a vertex-to-pair index finds
   them, so the work follows what moved, not the size of the world); a vertex moved
   further than the margin rebuilds the grid first. Crossings found are solved together
   with those of earlier rounds (two that hold each other converge only together), up to
   ``VERIFY_ROUNDS`` times. Then a fail-safe makes the result crossing-free for sure:
   *impact zones* (Bridson, Fedkiw and Anderson 2002, with translations only). The
   vertices of each remaining crossing merge into a zone that moves as one rigid
   translation from its start positions at its mass-weighted mean velocity (linear
   momentum kept); zones grow until no crossing is left. The start of the substep had none
   and a translated zone keeps its members' relative positions, so this ends. A zone that
   the translation would push into (or through) a collider stays where it started. It is
   needed where the response cannot converge, e.g. a vertex at the tip of an outline
   crushed into a hairpin, which would have to be in front of both faces at once.
5. **Colliders last.** Every vertex the stage moved and left in or through a collider gets
   the collider response, and if that moved any, the check and fail-safe of step 4 run
   again on what it moved.

What is guaranteed: if no outline crossed another or itself and no vertex lay inside
another body at the start of a substep, the same holds at its end (tested at every step of
the 10 s ``pile`` scene by ``tests/physics/contact_checks.py``, which is independent of this
module).

The contact thickness keeps resting bodies a hair apart, so resting contact is found by the
cheap proximity test and the crossing test is the exception.

Everything here is a pure kernel over arrays; :class:`ContactTopology`,
:class:`ContactScratch` and :class:`ContactBuffer` are namedtuples of arrays that
:class:`~deforma.physics.model.Model`, the world and the integrators own. Units: m, m/s, kg.
"""

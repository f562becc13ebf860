"""Rigid bodies: ``deforma.Material("rigid", density=...)`` on any mesh.

A rigid body keeps its mesh (drawn, exported and grabbed as any body's) but moves as one:
three degrees of freedom, a position and an angle, with the mass, centre of mass and moment
of inertia of its triangles at its density. Its state is its vertices' (``State.x``,
``State.v``): the pose and velocity are read back from them each step (exact, as they move
rigidly), so a failed step's undo, recordings and every reader of positions need nothing new.

Under ``avbd`` (the default), a rigid body is instead one block of the integrator's own
sweep (:mod:`deforma.physics.integrators.avbd.rigid`), its outline a contact outline like
any body's and its joints rows of the sweep (:mod:`deforma.physics.integrators.avbd.joints`);
what follows is the path of the other integrators.

One soft substep, then the rigid stage over it (:func:`~deforma.physics.stepper.step` runs
them in turn, so a soft body never meets an outline that stood still for a whole step):

1. Before the step the World packs each rigid body's outline as a moving polygon collider
   (:mod:`~deforma.physics.rigid.bodies`) with the body's velocity, spin, 1/mass and
   1/inertia. The soft integrators hold the rigid body's own vertices (infinite mass there).
2. Soft vertices that end a substep inside an outline are put out of it one at a time by
   :func:`~deforma.physics.colliders.response.collide_dynamic`: the impulse between the two
   masses (the vertex's and the body's, at the surface point), friction by the colliders'
   Coulomb rule; the body's packed velocity takes its share at once, so the next vertex
   meets it moving. Every change a rigid outline makes to a soft vertex (corners pushed
   through outline edges too) is summed in ``ColliderHits.dv`` and ``.dm`` (the vertex's
   ``x cross v`` change about the origin).
3. The rigid solver (:mod:`~deforma.physics.rigid.solver`) then advances the rigid bodies
   over the substep from where they started it: gravity, applied forces, grabs and the
   opposite of those impulses (linear and angular momentum kept exactly); contacts of
   their outline vertices with colliders and with other rigid bodies' outlines, solved by
   sequential impulses (accumulated and clamped, warm-started, Coulomb friction with
   static and dynamic coefficients), and the overlap left removed by a position
   projection. Its own substeps are at most ``RIGID_SUBSTEP`` (1/240 s), ``JOINT_SUBSTEP``
   (1/960 s) with joints (:mod:`~deforma.physics.rigid.joints`: pins, welds, springs
   between rigid bodies or to the world, solved in the same passes).

Implicit Euler holds the soft vertices headed into an outline inside its solve, the outline
moving with the velocity the body will have once they stick to it, and gives each plane's
force back to the body (:func:`~deforma.physics.integrators.implicit.solver.recoil_planes`,
:func:`~deforma.physics.integrators.implicit.solver.rigid_plane_impulses`).

Measured (``tests/physics/test_rigid.py``): a soft ball into a crate of 1.6 to 160 kg
keeps linear momentum to 1e-9 under symplectic Euler, implicit Euler and XPBD, angular
momentum to 1e-14 under symplectic Euler (backward Euler loses a few percent of any spin:
it is not a property of the coupling), and the total energy never rises under symplectic
Euler; implicit Euler gains 5.5 % with the 1.6 kg crate and 0.6 % with the 160 kg one, XPBD
2 % with the heaviest, and BDF2's velocity, read from the position history, loses 10 % of
the momentum a contact moves.
"""

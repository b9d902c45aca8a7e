"""Paper 003: the screw-nut connection, in vector form, with dry friction in the thread.

Two rigid bodies are joined by a screw pair (SPEC section 10): body 1 carries
the screw, body 2 the nut. The joint's parameters are constant in body 1's
frame: a point ``P`` on the screw axis, the axis direction ``c`` (unit
vector) and the lead per radian ``h = lead / (2 pi)`` (m/rad). The paper's
equations, written as vectors (world frame, ``w = w2 - w1`` the relative
angular velocity):

* the relative angular velocity lies along the axis:
  ``w - (c . w) c = 0``;
* the nut's point at ``P`` moves along the axis by the lead:
  ``(v2 + w2 x r2) - (v1 + w1 x r1) = h (c . w) c`` with ``r1``, ``r2`` the
  radius vectors from each body's centre of mass to ``P``;
* the reaction force ``F`` (on the nut; ``-F`` on the screw) creates the
  moments ``r2 x F`` and ``-r1 x F``, a reaction moment perpendicular to the
  axis acts on each body, and the axial force gives the torque
  ``M_a = h (c . F)`` about the axis -- the pair converts axial force to
  torque through the lead.

Both defects the paper names are avoided here. (1) The paper picks two of the
three angular-velocity components by dividing by the direction cosine
``c_x``; here the two conditions are the projections of ``w`` on a pair of
unit vectors ``e1, e2`` perpendicular to ``c`` and fixed in body 1 (chosen
once by cross products, never by dividing by a component), so any axis
direction works. (2) The paper's equations are velocity-level only, so body
positions drift apart over long runs; here the same five conditions are also
imposed at position level (axis alignment, the nut's point on the axis,
axial offset ``= h`` times the relative angle) and
:class:`~wire_fmu.core.components.screw_nut.system.ScrewNutSystem` projects
positions and velocities back onto them after every step.

Dry friction in the thread (paper 003, section 4)
-------------------------------------------------
A torque about the axis, opposing relative rotation, bounded by
``M1 = r_mean mu |F_axial|`` (the paper: mean thread radius 0.01 m, mu 0.1
for steel on steel). The paper regularises it: linear in the relative
speed inside ``|w| < w1`` (``w1 = 1e-6`` rad/s) and saturated outside.
Such a torque never truly holds: a held load creeps at the speed where the
regularised torque balances it, ``w1 x`` for the linear form and
``w1 atanh(x)`` for the ``tanh`` form, ``x = |M_load| / M1``
(:meth:`~wire_fmu.core.components.screw_nut.thread.ScrewThread.creep_speed`).
:class:`~wire_fmu.core.components.screw_nut.thread.ScrewThread` offers both
regularised forms; the exact one (a stuck thread does not move at all) is
used twice: by :class:`~wire_fmu.core.components.screw_nut.system.ScrewNutSystem`
in 3-D, where a stuck thread adds a sixth constraint and a sliding one a
torque solved together with the axial force it depends on, and -- along
the joint's one degree of freedom, the relative angle -- with
:class:`~wire_fmu.core.components.friction.StickSlip` by the scissor jack's
kinematic reduction (:mod:`wire_fmu.core.units.scissor_jack.model`).

Modules
-------
:mod:`~wire_fmu.core.components.screw_nut.thread`
    The thread: lead, dry friction and its regularised forms.
:mod:`~wire_fmu.core.components.screw_nut.bodies`
    Rigid bodies, their states and the quaternion helpers.
:mod:`~wire_fmu.core.components.screw_nut.joint`
    The screw pair's five constraints, their Jacobian and reactions.
:mod:`~wire_fmu.core.components.screw_nut.system`
    Two bodies joined by the pair, stepped in time with thread friction.
"""

"""Hydraulic cylinder with a gas accumulator: the hydro-pneumatic spring (SPEC section 11).

One cylinder chamber is filled with oil and connected through a line to an
accumulator whose gas side joins a bank of air pressure vessels; the other
side of the piston is vented to ambient. Gas pressure pushes the piston
through the oil: this is the near-constant-force spring of a riser tensioner
or passive heave compensator (paper 000, Fig. 6). The paper gives no
hydraulic equations; everything here is **ours**.

Coordinates and signs
---------------------
``x`` (m) is the rod's extension from fully retracted (``0 <= x <= stroke``),
``v = dx/dt`` (m/s). The external force on the rod, ``force`` (N), acts
along the extension direction (positive pushes the rod out). The
*pressurised side* is either the ``bore`` (push cylinder: gas pushes the rod
out, working area ``A = pi D^2/4``) or the ``annulus`` (pull cylinder: gas
pulls the rod in, ``A = pi (D^2 - d^2)/4``); ``s = +1`` or ``-1`` is the
direction in which the oil force pushes the rod. The chamber volume is
``V_c = V_dead + A x`` (bore) or ``V_dead + A (stroke - x)`` (annulus), so
it grows by ``s A v``. The line flow ``q`` (m^3/s) is positive from the
accumulator to the cylinder; the gas volume grows by ``q``.

Equations (every effect absent)
-------------------------------
``m dv/dt = force + s A (p_c - p_amb) + m g_rod``, with the chamber pressure
``p_c`` equal to the gas pressure ``p_g(V_g)`` of :class:`~.gas.PolytropicGas`
and the gas volume ``V_g = V_g0 + s A (x - x0)`` (incompressible oil). The
vented side and the outer end of the rod see ambient pressure ``p_amb``,
hence the gauge pressure in the force; ``g_rod`` is the component of
gravity along the extension direction. States: ``x, v``.

Effects (SPEC section 12, hydraulics rows)
------------------------------------------
========================  ===================================================
``polytropic_gas``        ``p V^n = const`` with ``n = polytropic_exponent``
                          (1.4: adiabatic) instead of isothermal ``n = 1``
``line_losses``           ``p_g - p_c = R_l q + R_t q|q|`` (laminar + turbulent,
                          :class:`~.hydraulic_line.HydraulicLine`)
``line_inertance``        ``L dq/dt`` of the oil in the line. With
                          incompressible oil ``q = s A v`` and the column adds
                          the mass ``L A^2`` to the rod (no state); with
                          compressible oil ``q`` is a state
``oil_compressibility``   the oil column is a linear hydraulic capacitance
                          ``C = V_oil / K`` (``K`` bulk modulus): states
                          ``V_g`` and, when a line element separates chamber
                          and accumulator, ``p_c`` with
                          ``C dp_c/dt = q - s A v``
``seal_friction``         Coulomb + viscous (+ Stribeck) seal friction that
                          really sticks (:class:`~.friction.StickSlip`)
``end_stops``             a quadratic hydraulic cushion over the last
                          ``cushion_length`` at each end, then a stiff
                          unilateral spring-damper stop; without it leaving
                          the stroke refuses the step
========================  ===================================================

Oil compressibility, modelling choice
-------------------------------------
The compliance ``C = V_oil / K`` is taken constant, with ``V_oil`` the oil in
the chamber at the initial position plus the line (a linear oil column about
the working point). With a compliance that varied with ``x`` the stored
energy ``C p^2 / 2`` would not be a state function of ``(x, p)``: an
energy-consistent variable compliance makes the piston pressure differ from
the line pressure by ``p^2/(2K)`` (about 0.5 % at 15 MPa), so that chamber
and gas pressures would disagree at rest. The constant compliance keeps
them equal at rest and closes the ledger exactly; it misses how the oil
column stiffens as the chamber empties, which matters only far above the
gas-spring frequency. Without a line element (no losses, no inertance) the
chamber and the accumulator share one pressure and the oil compliance acts
in parallel with the gas's: ``dV_g/dt = s A v C_g / (C_g + C)``.

End stops
---------
*Cushion*: inside the last ``cushion_length`` of the stroke at either end a
spear throttles the oil leaving the cushion pocket, ``F = -c v|v|`` while the
rod moves towards that end (free flow through the check valve the other
way, so the force is ``c max(v, 0)^2``: continuous in ``v``). Alone it gives
``m v dv/dx = -c v^2``, i.e. ``v(x) = v0 exp(-c x / m)``. Entering or
leaving a cushion zone is a mode change (the force jumps).

*Stop*: a spring ``k`` with a dashpot ``c_s`` that only pushes. Contact is a
mode, exactly like the block train's floor: it begins when the rod reaches
the stop (located, so the rod never tunnels through it at any step size)
and ends when the contact force ``k delta + c_s d(delta)/dt`` falls to zero,
after which the unloaded pad relaxes and its strain energy is booked as
dissipated. For this force-release linear dashpot the coefficient of
restitution of a free rod is ``e = exp(-2 zeta arccos(zeta) / sqrt(1 -
zeta^2))`` (Schwager and Poeschel, Granular Matter 9 (2007) 465; continued
with ``arccosh`` for ``zeta > 1``); ``c_s = 2 zeta sqrt(k m)`` is derived from
the set restitution by inverting it (:func:`damping_ratio_for_restitution`).

Limits that refuse a step (FMI discard)
---------------------------------------
Gas volume reaching its dead volume (the accumulator is full of oil: the gas
cannot be compressed further), gas volume reaching the empty-accumulator
volume (no oil left to supply the cylinder), chamber pressure falling to the
cavitation pressure, and (without end stops) the rod leaving its stroke.
Each is a guard located within the step; the step is refused there, so no
volume ever goes negative and nothing becomes NaN.

Numerics
--------
Every mode (seal stuck or sliding, rod on a stop or not, inside a cushion
zone or not) has a smooth right-hand side; mode changes are guards located
by :mod:`.hybrid`, and so is the kink where a relaxing stop pad reaches zero
depth (a direction-0 guard that changes no mode). The fixed-step solvers
(``ros2``, ``rk4``) step at ``solver_max_step`` except where the physics is
much faster: during a stop impact (for two contact periods or five decay
times after contact begins) they step at ``0.02 / omega`` with
``omega = sqrt(k / m)``, and while the rod runs into a cushion at speed
``v`` at ``0.03 m / (c v)``; the integration is restarted at the located
event and in fixed pieces, so the result is still a function of the state
and the communication step only (bit-reproducible). Restitution and the
cushion law are then met to about 0.1 % whatever ``solver_max_step`` is.
The adaptive SciPy solvers need none of this.

The equations run compiled (:mod:`.kernel`, numba) for every effect set unless
``WIRE_FMU_KERNEL=python``; the Python model stays the reference, and events,
their messages and the refused steps' reasons stay in Python.

Energy
------
Stored: rod kinetic ``m_eff v^2/2``, line kinetic ``L q^2/2``, gas ``E(V_g)``
(:mod:`.gas`), oil ``C p_c^2/2``, stop pads ``k delta^2/2``, the potential of
ambient pressure ``s p_amb A x`` and of gravity ``-m g_rod x``. Dissipated:
line ``R(q) q``, seal friction (sliding and viscous), cushions, stop dampers
and relaxing pads. External work: ``force * (x1 - x0)`` per step, exact for
the held input; with the effort side's interface model (the rod force
``F = E0 - K (x - x_ref) - D (v - v_ref) + R (t - t0)`` over the step,
:mod:`.interface`) ``E0 (x1 - x0)`` and the spring's
``-K [(x1 - x_ref)^2 - (x0 - x_ref)^2] / 2`` exactly and the damper's and the
rate's work as a state integrated with the step (present only in such steps).
"""

"""Stepping a cylinder over one communication step, refined at end-stop impacts and cushions.

Fixed-step solvers (``ros2``, ``rk4``) step at ``solver_max_step`` except
where the physics is much faster: during a stop impact they step at
``CONTACT_STEP_FACTOR / omega`` for the impact's transient, and while the rod
runs into a cushion at ``CUSHION_STEP_FACTOR m / (c v)``. The integration is
restarted at located events and in fixed pieces, so the result depends only
on the state and the step (bit-reproducible). :class:`RefinedStepping` is the
part of :class:`~wire_fmu.core.units.hydraulics.model.HydraulicsModel` that
does this.

With the effort side's interface model (:mod:`.interface`) the rod force varies over
the step, ``F(x, v, t)``; the step is then taken in the model's
:attr:`~wire_fmu.core.units.hydraulics.model.HydraulicsModel.interface_layout`, whose
last state integrates the power of the model's damper and rate terms, so that the
work through the rod is booked exactly for the force the rod saw.

With the compiled kernel (:mod:`~wire_fmu.core.units.hydraulics.kernel`) every
fixed-step solver the cylinder makes is a
:class:`~wire_fmu.core.framework.compiled_step.CompiledFixedStep`, and a step in
which nothing happens (no limit, no seal breakaway, no event, no refinement) is
taken in one call of the kernel; any other step goes the general way, in which
the Python model switches the modes and words the events.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from wire_fmu.core.framework.compiled_step import COMPILED_METHODS
from wire_fmu.core.framework.hybrid import SolverSettings
from wire_fmu.core.framework.step_limits import IntegrationError, internal_step_count
from wire_fmu.core.units.hydraulics import kernel
from wire_fmu.core.units.hydraulics.interface import NO_INTERFACE, RodInterface

__all__ = [
    "CONTACT_CHUNK_STEPS",
    "CONTACT_STEP_FACTOR",
    "CUSHION_CHUNK_STEPS",
    "CUSHION_STEP_FACTOR",
    "RefinedStepping",
]


class _Resolve(Exception):  # noqa: N818 - control flow, not an error
    """Raised from an event handler to restart integration with a finer or coarser solver."""

    def __init__(self, time: float, state: np.ndarray) -> None:
        super().__init__(time)
        self.time = time
        self.state = state


CONTACT_STEP_FACTOR = 0.02
"""While on a stop, fixed-step solvers step at most ``CONTACT_STEP_FACTOR / omega``
(``omega = sqrt(k / m)``): the restitution error of ROS2 is about
``2 (omega h)^2``, so about 0.1 %."""

CONTACT_CHUNK_STEPS = 16
"""While on a stop, the solver is restarted every this many steps, which refreshes
ROS2's Jacobian (the stop damper's loss ``c v^2`` changes slope as the rod rebounds)."""

CUSHION_STEP_FACTOR = 0.03
"""While the rod runs into a cushion at speed ``v``, fixed-step solvers step at most
``CUSHION_STEP_FACTOR m / (c v)`` (``m / (c v)`` is the time in which the cushion
would halve the speed); the error in ``v(x)`` and in the ledger is then about 0.1 %."""

CUSHION_CHUNK_STEPS = 8
"""In a cushion the step is re-chosen (and the Jacobian refreshed) every this many steps."""

_FIXED_STEP = ("rk4", "ros2")
_REPORTED = len(kernel.REPORT)
"""How many of the quiet step's outputs are the model's report."""
_EXTERNAL_WORK = kernel.QUIET_OUTPUTS.index("external_work")
_NO_WORK = np.zeros(1)
"""The interface model's work at a step's start, J (read only: copied into the state)."""
_NO_WORK.flags.writeable = False


class RefinedStepping:
    """Advance, settle and the refined integration of a cylinder model (a mixin).

    The model provides ``state``, ``force``, ``interface``, ``time``, ``initial_position``,
    ``own_layout``, ``interface_layout``, ``own_kernel_layout``, ``interface_kernel_layout``,
    ``use_layout``, ``load``, ``settings``,
    ``solver``, ``stops``, ``seal``, ``mass``, ``spec``, ``compiled``, ``step_report``,
    ``kernel_data``, ``project``, ``_directions``, ``_limits_and_force``,
    ``_refuse_at_limit`` and ``_settle_friction``.
    """

    def _make_contact_solver(self, settings: SolverSettings):
        """A solver resolving the stop contact (fixed-step methods only), or None.

        Also sets :attr:`contact_transient`: how long after contact begins
        the fine steps are kept (two periods of the contact oscillation or
        five decay times, whichever is longer), s.
        """
        self.contact_transient = 0.0
        if self.stops is None or settings.method not in _FIXED_STEP:
            return None
        omega, zeta = self.stops.contact_frequency(self.mass)
        self.contact_transient = max(
            4.0 * math.pi / omega, 5.0 / (zeta * omega) if zeta > 0.0 else math.inf
        )
        fine = min(settings.max_step, CONTACT_STEP_FACTOR / omega)
        if fine >= settings.max_step:
            return None
        return self.kernel_solver(replace(settings, max_step=fine))

    # -------------------------------------------------------------- stepping
    def advance(
        self, t: float, h: float, force: float, interface: RodInterface = NO_INTERFACE
    ) -> int:
        """Advance from ``t`` by ``h`` (s) against the rod force; return the events.

        The rod force is ``force`` held, or with ``interface`` the local model
        ``F(x, v, t)`` about ``t`` (:mod:`.interface`); its work is added to
        :attr:`external_work`. A step in which nothing happens is taken in one call of
        the compiled kernel (:meth:`_quiet_step`), any other the general way.

        Parameters
        ----------
        t : float
            Start of the step, s.
        h : float
            Step length, s.
        force : float
            External force on the rod along extension (positive pushes it out) at ``t``,
            ``E0``, N.
        interface : RodInterface
            The effort side's interface model of the force over the step (its ``start``
            is taken as ``t``).

        Returns
        -------
        int
            Number of events located in the step.

        Raises
        ------
        HydraulicLimitError
            At a limit (the caller restores the state and refuses the step).
        """
        self._take_load(t, force, interface)
        if self._quiet_step(t, t + h) is not None:
            return 0
        return self._integrate_step(t, t + h)

    def quiet_step_outputs(
        self, t: float, h: float, force: float, interface: RodInterface, initial_energy: float
    ) -> list[float] | None:
        """:meth:`advance` for a step in which nothing happens, with the outputs it changes,
        in one compiled call; None (nothing changed) for any other step.

        A step whose outputs are not all finite counts as not quiet: the general way then
        refuses it with the reason.

        Parameters
        ----------
        t, h, force, interface
            As :meth:`advance` takes them, but ``interface`` as :meth:`advance` would hold
            it: :data:`~.interface.NO_INTERFACE` unless it is active, and then about ``t``.
        initial_energy : float
            Stored energy at the start of the ledger, J.

        Returns
        -------
        list of float or None
            The values of :data:`kernel.QUIET_OUTPUTS
            <wire_fmu.core.units.hydraulics.kernel_arrays.QUIET_OUTPUTS>`; None if the
            step was not taken.
        """
        load = self.load
        held_position = None if self.seal is None else self.seal.held_position
        self.force, self.interface, self.time = force, interface, t
        outputs = self._quiet_step(t, t + h, initial_energy, finite_only=True)
        if outputs is None:
            self.force, self.interface, self.time = load
            if self.seal is not None:
                self.seal.held_position = held_position
            return None
        self.last_events = []
        self.first_event_time = math.inf
        return outputs

    def _take_load(self, t: float, force: float, interface: RodInterface) -> None:
        """The rod force and its interface model for the step from ``t`` (s); no events yet."""
        self.last_events = []
        self.first_event_time = math.inf
        self.force = float(force)
        if not interface.active:
            interface = NO_INTERFACE
        elif interface.start != t:
            interface = replace(interface, start=float(t))
        self.interface = interface
        self.time = t
        self.step_report = None

    def _integrate_step(self, t: float, t_end: float) -> int:
        """The general way of :meth:`advance` from ``t`` to ``t_end`` (s), the load taken:
        limits, settling, the refined integration and the rod's work; the events."""
        start = float(self.state[0])
        if not self.interface.active:
            events = self._step(t, t_end)
            self.external_work += self.force * (float(self.state[0]) - start)
            return events
        self.state = np.concatenate((self.state, _NO_WORK))  # the interface model's work, J
        self.use_layout(self.interface_layout)
        try:
            events = self._step(t, t_end)
        finally:
            self.use_layout(self.own_layout)
            self.state, varying = self.state[:-1], float(self.state[-1])
        self.external_work += self._interface_work(start, float(self.state[0]), varying)
        return events

    def _step(self, t: float, t_end: float) -> int:
        """Integrate from ``t`` to ``t_end`` (s) in the present layout; the events located."""
        try:
            violated, rod_force = self._limits_and_force(self.state, t)
            self._refuse_at_limit(violated, t, self.state)
            self.state = self.settle(self.state, rod_force)
            self.state, events = self._integrate(t, self.state, t_end)
            return events
        finally:
            self.time = t_end

    def _interface_work(self, x0: float, x1: float, varying: float) -> float:
        """Work of the interface model's force on a rod moved from ``x0`` to ``x1`` (m), J.

        ``E0 (x1 - x0)`` and the spring's work exactly; ``varying`` (J) is the damper's
        and the rate's, as the step's solver integrated it.
        """
        x_ref = self.interface.reference_extension(self.initial_position)
        return self.force * (x1 - x0) + self.interface.elastic_work(x0, x1, x_ref) + varying

    def _preload_quiet_step(self) -> None:
        """Load :func:`kernel.quiet_step_outputs` and the loop after an event
        (:func:`kernel.advance`, :meth:`preload_kernel`) from the compiled-code cache now,
        by calls that take no step, so that neither the first step nor the first event
        pays for it."""
        method = COMPILED_METHODS.get(self.settings.method) if self.compiled else None
        if method is not None:
            t = self.time
            kernel.quiet_step_outputs(
                method,
                t,
                t,
                0,
                self.state,
                self._directions,
                self.kernel_data(),
                self.external_work,
                0.0,
                self.initial_position,
            )
            self.preload_kernel(t)

    def _quiet_step(
        self, t: float, t_end: float, initial_energy: float = 0.0, finite_only: bool = False
    ) -> list[float] | None:
        """Take a step in which nothing happens in one call of the compiled kernel.

        Nothing happens when no limit is reached, the seal keeps its mode, no guard
        fires and the step needs no refinement. The kernel then does what
        :meth:`advance` would (limits, settle, :class:`CompiledFixedStep` on its grid,
        the rod's work) from the load taken, and reports the end state (kept in
        :attr:`step_report` for the outputs). If anything happens (or, with
        ``finite_only``, an output is not finite), it answers None and leaves the state
        alone, but for the seal's held position: the step is then taken the general way,
        from the start.

        Returns
        -------
        list of float or None
            The values of ``kernel.QUIET_OUTPUTS`` (the ledger's balance from
            ``initial_energy``, J), or None.
        """
        settings = self.settings
        method = COMPILED_METHODS.get(settings.method) if self.compiled else None
        if method is None or t >= t_end - settings.event_time_tolerance:
            return None
        if self.stops is not None and self._resolution(t, self.state) != "coarse":
            return None
        try:
            count = internal_step_count(t, t_end, settings.max_step)  # CompiledFixedStep's grid
        except IntegrationError:
            return None
        if self.seal is not None:
            self.seal.held_position = float(self.state[0])  # as settling would
        active = self.interface.active  # the kernel appends the interface model's work state
        layout = self.interface_kernel_layout if active else self.own_kernel_layout
        taken, x, values, finite = kernel.quiet_step_outputs(
            method,
            t,
            t_end,
            count,
            self.state,
            self._directions,
            kernel.kernel_data(self, layout=layout),
            self.external_work,
            initial_energy,
            self.initial_position,
        )
        if not taken or (finite_only and not finite):
            return None
        outputs = values.tolist()
        self.state, self.time, self.external_work = x, t_end, outputs[_EXTERNAL_WORK]
        self.step_report = (x, self.load, outputs[:_REPORTED])
        return outputs

    def settle(self, x: np.ndarray, force: float | None = None) -> np.ndarray:
        """Seal mode consistent with the rod force now (it may have jumped); the new state.

        Parameters
        ----------
        x : numpy.ndarray
            The model's state (see :class:`HydraulicsModel`) at its :attr:`time`.
        force : float or None
            Every force on the rod but seal friction at ``x``, N, if already known.
        """
        if self.seal is None:
            return self.project(np.array(x, dtype=float))
        before = self.seal.mode
        x = self._settle_friction(np.array(x, dtype=float), [], self.time, force)
        self.mode_changes += int(self.seal.mode != before)
        return self.project(x)

    def _integrate(self, t: float, x: np.ndarray, t_end: float) -> tuple[np.ndarray, int]:
        """Integrate to ``t_end``; fixed-step solvers refine on a stop and in a cushion.

        The refined pieces start at located events and have fixed lengths, so
        the result depends only on the state and ``t_end`` (bit-reproducible).
        """
        events = 0
        tolerance = self.settings.event_time_tolerance
        self._integrating = True
        try:
            while t < t_end - tolerance:
                solver, stop = self._piece(t, x, t_end)
                try:
                    x, count = solver.advance(self, t, x, stop)
                    t, events = stop, events + count
                except _Resolve as restart:
                    t, x, events = restart.time, restart.state, events + 1
        finally:
            self._integrating = False
        return x, events

    @property
    def _refining(self) -> bool:
        """Whether event handlers may restart the integration (only inside :meth:`advance`)."""
        return self._integrating and self.stops is not None and self.settings.method in _FIXED_STEP

    def _resolution(self, t: float, x: np.ndarray) -> str:
        """``"contact"`` (impact transient), ``"cushion"`` (running into one) or ``"coarse"``."""
        stops = self.stops
        if any(stops.contact) and t < stops.contact_since + self.contact_transient:
            return "contact"
        if stops.cushion_speed(float(x[1])) > 0.0:
            return "cushion"
        return "coarse"

    def _piece(self, t: float, x: np.ndarray, t_end: float):
        """The solver for the next piece of integration and where the piece ends."""
        self._current_resolution = self._resolution(t, x) if self._refining else "coarse"
        if self._current_resolution == "contact" and self.contact_solver is not None:
            solver = self.contact_solver
            settled = self.stops.contact_since + self.contact_transient
            return solver, min(
                t_end,
                t + CONTACT_CHUNK_STEPS * solver.settings.max_step,
                max(settled, t + solver.settings.max_step),
            )
        if self._current_resolution == "cushion":
            c = self.spec.stops.cushion_coefficient
            h = CUSHION_STEP_FACTOR * self.mass / (c * self.stops.cushion_speed(float(x[1])))
            if h < self.settings.max_step:
                solver = self.kernel_solver(replace(self.settings, max_step=h))
                return solver, min(t_end, t + CUSHION_CHUNK_STEPS * h)
        return self.solver, t_end

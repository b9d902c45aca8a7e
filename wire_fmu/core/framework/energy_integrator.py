"""Paper 004: a machine unit with variable reduced inertia, integrated in energy form.

The machine unit (SPEC section 9) has one degree of freedom ``phi`` (rad),
angular velocity ``omega`` (rad/s), reduced inertia ``I(phi)`` (kg m^2),
kinetic energy ``E = I omega^2 / 2``, a driving torque with the linear
characteristic of an induction motor (eq. 6) and resistance torques that
depend on the angle, the speed or the time::

    M_d(omega) = a - b omega
    I(phi) omega' + I'(phi) omega^2 / 2 = M_d(omega) - M_c(phi) - M_c(omega) - M_c(t)

(all in N m). Torques are positive in the sense of ``phi``; a resistance is
positive when it opposes positive motion.

The energy form (paper 004)
---------------------------
Over an angle step ``dphi`` the kinetic energy grows by the work done,
``E_{i+1} = E_i + dA_d - dA_c`` (4), each work by a trapezoid (5) except
the work of ``M_c(phi)``, which is integrated exactly when its integral is
given. Taking logarithms of ``E = I omega^2/2`` gives (1)::

    2 domega / omega_i = dE / E_i + ln I_i - ln I_{i+1}

With the speed-dependent torques linearised at ``omega_i`` (slope
``s = d(M_d - M_c(omega))/domega = k - b`` in the paper's notation, ``k``
the tangent of ``M_c(omega)``) this is solved for the *first-order step*
(9), or (15) with ``M_c(t)``; the time advances by ``dt = dphi/omega_i``
(13). The *second-order correction* (12), (18) is a Newton step on the
logarithmic form (3)::

    2 domega* / omega_{i+1} = dE*/E_{i+1} + ln E_{i+1} - ln(I_{i+1} omega_{i+1}^2 / 2)
    domega* = 2 B E_{i+1} omega_{i+1} / (4 E_{i+1} - s* dphi omega_{i+1})

with ``B = ln(2 E_{i+1} / (I_{i+1} omega_{i+1}^2))``, ``s*`` the slope of the
secant through ``omega_i`` and ``omega_{i+1}`` (the paper's ``k* - b``) and
the time refined by ``dt* = 2 dphi/(omega_i + omega_{i+1})`` (16). Repeated
until ``|domega*|`` is below the tolerance, it converges to the trapezoidal
energy balance, which is second order.

Reconstructed from a garbled print, and regrouped: ``E_{i+1}`` in the
correction is evaluated by (4) at the current ``omega_{i+1}`` and
``t*_{i+1}`` on the true torque curves, so the constant parts of ``dE*``
(the paper's ``[l - l* + (k* - k) omega_{i+1}] dphi/2`` in (11) and ``D`` in
(17)) are already inside ``E_{i+1}``; the update agrees with (12) and (18)
to first order in the correction and has the same fixed point. (16) must
read ``t*_{i+1} = t_i + dt*``; (18)'s ``J`` is ``ln(2E/(I omega^2))``.

Where it breaks down
--------------------
Everything divides by ``omega_i`` and ``E_i``: at ``omega -> 0`` the step
``dt = dphi / omega`` is unbounded (a machine at rest cannot advance by
an angle), the logarithmic linearisation ``ln(1 + x) ~ x`` fails once
``|domega| ~ |omega|``, and ``E = I omega^2 / 2`` loses the sign of
``omega``, so a reversal cannot be represented. Start-up from rest and a
band brake bringing the drum to rest are exactly these cases. The
time-stepped solver
:class:`~wire_fmu.core.framework.energy_solver.EnergyFormSolver` therefore
steps in time form (explicit Euler for the first-order variant, Heun for the
refined one -- same order) whenever ``omega_i = 0``, the first-order prediction
changes ``omega`` by more than half of itself or reverses it, or the
refinement fails to converge; a drum *held* by the brake is a stuck mode
with ``omega = 0`` exactly and is not integrated at all.

The machine unit itself is :class:`~wire_fmu.core.framework.machine_unit.MachineUnit`;
the solver a unit chooses by name is in :mod:`wire_fmu.core.framework.energy_solver`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from wire_fmu.core.framework.machine_unit import MachineUnit, StepWork

__all__ = ["EnergyStep", "EnergyFormBreakdownError", "EnergyFormIntegrator"]


class EnergyFormBreakdownError(ArithmeticError):
    """The energy form cannot take this step (omega at or through zero, no convergence)."""


@dataclass(frozen=True)
class EnergyStep:
    """Result of one step: new angle (rad), speed (rad/s), time (s) and the works.

    ``refinements`` counts second-order corrections; ``form`` is ``"energy"``
    or ``"time"`` (the fallback near ``omega = 0``).
    """

    phi: float
    omega: float
    time: float
    work: StepWork
    refinements: int
    form: str = "energy"


def _trapezoid_work(
    machine: MachineUnit,
    t0: float,
    t1: float,
    phi0: float,
    dphi: float,
    omega0: float,
    omega1: float,
) -> StepWork:
    half = 0.5 * dphi
    return StepWork(
        driving=half * (machine.driving_torque(omega0) + machine.driving_torque(omega1)),
        angle=machine.angle_work(phi0, phi0 + dphi),
        speed=half * (machine.resistance_speed(omega0) + machine.resistance_speed(omega1)),
        time=half * (machine.resistance_time(t0) + machine.resistance_time(t1)),
    )


class EnergyFormIntegrator:
    """Paper 004's energy-form step with successive second-order refinement.

    Parameters
    ----------
    refinements : int or None
        Second-order corrections per step: 0 gives the first-order step
        (9)/(15) alone (order 1), ``n`` exactly ``n`` corrections, None
        repeats them until ``|domega*| <= tolerance * |omega|`` (order 2).
    tolerance : float
        Relative tolerance of the successive refinement.
    max_iterations : int
        Refinements allowed before :class:`EnergyFormBreakdownError` (``None`` mode).
    """

    def __init__(
        self, refinements: int | None = None, tolerance: float = 1e-12, max_iterations: int = 50
    ) -> None:
        self.refinements = refinements
        self.tolerance = tolerance
        self.max_iterations = max_iterations
        self.torque_evaluations = 0

    @property
    def order(self) -> int:
        """Order of accuracy the variant claims."""
        return 1 if self.refinements == 0 else 2

    # ------------------------------------------------------------ angle steps
    def step_angle(
        self, machine: MachineUnit, t: float, phi: float, omega: float, dphi: float
    ) -> EnergyStep:
        """One step of angle ``dphi`` (the paper's own form; ``dphi`` has the sign of omega).

        Parameters
        ----------
        machine : MachineUnit
            The machine unit of the step.
        t : float
            Time at the start of the step, s.
        phi : float
            Shaft angle at the start, rad.
        omega : float
            Shaft speed at the start, rad/s.
        dphi : float
            Angle step, rad.

        Raises
        ------
        EnergyFormBreakdownError
            If ``omega`` is zero, reverses, or the refinement does not converge.
        """
        if omega == 0.0 or dphi * omega <= 0.0:
            raise EnergyFormBreakdownError(
                f"energy form needs motion in the step's direction (omega = {omega}, "
                f"dphi = {dphi}): dt = dphi/omega is undefined"
            )

        def kinematics(omega1: float | None) -> tuple[float, float]:
            """Angle step (rad) and end time (s): by (13), or by (16) given ``omega1``.

            Parameters
            ----------
            omega1 : float or None
                Speed at the end of the step, rad/s (None for the first-order step).
            """
            if omega1 is None:
                return dphi, t + dphi / omega  # (13)
            return dphi, t + 2.0 * dphi / (omega + omega1)  # (16), corrected

        return self._solve(machine, t, phi, omega, kinematics)

    def step_time(
        self, machine: MachineUnit, t: float, phi: float, omega: float, dt: float
    ) -> EnergyStep:
        """One step of time ``dt``: (13) and (16) read backwards give the angle step.

        First order: ``dphi = omega_i dt``; refined: ``dphi = (omega_i +
        omega_{i+1}) dt / 2``, iterated with the speed. Falls back to the
        time form near ``omega = 0`` (module docstring).

        Parameters
        ----------
        machine : MachineUnit
            The machine unit of the step.
        t, phi, omega : float
            Time (s), shaft angle (rad) and shaft speed (rad/s) at the start.
        dt : float
            Time step, s.
        """
        if omega != 0.0:

            def kinematics(omega1: float | None) -> tuple[float, float]:
                """Angle step (rad) and end time (s) of the time step ``dt``.

                Parameters
                ----------
                omega1 : float or None
                    Speed at the end of the step, rad/s (None for the first-order step).
                """
                if omega1 is None:
                    return omega * dt, t + dt
                return 0.5 * (omega + omega1) * dt, t + dt

            try:
                return self._solve(machine, t, phi, omega, kinematics)
            except EnergyFormBreakdownError:
                pass
        return self._time_form(machine, t, phi, omega, dt)

    # ------------------------------------------------------------ internals
    def _first_order(
        self, machine: MachineUnit, t: float, t1: float, phi: float, omega: float, dphi: float
    ) -> float:
        """``omega_{i+1}`` by (9)/(15)."""
        i0, i1 = machine.inertia(phi), machine.inertia(phi + dphi)
        energy = 0.5 * i0 * omega * omega
        gain = (
            machine.speed_torque(omega) * dphi
            - machine.angle_work(phi, phi + dphi)
            - 0.5 * (machine.resistance_time(t) + machine.resistance_time(t1)) * dphi
        )
        slope = machine.speed_torque_slope(omega)
        self.torque_evaluations += 1
        d_omega = (
            2.0
            * (gain + energy * (math.log(i0) - math.log(i1)))
            / (2.0 * i0 * omega - slope * dphi)
        )
        if not abs(d_omega) < 0.5 * abs(omega):
            raise EnergyFormBreakdownError(
                f"first-order step changes omega = {omega:.6g} rad/s by {d_omega:.6g}: "
                "too close to rest for the energy form"
            )
        return omega + d_omega

    def _correction(
        self,
        machine: MachineUnit,
        t: float,
        t1: float,
        phi: float,
        omega: float,
        omega1: float,
        dphi: float,
    ) -> float:
        """``domega*`` by (12)/(18) as regrouped in the module docstring."""
        i1 = machine.inertia(phi + dphi)
        work = _trapezoid_work(machine, t, t1, phi, dphi, omega, omega1)
        energy1 = machine.kinetic_energy(phi, omega) + work.net  # (4)
        self.torque_evaluations += 1
        if not energy1 > 0.0:
            raise EnergyFormBreakdownError("the kinetic energy would vanish within the step")
        if omega1 != omega:
            secant = (machine.speed_torque(omega1) - machine.speed_torque(omega)) / (omega1 - omega)
        else:
            secant = machine.speed_torque_slope(omega1)
        log_gap = math.log(2.0 * energy1 / (i1 * omega1 * omega1))
        return 2.0 * log_gap * energy1 * omega1 / (4.0 * energy1 - secant * dphi * omega1)

    def _solve(
        self,
        machine: MachineUnit,
        t: float,
        phi: float,
        omega: float,
        kinematics: Callable[[float | None], tuple[float, float]],
    ) -> EnergyStep:
        dphi, t1 = kinematics(None)
        omega1 = self._first_order(machine, t, t1, phi, omega, dphi)
        limit = self.max_iterations if self.refinements is None else self.refinements
        done = 0
        converged = self.refinements is not None
        for done in range(1, limit + 1):  # noqa: B007 - the count is reported
            dphi, t1 = kinematics(omega1)
            correction = self._correction(machine, t, t1, phi, omega, omega1, dphi)
            omega1 += correction
            if omega1 * omega <= 0.0:
                raise EnergyFormBreakdownError("omega reverses within the step")
            if abs(correction) <= self.tolerance * abs(omega1):
                converged = True
                break
        if not converged:
            raise EnergyFormBreakdownError(f"refinement did not converge in {limit} iterations")
        if limit:
            dphi, t1 = kinematics(omega1)
        work = _trapezoid_work(machine, t, t1, phi, dphi, omega, omega1)
        return EnergyStep(phi + dphi, omega1, t1, work, done if limit else 0)

    def _time_form(
        self, machine: MachineUnit, t: float, phi: float, omega: float, dt: float
    ) -> EnergyStep:
        """Euler (first-order variant) or Heun (refined variant) in time."""
        acc0 = machine.acceleration(t, phi, omega)
        omega_p, phi_p = omega + dt * acc0, phi + dt * omega
        self.torque_evaluations += 1
        if self.refinements == 0:
            omega1, phi1 = omega_p, phi_p
        else:
            acc1 = machine.acceleration(t + dt, phi_p, omega_p)
            self.torque_evaluations += 1
            omega1 = omega + 0.5 * dt * (acc0 + acc1)
            phi1 = phi + 0.5 * dt * (omega + omega_p)
        work = _time_work(machine, t, dt, phi, phi1, omega, omega1)
        return EnergyStep(phi1, omega1, t + dt, work, 0, form="time")


def _time_work(
    machine: MachineUnit,
    t: float,
    dt: float,
    phi0: float,
    phi1: float,
    omega0: float,
    omega1: float,
) -> StepWork:
    """Works as trapezoids of power in time (the time-form fallback)."""
    half = 0.5 * dt
    return StepWork(
        driving=half
        * (machine.driving_torque(omega0) * omega0 + machine.driving_torque(omega1) * omega1),
        angle=machine.angle_work(phi0, phi1),
        speed=half
        * (machine.resistance_speed(omega0) * omega0 + machine.resistance_speed(omega1) * omega1),
        time=half
        * (machine.resistance_time(t) * omega0 + machine.resistance_time(t + dt) * omega1),
    )

"""Paper 004's machine unit in steady motion: laws of I(phi) and of the resistances, and the model.

A machine unit (SPEC section 9) is one rigid degree of freedom: the main
shaft's angle ``phi`` (rad) and speed ``omega`` (rad/s), everything reduced
to the main shaft. The paper treats it in general; here its ingredients are
configurable laws (:mod:`wire_fmu.core.units.machine.laws`):

reduced inertia ``I(phi)`` (kg m^2)
    ``crank_slider``: ``I0 + m x'(phi)^2`` for a slider of mass ``m``
    driven by a crank ``r`` through a rod ``l`` (``x = r cos(phi) +
    sqrt(l^2 - r^2 sin^2(phi))``, exact, no series), or ``fourier``:
    ``I0 + sum a_k cos(k phi) + b_k sin(k phi)``;
resistance of the angle ``M_c(phi)`` (N m)
    a Fourier series in ``phi`` with its work integrated exactly (the
    technological load of a cyclic machine);
resistance of the speed ``M_c(omega)`` (N m)
    a polynomial ``sum c_j omega^j`` (bearings, ventilation);
resistance of time ``M_c(t)`` (N m)
    a Fourier series in ``t`` of a given period (a load that varies with
    time, unrelated to the shaft's cycle), plus the ``load.torque`` input.

The motor has the linear characteristic ``M_d = a - b omega`` (paper 004,
eq. 6), ``a`` an input (``motor.command``), ``b`` a parameter.

:class:`MachineDriveModel` is both a :class:`~wire_fmu.core.framework.hybrid.HybridSystem`
(for the reference integrators) and a
:class:`~wire_fmu.core.framework.energy_solver.RigidMachineSystem` (for paper 004's
energy-form integrator, :class:`~wire_fmu.core.framework.energy_solver.EnergyFormSolver`),
so the same machine is solved both ways.

Modules
-------
:mod:`~wire_fmu.core.units.machine.laws`
    The laws: Fourier series, crank-slider and Fourier inertias, polynomials.
:mod:`~wire_fmu.core.units.machine.spec`
    A machine's laws together, read from JSON data, and the default crank press.
:mod:`~wire_fmu.core.units.machine.cycle_statistics`
    Per-revolution speed statistics of the main shaft (steady motion).
"""

from __future__ import annotations

import numpy as np

from wire_fmu.core.framework.hybrid import SmoothSystem
from wire_fmu.core.framework.machine_unit import MachineUnit, StepWork
from wire_fmu.core.units.machine.spec import MachineSpec

__all__ = ["MachineDriveModel"]


class MachineDriveModel(SmoothSystem):
    """The machine unit as a hybrid ODE and as a rigid machine for the energy form.

    State ``[phi, omega, dissipated, external work]`` (rad, rad/s, J, J).
    Dissipated: the work of ``M_c(omega)``; external: the motor's work minus
    that of ``M_c(phi)``, ``M_c(t)`` and the load input.

    Parameters
    ----------
    spec : MachineSpec
        The machine's laws.
    motor_slope : float
        ``b``, N m s/rad.
    """

    def __init__(self, spec: MachineSpec, motor_slope: float) -> None:
        self.spec = spec
        self.b = motor_slope
        self.command = 0.0
        self.load = 0.0
        self.state = np.zeros(4)
        self._machine = spec.machine(0.0, motor_slope)

    def set_inputs(self, command: float, load: float) -> None:
        """Motor ``a`` (N m) and extra load torque (N m), held over a step.

        Parameters
        ----------
        command : float
            Motor torque at zero speed ``a``, N m.
        load : float
            Extra load torque, N m.
        """
        if (command, load) != (self.command, self.load):
            self.command, self.load = command, load
            self._machine = self.spec.machine(command, self.b, load)

    @property
    def unit(self) -> MachineUnit:
        """Paper 004's machine unit for the inputs now held."""
        return self._machine

    # -- HybridSystem (no modes: the rest is SmoothSystem's) -------------------
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[omega, omega', dissipated', external work']``.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[phi (rad), omega (rad/s), dissipated (J), external work (J)]``.
        """
        m = self._machine
        phi, omega = float(x[0]), float(x[1])
        dissipated = m.resistance_speed(omega) * omega
        external = (
            m.driving_torque(omega) - m.resistance_angle(phi) - m.resistance_time(t)
        ) * omega
        return np.array([omega, m.acceleration(t, phi, omega), dissipated, external])

    # -- RigidMachineSystem -----------------------------------------------------
    def machine(self, t: float, x: np.ndarray) -> MachineUnit:
        """The machine for paper 004's integrator (never held at rest).

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[phi (rad), omega (rad/s), dissipated (J), external work (J)]``.
        """
        return self._machine

    def book(self, work: StepWork) -> tuple[float, float]:
        """``M_c(omega)`` dissipates; the motor, ``M_c(phi)`` and ``M_c(t)`` are external.

        Parameters
        ----------
        work : StepWork
            The works of the step, J.

        Returns
        -------
        tuple of float
            (dissipated, external work), J.
        """
        return work.speed, work.driving - work.angle - work.time

    # -- outputs ----------------------------------------------------------------
    def kinetic_energy(self, x: np.ndarray | None = None) -> float:
        """``I(phi) omega^2 / 2``, J.

        Parameters
        ----------
        x : ndarray, optional
            State ``[phi (rad), omega (rad/s), ...]`` (default: the current one).
        """
        x = self.state if x is None else x
        return self._machine.kinetic_energy(float(x[0]), float(x[1]))

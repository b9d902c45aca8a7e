"""Paper 004's machine unit: reduced inertia, motor characteristic and resistances.

One rigid degree of freedom ``phi`` (rad) with ``I(phi) omega' + I'(phi)
omega^2 / 2 = M_d(omega) - M_c(phi) - M_c(omega) - M_c(t)`` (N m), the
equation :mod:`wire_fmu.core.framework.energy_integrator` integrates in energy form.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

__all__ = ["MachineUnit", "StepWork"]


def _zero(_: float) -> float:
    return 0.0


@dataclass(frozen=True)
class MachineUnit:
    """Paper 004's machine unit: ``I(phi)``, ``M_d = a - b omega`` and resistances.

    Parameters
    ----------
    inertia : callable
        ``I(phi)``, kg m^2 (> 0).
    inertia_slope : callable
        ``dI/dphi``, kg m^2/rad.
    a : float
        Motor torque at zero speed, N m.
    b : float
        Slope of the motor characteristic, N m s/rad.
    resistance_angle : callable
        ``M_c(phi)``, N m.
    resistance_angle_work : callable or None
        ``(phi0, phi1) -> integral of M_c(phi) dphi``, J; Simpson's rule if None.
    resistance_speed, resistance_speed_slope : callable
        ``M_c(omega)`` (N m) and ``dM_c/domega`` (N m s/rad).
    resistance_time : callable
        ``M_c(t)``, N m.
    """

    inertia: Callable[[float], float]
    inertia_slope: Callable[[float], float] = _zero
    a: float = 0.0
    b: float = 0.0
    resistance_angle: Callable[[float], float] = _zero
    resistance_angle_work: Callable[[float, float], float] | None = None
    resistance_speed: Callable[[float], float] = _zero
    resistance_speed_slope: Callable[[float], float] = _zero
    resistance_time: Callable[[float], float] = _zero

    def driving_torque(self, omega: float) -> float:
        """``M_d = a - b omega`` (eq. 6), N m.

        Parameters
        ----------
        omega : float
            Shaft speed, rad/s.
        """
        return self.a - self.b * omega

    def speed_torque(self, omega: float) -> float:
        """Net speed-dependent torque ``M_d(omega) - M_c(omega)``, N m.

        Parameters
        ----------
        omega : float
            Shaft speed, rad/s.
        """
        return self.a - self.b * omega - self.resistance_speed(omega)

    def speed_torque_slope(self, omega: float) -> float:
        """``d(M_d - M_c(omega))/domega``, N m s/rad (the paper's ``k - b``).

        Parameters
        ----------
        omega : float
            Shaft speed, rad/s.
        """
        return -self.b - self.resistance_speed_slope(omega)

    def angle_work(self, phi0: float, phi1: float) -> float:
        """Work absorbed by ``M_c(phi)`` from ``phi0`` to ``phi1``, J.

        Parameters
        ----------
        phi0, phi1 : float
            Shaft angles at the start and the end, rad.
        """
        if self.resistance_angle_work is not None:
            return self.resistance_angle_work(phi0, phi1)
        mid = self.resistance_angle(0.5 * (phi0 + phi1))
        ends = self.resistance_angle(phi0) + self.resistance_angle(phi1)
        return (phi1 - phi0) * (ends + 4.0 * mid) / 6.0

    def net_torque(self, t: float, phi: float, omega: float) -> float:
        """All torques, N m.

        Parameters
        ----------
        t : float
            Time, s.
        phi : float
            Shaft angle, rad.
        omega : float
            Shaft speed, rad/s.
        """
        return self.speed_torque(omega) - self.resistance_angle(phi) - self.resistance_time(t)

    def acceleration(self, t: float, phi: float, omega: float) -> float:
        """``omega'`` from the Lagrange equation, rad/s^2.

        Parameters
        ----------
        t : float
            Time, s.
        phi : float
            Shaft angle, rad.
        omega : float
            Shaft speed, rad/s.
        """
        centrifugal = 0.5 * self.inertia_slope(phi) * omega * omega
        return (self.net_torque(t, phi, omega) - centrifugal) / self.inertia(phi)

    def rhs_time(self, t: float, y: np.ndarray) -> np.ndarray:
        """``d[phi, omega]/dt`` (for reference solutions).

        Parameters
        ----------
        t : float
            Time, s.
        y : ndarray, shape (2,)
            ``[phi (rad), omega (rad/s)]``.
        """
        return np.array([y[1], self.acceleration(t, y[0], y[1])])

    def rhs_angle(self, phi: float, y: np.ndarray) -> np.ndarray:
        """``d[omega, t]/dphi`` (for reference solutions; omega must not vanish).

        Parameters
        ----------
        phi : float
            Shaft angle, rad.
        y : ndarray, shape (2,)
            ``[omega (rad/s), t (s)]``.
        """
        omega, t = y
        return np.array([self.acceleration(t, phi, omega) / omega, 1.0 / omega])

    def kinetic_energy(self, phi: float, omega: float) -> float:
        """``I(phi) omega^2 / 2``, J.

        Parameters
        ----------
        phi : float
            Shaft angle, rad.
        omega : float
            Shaft speed, rad/s.
        """
        return 0.5 * self.inertia(phi) * omega * omega


@dataclass(frozen=True)
class StepWork:
    """Works over one step, J.

    Attributes
    ----------
    driving : float
        Done by ``M_d(omega)`` on the machine.
    angle, speed, time : float
        Absorbed by ``M_c(phi)``, ``M_c(omega)``, ``M_c(t)``.
    """

    driving: float
    angle: float
    speed: float
    time: float

    @property
    def net(self) -> float:
        """Change of kinetic energy these works imply, J."""
        return self.driving - self.angle - self.speed - self.time

"""The scissor jack's kinematics and forces in the current mode, in the handle angle.

The equations are derived in :mod:`wire_fmu.core.units.scissor_jack.model`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wire_fmu.core.components.friction import StickSlip
from wire_fmu.core.components.screw_nut.thread import REGULARISATIONS
from wire_fmu.core.errors import ModelError
from wire_fmu.core.units.scissor_jack.config import JackConfig, JackInputs

__all__ = ["JackMechanics"]


@dataclass(frozen=True)
class _Forces:
    """Handle acceleration (rad/s^2), axial force (N), thread friction and handle torque (N m)."""

    acceleration: float
    axial_force: float
    friction_torque: float
    handle_torque: float


class JackMechanics:
    """Kinematics and forces of :class:`~wire_fmu.core.units.scissor_jack.model.ScissorJackModel`.

    A part of the model, kept apart for size: it reads the model's
    attributes ``config`` (:class:`JackConfig`), ``h`` (lead per radian,
    m/rad), ``r_mu`` (mean thread radius times friction coefficient, m),
    ``inputs`` (:class:`JackInputs`) and ``friction`` (the thread's
    :class:`~wire_fmu.core.components.friction.StickSlip`).
    """

    config: JackConfig
    h: float
    r_mu: float
    inputs: JackInputs
    friction: StickSlip

    # ---------------------------------------------------------- kinematics
    def travel(self, psi: float) -> float:
        """Screw travel ``s = h psi``, m.

        Parameters
        ----------
        psi : float
            Handle angle relative to the nut since the start, rad.
        """
        return self.h * psi

    def inertia(self, psi: float) -> float:
        """``I(psi) = J_s + m (h cot theta)^2``, kg m^2.

        Parameters
        ----------
        psi : float
            Handle angle relative to the nut since the start, rad.
        """
        _, slope, _ = self.config.geometry.slopes(self.travel(psi))
        return self.config.handle_inertia + self.config.load_mass * (self.h * slope) ** 2

    def height(self, psi: float) -> float:
        """Shoe height, m.

        Parameters
        ----------
        psi : float
            Handle angle relative to the nut since the start, rad.
        """
        return self.config.geometry.height(self.travel(psi))

    # ---------------------------------------------------------- forces
    def _axial_force(self, psi: float, omega: float, acceleration: float) -> float:
        """``F = (W + m y'') cot(theta)``, N."""
        _, slope, curvature = self.config.geometry.slopes(self.travel(psi))
        load_acc = self.h * slope * acceleration + self.h**2 * curvature * omega * omega
        return (self.config.load_weight + self.config.load_mass * load_acc) * slope

    def _sliding(self, psi: float, omega: float, torque: float, shape: float) -> _Forces:
        """Motion under handle ``torque`` with friction ``-shape r mu |F|`` (``|shape| <= 1``).

        Solves the equation linear in ``psi''`` for each sign of ``F`` and
        keeps the consistent one (module docstring).
        """
        cfg = self.config
        _, slope, curvature = cfg.geometry.slopes(self.travel(psi))
        static = cfg.load_weight + cfg.load_mass * self.h**2 * curvature * omega * omega
        for sign in (1.0, -1.0):
            q = self.h + shape * self.r_mu * sign
            inertia = cfg.handle_inertia + q * cfg.load_mass * self.h * slope * slope
            if inertia <= 0.0:
                continue
            acc = (torque - q * slope * static) / inertia
            force = self._axial_force(psi, omega, acc)
            if force * sign >= 0.0:
                friction = -shape * self.r_mu * abs(force)
                return _Forces(acc, force, friction, torque)
        raise ModelError(
            f"scissor jack: no consistent motion at psi = {psi:.6g} rad, speed {omega:.6g} "
            f"rad/s, handle torque {torque:.6g} N m (dry friction without a solution: "
            "Painleve's paradox); a heavier handle_inertia avoids it"
        )

    def _torque_driven(self, x: np.ndarray) -> _Forces:
        """Acceleration and forces under the torque command in the current mode."""
        psi, omega = float(x[0]), float(x[1])
        torque = self.inputs.torque_command
        friction = self.config.friction
        if friction == "none":
            return self._sliding(psi, omega, torque, 0.0)
        if self.config.regularised:
            shape, _ = REGULARISATIONS[friction]
            return self._sliding(psi, omega, torque, shape(omega / self.config.speed_scale))
        mode = int(self.friction.mode[0])
        if mode != 0:
            return self._sliding(psi, omega, torque, float(mode))
        force = self.config.static_force(self.travel(psi))
        holding = -(torque - self.h * force)
        return _Forces(0.0, force, holding, torque)

    def _speed_driven(self, x: np.ndarray) -> _Forces:
        """Forces and the handle torque needed to turn at the held speed ``x[1]``."""
        psi, omega = float(x[0]), float(x[1])
        force = self._axial_force(psi, omega, 0.0)
        friction = self.config.friction
        if friction == "none":
            resist = 0.0
        elif self.config.regularised:
            shape, _ = REGULARISATIONS[friction]
            resist = -shape(omega / self.config.speed_scale) * self.r_mu * abs(force)
        elif omega != 0.0:
            resist = -math.copysign(self.r_mu * abs(force), omega)
        else:  # held still by the drive: the thread holds what it can of the lead torque
            capacity = self.r_mu * abs(force)
            resist = max(-capacity, min(capacity, self.h * force))
        return _Forces(0.0, force, resist, self.h * force - resist)

    def forces(self, x: np.ndarray) -> _Forces:
        """Acceleration, axial force, friction and handle torque at state ``x``.

        Parameters
        ----------
        x : ndarray
            State ``[psi (rad), psi' (rad/s), ...]``.
        """
        if self.config.drive == "speed":
            return self._speed_driven(x)
        return self._torque_driven(x)

    def _capacity(self, psi: float) -> np.ndarray:
        return np.array([self.r_mu * abs(self.config.static_force(self.travel(psi)))])

    def _free_torque(self, x: np.ndarray) -> np.ndarray:
        """Non-friction generalised torque for :class:`StickSlip` (at rest: static)."""
        psi, omega = float(x[0]), float(x[1])
        self.friction.masses[0] = self.inertia(psi)
        _, slope, curvature = self.config.geometry.slopes(self.travel(psi))
        centrifugal = self.config.load_mass * self.h**2 * slope * curvature * self.h * omega**2
        gravity = self.config.load_weight * self.h * slope
        return np.array([self.inputs.torque_command - gravity - centrifugal])

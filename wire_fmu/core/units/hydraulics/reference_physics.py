"""The cylinder's equations at one state, readable: the reference the compiled kernel follows.

:class:`ReferencePhysics` is the part of
:class:`~wire_fmu.core.units.hydraulics.model.HydraulicsModel` that evaluates the
equations in Python: pressures, flow, forces and losses at a state, the state
derivative, the guards, the limits and the report. The model calls it when it runs the
Python kernel (``WIRE_FMU_KERNEL=python``), and for the words of its messages;
:mod:`~wire_fmu.core.units.hydraulics.kernel` has the same equations compiled. The
physics is described in the package docstring (:mod:`wire_fmu.core.units.hydraulics`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wire_fmu.core.components.end_stops import RETRACTED

__all__ = ["ReferencePhysics"]

_LIMITS = ("gas_dead", "gas_empty", "cavitation", "stroke")
"""The guards that refuse a step."""
_NO_STOP = (0.0, (0.0, 0.0), (0.0, 0.0), 0.0, 0.0)
"""What :meth:`EndStops.forces` gives without the effect: no force, depth, loss or energy."""


@dataclass
class _Point:
    """Everything the model knows at one state (forces on the rod along extension)."""

    x: float
    v: float
    gas_volume: float
    gas_pressure: float
    chamber_pressure: float  # without the L dq/dt term of an incompressible column
    flow: float
    force: float  # all forces on the rod except seal friction and the inertance term
    hydraulic_force: float
    stop_force: float
    depth: tuple[float, float]
    trial: tuple[float, float]
    loss: float
    stored: float
    interface_power: float  # of the interface model's damper and rate terms, W


class ReferencePhysics:
    """The equations of a cylinder model in Python (a mixin).

    The model provides ``layout``, ``oil_constant``, ``sa``, ``spec``, ``cyl``, ``gas``,
    ``force``, ``interface``, ``initial_position``, ``time``, ``stops``, ``seal``,
    ``mass``, ``_viscous``, ``_oil_side``, ``has_inertance``, ``compressible``,
    ``inertance``, ``r_l``, ``r_t``, ``compliance``, ``area``, ``state`` and
    ``_guard_kinds``.
    """

    def gas_volume(self, x: np.ndarray) -> float:
        """Gas volume at state ``x``, m^3.

        Parameters
        ----------
        x : numpy.ndarray
            State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
        """
        if self.layout.gas_volume >= 0:
            return float(x[self.layout.gas_volume])
        return self.oil_constant + self.sa * float(x[0])

    def rod_force(self, t: float, pos: float, vel: float) -> float:
        """The external rod force ``F(x, v, t)`` over the step: held or the interface
        model's (:meth:`RodInterface.effort <.interface.RodInterface.effort>`), N.

        Parameters
        ----------
        t : float
            Time, s.
        pos, vel : float
            Rod extension (m) and velocity (m/s).
        """
        interface = self.interface
        x_ref = interface.reference_extension(self.initial_position)
        return interface.effort(self.force, t, pos, vel, x_ref)

    def evaluate(self, t: float, x: np.ndarray, energy: bool = False) -> _Point:
        """Pressures, flow, forces, losses (and stored energy if ``energy``) at ``(t, x)``.

        Parameters
        ----------
        t : float
            Time, s (the interface model's rod force varies with it).
        x : numpy.ndarray
            State ``[x, v, (V_g, p_c, q), dissipated, (interface work)]`` (m, m/s, m^3,
            Pa, m^3/s, J, J).
        energy : bool
            Also compute the stored energy (J).

        Returns
        -------
        _Point
            Rod position (m) and velocity (m/s), gas volume (m^3) and pressure (Pa),
            chamber pressure (Pa), line flow (m^3/s), forces on the rod (N), stop
            depths (m), loss power (W), stored energy (J, 0 without ``energy``) and the
            interface model's power (W, 0 without its work state).
        """
        pos, vel = float(x[0]), float(x[1])
        v_gas = self.gas_volume(x)
        dead = self.spec.accumulator.dead_volume
        p_g = self.gas.pressure(max(v_gas, 0.5 * dead))  # beyond the dead volume: refused
        p_c, flow, loss, stored = self._oil_side(x, vel, v_gas, p_g)
        hydraulic = self.sa * (p_c - self.cyl.ambient_pressure)
        stop_force, depth, trial, stop_loss, stop_energy = (
            _NO_STOP if self.stops is None else self.stops.forces(pos, vel)
        )
        weight = self.cyl.moving_mass * self.cyl.gravity_along_rod
        force = self.rod_force(t, pos, vel) + hydraulic + weight + stop_force
        force = force - self._viscous * vel
        loss += stop_loss + self._viscous * vel * vel
        power = self.interface.power(t, vel) if self.layout.interface_work >= 0 else 0.0
        if energy:
            stored += (
                0.5 * self.mass * vel * vel
                + self.gas.energy(max(v_gas, 0.5 * dead))
                + stop_energy
                + self.sa * self.cyl.ambient_pressure * pos
                - weight * pos
            )
        return _Point(
            pos,
            vel,
            v_gas,
            p_g,
            p_c,
            flow,
            force,
            hydraulic,
            stop_force,
            depth,
            trial,
            loss,
            stored,
            power,
        )

    def _accelerate(self, point: _Point) -> tuple[float, float, float]:
        """Acceleration (m/s^2), seal friction force on the rod (N) and its loss (W)."""
        if self.seal is None:
            return point.force / self.mass, 0.0, 0.0
        return self.seal.accelerate(point.force, point.v)

    def chamber_pressure(self, point: _Point, acceleration: float) -> float:
        """Pressure at the cylinder port, Pa (includes ``-L dq/dt`` of an incompressible column).

        Parameters
        ----------
        point : _Point
            The model at a state (:meth:`evaluate`).
        acceleration : float
            Rod acceleration, m/s^2.
        """
        if self.has_inertance and not self.compressible:
            return point.chamber_pressure - self.inertance * self.sa * acceleration
        return point.chamber_pressure

    def _reference_rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """State derivative: ``[x', v', (V_g', p_c', q'), dissipated']`` (the reference).

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
        """
        point = self.evaluate(t, x)
        acc, _, friction_loss = self._accelerate(point)
        lay = self.layout
        out = np.empty_like(x)
        stuck = self.seal is not None and self.seal.stuck
        out[0] = 0.0 if stuck else point.v
        out[1] = 0.0 if stuck else acc
        if lay.gas_volume >= 0:
            out[lay.gas_volume] = point.flow
        if lay.chamber_pressure >= 0:
            out[lay.chamber_pressure] = (point.flow - self.sa * point.v) / self.compliance
        if lay.flow >= 0:
            drop = (self.r_l + self.r_t * abs(point.flow)) * point.flow
            out[lay.flow] = (point.gas_pressure - point.chamber_pressure - drop) / self.inertance
        out[lay.dissipated] = point.loss + friction_loss
        if lay.interface_work >= 0:
            out[lay.interface_work] = 0.0 if stuck else point.interface_power
        return out

    def _reference_guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """Seal stick/slip, limits, stop contact and cushion zones (the reference).

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).

        Returns
        -------
        numpy.ndarray
            One value per guard (seal, gas, cavitation, stroke or stops); see
            ``guard_directions``.
        """
        point = self.evaluate(t, x)
        acc, link, _ = self._accelerate(point)
        return np.array(
            [self._guard(kind, end, point, acc, link) for kind, end in self._guard_kinds]
        )

    def _guard(self, kind: str, end: int, point: _Point, acc: float, link: float) -> float:
        acc_dead = self.spec.accumulator
        if kind == "seal":
            return self.seal.guard(point.v, link)
        if kind == "gas_dead":
            return point.gas_volume - acc_dead.dead_volume
        if kind == "gas_empty":
            return acc_dead.full_volume - point.gas_volume
        if kind == "cavitation":
            return self.chamber_pressure(point, acc) - self.spec.oil.cavitation_pressure
        if kind == "stroke":
            return point.x if end == RETRACTED else self.cyl.stroke - point.x
        return self.stops.guard(kind, end, point.x, point.depth, point.trial)

    def _reference_limits_and_force(self, x: np.ndarray, t: float) -> tuple[int, float]:
        """The first limit guard already violated at ``(t, x)`` (-1: none) and the force on
        the rod.

        The force is every force but seal friction and the column's inertia, N (what the
        seal must hold).
        """
        point = self.evaluate(t, x)
        acc, link, _ = self._accelerate(point)
        for i, (kind, end) in enumerate(self._guard_kinds):
            if kind in _LIMITS and self._guard(kind, end, point, acc, link) < 0.0:
                return i, point.force
        return -1, point.force

    def _reference_report(self) -> dict[str, float]:
        """Physical quantities at the current state, for outputs (keys: ``kernel.REPORT``)."""
        point = self.evaluate(self.time, self.state, energy=True)
        acc, link, _ = self._accelerate(point)
        if self.seal is not None and self.seal.stuck:
            acc = 0.0
        p_c = self.chamber_pressure(point, acc)
        compliance = self.gas.compliance(point.gas_volume)
        if self.compressible:
            compliance += self.compliance
        return {
            "position": point.x,
            "velocity": point.v,
            "acceleration": acc,
            "chamber_pressure": p_c,
            "hydraulic_force": self.sa * (p_c - self.cyl.ambient_pressure),
            "gas_pressure": point.gas_pressure,
            "gas_volume": point.gas_volume,
            "flow": point.flow,
            "oil_in_accumulator": self.spec.accumulator.full_volume - point.gas_volume,
            "stiffness": self.area**2 / compliance,
            "stop_force": point.stop_force,
            "friction_force": link - self._viscous * point.v,
            "stored_energy": point.stored,
        }

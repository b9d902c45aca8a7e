"""Where a cylinder starts: the state, the gas charge and the oil column at initialisation.

:class:`InitialState` is the part of
:class:`~wire_fmu.core.units.hydraulics.model.HydraulicsModel` that sets the state from
the rod's position and velocity and the gas pressure (or static equilibrium with the rod
force), charges the gas and sizes the oil column's compliance.
"""

from __future__ import annotations

import numpy as np

from wire_fmu.core.components.gas import PolytropicGas, isothermal_charge_volume
from wire_fmu.core.units.hydraulics.interface import NO_INTERFACE, RodInterface
from wire_fmu.core.units.hydraulics.limits import check_start

__all__ = ["InitialState"]


class InitialState:
    """Initialisation of a cylinder model (a mixin).

    The model provides ``cyl``, ``sa``, ``spec``, ``line``, ``exponent``, ``layout``,
    ``r_l``, ``r_t``, ``stops``, ``seal``, ``rod_force``, ``_settle_friction``,
    ``check_limits`` and ``_preload_quiet_step``.
    """

    def equilibrium_pressure(self, force: float) -> float:
        """Absolute chamber pressure holding the rod at rest against ``force`` (N), Pa.

        Parameters
        ----------
        force : float
            External force on the rod along extension (positive pushes it out), N.
        """
        weight = self.cyl.moving_mass * self.cyl.gravity_along_rod
        return self.cyl.ambient_pressure - (force + weight) / self.sa

    def initialize(
        self,
        force: float,
        *,
        position: float,
        velocity: float,
        gas_pressure: float | None,
        interface: RodInterface = NO_INTERFACE,
    ) -> None:
        """Set the state; ``gas_pressure`` None means static equilibrium with the rod force.

        The gas was charged slowly (isothermally) from the pre-charge to the
        initial pressure; from there on it follows ``p V^n = p0 V0^n``. The rod force
        is that of the interface model (if any) at the start: ``F(x0, v0, t0)``, with
        ``t0`` the interface's ``start``.

        Parameters
        ----------
        force : float
            External force on the rod along extension (positive pushes it out) at the
            start, ``E0``, N.
        position : float
            Rod extension, m.
        velocity : float
            Rod velocity along extension, m/s.
        gas_pressure : float or None
            Initial absolute gas pressure, Pa; None for static equilibrium with the rod
            force.
        interface : RodInterface
            The effort side's interface model of the rod force, if any.

        Raises
        ------
        ConfigurationError
            If the start is impossible (pressure, oil in the accumulator,
            position), listing every problem.
        """
        self.force = float(force)
        self.interface = interface
        self.time = interface.start
        self.initial_position = float(position)
        start_force = self.rod_force(self.time, float(position), float(velocity))
        p0 = self.equilibrium_pressure(start_force) if gas_pressure is None else gas_pressure
        p0 = float(p0)
        check_start(self, p0, position, velocity)
        acc = self.spec.accumulator
        v0 = min(
            isothermal_charge_volume(acc.precharge_pressure, acc.full_volume, p0), acc.full_volume
        )
        self.gas = PolytropicGas(p0, v0, self.exponent)
        oil = self.spec.oil.volume or (self.cyl.chamber_volume(position) + self.line.volume)
        self.compliance = oil / self.spec.oil.bulk_modulus
        self.oil_constant = v0 - self.sa * position
        self.state = self._initial_state(position, velocity, p0, v0)
        if self.stops is not None:
            self.stops.start(position)
        if self.seal is not None:
            self.seal.start(velocity)  # a moving seal slides
        self.external_work = 0.0
        self.mode_changes = 0
        self.last_events = []
        self.state = self._settle_friction(self.state, [], self.time)
        self.check_limits(self.time, self.state)
        self._preload_quiet_step()

    def _initial_state(self, position: float, velocity: float, p0: float, v0: float) -> np.ndarray:
        lay = self.layout
        state = np.zeros(lay.size)
        state[0], state[1] = position, velocity
        flow = self.sa * velocity
        if lay.gas_volume >= 0:
            state[lay.gas_volume] = v0
        if lay.chamber_pressure >= 0:
            state[lay.chamber_pressure] = p0 - (self.r_l + self.r_t * abs(flow)) * flow
        if lay.flow >= 0:
            state[lay.flow] = flow
        return state

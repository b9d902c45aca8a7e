"""Hydraulic cylinder with a gas accumulator: the hydro-pneumatic spring (SPEC section 11).

The physics, the effects and the numerics are described in the package
(:mod:`wire_fmu.core.units.hydraulics`); this module holds the model. Its
equations here are the readable reference; :mod:`.kernel` has the same equations
compiled, which the model evaluates instead when ``self.compiled`` (see
:func:`~wire_fmu.core.framework.compiled.use_compiled`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from wire_fmu.core.components.end_stops import (
    EXTENDED,
    RETRACTED,
    EndStops,
    EndStopSpec,
    damping_ratio_for_restitution,
    restitution_of_damping_ratio,
)
from wire_fmu.core.components.gas import ISOTHERMAL, PolytropicGas, isothermal_charge_volume
from wire_fmu.core.components.rod_seal import RodSeal, SealSpec
from wire_fmu.core.errors import ModelError
from wire_fmu.core.framework.compiled import use_compiled
from wire_fmu.core.framework.compiled_step import KernelModel
from wire_fmu.core.framework.effects import Effect, EffectCatalogue
from wire_fmu.core.framework.hybrid import SolverSettings
from wire_fmu.core.units.hydraulics import kernel
from wire_fmu.core.units.hydraulics.limits import check_start, limit_message
from wire_fmu.core.units.hydraulics.oil_side import OilSide
from wire_fmu.core.units.hydraulics.specs import (
    AccumulatorSpec,
    CylinderSpec,
    HydraulicsSpec,
    OilSpec,
)
from wire_fmu.core.units.hydraulics.stepping import RefinedStepping, _Resolve

__all__ = [
    "HYDRAULICS_EFFECTS",
    "CylinderSpec",
    "AccumulatorSpec",
    "OilSpec",
    "SealSpec",
    "EndStopSpec",
    "HydraulicsSpec",
    "HydraulicsModel",
    "HydraulicLimitError",
    "restitution_of_damping_ratio",
    "damping_ratio_for_restitution",
]

logger = logging.getLogger(__name__)

HYDRAULICS_EFFECTS = EffectCatalogue(
    "hydraulics",
    (
        Effect(
            "polytropic_gas",
            "isothermal gas (n = 1)",
            "polytropic gas p V^n = const (n = polytropic_exponent, 1.4 adiabatic)",
        ),
        Effect("line_losses", "lossless line", "laminar + turbulent line resistance"),
        Effect("line_inertance", "massless line oil", "oil inertia in the line (L dq/dt)"),
        Effect(
            "oil_compressibility", "incompressible oil", "compressible oil column (bulk modulus)"
        ),
        Effect(
            "seal_friction",
            "frictionless seals",
            "Coulomb + viscous (+ Stribeck) seal friction with stick",
        ),
        Effect(
            "end_stops",
            "no end stops (leaving the stroke refuses the step)",
            "hydraulic cushions and stiff end stops",
        ),
    ),
)


class HydraulicLimitError(ModelError):
    """A physical limit the unit cannot step through (the step is refused)."""


_LIMITS = ("gas_dead", "gas_empty", "cavitation", "stroke")
"""The guards that refuse a step."""
_NO_STOP = (0.0, (0.0, 0.0), (0.0, 0.0), 0.0, 0.0)
"""What :meth:`EndStops.forces` gives without the effect: no force, depth, loss or energy."""


# ------------------------------------------------------------------ the model
@dataclass(frozen=True)
class _Layout:
    """Indices of the optional states (-1 when absent)."""

    gas_volume: int
    chamber_pressure: int
    flow: int
    dissipated: int
    size: int


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


class HydraulicsModel(KernelModel, OilSide, RefinedStepping):
    """Hybrid ODE of a cylinder with gas accumulator; see the module docstring.

    Parameters
    ----------
    spec : HydraulicsSpec
        Validated physical parameters.
    effects : frozenset of str
        Effects to include (validated by :data:`HYDRAULICS_EFFECTS`).
    solver : SolverSettings
        Internal solver used by :meth:`advance`.
    """

    KERNEL = kernel

    def __init__(
        self, spec: HydraulicsSpec, effects: frozenset[str], solver: SolverSettings
    ) -> None:
        self.spec = spec
        self.effects = effects
        self.settings = solver
        self._read_effects(effects)
        self.cyl = spec.cylinder
        self.area = self.cyl.working_area
        self.sign = self.cyl.sign
        self.sa = self.sign * self.area
        self.line = spec.line
        self.r_l = self.line.laminar_resistance if self.losses else 0.0
        self.r_t = self.line.turbulent_resistance if self.losses else 0.0
        self.inertance = self.line.inertance if self.has_inertance else 0.0
        column = self.has_inertance and not self.compressible  # moves with the rod
        self.mass = self.cyl.moving_mass + (self.inertance * self.area**2 if column else 0.0)
        self.exponent = spec.accumulator.polytropic_exponent if self.polytropic else ISOTHERMAL
        self.layout = self._build_layout()
        self._oil_side = self._choose_oil_side()
        self.seal = RodSeal(spec.seal, self.mass) if "seal_friction" in effects else None
        self._viscous = self.seal.viscous if self.seal is not None else 0.0
        stops_on = "end_stops" in effects
        self.stops = EndStops(spec.stops, self.cyl.stroke, self.mass) if stops_on else None
        self._guard_kinds = self._build_guards()
        self._directions = np.array(
            [0.0 if kind == "pad" else -1.0 for kind, _ in self._guard_kinds]
        )
        self.compiled = use_compiled("hydraulic cylinder")  # the kernel covers every effect set
        self.kernel_parameters = kernel.kernel_parameters(self)
        self.kernel_layout = kernel.kernel_layout(self)
        self.step_report: tuple | None = None
        """``(state, force, report values)`` of the state a quiet step ended in, or None."""
        self.solver = self.kernel_solver(solver)
        self.contact_solver = self._make_contact_solver(solver)
        self._current_resolution = "coarse"
        self._integrating = False
        self.gas = PolytropicGas(
            spec.accumulator.precharge_pressure, spec.accumulator.full_volume, self.exponent
        )
        self.compliance = 0.0
        self.oil_constant = 0.0
        self.state = np.zeros(self.layout.size)
        self.force = 0.0
        self.mode_changes = 0
        self.external_work = 0.0
        self.initial_position = 0.0
        self.last_events: list[str] = []

    # ------------------------------------------------------------------ build
    def _read_effects(self, effects: frozenset[str]) -> None:
        self.polytropic = "polytropic_gas" in effects
        self.losses = "line_losses" in effects
        self.has_inertance = "line_inertance" in effects
        self.compressible = "oil_compressibility" in effects

    def _build_layout(self) -> _Layout:
        index = 2
        gas = p_c = flow = -1
        if self.compressible:
            gas, index = index, index + 1
            if self.losses or self.has_inertance:
                p_c, index = index, index + 1
            if self.has_inertance:
                flow, index = index, index + 1
        return _Layout(gas, p_c, flow, index, index + 1)

    def _build_guards(self) -> list[tuple[str, int]]:
        kinds = [("seal", 0)] if self.seal is not None else []
        kinds += [("gas_dead", 0), ("gas_empty", 0), ("cavitation", 0)]
        if self.stops is not None:
            kinds += self.stops.guard_kinds
        else:
            kinds += [("stroke", RETRACTED), ("stroke", EXTENDED)]
        return kinds

    @property
    def n_states(self) -> int:
        """Number of continuous states, dissipated energy included."""
        return self.layout.size

    # ------------------------------------------------------------ evaluation
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

    def evaluate(self, x: np.ndarray, energy: bool = False) -> _Point:
        """Pressures, flow, forces, losses (and stored energy if ``energy``) at state ``x``.

        Parameters
        ----------
        x : numpy.ndarray
            State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
        energy : bool
            Also compute the stored energy (J).

        Returns
        -------
        _Point
            Rod position (m) and velocity (m/s), gas volume (m^3) and pressure (Pa),
            chamber pressure (Pa), line flow (m^3/s), forces on the rod (N), stop
            depths (m), loss power (W) and stored energy (J, 0 without ``energy``).
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
        force = self.force + hydraulic + weight + stop_force - self._viscous * vel
        loss += stop_loss + self._viscous * vel * vel
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

    # ------------------------------------------------ HybridSystem protocol
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """State derivative: ``[x', v', (V_g', p_c', q'), dissipated']``.

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
        """
        if self.compiled:
            return kernel.rhs(t, x, self.kernel_data())
        point = self.evaluate(x)
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
        return out

    def guard_directions(self) -> np.ndarray:
        """-1 (fires leaving a mode; >= 0 inside it), 0 for the pad kinks (any crossing)."""
        return self._directions

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """Seal stick/slip, limits, stop contact and cushion zones (see :meth:`_guard`).

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
            :meth:`guard_directions`.
        """
        if self.compiled:
            return kernel.guards(t, x, self.kernel_data())
        point = self.evaluate(x)
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

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Refuse at a limit; otherwise switch contact, cushion and seal modes.

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
        fired : list of int
            Indices of the guards that fired at ``t``.

        Returns
        -------
        numpy.ndarray
            The state after the switches, projected.

        Raises
        ------
        HydraulicLimitError
            If a limit guard fired.
        """
        x = np.array(x, dtype=float)
        seal_fired = []
        kinks_only = True
        for i in fired:
            kind, end = self._guard_kinds[i]
            kinks_only = kinks_only and kind == "pad"
            if kind == "pad":
                continue
            if kind == "seal":
                seal_fired.append(0)
            elif kind in ("contact", "cushion"):
                self.last_events.append(self.stops.switch(kind, end, t))
            else:
                raise HydraulicLimitError(limit_message(self, kind, end, x, t))
        x = self._settle_friction(x, seal_fired)
        if not kinks_only:
            logger.debug("t = %.9g s: events so far this step: %s", t, "; ".join(self.last_events))
        self.mode_changes += 0 if kinks_only else 1
        x = self.project(x)
        if self._refining and self._resolution(t, x) != self._current_resolution:
            raise _Resolve(t, x)
        return x

    def project(self, x: np.ndarray) -> np.ndarray:
        """Hold a stuck rod exactly where it stuck, at rest.

        Parameters
        ----------
        x : numpy.ndarray
            State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J),
            changed in place.

        Returns
        -------
        numpy.ndarray
            ``x``.
        """
        if self.seal is not None and self.seal.stuck:
            x[0] = self.seal.held_position
            x[1] = 0.0
        return x

    # ------------------------------------------------------------ modes
    def _settle_friction(
        self, x: np.ndarray, fired: list[int], force: float | None = None
    ) -> np.ndarray:
        """Make the seal's mode consistent with the forces at ``x`` (``force``: on the rod, N,
        if already known)."""
        if self.seal is None:
            return x
        if force is None:
            force = self._limits_and_force(x)[1]
        x[1], event = self.seal.settle(float(x[0]), float(x[1]), force, fired)
        if event:
            self.last_events.append(event)
        return x

    def check_limits(self, t: float, x: np.ndarray) -> None:
        """Raise :class:`HydraulicLimitError` if a limit guard is already violated at ``x``.

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[x, v, (V_g, p_c, q), dissipated]`` (m, m/s, m^3, Pa, m^3/s, J).
        """
        self._refuse_at_limit(self._limits_and_force(x)[0], t, x)

    def _refuse_at_limit(self, violated: int, t: float, x: np.ndarray) -> None:
        """Raise :class:`HydraulicLimitError` for guard ``violated`` (nothing for -1)."""
        if violated >= 0:
            kind, end = self._guard_kinds[violated]
            raise HydraulicLimitError(limit_message(self, kind, end, x, t))

    def _limits_and_force(self, x: np.ndarray) -> tuple[int, float]:
        """The first limit guard already violated at ``x`` (-1: none) and the force on the rod.

        The force is every force but seal friction and the column's inertia, N (what the
        seal must hold).
        """
        if self.compiled:
            return kernel.limits_and_force(x, self.kernel_data())
        point = self.evaluate(x)
        acc, link, _ = self._accelerate(point)
        for i, (kind, end) in enumerate(self._guard_kinds):
            if kind in _LIMITS and self._guard(kind, end, point, acc, link) < 0.0:
                return i, point.force
        return -1, point.force

    def _report_values(self) -> list[float]:
        """The compiled kernel's report of the present state (that of the last quiet step if
        the state and force are still those it ended with)."""
        kept = self.step_report
        if kept is not None and kept[0] is self.state and kept[1] == self.force:
            return kept[2]
        return kernel.report(self.state, self.kernel_data()).tolist()

    # ---------------------------------------------------------- initial state
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
        self, force: float, *, position: float, velocity: float, gas_pressure: float | None
    ) -> None:
        """Set the state; ``gas_pressure`` None means static equilibrium with ``force``.

        The gas was charged slowly (isothermally) from the pre-charge to the
        initial pressure; from there on it follows ``p V^n = p0 V0^n``.

        Parameters
        ----------
        force : float
            External force on the rod along extension (positive pushes it out), N.
        position : float
            Rod extension, m.
        velocity : float
            Rod velocity along extension, m/s.
        gas_pressure : float or None
            Initial absolute gas pressure, Pa; None for static equilibrium with ``force``.

        Raises
        ------
        ConfigurationError
            If the start is impossible (pressure, oil in the accumulator,
            position), listing every problem.
        """
        self.force = float(force)
        p0 = self.equilibrium_pressure(force) if gas_pressure is None else float(gas_pressure)
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
        self.initial_position = float(position)
        self.external_work = 0.0
        self.mode_changes = 0
        self.last_events = []
        self.state = self._settle_friction(self.state, [])
        self.check_limits(0.0, self.state)

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

    # ----------------------------------------------------------------- report
    def stored_energy(self) -> float:
        """Stored energy at the current state, J (see the module docstring)."""
        return self.report()["stored_energy"]

    @property
    def dissipated_energy(self) -> float:
        """Energy dissipated since the start, J."""
        return float(self.state[self.layout.dissipated])

    def report_values(self) -> list[float]:
        """:meth:`report`'s quantities as a list, in the order of ``kernel.REPORT``."""
        if self.compiled:
            return self._report_values()
        report = self.report()
        return [report[name] for name in kernel.REPORT]

    def report(self) -> dict[str, float]:
        """Physical quantities at the current state, for outputs (keys: ``kernel.REPORT``)."""
        if self.compiled:
            # the kernel's report has one value per name by construction
            return dict(zip(kernel.REPORT, self._report_values(), strict=False))
        point = self.evaluate(self.state, energy=True)
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

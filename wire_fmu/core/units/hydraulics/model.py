"""Hydraulic cylinder with a gas accumulator: the hydro-pneumatic spring (SPEC section 11).

The physics, the effects and the numerics are described in the package
(:mod:`wire_fmu.core.units.hydraulics`); this module holds the model: how it is built
from the effects, the hybrid-system protocol, the modes and the report. Its parts are
mixins: the readable reference equations (:mod:`.reference_physics`), the oil side
(:mod:`.oil_side`), the initial state (:mod:`.initial_state`) and the refined stepping
(:mod:`.stepping`). :mod:`.kernel` has the same equations compiled, which the model
evaluates instead when ``self.compiled`` (see
:func:`~wire_fmu.core.framework.compiled.use_compiled`).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, replace

import numpy as np

from wire_fmu.core.components.end_stops import (
    EXTENDED,
    RETRACTED,
    EndStops,
    EndStopSpec,
    damping_ratio_for_restitution,
    restitution_of_damping_ratio,
)
from wire_fmu.core.components.gas import ISOTHERMAL, PolytropicGas
from wire_fmu.core.components.rod_seal import RodSeal, SealSpec
from wire_fmu.core.errors import ModelError
from wire_fmu.core.framework.compiled import use_compiled
from wire_fmu.core.framework.compiled_step import KernelModel
from wire_fmu.core.framework.effects import Effect, EffectCatalogue
from wire_fmu.core.framework.hybrid import SolverSettings
from wire_fmu.core.units.hydraulics import kernel
from wire_fmu.core.units.hydraulics.initial_state import InitialState
from wire_fmu.core.units.hydraulics.interface import NO_INTERFACE, RodInterface
from wire_fmu.core.units.hydraulics.limits import limit_message
from wire_fmu.core.units.hydraulics.oil_side import OilSide
from wire_fmu.core.units.hydraulics.reference_physics import ReferencePhysics
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
    "Layout",
    "RodInterface",
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


# ------------------------------------------------------------------ the model
@dataclass(frozen=True)
class Layout:
    """Indices of the optional states (-1 when absent) and the number of states.

    ``interface_work`` is the work of the interface model's damper and rate terms, a
    state only while a step with the model is taken (it starts at 0 J each step).
    """

    gas_volume: int
    chamber_pressure: int
    flow: int
    dissipated: int
    size: int
    interface_work: int = -1


class HydraulicsModel(KernelModel, OilSide, ReferencePhysics, InitialState, RefinedStepping):
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
        self.own_layout = self._build_layout()
        """Where the states are between steps (and in steps with the force held)."""
        self.interface_layout = replace(
            self.own_layout, interface_work=self.own_layout.size, size=self.own_layout.size + 1
        )
        """Where the states are in a step with the interface model: one more, its work."""
        self.layout = self.own_layout
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
        self.own_kernel_layout = kernel.kernel_layout(self, self.own_layout)
        """The kernel's layout array of :attr:`own_layout`."""
        self.interface_kernel_layout = kernel.kernel_layout(self, self.interface_layout)
        """The kernel's layout array of :attr:`interface_layout`."""
        self.kernel_layout = self.own_kernel_layout
        """The kernel's layout array of :attr:`layout`."""
        self.step_report: tuple | None = None
        """``(state, load, report values)`` of the state a quiet step ended in, or None."""
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
        """``E0``: the rod force at the step's start, held over it without interface model, N."""
        self.interface: RodInterface = NO_INTERFACE
        """The effort side's interface model of the rod force over the step."""
        self.time = 0.0
        """Time of :attr:`state`, s (the report and the limits are evaluated there)."""
        self.mode_changes = 0
        self.external_work = 0.0
        self.initial_position = 0.0
        self.last_events: list[str] = []
        self.first_event_time = math.inf  # of the last step's located events, s

    # ------------------------------------------------------------------ build
    def _read_effects(self, effects: frozenset[str]) -> None:
        self.polytropic = "polytropic_gas" in effects
        self.losses = "line_losses" in effects
        self.has_inertance = "line_inertance" in effects
        self.compressible = "oil_compressibility" in effects

    def _build_layout(self) -> Layout:
        index = 2
        gas = p_c = flow = -1
        if self.compressible:
            gas, index = index, index + 1
            if self.losses or self.has_inertance:
                p_c, index = index, index + 1
            if self.has_inertance:
                flow, index = index, index + 1
        return Layout(gas, p_c, flow, index, index + 1)

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

    def use_layout(self, lay: Layout) -> None:
        """Take the states as ``lay`` places them (:attr:`own_layout` or
        :attr:`interface_layout`); the state's length is the caller's.

        Parameters
        ----------
        lay : Layout
            One of the model's two layouts.
        """
        self.layout = lay
        own = lay == self.own_layout
        self.kernel_layout = self.own_kernel_layout if own else self.interface_kernel_layout

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
        return self._reference_rhs(t, x)

    def guard_directions(self) -> np.ndarray:
        """-1 (fires leaving a mode; >= 0 inside it), 0 for the pad kinks (any crossing)."""
        return self._directions

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """Seal stick/slip, limits, stop contact and cushion zones.

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
        return self._reference_guards(t, x)

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
        self.first_event_time = min(self.first_event_time, t)
        self.time = t
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
        x = self._settle_friction(x, seal_fired, t)
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
        self, x: np.ndarray, fired: list[int], t: float, force: float | None = None
    ) -> np.ndarray:
        """Make the seal's mode consistent with the forces at ``(t, x)`` (``force``: on the
        rod, N, if already known)."""
        if self.seal is None:
            return x
        if force is None:
            force = self._limits_and_force(x, t)[1]
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
        self._refuse_at_limit(self._limits_and_force(x, t)[0], t, x)

    def _refuse_at_limit(self, violated: int, t: float, x: np.ndarray) -> None:
        """Raise :class:`HydraulicLimitError` for guard ``violated`` (nothing for -1)."""
        if violated >= 0:
            kind, end = self._guard_kinds[violated]
            raise HydraulicLimitError(limit_message(self, kind, end, x, t))

    def _limits_and_force(self, x: np.ndarray, t: float) -> tuple[int, float]:
        """The first limit guard already violated at ``(t, x)`` (-1: none) and the force on
        the rod.

        The force is every force but seal friction and the column's inertia, N (what the
        seal must hold), with the rod force of the interface model at ``t``.
        """
        if self.compiled:
            return kernel.limits_and_force(x, kernel.kernel_data(self, t))
        return self._reference_limits_and_force(x, t)

    @property
    def load(self) -> tuple[float, RodInterface, float]:
        """What the report depends on besides the state: rod force, interface model, time."""
        return self.force, self.interface, self.time

    def _report_values(self) -> list[float]:
        """The compiled kernel's report of the present state (that of the last quiet step if
        the state and load are still those it ended with)."""
        kept = self.step_report
        if kept is not None and kept[0] is self.state and kept[1] == self.load:
            return kept[2]
        return kernel.report(self.state, self.kernel_data()).tolist()

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
        return self._reference_report()

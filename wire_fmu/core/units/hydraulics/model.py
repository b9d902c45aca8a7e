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

Energy
------
Stored: rod kinetic ``m_eff v^2/2``, line kinetic ``L q^2/2``, gas ``E(V_g)``
(:mod:`.gas`), oil ``C p_c^2/2``, stop pads ``k delta^2/2``, the potential of
ambient pressure ``s p_amb A x`` and of gravity ``-m g_rod x``. Dissipated:
line ``R(q) q``, seal friction (sliding and viscous), cushions, stop dampers
and relaxing pads. External work: ``force * (x1 - x0)`` per step, exact for
the held input.
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
from wire_fmu.core.components.gas import ISOTHERMAL, PolytropicGas, isothermal_charge_volume
from wire_fmu.core.components.hydraulic_line import HydraulicLine
from wire_fmu.core.components.rod_seal import RodSeal, SealSpec
from wire_fmu.core.errors import ConfigurationError, ModelError, check_positive
from wire_fmu.core.framework.effects import Effect, EffectCatalogue
from wire_fmu.core.framework.hybrid import SolverSettings, make_solver

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
_NO_STOP = (0.0, (0.0, 0.0), (0.0, 0.0), 0.0, 0.0)
"""What :meth:`EndStops.forces` gives without the effect: no force, depth, loss or energy."""


# --------------------------------------------------------------------- specs
@dataclass(frozen=True)
class CylinderSpec:
    """Geometry and moving mass of a single-acting cylinder.

    Parameters
    ----------
    bore_diameter, rod_diameter : float
        Piston and rod diameters, m.
    stroke : float
        Stroke, m.
    moving_mass : float
        Rod, piston and whatever the rod carries (sheave cluster), kg.
    pressurised_side : str
        ``"bore"`` (push: oil pushes the rod out) or ``"annulus"`` (pull).
    chamber_dead_volume : float
        Oil in the chamber when its working length is zero (ports, clearance), m^3.
    gravity_along_rod : float
        Component of gravity along the extension direction, m/s^2 (-9.81 for
        a vertical cylinder whose rod extends upwards).
    ambient_pressure : float
        Absolute pressure on the vented side and the rod's outer end, Pa.
    """

    bore_diameter: float
    rod_diameter: float
    stroke: float
    moving_mass: float
    pressurised_side: str = "bore"
    chamber_dead_volume: float = 0.01
    gravity_along_rod: float = 0.0
    ambient_pressure: float = 101325.0

    def problems(self) -> list[str]:
        """Every problem with the parameters, as sentences."""
        out: list[str] = []
        check_positive("bore_diameter", self.bore_diameter, out, "m")
        check_positive("rod_diameter", self.rod_diameter, out, "m")
        check_positive("stroke", self.stroke, out, "m")
        check_positive("moving_mass", self.moving_mass, out, "kg")
        check_positive("chamber_dead_volume", self.chamber_dead_volume, out, "m3", zero_ok=True)
        check_positive("ambient_pressure", self.ambient_pressure, out, "Pa", zero_ok=True)
        if self.rod_diameter >= self.bore_diameter > 0.0:
            out.append(
                f"parameter 'rod_diameter' ({self.rod_diameter} m) must be smaller than "
                f"'bore_diameter' ({self.bore_diameter} m)"
            )
        if self.pressurised_side not in ("bore", "annulus"):
            out.append(
                "parameter 'pressurised_side' must be 'bore' (push cylinder) or "
                f"'annulus' (pull cylinder), got {self.pressurised_side!r}"
            )
        if not math.isfinite(self.gravity_along_rod):
            out.append(
                f"parameter 'gravity_along_rod' must be finite, got {self.gravity_along_rod}"
            )
        return out

    @property
    def piston_area(self) -> float:
        """``pi D^2 / 4``, m^2."""
        return 0.25 * math.pi * self.bore_diameter**2

    @property
    def annulus_area(self) -> float:
        """``pi (D^2 - d^2) / 4``, m^2."""
        return 0.25 * math.pi * (self.bore_diameter**2 - self.rod_diameter**2)

    @property
    def working_area(self) -> float:
        """Area of the pressurised side, m^2."""
        return self.piston_area if self.pressurised_side == "bore" else self.annulus_area

    @property
    def sign(self) -> float:
        """+1 if the oil pushes the rod out (bore side), -1 if it pulls it in."""
        return 1.0 if self.pressurised_side == "bore" else -1.0

    def chamber_volume(self, x: float) -> float:
        """Oil volume of the pressurised chamber at extension ``x`` (m), m^3."""
        length = x if self.pressurised_side == "bore" else self.stroke - x
        return self.chamber_dead_volume + self.working_area * length


@dataclass(frozen=True)
class AccumulatorSpec:
    """Accumulator and gas bank.

    Parameters
    ----------
    accumulator_volume : float
        Total volume of the accumulator (gas plus oil side), m^3.
    gas_bank_volume : float
        Volume of the air pressure vessels on its gas side, m^3.
    accumulator_dead_volume : float
        Gas left in the accumulator when it is full of oil, m^3.
    precharge_pressure : float
        Absolute gas pressure with no oil in the accumulator, Pa.
    polytropic_exponent : float
        ``n`` used with the effect ``polytropic_gas``, 1.
    """

    accumulator_volume: float
    gas_bank_volume: float
    accumulator_dead_volume: float
    precharge_pressure: float
    polytropic_exponent: float = 1.4

    def problems(self) -> list[str]:
        """Every problem with the parameters, as sentences."""
        out: list[str] = []
        check_positive("accumulator_volume", self.accumulator_volume, out, "m3")
        check_positive("gas_bank_volume", self.gas_bank_volume, out, "m3", zero_ok=True)
        check_positive(
            "accumulator_dead_volume", self.accumulator_dead_volume, out, "m3", zero_ok=True
        )
        check_positive("precharge_pressure", self.precharge_pressure, out, "Pa")
        if self.accumulator_dead_volume >= self.accumulator_volume > 0.0:
            out.append(
                "parameter 'accumulator_dead_volume' must be smaller than 'accumulator_volume'"
            )
        if not self.dead_volume > 0.0:
            out.append(
                "the gas needs a dead volume > 0 m3: set 'gas_bank_volume' or "
                "'accumulator_dead_volume' > 0 (gas cannot be compressed to nothing)"
            )
        if not (1.0 <= self.polytropic_exponent <= 2.0):
            out.append(
                "parameter 'polytropic_exponent' must lie in [1, 2] (1 isothermal, "
                f"1.4 adiabatic), got {self.polytropic_exponent}"
            )
        return out

    @property
    def full_volume(self) -> float:
        """Gas volume with the accumulator empty of oil, m^3."""
        return self.accumulator_volume + self.gas_bank_volume

    @property
    def dead_volume(self) -> float:
        """Gas volume with the accumulator full of oil, m^3."""
        return self.accumulator_dead_volume + self.gas_bank_volume


@dataclass(frozen=True)
class OilSpec:
    """Oil properties beyond those of the line.

    Parameters
    ----------
    bulk_modulus : float
        Effective bulk modulus, Pa.
    volume : float
        Oil volume whose compressibility is modelled, m^3; 0 means the
        chamber at the initial position plus the line.
    cavitation_pressure : float
        Absolute pressure below which the oil column would cavitate, Pa.
    """

    bulk_modulus: float = 1.5e9
    volume: float = 0.0
    cavitation_pressure: float = 1.0e4

    def problems(self) -> list[str]:
        """Every problem with the parameters, as sentences."""
        out: list[str] = []
        check_positive("bulk_modulus", self.bulk_modulus, out, "Pa")
        check_positive("oil_volume", self.volume, out, "m3", zero_ok=True)
        check_positive("cavitation_pressure", self.cavitation_pressure, out, "Pa", zero_ok=True)
        return out


@dataclass(frozen=True)
class HydraulicsSpec:
    """Everything physical about one cylinder-accumulator unit."""

    cylinder: CylinderSpec
    accumulator: AccumulatorSpec
    line: HydraulicLine
    oil: OilSpec
    seal: SealSpec
    stops: EndStopSpec

    def problems(self) -> list[str]:
        """Every problem with every part, as sentences."""
        return (
            self.cylinder.problems()
            + self.accumulator.problems()
            + self.line.problems()
            + self.oil.problems()
            + self.seal.problems()
            + self.stops.problems(self.cylinder.stroke)
        )


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


class HydraulicsModel:
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
        self.seal = RodSeal(spec.seal, self.mass) if self.friction_on else None
        self._viscous = self.seal.viscous if self.seal is not None else 0.0
        self.stops = EndStops(spec.stops, self.cyl.stroke, self.mass) if self.stops_on else None
        self._guard_kinds = self._build_guards()
        self._directions = np.array(
            [0.0 if kind == "pad" else -1.0 for kind, _ in self._guard_kinds]
        )
        self.solver = make_solver(solver)
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
        self.friction_on = "seal_friction" in effects
        self.stops_on = "end_stops" in effects

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
        return make_solver(replace(settings, max_step=fine))

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
        """Gas volume at state ``x``, m^3."""
        if self.layout.gas_volume >= 0:
            return float(x[self.layout.gas_volume])
        return self.oil_constant + self.sa * float(x[0])

    def evaluate(self, x: np.ndarray, energy: bool = False) -> _Point:
        """Pressures, flow, forces, losses (and stored energy if ``energy``) at state ``x``."""
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

    def _choose_oil_side(self):
        """The oil side's equations for the effects chosen (chosen once, at build).

        Each gives, at a state, the chamber pressure (Pa), the line flow (m^3/s), the line's
        loss (W) and the energy stored in oil and line (J).
        """
        if not self.compressible:
            return self._rigid_column if self.losses else self._lossless_rigid_column
        if self.layout.chamber_pressure < 0:
            return self._one_pressure_node
        return self._two_pressure_nodes

    def _lossless_rigid_column(self, x: np.ndarray, vel: float, v_gas: float, p_g: float):
        """Incompressible oil, lossless line: the chamber is at the gas pressure."""
        return p_g, self.sa * vel, 0.0, 0.0

    def _rigid_column(self, x: np.ndarray, vel: float, v_gas: float, p_g: float):
        """Incompressible oil: the line's drop at the rod's flow."""
        flow = self.sa * vel
        drop = (self.r_l + self.r_t * abs(flow)) * flow
        return p_g - drop, flow, drop * flow, 0.0

    def _one_pressure_node(self, x: np.ndarray, vel: float, v_gas: float, p_g: float):
        """Compressible oil with a lossless, massless line: oil and gas in parallel."""
        c_gas = v_gas / (self.exponent * p_g)
        flow = self.sa * vel * c_gas / (c_gas + self.compliance)
        return p_g, flow, 0.0, 0.5 * self.compliance * p_g * p_g

    def _two_pressure_nodes(self, x: np.ndarray, vel: float, v_gas: float, p_g: float):
        """Compressible oil in the chamber, the line between it and the gas (losses, mass)."""
        lay = self.layout
        p_c = float(x[lay.chamber_pressure])
        stored = 0.5 * self.compliance * p_c * p_c
        if lay.flow >= 0:
            flow = float(x[lay.flow])
            stored += 0.5 * self.inertance * flow * flow
        else:
            flow = self.line.flow(p_g - p_c)
        drop = (self.r_l + self.r_t * abs(flow)) * flow
        return p_c, flow, drop * flow, stored

    def _accelerate(self, point: _Point) -> tuple[float, float, float]:
        """Acceleration (m/s^2), seal friction force on the rod (N) and its loss (W)."""
        if self.seal is None:
            return point.force / self.mass, 0.0, 0.0
        return self.seal.accelerate(point.force, point.v)

    def chamber_pressure(self, point: _Point, acceleration: float) -> float:
        """Pressure at the cylinder port, Pa (includes ``-L dq/dt`` of an incompressible column)."""
        if self.has_inertance and not self.compressible:
            return point.chamber_pressure - self.inertance * self.sa * acceleration
        return point.chamber_pressure

    # ------------------------------------------------ HybridSystem protocol
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """State derivative: ``[x', v', (V_g', p_c', q'), dissipated']``."""
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
        """Seal stick/slip, limits, stop contact and cushion zones (see :meth:`_guard`)."""
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
        """Refuse at a limit; otherwise switch contact, cushion and seal modes."""
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
                raise HydraulicLimitError(self.limit_message(kind, end, x, t))
        x = self._settle_friction(x, seal_fired)
        if not kinks_only:
            logger.debug("t = %.9g s: events so far this step: %s", t, "; ".join(self.last_events))
        self.mode_changes += 0 if kinks_only else 1
        x = self.project(x)
        if self._refining and self._resolution(t, x) != self._current_resolution:
            raise _Resolve(t, x)
        return x

    def limit_message(self, kind: str, end: int, x: np.ndarray, t: float) -> str:
        """Why a limit refuses the step, with the quantities involved."""
        acc = self.spec.accumulator
        v_gas = self.gas_volume(x)
        if kind == "gas_dead":
            return (
                f"gas volume {v_gas:.6g} m3 reached its dead volume {acc.dead_volume:.6g} m3 "
                f"at t = {t:.9g} s (accumulator full of oil; gas pressure "
                f"{self.gas.pressure(max(v_gas, acc.dead_volume)):.6g} Pa): "
                "the rod is driven towards zero gas volume"
            )
        if kind == "gas_empty":
            return (
                f"gas volume {v_gas:.6g} m3 reached the empty-accumulator volume "
                f"{acc.full_volume:.6g} m3 at t = {t:.9g} s: no oil left to feed the cylinder"
            )
        if kind == "cavitation":
            point = self.evaluate(x)
            p_c = self.chamber_pressure(point, self._accelerate(point)[0])
            return (
                f"chamber pressure {p_c:.6g} Pa fell to the cavitation pressure "
                f"{self.spec.oil.cavitation_pressure:.6g} Pa at t = {t:.9g} s "
                f"(rod velocity {x[1]:.6g} m/s)"
            )
        where = "below 0 m" if end == RETRACTED else f"beyond the stroke {self.cyl.stroke:.6g} m"
        return (
            f"rod extension {x[0]:.6g} m went {where} at t = {t:.9g} s; "
            "add the effect 'end_stops' to model cushions and stops"
        )

    def project(self, x: np.ndarray) -> np.ndarray:
        """Hold a stuck rod exactly where it stuck, at rest."""
        if self.seal is not None and self.seal.stuck:
            x[0] = self.seal.held_position
            x[1] = 0.0
        return x

    # ------------------------------------------------------------ modes
    def _settle_friction(self, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Make the seal's mode consistent with the forces at ``x``."""
        if self.seal is None:
            return x
        point = self.evaluate(x)
        x[1], event = self.seal.settle(float(x[0]), float(x[1]), point.force, fired)
        if event:
            self.last_events.append(event)
        return x

    def check_limits(self, t: float, x: np.ndarray) -> None:
        """Raise :class:`HydraulicLimitError` if a limit guard is already violated at ``x``."""
        point = self.evaluate(x)
        acc, link, _ = self._accelerate(point)
        for kind, end in self._guard_kinds:
            if kind in ("gas_dead", "gas_empty", "cavitation", "stroke"):
                if self._guard(kind, end, point, acc, link) < 0.0:
                    raise HydraulicLimitError(self.limit_message(kind, end, x, t))

    # ---------------------------------------------------------- initial state
    def equilibrium_pressure(self, force: float) -> float:
        """Absolute chamber pressure holding the rod at rest against ``force`` (N), Pa."""
        weight = self.cyl.moving_mass * self.cyl.gravity_along_rod
        return self.cyl.ambient_pressure - (force + weight) / self.sa

    def initialize(
        self, force: float, *, position: float, velocity: float, gas_pressure: float | None
    ) -> None:
        """Set the state; ``gas_pressure`` None means static equilibrium with ``force``.

        The gas was charged slowly (isothermally) from the pre-charge to the
        initial pressure; from there on it follows ``p V^n = p0 V0^n``.

        Raises
        ------
        ConfigurationError
            If the start is impossible (pressure, oil in the accumulator,
            position), listing every problem.
        """
        self.force = float(force)
        p0 = self.equilibrium_pressure(force) if gas_pressure is None else float(gas_pressure)
        self._check_start(p0, position, velocity)
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

    def _check_start(self, pressure: float, position: float, velocity: float) -> None:
        problems = []
        acc = self.spec.accumulator
        if not (pressure > 0.0 and math.isfinite(pressure)):
            problems.append(
                f"initial gas pressure must be > 0 Pa, got {pressure:.6g} Pa (the "
                "rod force would pull the rod out against vacuum)"
            )
        elif pressure < acc.precharge_pressure * (1.0 - 1e-12):
            problems.append(
                f"initial gas pressure {pressure:.6g} Pa is below the pre-charge "
                f"{acc.precharge_pressure:.6g} Pa: the accumulator would hold no oil; "
                "lower 'precharge_pressure' or raise the load"
            )
        elif (
            isothermal_charge_volume(acc.precharge_pressure, acc.full_volume, pressure)
            <= acc.dead_volume
        ):
            problems.append(
                f"initial gas pressure {pressure:.6g} Pa needs more oil than the "
                f"accumulator holds (pre-charge {acc.precharge_pressure:.6g} Pa); "
                "raise 'precharge_pressure' or lower the load"
            )
        if not (0.0 <= position <= self.cyl.stroke):
            problems.append(
                f"parameter 'initial_position' must lie in [0, stroke = "
                f"{self.cyl.stroke:.6g}] m, got {position}"
            )
        if not math.isfinite(velocity):
            problems.append(f"parameter 'initial_velocity' must be finite, got {velocity}")
        if problems:
            raise ConfigurationError("hydraulics", problems)

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

    # -------------------------------------------------------------- stepping
    def advance(self, t: float, h: float, force: float) -> int:
        """Advance from ``t`` by ``h`` (s) with the rod ``force`` (N) held; return events.

        Raises
        ------
        HydraulicLimitError
            At a limit (the caller restores the state and refuses the step).
        """
        self.last_events = []
        self.force = float(force)
        self.check_limits(t, self.state)
        self.state = self.settle(self.state)
        start = float(self.state[0])
        x, events = self._integrate(t, self.state, t + h)
        self.state = x
        self.external_work += self.force * (float(x[0]) - start)
        return events

    def settle(self, x: np.ndarray) -> np.ndarray:
        """Seal mode consistent with the force now held (it may have jumped); the new state."""
        before = self._seal_mode()
        x = self._settle_friction(np.array(x, dtype=float), [])
        self.mode_changes += int(self._seal_mode() != before)
        return self.project(x)

    def _seal_mode(self) -> list[int]:
        return [] if self.seal is None else self.seal.friction.get_mode()

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
                solver = make_solver(replace(self.settings, max_step=h))
                return solver, min(t_end, t + CUSHION_CHUNK_STEPS * h)
        return self.solver, t_end

    # ----------------------------------------------------------------- report
    def stored_energy(self) -> float:
        """Stored energy at the current state, J (see the module docstring)."""
        return self.evaluate(self.state, energy=True).stored

    @property
    def dissipated_energy(self) -> float:
        """Energy dissipated since the start, J."""
        return float(self.state[self.layout.dissipated])

    def report(self) -> dict[str, float]:
        """Physical quantities at the current state, for outputs."""
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

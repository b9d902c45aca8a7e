"""The hydraulic cylinder with gas accumulator as a co-simulation unit.

Port (power bond)
-----------------
``rod``
    Input ``rod.force`` (N): the external force on the rod along its
    extension direction (positive pushes the rod out). In a riser tensioner
    it is the block train's ``mover_a.force`` (the rope's force on the
    driven body along the body's direction, which is the rod's extension
    direction), negative because the rope pulls the rod in. Outputs
    ``rod.position`` (m, extension from fully retracted) and
    ``rod.velocity`` (m/s) are states of the rod mass and depend on no
    input: the rope's compliance lives in the block train, the cut is at
    the rod's inertia. ``rod.displacement`` (m) is the extension since the
    start, for a block train whose reeving is drawn at the initial position.
    Power into the hydraulics through the rod is ``rod.force * rod.velocity``.

Interface model (flow side of the bond)
---------------------------------------
Inputs ``rod.stiffness`` ``K`` (N/m), ``rod.damping`` ``D`` (N s/m),
``rod.effort_rate`` ``R`` (N/s), ``rod.reference_position`` ``d_ref`` (m, in
``rod.displacement``'s convention) and ``rod.reference_velocity`` ``v_ref`` (m/s):
the block train's ``mover_a.stiffness`` ... ``mover_a.reference_velocity``. Over a
step from ``t0`` the rod is then integrated against

``F = rod.force - K (rod.displacement - d_ref) - D (rod.velocity - v_ref) + R (t - t0)``

instead of the held ``rod.force``: the rope's stiff spring acts inside the cylinder's
own implicit solver, a stuck seal breaks away where ``|F|`` reaches the breakaway
force (located inside the step), and ``external_work`` books the work of ``F`` on the
rod. All 0 (their start values): the held force, bit for bit. ``K`` and ``D`` must
not be negative (the step is refused, naming the input). See
:mod:`wire_fmu.core.units.hydraulics.interface`.

Outputs that depend on the input within a step
----------------------------------------------
``rod.acceleration``, ``seal.friction_force`` (a stuck seal holds whatever
the forces need), ``chamber.pressure`` and ``hydraulic_force`` (with
``line_inertance`` and incompressible oil the line's oil column is
accelerated with the rod), through ``rod.force`` and its interface model (set
inputs start the local model afresh at the present time). Everything else is a
function of the state.

Initial state
-------------
With ``initial_equilibrium`` (the default) the unit starts at rest at
``initial_position`` in static equilibrium with the value of ``rod.force``
at initialisation (with the interface model's, at the start): the gas pressure is set
so that ``s A (p - p_amb) + rod.force + m g_rod = 0`` (the gas having been charged
slowly from the pre-charge, so its volume is ``V_full p_precharge / p``),
the line is at rest and a seal starts stuck with no load on it: no start-up
transient. Otherwise the gas starts at ``initial_gas_pressure`` and the rod
moves at ``initial_velocity``.

Parameter defaults and where they come from
-------------------------------------------
A push-type (bore-pressurised) cylinder of a single wire-line riser
tensioner reeved 4:1 (paper 000, Fig. 6; the reeving
:func:`wire_fmu.core.units.block_train.reevings.riser_tensioner`: vertical cylinder, rod
extending upwards, so ``gravity_along_rod = -9.81``), sized for the common
80 kip (356 kN) wire-line tensioner class with about 50 ft (15 m) of wire
travel: 4 x 356 kN = 1.42 MN on the rod over a 3.81 m (12.5 ft) stroke.

* Bore 14 in (0.356 m) gives 14.7 MPa (2130 psi) working pressure at that
  load, within the 2000-3000 psi class of such tensioners; rod 9 in
  (0.229 m), thick against buckling (estimate).
* Moving mass 3500 kg: rod about 1450 kg (9 in x 4.5 m steel), piston
  about 250 kg, moving sheave cluster (two 60 in sheaves and yoke) about
  1800 kg (estimate).
* Gas: air/oil accumulator 0.6 m^3 (the swept volume is 0.38 m^3) and
  3.0 m^3 of air pressure vessels, so that the tension varies by about
  10-15 % over the full stroke (API RP 16Q asks for a tension variation
  the designer states; the gas volume is chosen for it). Pre-charge
  13.5 MPa leaves about 0.3 m^3 of oil in the accumulator at mid stroke.
  ``polytropic_exponent`` 1.4: nitrogen/air, adiabatic (fast heave).
* Line: 15 m of 6 in (0.152 m) bore pipe and hose; mineral oil ISO VG 32
  at 40 C: 870 kg/m^3, 0.028 Pa s; Darcy factor 0.025 (Blasius at
  Re ~ 2e4); minor losses K = 5 for the velocity-limiting (anti-recoil)
  valve that API RP 16Q places between each tensioner and its air/oil
  bottle, bends, entry and exit (estimate).
* Oil: effective bulk modulus 1.5 GPa (mineral oil about 1.7 GPa, less
  with entrained air and pipe compliance); cavitation at 0.1 bar absolute.
* Seals: breakaway 25 kN (about 1.7 % of the rated force; large cylinder
  seals take 1-3 %), Coulomb 15 kN, viscous 2e4 N s/m, Stribeck velocity
  0.01 m/s (estimates).
* End stops: 0.15 m cushions with ``c = 1e5 N s^2/m^2``: 2.5 MN at 5 m/s,
  enough to catch a rod that runs away when a wire breaks (1.46 MN of gas
  force), and an e-folding length ``m / c = 35 mm`` well inside the cushion;
  stop 1e9 N/m, restitution 0.3 (estimates).
* Solver ``ros2``, 1 ms: linearly implicit and L-stable, so the stiff oil
  column (line time constant ``R_l C`` about 10 microseconds) and the stuck
  seal cost no more than the gas spring, and its fixed steps make FMU runs
  bit-reproducible; during stop impacts and cushion runs the model refines
  the fixed step itself (see :mod:`wire_fmu.core.units.hydraulics.model`, Numerics).
  ``radau`` is the adaptive alternative, e.g. for a line restricted so much
  that its turbulent loss changes stiffness by orders of magnitude within
  one communication step (ROS2 keeps one Jacobian per step).

Connecting it to a block train
------------------------------
``rope.mover_a.force -> rod.force`` and ``rod.velocity ->
rope.mover_a.velocity``, and with the interface model ``rope.mover_a.{stiffness,
damping, effort_rate, reference_position, reference_velocity} -> rod.{...}`` (the
port ``rod`` declares them); for the position use ``rod.displacement`` (what the
port declares, and what ``reference_position`` is measured in) when the
reeving is drawn at the initial extension (as
:func:`~wire_fmu.core.units.block_train.reevings.riser_tensioner` is, at mid stroke, the default
``initial_position``), ``rod.position`` when it is drawn fully retracted.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping
from operator import itemgetter
from typing import Any

import numpy as np

from wire_fmu.core.components.hydraulic_line import HydraulicLine
from wire_fmu.core.components.rod_seal import SealSpec
from wire_fmu.core.errors import ConfigurationError, ModelError
from wire_fmu.core.framework.interface_model import inputs_taken
from wire_fmu.core.framework.ports import PortSide, port
from wire_fmu.core.framework.solver_options import solver_settings
from wire_fmu.core.framework.unit import OdeView, Unit
from wire_fmu.core.units.hydraulics.interface import (
    INTERFACE_INPUTS,
    NO_INTERFACE,
    RodInterface,
)
from wire_fmu.core.units.hydraulics.kernel import QUIET_OUTPUTS, REPORT
from wire_fmu.core.units.hydraulics.model import (
    HYDRAULICS_EFFECTS,
    AccumulatorSpec,
    CylinderSpec,
    EndStopSpec,
    HydraulicsModel,
    HydraulicsSpec,
    OilSpec,
)
from wire_fmu.core.units.hydraulics.variables import DEFAULT_ROD_FORCE, variables

__all__ = ["HydraulicsUnit", "DEFAULT_ROD_FORCE"]


logger = logging.getLogger(__name__)

_OUTPUT_OF = {  # the model's report quantity: the output that shows it
    "position": "rod.position",
    "velocity": "rod.velocity",
    "acceleration": "rod.acceleration",
    "chamber_pressure": "chamber.pressure",
    "hydraulic_force": "hydraulic_force",
    "gas_pressure": "gas.pressure",
    "gas_volume": "gas.volume",
    "flow": "line.flow",
    "oil_in_accumulator": "accumulator.oil_volume",
    "stiffness": "hydraulic_stiffness",
    "stop_force": "end_stop.force",
    "friction_force": "seal.friction_force",
    "stored_energy": "stored_energy",
}
_QUIET_OUTPUT_OF = {  # the kernel's quiet step's other quantities: their outputs
    "displacement": "rod.displacement",
    "stroke_used": "stroke_used",
    "dissipated_energy": "dissipated_energy",
    "external_work": "external_work",
    "energy_balance": "energy_balance",
}
_REPORTED_OUTPUTS = tuple(_OUTPUT_OF[name] for name in REPORT)
"""The outputs that show the model's report, in the order of its values."""
_QUIET_OUTPUTS = tuple(_OUTPUT_OF.get(name) or _QUIET_OUTPUT_OF[name] for name in QUIET_OUTPUTS)
"""The outputs a quiet step writes, in the order of its values: every one but the modes'
(``seal.stuck``, ``end_stop.contact``, ``mode_changes``), which such a step keeps."""
_FLAT_INPUTS = ("rod.force", *INTERFACE_INPUTS)
"""The inputs a step takes, in the order the quiet step reads them."""
_read_flat_inputs = itemgetter(*_FLAT_INPUTS)
_STIFFNESS_AT = _FLAT_INPUTS.index("rod.stiffness")


class HydraulicsUnit(Unit):
    """Hydraulic cylinder with gas accumulator and gas bank (SPEC sections 11-12)."""

    NAME = "Hydraulics"
    DESCRIPTION = "Hydraulic cylinder with gas accumulator (hydro-pneumatic spring), wire_fmu"
    VARIABLES = variables()
    PORTS = (
        port(
            "rod",
            "translational",
            PortSide.flow,
            "force",
            "velocity",
            "displacement",
            "the rod",
            interface=True,
        ),
    )

    def __init__(self, instance_name: str = "hydraulics") -> None:
        super().__init__(instance_name)
        self.model: HydraulicsModel | None = None
        self.initial_energy = 0.0
        self.time = 0.0

    @property
    def who(self) -> str:
        """``"Hydraulics '<instance>'"``, the prefix of every message."""
        return f"{self.NAME} {self.instance_name!r}"

    # ------------------------------------------------------------ life cycle
    def configure(self) -> None:
        """Parse effects, solver and physical parameters; build the model.

        Raises
        ------
        ConfigurationError
            Listing every problem with the parameters.
        """
        v = self.values
        problems: list[str] = []
        effects, effect_problems = HYDRAULICS_EFFECTS.parse(v["effects"])
        problems += [f"parameter 'effects': {p}" for p in effect_problems]
        settings, solver_problems = solver_settings(v)
        problems += solver_problems
        spec = self.spec()
        problems += spec.problems()
        problems += self._initial_problems()
        if problems:
            raise ConfigurationError(self.who, problems)
        self.model = HydraulicsModel(spec, effects, settings)

    def spec(self) -> HydraulicsSpec:
        """The physical parameters now in :attr:`values`, unvalidated."""
        v = {k: val for k, val in self.values.items()}
        f = {k: float(val) for k, val in v.items() if not isinstance(val, str | bool)}
        return HydraulicsSpec(
            cylinder=CylinderSpec(
                f["bore_diameter"],
                f["rod_diameter"],
                f["stroke"],
                f["moving_mass"],
                str(v["pressurised_side"]),
                f["chamber_dead_volume"],
                f["gravity_along_rod"],
                f["ambient_pressure"],
            ),
            accumulator=AccumulatorSpec(
                f["accumulator_volume"],
                f["gas_bank_volume"],
                f["accumulator_dead_volume"],
                f["precharge_pressure"],
                f["polytropic_exponent"],
            ),
            line=HydraulicLine(
                f["line_length"],
                f["line_diameter"],
                f["oil_density"],
                f["oil_viscosity"],
                f["line_friction_factor"],
                f["line_loss_coefficient"],
            ),
            oil=OilSpec(f["bulk_modulus"], f["oil_volume"], f["cavitation_pressure"]),
            seal=SealSpec(
                f["seal_static_friction"],
                f["seal_coulomb_friction"],
                f["seal_viscous_friction"],
                f["seal_stribeck_velocity"],
            ),
            stops=EndStopSpec(
                f["cushion_length"],
                f["cushion_coefficient"],
                f["stop_stiffness"],
                f["stop_restitution"],
            ),
        )

    def _initial_problems(self) -> list[str]:
        v = self.values
        out = []
        if bool(v["initial_equilibrium"]) and float(v["initial_velocity"]) != 0.0:
            out.append(
                "parameter 'initial_velocity' must be 0 with initial_equilibrium "
                f"(static equilibrium is at rest), got {v['initial_velocity']}"
            )
        if not bool(v["initial_equilibrium"]) and not float(v["initial_gas_pressure"]) > 0.0:
            out.append(
                f"parameter 'initial_gas_pressure' must be > 0 Pa, got {v['initial_gas_pressure']}"
            )
        return out

    def initialize(self, start_time: float) -> None:
        """Initial state (equilibrium or as given); outputs filled.

        Implements :meth:`Unit.initialize`.
        """
        model = self._require_model()
        v = self.values
        pressure = None if bool(v["initial_equilibrium"]) else float(v["initial_gas_pressure"])
        bad = self.input_problems()
        if bad:
            raise ConfigurationError(self.who, [f"initial inputs: {p}" for p in bad])
        try:
            model.initialize(
                float(v["rod.force"]),
                position=float(v["initial_position"]),
                velocity=float(v["initial_velocity"]),
                gas_pressure=pressure,
                interface=self.rod_interface(start_time),
            )
        except ConfigurationError as err:
            raise ConfigurationError(self.who, err.problems) from None
        except ModelError as err:
            raise ConfigurationError(self.who, [f"initial state: {err}"]) from None
        self.time = float(start_time)
        self.initial_energy = model.stored_energy()
        self._update_outputs()

    def input_problems(self) -> list[str]:
        """Inputs the cylinder cannot step with: not finite, or a negative spring or damper
        in the interface model (each named)."""
        return self._input_problems(self.rod_interface(self.time))

    def _input_problems(self, interface: RodInterface) -> list[str]:
        """:meth:`input_problems`, the interface model in the inputs being ``interface``."""
        return self.non_finite_inputs(_FLAT_INPUTS) + interface.problems("rod")

    def _take_quiet_step(self, time: float, step: float) -> bool:
        """A step in which nothing happens, outputs included, in one compiled call
        (:meth:`HydraulicsModel.quiet_step_outputs
        <wire_fmu.core.units.hydraulics.stepping.RefinedStepping.quiet_step_outputs>`).

        Implements :meth:`Unit._take_quiet_step`: inputs the cylinder cannot take, and
        steps that are not quiet, go the general way, which names why.
        """
        model = self.model
        if model is None or not model.compiled:
            return False
        flat = tuple(map(float, _read_flat_inputs(self.values)))
        if not inputs_taken(flat, _STIFFNESS_AT):
            return False
        force, stiffness, damping, rate, *reference = flat
        if stiffness != 0.0 or damping != 0.0 or rate != 0.0:
            interface = RodInterface(stiffness, damping, rate, *reference, start=float(time))
        else:
            interface = NO_INTERFACE
        outputs = model.quiet_step_outputs(time, step, force, interface, self.initial_energy)
        if outputs is None:
            return False
        self.values.update(zip(_QUIET_OUTPUTS, outputs))  # noqa: B905 - as many by construction
        self.time = time + step
        return True

    def rod_interface(self, start: float) -> RodInterface:
        """The interface model of the rod force in the inputs now set, about ``start`` (s).

        Parameters
        ----------
        start : float
            The communication point ``t0`` the model is about, s.
        """
        values = map(float, map(self.values.__getitem__, INTERFACE_INPUTS))
        return RodInterface(*values, start=float(start))

    def _advance(self, time: float, step: float) -> list[str]:
        """Integrate the cylinder against ``rod.force`` (held, or its interface model);
        refuse at a limit (ModelError)."""
        model = self._require_model()
        model.advance(time, step, float(self.values["rod.force"]), self.rod_interface(time))
        return list(model.last_events)

    def evaluate_outputs(self) -> None:
        """Feedthrough outputs for the rod force and interface model now set, at the present
        time; the state is untouched."""
        model = self._require_model()
        held = model.load
        model.force = float(self.values["rod.force"])
        model.interface = self.rod_interface(self.time)
        model.time = self.time
        try:
            self._update_outputs()
        finally:
            model.force, model.interface, model.time = held

    def ode(self) -> OdeView:
        """The cylinder's hybrid ODE, for a monolithic model."""
        return _HydraulicsOde(self)

    # ---------------------------------------------------------------- state
    def get_state(self) -> dict[str, Any]:
        """Complete state: continuous state, modes, held input, gas reference."""
        m = self._require_model()
        interface = m.interface
        return {
            "x": m.state.tolist(),
            "force": float(m.force),
            "interface": [
                float(interface.stiffness),
                float(interface.damping),
                float(interface.effort_rate),
                float(interface.reference_position),
                float(interface.reference_velocity),
                float(interface.start),
            ],
            "model_time": float(m.time),
            "stops": None if m.stops is None else m.stops.get_state(),
            "seal": None if m.seal is None else m.seal.get_state(),
            "mode_changes": int(m.mode_changes),
            "external_work": float(m.external_work),
            "gas_reference": [float(m.gas.reference_pressure), float(m.gas.reference_volume)],
            "compliance": float(m.compliance),
            "oil_constant": float(m.oil_constant),
            "initial_position": float(m.initial_position),
            "time": float(self.time),
            "initial_energy": float(self.initial_energy),
        }

    def _snapshot(self) -> tuple:
        """What a step changes, copied (cheaper than :meth:`get_state`)."""
        m = self._require_model()
        return (
            m.state.copy(),
            m.load,
            None if m.stops is None else m.stops.snapshot(),
            None if m.seal is None else m.seal.snapshot(),
            m.mode_changes,
            m.external_work,
            self.time,
        )

    def _restore_snapshot(self, saved: tuple) -> None:
        """Implements :meth:`Unit._restore_snapshot`."""
        m = self._require_model()
        m.state, load, stops, seal, m.mode_changes, m.external_work, self.time = saved
        m.force, m.interface, m.time = load
        if m.stops is not None:
            m.stops.restore(stops)
        if m.seal is not None:
            m.seal.restore(seal)
        self._update_outputs()

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore a state from :meth:`get_state`.

        Parameters
        ----------
        state : mapping
            A state returned by :meth:`get_state` of this unit.
        """
        from wire_fmu.core.components.gas import PolytropicGas

        m = self._require_model()
        m.state = np.array(state["x"], dtype=float)
        m.force = float(state["force"])
        interface = state.get("interface")
        m.interface = NO_INTERFACE if interface is None else RodInterface(*map(float, interface))
        m.time = float(state.get("model_time", state["time"]))
        if m.stops is not None:
            m.stops.set_state(state["stops"])
        if m.seal is not None:
            m.seal.set_state(state["seal"])
        m.mode_changes = int(state["mode_changes"])
        m.external_work = float(state["external_work"])
        p0, v0 = state["gas_reference"]
        m.gas = PolytropicGas(float(p0), float(v0), m.exponent)
        m.compliance = float(state["compliance"])
        m.oil_constant = float(state["oil_constant"])
        m.initial_position = float(state["initial_position"])
        self.time = float(state["time"])
        self.initial_energy = float(state["initial_energy"])
        self._update_outputs()

    # -------------------------------------------------------------- helpers
    def _update_outputs(self) -> None:
        m = self._require_model()
        values = m.report_values()
        out = self.values
        # one value per name (tests/test_hydraulics_kernel.py holds it); strict= costs a
        # keyword parse every step
        out.update(zip(_REPORTED_OUTPUTS, values))  # noqa: B905
        position = out["rod.position"]
        out["rod.displacement"] = position - m.initial_position
        out["stroke_used"] = position / m.cyl.stroke
        out["seal.stuck"] = m.seal is not None and m.seal.stuck
        out["end_stop.contact"] = m.stops is not None and any(m.stops.contact)
        out["dissipated_energy"] = m.dissipated_energy
        out["external_work"] = float(m.external_work)
        out["energy_balance"] = (
            out["stored_energy"]
            - self.initial_energy
            + out["dissipated_energy"]
            - out["external_work"]
        )
        out["mode_changes"] = int(m.mode_changes)
        if not all(map(math.isfinite, values)):
            report = dict(zip(REPORT, values, strict=True))
            raise FloatingPointError(f"{self.who}: non-finite outputs {report}")


class _HydraulicsOde(OdeView):
    """:class:`HydraulicsUnit` as a piece of a monolithic ODE.

    The state is the model's, ``[x, v, (V_g, p_c, q), dissipated]``, followed
    by the external work: in a monolithic model ``rod.force`` varies within a
    step, so its work ``force * v`` is integrated rather than booked per step.
    The unit's own step refinement (stop impacts, cushions) is not used here;
    the monolithic solver chooses its steps. A limit still raises
    :class:`~wire_fmu.core.units.hydraulics.model.HydraulicLimitError` from ``handle_events``.
    """

    def __init__(self, unit: HydraulicsUnit) -> None:
        self.unit = unit
        self.model = unit._require_model()

    @property
    def state(self) -> np.ndarray:
        """``[model state, external work]`` (a copy)."""
        return np.append(self.model.state, self.model.external_work)

    def set_state(self, x: np.ndarray, t: float) -> None:
        """Adopt ``x`` at ``t`` and refresh the outputs.

        Implements :meth:`OdeView.set_state`.
        """
        self.model.state = np.array(x[:-1], dtype=float)
        self.model.external_work = float(x[-1])
        self.unit.time = t
        self.bind_inputs(t)
        self.unit._update_outputs()

    def bind_inputs(self, t: float) -> None:
        """``rod.force`` in ``values`` is the force at ``t`` (exact: no interface model).

        Parameters
        ----------
        t : float
            Time, s.
        """
        self.model.force = float(self.unit.values["rod.force"])
        self.model.interface = NO_INTERFACE
        self.model.time = t

    def publish(self, t: float, x: np.ndarray) -> None:
        """Outputs of ``x`` at ``t`` into ``values`` (state left alone).

        Implements :meth:`OdeView.publish`.
        """
        m = self.model
        saved = m.state, m.external_work, self.unit.time
        m.state, m.external_work, self.unit.time = np.asarray(x[:-1], dtype=float), float(x[-1]), t
        try:
            self.unit._update_outputs()
        finally:
            m.state, m.external_work, self.unit.time = saved

    def rhs(self, t, x):
        """Model derivative, then the power ``force * dx/dt`` into the rod port.

        Implements :meth:`OdeView.rhs`.
        """
        derivative = self.model.rhs(t, x[:-1])
        return np.append(derivative, self.model.force * derivative[0])

    def guards(self, t, x):
        """See :meth:`HydraulicsModel.guards`.

        Implements :meth:`OdeView.guards`.
        """
        return self.model.guards(t, x[:-1])

    def guard_directions(self):
        """See :meth:`HydraulicsModel.guard_directions`."""
        return self.model.guard_directions()

    def handle_events(self, t, x, fired):
        """See :meth:`HydraulicsModel.handle_events`.

        Implements :meth:`OdeView.handle_events`.
        """
        return np.append(self.model.handle_events(t, x[:-1], fired), x[-1])

    def project(self, x):
        """See :meth:`HydraulicsModel.project`.

        Implements :meth:`OdeView.project`.
        """
        return np.append(self.model.project(np.array(x[:-1], dtype=float)), x[-1])

    def reconcile(self, t, x):
        """The force jumped at ``t``: settle the seal's mode.

        Implements :meth:`OdeView.reconcile`.
        """
        self.bind_inputs(t)
        self.model.state = self.model.settle(x[:-1])
        return self.state

"""Paper 004's machine unit as a co-simulation unit, solvable by the paper's method or a reference.

Ports
-----
``motor``
    Input ``command`` (N m): ``a`` of the characteristic ``M_d = a - b w``
    (``b`` = ``motor_slope``); output ``torque`` (N m, ``a - b w``).
``load``
    Input ``torque`` (N m, an extra resistance on the main shaft, positive
    opposing positive rotation); outputs ``shaft.speed`` (rad/s) and
    ``shaft.angle`` (rad) are states with no direct feedthrough, so a
    partner taking the speed and returning a torque closes a rotational bond.
``cycle``
    Per revolution of the main shaft: ``period`` (s), ``omega_mean``,
    ``omega_max``, ``omega_min`` (rad/s) and the coefficient of
    non-uniformity ``delta = (omega_max - omega_min) / omega_mean``
    (:class:`~wire_fmu.core.units.machine.cycle_statistics.CycleStatistics`; extremes over the
    communication points, updated by :meth:`MachineDriveUnit.advance` -- a
    monolithic model, which has no communication points, leaves them at 0).
``solver``
    ``evaluations`` (torque evaluations so far: right-hand sides, or the
    energy form's first-order steps and corrections) and ``steps``: the
    cost of the solution, next to its accuracy.

Solvers: ``energy`` -- paper 004's energy-form step with successive
second-order refinement to tolerance; ``energy1`` -- its first-order step
alone (:mod:`wire_fmu.core.framework.energy_integrator`); or any reference integrator of
:mod:`wire_fmu.core.framework.hybrid` (``radau`` at tight tolerance is the reference).
The machine's laws are the JSON parameter ``machine``
(:func:`~wire_fmu.core.units.machine.spec.parse_machine`), a crank press by default.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.energy_solver import ENERGY_SOLVERS, make_energy_solver
from wire_fmu.core.framework.hybrid import make_solver
from wire_fmu.core.framework.ports import PortSide, port
from wire_fmu.core.framework.solver_options import solver_parameters, solver_settings
from wire_fmu.core.framework.unit import (
    ModelOdeView,
    OdeView,
    Unit,
    input_,
    output,
    parameter,
)
from wire_fmu.core.units.machine.cycle_statistics import CycleStatistics
from wire_fmu.core.units.machine.model import MachineDriveModel
from wire_fmu.core.units.machine.spec import crank_press, parse_machine

__all__ = ["MachineDriveUnit"]


def _parameters():
    return (
        parameter(
            "machine",
            json.dumps(crank_press()),
            "",
            "Machine as JSON: inertia "
            "(crank_slider or fourier), resistance_angle and resistance_time (Fourier "
            "series), resistance_speed (polynomial); a crank press by default",
            type=str,
        ),
        parameter(
            "motor_slope",
            2117.0,
            "N.m.s/rad",
            "Slope b of the motor characteristic "
            "a - b omega at the main shaft (7.5 kW, 1500 rpm, 3.3 % slip through 1:15; "
            "estimate)",
            min=0.0,
        ),
        parameter("initial_speed", 10.0, "rad/s", "Main shaft speed at the start", min=0.0),
        parameter("initial_angle", 0.0, "rad", "Main shaft angle at the start"),
        *solver_parameters(
            "energy",
            5e-3,
            rtol=1e-8,
            atol=1e-10,
            also=ENERGY_SOLVERS,
            note="energy: paper 004 with refinement; energy1: its first-order step",
        ),
    )


def _inputs():
    return (
        input_(
            "motor.command",
            22170.0,
            "N.m",
            "a of the motor characteristic a - b omega "
            "(b omega_sync of the default motor: 2117 x 10.472)",
        ),
        input_(
            "load.torque",
            0.0,
            "N.m",
            "Extra load torque on the main shaft, positive opposing positive rotation",
        ),
    )


def _outputs():
    return (
        output("shaft.angle", "rad", "Main shaft angle"),
        output("shaft.speed", "rad/s", "Main shaft speed"),
        output("inertia", "kg.m2", "Reduced moment of inertia I(phi)"),
        output("motor.torque", "N.m", "Motor torque a - b omega", depends_on=("motor.command",)),
        output("resistance.angle_torque", "N.m", "Resistance of the angle M_c(phi)"),
        output("resistance.speed_torque", "N.m", "Resistance of the speed M_c(omega)"),
        output(
            "resistance.time_torque",
            "N.m",
            "Resistance of time M_c(t) plus the load input",
            depends_on=("load.torque",),
        ),
        output("cycle.count", "", "Revolutions of the main shaft completed", type=int),
        output("cycle.period", "s", "Duration of the last revolution"),
        output("cycle.omega_mean", "rad/s", "Mean speed of the last revolution, 2 pi / period"),
        output("cycle.omega_max", "rad/s", "Highest speed in the last revolution"),
        output("cycle.omega_min", "rad/s", "Lowest speed in the last revolution"),
        output(
            "cycle.delta",
            "1",
            "Coefficient of non-uniformity of the last revolution, "
            "(omega_max - omega_min) / omega_mean",
        ),
        output(
            "solver.evaluations", "", "Torque evaluations of the internal solver so far", type=int
        ),
        output("solver.steps", "", "Internal steps so far", type=int),
        output("stored_energy", "J", "Kinetic energy I(phi) omega^2 / 2"),
        output("dissipated_energy", "J", "Work of the speed resistance M_c(omega)"),
        output(
            "external_work", "J", "Work of the motor minus that of M_c(phi), M_c(t) and the load"
        ),
        output(
            "energy_balance", "J", "Ledger residual: stored change + dissipated - external work"
        ),
        output(
            "mode_changes", "", "Mode events so far (always 0: the machine is smooth)", type=int
        ),
    )


class MachineDriveUnit(Unit):
    """Machine unit with I(phi), motor a - b omega and resistances of phi, omega, t (paper 004)."""

    NAME = "MachineUnit"
    DESCRIPTION = "Machine unit in steady motion, paper 004's energy-form integrator, wire_fmu"
    VARIABLES = _parameters() + _inputs() + _outputs()
    PORTS = (
        port("load", "rotational", PortSide.flow, "torque", "shaft.speed", "shaft.angle", "shaft"),
    )

    def __init__(self, instance_name: str = "machine") -> None:
        super().__init__(instance_name)
        self.model: MachineDriveModel | None = None
        self.solver = None
        self.cycles = CycleStatistics()
        self.initial_energy = 0.0
        self.time = 0.0

    # ------------------------------------------------------------ life cycle
    def configure(self) -> None:
        """Parse the machine and the solver; list every problem at once."""
        v = self.values
        problems: list[str] = []
        settings, solver_problems = solver_settings(v, also=ENERGY_SOLVERS)
        problems += solver_problems
        spec = None
        try:
            spec, spec_problems = parse_machine(json.loads(v["machine"]))
            problems += [f"parameter 'machine': {p}" for p in spec_problems]
        except (TypeError, ValueError) as err:
            problems.append(f"parameter 'machine' is not valid JSON: {err}")
        slope = float(v["motor_slope"])
        if not (slope >= 0.0 and math.isfinite(slope)):
            problems.append(f"parameter 'motor_slope' must be >= 0 N.m.s/rad, got {slope}")
        for name in ("initial_speed", "initial_angle"):
            if not math.isfinite(float(v[name])):
                problems.append(f"parameter {name!r} must be finite, got {v[name]}")
        if float(v["initial_speed"]) < 0.0:
            problems.append(
                f"parameter 'initial_speed' must be >= 0 rad/s, got {v['initial_speed']}"
            )
        if problems:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", problems)
        self.model = MachineDriveModel(spec, slope)
        self.solver = (
            make_energy_solver(settings)
            if settings.method in ENERGY_SOLVERS
            else make_solver(settings)
        )

    def initialize(self, start_time: float) -> None:
        """Start at ``initial_angle`` and ``initial_speed``.

        Parameters
        ----------
        start_time : float
            Start time, s.
        """
        model = self._require_model()
        self._bind(model)
        model.state = np.array(
            [float(self.values["initial_angle"]), float(self.values["initial_speed"]), 0.0, 0.0]
        )
        self.time = start_time
        self.initial_energy = model.kinetic_energy()
        self.cycles.start(start_time, model.state[0], model.state[1])
        self._update_outputs()

    def input_problems(self) -> list[str]:
        """Inputs that are not finite."""
        return self.non_finite_inputs(("motor.command", "load.torque"))

    def _advance(self, time: float, step: float) -> list[str]:
        """Integrate the machine unit with paper 004's integrator; book its cycles."""
        model = self._require_model()
        self._bind(model)
        x0 = model.state.copy()
        model.state, _ = self.solver.advance(model, time, x0, time + step)
        self.cycles.update(time, x0, time + step, model.state)
        return []

    def evaluate_outputs(self) -> None:
        """Motor and load torques for the inputs now set; the state is untouched."""
        model = self._require_model()
        saved = (model.command, model.load)
        try:
            self._bind(model)
            self._update_outputs()
        finally:
            model.set_inputs(*saved)

    def ode(self) -> OdeView:
        """The machine's ODE, for a monolithic model."""
        return _MachineOde(self, self._require_model())

    # ---------------------------------------------------------------- state
    def get_state(self) -> dict[str, Any]:
        """Continuous state, held inputs, cycle statistics, solver counters."""
        m = self._require_model()
        counters = {"rhs_calls": int(self.solver.rhs_calls), "steps": int(self.solver.steps)}
        if hasattr(self.solver, "fallbacks"):
            counters["fallbacks"] = int(self.solver.fallbacks)
            counters["torque_evaluations"] = int(self.solver.integrator.torque_evaluations)
        return {
            "x": [float(c) for c in m.state],
            "inputs": [float(m.command), float(m.load)],
            "cycles": self.cycles.get_state(),
            "time": float(self.time),
            "initial_energy": float(self.initial_energy),
            "solver": counters,
        }

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore a state from :meth:`get_state`.

        Parameters
        ----------
        state : mapping
            A state from :meth:`get_state`.
        """
        m = self._require_model()
        m.state = np.array(state["x"], dtype=float)
        m.set_inputs(*state["inputs"])
        self.cycles.set_state(state["cycles"])
        self.time = float(state["time"])
        self.initial_energy = float(state["initial_energy"])
        counters = state["solver"]
        self.solver.rhs_calls = int(counters["rhs_calls"])
        self.solver.steps = int(counters["steps"])
        if "fallbacks" in counters:
            self.solver.fallbacks = int(counters["fallbacks"])
            self.solver.integrator.torque_evaluations = int(counters["torque_evaluations"])
        self._update_outputs()

    # -------------------------------------------------------------- helpers
    def _bind(self, model: MachineDriveModel) -> None:
        model.set_inputs(float(self.values["motor.command"]), float(self.values["load.torque"]))

    def _update_outputs(self, x: np.ndarray | None = None) -> None:
        m = self._require_model()
        x = m.state if x is None else x
        phi, omega = float(x[0]), float(x[1])
        unit = m.unit
        out = self.values
        out["shaft.angle"] = phi
        out["shaft.speed"] = omega
        out["inertia"] = unit.inertia(phi)
        out["motor.torque"] = unit.driving_torque(omega)
        out["resistance.angle_torque"] = unit.resistance_angle(phi)
        out["resistance.speed_torque"] = unit.resistance_speed(omega)
        out["resistance.time_torque"] = unit.resistance_time(self.time)
        out["cycle.count"] = int(self.cycles.count)
        for key in ("period", "omega_mean", "omega_max", "omega_min", "delta"):
            out[f"cycle.{key}"] = float(self.cycles.last[key])
        out["solver.evaluations"] = int(self.solver.rhs_calls)
        out["solver.steps"] = int(self.solver.steps)
        stored = m.kinetic_energy(x)
        out["stored_energy"] = stored
        out["dissipated_energy"] = float(x[2])
        out["external_work"] = float(x[3])
        out["energy_balance"] = stored - self.initial_energy + float(x[2]) - float(x[3])
        out["mode_changes"] = 0
        if not (math.isfinite(phi) and math.isfinite(omega) and math.isfinite(stored)):
            raise FloatingPointError(f"{self.instance_name}: non-finite state")


class _MachineOde(ModelOdeView):
    """:class:`MachineDriveUnit` as a piece of a monolithic ODE (inputs read as instantaneous)."""

    def bind_inputs(self, t: float) -> None:
        """Inputs in ``values`` are those at ``t``.

        Parameters
        ----------
        t : float
            Time the inputs belong to, s.
        """
        self.unit._bind(self.model)

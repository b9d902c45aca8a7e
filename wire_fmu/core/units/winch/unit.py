"""The winch (drawworks) as a co-simulation unit: ports, parameters, outputs.

Ports (power bonds)
-------------------
``rope``
    Input ``tension`` (N, from the block train's ``line_a.tension``);
    outputs ``payout`` (m, unstretched rope paid out since the start) and
    ``payout_rate`` (m/s), taken by the block train as ``line_a.payout`` /
    ``line_a.payout_rate``. Power into the winch: ``+tension *
    payout_rate`` (paying out under tension drives the drum). The payout
    outputs come from the drum's state and depend on no input.
``motor``
    Input ``command`` (N m at the motor shaft): the motor torque, or with
    the effect ``motor_characteristic`` the zero-speed torque ``a`` of
    ``M = a - b omega``. Outputs ``speed`` (rad/s) and ``torque`` (N m).
``brake``
    Input ``lever_force`` (N); outputs ``torque`` (N m on the drum),
    ``capacity`` (N m, against paying out) and ``state`` (0 released,
    1 slipping, 2 holding).
``drum``
    Input ``speed_command`` (rad/s), used only in kinetostatic mode (no
    ``drum_inertia``); outputs ``speed``, ``angle``, ``layer``, ``radius``.

All angles, speeds and torques are positive in the paying-out sense
(:mod:`wire_fmu.core.units.winch.model`); torques are on the drum unless said otherwise.

Internal solver
---------------
The default is ``rk4`` with 1 ms steps: the default drive train's fastest
eigenvalue is about 400 1/s (``|lambda| h = 0.4``), where RK4's energy error
is negligible, while the L-stable ``ros2`` damps the shaft modes
numerically (measured on a lowering-and-braking run: ledger residual 4e-3 J
with rk4 against 12 J with ros2, at equal cost). Settings for which RK4
cannot be stable (``|lambda| h >= 2.5``) are refused by :meth:`configure`
with the step size that would do. ``energy``/``energy1`` select paper
004's integrator (:mod:`wire_fmu.core.framework.energy_integrator`) for a rigid drive
train; without ``drum_inertia`` nothing is integrated.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from wire_fmu.core.components.drive_train import DriveChain, default_drive_train, parse_drive_train
from wire_fmu.core.components.drum import Drum
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.energy_solver import ENERGY_SOLVERS
from wire_fmu.core.framework.hybrid import RK4_STABILITY, SolverSettings
from wire_fmu.core.framework.ports import Port, PortSide
from wire_fmu.core.framework.report_outputs import ReportOutputs
from wire_fmu.core.framework.solver_options import solver_parameters, solver_settings
from wire_fmu.core.framework.unit import (
    HeldInputsUnit,
    ModelOdeView,
    OdeView,
    input_,
    output,
    parameter,
)
from wire_fmu.core.units.winch.base import WinchConfig, WinchInputs
from wire_fmu.core.units.winch.brake import BandBrake
from wire_fmu.core.units.winch.drive import WinchModel
from wire_fmu.core.units.winch.kinetostatic import KinetostaticWinch
from wire_fmu.core.units.winch.model import WINCH_EFFECTS, build_winch, fastest_rate

__all__ = ["WinchUnit"]

_FEEDTHROUGH = ("rope.tension", "brake.lever_force", "motor.command")


def _parameters():
    return (
        parameter(
            "effects",
            "",
            "",
            "Effects to include, comma separated: " + ", ".join(WINCH_EFFECTS.names),
            type=str,
        ),
        *solver_parameters(
            "rk4",
            1e-3,
            also=ENERGY_SOLVERS,
            note="energy, energy1: paper 004's energy form, rigid drive train only",
        ),
        parameter(
            "drive_train",
            json.dumps(default_drive_train()),
            "",
            "Drive train as JSON: masses (motor rotor .. drum) and shafts, each with its "
            "speed ratio to the drum (estimated 1500-2000 hp drawworks by default)",
            type=str,
        ),
        parameter(
            "drive_train_masses",
            0,
            "",
            "Masses kept with elastic_drive_train: 0 the "
            "full chain, 1 rigid, 2.. reduced by delta-star elimination",
            type=int,
        ),
        parameter(
            "drum_radius",
            0.42,
            "m",
            "Rope centreline radius on the first layer (32 in "
            "barrel with 1-3/8 in line, typical 1500-2000 hp drawworks; estimate)",
            min=0.0,
        ),
        parameter(
            "rope_diameter",
            0.0349,
            "m",
            "Rope diameter: 1-3/8 in drilling line "
            "(API 9A size); the radius grows by one diameter per layer",
            min=0.0,
        ),
        parameter(
            "rope_linear_mass",
            5.06,
            "kg/m",
            "Rope mass per metre (1-3/8 in 6x19 IWRC, about 3.4 lb/ft)",
            min=0.0,
        ),
        parameter(
            "drum_wraps_per_layer",
            40,
            "",
            "Turns per layer (about 1.4 m barrel / rope diameter)",
            type=int,
        ),
        parameter("drum_layers", 4, "", "Layers the drum flanges allow", type=int),
        parameter(
            "rope_on_drum", 150.0, "m", "Rope on the drum at the start (rope_layers)", min=0.0
        ),
        parameter(
            "brake_rim_radius",
            0.62,
            "m",
            "Brake-rim radius r_f (about 49 in rims; estimate)",
            min=0.0,
        ),
        parameter(
            "brake_lever_ratio",
            15.0,
            "1",
            "Lever ratio L/l of the brake handle linkage (estimate)",
            min=0.0,
        ),
        parameter(
            "brake_efficiency", 0.9, "1", "Efficiency eta of the brake linkage", min=0.0, max=1.0
        ),
        parameter(
            "brake_friction",
            0.4,
            "1",
            "Band friction coefficient mu (moulded lining on steel, 0.35-0.45)",
            min=0.0,
        ),
        parameter(
            "brake_wrap_angle", 5.24, "rad", "Band wrap angle alpha (about 300 deg)", min=0.0
        ),
        parameter(
            "motor_slope",
            3.6e3,
            "N.m.s/rad",
            "Slope b of the motor characteristic at "
            "the motor shaft (1150 hp AC motor, 1.5 % slip at 1200 rpm; estimate)",
            min=0.0,
        ),
        parameter("initial_drum_speed", 0.0, "rad/s", "Drum speed at the start (drum_inertia)"),
    )


def _inputs():
    return (
        input_("rope.tension", 0.0, "N", "Rope tension at the drum"),
        input_("brake.lever_force", 0.0, "N", "Force on the brake lever (<= 0: released)"),
        input_(
            "motor.command",
            0.0,
            "N.m",
            "Motor torque at the motor shaft, positive paying "
            "out; with motor_characteristic the zero-speed torque a of a - b omega",
        ),
        input_(
            "drum.speed_command",
            0.0,
            "rad/s",
            "Drum speed the drive imposes without "
            "drum_inertia (kinetostatic mode), positive paying out",
        ),
    )


def _outputs():
    deps = _FEEDTHROUGH
    return (
        output("rope.payout", "m", "Rope paid out since the start (unstretched)"),
        output("rope.payout_rate", "m/s", "Rate of rope paid out"),
        output("drum.speed", "rad/s", "Drum speed, positive paying out"),
        output("drum.angle", "rad", "Drum angle since the start, positive paying out"),
        output(
            "drum.layer",
            "",
            "Rope layer the rope leaves from (1 = on the barrel)",
            type=int,
            start=1,
        ),
        output("drum.radius", "m", "Winding radius where the rope leaves the drum"),
        output("motor.speed", "rad/s", "Motor shaft speed"),
        output("motor.torque", "N.m", "Motor torque at the motor shaft", depends_on=deps),
        output("brake.torque", "N.m", "Torque of the band brake on the drum", depends_on=deps),
        output(
            "brake.capacity",
            "N.m",
            "Brake capacity against paying out (eq. 34)",
            depends_on=("brake.lever_force",),
        ),
        output(
            "brake.state",
            "",
            "Band brake: 0 released, 1 slipping, 2 holding",
            type=int,
            depends_on=deps,
        ),
        output(
            "stored_energy",
            "J",
            "Kinetic energy of the drive train and drum plus shaft strain energy",
        ),
        output("dissipated_energy", "J", "Energy dissipated by the brake and dampers"),
        output("external_work", "J", "Work done on the winch by the rope and the motor"),
        output(
            "energy_balance", "J", "Ledger residual: stored change + dissipated - external work"
        ),
        output(
            "mode_changes", "", "Number of mode events so far (stick/slip, layer changes)", type=int
        ),
    )


_REPORTED = ReportOutputs.of(
    _outputs(),
    finite=(
        "rope.payout",
        "rope.payout_rate",
        "drum.speed",
        "motor.torque",
        "brake.torque",
        "stored_energy",
    ),
)
"""The outputs copied from the model's report, and those that must be finite."""


class WinchUnit(HeldInputsUnit):
    """Winch (drawworks) with band brake, motor and drive train (SPEC sections 7-9)."""

    NAME = "Winch"
    DESCRIPTION = "Winch (drawworks): drum, band brake, motor, drive train, wire_fmu"
    VARIABLES = _parameters() + _inputs() + _outputs()
    PORTS = (
        Port(
            "rope",
            "rope",
            PortSide.flow,
            "rope.tension",
            "rope.payout_rate",
            "rope.payout",
            "the rope leaving the drum",
        ),
    )

    def __init__(self, instance_name: str = "winch") -> None:
        super().__init__(instance_name)
        self.model: WinchModel | KinetostaticWinch | None = None
        self.initial_energy = 0.0
        self.time = 0.0

    # ------------------------------------------------------------ life cycle
    def configure(self) -> None:
        """Parse effects, drive train, drum, brake and solver; build the model."""
        problems: list[str] = []
        effects, effect_problems = WINCH_EFFECTS.parse(self.values["effects"])
        problems += [f"parameter 'effects': {p}" for p in effect_problems]
        settings = self._settings(problems)
        chain = self._chain(effects, problems)
        drum = self._drum(effects)
        problems += drum.problems()
        brake = self._brake()
        if "band_brake" in effects:
            problems += brake.problems()
        problems += self._scalar_problems(effects)
        if chain is not None and settings.method in ENERGY_SOLVERS:
            problems += _energy_solver_problems(settings.method, effects, chain)
        if chain is not None and settings.method == "rk4" and "drum_inertia" in effects:
            problems += self._stability_problems(chain, effects, settings.max_step)
        if problems:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", problems)
        config = WinchConfig(
            effects,
            drum,
            chain,
            brake,
            float(self.values["motor_slope"]),
            float(self.values["initial_drum_speed"]),
        )
        self.model = build_winch(config, settings)

    def evaluate_outputs(self) -> None:
        """Feedthrough outputs for the inputs now set; the state is untouched."""
        model = self._require_model()
        with model.trial(self._inputs()):
            self._update_outputs()

    def ode(self) -> OdeView:
        """The winch's hybrid ODE, for a monolithic model (inputs read as instantaneous)."""
        return _WinchOde(self)

    # ---------------------------------------------------------------- state
    def get_state(self) -> dict[str, Any]:
        """Complete state: the model's (continuous state, modes, layer), time, ledger start."""
        model = self._require_model()
        return {
            **model.get_state(),  # "x": the continuous state; modes, layer, held inputs
            "time": float(self.time),
            "initial_energy": float(self.initial_energy),
        }

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore a state from :meth:`get_state`."""
        model = self._require_model()
        model.set_state(dict(state))
        self.time = float(state["time"])
        self.initial_energy = float(state["initial_energy"])
        self._update_outputs()

    # -------------------------------------------------------------- helpers
    def _inputs(self) -> WinchInputs:
        v = self.values
        return WinchInputs(
            float(v["rope.tension"]),
            float(v["brake.lever_force"]),
            float(v["motor.command"]),
            float(v["drum.speed_command"]),
        )

    def _settings(self, problems: list[str]) -> SolverSettings:
        settings, solver_problems = solver_settings(self.values, also=ENERGY_SOLVERS)
        problems += solver_problems
        return settings

    def _chain(self, effects: frozenset[str], problems: list[str]) -> DriveChain | None:
        try:
            data = json.loads(self.values["drive_train"])
        except (TypeError, ValueError) as err:
            problems.append(f"parameter 'drive_train' is not valid JSON: {err}")
            return None
        chain, chain_problems = parse_drive_train(data)
        problems += [f"parameter 'drive_train': {p}" for p in chain_problems]
        if chain is None:
            return None
        keep = int(self.values["drive_train_masses"])
        if not 0 <= keep <= chain.n:
            problems.append(
                f"parameter 'drive_train_masses' must be 0 (full chain) or 1..{chain.n}"
                f" (the drive train has {chain.n} masses), got {keep}"
            )
            return None
        return chain.reduced(keep) if "elastic_drive_train" in effects else chain.rigid()

    def _drum(self, effects: frozenset[str]) -> Drum:
        v = self.values
        return Drum(
            float(v["drum_radius"]),
            float(v["rope_diameter"]),
            float(v["rope_linear_mass"]),
            int(v["drum_wraps_per_layer"]),
            int(v["drum_layers"]),
            float(v["rope_on_drum"]),
            "rope_layers" in effects,
        )

    def _brake(self) -> BandBrake:
        v = self.values
        return BandBrake(
            float(v["brake_rim_radius"]),
            float(v["brake_lever_ratio"]),
            float(v["brake_efficiency"]),
            float(v["brake_friction"]),
            float(v["brake_wrap_angle"]),
        )

    def _scalar_problems(self, effects: frozenset[str]) -> list[str]:
        v, out = self.values, []
        slope = float(v["motor_slope"])
        if "motor_characteristic" in effects and not (slope >= 0 and math.isfinite(slope)):
            out.append(f"parameter 'motor_slope' must be >= 0 N.m.s/rad, got {slope}")
        if not math.isfinite(float(v["initial_drum_speed"])):
            out.append(
                f"parameter 'initial_drum_speed' must be finite, got {v['initial_drum_speed']}"
            )
        return out

    def _stability_problems(
        self, chain: DriveChain, effects: frozenset[str], max_step: float
    ) -> list[str]:
        """RK4 is stable for ``|lambda| h < 2.8``: refuse settings that cannot be."""
        slope = float(self.values["motor_slope"]) if "motor_characteristic" in effects else 0.0
        rate = fastest_rate(chain, slope)
        if rate * max_step < RK4_STABILITY:
            return []
        return [
            f"parameter 'solver_max_step': rk4 with steps of {max_step:.3g} s is unstable for "
            f"this drive train (fastest eigenvalue {rate:.4g} 1/s; rk4 needs |lambda| h < "
            f"{RK4_STABILITY}): set solver_max_step below {RK4_STABILITY / rate:.3g} s, "
            "reduce the chain (drive_train_masses) or choose the L-stable 'ros2'"
        ]

    def _update_outputs(self) -> None:
        model = self._require_model()
        _REPORTED.publish(
            self.values, model.report(), self.initial_energy, model.mode_changes, self.instance_name
        )


def _energy_solver_problems(method: str, effects: frozenset[str], chain: DriveChain) -> list[str]:
    """Paper 004's integrator needs a rigid one-degree-of-freedom machine."""
    out = []
    if "drum_inertia" not in effects:
        out.append(
            f"parameter 'solver': {method!r} integrates a drum with inertia; add the "
            "effect 'drum_inertia' (the kinetostatic winch needs no solver)"
        )
    elif chain.n != 1:
        out.append(
            f"parameter 'solver': {method!r} integrates a rigid one-degree-of-freedom "
            f"machine, but the drive train keeps {chain.n} masses; set "
            "drive_train_masses to 1, drop 'elastic_drive_train', or choose ros2"
        )
    return out


class _WinchOde(ModelOdeView):
    """:class:`WinchUnit` as a piece of a monolithic ODE.

    With ``drum_inertia`` this is the unit's own hybrid ODE. Without it the
    state is ``[phi, speed, dissipated, external work]`` with ``phi' =``
    the commanded speed taken at each instant (no left limit here: a
    monolithic model has no communication steps).
    """

    def __init__(self, unit: WinchUnit) -> None:
        super().__init__(unit, unit._require_model())
        self._kinetostatic = isinstance(self.model, KinetostaticWinch)

    def bind_inputs(self, t: float) -> None:
        """Inputs in ``values`` are the values at ``t``."""
        self.model.set_inputs(self.unit._inputs())

    def publish(self, t: float, x: np.ndarray) -> None:
        """Outputs of ``x`` at ``t`` into ``values`` (state left alone)."""
        model = self.model
        x = np.array(x, dtype=float)
        if self._kinetostatic:
            x[1] = model.inputs.speed_command
        saved, model.state = model.state, x
        saved_time, self.unit.time = self.unit.time, t
        try:
            self.unit._update_outputs()
        finally:
            model.state, self.unit.time = saved, saved_time

    def reconcile(self, t, x):
        """Inputs jumped: settle the brake's modes for them."""
        model = self.model
        self.bind_inputs(t)
        if self._kinetostatic:
            return np.array(x, dtype=float)
        model.state = model._settle_modes(t, np.array(x, dtype=float))
        return model.state.copy()

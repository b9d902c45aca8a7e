"""The winch (drawworks) as a co-simulation unit: ports, parameters, outputs.

Ports (power bonds)
-------------------
``rope``
    Input ``tension`` (N, from the block train's ``line_a.tension``);
    outputs ``payout`` (m, unstretched rope paid out since the start) and
    ``payout_rate`` (m/s), taken by the block train as ``line_a.payout`` /
    ``line_a.payout_rate``. Power into the winch: ``+tension *
    payout_rate`` (paying out under tension drives the drum). The payout
    outputs come from the drum's state and depend on no input. The port
    accepts the block train's interface model of the tension (inputs
    ``rope.stiffness``, ``rope.damping``, ``rope.effort_rate``,
    ``rope.reference_position``, ``rope.reference_velocity``;
    :mod:`~wire_fmu.core.framework.interface_model`): the drum is then
    integrated against ``T0 - K (payout - x_ref) - D (payout_rate - v_ref) +
    R (t - t0)``, at least 0 (a rope cannot push), instead of the held
    tension, so the rope's spring acts inside the winch's own solver and
    brake stick/slip events (issue 17).
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

The variables themselves (units, descriptions, defaults) are declared in
:mod:`wire_fmu.core.units.winch.variables`.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from operator import itemgetter
from typing import Any

import numpy as np

from wire_fmu.core.components.drive_train import DriveChain, parse_drive_train
from wire_fmu.core.components.drum import Drum, LayeredDrum
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.energy_solver import ENERGY_SOLVERS
from wire_fmu.core.framework.hybrid import RK4_STABILITY, SolverSettings
from wire_fmu.core.framework.interface_model import EffortModel
from wire_fmu.core.framework.ports import PortSide, port
from wire_fmu.core.framework.report_outputs import ReportOutputs
from wire_fmu.core.framework.solver_options import solver_settings
from wire_fmu.core.framework.unit import (
    HeldInputsUnit,
    ModelOdeView,
    OdeView,
)
from wire_fmu.core.units.winch import kernel
from wire_fmu.core.units.winch.base import (
    FLAT_INPUTS,
    NO_ROPE_MODEL,
    ROPE_MODEL_INPUTS,
    WinchConfig,
    WinchInputs,
)
from wire_fmu.core.units.winch.brake import BandBrake
from wire_fmu.core.units.winch.drive import WinchModel
from wire_fmu.core.units.winch.kinetostatic import KinetostaticWinch
from wire_fmu.core.units.winch.model import WINCH_EFFECTS, build_winch, fastest_rate
from wire_fmu.core.units.winch.variables import winch_inputs, winch_outputs, winch_parameters

__all__ = ["WinchUnit"]

_REPORTED = ReportOutputs.of(
    winch_outputs(),
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
_read_flat_inputs = itemgetter(*FLAT_INPUTS)


class WinchUnit(HeldInputsUnit):
    """Winch (drawworks) with band brake, motor and drive train (SPEC sections 7-9)."""

    NAME = "Winch"
    DESCRIPTION = "Winch (drawworks): drum, band brake, motor, drive train, wire_fmu"
    VARIABLES = winch_parameters() + winch_inputs() + winch_outputs()
    PORTS = (
        port(
            "rope",
            "rope",
            PortSide.flow,
            "tension",
            "payout_rate",
            "payout",
            "the fast line",
            interface=True,
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
        brake = self._brake() if "band_brake" in effects else None
        if brake is not None:
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

    def initialize(self, start_time: float) -> None:
        """Initial state for the parameters and inputs set (a rope model about ``start_time``).

        Implements :meth:`Unit.initialize`.
        """
        self.time = float(start_time)
        super().initialize(start_time)

    def input_problems(self) -> list[str]:
        """Inputs the winch cannot step with (each named), also a rope model with a solver
        that integrates against a held tension only."""
        inputs = self.step_inputs()
        problems = inputs.problems()
        settings = getattr(self._require_model(), "settings", None)  # None: kinetostatic
        if inputs.rope_model.active and settings is not None and settings.method in ENERGY_SOLVERS:
            problems.append(
                f"inputs {', '.join(ROPE_MODEL_INPUTS[:3])}: solver {settings.method!r} "
                "integrates the drum against a held rope tension; choose 'rk4' or 'ros2' "
                "to integrate it against the rope's interface model"
            )
        return problems

    def _take_quiet_step(self, time: float, step: float) -> bool:
        """A step in which nothing happens, outputs included, in one compiled call.

        Implements :meth:`Unit._take_quiet_step` with :meth:`WinchModel.quiet_step_outputs
        <wire_fmu.core.units.winch.drive.WinchModel.quiet_step_outputs>` when the compiled
        kernel runs the model's steps. The outputs a quiet step cannot change (the layer,
        its radius, the brake's state, the mode changes) keep their values.
        """
        model = self.model
        if not (isinstance(model, WinchModel) and model.compiled):
            return False
        flat = tuple(map(float, _read_flat_inputs(self.values)))
        taken = model.quiet_step_outputs(time, step, flat, self.initial_energy)
        if taken is None:
            return False
        self.values.update(zip(kernel.OUTPUTS, taken))  # noqa: B905 - as many by construction
        self.time = time + step
        return True

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

    def _snapshot(self) -> Any:
        """The model's own snapshot where it has one (the winch with drum inertia)."""
        model = self._require_model()
        if isinstance(model, WinchModel):
            return model.snapshot(), self.time
        return super()._snapshot()

    def _restore_snapshot(self, saved: Any) -> None:
        """Implements :meth:`Unit._restore_snapshot`."""
        model = self._require_model()
        if isinstance(model, WinchModel):
            kept, self.time = saved
            model.restore(kept)
            self._update_outputs()
        else:
            super()._restore_snapshot(saved)

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore a state from :meth:`get_state`.

        Parameters
        ----------
        state : mapping
            A state from :meth:`get_state`.
        """
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
            self._rope_model(),
        )

    def _rope_model(self) -> EffortModel:
        """The block train's interface model of the tension set now, about the present time."""
        v = self.values
        fields = [float(v[name]) for name in ROPE_MODEL_INPUTS]
        if fields[0] == 0.0 and fields[1] == 0.0 and fields[2] == 0.0:
            return NO_ROPE_MODEL
        return EffortModel(*fields, start=float(self.time))

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
        if "rope_layers" not in effects:
            return Drum(float(v["drum_radius"]))
        return LayeredDrum(
            float(v["drum_radius"]),
            rope_diameter=float(v["rope_diameter"]),
            rope_linear_mass=float(v["rope_linear_mass"]),
            wraps_per_layer=int(v["drum_wraps_per_layer"]),
            max_layers=int(v["drum_layers"]),
            initial_rope=float(v["rope_on_drum"]),
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
        """Inputs in ``values`` are the values at ``t``.

        Parameters
        ----------
        t : float
            Time the inputs belong to, s.
        """
        self.model.set_inputs(self.unit._inputs())

    def publish(self, t: float, x: np.ndarray) -> None:
        """Outputs of ``x`` at ``t`` into ``values`` (state left alone).

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State of the winch's ODE.
        """
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
        """Inputs jumped: settle the brake's modes for them.

        Parameters
        ----------
        t : float
            Time of the jump, s.
        x : ndarray
            State of the winch's ODE.

        Returns
        -------
        ndarray
            The state with the brake's modes settled.
        """
        model = self.model
        self.bind_inputs(t)
        if self._kinetostatic:
            return np.array(x, dtype=float)
        model.state = model._settle_modes(t, np.array(x, dtype=float))
        return model.state.copy()

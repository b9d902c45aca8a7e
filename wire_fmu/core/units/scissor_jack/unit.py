"""Paper 003's scissor jack as a co-simulation unit: ports, parameters, outputs.

Ports
-----
``handle``
    With ``handle_drive = "speed"`` the handle is turned kinematically:
    input ``speed_command`` (rad/s, positive lifts), output ``torque`` (N m,
    the torque the drive must supply; direct feedthrough). With
    ``handle_drive = "torque"``: input ``torque_command`` (N m), outputs
    ``speed`` and ``angle`` from the jack's state. Power into the jack:
    ``torque * speed``.
``load``
    Outputs ``height`` (m, of the shoe above the base joint) and
    ``velocity`` (m/s).
``screw``, ``thread``
    Outputs ``screw.travel`` (m), ``screw.displacement`` (m, horizontal,
    of the screw's centre of mass), ``screw.axial_force`` (N),
    ``thread.lead_torque`` (``h F``, N m), ``thread.friction_torque`` (N m
    on the screw, opposing its rotation) and ``thread.state`` (0
    frictionless, 1 sliding, 2 stuck, 3 creeping in a regularised model).

Effects: ``thread_friction`` (absent: a frictionless thread, paper 003's
section 2; present: dry friction ``r_mean mu |F|`` with the model
``friction_model``: ``stick_slip`` exact, or the paper's regularised
``linear`` form, or ``tanh``). The physics is in
:mod:`wire_fmu.core.units.scissor_jack.model`; the numbers default to the paper's jack.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from wire_fmu.core.components.screw_nut.thread import REGULARISATIONS, ScrewThread
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.effects import Effect, EffectCatalogue
from wire_fmu.core.framework.hybrid import SolverSettings
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
from wire_fmu.core.units.scissor_jack.config import (
    FRICTION_MODELS,
    HANDLE_DRIVES,
    JackConfig,
    JackInputs,
)
from wire_fmu.core.units.scissor_jack.geometry import JackGeometry
from wire_fmu.core.units.scissor_jack.model import ScissorJackModel

__all__ = ["ScissorJackUnit", "JACK_EFFECTS"]

JACK_EFFECTS = EffectCatalogue(
    "ScissorJack",
    (
        Effect(
            "thread_friction",
            "frictionless thread",
            "dry friction r_mean mu |F| in the thread (friction_model)",
        ),
    ),
)

_INPUTS = ("handle.speed_command", "handle.torque_command")
_FRICTION = ("thread_friction",)
_POSITIVE = {"min": 0.0, "min_exclusive": True}
_SPEED = ("handle.speed_command",)
_SPEED_DRIVE = (("handle_drive", ("speed",)),)
_TORQUE_DRIVE = (("handle_drive", ("torque",)),)
"""What acts only with one handle drive: its command, the torque drive's start speed."""
RK4_STABILITY = 2.5
"""Largest ``|lambda| h`` accepted for ``rk4`` (its real-axis limit is about 2.8)."""


def _parameters():
    return (
        parameter(
            "effects",
            "",
            "",
            "Effects to include, comma separated: " + ", ".join(JACK_EFFECTS.names),
            type=str,
        ),
        parameter(
            "handle_drive",
            "speed",
            "",
            "How the handle is driven: 'speed' "
            "(kinematically, input handle.speed_command) or 'torque' (input "
            "handle.torque_command)",
            type=str,
        ),
        parameter(
            "friction_model",
            "stick_slip",
            "",
            "Thread friction with thread_friction: "
            "stick_slip (exact), linear (paper 003's regularised form) or tanh",
            type=str,
            acts_with=_FRICTION,
        ),
        parameter("rod_length", 0.130, "m", "Tie rod length (paper 003: 130 mm)", **_POSITIVE),
        parameter(
            "initial_height",
            0.130,
            "m",
            "Shoe height at the start, within [min_height, max_height] (paper 003: 130 mm, "
            "rods at 30 deg)",
            **_POSITIVE,
        ),
        parameter(
            "min_height",
            0.04,
            "m",
            "Lowest shoe height (end of travel), below twice rod_length",
            **_POSITIVE,
        ),
        parameter(
            "max_height",
            0.25,
            "m",
            "Highest shoe height (end of travel), below twice rod_length",
            **_POSITIVE,
        ),
        parameter(
            "thread_lead", 0.002, "m", "Screw travel per turn (paper 003: 2 mm)", **_POSITIVE
        ),
        parameter(
            "thread_mean_radius",
            0.01,
            "m",
            "Mean thread radius r of the friction torque r mu |F| (paper 003: 0.01 m)",
            acts_with=_FRICTION,
            **_POSITIVE,
        ),
        parameter(
            "thread_friction",
            0.1,
            "1",
            "Thread friction coefficient (paper 003: 0.1, steel on steel)",
            min=0.0,
            acts_with=_FRICTION,
        ),
        parameter(
            "friction_speed_scale",
            1.0e-6,
            "rad/s",
            "w1 of the regularised friction models linear and tanh (paper 003: 1e-6 rad/s)",
            acts_with=_FRICTION,
            **_POSITIVE,
        ),
        parameter(
            "load_mass",
            306.0,
            "kg",
            "Mass of the shoe with the load (paper 003: 306 kg)",
            **_POSITIVE,
        ),
        parameter(
            "load_weight", 3000.0, "N", "Weight on the shoe (paper 003: 3000 N)", **_POSITIVE
        ),
        parameter(
            "handle_inertia",
            5.0e-3,
            "kg.m2",
            "Inertia of screw and handle about the "
            "screw axis (estimate: 20 mm x 350 mm steel screw 4e-5 plus a 0.25 kg crank "
            "at 0.14 m, 4.9e-3)",
            **_POSITIVE,
        ),
        parameter(
            "initial_handle_speed",
            0.0,
            "rad/s",
            "Handle speed at the start with a torque drive",
            acts_when=_TORQUE_DRIVE,
        ),
        *solver_parameters(
            "rk4",
            2.0e-3,
            rtol=1e-8,
            atol=1e-12,
            note="the regularised friction models are stiff: radau",
        ),
    )


def _inputs():
    return (
        input_(
            "handle.speed_command",
            0.0,
            "rad/s",
            "Handle speed with handle_drive 'speed', positive lifts",
            acts_when=_SPEED_DRIVE,
        ),
        input_(
            "handle.torque_command",
            0.0,
            "N.m",
            "Handle torque with handle_drive 'torque', positive lifts",
            acts_when=_TORQUE_DRIVE,
        ),
    )


def _outputs():
    both = _INPUTS
    return (
        output("handle.angle", "rad", "Handle (screw) angle relative to the nut since the start"),
        output("handle.speed", "rad/s", "Handle speed", depends_on=_SPEED),
        output(
            "handle.torque",
            "N.m",
            "Torque on the handle: the command, or the torque the speed drive must supply",
            depends_on=both,
        ),
        output("load.height", "m", "Shoe height above the base joint"),
        output("load.velocity", "m/s", "Shoe velocity, positive up", depends_on=_SPEED),
        output("rod_angle", "rad", "Tie rod angle to the horizontal"),
        output("screw.travel", "m", "Screw travel through the nut since the start"),
        output(
            "screw.displacement",
            "m",
            "Horizontal displacement of the screw's centre of mass since the start",
        ),
        output("screw.axial_force", "N", "Axial force in the thread", depends_on=both),
        output(
            "thread.lead_torque",
            "N.m",
            "Torque h F of the axial force about the screw axis",
            depends_on=both,
        ),
        output(
            "thread.friction_torque",
            "N.m",
            "Thread friction torque on the screw (opposes its rotation relative to the nut)",
            depends_on=both,
        ),
        output(
            "thread.state",
            "",
            "Thread: 0 frictionless, 1 sliding, 2 stuck, 3 creeping (regularised)",
            type=int,
            depends_on=both,
        ),
        output(
            "stored_energy",
            "J",
            "Kinetic energy of handle and load plus W times height",
            depends_on=_SPEED,
        ),
        output("dissipated_energy", "J", "Energy dissipated by the thread friction"),
        output("external_work", "J", "Work done on the jack through the handle", depends_on=_SPEED),
        output(
            "energy_balance",
            "J",
            "Ledger residual: stored change + dissipated - external work",
            depends_on=_SPEED,
        ),
        output("mode_changes", "", "Number of thread stick/slip events so far", type=int),
    )


_REPORTED = ReportOutputs.of(
    _outputs(),
    finite=("load.height", "handle.speed", "handle.torque", "screw.axial_force", "stored_energy"),
)
"""The outputs copied from the model's report, and those that must be finite."""


class ScissorJackUnit(HeldInputsUnit):
    """Scissor jack with screw-nut drive and thread friction (SPEC section 10, paper 003)."""

    NAME = "ScissorJack"
    DESCRIPTION = "Scissor jack: screw-nut pair with dry thread friction (paper 003), wire_fmu"
    VARIABLES = _parameters() + _inputs() + _outputs()

    def __init__(self, instance_name: str = "jack") -> None:
        super().__init__(instance_name)
        self.model: ScissorJackModel | None = None
        self.initial_energy = 0.0
        self.time = 0.0

    # ------------------------------------------------------------ life cycle
    def configure(self) -> None:
        """Build the jack from the parameters; list every problem at once."""
        problems: list[str] = []
        effects, effect_problems = JACK_EFFECTS.parse(self.values["effects"])
        problems += [f"parameter 'effects': {p}" for p in effect_problems]
        config = self._config(effects, problems)
        settings = self._settings(problems)
        problems += [f"parameters: {p}" for p in config.problems()]
        if not problems and settings.method == "rk4":
            problems += _stability_problems(config, settings.max_step)
        if problems:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", problems)
        self.model = ScissorJackModel(config, settings)

    def evaluate_outputs(self) -> None:
        """Feedthrough outputs for the inputs now set; the state is untouched."""
        model = self._require_model()
        with model.trial(self._inputs()) as x:
            self._update_outputs(x)

    def ode(self) -> OdeView:
        """The jack's hybrid ODE, for a monolithic model (inputs read as instantaneous)."""
        return _JackOde(self)

    # ---------------------------------------------------------------- state
    def get_state(self) -> dict[str, Any]:
        """Complete state: the model's, time and the ledger's start."""
        return {
            **self._require_model().get_state(),
            "time": float(self.time),
            "initial_energy": float(self.initial_energy),
        }

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore a state from :meth:`get_state`.

        Parameters
        ----------
        state : mapping
            A state from :meth:`get_state`.
        """
        self._require_model().set_state(dict(state))
        self.time = float(state["time"])
        self.initial_energy = float(state["initial_energy"])
        self._update_outputs()

    # -------------------------------------------------------------- helpers
    def _inputs(self) -> JackInputs:
        return JackInputs(
            float(self.values["handle.speed_command"]), float(self.values["handle.torque_command"])
        )

    def _config(self, effects: frozenset[str], problems: list[str]) -> JackConfig:
        v = self.values
        friction = "none"
        if "thread_friction" in effects:
            friction = str(v["friction_model"])
            if friction not in FRICTION_MODELS or friction == "none":
                problems.append(
                    f"parameter 'friction_model' must be one of stick_slip, "
                    f"{', '.join(REGULARISATIONS)}; got {friction!r}"
                )
                friction = "stick_slip"
        drive = str(v["handle_drive"])
        if drive not in HANDLE_DRIVES:
            problems.append(
                f"parameter 'handle_drive' must be one of {', '.join(HANDLE_DRIVES)}; got {drive!r}"
            )
            drive = "speed"
        geometry = JackGeometry(
            float(v["rod_length"]),
            float(v["initial_height"]),
            float(v["min_height"]),
            float(v["max_height"]),
        )
        thread = ScrewThread(
            float(v["thread_lead"]), float(v["thread_mean_radius"]), float(v["thread_friction"])
        )
        return JackConfig(
            geometry,
            thread,
            float(v["load_mass"]),
            float(v["load_weight"]),
            float(v["handle_inertia"]),
            friction,
            float(v["friction_speed_scale"]),
            drive,
            float(v["initial_handle_speed"]),
        )

    def _settings(self, problems: list[str]) -> SolverSettings:
        settings, solver_problems = solver_settings(self.values)
        problems += solver_problems
        return settings

    def _update_outputs(self, x: np.ndarray | None = None) -> None:
        model = self._require_model()
        _REPORTED.publish(
            self.values,
            model.report(x),
            self.initial_energy,
            model.mode_changes,
            self.instance_name,
        )


def _stability_problems(config: JackConfig, max_step: float) -> list[str]:
    """rk4 cannot integrate the regularised thread's stiff linear zone: refuse it."""
    if not config.regularised or config.drive == "speed":
        return []
    geometry = config.geometry
    rate = 0.0
    for height in (geometry.min_height, geometry.initial_height, geometry.max_height):
        travel = geometry.travel_at_height(height)
        capacity = config.thread.friction_capacity(config.static_force(travel))
        inertia = config.effective_inertia(travel, 1.0)
        rate = max(rate, capacity / (config.speed_scale * inertia))
    if rate * max_step < RK4_STABILITY:
        return []
    return [
        f"parameter 'solver': rk4 with steps of {max_step:.3g} s is unstable for the "
        f"regularised thread friction (stiffness about {rate:.3g} 1/s = M1 / (I w1)); "
        f"choose 'radau' (or 'ros2'), or solver_max_step below {RK4_STABILITY / rate:.3g} s"
    ]


class _JackOde(ModelOdeView):
    """:class:`ScissorJackUnit` as a piece of a monolithic ODE.

    With a speed drive the commanded speed is read at each instant and held
    between input jumps, whose kinetic-energy step :meth:`reconcile` books
    as work of the drive (the unit's own step does the same).
    """

    def __init__(self, unit: ScissorJackUnit) -> None:
        super().__init__(unit, unit._require_model())
        self._speed_drive = self.model.config.drive == "speed"

    def bind_inputs(self, t: float) -> None:
        """Inputs in ``values`` are the values at ``t``.

        Parameters
        ----------
        t : float
            Time the inputs belong to, s.
        """
        self.model.inputs = self.unit._inputs()

    def _driven(self, x: np.ndarray) -> np.ndarray:
        x = np.array(x, dtype=float)
        if self._speed_drive:
            x[1] = self.model.inputs.speed_command
        return x

    def publish(self, t: float, x: np.ndarray) -> None:
        """Outputs of ``x`` at ``t`` into ``values`` (state left alone).

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[psi (rad), psi' (rad/s), dissipated (J), external work (J)]``.
        """
        self.unit._update_outputs(self._driven(x))

    def rhs(self, t, x):
        """See :meth:`ScissorJackModel.rhs`.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[psi (rad), psi' (rad/s), dissipated (J), external work (J)]``.
        """
        out = self.model.rhs(t, self._driven(x))
        if self._speed_drive:
            out[1] = 0.0
        return out

    def reconcile(self, t, x):
        """Inputs jumped: book a speed jump, or settle the thread's mode.

        Parameters
        ----------
        t : float
            Time of the jump, s.
        x : ndarray
            State of the jack's ODE.

        Returns
        -------
        ndarray
            The state after the jump.
        """
        self.bind_inputs(t)
        x = np.array(x, dtype=float)
        if self._speed_drive:
            return self.model._speed_jump(x, self.model.inputs.speed_command)
        return self.model._settle(t, x, [])

"""Paper 002's multi-mass elastic drive as a co-simulation unit.

A chain or a tree of rotating masses joined by elastic shafts
(:mod:`wire_fmu.core.components.drive_tree`), every quantity reduced to the motor
shaft, with one or two motors and one load.

Ports
-----
``motor``, ``motor2``
    Input ``torque`` (N m): the electromagnetic torque, or with the effect
    ``motor_characteristic`` the zero-speed torque ``a`` of ``M = a - b w``
    (paper 004, eq. 6; ``b`` = ``motor_slope``). Outputs ``speed`` (rad/s),
    ``angle`` (rad) and ``drive_torque`` (N m, the torque the motor develops).
    ``motor2`` acts only on a drive with two motors (paper 002's Fig. 7).
``load``
    Input ``torque`` (N m, the load torque ``M_c``, positive opposing
    positive rotation); outputs ``speed`` (rad/s) and ``angle`` (rad) of the
    load mass, states with no direct feedthrough: a partner unit taking
    ``load.speed`` and returning a torque closes a rotational bond. Power
    into the drive through the load port: ``-torque * speed``.
``mass_k``, ``shaft_k``
    Speed of every mass (``mass_1`` .. ``mass_12``, the size of paper 002's
    car-dumper drive) and torque in every shaft (``c`` twist plus ``beta``
    twist rate, positive when it drives the shaft's second mass forward);
    unused slots read 0.

Parameters
----------
``drive`` (JSON, :func:`~wire_fmu.core.components.drive_data.parse_drive`) and
``masses_kept``: a chain may be reduced to fewer masses by paper 002's
delta-star elimination (:meth:`~wire_fmu.core.components.drive_train.DriveChain.reduced`,
interior masses smallest first; motor and load are kept). ``mode_k``
outputs give the damped natural frequencies (Hz) and damping ratios of the
model actually simulated, so a scene shows what the reduction kept.

The equations are linear: ``J w' = -K theta - B w + torques``; the
internal solver is ``rk4`` with steps refused when ``|lambda| h`` exceeds
RK4's stability (the fastest eigenvalue of the state matrix), or any solver
of :mod:`wire_fmu.core.framework.hybrid`.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from wire_fmu.core.components.drive_data import default_multimass_drive, parse_drive
from wire_fmu.core.components.drive_tree import DriveTree
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.effects import Effect, EffectCatalogue
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
from wire_fmu.core.units.multimass_drive.model import DriveModel

__all__ = ["DriveUnit", "DRIVE_EFFECTS", "MAX_MASSES", "MODES_REPORTED"]

MAX_MASSES = 12
"""Masses a drive may have (paper 002's car-dumper drive has 12)."""

MODES_REPORTED = 3
"""Lowest oscillatory modes reported as outputs."""

RK4_STABILITY = 2.5
"""Largest ``|lambda| h`` accepted for ``rk4`` (its limit on the imaginary axis is 2.83)."""

DRIVE_EFFECTS = EffectCatalogue(
    "MultiMassDrive",
    (
        Effect(
            "motor_characteristic",
            "motor torque input",
            "M = a - b omega with the input as a and b = motor_slope",
        ),
    ),
)

_MOTOR_INPUTS = ("motor.torque", "motor2.torque")


def _parameters():
    return (
        parameter(
            "effects",
            "",
            "",
            "Effects to include, comma separated: " + ", ".join(DRIVE_EFFECTS.names),
            type=str,
        ),
        parameter(
            "drive",
            json.dumps(default_multimass_drive()),
            "",
            "Drive as JSON: masses "
            "(name, inertia, damping), shafts (name, from, to, stiffness, damping), "
            "motors, load; all reduced to the motor shaft (a four-mass estimated drive "
            "by default)",
            type=str,
        ),
        parameter(
            "masses_kept",
            0,
            "",
            "Masses kept: 0 the full drive, 2.. a chain reduced "
            "by delta-star elimination (paper 002)",
            type=int,
            min=0,
        ),
        parameter(
            "motor_slope",
            0.0,
            "N.m.s/rad",
            "Slope b of each motor's characteristic a - b omega",
            min=0.0,
            acts_with=("motor_characteristic",),
        ),
        parameter("initial_speed", 0.0, "rad/s", "Speed of every mass at the start"),
        *solver_parameters("rk4", 5e-4, rtol=1e-8, atol=1e-10),
    )


def _inputs():
    return (
        input_(
            "motor.torque",
            0.0,
            "N.m",
            "Torque of the (first) motor, or a of a - b omega with motor_characteristic",
        ),
        input_("motor2.torque", 0.0, "N.m", "Torque of the second motor (two-motor drives)"),
        input_(
            "load.torque",
            0.0,
            "N.m",
            "Load torque M_c on the load mass, positive opposing positive rotation",
        ),
    )


def _outputs():
    outs = [
        output("motor.speed", "rad/s", "Speed of the (first) motor's mass"),
        output("motor.angle", "rad", "Angle of the (first) motor's mass"),
        output(
            "motor.drive_torque",
            "N.m",
            "Torque the (first) motor develops",
            depends_on=("motor.torque",),
        ),
        output("motor2.speed", "rad/s", "Speed of the second motor's mass (0 if none)"),
        output(
            "motor2.drive_torque",
            "N.m",
            "Torque the second motor develops (0 if none)",
            depends_on=("motor2.torque",),
        ),
        output("load.speed", "rad/s", "Speed of the load mass"),
        output("load.angle", "rad", "Angle of the load mass"),
    ]
    outs += [
        output(f"mass_{k}.speed", "rad/s", f"Speed of mass {k} (0 if the drive has fewer)")
        for k in range(1, MAX_MASSES + 1)
    ]
    outs += [
        output(f"shaft_{k}.torque", "N.m", f"Torque in shaft {k} (0 if the drive has fewer)")
        for k in range(1, MAX_MASSES)
    ]
    for k in range(1, MODES_REPORTED + 1):
        outs += [
            output(
                f"mode_{k}.frequency",
                "Hz",
                f"Damped natural frequency of oscillatory "
                f"mode {k} of the simulated drive, motor characteristic included "
                "(0 if none)",
            ),
            output(f"mode_{k}.damping_ratio", "1", f"Damping ratio of mode {k}"),
        ]
    outs += [
        output("stored_energy", "J", "Kinetic energy of the masses plus shaft strain energy"),
        output("dissipated_energy", "J", "Energy dissipated by ground and shaft dampers"),
        output("external_work", "J", "Work done on the drive by the motors and the load"),
        output(
            "energy_balance", "J", "Ledger residual: stored change + dissipated - external work"
        ),
        output("mode_changes", "", "Mode events so far (always 0: the drive is smooth)", type=int),
    ]
    return tuple(outs)


class DriveUnit(Unit):
    """Multi-mass elastic drive, chain or tree, one or two motors (SPEC section 8, paper 002)."""

    NAME = "MultiMassDrive"
    DESCRIPTION = "Multi-mass elastic drive with delta-star reduction (paper 002), wire_fmu"
    VARIABLES = _parameters() + _inputs() + _outputs()
    PORTS = (
        port("motor", "rotational", PortSide.flow, "torque", "speed", "angle", "first motor"),
        port("motor2", "rotational", PortSide.flow, "torque", "speed", None, "second motor"),
        port("load", "rotational", PortSide.flow, "torque", "speed", "angle", "the load's shaft"),
    )

    def __init__(self, instance_name: str = "drive") -> None:
        super().__init__(instance_name)
        self.model: DriveModel | None = None
        self.initial_energy = 0.0
        self.time = 0.0

    # ------------------------------------------------------------ life cycle
    def configure(self) -> None:
        """Parse the drive, reduce it, check the solver; list every problem at once."""
        v = self.values
        problems: list[str] = []
        effects, effect_problems = DRIVE_EFFECTS.parse(v["effects"])
        problems += [f"parameter 'effects': {p}" for p in effect_problems]
        settings, solver_problems = solver_settings(v)
        problems += solver_problems
        tree = self._tree(problems)
        slope = float(v["motor_slope"]) if "motor_characteristic" in effects else 0.0
        if not (slope >= 0.0 and math.isfinite(slope)):
            problems.append(f"parameter 'motor_slope' must be >= 0 N.m.s/rad, got {slope}")
        if not math.isfinite(float(v["initial_speed"])):
            problems.append(f"parameter 'initial_speed' must be finite, got {v['initial_speed']}")
        if problems:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", problems)
        model = DriveModel(tree, slope, settings)
        if settings.method == "rk4":
            problems += _stability_problems(model, settings.max_step)
        if problems:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", problems)
        self.model = model

    def initialize(self, start_time: float) -> None:
        """Start at ``initial_speed`` with the shafts carrying their quasi-static torques.

        Parameters
        ----------
        start_time : float
            Start time, s.
        """
        model = self._require_model()
        self._bind(model)
        # set-up only: values too large for the drive overflow here, and are named below
        with np.errstate(over="ignore", invalid="ignore"):
            if not _finite_start(model, float(self.values["initial_speed"])):
                raise ConfigurationError(self.who, [self._overflow_problem(model)])
            self.time = start_time
            self.initial_energy = model.stored_energy()
            self._update_outputs()

    def input_problems(self) -> list[str]:
        """Torque inputs that are not finite."""
        return self.non_finite_inputs((*_MOTOR_INPUTS, "load.torque"))

    def _advance(self, time: float, step: float) -> list[str]:
        """Integrate the drive with the torques held."""
        model = self._require_model()
        self._bind(model)
        model.advance(time, step)
        return []

    def evaluate_outputs(self) -> None:
        """The motors' torques for the commands now set; the state is untouched."""
        model = self._require_model()
        saved = (model.commands.copy(), model.load_torque)
        try:
            self._bind(model)
            self._update_outputs()
        finally:
            model.commands, model.load_torque = saved

    def ode(self) -> OdeView:
        """The drive's ODE, for a monolithic model."""
        return _DriveOde(self, self._require_model())

    # ---------------------------------------------------------------- state
    def get_state(self) -> dict[str, Any]:
        """Continuous state, held inputs, time, ledger start and solver counters."""
        m = self._require_model()
        return {
            "x": [float(c) for c in m.state],
            "commands": [float(c) for c in m.commands],
            "load_torque": float(m.load_torque),
            "time": float(self.time),
            "initial_energy": float(self.initial_energy),
            "solver": {"rhs_calls": int(m.solver.rhs_calls), "steps": int(m.solver.steps)},
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
        m.commands = np.array(state["commands"], dtype=float)
        m.load_torque = float(state["load_torque"])
        self.time = float(state["time"])
        self.initial_energy = float(state["initial_energy"])
        m.solver.rhs_calls = int(state["solver"]["rhs_calls"])
        m.solver.steps = int(state["solver"]["steps"])
        self._update_outputs()

    # -------------------------------------------------------------- helpers
    def _bind(self, model: DriveModel) -> None:
        v = self.values
        model.commands = np.array([float(v[name]) for name in _MOTOR_INPUTS[: len(model.motors)]])
        model.load_torque = float(v["load.torque"])

    def _tree(self, problems: list[str]) -> DriveTree | None:
        try:
            data = json.loads(self.values["drive"])
        except (TypeError, ValueError) as err:
            problems.append(f"parameter 'drive' is not valid JSON: {err}")
            return None
        tree, tree_problems = parse_drive(data)
        problems += [f"parameter 'drive': {p}" for p in tree_problems]
        if tree is None:
            return None
        if tree.n > MAX_MASSES:
            problems.append(f"parameter 'drive': at most {MAX_MASSES} masses, got {tree.n}")
        keep = int(self.values["masses_kept"])
        if keep > tree.n:
            kept = "2..{n}" if tree.is_chain() else "{n} (a branched drive is not reduced)"
            problems.append(
                f"parameter 'masses_kept': the drive has {tree.n} masses; keep "
                f"{kept.format(n=tree.n)} or 0 (the full drive); got {keep}"
            )
            return tree
        if keep == 0 or keep == tree.n:
            return tree
        if not tree.is_chain() or keep < 2:
            what = "a branched drive" if not tree.is_chain() else f"masses_kept = {keep}"
            problems.append(
                f"parameter 'masses_kept': delta-star reduction keeps 2..{tree.n} "
                f"masses of a chain (motor first, load last), or 0 for the full drive; "
                f"got {what}"
            )
            return tree
        if tree.motors != (0,) or tree.load_index != tree.n - 1:
            problems.append(
                "parameter 'masses_kept': a reduced chain needs its motor on the "
                "first mass and its load on the last"
            )
            return tree
        return DriveTree.from_chain(tree.to_chain().reduced(keep))

    def _overflow_problem(self, model: DriveModel) -> str:
        """Which start values make the drive's start state overflow, each with its value.

        The start state is linear in the initial speed and the torques, so each is tried
        alone; when none overflows alone, all that are set are named together.
        """
        names = ("initial_speed", *_MOTOR_INPUTS[: len(model.motors)], "load.torque")
        given = {name: float(self.values[name]) for name in names if self.values[name] != 0.0}
        alone = [n for n, value in given.items() if not self._finite_alone(model, n, value)]
        self._bind(model)
        guilty = alone or list(given)
        if not guilty:
            return "the drive's start state is not finite (its parameters overflow it)"
        shown = " and ".join(
            f"{self.variable(n).causality.value} {n!r} = {given[n]:g} {self.variable(n).unit}"
            for n in guilty
        )
        verb = "is" if len(guilty) == 1 else "are"
        return (
            f"{shown} {verb} too large for this drive: its start state (shaft twists, "
            "stored energy) is not finite"
        )

    def _finite_alone(self, model: DriveModel, name: str, value: float) -> bool:
        """Whether the start state is finite with ``name`` at ``value`` and all else at 0."""
        motors = _MOTOR_INPUTS[: len(model.motors)]
        model.commands = np.array([value if m == name else 0.0 for m in motors])
        model.load_torque = value if name == "load.torque" else 0.0
        return _finite_start(model, value if name == "initial_speed" else 0.0)

    def _update_outputs(self) -> None:
        m = self._require_model()
        x = m.state
        n = m.n
        omega = x[n : 2 * n]
        motor_torques = m.motor_torques(omega)
        out = self.values
        first = m.motors[0]
        out["motor.speed"] = float(omega[first])
        out["motor.angle"] = float(x[first])
        out["motor.drive_torque"] = float(motor_torques[0])
        second = len(m.motors) > 1
        out["motor2.speed"] = float(omega[m.motors[1]]) if second else 0.0
        out["motor2.drive_torque"] = float(motor_torques[1]) if second else 0.0
        out["load.speed"] = float(omega[m.load])
        out["load.angle"] = float(x[m.load])
        for k in range(MAX_MASSES):
            out[f"mass_{k + 1}.speed"] = float(omega[k]) if k < n else 0.0
        shafts = m.shaft_torques(x)
        for k in range(MAX_MASSES - 1):
            out[f"shaft_{k + 1}.torque"] = float(shafts[k]) if k < shafts.size else 0.0
        freqs, zetas = m.modes
        for k in range(MODES_REPORTED):
            out[f"mode_{k + 1}.frequency"] = float(freqs[k]) if k < freqs.size else 0.0
            out[f"mode_{k + 1}.damping_ratio"] = float(zetas[k]) if k < zetas.size else 0.0
        stored = m.stored_energy()
        out["stored_energy"] = stored
        out["dissipated_energy"] = float(x[2 * n])
        out["external_work"] = float(x[2 * n + 1])
        out["energy_balance"] = stored - self.initial_energy + float(x[2 * n]) - float(x[2 * n + 1])
        out["mode_changes"] = 0
        if not np.all(np.isfinite(x)):
            raise FloatingPointError(f"{self.instance_name}: non-finite state")


def _finite_start(model: DriveModel, speed: float) -> bool:
    """Start ``model`` at ``speed`` (rad/s); whether its state and stored energy are finite."""
    model.initialize(speed)
    return bool(np.all(np.isfinite(model.state))) and math.isfinite(model.stored_energy())


def _stability_problems(model: DriveModel, max_step: float) -> list[str]:
    """RK4 is stable for ``|lambda| h < 2.8``: refuse settings that cannot be."""
    rate = model.fastest_rate()
    if rate * max_step < RK4_STABILITY:
        return []
    return [
        f"parameter 'solver_max_step': rk4 with steps of {max_step:.3g} s is unstable for "
        f"this drive (fastest eigenvalue {rate:.4g} 1/s; rk4 needs |lambda| h < "
        f"{RK4_STABILITY}): set solver_max_step below {RK4_STABILITY / rate:.3g} s, reduce "
        "the drive (masses_kept) or choose the L-stable 'ros2'"
    ]


class _DriveOde(ModelOdeView):
    """:class:`DriveUnit` as a piece of a monolithic ODE (torques read as instantaneous)."""

    def bind_inputs(self, t: float) -> None:
        """Torques in ``values`` are those at ``t``.

        Parameters
        ----------
        t : float
            Time the torques belong to, s.
        """
        self.unit._bind(self.model)

"""The block train as a co-simulation unit: ports, parameters, outputs.

Ports (power bonds)
-------------------
``line_a``, ``line_b``
    Rope ends through which rope is paid in (e.g. by a winch drum). Inputs
    ``payout`` (m, unstretched rope paid in since the start) and
    ``payout_rate`` (m/s); output ``tension`` (N). Power into the block
    train is ``-tension * payout_rate``.
``mover_a``, ``mover_b``
    Driven bodies (a cylinder rod, a heaving deck). Inputs ``position`` (m,
    displacement along the body's direction) and ``velocity`` (m/s);
    output ``force`` (N, the rope's force on the body along its
    direction). Power into the block train is ``-force * velocity``.

Within a step a position input advances with its rate input, so a master
that holds a (position, velocity) pair gets kinematically consistent motion.
The rope's compliance lives here, so tensions and forces depend directly on
those inputs; block positions and velocities are states and depend on none.
"""

from __future__ import annotations

import itertools
import json
import logging
import math
import operator
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import numpy as np

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.compiled_step import CompiledFixedStep
from wire_fmu.core.framework.hybrid import RK4_STABILITY, fastest_mode
from wire_fmu.core.framework.ports import INTERFACE_QUANTITIES, PortSide, port
from wire_fmu.core.framework.solver_options import solver_parameters, solver_settings
from wire_fmu.core.framework.unit import (
    ModelOdeView,
    OdeView,
    Unit,
    input_,
    mode_change_time_output,
    output,
    parameter,
)
from wire_fmu.core.units.block_train.interface import interface_plan, linearisation_table
from wire_fmu.core.units.block_train.model import (
    BLOCK_TRAIN_EFFECTS,
    FLAT_INPUTS,
    BlockTrainInputs,
    BlockTrainModel,
)
from wire_fmu.core.units.block_train.quiet_outputs import OutputPlan, output_plan
from wire_fmu.core.units.block_train.reeving import (
    BLOCK_PORTS,
    LINE_PORTS,
    MOVER_PORTS,
)
from wire_fmu.core.units.block_train.reeving_fields import REEVING_FIELDS
from wire_fmu.core.units.block_train.reeving_parse import parse_reeving
from wire_fmu.core.units.block_train.reevings import drilling_block_train

__all__ = ["BlockTrainUnit"]

logger = logging.getLogger(__name__)

_INTERFACE_PORTS = LINE_PORTS + MOVER_PORTS
"""The ports that can publish an interface model."""
_TAKE_SWITCHES = operator.itemgetter(*(f"{p}.interface_model" for p in _INTERFACE_PORTS))
"""Each of :data:`_INTERFACE_PORTS`' own interface-model switch, in their order."""
_KINEMATIC_INPUTS = tuple(
    [f"{p}.payout" for p in LINE_PORTS]
    + [f"{p}.payout_rate" for p in LINE_PORTS]
    + [f"{p}.position" for p in MOVER_PORTS]
    + [f"{p}.velocity" for p in MOVER_PORTS]
)
_INPUT_NAMES = {  # each field of BlockTrainInputs: the input's name after the port
    "payout": "payout",
    "payout_rate": "payout_rate",
    "payout_acceleration": "payout_acceleration",
    "mover_position": "position",
    "mover_velocity": "velocity",
    "mover_acceleration": "acceleration",
}
_TAKE_INPUTS = operator.itemgetter(
    *(f"{port}.{_INPUT_NAMES[field]}" for field, ports in FLAT_INPUTS for port in ports)
)
"""Every kinematic input's value, in the order of :data:`~.model.FLAT_INPUTS`."""


def _variables():
    params = (
        parameter(
            "reeving",
            json.dumps(drilling_block_train(4)),
            "",
            "Reeving as JSON text: bodies, sheaves, anchors, rope path",
            type=str,
        ),
        parameter(
            "effects",
            "",
            "",
            "Effects to include, comma separated: " + ", ".join(BLOCK_TRAIN_EFFECTS.names),
            type=str,
        ),
        *solver_parameters("ros2", 1e-3),
        parameter(
            "initial_equilibrium",
            True,
            "",
            "Start with every block hanging at rest where the reeving puts it",
            type=bool,
        ),
        parameter(
            "pretension",
            1.0e3,
            "N",
            "Initial rope tension when not set by block equilibrium",
            min=0.0,
        ),
        parameter(
            "interface_model",
            False,
            "",
            "Publish each port's effort linearised about the state at the end of every step "
            "(stiffness, damping, effort_rate) and the port motion it was taken at "
            "(reference_position, reference_velocity), for a flow-side unit to integrate "
            "against; <port>.interface_model publishes one port's",
            type=bool,
        ),
        *(
            parameter(
                f"{p}.interface_model",
                False,
                "",
                f"Publish the interface model of port {p} alone (as interface_model does for "
                "every port): the master sets it for a port whose bond wires the model",
                type=bool,
            )
            for p in _INTERFACE_PORTS
        ),
    )
    inputs = []
    ramp = "over the step, its rate ramping from the value set at the step's start (0: held)"
    for line in LINE_PORTS:
        inputs += [
            input_(f"{line}.payout", 0.0, "m", f"Rope paid in through {line} since the start"),
            input_(f"{line}.payout_rate", 0.0, "m/s", f"Rate of rope paid in through {line}"),
            input_(f"{line}.payout_acceleration", 0.0, "m/s2", f"Change of that rate {ramp}"),
        ]
    for mover in MOVER_PORTS:
        inputs += [
            input_(f"{mover}.position", 0.0, "m", f"Displacement of driven body {mover}"),
            input_(f"{mover}.velocity", 0.0, "m/s", f"Velocity of driven body {mover}"),
            input_(f"{mover}.acceleration", 0.0, "m/s2", f"Change of that velocity {ramp}"),
        ]
    inputs.append(
        input_("break_segment", 0, "", "Break this rope segment (1-based) now; 0: none", type=int)
    )
    deps = _KINEMATIC_INPUTS
    outputs = [
        output(f"{p}.tension", "N", f"Rope tension at line end {p}", depends_on=deps)
        for p in LINE_PORTS
    ]
    outputs += [
        output(
            f"{p}.force", "N", f"Rope force on driven body {p} along its direction", depends_on=deps
        )
        for p in MOVER_PORTS
    ]
    interface_ports = [
        *((p, "tension", "payout", "payout_rate") for p in LINE_PORTS),
        *((p, "force", "position", "velocity") for p in MOVER_PORTS),
    ]
    for p, effort, position, velocity in interface_ports:
        outputs += [
            output(
                f"{p}.stiffness",
                "N/m",
                f"-d {effort} / d position at {p} with the rope's state frozen "
                "(with its interface_model; else 0)",
            ),
            output(
                f"{p}.damping",
                "N.s/m",
                f"-d {effort} / d velocity at {p} (with its interface_model; else 0)",
            ),
            output(
                f"{p}.effort_rate",
                "N/s",
                f"d {effort} / d t with {p} held still: the other inputs' share "
                "(with its interface_model; else 0)",
            ),
            output(
                f"{p}.reference_position",
                "m",
                f"{position} at {p} the {effort} was linearised at: the held input at the "
                "step's end (with its interface_model; else 0)",
            ),
            output(
                f"{p}.reference_velocity",
                "m/s",
                f"{velocity} at {p} the {effort} was linearised at "
                "(with its interface_model; else 0)",
            ),
        ]
    for p in BLOCK_PORTS:
        outputs += [
            output(f"{p}.position", "m", f"Position of block {p} along its direction"),
            output(f"{p}.velocity", "m/s", f"Velocity of block {p} along its direction"),
        ]
    outputs += [
        output(
            "path_start.tension", "N", "Rope tension at the first node of the path", depends_on=deps
        ),
        output(
            "path_end.tension", "N", "Rope tension at the last node of the path", depends_on=deps
        ),
        output("tension_max", "N", "Largest rope tension in any span", depends_on=deps),
        output("slack_spans", "", "Number of slack rope spans", type=int, depends_on=deps),
        output("broken", "", "Whether any rope span has broken", type=bool),
        output(
            "stored_energy",
            "J",
            "Kinetic, strain, gravitational and contact energy",
            depends_on=deps,
        ),
        output("dissipated_energy", "J", "Energy dissipated since the start"),
        output("external_work", "J", "Work done on the block train through its ports"),
        output(
            "energy_balance",
            "J",
            "Ledger residual: stored change + dissipated - external work",
            depends_on=deps,
        ),
        mode_change_time_output("stick/slip, slack, break"),
        output(
            "mode_changes", "", "Number of mode events so far (stick/slip, slack, break)", type=int
        ),
    ]
    return params + tuple(inputs) + tuple(outputs)


def _interface(port_name: str) -> dict[str, object]:
    """A port's interface model and the parameter that switches it on for the port alone
    (``interface_model`` switches every port's)."""
    return {"interface": True, "interface_switch": f"{port_name}.interface_model"}


class BlockTrainUnit(Unit):
    """Rope reeved over sheaves on fixed and moving blocks (SPEC sections 2-6)."""

    NAME = "BlockTrain"
    DESCRIPTION = "Rope reeved over sheaves and anchors (block train), wire_fmu"
    VARIABLES = _variables()
    DATA_FIELDS = MappingProxyType({"reeving": REEVING_FIELDS})
    PORTS = (
        *(
            port(
                n,
                "rope",
                PortSide.effort,
                "tension",
                "payout_rate",
                "payout",
                flow_ramp="payout_acceleration",
                **_interface(n),
            )
            for n in LINE_PORTS
        ),
        *(
            port(
                n,
                "translational",
                PortSide.effort,
                "force",
                "velocity",
                "position",
                flow_ramp="acceleration",
                **_interface(n),
            )
            for n in MOVER_PORTS
        ),
    )

    def __init__(self, instance_name: str = "block_train") -> None:
        super().__init__(instance_name)
        self.model: BlockTrainModel | None = None
        self.initial_energy = 0.0
        self._outputs_of_quiet_steps: OutputPlan | None = None

    # ------------------------------------------------------------ life cycle
    def configure(self) -> None:
        """Parse reeving, effects and solver; build the model."""
        v = self.values
        problems: list[str] = []
        effects, effect_problems = BLOCK_TRAIN_EFFECTS.parse(v["effects"])
        problems += [f"parameter 'effects': {p}" for p in effect_problems]
        settings, solver_problems = solver_settings(v)
        problems += solver_problems
        if not (float(v["pretension"]) >= 0.0):
            problems.append(f"parameter 'pretension' must be >= 0 N, got {v['pretension']}")
        reeving = None
        try:
            data = json.loads(v["reeving"])
        except (TypeError, ValueError) as err:
            problems.append(f"parameter 'reeving' is not valid JSON: {err}")
        else:
            try:
                reeving = parse_reeving(data)
            except ConfigurationError as err:
                problems += [f"parameter 'reeving': {p}" for p in err.problems]
        if problems:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", problems)
        try:
            self.model = BlockTrainModel(reeving, effects, settings)
            problems = self._stability_problems()
        except ConfigurationError as err:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", err.problems) from None
        if problems:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", problems)
        for warning in self.model.wrap_warnings:  # legal, but most likely a mistake
            logger.warning("%s %r: parameter 'reeving': %s", self.NAME, self.instance_name, warning)

    def initialize(self, start_time: float) -> None:
        """Rope stretched for equilibrium (or pretension); outputs filled.

        Implements :meth:`Unit.initialize`.
        """
        model = self._require_model()
        segment = self.values["break_segment"]
        if not 0 <= segment <= model.n_segments:
            raise ConfigurationError(
                f"{self.NAME} {self.instance_name!r}",
                [
                    f"break_segment {segment} does not exist: 0 for none, 1..{model.n_segments} "
                    "for a segment of this reeving"
                ],
            )
        try:
            model.initialize(
                start_time,
                self._inputs(),
                equilibrium=bool(self.values["initial_equilibrium"]),
                pretension=float(self.values["pretension"]),
            )
        except ConfigurationError as err:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", err.problems) from None
        self.time = start_time
        plan = self._quiet_plan()
        if plan is not None:
            model.evaluate_start(start_time, plan)
        self.initial_energy = model.stored_energy(start_time)
        self._update_outputs()

    def _stability_problems(self) -> list[str]:
        """An rk4 step the stiffest mode of the initial state cannot be stable with."""
        model = self._require_model()
        if model.settings.method != "rk4":
            return []
        model.initialize(
            0.0,
            self._inputs(),
            equilibrium=bool(self.values["initial_equilibrium"]),
            pretension=float(self.values["pretension"]),
        )
        rate = fastest_mode(model, 0.0, model.state)
        if rate * model.settings.max_step < RK4_STABILITY:
            return []
        return [
            f"parameter 'solver_max_step' = {model.settings.max_step:g} s is unstable with "
            f"solver 'rk4' for the stiffest mode (|lambda| = {rate:.4g} 1/s): set "
            f"solver_max_step below {RK4_STABILITY / rate:.3g} s, or use solver 'ros2' "
            "(L-stable)"
        ]

    def input_problems(self) -> list[str]:
        """A commanded break of a segment the reeving does not have."""
        segment = int(self.values["break_segment"])
        n = self._require_model().n_segments
        if 0 <= segment <= n:
            return []
        return [f"break_segment {segment} does not exist (0 for none, 1..{n})"]

    def _take_quiet_step(self, time: float, step: float) -> bool:
        """A step in which nothing happens, outputs included, in a few compiled calls.

        Implements :meth:`Unit._take_quiet_step` with :meth:`CompiledBlockTrain.quiet_step_outputs
        <wire_fmu.core.units.block_train.compiled_model.CompiledBlockTrain.quiet_step_outputs>`
        when the compiled kernel runs the model's steps and no segment is commanded to
        break. The outputs a quiet step cannot change (slack spans, broken, mode changes)
        keep their values.
        """
        plan = self._quiet_plan()
        if plan is None or self.values["break_segment"]:
            return False
        taken = plan.model.quiet_step_outputs(
            time, step, self._flat_inputs(), plan, self.initial_energy
        )
        if taken is None:
            return False
        self.values.update(zip(plan.names, taken))  # noqa: B905 - as many by construction
        self.time = time + step
        return True

    def _quiet_plan(self) -> OutputPlan | None:
        """The outputs of a quiet step for the present model and published ports (made
        when either changes), or None when the model's steps are not compiled."""
        m = self.model
        if m is None or not (m.compiled and isinstance(m.solver, CompiledFixedStep)):
            return None
        ports = self._interface_ports()
        plan = self._outputs_of_quiet_steps
        if plan is None or plan.model is not m or plan.ports != ports:
            plan = output_plan(m, *self._output_plan(m), ports)
            self._outputs_of_quiet_steps = plan
        return plan

    def _advance(self, time: float, step: float) -> list[str]:
        """Integrate the rope (breaking a commanded segment first); its events as text."""
        model = self._require_model()
        segment = int(self.values["break_segment"])
        model.advance(time, step, self._inputs(), segment - 1 if segment else None)
        return list(model.last_events)

    def evaluate_outputs(self) -> None:
        """Outputs for the inputs now set, at the current time; the state is untouched."""
        model = self._require_model()
        held = model.held_inputs()
        model.set_inputs(self.time, self._inputs())
        try:
            self._update_outputs()
        finally:
            model.restore_held_inputs(held)

    def ode(self) -> OdeView:
        """The block train's hybrid ODE, for a monolithic model."""
        return _BlockTrainOde(self, self._require_model())

    # ---------------------------------------------------------------- state
    def get_state(self) -> dict[str, Any]:
        """Complete state: continuous state, modes, broken spans, offsets."""
        m = self._require_model()
        return {
            "x": [float(c) for c in m.state],
            "offsets": [float(c) for c in m.offsets],
            "broken": list(m.broken),
            "taut": [bool(b) for b in m.taut_mask],
            "contact": [bool(b) for b in m.contact_mask],
            "friction_mode": m.friction.get_mode(),
            "mode_changes": m.mode_changes,
            "time": float(getattr(self, "time", 0.0)),
            "initial_energy": float(self.initial_energy),
            "held_inputs": m.held_inputs(),
            "solver": {"rhs_calls": m.solver.rhs_calls, "steps": m.solver.steps},
        }

    def _snapshot(self) -> tuple:
        """The model's arrays, modes and held inputs, copied (cheaper than :meth:`get_state`)."""
        m = self._require_model()
        return (
            m.state.copy(),
            m.offsets.copy(),
            m.broken_mask.copy(),
            m.taut_mask.copy(),
            m.contact_mask.copy(),
            m.friction.mode.copy(),
            m.mode_changes,
            m.inputs,
            m._t_step,
            m._held_positions.copy(),
            m.solver.rhs_calls,
            m.solver.steps,
            self.time,
        )

    def _restore_snapshot(self, saved: tuple) -> None:
        """Implements :meth:`Unit._restore_snapshot`."""
        m = self._require_model()
        (m.state, m.offsets, m.broken_mask, m.taut_mask, m.contact_mask, mode, m.mode_changes,
         inputs, t_step, m._held_positions, m.solver.rhs_calls, m.solver.steps,
         self.time) = saved  # fmt: skip
        m.friction.set_mode(mode)
        m.set_inputs(t_step, inputs)
        self._update_outputs()

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore a state from :meth:`get_state`.

        Parameters
        ----------
        state : mapping
            A state returned by :meth:`get_state` of this unit.
        """
        m = self._require_model()
        m.state = np.array(state["x"], dtype=float)
        m.offsets = np.array(state["offsets"], dtype=float)
        m.broken = list(state["broken"])
        m.taut_mask = np.array(state["taut"], dtype=bool)
        m.contact_mask = np.array(state["contact"], dtype=bool)
        m.friction.set_mode(list(state["friction_mode"]))
        m.mode_changes = int(state["mode_changes"])
        m.restore_held_inputs(state["held_inputs"])
        m._held_positions = m.q.copy()
        self.time = float(state["time"])
        self.initial_energy = float(state["initial_energy"])
        self._update_outputs()

    # -------------------------------------------------------------- helpers
    def _inputs(self) -> BlockTrainInputs:
        return BlockTrainInputs.from_flat(self._flat_inputs())

    def _flat_inputs(self) -> tuple[float, ...]:
        """The kinematic inputs' values in the order of :data:`~.model.FLAT_INPUTS`."""
        return tuple(map(float, _TAKE_INPUTS(self.values)))

    def _output_plan(self, m: BlockTrainModel) -> tuple[list, list, list]:
        """Which span, body and coordinate feed each port output (built once per model)."""
        plan = getattr(self, "_plan", None)
        if plan is not None and plan[0] is m:
            return plan[1]
        nb = len(m.blocks)
        lines = [
            (f"{m.nodes[k].name}.tension", 0 if k == 0 else len(m.spans) - 1)
            for k in (0, m.n_nodes - 1)
            if m.nodes[k].kind == "line_end"
        ]
        drivers = [(f"{b.port}.force", nb + j) for j, b in enumerate(m.drivers)]
        blocks = [
            (f"{b.port}.position", f"{b.port}.velocity", j, b.position)
            for j, b in enumerate(m.blocks)
            if b.port
        ]
        self._plan = (m, (lines, drivers, blocks))
        return lines, drivers, blocks

    def _update_outputs(self) -> None:
        m = self._require_model()
        # inputs as they evolved over the last step
        rope_energy, potential, tension, body_force = m.summary(self.time, m.state)
        out = self.values
        lines, drivers, blocks = self._output_plan(m)
        tensions, forces, x = tension.tolist(), body_force.tolist(), m.state.tolist()
        for name, span in lines:
            out[name] = tensions[span]
        for name, j in drivers:
            out[name] = forces[j]
        n = m.n_coords
        for position, velocity, j, start in blocks:
            out[position] = start + x[j]
            out[velocity] = x[n + j]
        out["path_start.tension"] = tensions[0]
        out["path_end.tension"] = tensions[-1]
        out["tension_max"] = max(tensions) if tensions else 0.0
        # the masks as bytes (0 or 1 each): counted in C, cheaper than numpy on a few spans
        broken = m.broken_mask.tobytes()
        out["slack_spans"] = bytes(map(operator.or_, m.taut_mask.tobytes(), broken)).count(0)
        out["broken"] = 1 in broken
        stored = m.kinetic_energy(x) + rope_energy + potential
        out["stored_energy"] = float(stored)
        out["dissipated_energy"] = x[2 * n]
        out["external_work"] = x[2 * n + 1]
        out["energy_balance"] = float(
            stored - self.initial_energy + out["dissipated_energy"] - out["external_work"]
        )
        out["mode_changes"] = int(m.mode_changes)
        ports = self._interface_ports()
        if ports:
            self._update_interface_outputs(m, ports)
        if not (math.isfinite(out["stored_energy"]) and math.isfinite(out["tension_max"])):
            raise FloatingPointError(f"{self.instance_name}: non-finite outputs")

    def _interface_ports(self) -> tuple[str, ...]:
        """The ports whose interface model is published: all with ``interface_model``, else
        those whose own ``<port>.interface_model`` is set."""
        v = self.values
        if v["interface_model"]:
            return _INTERFACE_PORTS
        return tuple(itertools.compress(_INTERFACE_PORTS, _TAKE_SWITCHES(v)))

    def _update_interface_outputs(self, m: BlockTrainModel, ports: tuple[str, ...]) -> None:
        """The interface model (see :mod:`.interface`) of each of ``ports`` the reeving
        uses into its outputs; the other ports' are left as they are."""
        kept = getattr(self, "_interface", None)
        if kept is None or kept[0] is not m or kept[1] != ports:
            plan = interface_plan(m, ports)
            names = tuple(f"{p}.{q}" for p in plan.names for q in INTERFACE_QUANTITIES)
            kept = self._interface = (m, ports, plan, names)
        _, _, plan, names = kept
        table = linearisation_table(m, plan, self.time, m.state)  # a row per port
        self.values.update(zip(names, table.ravel().tolist(), strict=True))


class _BlockTrainOde(ModelOdeView):
    """:class:`BlockTrainUnit` as a piece of a monolithic ODE."""

    def bind_inputs(self, t: float) -> None:
        """Inputs in ``values`` are the values at ``t``.

        Parameters
        ----------
        t : float
            Time, s.
        """
        self.model.set_inputs(t, self.unit._inputs())

    def reconcile(self, t, x):
        """Break a commanded segment, then settle contact and friction modes.

        Implements :meth:`OdeView.reconcile`.
        """
        m = self.model
        m.state = np.array(x, dtype=float)
        self.bind_inputs(t)
        segment = int(self.unit.values["break_segment"])
        if 0 < segment <= m.n_segments:
            m._break_span(m.span_of_segment[segment - 1], m.state, t)
        m._settle_contact_modes(t, m.state)
        m.state = m._settle_modes(t, m.state)
        return m.state.copy()

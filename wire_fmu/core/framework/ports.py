"""Ports: the named places where a unit exchanges power with another.

A port groups the variables of one power bond on one unit: the *effort*
(force, tension, torque), the *flow* (velocity, payout rate, speed) and
optionally the *position* the flow integrates to. Across a bond, one unit
computes the effort from the motion it is given (its port is on the
``effort`` side: effort an output, flow and position inputs) and the other
computes the motion from the effort it is given (``flow`` side: the reverse).

A unit declares its ports in ``PORTS``; the FMU carries them in its model
description (``VendorAnnotations``), so that a scene can bond two ports by
name, ``"cylinder.rod <-> rope.mover_a"``, and the master derives the three
connections.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

__all__ = [
    "FLOW_RAMP_UNITS",
    "INTERFACE_QUANTITIES",
    "INTERFACE_UNITS",
    "PORT_KINDS",
    "Port",
    "PortSide",
    "port",
]

PORT_KINDS = {
    # kind: (effort unit, flow unit, position unit)
    "translational": ("N", "m/s", "m"),
    "rope": ("N", "m/s", "m"),
    "rotational": ("N.m", "rad/s", "rad"),
}
"""Kinds of power port and the SI units of their effort, flow and position."""

INTERFACE_QUANTITIES = (
    "stiffness",
    "damping",
    "effort_rate",
    "reference_position",
    "reference_velocity",
)
"""The interface model of a port's effort, as ``{port}.{quantity}`` variables.

``effort(x, v, t) ~ effort - stiffness (x - reference_position)
- damping (v - reference_velocity) + effort_rate (t - t0)`` about the communication
point ``t0``: outputs of the effort side, inputs of a flow side that integrates its
step against this local model instead of a held effort.
"""
INTERFACE_UNITS = {
    "translational": ("N/m", "N.s/m", "N/s", "m", "m/s"),
    "rope": ("N/m", "N.s/m", "N/s", "m", "m/s"),
    "rotational": ("N.m/rad", "N.m.s/rad", "N.m/s", "rad", "rad/s"),
}
"""SI units of the :data:`INTERFACE_QUANTITIES` by port kind."""
FLOW_RAMP_UNITS = {"translational": "m/s2", "rope": "m/s2", "rotational": "rad/s2"}
"""SI unit of a flow's rate of change (a port's ``flow_ramp`` input) by port kind."""


class PortSide(StrEnum):
    """Which of the bond's two quantities the unit computes at this port."""

    effort = "effort"
    """The unit outputs the effort and takes the flow (and position) as inputs."""
    flow = "flow"
    """The unit outputs the flow (and position) and takes the effort as input."""


@dataclass(frozen=True)
class Port:
    """One power port of a unit.

    Parameters
    ----------
    name : str
        The port's name, unique in its unit (``"rod"``, ``"line_a"``).
    kind : str
        One of :data:`PORT_KINDS`.
    side : PortSide
        Which quantity the unit computes here.
    effort, flow : str
        Names of the unit's effort and flow variables at the port.
    position : str or None
        Name of the position variable the flow integrates to, if any.
    description : str
        What the port is, for listings.
    interface : bool
        Whether the port carries the interface model (:data:`INTERFACE_QUANTITIES`):
        outputs on the effort side, inputs on the flow side.
    interface_switch : str or None
        On the effort side, the Boolean parameter that turns the interface model's
        computation on (the master sets it when it wires the model).
    flow_ramp : str or None
        On the effort side, the input that takes the flow's rate of change over the
        step (:data:`FLOW_RAMP_UNITS`): the flow input is then its value at the step's
        start and ramps from there (a ramped flow), instead of being held.
    """

    name: str
    kind: str
    side: PortSide
    effort: str
    flow: str
    position: str | None = None
    description: str = ""
    interface: bool = False
    interface_switch: str | None = None
    flow_ramp: str | None = None

    @property
    def variables(self) -> tuple[str, ...]:
        """The port's variable names: effort, flow and (if any) position."""
        return (self.effort, self.flow) + ((self.position,) if self.position else ())

    @property
    def interface_variables(self) -> dict[str, str]:
        """Variable name of each interface quantity by quantity (empty without a model)."""
        if not self.interface:
            return {}
        return {q: f"{self.name}.{q}" for q in INTERFACE_QUANTITIES}

    def problems(self, causality: dict[str, str], units: dict[str, str]) -> list[str]:
        """What is wrong with the port against its unit's variables (empty when sound).

        Parameters
        ----------
        causality : dict of str to str
            Causality (``"input"``, ``"output"``, ...) of every variable of the unit, by name.
        units : dict of str to str
            SI unit of every Real variable of the unit, by name.
        """
        if self.kind not in PORT_KINDS:
            return [f"port {self.name!r}: kind {self.kind!r} is not one of {sorted(PORT_KINDS)}"]
        gives = "output" if self.side is PortSide.effort else "input"
        takes = "input" if gives == "output" else "output"
        wanted = {self.effort: gives, self.flow: takes}
        if self.position:
            wanted[self.position] = takes
        expected = list(zip(wanted.items(), PORT_KINDS[self.kind], strict=False))
        if self.interface:
            units_wanted = INTERFACE_UNITS[self.kind]
            names = self.interface_variables.values()
            expected += [((n, gives), u) for n, u in zip(names, units_wanted, strict=True)]
        if self.flow_ramp:
            expected.append(((self.flow_ramp, takes), FLOW_RAMP_UNITS[self.kind]))
        problems = []
        for (name, want), unit in expected:
            if causality.get(name) != want:
                problems.append(f"port {self.name!r}: {name!r} must be an {want} of the unit")
            elif units.get(name) != unit:
                problems.append(f"port {self.name!r}: {name!r} must be in {unit}")
        if self.interface_switch and (not self.interface or self.side is not PortSide.effort):
            problems.append(
                f"port {self.name!r}: an interface switch belongs to an effort-side port "
                "with an interface model"
            )
        elif self.interface_switch and causality.get(self.interface_switch) != "parameter":
            problems.append(
                f"port {self.name!r}: interface switch {self.interface_switch!r} must be a "
                "parameter of the unit"
            )
        if self.flow_ramp and self.side is not PortSide.effort:
            problems.append(f"port {self.name!r}: a flow ramp belongs to an effort-side port")
        return problems


def port(
    name: str,
    kind: str,
    side: PortSide,
    effort: str,
    flow: str,
    position: str | None = None,
    description: str = "",
    interface: bool = False,
    interface_switch: str | None = None,
    flow_ramp: str | None = None,
) -> Port:
    """A :class:`Port` whose variable names without a dot are taken under the port's name.

    ``port("rod", "translational", PortSide.flow, "force", "velocity", "displacement")``
    declares ``rod.force``, ``rod.velocity`` and ``rod.displacement``; a name with a dot
    (``"shaft.speed"``) is taken as it is.

    Parameters
    ----------
    name, kind, side, effort, flow, position, description, interface, interface_switch, flow_ramp
        As for :class:`Port`; ``effort``, ``flow``, ``position`` and ``flow_ramp`` may be
        short names.
    """

    def full(variable: str | None) -> str | None:
        """``variable`` under the port's name unless it has a dot (None stays None).

        Parameters
        ----------
        variable : str or None
            Short or full variable name.
        """
        return variable if variable is None or "." in variable else f"{name}.{variable}"

    return Port(
        name,
        kind,
        side,
        full(effort),
        full(flow),
        full(position),
        description,
        interface,
        interface_switch,
        full(flow_ramp),
    )

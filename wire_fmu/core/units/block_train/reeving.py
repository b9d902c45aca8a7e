"""A reeving: bodies, sheaves, anchors and the ordered rope path over them.

The description is plain data (JSON-compatible dicts), so a scene file or an
FMU string parameter can carry it. :func:`~.reeving_parse.parse_reeving` checks it whole and
raises one :class:`~wire_fmu.core.errors.ConfigurationError` that lists
every problem, each naming the element at fault.

Format (all lengths m, masses kg, forces N, angles in degrees where named)::

    {
      "rope": {"axial_stiffness": 5.8e7, "damping": 1.2e5,
               "breaking_load": 1.0e6, "linear_mass": 6.2},
      "gravity": [0, -9.81, 0],
      "bodies": {
        "travelling_block": {"kind": "block", "mass": 2.2e5,
                             "direction": [0, 1, 0], "position": 15.0,
                             "port": "block_a",
                             "floor": {"position": 2.0, "stiffness": 5e8,
                                       "damping": 2e6}},
        "rod": {"kind": "driven", "direction": [1, 0, 0], "port": "mover_a"}
      },
      "sheaves": {
        "crown_0": {"body": "ground", "centre": [0, 45, 0], "radius": 0.76,
                    "axis": [0, 0, 1], "inertia": 180.0,
                    "bearing_torque": 0.0, "efficiency": 0.9615,
                    "groove_friction": 0.1}
      },
      "anchors": {"deadline": {"body": "ground", "point": [9.9, 0, 0]}},
      "path": [
        {"line_end": "line_a", "point": [-0.76, 0, 0]},
        {"sheave": "crown_0", "wrap": "cw"},
        ...,
        {"anchor": "deadline"}
      ],
      "max_fleet_angle_deg": 2.5
    }

Bodies move in translation only, each along its unit ``direction``; the
``ground`` body always exists. A ``block`` has mass and is a state of the
block train (its sheaves' translational mass is part of ``mass``); a
``driven`` body's motion is an input at its port (``mover_a`` or
``mover_b``) and the rope's force on it is an output. A rope end is either
an anchor on a body or a *line end* (port ``line_a`` or ``line_b``) through
which rope is paid out, e.g. by a winch. Centres and points are given at
zero body displacement. Wrap ``ccw``/``cw`` is the sense in which the rope,
followed along the path, goes round the sheave about its axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from wire_fmu.core.components.rope import RopeProperties

__all__ = [
    "Body",
    "Floor",
    "SheaveSpec",
    "AnchorSpec",
    "PathElement",
    "Reeving",
    "LINE_PORTS",
    "MOVER_PORTS",
    "BLOCK_PORTS",
]

LINE_PORTS = ("line_a", "line_b")
MOVER_PORTS = ("mover_a", "mover_b")
BLOCK_PORTS = ("block_a", "block_b")
_WRAPS = {"ccw": 1, "cw": -1}

Vector = tuple[float, float, float]


@dataclass(frozen=True)
class Floor:
    """A support a block lands on: it only pushes.

    Parameters
    ----------
    position : float
        Body coordinate (along its direction) at which contact begins, m.
    stiffness : float
        Contact stiffness, N/m.
    damping : float
        Contact damping, N s/m.
    """

    position: float
    stiffness: float
    damping: float = 0.0


@dataclass(frozen=True)
class Body:
    """A rigid body that carries sheaves or anchors (translation only)."""

    name: str
    kind: str  # "ground", "block" or "driven"
    direction: Vector = (0.0, 1.0, 0.0)
    mass: float = 0.0
    position: float = 0.0
    port: str | None = None
    floor: Floor | None = None
    on: str = "ground"


@dataclass(frozen=True)
class SheaveSpec:
    """A sheave on a body (a fork's axle is the body; several may share it)."""

    name: str
    body: str
    centre: Vector
    radius: float
    axis: Vector = (0.0, 0.0, 1.0)
    inertia: float = 0.0
    bearing_torque: float = 0.0
    efficiency: float = 1.0
    groove_friction: float = 0.1


@dataclass(frozen=True)
class AnchorSpec:
    """A rope end clamped to a body."""

    name: str
    body: str
    point: Vector


@dataclass(frozen=True)
class PathElement:
    """One node of the rope path.

    ``kind`` is ``"sheave"``, ``"anchor"`` or ``"line_end"``; ``name`` is the
    sheave or anchor name, or the port name of a line end; ``sense`` is +1
    (ccw) or -1 (cw) for a sheave and 0 otherwise.
    """

    kind: str
    name: str
    sense: int = 0
    point: Vector | None = None
    body: str = "ground"


@dataclass(frozen=True)
class Reeving:
    """A validated reeving."""

    rope: RopeProperties
    gravity: Vector
    bodies: dict[str, Body]
    sheaves: dict[str, SheaveSpec]
    anchors: dict[str, AnchorSpec]
    path: tuple[PathElement, ...]
    max_fleet_angle: float = math.radians(2.5)
    source: dict[str, Any] = field(default_factory=dict, compare=False)

    def node_body(self, element: PathElement) -> str:
        """The body a path node is fixed to.

        Parameters
        ----------
        element : PathElement
            A node of :attr:`path`.

        Returns
        -------
        str
            The body's name (``"ground"`` if fixed).
        """
        if element.kind == "sheave":
            return self.sheaves[element.name].body
        if element.kind == "anchor":
            return self.anchors[element.name].body
        return element.body

    def carriers(self, body: str) -> list[str]:
        """``body`` and the bodies it rides on, innermost first (ground excluded).

        Parameters
        ----------
        body : str
            Body name (``"ground"`` gives none).
        """
        chain = []
        while body != "ground":
            chain.append(body)
            body = self.bodies[body].on
        return chain

    def bodies_of_kind(self, kind: str) -> list[Body]:
        """Bodies of one kind, in declaration order.

        Parameters
        ----------
        kind : str
            ``"block"`` or ``"driven"``.
        """
        return [b for b in self.bodies.values() if b.kind == kind]

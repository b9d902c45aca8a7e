"""The keys of a reeving description, each declared once: unit, default, range, effects.

:func:`~.reeving_parse.parse_reeving` reads defaults and bounds from here, and
the parameter reference (``wire-fmu info BlockTrain``) and the scene checks
(which keys the chosen effects leave without influence) read the same
declarations. The format itself is described in :mod:`~.reeving`.
"""

from __future__ import annotations

import math
from types import MappingProxyType

from wire_fmu.core.framework.data_fields import DataField

__all__ = ["REEVING_FIELDS", "FIELD"]

_DAMPING = ("rope_damping",)
_INERTIA = ("sheave_inertia",)
_BEARING = ("bearing_friction",)
_SLIP = ("rope_slip",)


def _number(path: str, unit: str, description: str, default=None, **more) -> DataField:
    """A numeric key; ``default`` None makes it required unless ``more`` says otherwise."""
    more.setdefault("required", default is None)
    return DataField(path, "number", unit, description, default, **more)


def _vector(path: str, unit: str, description: str, default=None, **more) -> DataField:
    more.setdefault("required", default is None)
    return DataField(path, "vector", unit, description, default, **more)


def _text(path: str, description: str, default=None, **more) -> DataField:
    return DataField(path, "text", "", description, default, **more)


_ROPE = (
    _number(
        "rope.axial_stiffness",
        "N",
        "Axial stiffness EA (force per unit strain); give it, or metallic_area and modulus",
        min=0.0,
        min_exclusive=True,
        required=False,
    ),
    _number(
        "rope.damping",
        "N.s",
        "Kelvin-Voigt coefficient c (force per unit strain rate), with axial_stiffness",
        0.0,
        min=0.0,
        acts_with=_DAMPING,
    ),
    _number(
        "rope.metallic_area",
        "m2",
        "Metallic cross-section A_w (eq. 4), when axial_stiffness is not given",
        min=0.0,
        min_exclusive=True,
        required=False,
    ),
    _number(
        "rope.modulus",
        "Pa",
        "Young's modulus of the rope E_w (eq. 4), when axial_stiffness is not given",
        min=0.0,
        min_exclusive=True,
        required=False,
    ),
    _number(
        "rope.fill_factor",
        "1",
        "Fill factor k_f, metal area over section area (eq. 4), with metallic_area",
        1.0,
        min=0.0,
        max=1.0,
        min_exclusive=True,
    ),
    _number(
        "rope.viscosity",
        "Pa.s",
        "Kelvin-Voigt viscosity eta (eq. 5), with metallic_area",
        0.0,
        min=0.0,
        acts_with=_DAMPING,
    ),
    _number(
        "rope.breaking_load",
        "N",
        "Tension at which a span breaks (inf: never)",
        math.inf,
        min=0.0,
        min_exclusive=True,
    ),
    _number(
        "rope.linear_mass",
        "kg/m",
        "Rope mass per metre: the rope lying on each groove, a mass of its own when it may slip",
        0.0,
        min=0.0,
        acts_with=_SLIP,
    ),
)

_BODIES = (
    _text("bodies.<name>.kind", "'block' (a mass, a state) or 'driven' (motion an input)"),
    _vector("bodies.<name>.direction", "1", "Unit direction the body moves along", (0.0, 1.0, 0.0)),
    _number(
        "bodies.<name>.mass",
        "kg",
        "Mass of a block with its sheaves and load (blocks only)",
        min=0.0,
        min_exclusive=True,
    ),
    _number(
        "bodies.<name>.position",
        "m",
        "Block coordinate along its direction at the start (blocks only)",
        0.0,
    ),
    _text(
        "bodies.<name>.port",
        "Port of the body: block_a/block_b for a block (outputs), mover_a/mover_b for a "
        "driven body (its motion an input)",
    ),
    _text(
        "bodies.<name>.on",
        "Driven body this driven body rides on (a crown on a heaving deck)",
        "ground",
    ),
    _number(
        "bodies.<name>.floor.position",
        "m",
        "Block coordinate at which it lands on its support (the support only pushes)",
    ),
    _number(
        "bodies.<name>.floor.stiffness",
        "N/m",
        "Contact stiffness of the support",
        min=0.0,
        min_exclusive=True,
    ),
    _number("bodies.<name>.floor.damping", "N.s/m", "Contact damping of the support", 0.0, min=0.0),
)

_SHEAVES = (
    _text("sheaves.<name>.body", "Body the sheave's axle is fixed to", "ground"),
    _vector("sheaves.<name>.centre", "m", "Centre of the sheave at zero displacement of its body"),
    _number(
        "sheaves.<name>.radius",
        "m",
        "Working radius (to the rope's centreline)",
        min=0.0,
        min_exclusive=True,
    ),
    _vector(
        "sheaves.<name>.axis", "1", "Axis of the sheave (wrap sense about it)", (0.0, 0.0, 1.0)
    ),
    _number(
        "sheaves.<name>.inertia",
        "kg.m2",
        "Moment of inertia J_p of the sheave about its axle (eq. 11)",
        0.0,
        min=0.0,
        acts_with=_INERTIA,
    ),
    _number(
        "sheaves.<name>.bearing_torque",
        "N.m",
        "Load-independent bearing friction torque M_f (eq. 11)",
        0.0,
        min=0.0,
        acts_with=_BEARING,
    ),
    _number(
        "sheaves.<name>.efficiency",
        "1",
        "Sheave efficiency K, the tension ratio across the sheave in steady motion: a bearing "
        "friction torque (1 - K)/(1 + K) R (T_in + T_out)",
        1.0,
        min=0.0,
        max=1.0,
        min_exclusive=True,
        acts_with=_BEARING,
    ),
    _number(
        "sheaves.<name>.groove_friction",
        "1",
        "Rope-groove friction coefficient mu of the capstan law (eq. 9, 12)",
        0.1,
        min=0.0,
        acts_with=_SLIP,
    ),
)

_OTHER = (
    _text("name", "Name of the reeving, for drawings and messages"),
    _text("description", "What the reeving is, for humans"),
    _vector("gravity", "m/s2", "Gravitational acceleration", (0.0, -9.81, 0.0)),
    _text("anchors.<name>.body", "Body a rope end is clamped to", "ground"),
    _vector("anchors.<name>.point", "m", "Where the rope end is clamped, at zero displacement"),
    DataField(
        "path", "list", "", "The rope's path, from one rope end over the sheaves to the other"
    ),
    _text("path[i].sheave", "A sheave the rope passes over"),
    _text("path[i].wrap", "Sense the rope goes round that sheave about its axis: 'ccw' or 'cw'"),
    _text("path[i].anchor", "An anchor at an end of the path"),
    _text("path[i].line_end", "A line end at an end of the path: port line_a or line_b"),
    _vector("path[i].point", "m", "Where a line end leaves the path (line ends only)"),
    _text("path[i].body", "Body a line end is on (line ends only)", "ground"),
    _number(
        "max_fleet_angle_deg",
        "deg",
        "Largest fleet angle a rope may leave a sheave's plane at",
        2.5,
        min=0.0,
        max=45.0,
        min_exclusive=True,
    ),
)

REEVING_FIELDS: tuple[DataField, ...] = _OTHER[:3] + _ROPE + _BODIES + _SHEAVES + _OTHER[3:]
"""Every key of a reeving description, in the order the reference lists them."""

FIELD = MappingProxyType({f.path: f for f in REEVING_FIELDS})
"""The declarations by path."""

"""Reading a reeving from plain data (JSON or a TOML table): every problem named at once.

:func:`parse_reeving` turns the data into a :class:`~.reeving.Reeving` or raises
:class:`~wire_fmu.core.errors.ConfigurationError` listing every problem, each
with where it is (``sheave 'crown_1': 'radius' must be > 0 m, got -1``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

from wire_fmu.core.components.rope import RopeProperties
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.units.block_train.reeving import (
    _WRAPS,
    BLOCK_PORTS,
    LINE_PORTS,
    MOVER_PORTS,
    AnchorSpec,
    Body,
    Floor,
    PathElement,
    Reeving,
    SheaveSpec,
    Vector,
)
from wire_fmu.core.units.block_train.reeving_fields import FIELD

__all__ = ["parse_reeving"]


class _Problems:
    """Collects problems while parsing, each prefixed with where it is."""

    def __init__(self) -> None:
        self.items: list[str] = []

    def add(self, where: str, text: str) -> None:
        """Record ``text`` as a problem at ``where``.

        Parameters
        ----------
        where : str
            The element at fault, e.g. ``"sheave 'crown_0'"``.
        text : str
            The problem.
        """
        self.items.append(f"{where}: {text}")

    def number(
        self,
        data: Mapping,
        key: str,
        where: str,
        default: Any = None,
        *,
        positive: bool = False,
        nonnegative: bool = False,
        at_most: float | None = None,
        finite: bool = True,
    ) -> float:
        """A number ``data[key]``; a problem recorded if missing, not a number or out of range.

        Parameters
        ----------
        data : mapping
            The description holding the number.
        key : str
            Its key.
        where : str
            The element, for the problem's text.
        default : Any
            Value when ``key`` is absent; None makes it required.
        positive, nonnegative : bool
            Require ``> 0``, ``>= 0``.
        at_most : float or None
            Upper bound; None for none.
        finite : bool
            Require a finite value.

        Returns
        -------
        float
            The value (NaN if missing or not a number).
        """
        value = data.get(key, default)
        if value is None:
            self.add(where, f"'{key}' is required")
            return math.nan
        if isinstance(value, bool) or not isinstance(value, int | float):  # no silent casts
            self.add(where, f"'{key}' must be a number, got {value!r}")
            return math.nan
        try:
            value = float(value)
        except OverflowError:
            self.add(where, f"'{key}' is too large, got {value!r}")
            return math.nan
        if math.isnan(value):
            self.add(where, f"'{key}' must be a number, got NaN")
        elif finite and math.isinf(value):
            self.add(where, f"'{key}' must be finite, got {value:g}")
        elif positive and not value > 0:
            self.add(where, f"'{key}' must be > 0, got {value:g}")
        elif nonnegative and value < 0:
            self.add(where, f"'{key}' must be >= 0, got {value:g}")
        elif at_most is not None and value > at_most:
            self.add(where, f"'{key}' must be <= {at_most:g}, got {value:g}")
        return value

    def declared(self, data: Mapping, path: str, where: str) -> Any:
        """The key declared at ``path`` (:mod:`.reeving_fields`): its default and bounds.

        Parameters
        ----------
        data : mapping
            The table holding the key.
        path : str
            The key's declared path, e.g. ``"sheaves.<name>.efficiency"``.
        where : str
            The element, for the problem's text.

        Returns
        -------
        float or Vector
            The value (NaN if missing or invalid).
        """
        field = FIELD[path]
        default = None if field.required else field.default
        if field.kind == "vector":
            return self.vector(data, field.key, where, default, unit=field.unit == "1")
        low = field.min
        if low not in (None, 0.0):
            raise ValueError(f"{path}: only 0 is supported as a lower bound")
        infinite_default = isinstance(default, float) and math.isinf(default)
        return self.number(
            data,
            field.key,
            where,
            default,
            positive=low is not None and field.min_exclusive,
            nonnegative=low is not None and not field.min_exclusive,
            at_most=field.max,
            finite=not infinite_default,
        )

    def vector(
        self, data: Mapping, key: str, where: str, default: Any = None, *, unit: bool = False
    ) -> Vector:
        """Three finite numbers ``data[key]`` as a vector; a problem recorded otherwise.

        Parameters
        ----------
        data : mapping
            The description holding the vector.
        key : str
            Its key.
        where : str
            The element, for the problem's text.
        default : Any
            Value when ``key`` is absent.
        unit : bool
            Normalise to unit length (the zero vector is a problem).

        Returns
        -------
        Vector
            The vector (NaNs if invalid).
        """
        value = data.get(key, default)
        try:
            if any(isinstance(c, bool) or not isinstance(c, int | float) for c in value):
                raise TypeError
            vec = tuple(float(c) for c in value)
            if len(vec) != 3 or not all(math.isfinite(c) for c in vec):
                raise ValueError
        except (TypeError, ValueError, OverflowError):
            self.add(where, f"'{key}' must be three finite numbers [x, y, z] (m), got {value!r}")
            return (math.nan, math.nan, math.nan)
        if unit:
            norm = math.sqrt(sum(c * c for c in vec))
            if norm == 0.0:
                self.add(where, f"'{key}' must not be the zero vector")
                return vec
            vec = tuple(c / norm for c in vec)
        return vec


def _known(name: Any, names: Mapping[str, Any]) -> bool:
    """Whether ``name`` is text and one of ``names`` (a list or table given for a name is not,
    rather than an error of its own).

    Parameters
    ----------
    name : Any
        The name as given.
    names : mapping
        The names defined, as keys.
    """
    return isinstance(name, str) and name in names


def parse_reeving(data: Mapping[str, Any]) -> Reeving:
    """Validate a reeving description and build a :class:`Reeving`.

    Parameters
    ----------
    data : mapping
        The description: ``rope``, ``gravity`` (m/s^2), ``bodies``, ``sheaves``,
        ``anchors``, ``path``, optional ``max_fleet_angle_deg`` (deg), ``name``,
        ``description`` (lengths in m, masses in kg, forces in N).

    Raises
    ------
    ConfigurationError
        Listing every problem found, each naming the element at fault.
    """
    p = _Problems()
    if not isinstance(data, Mapping):
        raise ConfigurationError("reeving", [f"must be a mapping, got {type(data).__name__}"])
    known = {
        "rope",
        "gravity",
        "bodies",
        "sheaves",
        "anchors",
        "path",
        "max_fleet_angle_deg",
        "name",
        "description",
    }
    for key in data:
        if key not in known:
            p.add("reeving", f"unknown key {key!r}; known keys: {', '.join(sorted(known))}")
    rope = _parse_rope(data.get("rope", {}), p)
    gravity = p.declared(data, "gravity", "reeving")
    bodies = _parse_bodies(data.get("bodies", {}), p)
    sheaves = _parse_sheaves(data.get("sheaves", {}), bodies, p)
    anchors = _parse_anchors(data.get("anchors", {}), bodies, p)
    _check_names(sheaves, anchors, p)
    path = _parse_path(data.get("path", []), sheaves, anchors, bodies, p)
    fleet = p.declared(data, "max_fleet_angle_deg", "reeving")
    _check_ports(bodies, path, p)
    if p.items:
        raise ConfigurationError("reeving", p.items)
    return Reeving(rope, gravity, bodies, sheaves, anchors, path, math.radians(fleet), dict(data))


def _parse_rope(data: Mapping, p: _Problems) -> RopeProperties:
    where = "rope"
    if not isinstance(data, Mapping):
        p.add(where, "must be a mapping")
        return RopeProperties(1.0)
    if "axial_stiffness" in data:
        ea = p.declared(data, "rope.axial_stiffness", where)
        damping = p.declared(data, "rope.damping", where)
    else:
        ea, damping = _section_stiffness(data, where, p)
    breaking = p.declared(data, "rope.breaking_load", where)
    linear_mass = p.declared(data, "rope.linear_mass", where)
    return RopeProperties(ea, damping, breaking, linear_mass)


def _section_stiffness(data: Mapping, where: str, p: _Problems) -> tuple[float, float]:
    """EA (N) and the damping coefficient (N s) from metallic area, modulus, fill and viscosity.

    Without ``axial_stiffness`` the rope needs both ``metallic_area`` and ``modulus``; a
    problem naming both ways to give the stiffness is recorded when either is missing.

    Parameters
    ----------
    data : mapping
        The rope's table (no ``axial_stiffness``).
    where : str
        The rope, for the problems' text.
    p : _Problems
        Where problems are recorded.

    Returns
    -------
    tuple of float
        EA (N) and damping coefficient (N s); NaN when the stiffness is not given.
    """
    given = [key for key in ("metallic_area", "modulus") if key in data]
    if not given:
        p.add(
            where,
            "its stiffness is required: give 'axial_stiffness' (EA, N), or "
            "'metallic_area' (m2) and 'modulus' (Pa)",
        )
    elif len(given) == 1:
        (have,) = given
        missing = "modulus" if have == "metallic_area" else "metallic_area"
        p.add(where, f"'{missing}' is required with '{have}' (or give 'axial_stiffness' instead)")
    values = {key: p.declared(data, f"rope.{key}", where) for key in given}
    fill = p.declared(data, "rope.fill_factor", where)
    viscosity = p.declared(data, "rope.viscosity", where)
    if len(values) < 2:
        return math.nan, math.nan
    area, modulus = values["metallic_area"], values["modulus"]
    return area * fill * modulus, area * fill * viscosity


def _parse_bodies(data: Mapping, p: _Problems) -> dict[str, Body]:
    bodies = {"ground": Body("ground", "ground")}
    if not isinstance(data, Mapping):
        p.add("bodies", "must be a mapping of name -> body")
        return bodies
    for name, spec in data.items():
        where = f"body {name!r}"
        if name == "ground":
            p.add(where, "'ground' is built in and cannot be redefined")
            continue
        kind = spec.get("kind") if isinstance(spec, Mapping) else None
        if kind not in ("block", "driven"):
            p.add(where, f"'kind' must be 'block' or 'driven', got {kind!r}")
            continue
        direction = p.declared(spec, "bodies.<name>.direction", where)
        port = spec.get("port")
        if kind == "block":
            mass = p.declared(spec, "bodies.<name>.mass", where)
            position = p.declared(spec, "bodies.<name>.position", where)
            floor = _parse_floor(spec.get("floor"), where, p)
            if port is not None and port not in BLOCK_PORTS:
                p.add(where, f"'port' of a block must be one of {BLOCK_PORTS}, got {port!r}")
            bodies[name] = Body(name, kind, direction, mass, position, port, floor)
        else:
            if port not in MOVER_PORTS:
                p.add(where, f"'port' of a driven body must be one of {MOVER_PORTS}, got {port!r}")
            bodies[name] = Body(name, kind, direction, 0.0, 0.0, port, on=spec.get("on", "ground"))
    _check_carriers(bodies, data, p)
    return bodies


def _check_carriers(bodies: dict[str, Body], data: Mapping, p: _Problems) -> None:
    """A driven body may ride on another driven body (a crown on a heaving deck)."""
    for name, body in bodies.items():
        if body.on == "ground":
            continue
        where = f"body {name!r}"
        carrier = bodies.get(body.on) if _known(body.on, bodies) else None
        if carrier is None:
            p.add(where, f"'on' names {body.on!r}, which is not a body")
        elif carrier.kind != "driven":
            p.add(
                where,
                f"'on' must name a driven body (its motion is an input), "
                f"{body.on!r} is a {carrier.kind}",
            )
        seen, current = {name}, body.on
        while _known(current, bodies) and current != "ground":
            if current in seen:
                p.add(where, "bodies ride on each other in a circle")
                break
            seen.add(current)
            current = bodies[current].on
    for name, spec in data.items():
        if isinstance(spec, Mapping) and spec.get("kind") == "block" and "on" in spec:
            p.add(
                f"body {name!r}",
                "a block moves in the inertial frame; it cannot ride on another body",
            )


def _parse_floor(data: Any, where: str, p: _Problems) -> Floor | None:
    if data is None:
        return None
    if not isinstance(data, Mapping):
        p.add(where, "'floor' must be a mapping with position, stiffness, damping")
        return None
    where = f"{where} floor"
    return Floor(
        p.declared(data, "bodies.<name>.floor.position", where),
        p.declared(data, "bodies.<name>.floor.stiffness", where),
        p.declared(data, "bodies.<name>.floor.damping", where),
    )


def _parse_on_bodies(
    data: Mapping, what: str, bodies: dict[str, Body], p: _Problems, build: Callable
) -> dict:
    """Parts named in ``data`` (sheaves, anchors), each on a body; ``build(name, body,
    spec, where)`` makes one from its table."""
    parts: dict = {}
    if not isinstance(data, Mapping):
        p.add(f"{what}s", f"must be a mapping of name -> {what}")
        return parts
    for name, spec in data.items():
        where = f"{what} {name!r}"
        if not isinstance(spec, Mapping):
            p.add(where, "must be a mapping")
            continue
        body = spec.get("body", "ground")
        if not _known(body, bodies):
            p.add(where, f"'body' {body!r} is not a body; bodies: {', '.join(bodies)}")
        parts[name] = build(name, body, spec, where)
    return parts


def _parse_sheaves(data: Mapping, bodies: dict[str, Body], p: _Problems) -> dict[str, SheaveSpec]:
    def sheave(name: str, body: str, spec: Mapping, where: str) -> SheaveSpec:
        """A :class:`SheaveSpec` from its description.

        Parameters
        ----------
        name : str
            Sheave name.
        body : str
            Body it is fixed to.
        spec : mapping
            Its description (centre and radius in m, inertia in kg m^2, bearing torque in N m).
        where : str
            The sheave, for the problems' text.
        """
        return SheaveSpec(
            name,
            body,
            p.declared(spec, "sheaves.<name>.centre", where),
            p.declared(spec, "sheaves.<name>.radius", where),
            p.declared(spec, "sheaves.<name>.axis", where),
            p.declared(spec, "sheaves.<name>.inertia", where),
            p.declared(spec, "sheaves.<name>.bearing_torque", where),
            p.declared(spec, "sheaves.<name>.efficiency", where),
            p.declared(spec, "sheaves.<name>.groove_friction", where),
        )

    return _parse_on_bodies(data, "sheave", bodies, p, sheave)


def _parse_anchors(data: Mapping, bodies: dict[str, Body], p: _Problems) -> dict[str, AnchorSpec]:
    def anchor(name: str, body: str, spec: Mapping, where: str) -> AnchorSpec:
        """An :class:`AnchorSpec` from its description.

        Parameters
        ----------
        name : str
            Anchor name.
        body : str
            Body it is fixed to.
        spec : mapping
            Its description (``point``, m).
        where : str
            The anchor, for the problems' text.
        """
        return AnchorSpec(name, body, p.declared(spec, "anchors.<name>.point", where))

    return _parse_on_bodies(data, "anchor", bodies, p, anchor)


def _check_names(sheaves: Mapping, anchors: Mapping, p: _Problems) -> None:
    """A name given to a sheave and to an anchor: refused, naming both.

    The path says which kind each node is, but drawings, messages and the geometry name
    nodes by their names alone, so a name must point at one node. Bodies are a namespace
    of their own (only ``body`` and ``on`` name them); line ends are named by their port.

    Parameters
    ----------
    sheaves, anchors : mapping
        The parsed sheaves and anchors, by name.
    p : _Problems
        Where problems are recorded.
    """
    for name in anchors:
        if name in sheaves:
            p.add(
                f"sheave {name!r} and anchor {name!r}",
                "the same name for two nodes; every sheave and anchor needs a name of its own",
            )


def _parse_path(data: Any, sheaves, anchors, bodies, p: _Problems) -> tuple[PathElement, ...]:
    if not isinstance(data, list | tuple) or len(data) < 2:
        p.add("path", "must be a list of at least two nodes (two rope ends)")
        return ()
    out = []
    first_pass: dict[str, int] = {}  # sheave -> the path node that passes it first
    last = len(data) - 1
    for i, node in enumerate(data):
        where = f"path node {i}"
        if not isinstance(node, Mapping):
            p.add(where, f"must be a mapping, got {node!r}")
            continue
        if "sheave" in node:
            name = node["sheave"]
            wrap = node.get("wrap")
            if not _known(name, sheaves):
                p.add(where, f"sheave {name!r} is not defined; sheaves: {', '.join(sheaves)}")
            if not _known(wrap, _WRAPS):
                p.add(where, f"sheave {name!r}: 'wrap' must be 'ccw' or 'cw', got {wrap!r}")
            if _known(name, sheaves) and name in first_pass:
                p.add(
                    f"path nodes {first_pass[name]} and {i}",
                    f"sheave {name!r} is passed twice; the rope may pass a sheave once (the "
                    "model gives each pass a groove, rim and bearing of its own); for a sheave "
                    "with several grooves give one sheave per groove, centres offset along "
                    "the axis",
                )
            elif _known(name, sheaves):
                first_pass[name] = i
            out.append(
                PathElement("sheave", str(name), _WRAPS[wrap] if _known(wrap, _WRAPS) else 1)
            )
        elif "anchor" in node:
            name = node["anchor"]
            if not _known(name, anchors):
                p.add(where, f"anchor {name!r} is not defined; anchors: {', '.join(anchors)}")
            if 0 < i < last:
                p.add(where, f"anchor {name!r} must be at an end of the path")
            out.append(PathElement("anchor", str(name)))
        elif "line_end" in node:
            port = node["line_end"]
            body = node.get("body", "ground")
            if port not in LINE_PORTS:
                p.add(where, f"'line_end' must be one of {LINE_PORTS}, got {port!r}")
            if 0 < i < last:
                p.add(where, f"line end {port!r} must be at an end of the path")
            if not _known(body, bodies):
                p.add(where, f"'body' {body!r} is not a body")
            point = p.declared(node, "path[i].point", where)
            out.append(PathElement("line_end", str(port), 0, point, body))
        else:
            p.add(where, "must name a 'sheave', an 'anchor' or a 'line_end'")
    for end in (0, last):
        if end < len(out) and out[end].kind == "sheave":
            p.add(f"path node {end}", "a rope end must be an anchor or a line end, not a sheave")
    return tuple(out)


def _check_ports(bodies: dict[str, Body], path, p: _Problems) -> None:
    used: dict[str, str] = {}
    owners = [(b.port, f"body {b.name!r}") for b in bodies.values() if b.port]
    owners += [(e.name, f"path line end {e.name!r}") for e in path if e.kind == "line_end"]
    for port, owner in owners:
        if not isinstance(port, str):  # a problem of its own already
            continue
        if port in used:
            p.add("ports", f"port {port!r} is used by both {used[port]} and {owner}")
        used[port] = owner
    if not any(e.kind in ("anchor", "line_end") for e in path[:1] + path[-1:]):
        return

"""Scenes: which units, how they connect, what drives them, how to run.

A scene is a TOML file (data only, nothing is executed). :func:`load_scene`
reads it and :func:`parse_scene` turns the data into a :class:`Scene`,
collecting every problem it can see without opening an FMU; the checks that
need the units' model descriptions are in :mod:`wire_fmu.master.validate`.

Format::

    name = "riser_tensioner"
    description = "..."

    [run]
    stop_time = 60.0          # s
    step = 0.01               # s, macro (communication) step
    algorithm = "gauss_seidel"        # or "jacobi"
    extrapolation = "linear"          # "constant", "linear" or "quadratic"
    output_interval = 0.05    # s
    iterations = 1            # > 1: iterate each step with rollback
    iteration_tolerance = 1e-6
    adaptive = false          # macro step from the bonds' energy residual
    energy_tolerance = 10.0   # J per step, with adaptive; the energy guard's floor
    energy_guard = 0.1        # stop once a bond's coupling created this share of
                              # the energy it carried (inf: off); see energy_guard.py
    min_step = 1e-4
    max_step = 0.05
    max_steps = 10000000      # a run of more macro steps is refused (adaptive: stop / min_step)

    [units.rope]
    fmu = "BlockTrain"        # one of ours by name, or a path to any FMI 2.0 CS FMU
    effects = ["rope_damping"]
    [units.rope.parameters]
    pretension = 2.0e5
    reeving = { ... }         # a table is passed to a String parameter as JSON

    [[bonds]]                 # a power bond: effort one way, flow (and position) back
    name = "rod"
    kind = "translational"    # "translational", "rotational" or "rope"
    effort = "rope.mover_a.force -> cylinder.rod.force"
    flow = "cylinder.rod.velocity -> rope.mover_a.velocity"
    position = "cylinder.rod.position -> rope.mover_a.position"

    [[connections]]           # plain signals
    from = "a.x"
    to = "b.y"

    [[drivers]]               # see wire_fmu.master.drivers
    target = "rope.mover_b.position"
    rate_target = "rope.mover_b.velocity"
    kind = "sine"
    amplitude = 1.5
    period = 10.0

    [[events]]
    time = 30.0
    label = "brake applied"
    set = { "winch.brake.lever_force" = 2000.0 }

    [outputs]
    variables = ["rope.line_a.tension"]      # or "all"

    [[plots]]
    title = "Riser tension"
    variables = ["rope.line_b.tension"]

    [study]                   # optional, for wire-fmu study (wire_fmu.study.accuracy)
    key_outputs = ["rope.line_b.tension"]    # default: the plots' variables
    stop_time = 10.0          # s, of every study run
    steps = [0.02, 0.01, 0.005]              # macro steps, s
    output_interval = 0.02    # s, a multiple of every step
"""

from __future__ import annotations

import json
import math
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from wire_fmu.core.errors import ConfigurationError

from .energy_guard import DEFAULT_SHARE
from .files import UnreadableFileError, read_regular

__all__ = [
    "VarRef",
    "UnitSpec",
    "Connection",
    "Bond",
    "DriverSpec",
    "EventSpec",
    "RunSettings",
    "PlotSpec",
    "Scene",
    "SceneError",
    "load_scene",
    "parse_scene",
    "read_scene",
    "read_scene_data",
    "is_plain_name",
    "unknown_unit_problems",
    "valid_time",
    "is_scalar",
    "MAX_SCENE_BYTES",
    "ALGORITHMS",
    "EXTRAPOLATIONS",
    "BOND_KINDS",
]

ALGORITHMS = ("jacobi", "gauss_seidel")
EXTRAPOLATIONS = ("constant", "linear", "quadratic")
MIN_TIME, MAX_TIME = 1e-9, 1e12
"""Shortest step and latest time a run can count (whole nanoseconds in 64 bits), s."""
MAX_SCENE_BYTES = 16 * 2**20
"""The largest scene file read (a scene is a few kilobytes; a reeving table a few more)."""
MAX_ITERATIONS = 1000
"""Most sweeps of one macro step ``run.iterations`` may ask for."""
BOND_KINDS = {
    # kind: (effort unit, flow unit, position unit)
    "translational": ("N", "m/s", "m"),
    "rope": ("N", "m/s", "m"),
    "rotational": ("N.m", "rad/s", "rad"),
    "hydraulic": ("Pa", "m3/s", "m3"),
}


class SceneError(ConfigurationError):
    """A scene with problems; ``problems`` lists every one."""


@dataclass(frozen=True, order=True)
class VarRef:
    """``unit.variable``: the first dotted component names the unit."""

    unit: str
    variable: str

    def __str__(self) -> str:
        return f"{self.unit}.{self.variable}"

    @classmethod
    def parse(cls, text: Any) -> VarRef | None:
        """Parse ``"unit.variable.path"``; None if malformed."""
        if not isinstance(text, str) or "." not in text.strip():
            return None
        unit, _, variable = text.strip().partition(".")
        if not unit or not variable:
            return None
        return cls(unit, variable)


@dataclass(frozen=True)
class UnitSpec:
    """One unit of the scene.

    Attributes
    ----------
    name : str
        Instance name used in connections.
    fmu : str
        Name of one of our FMUs (``"BlockTrain"``) or a path to an FMU.
    effects : tuple of str
        Effects to include (ours only); everything else is the simplest model.
    parameters : dict
        Parameter values; tables become JSON text for String parameters.
    """

    name: str
    fmu: str
    effects: tuple[str, ...] = ()
    parameters: dict[str, Any] = field(default_factory=dict)

    def parameter_values(self) -> dict[str, Any]:
        """Parameters as FMI values (tables and lists serialised to JSON)."""
        out = {}
        for key, value in self.parameters.items():
            out[key] = json.dumps(value) if isinstance(value, Mapping | list) else value
        return out


@dataclass(frozen=True)
class Connection:
    """An output feeding an input.

    ``role`` is ``"effort"``, ``"flow"`` or ``"position"`` inside a bond,
    ``"signal"`` otherwise.
    """

    source: VarRef
    target: VarRef
    role: str = "signal"
    bond: str | None = None
    extrapolation: str | None = None


@dataclass(frozen=True)
class Bond:
    """A power bond between two units (effort one way, flow back)."""

    name: str
    kind: str
    effort: Connection
    flow: Connection
    position: Connection | None = None

    @property
    def connections(self) -> tuple[Connection, ...]:
        """The bond's connections."""
        return tuple(c for c in (self.effort, self.flow, self.position) if c is not None)


@dataclass(frozen=True)
class DriverSpec:
    """A time signal on an input (and optionally its rate on another)."""

    target: VarRef
    spec: dict[str, Any]
    rate_target: VarRef | None = None
    label: str = ""


@dataclass(frozen=True)
class EventSpec:
    """Inputs set to new values at a scheduled time."""

    time: float
    values: dict[VarRef, Any]
    label: str = ""


@dataclass(frozen=True)
class PlotSpec:
    """One figure of the scene's key outputs."""

    title: str
    variables: tuple[VarRef, ...]
    ylabel: str = ""


@dataclass(frozen=True)
class RunSettings:
    """How to run the scene (see the module docstring for the keys)."""

    stop_time: float = 10.0
    step: float = 0.01
    algorithm: str = "gauss_seidel"
    extrapolation: str = "linear"
    output_interval: float | None = None
    iterations: int = 1
    iteration_tolerance: float = 1e-6
    adaptive: bool = False
    energy_tolerance: float = 10.0
    energy_guard: float = DEFAULT_SHARE
    min_step: float = 1e-5
    max_step: float | None = None
    order: tuple[str, ...] = ()
    max_steps: int = 10_000_000


@dataclass(frozen=True)
class Scene:
    """A parsed scene."""

    name: str
    description: str
    units: dict[str, UnitSpec]
    bonds: tuple[Bond, ...]
    connections: tuple[Connection, ...]
    drivers: tuple[DriverSpec, ...]
    events: tuple[EventSpec, ...]
    outputs: tuple[VarRef, ...] | None
    plots: tuple[PlotSpec, ...]
    run: RunSettings
    base_dir: Path
    source: Path | None = None
    study: dict = field(default_factory=dict)

    @property
    def all_connections(self) -> tuple[Connection, ...]:
        """Signal connections and every bond's connections."""
        return self.connections + tuple(c for b in self.bonds for c in b.connections)


_TOP_KEYS = {
    "name",
    "description",
    "run",
    "units",
    "bonds",
    "connections",
    "drivers",
    "events",
    "outputs",
    "plots",
    "study",
}
_RUN_KEYS = set(RunSettings.__dataclass_fields__)


def load_scene(path: Path) -> Scene:
    """Read and parse a scene file.

    Raises
    ------
    SceneError
        Listing every problem found.
    """
    scene, problems = read_scene(path)
    if problems:
        raise SceneError(f"scene {scene.name!r}" if scene else str(path), problems)
    return scene


def parse_scene(data: Mapping[str, Any], *, base_dir: Path, source: Path | None = None) -> Scene:
    """Build a :class:`Scene` from plain data; raise :class:`SceneError` with every problem."""
    scene, problems = read_scene_data(data, base_dir=base_dir, source=source)
    if problems:
        raise SceneError(f"scene {scene.name!r}", problems)
    return scene


def read_scene(path: Path) -> tuple[Scene | None, list[str]]:
    """Read a scene file; return it (None if unreadable) and every problem of its data.

    The scene returned with problems has each invalid item left out or at its
    default, so that the checks that need the units can still run and report
    their problems in the same list (``wire-fmu check``).
    """
    path = Path(path)
    try:
        data = tomllib.loads(read_regular(path, MAX_SCENE_BYTES).decode("utf-8"))
    except UnreadableFileError as err:
        return None, [f"cannot read the scene file: {err}"]
    except UnicodeDecodeError:
        return None, ["cannot read the scene file: it is not UTF-8 text"]
    except tomllib.TOMLDecodeError as err:
        return None, [f"not valid TOML: {err}"]
    except RecursionError:
        return None, ["nested too deeply to be a scene"]
    return read_scene_data(data, base_dir=path.parent, source=path)


def read_scene_data(
    data: Mapping[str, Any], *, base_dir: Path, source: Path | None = None
) -> tuple[Scene, list[str]]:
    """Build a :class:`Scene` from plain data and list every problem (see :func:`read_scene`)."""
    problems: list[str] = []
    if not isinstance(data, Mapping):
        data = {}
        problems.append("a scene must be a table of keys")
    for key in data:
        if key not in _TOP_KEYS:
            problems.append(f"unknown top-level key {key!r}; known: {', '.join(sorted(_TOP_KEYS))}")
    name = _scene_name(data.get("name", source.stem if source else "scene"), problems)
    description = data.get("description", "")
    if not isinstance(description, str):
        problems.append(f"'description' must be text, got {type(description).__name__}")
        description = ""
    units = _parse_units(data.get("units", {}), problems)
    bonds = _parse_bonds(data.get("bonds", []), problems, set(units))
    connections = _parse_connections(data.get("connections", []), problems)
    drivers = _parse_drivers(data.get("drivers", []), problems)
    events = _parse_events(data.get("events", []), problems)
    outputs = _parse_outputs(data.get("outputs", {}), problems)
    plots = _parse_plots(data.get("plots", []), problems)
    run = _parse_run(data.get("run", {}), problems)
    study = data.get("study", {})
    if not isinstance(study, Mapping):
        problems.append("[study] must be a table (see wire_fmu.study.accuracy)")
        study = {}
    scene = Scene(
        name,
        description,
        units,
        bonds,
        connections,
        drivers,
        events,
        outputs,
        plots,
        run,
        Path(base_dir),
        source,
        study=dict(study),
    )
    problems += unknown_unit_problems(scene)
    problems += [
        f"run.order names {name!r}, which is no unit of the scene"
        for name in run.order
        if name not in units
    ]
    return scene, problems


_UNIT_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")
_SAFE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,127}")


def is_plain_name(name: str) -> bool:
    """Whether ``name`` can name a folder inside another: letters, digits, ``_-.``, no ``..``."""
    return bool(_SAFE_NAME.fullmatch(name)) and ".." not in name


def _scene_name(name: Any, problems: list[str]) -> str:
    """The scene's name; it names the results folder, so it must be a plain file name."""
    if isinstance(name, str) and is_plain_name(name):
        return name
    problems.append(
        f"'name' {name!r}: must be a plain file name (letters, digits, '_', '-', "
        "'.', at most 128 characters, no '..'), since it names the results folder"
    )
    return "scene"


def unknown_unit_problems(scene: Scene) -> list[str]:
    """Every reference to a unit the scene does not have, naming where it is."""
    units = set(scene.units)
    known = ", ".join(sorted(units)) or "none"
    refs: list[tuple[str, VarRef]] = []
    for bond in scene.bonds:
        refs += [
            (f"bond {bond.name!r} {c.role}", r)
            for c in bond.connections
            for r in (c.source, c.target)
        ]
    for i, c in enumerate(scene.connections):
        refs += [(f"connection {i}", c.source), (f"connection {i}", c.target)]
    for i, d in enumerate(scene.drivers):
        refs += [(f"driver {i}", r) for r in (d.target, d.rate_target) if r is not None]
    for e in scene.events:
        refs += [(f"event {e.label!r}", r) for r in e.values]
    refs += [("outputs", r) for r in scene.outputs or ()]
    refs += [(f"plot {p.title!r}", r) for p in scene.plots for r in p.variables]
    return [
        f"{where}: {ref} names no unit {ref.unit!r}; the scene's units: {known}"
        for where, ref in refs
        if ref.unit not in units
    ]


def _unknown_keys(spec: Mapping, known: set[str], where: str, problems: list[str]) -> None:
    """A problem naming the keys of ``spec`` that are not ``known`` (typos silently ignored
    would change what runs)."""
    unknown = sorted(str(k) for k in set(spec) - known)
    if unknown:
        problems.append(f"{where}: unknown keys {unknown}; known: {', '.join(sorted(known))}")


def _text(value: Any, where: str, key: str, problems: list[str], default: str) -> str:
    """A name, label or title: text, else a problem and ``default``."""
    if isinstance(value, str):
        return value
    problems.append(f"{where}: {key!r} must be text, got {value!r}")
    return default


def _as_list(value: Any, where: str, problems: list[str]) -> list:
    if isinstance(value, list):
        return value
    problems.append(f"{where} must be a list of tables ([[{where}]])")
    return []


def _parse_units(data: Any, problems: list[str]) -> dict[str, UnitSpec]:
    units: dict[str, UnitSpec] = {}
    if not isinstance(data, Mapping) or not data:
        problems.append("the scene needs a [units] table with at least one unit")
        return units
    for name, spec in data.items():
        where = f"unit {name!r}"
        if not _UNIT_NAME.fullmatch(name):
            problems.append(
                f"{where}: a unit name is a letter or '_', then letters, digits or '_' (it "
                "names the unit's variables, 'unit.variable')"
            )
        if not isinstance(spec, Mapping):
            problems.append(f"{where}: must be a table")
            continue
        unknown = set(spec) - {"fmu", "effects", "parameters"}
        if unknown:
            problems.append(
                f"{where}: unknown keys {sorted(unknown)}; known: fmu, effects, parameters"
            )
        fmu = spec.get("fmu")
        if not isinstance(fmu, str) or not fmu:
            problems.append(f"{where}: 'fmu' must name one of our FMUs or give a path to one")
            fmu = ""
        effects = spec.get("effects", [])
        if isinstance(effects, str):
            effects = [e.strip() for e in effects.replace(",", " ").split() if e.strip()]
        if not isinstance(effects, list) or not all(isinstance(e, str) for e in effects):
            problems.append(f"{where}: 'effects' must be a list of effect names")
            effects = []
        params = spec.get("parameters", {})
        if not isinstance(params, Mapping):
            problems.append(f"{where}: 'parameters' must be a table")
            params = {}
        units[name] = UnitSpec(name, fmu, tuple(effects), dict(params))
    return units


def _parse_link(text: Any, where: str, problems: list[str]) -> tuple[VarRef, VarRef] | None:
    if not isinstance(text, str) or "->" not in text:
        problems.append(f"{where}: must read 'unit.output -> unit.input', got {text!r}")
        return None
    left, _, right = text.partition("->")
    source, target = VarRef.parse(left), VarRef.parse(right)
    if source is None or target is None:
        problems.append(f"{where}: both sides must be 'unit.variable', got {text!r}")
        return None
    return source, target


def _parse_bonds(data: Any, problems: list[str], units: set[str]) -> tuple[Bond, ...]:
    bonds = []
    names: set[str] = set()
    for i, spec in enumerate(_as_list(data, "bonds", problems)):
        if not isinstance(spec, Mapping):
            problems.append(f"bond {i}: must be a table")
            continue
        name = _text(spec.get("name", f"bond{i}"), f"bond {i}", "name", problems, f"bond{i}")
        where = f"bond {name!r}"
        if name in names:
            problems.append(f"{where}: defined twice")
        names.add(name)
        kind = spec.get("kind")
        if kind not in BOND_KINDS:
            problems.append(f"{where}: 'kind' must be one of {sorted(BOND_KINDS)}, got {kind!r}")
        extrapolation = spec.get("extrapolation")
        if extrapolation is not None and extrapolation not in EXTRAPOLATIONS:
            problems.append(f"{where}: 'extrapolation' must be one of {EXTRAPOLATIONS}")
        links = {}
        for role in ("effort", "flow", "position"):
            if role not in spec:
                if role != "position":
                    problems.append(f"{where}: '{role}' is required")
                continue
            link = _parse_link(spec[role], f"{where} {role}", problems)
            if link:
                links[role] = Connection(*link, role=role, bond=name, extrapolation=extrapolation)
        unknown = set(spec) - {"name", "kind", "effort", "flow", "position", "extrapolation"}
        if unknown:
            problems.append(f"{where}: unknown keys {sorted(unknown)}")
        if "effort" in links and "flow" in links:
            e, f = links["effort"], links["flow"]
            named = {e.source.unit, e.target.unit, f.source.unit, f.target.unit}
            crossed = e.source.unit != f.target.unit or e.target.unit != f.source.unit
            if named <= units and crossed:
                problems.append(
                    f"{where}: the effort must go from the unit the flow goes to "
                    f"(effort {e.source.unit} -> {e.target.unit}, flow "
                    f"{f.source.unit} -> {f.target.unit})"
                )
            bonds.append(Bond(name, str(kind), e, f, links.get("position")))
    return tuple(bonds)


def _parse_connections(data: Any, problems: list[str]) -> tuple[Connection, ...]:
    out = []
    for i, spec in enumerate(_as_list(data, "connections", problems)):
        where = f"connection {i}"
        if not isinstance(spec, Mapping):
            problems.append(f"{where}: must be a table with 'from' and 'to'")
            continue
        _unknown_keys(spec, {"from", "to", "extrapolation"}, where, problems)
        source, target = VarRef.parse(spec.get("from")), VarRef.parse(spec.get("to"))
        if source is None or target is None:
            problems.append(f"{where}: 'from' and 'to' must be 'unit.variable'")
            continue
        extrapolation = spec.get("extrapolation")
        if extrapolation is not None and extrapolation not in EXTRAPOLATIONS:
            problems.append(f"{where}: 'extrapolation' must be one of {EXTRAPOLATIONS}")
        out.append(Connection(source, target, extrapolation=extrapolation))
    return tuple(out)


def _parse_drivers(data: Any, problems: list[str]) -> tuple[DriverSpec, ...]:
    out = []
    for i, spec in enumerate(_as_list(data, "drivers", problems)):
        if not isinstance(spec, Mapping):
            problems.append(f"driver {i}: must be a table")
            continue
        target = VarRef.parse(spec.get("target"))
        if target is None:
            problems.append(f"driver {i}: 'target' must be 'unit.input'")
            continue
        rate = spec.get("rate_target")
        rate_ref = VarRef.parse(rate) if rate is not None else None
        if rate is not None and rate_ref is None:
            problems.append(f"driver {i}: 'rate_target' must be 'unit.input'")
        body = {k: v for k, v in spec.items() if k not in ("target", "rate_target", "label")}
        label = _text(spec.get("label", ""), f"driver {i}", "label", problems, "")
        out.append(DriverSpec(target, body, rate_ref, label))
    return tuple(out)


def _parse_events(data: Any, problems: list[str]) -> tuple[EventSpec, ...]:
    out = []
    for i, spec in enumerate(_as_list(data, "events", problems)):
        where = f"event {i}"
        if not isinstance(spec, Mapping):
            problems.append(f"{where}: must be a table")
            continue
        _unknown_keys(spec, {"time", "set", "label"}, where, problems)
        time = spec.get("time")
        if not _finite(time) or not 0 <= time <= MAX_TIME:
            problems.append(
                f"{where}: 'time' must be a number of seconds from 0 to {MAX_TIME:g}, got {time!r}"
            )
            continue
        values = {}
        raw = spec.get("set", {})
        if not isinstance(raw, Mapping) or not raw:
            problems.append(f"{where}: 'set' must be a table of 'unit.input' = value")
            continue
        for key, value in raw.items():
            ref = VarRef.parse(key)
            if ref is None:
                problems.append(f"{where}: {key!r} is not 'unit.input'")
            elif not is_scalar(value):
                problems.append(
                    f"{where}: {key} = {value!r}: must be a finite number, true/false or text"
                )
            else:
                values[ref] = value
        label = _text(spec.get("label", f"event {i}"), where, "label", problems, f"event {i}")
        out.append(EventSpec(float(time), values, label))
    return tuple(sorted(out, key=lambda e: e.time))


def _parse_outputs(data: Any, problems: list[str]) -> tuple[VarRef, ...] | None:
    if not isinstance(data, Mapping):
        problems.append("[outputs] must be a table with 'variables'")
        return None
    _unknown_keys(data, {"variables"}, "[outputs]", problems)
    variables = data.get("variables", "all")
    if variables == "all":
        return None
    if not isinstance(variables, list):
        problems.append("outputs.variables must be \"all\" or a list of 'unit.variable'")
        return None
    refs = []
    for text in variables:
        ref = VarRef.parse(text)
        if ref is None:
            problems.append(f"outputs: {text!r} is not 'unit.variable'")
        else:
            refs.append(ref)
    return tuple(refs)


def _parse_plots(data: Any, problems: list[str]) -> tuple[PlotSpec, ...]:
    out = []
    for i, spec in enumerate(_as_list(data, "plots", problems)):
        if not isinstance(spec, Mapping) or not isinstance(spec.get("variables"), list):
            problems.append(f"plot {i}: needs 'title' and a list 'variables'")
            continue
        _unknown_keys(spec, {"title", "variables", "ylabel"}, f"plot {i}", problems)
        refs = [VarRef.parse(v) for v in spec["variables"]]
        if not refs or any(r is None for r in refs):
            problems.append(f"plot {i}: 'variables' must list at least one 'unit.variable'")
            continue
        title = _text(spec.get("title", f"plot {i}"), f"plot {i}", "title", problems, "plot")
        if not title.strip() or len(title) > 100:
            problems.append(f"plot {i}: 'title' must be 1 to 100 characters (it names the PNG)")
        ylabel = _text(spec.get("ylabel", ""), f"plot {i}", "ylabel", problems, "")
        out.append(PlotSpec(title, tuple(refs), ylabel))
    return tuple(out)


def _parse_run(data: Any, problems: list[str]) -> RunSettings:
    if not isinstance(data, Mapping):
        problems.append("[run] must be a table")
        return RunSettings()
    unknown = set(data) - _RUN_KEYS
    if unknown:
        problems.append(f"run: unknown keys {sorted(unknown)}; known: {sorted(_RUN_KEYS)}")
    given = {k: v for k, v in data.items() if k in _RUN_KEYS}
    if "order" in given:
        order = given["order"]
        given["order"] = tuple(order) if isinstance(order, list) else order
    settings = RunSettings(**given)
    mine: list[str] = []
    _check_run(settings, mine)
    problems += mine
    if mine:  # go on with the defaults of the settings that are wrong
        defaults = RunSettings()
        valid = {}
        for key, value in given.items():
            trial: list[str] = []
            _check_run(replace(defaults, **{key: value}), trial)
            if not trial:
                valid[key] = value
        settings = replace(defaults, **valid)
    return settings


def valid_time(value: Any) -> bool:
    """A time a run can count: a number of seconds from 0 to :data:`MAX_TIME`, not a boolean."""
    return _finite(value) and 0 <= value <= MAX_TIME


def is_scalar(value: Any) -> bool:
    """A finite number, a boolean or text: what one FMI variable can hold."""
    return isinstance(value, bool | str) or _finite(value)


def _finite(value: Any) -> bool:
    """A finite number (not a boolean); an integer too large for a float is not."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _positive(value: Any) -> bool:
    return _finite(value) and value > 0


def _check_run(s: RunSettings, problems: list[str]) -> None:
    for key in ("stop_time", "step", "iteration_tolerance", "energy_tolerance", "min_step"):
        if not _positive(getattr(s, key)):
            problems.append(f"run.{key} must be a positive number, got {getattr(s, key)!r}")
    if not (_positive(s.energy_guard) or s.energy_guard == math.inf):
        problems.append(
            f"run.energy_guard must be a positive number (inf turns the guard "
            f"off), got {s.energy_guard!r}"
        )
    for key in ("output_interval", "max_step"):
        value = getattr(s, key)
        if value is not None and not _positive(value):
            problems.append(f"run.{key} must be a positive number, got {value!r}")
    if s.algorithm not in ALGORITHMS:
        problems.append(f"run.algorithm must be one of {ALGORITHMS}, got {s.algorithm!r}")
    if s.extrapolation not in EXTRAPOLATIONS:
        problems.append(
            f"run.extrapolation must be one of {EXTRAPOLATIONS}, got {s.extrapolation!r}"
        )
    if not isinstance(s.iterations, int) or isinstance(s.iterations, bool) or s.iterations < 1:
        problems.append(f"run.iterations must be an integer >= 1, got {s.iterations!r}")
    elif s.iterations > MAX_ITERATIONS:
        problems.append(
            f"run.iterations = {s.iterations}: at most {MAX_ITERATIONS} sweeps of "
            "one step (a coupling that needs more does not converge)"
        )
    if not isinstance(s.adaptive, bool):
        problems.append(f"run.adaptive must be true or false, got {s.adaptive!r}")
    if not isinstance(s.order, tuple) or not all(isinstance(u, str) for u in s.order):
        problems.append(f"run.order must be a list of unit names, got {s.order!r}")
    elif len(set(s.order)) != len(s.order):
        problems.append(f"run.order names a unit more than once: {list(s.order)}")
    for key in ("stop_time", "step", "min_step", "max_step", "output_interval"):
        value = getattr(s, key)
        if _positive(value) and not MIN_TIME <= value <= MAX_TIME:
            problems.append(
                f"run.{key} = {value!r} s: times are counted in whole nanoseconds, from "
                f"{MIN_TIME:g} to {MAX_TIME:g} s"
            )
    if not isinstance(s.max_steps, int) or isinstance(s.max_steps, bool) or s.max_steps < 1:
        problems.append(f"run.max_steps must be an integer >= 1, got {s.max_steps!r}")
    elif _positive(s.stop_time) and _positive(s.step):
        _check_step_count(s, problems)
    if _positive(s.min_step) and s.max_step is not None and _positive(s.max_step):
        if s.min_step > s.max_step:
            problems.append(
                f"run.min_step {s.min_step!r} s is larger than run.max_step {s.max_step!r} s"
            )


def _check_step_count(s: RunSettings, problems: list[str]) -> None:
    """Refuse a run whose number of macro steps is absurd, saying how to allow it."""
    smallest = s.min_step if s.adaptive and _positive(s.min_step) else s.step
    count = s.stop_time / smallest
    if count > s.max_steps:
        what = "run.stop_time / run.min_step" if s.adaptive else "run.stop_time / run.step"
        problems.append(
            f"{what} = {s.stop_time:g} s / {smallest:g} s is up to {count:.3g} macro steps, more "
            f"than run.max_steps = {s.max_steps}; raise max_steps to allow it, or take a "
            "larger step"
        )

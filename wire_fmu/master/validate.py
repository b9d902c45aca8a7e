"""Check a scene against its units' model descriptions, before anything runs.

Every problem is collected, each naming the unit and variable, in the manner
of libcosim's ``system_structure`` and Drake's ``DiagramBuilder``: unknown
units, variables and effects; inputs fed twice; outputs fed into outputs;
unit and type mismatches; a bond whose effort and flow do not make a power;
a wired interface model whose quantities are not in their units, or whose
effort unit's switch parameter is off (its links would carry zeros);
algebraic loops through direct feedthrough; drivers, events, recorded and
plotted variables that do not exist. :func:`check_through_fmi` then
instantiates each unit with its parameters and enters initialisation mode,
so a unit's own configuration problems (a malformed reeving, an unknown
effect) are reported too — through FMI only.
"""

from __future__ import annotations

import json
import logging
from collections import defaultdict
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from fmpy import read_model_description

from wire_fmu.export.model_description import INTERFACE_QUANTITIES, INTERFACE_UNITS

from .catalog import DEFAULT_FMU_DIR, is_ours, resolve_fmu
from .ports import read_ports
from .run_record import declared_start
from .scene import (
    BOND_KINDS,
    INTERFACE_ROLE,
    Bond,
    Connection,
    Scene,
    SceneError,
    VarRef,
    unknown_unit_problems,
)
from .scene.data import RAMP_ROLE
from .slave import value_problem

__all__ = [
    "Structure",
    "resolve_units",
    "check_structure",
    "check_through_fmi",
    "validate_scene",
    "feedthrough_loops",
]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Structure:
    """Model descriptions of a scene's units, by unit name."""

    paths: dict[str, Path]
    descriptions: dict[str, object]

    def variable(self, ref: VarRef):
        """The model variable ``ref`` names, or None.

        Parameters
        ----------
        ref : VarRef
            ``unit.variable``.
        """
        md = self.descriptions.get(ref.unit)
        if md is None:
            return None
        for var in md.modelVariables:
            if var.name == ref.variable:
                return var
        return None

    def dependencies(self, unit: str) -> dict[str, list[str]]:
        """Each output's direct-feedthrough inputs (all inputs when undeclared).

        Parameters
        ----------
        unit : str
            Instance name of the unit in the scene.

        Returns
        -------
        dict of str to list of str
            The inputs each output depends on directly, by output name.
        """
        md = self.descriptions[unit]
        inputs = [v.name for v in md.modelVariables if v.causality == "input"]
        out = {}
        for unknown in md.outputs:
            deps = unknown.dependencies
            out[unknown.variable.name] = inputs if deps is None else [d.name for d in deps]
        return out


def resolve_units(scene: Scene, fmu_dir: Path = DEFAULT_FMU_DIR) -> tuple[Structure, list[str]]:
    """Find (and build) every unit's FMU and read its model description.

    Parameters
    ----------
    scene : Scene
        The scene.
    fmu_dir : Path
        Where our FMUs are built and cached.

    Returns
    -------
    structure : Structure
        The units found, by name (those with a problem left out).
    problems : list of str
        Each unit whose FMU cannot be found, built or read, and why.
    """
    problems, paths, descriptions = [], {}, {}
    for name, spec in scene.units.items():
        path, problem = resolve_fmu(spec.fmu, scene.base_dir, fmu_dir)
        if problem:
            problems.append(f"unit {name!r}: {problem}")
            continue
        try:
            md = read_model_description(str(path))
        except Exception as exc:  # noqa: BLE001 - any unreadable FMU is a scene problem
            problems.append(f"unit {name!r}: cannot read {path}: {exc}")
            continue
        if md.coSimulation is None or md.fmiVersion != "2.0":
            problems.append(f"unit {name!r}: {path.name} is not an FMI 2.0 co-simulation FMU")
            continue
        paths[name], descriptions[name] = path, md
    return Structure(paths, descriptions), problems


def _variable_problem(structure: Structure, ref: VarRef, causality: str, what: str) -> str | None:
    """What is wrong with ``ref`` as a ``causality`` variable; "" when its unit is unknown or
    unresolved (said once already, where the scene is read or its FMU resolved)."""
    if ref.unit not in structure.descriptions:
        return ""
    var = structure.variable(ref)
    if var is None:
        md = structure.descriptions[ref.unit]
        names = [v.name for v in md.modelVariables if v.causality == causality]
        return (
            f"{what} {ref}: unit {ref.unit!r} has no variable {ref.variable!r}; its "
            f"{causality}s: {', '.join(names)}"
        )
    if var.causality != causality:
        output_fed = causality == "input" and var.causality == "output"
        hint = " (an output cannot feed an output)" if output_fed else ""
        article = "an" if var.causality[:1] in ("a", "e", "i", "o", "u") else "a"
        return f"{what} {ref}: is {article} {var.causality}, expected an {causality}{hint}"
    return None


def _target_unit(connection: Connection, source_unit: str | None) -> str:
    """The unit the target of ``connection`` must have: the source's, or for a ramp link
    (the source's rate of change) the source's per second (``m/s`` to ``m/s2``)."""
    unit = source_unit or ""
    if connection.role != RAMP_ROLE:
        return unit
    return f"{unit}2" if unit.endswith("/s") else f"{unit}/s"


def _connection_problems(scene: Scene, structure: Structure) -> list[str]:
    problems, fed = [], defaultdict(list)
    for c in scene.all_connections:
        what = f"bond {c.bond!r} {c.role}" if c.bond else "connection"
        p_src = _variable_problem(structure, c.source, "output", f"{what} from")
        p_dst = _variable_problem(structure, c.target, "input", f"{what} to")
        problems += [p for p in (p_src, p_dst) if p]
        fed[c.target].append(f"{what} from {c.source}")
        if p_src is not None or p_dst is not None:
            continue
        src, dst = structure.variable(c.source), structure.variable(c.target)
        if src.type != "Real" or dst.type != "Real":
            problems.append(
                f"{what} {c.source} -> {c.target}: connects a {src.type} to a "
                f"{dst.type}; the master connects Real variables only"
            )
        elif src.type != dst.type:
            problems.append(f"{what} {c.source} -> {c.target}: type {src.type} feeds {dst.type}")
        elif src.type == "Real" and _target_unit(c, src.unit) != (dst.unit or ""):
            problems.append(
                f"{what} {c.source} -> {c.target}: unit mismatch, "
                f"{src.unit or 'no unit'} feeds {dst.unit or 'no unit'}"
                + (f" (a ramp takes {_target_unit(c, src.unit)})" if c.role == RAMP_ROLE else "")
            )
    for d in scene.drivers:
        for ref in (d.target, d.rate_target):
            if ref is not None:
                fed[ref].append("a driver")
    for e in scene.events:
        for ref in e.values:
            if fed.get(ref):  # an event would cut a connection or a driver from then on
                problems.append(
                    f"event {e.label!r} sets {ref}, which is fed by "
                    f"{' and by '.join(fed[ref])}; an event may set only inputs "
                    "nothing else feeds"
                )
    for target, sources in fed.items():
        if len(sources) > 1:
            problems.append(f"input {target} is fed twice: by {' and by '.join(sources)}")
    return problems


def _interface_unit(kind: str, variable: str) -> str | None:
    """The unit an interface model's quantity ``{port}.{quantity}`` has in a ``kind`` bond."""
    quantity = variable.rpartition(".")[2]
    if kind not in INTERFACE_UNITS or quantity not in INTERFACE_QUANTITIES:
        return None
    return INTERFACE_UNITS[kind][INTERFACE_QUANTITIES.index(quantity)]


def _interface_unit_problems(bond: Bond, structure: Structure) -> list[str]:
    """An interface link whose source is not in its quantity's unit for the bond's kind."""
    problems = []
    for c in bond.connections:
        var = structure.variable(c.source) if c.role == INTERFACE_ROLE else None
        expected = var is not None and _interface_unit(bond.kind, c.source.variable)
        if expected and var.type == "Real" and (var.unit or "") != expected:
            problems.append(
                f"bond {bond.name!r} ({bond.kind}): interface link {c.source} -> {c.target}: "
                f"{c.source} has unit {var.unit or 'none'}, expected {expected} (the "
                f"interface model of a {bond.kind} bond)"
            )
    return problems


def _declared_switch(bond: Bond, structure: Structure) -> str | None:
    """The effort unit's declared switch of the port whose interface outputs the bond links."""
    unit = bond.effort.source.unit
    try:
        ports = read_ports(structure.paths[unit]) if unit in structure.paths else {}
    except ValueError:
        return None  # said where the scene's ports are read, if the scene bonds by port
    sources = {c.source.variable for c in bond.interface}
    for port in ports.values():
        offered = {f"{port.name}.{q}" for q in INTERFACE_QUANTITIES}
        if port.interface and port.interface_switch and sources & offered:
            return port.interface_switch
    return None


def _switch_problem(scene: Scene, bond: Bond, structure: Structure) -> str | None:
    """Why a wired interface model's links would carry zeros: its switch is off."""
    unit = bond.effort.source.unit
    spec = scene.units.get(unit)
    if spec is None or unit not in structure.descriptions:
        return None
    switch = bond.interface_switch.variable if bond.interface_switch else None
    switch = switch or _declared_switch(bond, structure)
    var = structure.variable(VarRef(unit, switch)) if switch else None
    if var is None or switch in spec.switched_on:
        return None
    given = switch in spec.parameters
    value = spec.parameters[switch] if given else declared_start(var)
    if value is True:
        return None
    asked = "run.interface_models" if bond.interface_model is None else "its interface_model = true"
    shown = str(value).lower() if isinstance(value, bool) else repr(value)
    said = f"sets {switch} = {shown}" if given else f"leaves {switch} at {shown}"
    fix = (
        f"leave {switch} out (the master sets it) or set interface_model = false on the bond"
        if given
        else f"set {switch} = true on unit {unit!r} or interface_model = false on the bond"
    )
    return (
        f"bond {bond.name!r}: its interface model is wired ({asked}), but unit {unit!r} "
        f"{said}, so {bond.interface[0].source} and the model's other outputs would carry "
        f"zeros; expected {switch} = true: {fix}"
    )


def _bond_problems(scene: Scene, structure: Structure) -> list[str]:
    problems = []
    for bond in scene.bonds:
        units = dict(
            zip(("effort", "flow", "position"), BOND_KINDS.get(bond.kind, ()), strict=False)
        )
        if bond.wired:
            problems += _interface_unit_problems(bond, structure)
            switch = _switch_problem(scene, bond, structure)
            problems += [switch] if switch else []
        for c in bond.connections:
            var = structure.variable(c.source)
            if var is None or var.type != "Real":
                continue
            expected = units.get(c.role)
            if expected and (var.unit or "") != expected:
                noun = {"effort": "an effort", "flow": "a flow", "position": "a position"}[c.role]
                problems.append(
                    f"bond {bond.name!r} ({bond.kind}): {c.source} has unit "
                    f"{var.unit or 'none'} but {noun} of a {bond.kind} bond is in {expected} "
                    f"(a force must pair with its velocity, a torque with its angular velocity)"
                )
    return problems


def feedthrough_loops(scene: Scene, structure: Structure) -> list[list[str]]:
    """Cycles of the signal graph through direct feedthrough (algebraic loops).

    Parameters
    ----------
    scene : Scene
        The scene (its connections).
    structure : Structure
        Its units' model descriptions (their outputs' dependencies).

    Returns
    -------
    list of list of str
        Each loop as the ``"unit.variable"`` names along it.
    """
    graph: dict[str, list[str]] = defaultdict(list)
    for c in scene.all_connections:
        graph[str(c.source)].append(str(c.target))
    for unit in structure.descriptions:
        for output, inputs in structure.dependencies(unit).items():
            for name in inputs:
                graph[f"{unit}.{name}"].append(f"{unit}.{output}")
    loops: list[list[str]] = []
    colour: dict[str, int] = {}  # 1: on the path now, 2: done
    for root in list(graph):
        if root in colour:
            continue
        # depth first without recursion: a chain of thousands of connections is fine
        path, pending = [root], [iter(graph.get(root, ()))]
        colour[root] = 1
        while pending:
            nxt = next(pending[-1], None)
            if nxt is None:
                colour[path.pop()] = 2
                pending.pop()
            elif colour.get(nxt) == 1:
                loops.append(path[path.index(nxt) :] + [nxt])
            elif nxt not in colour:
                colour[nxt] = 1
                path.append(nxt)
                pending.append(iter(graph.get(nxt, ())))
    return loops


def _other_problems(scene: Scene, structure: Structure) -> list[str]:
    problems = []
    for d in scene.drivers:
        for ref in (d.target, d.rate_target):
            if ref is not None:
                p = _variable_problem(structure, ref, "input", "driver target")
                problems += [p] if p else []
    for e in scene.events:  # one after the stop time is a warning (late_event_warnings)
        for ref in e.values:
            p = _variable_problem(structure, ref, "input", f"event {e.label!r} sets")
            problems += [p] if p else []
    for ref in list(scene.outputs or ()) + [r for p in scene.plots for r in p.variables]:
        if ref.unit in structure.descriptions and structure.variable(ref) is None:
            problems.append(f"recorded/plotted variable {ref} does not exist")
    for e in scene.events:
        for ref, value in e.values.items():
            var = structure.variable(ref)
            problem = var is not None and value_problem(var, value)
            if problem:
                problems.append(f"event {e.label!r} sets {ref} = {value!r}: {problem}")
    for d in scene.drivers:
        for ref in (d.target, d.rate_target):
            var = structure.variable(ref) if ref is not None else None
            if var is not None and var.type != "Real":
                problems.append(f"driver target {ref}: is a {var.type}; a driver feeds a Real")
    for name, spec in scene.units.items():
        md = structure.descriptions.get(name)
        if md is None:
            continue
        problems += _parameter_problems(name, spec, structure)
        params = {v.name for v in md.modelVariables if v.causality in ("parameter", "input")}
        if spec.effects and not is_ours(spec.fmu) and "effects" not in params:
            problems.append(f"unit {name!r}: effects are only known for our FMUs")
    needs_state = scene.run.iterations > 1 or scene.run.adaptive
    if needs_state:
        for name, md in structure.descriptions.items():
            if not md.coSimulation.canGetAndSetFMUstate:
                problems.append(
                    f"unit {name!r} cannot save its state, which iteration and "
                    "adaptive steps need (rollback)"
                )
    return problems


def _parameter_problems(name: str, spec, structure: Structure) -> list[str]:
    """Parameters a unit does not have, or values of the wrong type for it."""
    return list(_refused_parameters(name, spec, structure).values())


def _refused_parameters(name: str, spec, structure: Structure) -> dict[str, str]:
    """Each parameter (or start input) the scene gives unit ``name`` that its FMU cannot
    take, by name, with the problem that says why."""
    md = structure.descriptions[name]
    params = {v.name: v for v in md.modelVariables if v.causality in ("parameter", "input")}
    refused = {}
    for key, value in spec.parameters.items():
        if key not in params:
            refused[key] = f"unit {name!r}: no parameter {key!r}"
            continue
        problem = _start_value_problem(params[key], value)
        if problem:
            refused[key] = f"unit {name!r}: parameter {key!r} = {_short(value)}: {problem}"
    return refused


def _start_value_problem(variable, value) -> str | None:
    """:func:`value_problem` of a value as the scene gives it: a table or a list is passed
    to a String parameter as JSON, and is no number, whole number or boolean."""
    if variable.type != "String" or not isinstance(value, Mapping | list):
        return value_problem(variable, value)
    try:
        json.dumps(value)
    except (TypeError, ValueError) as err:  # a TOML date or time: JSON has none
        return f"a table or list is passed as JSON text, which has no dates or times ({err})"
    return None


def _short(value) -> str:
    text = str(value).lower() if isinstance(value, bool) else repr(value)  # as TOML writes it
    return text if len(text) <= 60 else text[:57] + "..."


def check_structure(scene: Scene, structure: Structure) -> list[str]:
    """Every structural problem of ``scene`` (empty when sound).

    Parameters
    ----------
    scene : Scene
        The scene.
    structure : Structure
        Its units' model descriptions.
    """
    problems = unknown_unit_problems(scene)  # also for scenes not read from a file (sweeps)
    problems += _connection_problems(scene, structure) + _bond_problems(scene, structure)
    for loop in feedthrough_loops(scene, structure):
        problems.append("algebraic loop through direct feedthrough: " + " -> ".join(loop))
    problems += _other_problems(scene, structure)
    from .drivers import make_driver

    for i, d in enumerate(scene.drivers):
        _, more = make_driver(d.spec, where=f"driver {i} ({d.target})", base_dir=scene.base_dir)
        problems += more
    return problems


def check_through_fmi(scene: Scene, structure: Structure) -> list[str]:
    """Instantiate each unit with its parameters and enter initialisation mode.

    A parameter the unit does not have, or a value it cannot take (said by
    :func:`check_structure`), is left out, so that the unit's own problems with the rest
    come out in the same list; what the unit says then notes what was left out.

    Parameters
    ----------
    scene : Scene
        The scene.
    structure : Structure
        Its units' FMU files.

    Returns
    -------
    list of str
        What each unit that failed said, naming the unit.
    """
    from .slave import Slave, UnitFailedError

    problems = []
    for name, spec in scene.units.items():
        if name not in structure.paths:
            continue
        # parameters it has not, or values it cannot take, are said already: the unit checks
        # the rest, so that its own problems come out with them
        refused = _refused_parameters(name, spec, structure)
        slave = Slave(name, structure.paths[name])
        try:
            slave.instantiate()
            slave.initialize(0.0, unit_start_values(spec, slave, leave_out=refused))
        except UnitFailedError as exc:
            problems += [m + _left_out(refused) for m in unit_messages(name, slave, exc)]
        finally:
            slave.terminate()
    return problems


def _left_out(refused: Mapping[str, str]) -> str:
    """The note on what a unit said when parameters it cannot take were left out."""
    if not refused:
        return ""
    names = ", ".join(repr(k) for k in refused)
    them = "it" if len(refused) == 1 else "them"
    return f" (found with {names} left out: the unit cannot take {them} as given)"


def unit_messages(name: str, slave, exc: Exception) -> list[str]:
    """What a unit said when it failed, each message once, naming the unit.

    Parameters
    ----------
    name : str
        Instance name of the unit in the scene.
    slave : Slave
        The unit (its logged messages).
    exc : Exception
        The error it failed with (its text, when the unit said nothing).
    """
    said = list(dict.fromkeys(slave.messages.kept)) or [str(exc)]
    return [m if m.startswith(f"unit {name!r}") else f"unit {name!r}: {m}" for m in said]


def dry_initialization(scene: Scene, structure: Structure) -> list[str]:
    """Initialise every unit exactly as a run does (connected start values, drivers, events at
    the start time), then free them: what a run would refuse before its first step.

    Parameters
    ----------
    scene : Scene
        The scene, without structural problems.
    structure : Structure
        Its units' FMU files and model descriptions.

    Returns
    -------
    list of str
        What the unit that failed said; empty if all initialised.
    """
    from .simulation import Simulation
    from .slave import StepRefusedError, UnitFailedError

    sim = Simulation(scene, structure, ())
    try:
        sim.initialize()
    except (UnitFailedError, StepRefusedError) as exc:
        name = getattr(exc, "unit", None)
        slave = sim.slaves.get(name)
        return unit_messages(name, slave, exc) if slave else [str(exc)]
    finally:
        for slave in sim.slaves.values():
            slave.terminate()
    return []


def unit_start_values(spec, slave, *, leave_out: Collection[str] = ()) -> dict:
    """Parameters (and the effects list of ours) as FMI values for ``slave``.

    Parameters
    ----------
    spec : UnitSpec
        The unit in the scene.
    slave : Slave
        The unit's FMU (whether it has an ``effects`` parameter).
    leave_out : collection of str
        Parameters not to give (those it cannot take).

    Returns
    -------
    dict of str to object
        Start value by variable name.
    """
    values = spec.parameter_values(leave_out)
    if spec.effects or is_ours(spec.fmu):
        if "effects" in slave.variables:
            values["effects"] = ",".join(spec.effects)
    return values


def validate_scene(
    scene: Scene,
    fmu_dir: Path = DEFAULT_FMU_DIR,
    *,
    through_fmi: bool = True,
    dry_run: bool = False,
    problems: Sequence[str] = (),
) -> Structure:
    """All checks; raise :class:`SceneError` listing every problem, each once.

    Parameters
    ----------
    scene : Scene
        The scene (as :func:`~wire_fmu.master.scene.read_scene` returns it, possibly with
        invalid items left out).
    fmu_dir : Path
        Where our FMUs are built and cached.
    through_fmi : bool
        Instantiate each unit with its parameters (its own checks of them).
    dry_run : bool
        Then, if nothing else is wrong, initialise all units as a run does
        (:func:`dry_initialization`); ``wire-fmu check`` does.
    problems : sequence of str
        Problems already found in the scene's data, reported with the rest.

    Returns
    -------
    Structure
        The units' FMU files and model descriptions.
    """
    found = list(problems)
    structure, unresolved = resolve_units(scene, fmu_dir)
    found += unresolved
    found += check_structure(scene, structure)
    if through_fmi:
        found += check_through_fmi(scene, structure)
    if dry_run and not found:
        found += dry_initialization(scene, structure)
    found = list(dict.fromkeys(found))
    if found:
        raise SceneError(f"scene {scene.name!r}", found)
    return structure

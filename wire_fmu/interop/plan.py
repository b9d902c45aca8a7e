"""What an export writes: a scene resolved against its units' model descriptions.

:func:`plan_export` validates a scene (structure only, through the same
checks as ``wire-fmu check``), resolves every unit's FMU (building ours),
types every start value by the FMU's own declaration, and turns the scene's
drivers and scheduled events into a generated *signals* unit
(:mod:`wire_fmu.interop.signals`) with plain connections, because SSP and
OSP know no time signals. The SSP and OSP writers only serialise an
:class:`ExportPlan`.

What another tool cannot be told (and is therefore logged as a warning):
the coupling algorithm (libcosim's fixed-step algorithm is Jacobi with
inputs held constant, see ``docs/interop.md``), extrapolation, iteration,
adaptive steps, ramped flows (a ramp link's value is the master's work: it is
not exported, the run settings keep the choice for our master to read back),
and event times off the fixed step grid. A bond's wired
interface model needs no warning: its links are ordinary connections
(:attr:`ExportPlan.all_connections`), held over the step as another tool
holds every input, and the effort unit's switch is among its start values.
"""

from __future__ import annotations

import json
import logging
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType, SimpleNamespace
from typing import Any

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.master.catalog import DEFAULT_FMU_DIR
from wire_fmu.master.run import with_run_settings
from wire_fmu.master.scene import Bond, Connection, Scene, VarRef
from wire_fmu.master.validate import Structure, unit_start_values, validate_scene

__all__ = [
    "FIXED_STEP_HOST_RUN",
    "as_fixed_step_host_runs_it",
    "ExportError",
    "TypedValue",
    "PlannedUnit",
    "ExportPlan",
    "plan_export",
    "portable_driver_spec",
    "archive_names",
    "safe_name",
]

logger = logging.getLogger(__name__)

FIXED_STEP_HOST_RUN = MappingProxyType(
    {
        "algorithm": "jacobi",
        "extrapolation": "constant",
        "iterations": 1,
        "adaptive": False,
        "ramped_flows": False,
    }
)
"""The run settings under which our master does what a fixed-step host (libcosim, FMPy's
SSP runner) does with an exported scene: every unit steps on its partners' values at the
step's start, held, once per fixed step (docs/interop.md)."""

SIGNALS_UNIT = "signals"
"""Instance name of the generated signals unit (suffixed if a scene uses it)."""


class ExportError(ConfigurationError):
    """A scene cannot be exported; ``problems`` lists every reason."""


@dataclass(frozen=True)
class TypedValue:
    """A start value with its FMI type (``Real``, ``Integer``, ``Boolean``, ``String``)."""

    type: str
    value: Any

    @classmethod
    def of(cls, fmi_type: str, value: Any) -> TypedValue:
        """Coerce ``value`` to ``fmi_type`` the way the master's slave does.

        Parameters
        ----------
        fmi_type : str
            ``"Real"``, ``"Integer"``, ``"Enumeration"`` (kept as Integer),
            ``"Boolean"`` or ``"String"``.
        value : object
            The value, in the variable's unit.
        """
        if fmi_type == "Real":
            return cls("Real", float(value))
        if fmi_type in ("Integer", "Enumeration"):
            return cls("Integer", int(value))
        if fmi_type == "Boolean":
            return cls("Boolean", bool(value))
        return cls("String", str(value))

    def text(self) -> str:
        """The value as XML attribute text (Reals round-trip exactly)."""
        if self.type == "Real":
            return repr(float(self.value))
        if self.type == "Boolean":
            return "true" if self.value else "false"
        return str(self.value)

    @classmethod
    def parse(cls, fmi_type: str, text: str) -> TypedValue:
        """Inverse of :meth:`text`.

        Parameters
        ----------
        fmi_type : str
            ``"Real"``, ``"Integer"``, ``"Enumeration"`` (kept as Integer),
            ``"Boolean"`` or ``"String"``.
        text : str
            The XML attribute text.
        """
        if fmi_type == "Boolean":
            return cls("Boolean", text.strip().lower() in ("true", "1"))
        if fmi_type == "Real":
            return cls("Real", float(text))
        if fmi_type in ("Integer", "Enumeration"):
            return cls("Integer", int(text))
        return cls("String", text)


@dataclass(frozen=True)
class PlannedUnit:
    """One unit as it will be exported.

    Attributes
    ----------
    name : str
        Instance name (the scene's unit name).
    fmu : Path
        The FMU file.
    model : object
        Its model description (fmpy).
    start_values : dict
        Parameter (and effects) values by variable name, typed.
    effects : tuple of str
        The scene's effects for this unit (already in ``start_values``).
    generated : bool
        True for the signals unit made from drivers and events.
    """

    name: str
    fmu: Path
    model: Any
    start_values: dict[str, TypedValue]
    effects: tuple[str, ...] = ()
    generated: bool = False

    def variable(self, name: str) -> Any:
        """The model variable ``name`` (KeyError naming the unit if missing).

        Parameters
        ----------
        name : str
            A variable of the unit's FMU.
        """
        for var in self.model.modelVariables:
            if var.name == name:
                return var
        raise KeyError(f"unit {self.name!r} has no variable {name!r}")


@dataclass(frozen=True)
class ExportPlan:
    """A scene ready to be written as SSP or OSP.

    Attributes
    ----------
    scene : Scene
        The scene as parsed.
    units : tuple of PlannedUnit
        Every unit, the generated signals unit last.
    bonds : tuple of Bond
        The scene's power bonds.
    connections : tuple of Connection
        Plain signal connections: the scene's and the signals unit's.
    signals : str or None
        Name of the generated signals unit, if any.
    metadata : dict
        What our reader needs to restore the scene exactly (drivers, events,
        outputs, plots, run settings), JSON-ready.
    """

    scene: Scene
    units: tuple[PlannedUnit, ...]
    bonds: tuple[Bond, ...]
    connections: tuple[Connection, ...]
    signals: str | None = None
    metadata: dict[str, Any] = field(default_factory=dict)

    def unit(self, name: str) -> PlannedUnit:
        """The planned unit called ``name``.

        Parameters
        ----------
        name : str
            Instance name of the unit (KeyError if there is none).
        """
        for unit in self.units:
            if unit.name == name:
                return unit
        raise KeyError(f"no unit {name!r} in the export of scene {self.scene.name!r}")

    def variable(self, ref: VarRef) -> Any:
        """The model variable ``ref`` names.

        Parameters
        ----------
        ref : VarRef
            ``unit.variable`` (KeyError if either is missing).
        """
        return self.unit(ref.unit).variable(ref.variable)

    @property
    def all_connections(self) -> tuple[Connection, ...]:
        """Plain connections followed by every bond's connections."""
        return self.connections + tuple(c for b in self.bonds for c in b.connections)


def safe_name(text: str) -> str:
    """``text`` reduced to an identifier (letters, digits, underscores).

    Parameters
    ----------
    text : str
        A name, e.g. a scene's.
    """
    name = re.sub(r"\W", "_", text)
    return name if name and not name[0].isdigit() else f"_{name}"


def archive_names(units: tuple[PlannedUnit, ...]) -> dict[Path, str]:
    """A file name for each distinct FMU (two units of one FMU share it).

    Parameters
    ----------
    units : tuple of PlannedUnit
        The units planned for export.

    Returns
    -------
    dict of Path to str
        The file name of each resolved FMU path, unique among them.
    """
    names: dict[Path, str] = {}
    taken: set[str] = set()
    for unit in units:
        path = unit.fmu.resolve()
        if path in names:
            continue
        name, i = path.name, 1
        while name in taken:
            i += 1
            name = f"{path.stem}_{i}{path.suffix}"
        names[path] = name
        taken.add(name)
    return names


def _typed_start_values(scene: Scene, structure: Structure, unit: str) -> dict[str, TypedValue]:
    spec = scene.units[unit]
    md = structure.descriptions[unit]
    names = SimpleNamespace(variables={v.name: v for v in md.modelVariables})
    values = unit_start_values(spec, names)
    return {key: TypedValue.of(names.variables[key].type, value) for key, value in values.items()}


def portable_driver_spec(spec: dict[str, Any], base_dir: Path) -> dict[str, Any]:
    """A driver table that needs no file: a ``table`` becomes a ``ramp`` of its points.

    Both build the same :class:`~wire_fmu.master.drivers.PiecewiseLinearDriver`.

    Parameters
    ----------
    spec : dict
        A scene's driver table (``kind`` and its keys).
    base_dir : Path
        Folder of the scene file, where a relative table file is found.

    Returns
    -------
    dict
        ``spec`` itself (copied), or for a ``table`` the equivalent ``ramp``.

    Raises
    ------
    ExportError
        If the table cannot be read.
    """
    if spec.get("kind") != "table":
        return dict(spec)
    from wire_fmu.master.drivers import make_driver

    driver, problems = make_driver(spec, where="table driver", base_dir=base_dir)
    if problems:
        raise ExportError("table driver", problems)
    points = [[float(t), float(v)] for t, v in zip(driver.times, driver.values, strict=True)]
    return {"kind": "ramp", "points": points}


def _portable(value: Any) -> Any:
    """A run setting as strict JSON: infinity (``energy_guard = inf``) as ``"inf"``."""
    return "inf" if isinstance(value, float) and value == math.inf else value


def _metadata(scene: Scene) -> dict[str, Any]:
    """What our reader restores: everything SSP has no element for."""
    run = {k: _portable(getattr(scene.run, k)) for k in scene.run.__dataclass_fields__}
    run["order"] = list(run["order"])
    return {
        "format": "wire_fmu.scene/1",
        "name": scene.name,
        "description": scene.description,
        "run": run,
        "drivers": [
            {
                "target": str(d.target),
                "rate_target": str(d.rate_target) if d.rate_target else None,
                "label": d.label,
                "spec": portable_driver_spec(d.spec, scene.base_dir),
            }
            for d in scene.drivers
        ],
        "events": [
            {"time": e.time, "label": e.label, "set": {str(k): v for k, v in e.values.items()}}
            for e in scene.events
        ],
        "outputs": None if scene.outputs is None else [str(r) for r in scene.outputs],
        "plots": [
            {"title": p.title, "ylabel": p.ylabel, "variables": [str(r) for r in p.variables]}
            for p in scene.plots
        ],
        "effects": {name: list(u.effects) for name, u in scene.units.items() if u.effects},
        "fmus": {name: u.fmu for name, u in scene.units.items()},
    }


def as_fixed_step_host_runs_it(scene: Scene, **changes: Any) -> Scene:
    """``scene`` with :data:`FIXED_STEP_HOST_RUN` and ``changes`` as its run settings.

    Parameters
    ----------
    scene : Scene
        The scene.
    **changes
        Further run settings by name, e.g. ``stop_time=5.0`` (s).

    Returns
    -------
    Scene
        What our master runs to compute what a fixed-step host computes from the
        scene's export.
    """
    return with_run_settings(scene, **{**FIXED_STEP_HOST_RUN, **changes})


def _warn_about_run_settings(scene: Scene) -> None:
    s = scene.run
    differs = []
    if s.algorithm != "jacobi":
        differs.append(f"algorithm {s.algorithm!r}")
    if s.extrapolation != "constant" or any(
        c.extrapolation not in (None, "constant") for c in scene.all_connections
    ):
        differs.append(f"extrapolation {s.extrapolation!r}")
    if s.iterations > 1:
        differs.append(f"{s.iterations} iterations per step")
    if s.adaptive:
        differs.append("adaptive steps")
    if any(b.ramped for b in scene.bonds):
        differs.append("ramped flows")
    if differs:
        logger.warning(
            "scene %r asks for %s; the exported fixed-step system is run by other "
            "tools as Jacobi with inputs held constant (zero-order hold) at step "
            "%g s — see docs/interop.md",
            scene.name,
            ", ".join(differs),
            s.step,
        )
    for event in scene.events:
        ratio = event.time / s.step
        if abs(ratio - round(ratio)) > 1e-9 * max(1.0, ratio):
            logger.warning(
                "event %r at %g s is not on the %g s step grid; a fixed-step host "
                "applies it at the next step",
                event.label,
                event.time,
                s.step,
            )


def plan_export(
    scene: Scene, *, fmu_dir: Path = DEFAULT_FMU_DIR, build_dir: Path | None = None
) -> ExportPlan:
    """Validate ``scene`` and resolve everything an export writes.

    Parameters
    ----------
    scene : Scene
        The parsed scene.
    fmu_dir : Path
        Where our FMUs are built and cached.
    build_dir : Path, optional
        Where the signals FMU is built (default: ``fmu_dir``).

    Returns
    -------
    ExportPlan

    Raises
    ------
    SceneError
        If the scene itself has problems (every one listed).
    ExportError
        If the scene cannot be expressed with connections only (an event on
        a connected or driven input).
    """
    structure = validate_scene(scene, fmu_dir, through_fmi=False)
    _warn_about_run_settings(scene)
    units = [
        PlannedUnit(
            name,
            structure.paths[name],
            structure.descriptions[name],
            _typed_start_values(scene, structure, name),
            spec.effects,
        )
        for name, spec in scene.units.items()
    ]
    connections = list(scene.connections)
    signals_name = None
    if scene.drivers or scene.events:
        from .signals import build_signals_fmu

        signals_name = _free_name(SIGNALS_UNIT, scene.units)
        built = build_signals_fmu(scene, structure, Path(build_dir or fmu_dir), signals_name)
        units.append(
            PlannedUnit(
                signals_name,
                built.path,
                built.model,
                {"step": TypedValue("Real", scene.run.step)},
                generated=True,
            )
        )
        connections += built.connections
    # a ramp's value is the master's work (the flow's slope), no connection: another tool
    # leaves the ramp input at 0 and holds the flow; the run settings keep the choice
    bonds = tuple(b.wire(b.wired, ramp=False) for b in scene.bonds)
    plan = ExportPlan(
        scene, tuple(units), bonds, tuple(connections), signals_name, _metadata(scene)
    )
    json.dumps(plan.metadata)  # fail here, not half-way through writing, if not JSON-ready
    return plan


def _free_name(base: str, taken) -> str:
    name, i = base, 1
    while name in taken:
        i += 1
        name = f"{base}_{i}"
    return name

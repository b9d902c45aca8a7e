"""Cases of a sweep: expanding a spec, naming each case, applying it to a scene.

A case is one set of values, one per axis of the spec. Its id is a hash of
those values (target names and values, canonical JSON), so the same case
gets the same id in every invocation: a resumed sweep recognises the cases
whose results are already on disk, whatever order the spec lists them in.

:func:`apply_case` returns a new :class:`~wire_fmu.master.scene.Scene`
(``dataclasses.replace``); the parameter and driver tables it changes are
deep copies, so the scene a sweep starts from is never modified.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

from wire_fmu.master.observers import BOND_CHANNELS, LEDGER_CHANNEL
from wire_fmu.master.run import with_run_settings
from wire_fmu.master.scene import (
    DriverSpec,
    RunSettings,
    Scene,
    SceneError,
    UnitSpec,
    VarRef,
    is_scalar,
    valid_time,
)
from wire_fmu.master.validate import Structure

from .figures import Figure
from .spec import SweepSpec, SweepSpecError

__all__ = [
    "Case",
    "case_id",
    "expand",
    "check_targets",
    "target_problems",
    "apply_case",
    "with_figures_recorded",
]

logger = logging.getLogger(__name__)

ID_LENGTH = 16
"""Hexadecimal digits of a case id (64 bits of SHA-256)."""


@dataclass(frozen=True)
class Case:
    """One run of a sweep.

    Attributes
    ----------
    case_id : str
        Hash of ``values`` (see :func:`case_id`).
    index : int
        Position in the expanded sweep, from 0.
    values : mapping
        Target -> value, in the spec's axis order.
    """

    case_id: str
    index: int
    values: Mapping[str, Any]

    def label(self, width: int = 60) -> str:
        """Short ``name=value, ...`` text (last target component), cut at ``width``.

        Parameters
        ----------
        width : int
            Most characters (the cut ends in ``...``).
        """
        text = ", ".join(f"{t.rsplit('.', 1)[-1]}={_short(v)}" for t, v in self.values.items())
        return text if len(text) <= width else text[: width - 3] + "..."


def _short(value: Any) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def case_id(values: Mapping[str, Any]) -> str:
    """Stable id of a case: SHA-256 of its values as canonical JSON, shortened.

    Floats are written by ``repr`` (exact), keys sorted, so the id depends on
    the values only, not on the order of the axes or of the cases.

    Parameters
    ----------
    values : mapping
        Target -> value of the case.
    """
    text = json.dumps(values, sort_keys=True, separators=(",", ":"), allow_nan=True, default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:ID_LENGTH]


def _samples(spec: SweepSpec) -> list[dict[str, Any]]:
    axes = spec.sampled_axes
    if not axes or spec.sampling is None:
        return [{}]
    points = spec.sampling.unit_points(len(axes))
    drawn = [axis.draw(points[:, j]) for j, axis in enumerate(axes)]
    return [{a.target: drawn[j][i] for j, a in enumerate(axes)} for i in range(len(points))]


def expand(spec: SweepSpec) -> list[Case]:
    """Every case of ``spec``: each grid point combined with each sample.

    The first grid axis varies slowest; samples vary fastest. Cases whose
    values coincide (possible when sampled integer axes round alike) are
    kept once.

    Parameters
    ----------
    spec : SweepSpec
        The parsed spec.
    """
    grid_axes = spec.grid_axes
    cases: list[Case] = []
    seen: set[str] = set()
    for point in itertools.product(*(a.values for a in grid_axes)):
        on_grid = dict(zip((a.target for a in grid_axes), point, strict=True))
        for sample in _samples(spec):
            values = {a.target: (on_grid | sample)[a.target] for a in spec.axes}
            cid = case_id(values)
            if cid in seen:
                logger.warning("case %s repeats an earlier case; kept once", values)
                continue
            seen.add(cid)
            cases.append(Case(cid, len(cases), values))
    return cases


# -- where a target points --------------------------------------------------------------
def _nested(container: Any, parts: list[str], where: str) -> tuple[list[str | int], str | None]:
    """Keys leading into a table/list; a problem if one does not exist."""
    path: list[str | int] = []
    for part in parts:
        if isinstance(container, Mapping):
            if part not in container:
                known = ", ".join(map(str, container)) or "none"
                return path, f"{where}: no key {part!r} (keys: {known})"
            key: str | int = part
        elif isinstance(container, list):
            if not part.isdigit() or int(part) >= len(container):
                return path, f"{where}: {part!r} is not an index of a list of {len(container)}"
            key = int(part)
        else:
            return (
                path,
                f"{where}: {'.'.join(map(str, path)) or 'the value'} is a value, "
                f"not a table or list",
            )
        path.append(key)
        container = container[key]
    return path, None


def _parameter_path(
    params: Mapping[str, Any], rest: str, where: str
) -> tuple[list[str | int], str | None]:
    """Keys of a parameter (name possibly dotted, then a path into its table)."""
    if rest in params:
        return [rest], None
    parts = rest.split(".")
    for k in range(len(parts) - 1, 0, -1):
        head = ".".join(parts[:k])
        if head in params:
            path, problem = _nested(params[head], parts[k:], f"{where} (inside {head!r})")
            return [head, *path], problem
    return [rest], None  # not set by the scene: replaces the unit's default


def _driver_path(
    driver: DriverSpec, parts: list[str], where: str
) -> tuple[list[str | int], str | None]:
    from wire_fmu.master.drivers import DRIVER_KINDS

    key, nested = parts[0], parts[1:]
    if key not in driver.spec:
        kind = DRIVER_KINDS.get(driver.spec.get("kind"))
        if kind is None or key not in kind.keys or nested:
            known = ", ".join(kind.keys) if kind else "none"
            return [key], f"{where}: the driver sets no {key!r} (keys of its kind: {known})"
        return [key], None
    path, problem = _nested(driver.spec[key], nested, where)
    return [key, *path], problem


def _index(text: str, items: tuple, what: str, where: str) -> tuple[int | None, str | None]:
    i = int(text)
    if i >= len(items):
        return None, f"{where}: the scene has {len(items)} {what}, no index {i}"
    return i, None


def _target_problem(scene: Scene, target: str) -> str | None:
    """Why ``target`` does not point at something in ``scene``, or None."""
    where = f"axis {target!r}"
    root, _, rest = target.partition(".")
    parts = rest.split(".")
    if root == "units":
        unit = scene.units.get(parts[0])
        if unit is None:
            return f"{where}: the scene has no unit {parts[0]!r}; units: {', '.join(scene.units)}"
        if parts[1] == "effects":
            return None
        return _parameter_path(unit.parameters, ".".join(parts[2:]), where)[1]
    if root == "drivers":
        i, problem = _index(parts[0], scene.drivers, "drivers", where)
        return problem or _driver_path(scene.drivers[i], parts[1:], where)[1]
    if root == "events":
        i, problem = _index(parts[0], scene.events, "events", where)
        if problem is None and parts[1] == "set" and VarRef.parse(".".join(parts[2:])) is None:
            return f"{where}: an event sets 'unit.input'"
        return problem
    if parts[0] not in RunSettings.__dataclass_fields__:
        return (
            f"{where}: no run setting {parts[0]!r}; known: "
            f"{', '.join(RunSettings.__dataclass_fields__)}"
        )
    return None


def _parameter_exists(scene: Scene, structure: Structure, target: str) -> str | None:
    root, _, rest = target.partition(".")
    parts = rest.split(".")
    if root != "units" or parts[1] != "parameters" or parts[0] not in structure.descriptions:
        return None
    path, _ = _parameter_path(scene.units[parts[0]].parameters, ".".join(parts[2:]), target)
    md = structure.descriptions[parts[0]]
    names = [v.name for v in md.modelVariables if v.causality in ("parameter", "input")]
    if path[0] not in names:
        return (
            f"axis {target!r}: unit {parts[0]!r} has no parameter {path[0]!r}; its "
            f"parameters: {', '.join(names)}"
        )
    return None


def _column_problem(scene: Scene, structure: Structure | None, figure: Figure) -> str | None:
    where = f"figure {figure.name!r} ({figure.expression})"
    column = figure.column
    parts = column.split(".")
    if parts[0] == "bond" and len(parts) == 3 and parts[2] in BOND_CHANNELS:
        bonds = [b.name for b in scene.bonds]
        return None if parts[1] in bonds else f"{where}: the scene has no bond {parts[1]!r}"
    if column == LEDGER_CHANNEL:
        return None
    ref = VarRef.parse(column)
    if ref is None or ref.unit not in scene.units:
        return (
            f"{where}: {column!r} is neither 'unit.output' of a unit of the scene "
            f"({', '.join(scene.units)}) nor a bond or energy channel"
        )
    if structure is None or ref.unit not in structure.descriptions:
        return None
    var = structure.variable(ref)
    if var is None:
        return f"{where}: unit {ref.unit!r} has no variable {ref.variable!r}"
    if scene.outputs is None and var.causality != "output":
        return f"{where}: {column} is a {var.causality}, not an output (outputs are recorded)"
    return None


def check_targets(spec: SweepSpec, scene: Scene, structure: Structure | None = None) -> list[str]:
    """Every axis target and figure column of ``spec`` that ``scene`` lacks.

    Parameters
    ----------
    spec : SweepSpec
        The sweep.
    scene : Scene
        The scene it sweeps.
    structure : Structure, optional
        The units' model descriptions; with it, parameter and variable
        names are checked against the FMUs too.

    Returns
    -------
    list of str
        One sentence per problem; empty when everything exists.
    """
    return target_problems([a.target for a in spec.axes], spec.figures, scene, structure)


def target_problems(
    targets: Sequence[str],
    figures: Sequence[Figure],
    scene: Scene,
    structure: Structure | None = None,
) -> list[str]:
    """Every one of ``targets`` and of the ``figures``' columns that ``scene`` lacks.

    Each target and column is checked on its own, so that one's problem hides no
    other's (a spec with format problems is checked so too, see
    :class:`~wire_fmu.sweep.spec.SweepSpecError`).

    Parameters
    ----------
    targets : sequence of str
        Well-formed axis targets (``units.<unit>.parameters.<name>`` ...).
    figures : sequence of Figure
        Key figures.
    scene : Scene
        The scene swept.
    structure : Structure, optional
        The units' model descriptions, as for :func:`check_targets`.

    Returns
    -------
    list of str
        One sentence per problem; empty when everything exists.
    """
    problems = []
    for target in targets:
        problem = _target_problem(scene, target)
        if problem is None and structure is not None:
            problem = _parameter_exists(scene, structure, target)
        if problem:
            problems.append(problem)
    problems += [p for f in figures if (p := _column_problem(scene, structure, f))]
    return problems


# -- applying a case ------------------------------------------------------------------------
def _set(container: Any, path: list[str | int], value: Any) -> None:
    for key in path[:-1]:
        container = container[key]
    container[path[-1]] = value


def _effects(value: Any, target: str) -> tuple[str, ...]:
    if isinstance(value, str):
        return tuple(e.strip() for e in value.replace(",", " ").split() if e.strip())
    if isinstance(value, list | tuple) and all(isinstance(e, str) for e in value):
        return tuple(value)
    raise SceneError(target, [f"{value!r}: effects are a list of effect names"])


def _apply_unit(unit: UnitSpec, parts: list[str], value: Any, target: str) -> UnitSpec:
    if parts[1] == "effects":
        return replace(unit, effects=_effects(value, target))
    params = copy.deepcopy(unit.parameters)
    path, problem = _parameter_path(params, ".".join(parts[2:]), f"axis {target!r}")
    if problem:
        raise SweepSpecError(target, [problem])
    _set(params, path, value)
    return replace(unit, parameters=params)


def _apply_driver(driver: DriverSpec, parts: list[str], value: Any, target: str) -> DriverSpec:
    spec = copy.deepcopy(driver.spec)
    path, problem = _driver_path(driver, parts, f"axis {target!r}")
    if problem:
        raise SweepSpecError(target, [problem])
    _set(spec, path, value)
    return replace(driver, spec=spec)


def apply_case(scene: Scene, values: Mapping[str, Any]) -> Scene:
    """A copy of ``scene`` with a case's values applied.

    Parameters
    ----------
    scene : Scene
        The scene swept (left unchanged).
    values : mapping
        Target -> value (see :mod:`wire_fmu.sweep.spec` for targets).

    Raises
    ------
    SweepSpecError
        A target that does not exist in ``scene``.
    SceneError
        A run setting the case sets to an invalid value.
    """
    units, drivers, events = dict(scene.units), list(scene.drivers), list(scene.events)
    run: dict[str, Any] = {}
    for target, raw in values.items():
        value = copy.deepcopy(raw)
        problem = _target_problem(scene, target)
        if problem:
            raise SweepSpecError(target, [problem])
        root, _, rest = target.partition(".")
        parts = rest.split(".")
        if root == "units":
            units[parts[0]] = _apply_unit(units[parts[0]], parts, value, target)
        elif root == "drivers":
            i = int(parts[0])
            drivers[i] = _apply_driver(drivers[i], parts[1:], value, target)
        elif root == "events":
            i = int(parts[0])
            if parts[1] == "time":
                if not valid_time(value):
                    raise SceneError(target, [f"{value!r} is no time of an event (s, 0 to 1e12)"])
                events[i] = replace(events[i], time=float(value))
            else:
                if not is_scalar(value):
                    raise SceneError(
                        target, [f"{value!r}: an event sets a number, true/false or text"]
                    )
                ref = VarRef.parse(".".join(parts[2:]))
                events[i] = replace(events[i], values={**events[i].values, ref: value})
        elif parts[0] == "order":
            if not isinstance(value, list | tuple) or not all(isinstance(u, str) for u in value):
                raise SceneError(target, [f"{value!r}: run.order is a list of unit names"])
            run["order"] = tuple(value)
        else:
            run[parts[0]] = value
    changed = replace(
        scene,
        units=units,
        drivers=tuple(drivers),
        events=tuple(sorted(events, key=lambda e: e.time)),
    )
    return with_run_settings(changed, **run) if run else changed


def with_figures_recorded(scene: Scene, figures: tuple[Figure, ...]) -> Scene:
    """``scene`` recording every unit column a key figure reads (others are always recorded).

    Parameters
    ----------
    scene : Scene
        The scene; one that records every output is returned as is.
    figures : tuple of Figure
        The sweep's key figures.
    """
    if scene.outputs is None:
        return scene
    wanted = list(scene.outputs)
    for figure in figures:
        ref = VarRef.parse(figure.column)
        if ref is not None and ref.unit in scene.units and ref not in wanted:
            wanted.append(ref)
    return replace(scene, outputs=tuple(wanted))

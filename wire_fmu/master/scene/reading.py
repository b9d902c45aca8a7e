"""Reading a scene: from a TOML file or plain data to a :class:`~.data.Scene` and its problems."""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..files import UnreadableFileError, read_regular
from .bonds import PortsOf, parse_bonds
from .checks import is_plain_name, unknown_unit_problems
from .data import Scene, SceneError, UnitSpec
from .sections import (
    _parse_connections,
    _parse_drivers,
    _parse_events,
    _parse_outputs,
    _parse_plots,
    _parse_run,
    _parse_units,
)

__all__ = ["load_scene", "parse_scene", "read_scene", "read_scene_data", "MAX_SCENE_BYTES"]

MAX_SCENE_BYTES = 16 * 2**20
"""The largest scene file read (a scene is a few kilobytes; a reeving table a few more)."""
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


def load_scene(path: Path) -> Scene:
    """Read and parse a scene file.

    Parameters
    ----------
    path : Path
        The scene file (TOML, at most :data:`MAX_SCENE_BYTES`).

    Returns
    -------
    Scene

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
    """Build a :class:`Scene` from plain data; raise :class:`SceneError` with every problem.

    Parameters
    ----------
    data : mapping
        What a scene file holds, as :mod:`tomllib` reads it.
    base_dir : Path
        Folder relative paths (FMUs, driver tables) are found in.
    source : Path, optional
        The file the data came from.

    Returns
    -------
    Scene
    """
    scene, problems = read_scene_data(data, base_dir=base_dir, source=source)
    if problems:
        raise SceneError(f"scene {scene.name!r}", problems)
    return scene


def read_scene(path: Path) -> tuple[Scene | None, list[str]]:
    """Read a scene file; return it (None if unreadable) and every problem of its data.

    The scene returned with problems has each invalid item left out or at its
    default, so that the checks that need the units can still run and report
    their problems in the same list (``wire-fmu check``).

    Parameters
    ----------
    path : Path
        The scene file (TOML, at most :data:`MAX_SCENE_BYTES`).

    Returns
    -------
    scene : Scene or None
        The scene; None if the file cannot be read or is no TOML.
    problems : list of str
        Every problem found; empty if none.
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
    """Build a :class:`Scene` from plain data and list every problem (see :func:`read_scene`).

    Parameters
    ----------
    data : mapping
        What a scene file holds, as :mod:`tomllib` reads it.
    base_dir : Path
        Folder relative paths (FMUs, driver tables) are found in.
    source : Path, optional
        The file the data came from (its stem is the default name).

    Returns
    -------
    scene : Scene
        The scene, each invalid item left out or at its default.
    problems : list of str
        Every problem found; empty if none.
    """
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
    ports_of = _port_reader(units, Path(base_dir))
    bonds = parse_bonds(data.get("bonds", []), problems, set(units), ports_of)
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


def _port_reader(units: Mapping[str, UnitSpec], base_dir: Path) -> PortsOf:
    """Reads (once per unit) the ports a unit's FMU declares, for bonds written as ports."""
    read: dict[str, tuple] = {}

    def ports_of(unit: str) -> tuple:
        """Ports of ``unit``'s FMU, or why they cannot be read (see :data:`.bonds.PortsOf`).

        Parameters
        ----------
        unit : str
            Instance name of a unit of the scene.
        """
        from ..ports import unit_ports  # opens (and builds) FMUs: only when a bond needs it

        if unit not in read:
            read[unit] = unit_ports(units[unit].fmu, base_dir)
        return read[unit]

    return ports_of


def _scene_name(name: Any, problems: list[str]) -> str:
    """The scene's name; it names the results folder, so it must be a plain file name."""
    if isinstance(name, str) and is_plain_name(name):
        return name
    problems.append(
        f"'name' {name!r}: must be a plain file name (letters, digits, '_', '-', "
        "'.', at most 128 characters, no '..'), since it names the results folder"
    )
    return "scene"

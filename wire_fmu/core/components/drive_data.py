"""Multi-mass drives as data: the JSON reader and paper 002's example drives.

A drive is a table of masses (name, inertia, damping), shafts (name, the
masses they join, stiffness, damping), the motors and the load, all reduced
to the motor shaft; :func:`parse_drive` turns it into a
:class:`~wire_fmu.core.components.drive_tree.DriveTree` and lists every
problem it finds.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from wire_fmu.core.components.drive_tree import DriveTree, Shaft

__all__ = ["parse_drive", "default_multimass_drive", "two_motor_drive"]


# ---------------------------------------------------------------- examples
def default_multimass_drive() -> dict[str, Any]:
    """A four-mass conveyor or hoist drive, every quantity reduced to the motor shaft.

    Estimated values (paper 002 gives none): a 30 kW, 1470 rpm induction
    motor rotor (0.5 kg m^2); a flexible jaw coupling and the gearbox's
    first stage (0.02 kg m^2); the gearbox output and a brake disc reduced
    through 1:20 (0.1 kg m^2); the driven machine (2.0 kg m^2 reduced),
    with a speed-proportional load characteristic linearised as 0.8 N m s/rad.
    Stiffnesses: coupling 1.5e4, gear shaft 6e4, long output shaft 4e3 N m/rad
    at the motor shaft; shaft damping a few per cent of critical.
    """
    return {
        "masses": [
            {"name": "motor rotor", "inertia": 0.5, "damping": 0.02},
            {"name": "coupling", "inertia": 0.02, "damping": 0.0},
            {"name": "gearbox", "inertia": 0.1, "damping": 0.05},
            {"name": "machine", "inertia": 2.0, "damping": 0.8},
        ],
        "shafts": [
            {"name": "coupling", "stiffness": 1.5e4, "damping": 2.0},
            {"name": "gear shaft", "stiffness": 6.0e4, "damping": 3.0},
            {"name": "output shaft", "stiffness": 4.0e3, "damping": 2.5},
        ],
    }


def two_motor_drive() -> dict[str, Any]:
    """Paper 002's branched drive (Fig. 7): two motors into one gear, then the load.

    Estimated values: two 0.4 kg m^2 motor rotors on couplings of 1.2e4 and
    1.0e4 N m/rad (slightly unequal, so the motors share the load unevenly
    during transients) into a common gear mass of 0.3 kg m^2, driving a
    4 kg m^2 machine through a 6e3 N m/rad shaft, all at motor speed.
    """
    return {
        "masses": [
            {"name": "motor 1", "inertia": 0.4, "damping": 0.02},
            {"name": "motor 2", "inertia": 0.4, "damping": 0.02},
            {"name": "gear", "inertia": 0.3, "damping": 0.05},
            {"name": "machine", "inertia": 4.0, "damping": 1.0},
        ],
        "shafts": [
            {
                "name": "coupling 1",
                "from": "motor 1",
                "to": "gear",
                "stiffness": 1.2e4,
                "damping": 2.0,
            },
            {
                "name": "coupling 2",
                "from": "motor 2",
                "to": "gear",
                "stiffness": 1.0e4,
                "damping": 2.0,
            },
            {
                "name": "output shaft",
                "from": "gear",
                "to": "machine",
                "stiffness": 6.0e3,
                "damping": 3.0,
            },
        ],
        "motors": ["motor 1", "motor 2"],
        "load": "machine",
    }


# ---------------------------------------------------------------- parsing
def _number(
    item: Mapping[str, Any], key: str, default: float | None, where: str, problems: list[str]
) -> float:
    value = item.get(key, default)
    try:
        return float(value)
    except (TypeError, ValueError):
        problems.append(f"{where}: {key!r} must be a number, got {value!r}")
        return math.nan


def _index(ref: Any, names: list[str], where: str, problems: list[str]) -> int:
    if isinstance(ref, int) and not isinstance(ref, bool) and -len(names) <= ref < len(names):
        return ref % len(names)
    if isinstance(ref, str) and ref in names:
        return names.index(ref)
    problems.append(f"{where}: {ref!r} names no mass; masses: {', '.join(names)}")
    return 0


def _masses(data: Any, problems: list[str]) -> tuple[list[str], list[float], list[float]]:
    names, inertias, dampings = [], [], []
    if not isinstance(data, list) or not data:
        problems.append("drive: 'masses' must be a non-empty list of tables")
        return names, inertias, dampings
    for i, item in enumerate(data):
        where = f"drive masses[{i}]"
        if not isinstance(item, Mapping):
            problems.append(f"{where} must be a table with name, inertia, damping")
            continue
        unknown = sorted(set(item) - {"name", "inertia", "damping"})
        if unknown:
            problems.append(f"{where}: unknown keys {unknown}; known: name, inertia, damping")
        names.append(str(item.get("name", f"mass {i + 1}")))
        inertias.append(_number(item, "inertia", None, where, problems))
        dampings.append(_number(item, "damping", 0.0, where, problems))
    if len(set(names)) != len(names):
        problems.append(f"drive: mass names must be unique, got {names}")
    return names, inertias, dampings


def _shafts(data: Any, names: list[str], problems: list[str]) -> list[Shaft]:
    out = []
    if not isinstance(data, list):
        problems.append("drive: 'shafts' must be a list of tables")
        return out
    for i, item in enumerate(data):
        where = f"drive shafts[{i}]"
        if not isinstance(item, Mapping):
            problems.append(f"{where} must be a table")
            continue
        unknown = sorted(set(item) - {"name", "from", "to", "stiffness", "damping"})
        if unknown:
            problems.append(
                f"{where}: unknown keys {unknown}; known: name, from, to, stiffness, damping"
            )
        a = _index(item.get("from", i), names, f"{where} 'from'", problems) if names else 0
        b = _index(item.get("to", i + 1), names, f"{where} 'to'", problems) if names else 0
        out.append(
            Shaft(
                a,
                b,
                _number(item, "stiffness", None, where, problems),
                _number(item, "damping", 0.0, where, problems),
                str(item.get("name", f"shaft {i + 1}")),
            )
        )
    return out


def parse_drive(data: Any) -> tuple[DriveTree | None, list[str]]:
    """A :class:`DriveTree` from JSON data; every problem found.

    Parameters
    ----------
    data : dict
        ``{"masses": [{"name", "inertia", "damping"}, ...], "shafts":
        [{"name", "from", "to", "stiffness", "damping"}, ...], "motors":
        [mass, ...], "load": mass}``; masses are referred to by name or
        index. Shafts without ``from``/``to`` join consecutive masses (a
        chain); ``motors`` defaults to the first mass, ``load`` to the last.

    Returns
    -------
    drive : DriveTree or None
        None if there are problems.
    problems : list of str
    """
    if not isinstance(data, Mapping):
        return None, [f"drive must be a table with 'masses' and 'shafts', got {data!r}"]
    problems: list[str] = []
    unknown = sorted(set(data) - {"masses", "shafts", "motors", "load"})
    if unknown:
        problems.append(f"drive: unknown keys {unknown}; known: masses, shafts, motors, load")
    names, inertias, dampings = _masses(data.get("masses"), problems)
    shafts = _shafts(data.get("shafts", []), names, problems)
    motors_data = data.get("motors", [0])
    if not isinstance(motors_data, list) or not 1 <= len(motors_data) <= 2:
        problems.append(f"drive: 'motors' must list one or two masses, got {motors_data!r}")
        motors_data = [0]
    motors = (
        tuple(_index(m, names, "drive 'motors'", problems) for m in motors_data) if names else (0,)
    )
    load = _index(data.get("load", -1), names, "drive 'load'", problems) if names else 0
    if problems:
        return None, problems
    tree = DriveTree(tuple(inertias), tuple(dampings), tuple(shafts), tuple(names), motors, load)
    problems = tree.problems()
    return (None, problems) if problems else (tree, [])

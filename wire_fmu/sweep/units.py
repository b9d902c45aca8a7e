"""Units of a sweep's axes and key figures, for the axes of its plots.

A key figure (``max(rope.path_end.tension)``) is in the unit of its column;
an axis target is in the unit of what it sets: a unit's parameter (as the
unit's FMU declares it), a driver's key (a length or value in the unit of the
driven input, a time in s, a frequency in Hz), a run setting (times in s).
Both are read from the ``metadata.json`` of a case that ran, which records
the unit of every column and parameter (:mod:`wire_fmu.master.run_record`).
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

__all__ = ["sweep_units", "case_metadata"]

_DRIVER_TIMES = frozenset({"period", "peak_period", "start_time", "end_time", "ramp_time", "time"})
_DRIVER_VALUES = frozenset({"value", "amplitude", "offset", "start_value", "end_value"})
_DRIVER_HEIGHTS = frozenset({"significant_height"})  # a wave height: the heave's unit, m
_RUN_TIMES = frozenset({"stop_time", "step", "output_interval", "min_step", "max_step"})


def case_metadata(case_dirs: Iterable[Path]) -> dict[str, Any]:
    """The ``metadata.json`` of the first case folder that has a readable one (else empty).

    Parameters
    ----------
    case_dirs : iterable of Path
        Case results folders.
    """
    for folder in case_dirs:
        try:
            meta = json.loads((Path(folder) / "metadata.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if isinstance(meta, dict):
            return meta
    return {}


def sweep_units(targets: Iterable[str], columns: Iterable[str], meta: Mapping[str, Any]):
    """The unit of each axis target and each figure column ('' where it is unknown).

    Parameters
    ----------
    targets : iterable of str
        Axis targets (``units.cylinder.parameters.gas_bank_volume``,
        ``drivers.0.significant_height``, ``run.step``).
    columns : iterable of str
        Recorded columns the key figures are computed from.
    meta : mapping
        A case's ``metadata.json``.

    Returns
    -------
    dict of str to str
        Unit by target and by column (``"1"`` a pure number).
    """
    column_units = meta.get("column_units") or {}
    out = {c: str(column_units.get(c, "")) for c in columns}
    out.update({t: _target_unit(t, meta) for t in targets})
    return out


def _target_unit(target: str, meta: Mapping[str, Any]) -> str:
    parts = target.split(".")
    if parts[0] == "units" and len(parts) >= 4 and parts[2] == "parameters":
        unit = (meta.get("units") or {}).get(parts[1]) or {}
        entry = (unit.get("parameters") or {}).get(parts[3]) or {}
        return str(entry.get("unit", "")) if len(parts) == 4 else ""
    if parts[0] == "run" and len(parts) == 2:
        return "s" if parts[1] in _RUN_TIMES else ""
    if parts[0] == "drivers" and len(parts) == 3 and parts[1].isdigit():
        return _driver_key_unit(int(parts[1]), parts[2], meta)
    return ""


def _driver_key_unit(index: int, key: str, meta: Mapping[str, Any]) -> str:
    if key in _DRIVER_TIMES:
        return "s"
    if key == "frequency":
        return "Hz"
    drivers = meta.get("drivers") or []
    if index >= len(drivers) or not (key in _DRIVER_VALUES or key in _DRIVER_HEIGHTS):
        return ""
    target = str(drivers[index].get("target", ""))
    variables = meta.get("variables") or {}
    return str((variables.get(target) or {}).get("unit", ""))

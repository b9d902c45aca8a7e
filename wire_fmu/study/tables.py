"""Study data on disk: dataclass rows as CSV, study results as plain JSON."""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, fields
from pathlib import Path
from typing import Any

from wire_fmu.master.scene import VarRef

__all__ = ["write_csv", "to_json", "dumps"]


def write_csv(rows: Sequence[Any], path: Path) -> Path:
    """Write dataclass rows to ``path`` (header from the fields).

    Parameters
    ----------
    rows : sequence of dataclass instances
        One CSV row each (NaN as an empty cell); none: an empty file.
    path : Path
        CSV file to write (its folder is created).
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as f:
        if not rows:
            return path
        writer = csv.writer(f)
        names = [fl.name for fl in fields(rows[0])]
        writer.writerow(names)
        for r in rows:
            writer.writerow([_cell(getattr(r, n)) for n in names])
    return path


def _cell(value: Any) -> Any:
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    if isinstance(value, tuple | list):
        return " ".join(map(str, value))
    return value


def to_json(value: Any) -> Any:
    """Plain JSON data (NaN and infinity as None).

    Parameters
    ----------
    value : object
        Numbers, text, mappings, sequences, paths, variable references and
        dataclasses, nested.
    """
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, Mapping):
        return {str(k): to_json(v) for k, v in value.items()}
    if isinstance(value, tuple | list):
        return [to_json(v) for v in value]
    if isinstance(value, VarRef | Path):
        return str(value)
    if hasattr(value, "__dataclass_fields__"):
        return to_json(asdict(value))
    return value


def dumps(value: Any) -> str:
    """JSON text of study data.

    Parameters
    ----------
    value : object
        Anything :func:`to_json` takes.
    """
    return json.dumps(to_json(value), indent=2)

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

__all__ = ["write_csv", "to_json", "dumps", "write_tables"]


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


def write_tables(
    directory: Path, stem: str, rows: Sequence[Any], markdown: str, data: Any
) -> dict[str, Path]:
    """Write a study's table, summary and JSON into ``directory``; their paths by kind.

    Parameters
    ----------
    directory : Path
        Folder for the files (created).
    stem : str
        File name stem: ``<stem>.csv``, ``<stem>.md`` and ``<stem>.json``.
    rows : sequence of dataclass instances
        The table (see :func:`write_csv`).
    markdown : str
        The summary.
    data : object
        What the JSON holds (see :func:`to_json`).

    Returns
    -------
    dict of str to Path
        ``"csv"``, ``"md"`` and ``"json"``.
    """
    directory.mkdir(parents=True, exist_ok=True)
    files = {"csv": write_csv(rows, directory / f"{stem}.csv")}
    files["md"] = directory / f"{stem}.md"
    files["md"].write_text(markdown)
    files["json"] = directory / f"{stem}.json"
    files["json"].write_text(dumps(data))
    return files

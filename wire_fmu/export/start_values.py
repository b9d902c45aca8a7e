"""An FMU configured by its start values: one unit's parameters, carried inside the FMU.

A host that cannot set some parameter, or sets none (FMPy's SSP runner sets no
String, and only the parameters it is handed), still runs a unit as the scene
configured it when the FMU's own start values are the scene's values.
:func:`write_configured_fmu` copies an FMU of ours with

* the ``start`` of each given variable replaced in ``modelDescription.xml``, so
  that the description says what the FMU does;
* ``resources/start_values.json``, which the facade reads at ``fmi2Instantiate``
  (and ``fmi2Reset``) and applies as if the host had set each value before
  initialisation (:func:`read_start_values`): the facade's defaults come from the
  unit's declarations, not from the XML;
* a GUID of its own (derived from the original's and the values), in the model
  description and in the facade file the binary checks it against, so that no
  host mistakes one configuration for another.

This module runs inside FMUs (the facade reads the file): standard library only.
"""

from __future__ import annotations

import json
import shutil
import uuid
import zipfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any
from xml.etree import ElementTree as ET

from wire_fmu.export.fmu_archive import FACADE_FILE, MODEL_DESCRIPTION, rewrite_zip

__all__ = [
    "START_VALUES_FILE",
    "StartValuesError",
    "fits",
    "read_start_values",
    "write_configured_fmu",
]

START_VALUES_FILE = "start_values.json"
"""File in an FMU's ``resources/`` whose values the facade applies at instantiation."""

_TYPES = {"Real": float, "Integer": int, "Boolean": bool, "String": str}


class StartValuesError(ValueError):
    """A start-values file or request that cannot be applied; ``problems`` names each."""

    def __init__(self, where: str, problems: list[str]) -> None:
        self.problems = list(problems)
        super().__init__(f"{where}: " + "; ".join(self.problems))


def read_start_values(resources: str | Path) -> dict[str, Any]:
    """The values of ``resources/start_values.json`` by variable name (empty if none).

    Parameters
    ----------
    resources : str or Path
        The FMU's resources folder.

    Returns
    -------
    dict of str to object
        Each variable's value (float, int, bool or str), in its unit.

    Raises
    ------
    StartValuesError
        If the file is not a JSON object of names to numbers, booleans or text.
    """
    path = Path(resources) / START_VALUES_FILE
    if not path.is_file():
        return {}
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise StartValuesError(str(path), [f"cannot be read as JSON: {exc}"]) from None
    if not isinstance(data, dict):
        raise StartValuesError(str(path), ["expected an object of variable names to values"])
    bad = [
        f"{name!r} = {value!r}: expected a number, true/false or text"
        for name, value in data.items()
        if not isinstance(value, (int, float, str))
    ]
    if bad:
        raise StartValuesError(str(path), bad)
    return data


def _configured_guid(guid: str, values: Mapping[str, Any]) -> str:
    """A GUID for the FMU ``guid`` configured with ``values`` (the same for the same values)."""
    text = guid + json.dumps(values, sort_keys=True)
    return "{" + str(uuid.uuid5(uuid.NAMESPACE_URL, "wire-fmu:" + text)) + "}"


def fits(kind: type, value: Any) -> bool:
    """Whether ``value`` is a value of a variable of Python type ``kind``.

    Parameters
    ----------
    kind : type
        ``float``, ``int``, ``bool`` or ``str`` (a whole number is a float too).
    value : object
        The value.
    """
    if isinstance(value, bool):
        return kind is bool
    if kind is float:
        return isinstance(value, (int, float))
    return isinstance(value, kind)


def _fits(kind: str, value: Any) -> bool:
    """Whether ``value`` is a value of the FMI type ``kind``."""
    python_type = _TYPES.get("Integer" if kind == "Enumeration" else kind)
    return python_type is not None and fits(python_type, value)


def _start_text(kind: str, value: Any) -> str:
    if kind == "Real":
        return repr(float(value))
    if kind == "Boolean":
        return "true" if value else "false"
    return str(int(value)) if kind in ("Integer", "Enumeration") else str(value)


def _patched_description(xml: bytes, values: Mapping[str, Any], where: str) -> tuple[bytes, str]:
    """``modelDescription.xml`` with the start values and a GUID of its own; the GUID."""
    root = ET.fromstring(xml)
    found: dict[str, ET.Element] = {}
    for node in root.iter("ScalarVariable"):
        found[node.get("name", "")] = node
    problems = []
    for name, value in values.items():
        node = found.get(name)
        if node is None:
            problems.append(f"{name!r}: no such variable")
            continue
        if node.get("causality") not in ("parameter", "input"):
            problems.append(f"{name!r} is an {node.get('causality')}: only parameters and inputs")
            continue
        typed = node[0]
        kind = typed.tag
        if not _fits(kind, value):
            problems.append(f"{name!r} is a {kind}, got {value!r}")
            continue
        typed.set("start", _start_text(kind, value))
    if problems:
        raise StartValuesError(where, problems)
    guid = _configured_guid(root.get("guid", ""), values)
    root.set("guid", guid)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True), guid


def write_configured_fmu(fmu: str | Path, values: Mapping[str, Any], out: str | Path) -> Path:
    """Copy ``fmu`` to ``out`` with ``values`` as its start values (see the module).

    Parameters
    ----------
    fmu : str or Path
        An FMU built by :mod:`wire_fmu.export.builder`.
    values : mapping of str to object
        Values of parameters (and inputs) by variable name, each of the variable's
        type (float, int, bool or str), in the variable's unit.
    out : str or Path
        The configured FMU to write (replaced if it exists).

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    StartValuesError
        Naming every value that is not a parameter or input of the FMU, or not
        of its type.
    """
    fmu, out = Path(fmu), Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    if not values:  # nothing to configure: the FMU as it is
        shutil.copyfile(fmu, out)
        return out
    plain = {name: _plain(value) for name, value in values.items()}
    with zipfile.ZipFile(fmu) as src:
        xml, guid = _patched_description(src.read(MODEL_DESCRIPTION), plain, f"FMU {fmu.name}")
        module, cls, _ = src.read(FACADE_FILE).decode().splitlines()[:3]
    shutil.copyfile(fmu, out)
    rewrite_zip(
        out,
        {
            MODEL_DESCRIPTION: xml,
            FACADE_FILE: f"{module}\n{cls}\n{guid}\n".encode(),
            f"resources/{START_VALUES_FILE}": json.dumps(plain, indent=1).encode(),
        },
    )
    return out


def _plain(value: Any) -> Any:
    """A typed value (``.value``) or a plain one, as JSON takes it."""
    return getattr(value, "value", value)

"""Read an SSP package into a scene, so a system made in another tool runs here.

:func:`read_ssp` extracts the package (into a folder keyed by its content,
so reading it again reuses the files), reads ``SystemStructure.ssd`` and
builds the same plain data a scene file holds, then parses it with
:func:`~wire_fmu.master.scene.parse_scene`, so every scene check applies.

* Each ``ssd:Component`` becomes a unit whose ``fmu`` is the path of its FMU
  inside the extracted package.
* Parameter values come from the component's ``ssd:ParameterBinding``\\ s:
  an SSV file (``source``) or an inline ``ssv:ParameterSet``; bindings of the
  system whose names start with ``<component>.`` apply to that component.
  Values are typed by the SSV element (``Real``, ``Integer``, ``Boolean``,
  ``String``; String parameters like a JSON reeving pass through unchanged).
* Each ``ssd:Connection`` is oriented output to input by the FMUs' own
  causalities. Connections carrying our ``org.wire-fmu.bond`` annotation are
  regrouped into power bonds (name, kind, effort/flow/position, and the
  ``interface`` links of a wired interface model: such a bond comes back
  asking for its model, ``interface_model = true``, unless the restored run
  settings say ``interface_models = true``); all others are plain
  connections. The effort unit's interface switch comes back as the
  parameter it was exported as.
* Our ``org.wire-fmu.scene`` annotation, when present, restores the run
  settings, drivers, events, outputs, plots and effects exactly, and the
  generated signals component is dropped (its drivers are ours again).
  Without it the stop time comes from ``ssd:DefaultExperiment``, the step
  from the OSP ``FixedStepAlgorithm`` annotation if there is one, and the
  rest of the run settings are our defaults.

Not supported (each is reported as a scene problem): nested systems,
connections to system connectors, signal dictionaries, and connections
with a transformation (``ssc:LinearTransformation`` and the mappings).

A package is untrusted input. It is extracted by
:mod:`wire_fmu.master.archive` (bounded in size and member count, no member
outside the folder, atomic, so a half-extracted folder is never reused);
every file the SSD names (a component's FMU, an SSV parameter file, a table
a driver reads) must be a file inside the package; the XML is parsed
without entities, DTDs or network access; and anything malformed (XML that
is not well formed, a missing required attribute, a value that is not a
number, annotation JSON that does not parse or has the wrong shape) is
reported as a problem naming the element, never as a traceback. Every
problem found is listed in one :class:`~wire_fmu.master.scene.SceneError`.

The reader's parts: :mod:`.ssp_read_files` (files inside the package, safe
XML), :mod:`.ssp_read_elements` (components, parameter bindings,
connections, run settings) and :mod:`.ssp_read_annotation` (our scene
annotation).
"""

from __future__ import annotations

import logging
import tempfile
from pathlib import Path
from typing import Any

from wire_fmu.master.archive import ArchiveError, ArchiveLimits, extract_archive, extract_cached
from wire_fmu.master.scene import Scene, SceneError, parse_scene

from .ssp import SSD_NAME
from .ssp_read_annotation import _restore, _scene_metadata
from .ssp_read_elements import _components, _connections, _run_settings, _wire_interface_models
from .ssp_read_files import _q, _read_xml

__all__ = ["read_ssp", "extract_ssp", "ssp_scene_data"]

logger = logging.getLogger(__name__)


def _cache_root() -> Path:
    """Where packages are extracted by default (a folder per package content)."""
    return Path(tempfile.gettempdir()) / "wire_fmu_ssp"


def extract_ssp(
    path: Path, into: Path | None = None, *, limits: ArchiveLimits | None = None
) -> Path:
    """Extract the package ``path`` safely; return the folder holding its SSD.

    See :mod:`wire_fmu.master.archive`: the extraction is bounded, confined
    to the folder and atomic, and a folder is reused only if it holds a
    complete extraction of the same content.

    Parameters
    ----------
    path : Path
        The ``.ssp`` file.
    into : Path, optional
        Target folder (new, empty, or an earlier extraction of ours); default
        a folder under the system's temporary directory named by the
        package's SHA-256, reused when complete.
    limits : ArchiveLimits, optional
        Bounds on the extracted size and member count (default 1 GiB,
        10,000 members).

    Raises
    ------
    SceneError
        Naming the package and what is wrong with it.
    """
    path = Path(path)
    try:
        if into is None:
            folder = extract_cached(path, _cache_root(), what="package", limits=limits)
        else:
            folder = extract_archive(path, Path(into), what="package", limits=limits)
    except ArchiveError as err:
        raise SceneError(err.where, err.problems) from None
    if not (folder / SSD_NAME).is_file():
        raise SceneError(f"package {path}", [f"the package has no {SSD_NAME}"])
    return folder


def ssp_scene_data(folder: Path) -> tuple[dict[str, Any], list[str]]:
    """Scene data (as a scene file holds it) from an extracted package, and problems.

    Parameters
    ----------
    folder : Path
        The extracted package (see :func:`extract_ssp`).

    Returns
    -------
    data : dict
        Plain scene data, for :func:`~wire_fmu.master.scene.parse_scene`.
    problems : list of str
        Every problem found, each naming the element; empty if none.
    """
    folder = Path(folder)
    problems: list[str] = []
    root = _read_xml(folder / SSD_NAME, SSD_NAME, problems)
    if root is None:
        return {}, problems
    system = root.find(_q("ssd", "System"))
    if root.tag != _q("ssd", "SystemStructureDescription") or system is None:
        return {}, [f"{SSD_NAME} is not an SSP 1.0 system structure description"]
    meta = _scene_metadata(system, problems)
    skip = meta.get("signals") if meta else None
    units = _components(system, folder, problems)
    units.pop(skip, None)
    plain, bonds = _connections(system, units, skip, problems)
    data: dict[str, Any] = {
        "name": root.get("name") or system.get("name") or "ssp",
        "description": system.get("description", ""),
        "run": _run_settings(root, meta, problems),
        "units": units,
        "connections": plain,
        "bonds": bonds,
    }
    if meta is not None:
        data["name"] = meta.get("name", data["name"])
        _restore(data, meta, folder, problems)
    _wire_interface_models(data["bonds"], data["run"])
    return data, problems


def read_ssp(
    path: Path, *, extract_to: Path | None = None, limits: ArchiveLimits | None = None
) -> Scene:
    """The scene an SSP package describes.

    Parameters
    ----------
    path : Path
        The ``.ssp`` file.
    extract_to : Path, optional
        Where to extract it (see :func:`extract_ssp`).
    limits : ArchiveLimits, optional
        Bounds on the extracted size and member count (see :func:`extract_ssp`).

    Raises
    ------
    SceneError
        Listing every problem (unsupported SSP features included).
    """
    path = Path(path)
    folder = extract_ssp(path, extract_to, limits=limits)
    data, problems = ssp_scene_data(folder)
    if problems:
        raise SceneError(f"package {path}", problems)
    logger.info(
        "read %s: %d units, %d bonds, %d connections",
        path.name,
        len(data["units"]),
        len(data["bonds"]),
        len(data["connections"]),
    )
    return parse_scene(data, base_dir=folder, source=path)

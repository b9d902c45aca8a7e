"""Our FMUs by name, built on demand and rebuilt when the core has changed.

A scene names one of our units (``fmu = "BlockTrain"``) or gives a path to
any FMI 2.0 co-simulation FMU. Ours are built from the facade scripts in
``models/`` into a cache folder (default ``dist/fmus`` in the source tree);
an FMU whose recorded core fingerprint differs from the core imported here
is rebuilt, since the version guard would refuse it anyway.
"""

from __future__ import annotations

import logging
import zipfile
from pathlib import Path
from types import MappingProxyType

from wire_fmu._fingerprint import fingerprint, package_dir
from wire_fmu.export.guard import BUILD_INFO_FILE, BuildInfo
from wire_fmu.registry import BY_NAME, UNIT_TYPES

__all__ = ["OUR_FMUS", "ROOT", "DEFAULT_FMU_DIR", "resolve_fmu", "is_ours", "ensure_built"]

logger = logging.getLogger(__name__)

ROOT = package_dir().parent
DEFAULT_FMU_DIR = ROOT / "dist" / "fmus"
OUR_FMUS = MappingProxyType({u.name: u.facade for u in UNIT_TYPES})
"""Model name -> facade script in ``models/`` (from :mod:`wire_fmu.registry`)."""


def is_ours(fmu: str) -> bool:
    """Whether a scene's ``fmu`` names one of our units.

    Parameters
    ----------
    fmu : str
        A unit's ``fmu`` entry: a model name or a path.
    """
    return fmu in OUR_FMUS


def resolve_fmu(
    fmu: str, base_dir: Path, fmu_dir: Path = DEFAULT_FMU_DIR
) -> tuple[Path | None, str | None]:
    """The FMU file for a scene's ``fmu`` entry, building ours if needed.

    Parameters
    ----------
    fmu : str
        A unit's ``fmu`` entry: one of :data:`OUR_FMUS` or a path to a
        ``.fmu`` file.
    base_dir : Path
        Folder of the scene file; a relative path is found there.
    fmu_dir : Path
        Folder our FMUs are built into and reused from.

    Returns
    -------
    path : Path or None
        The FMU file; None if there is a problem.
    problem : str or None
        What is wrong with the entry; None if ``path`` is given.
    """
    if is_ours(fmu):
        script = BY_NAME[fmu].facade_path
        if not script.exists():
            return None, f"our FMU {fmu!r} has no facade script {script}"
        return ensure_built(fmu, script, fmu_dir), None
    path = Path(fmu)
    if not path.is_absolute():
        path = base_dir / path
    if path.suffix != ".fmu":
        known = ", ".join(OUR_FMUS)
        return None, f"{fmu!r} is neither one of our FMUs ({known}) nor a path to a .fmu file"
    if not path.exists():
        return None, f"FMU file {path} does not exist"
    if not path.is_file():  # a folder, a pipe or a device would hang or fail the reader
        return None, f"FMU file {path} is not a regular file"
    return path, None


def _recorded_fingerprint(path: Path) -> str | None:
    try:
        with zipfile.ZipFile(path) as archive:
            names = [n for n in archive.namelist() if n.endswith(BUILD_INFO_FILE)]
            if not names:
                return None
            data = archive.read(names[0]).decode("utf-8")
    except (OSError, zipfile.BadZipFile):
        return None
    import json

    return BuildInfo(
        **{k: str(v) for k, v in json.loads(data).items() if k in BuildInfo.__dataclass_fields__}
    ).fingerprint


def ensure_built(name: str, script: Path, fmu_dir: Path) -> Path:
    """Path of our FMU ``name``, (re)built from ``script`` if missing or stale.

    Parameters
    ----------
    name : str
        Model name, one of :data:`OUR_FMUS`.
    script : Path
        Its facade script.
    fmu_dir : Path
        Folder the FMU is built into (created if missing).

    Returns
    -------
    Path
        ``fmu_dir / "<name>.fmu"``, built with the core this process imported.
    """
    from wire_fmu.export.builder import build_fmu

    path = fmu_dir / f"{name}.fmu"
    current = fingerprint(package_dir())
    if path.exists() and _recorded_fingerprint(path) == current:
        return path
    logger.info("building %s.fmu from %s", name, script.name)
    fmu_dir.mkdir(parents=True, exist_ok=True)
    return build_fmu(script, fmu_dir)

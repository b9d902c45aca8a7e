"""Core-version guard: refuse to run on a ``wire_fmu`` other than the bundled one.

All pythonfmu FMUs in one process share one Python interpreter, so the
first ``wire_fmu`` package imported serves every FMU, whichever copy each
FMU bundles. The builder writes :data:`BUILD_INFO_FILE` into the FMU's
resources; at instantiation :func:`check_core` compares it with the
package actually imported.
"""

from __future__ import annotations

import functools
import json
import os
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import wire_fmu
from wire_fmu._fingerprint import fingerprint
from wire_fmu.core.errors import WireFmuError

__all__ = [
    "BUILD_INFO_FILE",
    "BuildInfo",
    "CoreVersionError",
    "check_core",
    "follow_bundled_copy",
    "imported_core",
]

BUILD_INFO_FILE = "wire_fmu_build.json"
"""Name of the build record in an FMU's ``resources`` folder."""


class CoreVersionError(WireFmuError, RuntimeError):
    """The ``wire_fmu`` imported in this process is not the one an FMU was built with."""


@dataclass(frozen=True)
class BuildInfo:
    """What an FMU was built from.

    Parameters
    ----------
    fmu : str
        Model name of the FMU.
    module : str
        Unique module name of the bundled facade script.
    version : str
        ``wire_fmu.__version__`` at build time.
    fingerprint : str
        :func:`wire_fmu._fingerprint.fingerprint` of the bundled package.
    """

    fmu: str
    module: str
    version: str
    fingerprint: str

    def write(self, path: Path) -> None:
        """Write as JSON to ``path``.

        Parameters
        ----------
        path : pathlib.Path
            File to write.
        """
        path.write_text(json.dumps(asdict(self), indent=2) + "\n", encoding="utf-8")

    @classmethod
    def read(cls, path: Path) -> BuildInfo:
        """Read a record written by :meth:`write`.

        Parameters
        ----------
        path : pathlib.Path
            A file written by :meth:`write`.
        """
        data = json.loads(path.read_text(encoding="utf-8"))
        return cls(**{k: str(data[k]) for k in ("fmu", "module", "version", "fingerprint")})


@functools.cache
def imported_core() -> tuple[str, str, Path]:
    """Version, fingerprint and directory of the ``wire_fmu`` imported here.

    Computed once, on the first call: inside an FMU that is the first
    instantiation, right after pythonfmu imported the package, while its
    files certainly exist. A master may delete them later (fmpy's
    ``simulate_fmu`` removes its extraction folder, whose
    ``resources/wire_fmu`` may be the copy this process imported), so the
    files are never read again.
    """
    root = Path(wire_fmu.__file__).resolve().parent
    return wire_fmu.__version__, fingerprint(root), root


def _mismatch_message(info: BuildInfo, instance: str, resources: Path) -> str:
    version, print_, root = imported_core()
    return (
        f"FMU {info.fmu!r} (instance {instance!r}) was built with wire_fmu {info.version} "
        f"(source fingerprint {info.fingerprint[:12]}, bundled in {resources / 'wire_fmu'}), "
        f"but this process already imported wire_fmu {version} (fingerprint {print_[:12]}) "
        f"from {root}. All pythonfmu FMUs in one process share one Python interpreter, "
        "so the first wire_fmu imported serves every FMU and this one would silently run "
        "on different physics. Rebuild all FMUs from the same wire_fmu source "
        "('python build_fmus.py') and restart the process, or run FMUs built from "
        "different wire_fmu sources in separate processes."
    )


def check_core(resources: str | Path, fmu: str, instance: str) -> None:
    """Check that the imported ``wire_fmu`` is the one bundled in ``resources``.

    Parameters
    ----------
    resources : str or Path
        The FMU's resources folder.
    fmu, instance : str
        Model and instance name, for the message.

    Raises
    ------
    CoreVersionError
        If the build record is missing or the version or fingerprint differ;
        the message names the FMU, both versions and paths, and what to do.
    """
    resources = Path(resources)
    record = resources / BUILD_INFO_FILE
    if not record.is_file():
        raise CoreVersionError(
            f"FMU {fmu!r} (instance {instance!r}): no {BUILD_INFO_FILE} in {resources}; "
            "the FMU was not built with wire_fmu.export.builder. Rebuild it with "
            "'python build_fmus.py'."
        )
    info = BuildInfo.read(record)
    version, print_, _ = imported_core()
    if (info.version, info.fingerprint) != (version, print_):
        raise CoreVersionError(_mismatch_message(info, instance, resources))


def follow_bundled_copy(resources: str | Path) -> None:
    """Let the ``wire_fmu`` imported here import what it has not yet from ``resources``'
    copy, where the folder it was imported from is gone.

    The first FMU's copy serves every later FMU (see the module docstring), but a master
    may delete that FMU's folder once it is done with it: fmpy's ``simulate_fmu`` removes
    its extraction folder, so a second FMU run in the same process could not import a
    module the first never did (``No module named 'wire_fmu.core.units.hydraulics'``).
    When ``resources`` holds the same ``wire_fmu`` (the version and fingerprint of
    :func:`check_core`), every imported package whose folder is gone is pointed at the
    same package in ``resources``; anything else is left for :func:`check_core` to refuse.
    The builder puts a call of this at the top of every FMU's facade script, before it
    imports its unit.

    Parameters
    ----------
    resources : str or Path
        The folder of the FMU being loaded (its facade script's folder).
    """
    resources = Path(resources)
    record = resources / BUILD_INFO_FILE
    if not record.is_file():
        return
    info = BuildInfo.read(record)
    version, print_, _ = imported_core()
    if (info.version, info.fingerprint) != (version, print_):
        return
    bundled = resources / "wire_fmu"
    for name, module in list(sys.modules.items()):
        if name != "wire_fmu" and not name.startswith("wire_fmu."):
            continue
        path = getattr(module, "__path__", None)
        if path is None or any(os.path.isdir(folder) for folder in path):
            continue
        module.__path__ = [str(bundled.joinpath(*name.split(".")[1:]))]

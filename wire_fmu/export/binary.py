"""Compile the FMU binary, ``native/fmi2_python.c``, for this platform's Python.

Every FMU we build carries this binary (not pythonfmu's prebuilt wrapper,
whose reference-counting faults corrupted the heap of the processes that
ran it; see the C file's header). It is compiled once per source, Python
version and platform with the system C compiler and cached next to the FMUs
that use it.

The binary is not linked against libpython: a Python host has the
interpreter loaded already; a C host preloads libpython (docs/interop.md).
"""

from __future__ import annotations

import hashlib
import importlib.util
import logging
import os
import platform
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.export.replaced_whole import replaced_whole

__all__ = ["BinaryError", "SOURCE", "platform_folder", "compiled_binary"]

logger = logging.getLogger(__name__)

SOURCE = Path(__file__).resolve().parent / "native" / "fmi2_python.c"
"""The C source of the FMU binary."""


class BinaryError(ConfigurationError):
    """The FMU binary cannot be compiled here (names what is missing)."""


def platform_folder() -> tuple[str, str]:
    """The FMI 2.0 ``binaries/`` folder and library suffix of this platform.

    Raises
    ------
    BinaryError
        On a platform we do not compile for.
    """
    bits = "64" if sys.maxsize > 2**32 else "32"
    if sys.platform.startswith("linux"):
        return f"linux{bits}", ".so"
    if sys.platform == "darwin":
        return f"darwin{bits}", ".dylib"
    raise BinaryError(
        "FMU binary",
        [f"building FMU binaries on {sys.platform} is not supported (Linux and macOS are)"],
    )


def _fmi_headers() -> Path:
    spec = importlib.util.find_spec("fmpy")  # the FMI 2.0 headers FMPy ships; fmpy not imported
    folder = Path(spec.origin).parent / "c-code" if spec and spec.origin else None
    if folder is None or not (folder / "fmi2Functions.h").is_file():
        raise BinaryError(
            "FMU binary", ["the FMI 2.0 headers were not found (FMPy installs them in fmpy/c-code)"]
        )
    return folder


def _compiler() -> list[str]:
    configured = (sysconfig.get_config_var("CC") or "").split()
    for candidate in (os.environ.get("CC", "").split(), configured, ["cc"], ["gcc"], ["clang"]):
        if candidate and shutil.which(candidate[0]):
            return candidate
    raise BinaryError(
        "FMU binary",
        ["no C compiler found (set CC, or install gcc: 'apt-get install gcc' on Debian)"],
    )


def _key(compiler: list[str]) -> str:
    parts = [
        SOURCE.read_bytes(),
        sys.version.encode(),
        platform.machine().encode(),
        " ".join(compiler).encode(),
    ]
    return hashlib.sha256(b"\0".join(parts)).hexdigest()[:16]


def _command(compiler: list[str], output: Path) -> list[str]:
    include = sysconfig.get_paths()["include"]
    flags = [
        "-O2",
        "-std=c11",
        "-Wall",
        "-Wextra",
        "-fPIC",
        "-fvisibility=default",
        f"-I{include}",
        f"-I{_fmi_headers()}",
    ]
    if sys.platform == "darwin":
        link = ["-dynamiclib", "-undefined", "dynamic_lookup"]
    else:
        link = ["-shared", "-pthread"]
    return [*compiler, *flags, *link, "-o", str(output), str(SOURCE)]


def compiled_binary(cache: Path) -> Path:
    """The FMU binary for this Python, compiled into ``cache`` if not there yet.

    Parameters
    ----------
    cache : Path
        Folder that keeps compiled binaries (created if missing).

    Returns
    -------
    Path
        The shared library.

    Raises
    ------
    BinaryError
        No compiler, no headers, or the compiler's own message.
    """
    _, suffix = platform_folder()
    compiler = _compiler()
    target = Path(cache) / f"wire_fmu_fmi2_{_key(compiler)}{suffix}"
    if target.is_file():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    with replaced_whole(target) as built:  # a concurrent build sees all of it or none
        run = subprocess.run(_command(compiler, built), capture_output=True, text=True, check=False)
        if run.returncode != 0:
            raise BinaryError(
                "FMU binary", [f"{compiler[0]} failed on {SOURCE.name}:\n{run.stderr.strip()}"]
            )
    logger.info("compiled the FMU binary %s", target.name)
    return target

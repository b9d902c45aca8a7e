"""Build an FMU from a facade script: bundle the core, build, finish the XML.

:func:`build_fmu` copies the facade script under a unique module name
(``wire_fmu_<stem>_<hash>``; pythonfmu imports every FMU's script as a
top-level module of one shared interpreter, PythonFMU issue #228), bundles
the ``wire_fmu`` package (without ``master/``, ``cli.py`` and caches) and a
build record for the core-version guard, builds with pythonfmu's
``FmuBuilder.build_FMU`` and rewrites ``modelDescription.xml`` with
:func:`~wire_fmu.export.model_description.patch_model_description`.
"""

from __future__ import annotations

import ast
import hashlib
import importlib.util
import inspect
import logging
import os
import re
import shutil
import sys
import tempfile
import zipfile
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from xml.etree import ElementTree

import pythonfmu
from pythonfmu import FmuBuilder

import wire_fmu
from wire_fmu._fingerprint import bundled_files, fingerprint, package_dir
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.unit import Unit
from wire_fmu.export.binary import compiled_binary, platform_folder
from wire_fmu.export.facade import CoreFacade
from wire_fmu.export.fmu_archive import FACADE_FILE, MODEL_DESCRIPTION, rewrite_zip
from wire_fmu.export.guard import BUILD_INFO_FILE, BuildInfo, imported_core
from wire_fmu.export.model_description import check_units, patch_model_description
from wire_fmu.export.replaced_whole import replaced_whole

__all__ = ["BuildError", "build_fmu", "find_facade_class", "unique_module_name"]

logger = logging.getLogger(__name__)


class BuildError(ConfigurationError):
    """A facade script cannot be built into an FMU (lists every problem)."""


FACADE_PREAMBLE = """\
# Put here by wire_fmu's builder. If this process imported wire_fmu from an FMU whose
# folder is gone since, import the rest of it from this FMU's identical copy
# (wire_fmu.export.guard.follow_bundled_copy); the first FMU in a process has nothing to do.
import os as _os
import sys as _sys

if "wire_fmu.export.guard" in _sys.modules:
    _sys.modules["wire_fmu.export.guard"].follow_bundled_copy(
        _os.path.dirname(_os.path.abspath(__file__))
    )

"""
"""Lines the builder puts before an FMU's facade script (see
:func:`~wire_fmu.export.guard.follow_bundled_copy`)."""


def _with_preamble(text: str) -> str:
    """The facade script ``text`` with :data:`FACADE_PREAMBLE` before its first statement
    after its docstring and ``from __future__`` imports (which must come first); a script
    Python cannot parse is left as it is, for its import to say why."""
    try:
        body = ast.parse(text).body
    except SyntaxError:
        return text
    first = next(
        (
            node
            for k, node in enumerate(body)
            if not (k == 0 and isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant))
            and not (isinstance(node, ast.ImportFrom) and node.module == "__future__")
        ),
        None,
    )
    lines = text.splitlines(keepends=True)
    at = len(lines) if first is None else first.lineno - 1
    return "".join(lines[:at]) + FACADE_PREAMBLE + "".join(lines[at:])


def unique_module_name(script: Path, core_fingerprint: str) -> str:
    """``wire_fmu_<stem>_<8 hex>``: the script's module name inside the FMU.

    The hash covers the script and the core fingerprint, so FMUs built from
    different sources never share a module name in one interpreter.

    Parameters
    ----------
    script : pathlib.Path
        The facade script.
    core_fingerprint : str
        Fingerprint of the bundled ``wire_fmu`` package.
    """
    stem = re.sub(r"\W", "_", script.stem).lower()
    digest = hashlib.sha256(script.read_bytes() + core_fingerprint.encode()).hexdigest()
    return f"wire_fmu_{stem}_{digest[:8]}"


@contextmanager
def _on_sys_path(directory: Path) -> Iterator[None]:
    entry = str(directory)
    sys.path.insert(0, entry)
    try:
        yield
    finally:
        while entry in sys.path:
            sys.path.remove(entry)


def _import_script(path: Path, module_name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(module_name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[module_name]
        raise
    return module


def find_facade_class(module: ModuleType, script: Path) -> type[CoreFacade]:
    """The one concrete :class:`CoreFacade` subclass in ``module``'s namespace.

    pythonfmu's builder and its C++ loader both pick the most derived slave
    class in the script's namespace, so exactly one facade class must be
    visible there (defined or imported).

    Parameters
    ----------
    module : types.ModuleType
        The facade script, imported.
    script : pathlib.Path
        Its path, for the messages.

    Raises
    ------
    BuildError
        Naming ``script`` and the classes found, if there is not exactly one.
    """
    found = sorted(
        {
            obj
            for obj in vars(module).values()
            if inspect.isclass(obj)
            and issubclass(obj, CoreFacade)
            and obj is not CoreFacade
            and not inspect.isabstract(obj)
        },
        key=lambda c: c.__qualname__,
    )
    if len(found) != 1:
        names = [c.__qualname__ for c in found] or "none"
        raise BuildError(
            str(script),
            [f"a facade script must contain exactly one CoreFacade subclass; found {names}"],
        )
    return found[0]


def _unit_problems(facade: type[CoreFacade]) -> list[str]:
    unit_class = facade.unit_class
    if not (isinstance(unit_class, type) and issubclass(unit_class, Unit)):
        return [f"{facade.__qualname__}.unit_class must be a Unit subclass, got {unit_class!r}"]
    problems = unit_class.check_declarations() + check_units(unit_class)
    if not unit_class.NAME.isidentifier():
        problems.append(f"{unit_class.__qualname__}.NAME {unit_class.NAME!r} must be an identifier")
    return problems


def _bundle_core(destination: Path) -> str:
    """Copy the bundled ``wire_fmu`` files to ``destination``; return their fingerprint."""
    root = package_dir()
    for relative in bundled_files(root):
        target = destination / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(root / relative, target)
    return fingerprint(destination)


@dataclass(frozen=True)
class _Staging:
    """What :func:`_stage` wrote into the build folder."""

    script: Path  # the facade script under its unique module name
    core: Path  # the bundled wire_fmu package
    core_print: str  # its fingerprint
    extras: tuple[Path, ...]  # extra modules, beside the script

    def project_files(self, build_info: Path) -> list[Path]:
        """What pythonfmu copies into the FMU's resources.

        Parameters
        ----------
        build_info : pathlib.Path
            The build record written for the FMU (:class:`~wire_fmu.export.guard.BuildInfo`).
        """
        return [self.core, build_info, *self.extras]


def _stage(script: Path, folder: Path, extra_modules: Sequence[Path]) -> _Staging:
    """Write the renamed script, the core bundle and the extra modules."""
    core = folder / "bundle" / "wire_fmu"
    core_print = _bundle_core(core)
    staged = folder / "script" / f"{unique_module_name(script, core_print)}.py"
    staged.parent.mkdir()
    staged.write_text(_with_preamble(script.read_text(encoding="utf-8")), encoding="utf-8")
    extras = tuple(staged.parent / extra.name for extra in extra_modules)
    for source, target in zip(extra_modules, extras, strict=True):
        shutil.copy2(source, target)
    return _Staging(staged, core, core_print, extras)


def _write_build_info(staging: _Staging, facade: type[CoreFacade]) -> Path:
    info = BuildInfo(
        fmu=facade.unit_class.NAME,
        module=staging.script.stem,
        version=wire_fmu.__version__,
        fingerprint=staging.core_print,
    )
    path = staging.core.parent / BUILD_INFO_FILE
    info.write(path)
    return path


def _finish(fmu: Path, facade: type[CoreFacade], module: str) -> None:
    """Our model description, our binary in place of pythonfmu's, the facade file."""
    with zipfile.ZipFile(fmu) as archive:
        xml = archive.read(MODEL_DESCRIPTION)
    tool = f"wire_fmu {wire_fmu.__version__} (PythonFMU {pythonfmu.__version__} exporter)"
    patched = patch_model_description(xml, facade.unit_class, tool)
    root = ElementTree.fromstring(patched)
    identifier = root.find("CoSimulation").get("modelIdentifier")
    folder, suffix = platform_folder()
    binary = compiled_binary(native_cache()).read_bytes()
    facade_file = f"{module}\n{facade.__name__}\n{root.get('guid')}\n"
    rewrite_zip(
        fmu,
        drop=lambda name: name.startswith("binaries/") or name == "resources/slavemodule.txt",
        add={
            MODEL_DESCRIPTION: patched,
            f"binaries/{folder}/{identifier}{suffix}": binary,
            FACADE_FILE: facade_file.encode(),
        },
    )


def native_cache() -> Path:
    """Where compiled FMU binaries are kept (``$XDG_CACHE_HOME/wire_fmu/native``)."""
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "wire_fmu" / "native"


def _check_sources_unchanged(script: Path, staging: _Staging) -> None:
    _, loaded, root = imported_core()
    if staging.core_print != loaded:
        raise BuildError(
            str(script),
            [
                f"the wire_fmu sources in {root} changed after this process loaded them "
                f"(fingerprint {loaded[:12]} then, {staging.core_print[:12]} now), so the FMU "
                "would bundle code this process is not running; build again in a fresh process"
            ],
        )


def _load_facade(script: Path, staged: Path) -> type[CoreFacade]:
    with _on_sys_path(staged.parent):
        try:
            module = _import_script(staged, staged.stem)
        except Exception as exc:
            raise BuildError(str(script), [f"importing the script failed: {exc!r}"]) from exc
    facade = find_facade_class(module, script)
    problems = _unit_problems(facade)
    if problems:
        raise BuildError(str(script), problems)
    return facade


def build_fmu(facade_script: Path, out_dir: Path, *, extra_modules: Iterable[Path] = ()) -> Path:
    """Build ``facade_script`` into ``out_dir/<unit NAME>.fmu``.

    Parameters
    ----------
    facade_script : Path
        Python file with exactly one :class:`CoreFacade` subclass.
    out_dir : Path
        Output folder (created if missing); an existing FMU is replaced.
    extra_modules : iterable of Path, optional
        Further top-level Python modules the script imports (bundled beside
        it; give them names no other FMU uses).

    Returns
    -------
    Path
        The FMU file.

    Raises
    ------
    BuildError
        Naming the script and every problem found (no or several facade
        classes, unsound declarations, unknown units, import failure).
    """
    script = Path(facade_script).resolve()
    if script.suffix != ".py" or not script.is_file():
        raise BuildError(str(script), ["not an existing .py file"])
    extras = [Path(p).resolve() for p in extra_modules]
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="wire_fmu_build_") as tmp:
        staging = _stage(script, Path(tmp), extras)
        _check_sources_unchanged(script, staging)
        try:
            facade = _load_facade(script, staging.script)
            files = staging.project_files(_write_build_info(staging, facade))
            target = out_dir / f"{facade.unit_class.NAME}.fmu"
            # a process loading the FMU while another builds it reads the old one or the new one
            with replaced_whole(target) as partial:
                FmuBuilder.build_FMU(staging.script, dest=partial, project_files=files)
                _finish(partial, facade, staging.script.stem)
        finally:
            module_dir = str(staging.script.parent)
            sys.modules.pop(staging.script.stem, None)
            while module_dir in sys.path:  # pythonfmu inserts it for good
                sys.path.remove(module_dir)
    logger.debug("built %s from %s (module %s)", target, script, staging.script.stem)
    return target

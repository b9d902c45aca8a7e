"""Compiled physics kernels: which kernel runs, the ``jit`` decorator and its disk cache.

A unit's inner loop (stages, guards, event location, Jacobian, linear solves)
runs in functions compiled by numba when it is installed; the readable numpy
implementation of the same physics stays the reference. The environment
variable ``WIRE_FMU_KERNEL`` chooses:

``compiled`` (default)
    numba kernels where a unit has them; the Python kernel where numba is
    missing (one log line per unit built says so).
``python``
    the Python kernel everywhere.

Compiled code is cached on disk so that compiling is paid once per machine:
by content (the kernel's own source, the shared loop every entry point
inlines, :data:`SHARED_KERNEL_SOURCES`, and every ``wire_fmu`` module they
import, followed through their imports), not by file path, in ``WIRE_FMU_CACHE_DIR`` (default
``~/.cache/wire_fmu/numba``). Every copy of the ``wire_fmu`` sources with the
same text shares one cache, so FMUs extracted to new temporary folders and FMUs
loaded by a C++ host start warm. The cache locator is registered with numba
when this module is imported, before any kernel is decorated.
"""

from __future__ import annotations

import hashlib
import logging
import os
import re
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

from wire_fmu.core.errors import ConfigurationError

__all__ = [
    "KERNEL_ENV",
    "CACHE_ENV",
    "KernelChoiceError",
    "KernelDecorators",
    "cache_directory",
    "cache_folder_name",
    "cache_problem",
    "jit",
    "jit_inline",
    "kernel_choice",
    "kernel_decorators",
    "source_digest",
    "numba_available",
    "use_compiled",
]

logger = logging.getLogger(__name__)

KERNEL_ENV = "WIRE_FMU_KERNEL"
"""Environment variable choosing the kernel: ``compiled`` or ``python``."""
CACHE_ENV = "WIRE_FMU_CACHE_DIR"
"""Environment variable naming the folder of the compiled-code cache."""
_CHOICES = ("compiled", "python")

try:  # numba is a declared dependency; without it every unit runs its Python kernel
    import numba
    from numba.core import caching as _numba_caching
except ImportError:  # pragma: no cover - exercised on machines without numba
    numba = None
    _numba_caching = None


class KernelChoiceError(ConfigurationError):
    """``WIRE_FMU_KERNEL`` holds something other than ``compiled`` or ``python``."""


def numba_available() -> bool:
    """Whether numba can be imported in this interpreter."""
    return numba is not None


def kernel_choice() -> str:
    """The kernel ``WIRE_FMU_KERNEL`` asks for: ``"compiled"`` (default) or ``"python"``.

    Raises
    ------
    KernelChoiceError
        If the variable holds anything else, naming the variable and the choices.
    """
    value = os.environ.get(KERNEL_ENV, "compiled").strip().lower() or "compiled"
    if value not in _CHOICES:
        raise KernelChoiceError(
            f"environment variable {KERNEL_ENV}",
            [
                f"{KERNEL_ENV}={os.environ[KERNEL_ENV]!r} is not a kernel: expected one of "
                f"{', '.join(_CHOICES)}"
            ],
        )
    return value


def use_compiled(unit: str) -> bool:
    """Whether ``unit`` should run compiled kernels now; logs once when it cannot, or when
    their compiled code cannot be cached (:func:`cache_problem`).

    Parameters
    ----------
    unit : str
        The unit being built, for the log line (e.g. ``"block train"``).
    """
    if kernel_choice() == "python":
        return False
    if numba is None:
        logger.info("%s: numba is not installed; running the Python kernel", unit)
        return False
    problem = cache_problem()
    if problem:
        logger.warning(
            "%s: %s; compiled kernels are cached where numba chooses, for an FMU extracted to "
            "a temporary folder inside it, so they are compiled afresh every run",
            unit,
            problem,
        )
    return True


def cache_directory() -> Path:
    """The folder compiled kernels are cached in (``WIRE_FMU_CACHE_DIR`` or the user cache).

    A ``~`` in the variable is the user's home (as a shell would not expand it inside
    quotes); a relative path is taken from the working folder, made absolute here, so
    that a host changing its working folder later (to load a binary) keeps the cache.
    """
    explicit = os.environ.get(CACHE_ENV)
    if explicit:
        return Path(explicit).expanduser().absolute()
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "wire_fmu" / "numba"


def cache_problem() -> str | None:
    """Why compiled kernels cannot be cached in :func:`cache_directory`, or None.

    The folder is made if missing and must take a new file. numba itself would
    go on silently with another place (the source's ``__pycache__``, which for an
    extracted FMU is a new temporary folder each run), so the units say it.
    """
    folder = cache_directory()
    named = f"{CACHE_ENV}={folder}" if os.environ.get(CACHE_ENV) else f"the cache folder {folder}"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        return f"{named} cannot be written ({exc.strerror or exc})"
    return None


def _package_relative(py_file: str) -> str | None:
    """``wire_fmu/...`` part of a source path inside some copy of the package, or None."""
    parts = Path(py_file).resolve().parts
    if "wire_fmu" not in parts:
        return None
    start = len(parts) - 1 - parts[::-1].index("wire_fmu")
    return "/".join(parts[start:])


SHARED_KERNEL_SOURCES = ("core/framework/compiled.py", "core/framework/compiled_step.py")
"""Sources (relative to the package) that every unit's entry point inlines: part of every key."""


def _package_root(py_file: str) -> Path | None:
    """The folder holding the copy of ``wire_fmu`` that ``py_file`` belongs to, or None."""
    parts = Path(py_file).resolve().parts
    if "wire_fmu" not in parts:
        return None
    return Path(*parts[: len(parts) - 1 - parts[::-1].index("wire_fmu")])


_IMPORT = re.compile(r"^from (wire_fmu(?:\.\w+)+) import", re.MULTILINE)


def _kernel_sources(py_file: str) -> list[Path]:
    """``py_file``, the :data:`SHARED_KERNEL_SOURCES` and every ``wire_fmu`` module it imports.

    Followed through imports, so that a kernel whose compiled helpers or constants
    live in another module is compiled afresh when that module changes (numba's
    own cache only looks at the file the function is in). Modules missing from
    this copy of the package are skipped.
    """
    root = _package_root(py_file)
    first = Path(py_file).resolve()
    if root is None:
        return [first]
    shared = [root / "wire_fmu" / name for name in SHARED_KERNEL_SOURCES]
    sources = [first, *(path for path in shared if path.is_file())]
    pending = list(sources)
    while pending:
        text = pending.pop().read_text(encoding="utf-8")
        for module in _IMPORT.findall(text):
            path = root.joinpath(*module.split(".")).with_suffix(".py")
            if path.is_file() and path not in sources:
                sources.append(path)
                pending.append(path)
    return sources


def source_digest(py_file: str) -> str:
    """The key of ``py_file``'s compiled code in the cache: a digest of its package-relative
    path and of the text of :func:`_kernel_sources` (hex, 16 characters).

    Parameters
    ----------
    py_file : str
        A kernel module's source file.
    """
    relative = _package_relative(py_file) or Path(py_file).name
    digest = hashlib.sha256(relative.encode())
    for source in _kernel_sources(py_file):
        digest.update(b"\0" + source.read_bytes())
    return digest.hexdigest()[:16]


def cache_folder_name(py_file: str, digest: str) -> str:
    """The name of the folder that holds the compiled code of the kernel module ``py_file``
    with the cache key ``digest`` (:func:`source_digest`): its package-relative path with
    ``_`` for ``/``, then the key (``wire_fmu_core_units_winch_kernel-<16 hex digits>``).

    Parameters
    ----------
    py_file : str
        A kernel module's source file.
    digest : str
        Its cache key.
    """
    relative = _package_relative(py_file) or Path(py_file).name
    return f"{relative.replace('/', '_').removesuffix('.py')}-{digest}"


_DIGEST_ATTRIBUTE = "_wire_fmu_source_digest"
"""The attribute of a kernel function that carries ``(its file, source_digest(file))``."""


if _numba_caching is not None:

    class _ContentCacheLocator(
        _numba_caching._SourceFileBackedLocatorMixin, _numba_caching._CacheLocator
    ):
        """Cache a ``wire_fmu`` kernel by its package-relative path and source text.

        numba's own locators key the cache on the file's folder, so every
        temporary extraction of an FMU would compile afresh.
        """

        def __init__(self, py_func: Callable[..., Any], py_file: str) -> None:
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            kept = getattr(py_func, _DIGEST_ATTRIBUTE, None)  # (file, digest) of its module's
            digest = kept[1] if kept is not None and kept[0] == py_file else source_digest(py_file)
            self._cache_path = str(cache_directory() / cache_folder_name(py_file, digest))

        def get_cache_path(self) -> str:
            return self._cache_path

        @classmethod
        def from_function(cls, py_func: Callable[..., Any], py_file: str):
            if _package_relative(py_file) is None or not os.path.exists(py_file):
                return None
            return super().from_function(py_func, py_file)

    _locators = _numba_caching.CacheImpl._locator_classes
    if not any(c.__name__ == _ContentCacheLocator.__name__ for c in _locators):
        _locators.insert(0, _ContentCacheLocator)


class KernelDecorators(NamedTuple):
    """:func:`jit` and :func:`jit_inline` for one kernel module (:func:`kernel_decorators`)."""

    jit: Callable[[Callable[..., Any]], Callable[..., Any]]
    jit_inline: Callable[[Callable[..., Any]], Callable[..., Any]]


def kernel_decorators(py_file: str) -> KernelDecorators:
    """:func:`jit` and :func:`jit_inline` for the functions of the kernel module ``py_file``,
    its cache key (:func:`source_digest`) computed once for all of them.

    The key follows the module's imports through the package's sources; computed for
    every function anew, that was a tenth of a second of every start. A kernel module
    takes its decorators with ``jit, jit_inline = kernel_decorators(__file__)``.

    Parameters
    ----------
    py_file : str
        The kernel module's source file (its ``__file__``).
    """
    if numba is None or _package_relative(py_file) is None or not os.path.exists(py_file):
        return KernelDecorators(jit, jit_inline)
    kept = (py_file, source_digest(py_file))

    def keyed(decorate: Callable[[Callable[..., Any]], Callable[..., Any]]):
        def decorator(function: Callable[..., Any]) -> Callable[..., Any]:
            setattr(function, _DIGEST_ATTRIBUTE, kept)
            return decorate(function)

        decorator.__doc__ = decorate.__doc__
        return decorator

    return KernelDecorators(keyed(jit), keyed(jit_inline))


def jit(function: Callable[..., Any]) -> Callable[..., Any]:
    """Compile ``function`` with numba (nopython, cached, IEEE arithmetic) when it is installed.

    Without numba the plain function is returned; the units then never call
    it on their hot path (:func:`use_compiled` is False).

    Parameters
    ----------
    function : callable
        A function over numbers and numpy arrays in numba's supported subset.
    """
    if numba is None:
        return function
    return numba.njit(cache=True, error_model="numpy")(function)


def jit_inline(function: Callable[..., Any]) -> Callable[..., Any]:
    """:func:`jit`, inlined into its callers at numba's IR level.

    For the generic loops that take a unit's kernel functions as arguments: once
    inlined into the unit's entry point, the kernel functions are called there as
    globals, which keeps the entry point cacheable (a function passed on as a value
    would be a process address, which numba refuses to cache).

    Parameters
    ----------
    function : callable
        A function over numbers, numpy arrays and compiled functions.
    """
    if numba is None:
        return function
    return numba.njit(cache=True, error_model="numpy", inline="always")(function)

"""Build every facade script in ``models/`` into a validated FMU.

Usage::

    python build_fmus.py [--out DIR] [--models DIR]

Each ``models/*.py`` whose name does not start with ``_`` is one facade
script (see :mod:`wire_fmu.export.facade`). Every FMU is checked with
``fmpy.validation.validate_fmu``. The exit status is non-zero if any script
fails; the log names the script and every problem.
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from wire_fmu.core.errors import WireFmuError
from wire_fmu.export.builder import BuildError, build_fmu
from wire_fmu.registry import MODELS_DIR, UNIT_TYPES

ROOT = Path(__file__).resolve().parent
logger = logging.getLogger("build_fmus")


def facade_scripts(models: Path) -> list[Path]:
    """Facade scripts in ``models``: ``*.py`` not starting with ``_``, sorted."""
    return sorted(p for p in models.glob("*.py") if not p.name.startswith("_"))


def unregistered(scripts: Sequence[Path]) -> list[str]:
    """Scripts in our ``models/`` that :mod:`wire_fmu.registry` does not list (one message each)."""
    registered = {u.facade_path.resolve() for u in UNIT_TYPES}
    return [
        f"{p}: not in wire_fmu.registry.UNIT_TYPES; add its line there"
        for p in scripts
        if p.resolve().parent == MODELS_DIR.resolve() and p.resolve() not in registered
    ]


def build_one(script: Path, out: Path, built: dict[Path, Path]) -> Path:
    """Build and validate one FMU; ``built`` maps FMU paths to their scripts."""
    from fmpy.validation import validate_fmu  # the build tool may use fmpy; FMUs may not

    start = time.perf_counter()
    fmu = build_fmu(script, out)
    if fmu in built:
        raise BuildError(str(script), [f"{fmu.name} was already built from {built[fmu]}"])
    built[fmu] = script
    problems = validate_fmu(str(fmu))
    if problems:
        raise BuildError(str(script), [f"fmpy validation of {fmu.name}: {p}" for p in problems])
    logger.info("built %-28s from %s in %.2f s", fmu.name, script.name, time.perf_counter() - start)
    return fmu


def build_all(scripts: Sequence[Path], out: Path) -> list[str]:
    """Build ``scripts`` into ``out``; return one message per failed script."""
    failures: list[str] = []
    built: dict[Path, Path] = {}
    for script in scripts:
        try:
            build_one(script, out, built)
        except WireFmuError as exc:
            failures.append(str(exc))
            logger.error("%s", exc)
        except Exception as exc:  # unexpected: keep the traceback
            failures.append(f"{script}: {exc!r}")
            logger.exception("%s: unexpected failure", script)
    return failures


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    """Command-line options."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "dist" / "fmus", help="output folder")
    parser.add_argument(
        "--models",
        type=Path,
        default=MODELS_DIR,
        help="facade scripts (default: ours, each listed in wire_fmu.registry)",
    )
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    """Build all FMUs; return the process exit status."""
    args = parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(message)s")
    scripts = facade_scripts(args.models)
    problems = unregistered(scripts)
    if problems:
        for problem in problems:
            logger.error("%s", problem)
        return 1
    if not scripts:
        logger.warning("no facade scripts in %s; nothing to build", args.models)
        return 0
    start = time.perf_counter()
    failures = build_all(scripts, args.out)
    elapsed = time.perf_counter() - start
    if failures:
        logger.error("%d of %d FMUs failed (%.1f s)", len(failures), len(scripts), elapsed)
        return 1
    logger.info("%d FMUs in %s (%.1f s)", len(scripts), args.out, elapsed)
    return 0


if __name__ == "__main__":
    sys.exit(main())

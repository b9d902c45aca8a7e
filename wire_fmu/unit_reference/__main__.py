"""``python -m wire_fmu.unit_reference``: write docs/units.md from the units' declarations.

::

    python -m wire_fmu.unit_reference            write docs/units.md
    python -m wire_fmu.unit_reference --check    exit 1 if docs/units.md is not current
    python -m wire_fmu.unit_reference -o FILE    write FILE instead
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence
from pathlib import Path

from wire_fmu.unit_reference.markdown import units_markdown

DOCS_PATH = Path(__file__).resolve().parents[2] / "docs" / "units.md"
"""The checked-in reference, in the source tree."""

logger = logging.getLogger("wire_fmu.unit_reference")


def main(argv: Sequence[str] | None = None) -> int:
    """Write (or check) the unit reference.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments; None reads the command line.

    Returns
    -------
    int
        0 when written or current, 1 when ``--check`` finds it out of date.
    """
    parser = argparse.ArgumentParser(prog="python -m wire_fmu.unit_reference")
    parser.add_argument("-o", "--output", type=Path, default=DOCS_PATH, help="file to write")
    parser.add_argument("--check", action="store_true", help="only compare, exit 1 if stale")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    text = units_markdown()
    current = args.output.read_text(encoding="utf-8") if args.output.is_file() else None
    if args.check:
        if current == text:
            logger.info("%s is current", args.output)
            return 0
        logger.error("%s is not current: run python -m wire_fmu.unit_reference", args.output)
        return 1
    args.output.write_text(text, encoding="utf-8")
    logger.info("written: %s", args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())

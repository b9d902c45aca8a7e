"""The command-line options the scene benchmarks share: which scenes, how many runs, where
the table goes (:mod:`~wire_fmu.bench.master`, :mod:`~wire_fmu.bench.scenes`,
:mod:`~wire_fmu.bench.libcosim`)."""

from __future__ import annotations

import argparse
import logging
from collections.abc import Sequence
from pathlib import Path

__all__ = [
    "add_counting_window",
    "counting_window_problems",
    "parse_scene_options",
    "report_table",
    "scene_parser",
]

logger = logging.getLogger(__name__)


def scene_parser(
    description: str, scenes: Sequence[str], repeats_help: str | None
) -> argparse.ArgumentParser:
    """A parser with ``--repeats N`` (unless ``repeats_help`` is None), ``--scenes NAME ...``
    and ``--out FILE``.

    Parameters
    ----------
    description : str
        What the command does (its help's first line).
    scenes : sequence of str
        The scenes it can run, in the order it runs them by default.
    repeats_help : str or None
        What ``--repeats`` counts (default 3); None: a command that runs each scene once
        has no ``--repeats``.

    Returns
    -------
    argparse.ArgumentParser
        For the command to add its own options to.
    """
    parser = argparse.ArgumentParser(description=description)
    if repeats_help is not None:
        parser.add_argument("--repeats", type=int, default=3, help=repeats_help)
    parser.add_argument(
        "--scenes",
        nargs="+",
        choices=list(scenes),
        default=list(scenes),
        metavar="NAME",
        help=f"scenes to run (default: all of {', '.join(scenes)})",
    )
    parser.add_argument("--out", type=Path, help="also write the table (Markdown) here")
    return parser


def parse_scene_options(
    parser: argparse.ArgumentParser, argv: list[str] | None
) -> argparse.Namespace:
    """The options, ``--repeats`` (where there is one) checked (an argparse error below 1);
    logging set up.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        From :func:`scene_parser`.
    argv : list of str or None
        The arguments; None reads the command line.
    """
    args = parser.parse_args(argv)
    if getattr(args, "repeats", 1) < 1:
        parser.error(f"--repeats must be at least 1, got {args.repeats}")
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    return args


def add_counting_window(parser: argparse.ArgumentParser, warm_up: float) -> None:
    """Add ``--stop-time S`` (default 1 s) and ``--warm-up F`` (a fraction of the run) to
    the parser of a benchmark that counts (bytecodes, instructions) over a shortened run.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        From :func:`scene_parser`.
    warm_up : float
        The default fraction of the run before counting starts.
    """
    parser.add_argument(
        "--stop-time", type=float, default=1.0, help="simulated time per scene, s (default 1)"
    )
    parser.add_argument(
        "--warm-up",
        type=float,
        default=warm_up,
        help=f"fraction of the run before counting starts (default {warm_up:g})",
    )


def counting_window_problems(args: argparse.Namespace) -> list[str]:
    """What is wrong with the options of :func:`add_counting_window` (nothing: an empty list).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options.
    """
    problems = []
    if not args.stop_time > 0.0:
        problems.append(f"--stop-time must be positive, got {args.stop_time}")
    if not 0.0 <= args.warm_up < 1.0:
        problems.append(f"--warm-up must be at least 0 and below 1, got {args.warm_up}")
    return problems


def report_table(text: str, out: Path | None) -> None:
    """Log the Markdown table ``text``; write it to ``out`` too when given.

    Parameters
    ----------
    text : str
        The table.
    out : Path or None
        The file ``--out`` named.
    """
    logger.info("\n%s", text)
    if out:
        out.write_text(text + "\n")

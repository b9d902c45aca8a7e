"""The wire-fmu command: run, check, draw, study and export co-simulation scenes.

::

    wire-fmu scenes                 list the shipped scenes
    wire-fmu info UNIT [--effects E1 E2 ...] [--markdown]
                                    a unit type's parameters, effects, ports and variables
    wire-fmu check SCENE            validate a scene; list every problem, exit 1 if any
    wire-fmu run SCENE [-o DIR]     run it: progress bar, summary table, CSV, plots, report
    wire-fmu run SCENE --monolithic [--rtol RTOL]
                                    the same units as one ODE (the accuracy reference)
    wire-fmu draw SCENE [-o DIR]    render each block train's reeving to a PNG
    wire-fmu report RESULTS_DIR [-o FILE]
                                    a run's results as one HTML page (run writes it too)
    wire-fmu build [-o DIR]         build our FMUs
    wire-fmu cache [--prune]        what the compiled-code cache holds; prune other versions'
    wire-fmu study accuracy SCENE [--quick] [-o DIR]
                                    work-precision study: error against cost per configuration
    wire-fmu study effects SCENE [--quick] [-o DIR]
                                    what leaving each effect out saves and changes
    wire-fmu sweep SCENE SWEEP_SPEC [-o DIR] [--workers N] [--scheduler ADDRESS]
                                    run a parameter sweep on Dask (docs/sweeps.md)
    wire-fmu export SCENE --format ssp|osp [-o DIR]
                                    write an SSP package or an OSP configuration

SCENE is a shipped scene's name or a path to a scene file; check, run and
export also take an SSP package (.ssp).

Exit status: 0 done (a run finished); 1 a problem (every one is listed), or a
run that ended ``stopped`` or ``failed``; 130 interrupted by Ctrl-C; 141 the
reader of the output went away (``wire-fmu scenes | head -1``). No command
prints a traceback unless ``--verbose`` is given.
"""

from __future__ import annotations

import argparse
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Sequence
from pathlib import Path

from wire_fmu.cli_cache import add_cache_parser
from wire_fmu.cli_commands import (
    EXIT_BROKEN_PIPE,
    EXIT_INTERRUPTED,
    _print,
    cmd_build,
    cmd_check,
    cmd_draw,
    cmd_export,
    cmd_report,
    cmd_run,
    cmd_scenes,
    cmd_study,
    cmd_sweep,
)
from wire_fmu.core.errors import WireFmuError
from wire_fmu.unit_reference.command import add_info_parser

__all__ = ["main"]

logger = logging.getLogger("wire_fmu")


def _whole_number(minimum: int, expected: str) -> Callable[[str], int]:
    """A parser of a whole number ``>= minimum`` from the command line, saying ``expected``
    when the text is not one (argparse names the option)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{expected}, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"{expected}, got {value}")
        return value

    return parse


_positive_int = _whole_number(1, "expected a whole number >= 1")
_worker_count = _whole_number(  # worker processes of a sweep's local cluster: 0 runs serially
    0, "expected a whole number >= 1, or 0 to run the cases serially in this process"
)


def _scheduler_address(text: str) -> str:
    """A Dask scheduler's address from the command line, checked for its form."""
    from wire_fmu.sweep.cluster import scheduler_problem

    problem = scheduler_problem(text)
    if problem:
        raise argparse.ArgumentTypeError(problem)
    return text


def _positive_float(text: str) -> float:
    """A finite number > 0 from the command line."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a number of seconds > 0, got {text!r}"
        ) from None
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"expected a number of seconds > 0, got {text}")
    return value


def _coupling_list(text: str) -> tuple[str, ...]:
    """Couplings of the accuracy study from the command line (see ``parse_couplings``)."""
    from wire_fmu.study.plan import parse_couplings

    try:
        return parse_couplings(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _positive_float_number(text: str) -> float:
    """A finite number > 0 from the command line (no unit)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text!r}") from None
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"expected a number > 0, got {text}")
    return value


def _refuse_conflicts(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Options that contradict each other end the command as a usage error (exit 2)."""
    if args.command != "run":
        return
    if args.monolithic and args.step is not None:
        parser.error(
            "--step sets the co-simulation's macro step; a --monolithic run has none: its "
            "solver chooses its own steps to --rtol, and it records at the scene's "
            "output_interval (else at its step): leave --step out"
        )
    if args.rtol is not None and not args.monolithic:
        parser.error(
            "--rtol is the tolerance of a --monolithic run; a co-simulated run's units take "
            "their solver settings from the scene"
        )


def _study_parser(sub) -> None:
    p = sub.add_parser("study", help="what accuracy and effects cost in time")
    kinds = p.add_subparsers(dest="study", required=True)
    for name, text in (
        ("accuracy", "work-precision study over couplings, steps and solvers"),
        ("effects", "time saved and output change of leaving each effect out"),
    ):
        q = kinds.add_parser(name, help=text)
        q.add_argument("scene", help="a shipped scene's name or a scene file")
        q.add_argument(
            "-o", "--output", type=Path, help=f"output folder (default results/SCENE/{name})"
        )
        q.add_argument(
            "--quick", action="store_true", help="a few configurations, short stop time (for CI)"
        )
        q.add_argument(
            "--repeats",
            type=_positive_int,
            default=None,
            help="runs per configuration, the fastest counts",
        )
        q.add_argument(
            "--stop-time",
            type=_positive_float,
            default=None,
            help="simulated seconds per run (default: [study] stop_time, else the "
            "scene's, at most 10 s; with --quick the end of [study] quick_window, else 1 s)",
        )
        if name == "accuracy":
            q.add_argument(
                "--grid",
                choices=("slices", "product"),
                default=None,
                help="slices (default): every coupling with the scene's solvers and "
                "every solver with the scene's coupling; product: all of them",
            )
            q.add_argument(
                "--couplings",
                type=_coupling_list,
                default=None,
                metavar="LIST",
                help="couplings to compare besides the scene's own, joined by commas, or "
                "all (default: held, interface, ramped, interface+ramped, synchronised, "
                "interface+synchronised); those the scene's bonds cannot take are left out",
            )
        q.set_defaults(func=cmd_study)


def _parser() -> argparse.ArgumentParser:
    from wire_fmu.master.catalog import DEFAULT_FMU_DIR

    parser = argparse.ArgumentParser(prog="wire-fmu", description=__doc__.splitlines()[0])
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    parser.add_argument(
        "--fmu-dir",
        type=Path,
        default=DEFAULT_FMU_DIR,
        help="where our FMUs are built and cached (default: %(default)s)",
    )
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("scenes", help="list the shipped scenes").set_defaults(func=cmd_scenes)
    for name, func, text in (
        ("check", cmd_check, "validate a scene"),
        ("run", cmd_run, "run a scene"),
        ("draw", cmd_draw, "draw a scene's reevings"),
    ):
        p = sub.add_parser(name, help=text)
        p.add_argument("scene", help="a shipped scene's name or a scene file")
        if name != "check":
            p.add_argument("-o", "--output", type=Path, help="results folder")
        if name == "run":
            p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
            p.add_argument("--stop-time", type=float, help="stop earlier (s), e.g. a quick look")
            p.add_argument("--step", type=float, help="macro step (s) instead of the scene's")
            p.add_argument(
                "--monolithic",
                action="store_true",
                help="solve the units as one ODE (no FMI, no macro step): the accuracy "
                "reference, written as a run is",
            )
            p.add_argument(
                "--rtol",
                type=_positive_float_number,
                help="with --monolithic: the solver's relative and absolute tolerance "
                "(default 1e-8; the accuracy study's reference uses 1e-10)",
            )
        p.set_defaults(func=func)
    p = sub.add_parser("sweep", help="run a parameter sweep (Dask)")
    p.add_argument("scene", help="a shipped scene's name or a scene file")
    p.add_argument("spec", metavar="SWEEP_SPEC", type=Path, help="the sweep spec (TOML)")
    p.add_argument(
        "-o",
        "--output",
        type=Path,
        help="results folder; an existing one is resumed (default: results/sweeps/<scene>_<sweep>)",
    )
    p.add_argument(
        "--workers",
        type=_worker_count,
        default=2,
        help="worker processes of the local cluster; 0 runs serially in this "
        "process (default: %(default)s)",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        type=_scheduler_address,
        help="use an existing Dask scheduler, e.g. tcp://10.0.0.5:8786",
    )
    p.add_argument(
        "--rerun-failed",
        action="store_true",
        help="also run again cases recorded as failed or stopped",
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    p.set_defaults(func=cmd_sweep)
    p = sub.add_parser("export", help="export a scene as SSP 1.0 or OSP (docs/interop.md)")
    p.add_argument("scene", help="a shipped scene's name, a scene file or an .ssp package")
    p.add_argument("--format", choices=("ssp", "osp"), required=True, help="what to write")
    p.add_argument(
        "-o",
        "--output",
        type=Path,
        help="ssp: a .ssp file or a folder for <scene>.ssp; osp: the configuration "
        "folder (default: results/export/)",
    )
    p.set_defaults(func=cmd_export)
    p = sub.add_parser("report", help="write a run's results as one self-contained HTML page")
    p.add_argument("results", type=Path, help="a results folder, as 'run' writes it")
    p.add_argument(
        "-o",
        "--output",
        type=Path,
        help="the HTML file, or a folder for report.html (default RESULTS/report.html)",
    )
    p.set_defaults(func=cmd_report)
    p = sub.add_parser("build", help="build our FMUs")
    p.add_argument("-o", "--output", type=Path, help="output folder")
    p.set_defaults(func=cmd_build)
    add_cache_parser(sub)
    _study_parser(sub)
    add_info_parser(sub)
    return parser


class _CtrlC:
    """Remembers a Ctrl-C for the whole command, also one that a unit's code turned into an
    FMI error on its way out (an FMU being instantiated), so the command exits 130."""

    def __init__(self) -> None:
        self.pressed = False
        self._previous = None

    def _handle(self, signum: int, frame: object) -> None:
        self.pressed = True
        raise KeyboardInterrupt

    def __enter__(self) -> _CtrlC:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is None:
            return
        # After a Ctrl-C the command is over: the same Ctrl-C may still be delivered again
        # (the FMU binary hands an interrupt a unit caught back to the host), and must not
        # end the exiting process with a signal instead of its exit status.
        signal.signal(signal.SIGINT, signal.SIG_IGN if self.pressed else self._previous)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``wire-fmu`` command.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments after the program name; None reads the command line
        (and then an interrupted command ends the process with status 130).

    Returns
    -------
    int
        Exit status: 0 on success, 1 after an error, 130 after Ctrl-C.
    """
    parser = _parser()
    args = parser.parse_args(argv)
    _refuse_conflicts(parser, args)
    logging.basicConfig(
        level=logging.DEBUG if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    with _CtrlC() as ctrl_c:
        try:
            code = _command(args, ctrl_c)
            sys.stdout.flush()
        except BrokenPipeError:
            return _closed_pipe()
    if code == EXIT_INTERRUPTED and argv is None:
        # The command line itself: end now with 130. A Ctrl-C a unit caught is delivered to
        # this process once more by the FMU binary, and would otherwise end it by SIGINT.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(EXIT_INTERRUPTED)
    return code


def _closed_pipe() -> int:
    """The reader of our output went away (``wire-fmu scenes | head -1``): end quietly.

    Standard output is pointed at the null device so that the interpreter's own
    flush at exit finds nothing to write to the closed pipe.

    Returns
    -------
    int
        Exit status 141 (128 + SIGPIPE), what a shell reports for a command
        ended by a closed pipe.
    """
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
    return EXIT_BROKEN_PIPE


def _command(args: argparse.Namespace, ctrl_c: _CtrlC) -> int:
    """Run the chosen command; every ending is an exit status and a message, no traceback."""
    try:
        return args.func(args)
    except BrokenPipeError:
        raise  # the reader went away: nothing more can be said (see _closed_pipe)
    except KeyboardInterrupt:
        _print("\ninterrupted")
        return EXIT_INTERRUPTED
    except WireFmuError as err:
        if ctrl_c.pressed:
            _print("\ninterrupted")
            return EXIT_INTERRUPTED
        _print(f"error: {err}")
        return 1
    except Exception as exc:  # noqa: BLE001 - a command ends with a message, never a traceback
        if ctrl_c.pressed:
            _print("\ninterrupted")
            return EXIT_INTERRUPTED
        logger.debug("unexpected failure", exc_info=True)
        _print(
            f"error: unexpected {type(exc).__name__}: {exc}"
            + ("" if args.verbose else " (run with --verbose for the traceback)")
        )
        return 1


if __name__ == "__main__":
    sys.exit(main())

"""What each ``wire-fmu`` command does (:mod:`wire_fmu.cli` reads the command line)."""

from __future__ import annotations

import argparse
import json
import logging
import re
import shutil
import sys
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from wire_fmu.core.errors import WireFmuError

__all__ = [
    "cmd_scenes",
    "cmd_check",
    "cmd_run",
    "cmd_draw",
    "cmd_build",
    "cmd_sweep",
    "cmd_export",
    "cmd_study",
    "cmd_report",
    "EXIT_INTERRUPTED",
    "EXIT_BROKEN_PIPE",
    "plural",
    "first_sentence",
]

EXIT_INTERRUPTED = 130
"""Exit status after Ctrl-C (128 + SIGINT), as shells report it."""

EXIT_BROKEN_PIPE = 141
"""Exit status when the reader of the output went away (128 + SIGPIPE), as shells report it."""

_SENTENCE_END = re.compile(r"(?<=[.!?])\s+(?=[A-Z('\"])")


def _print(text: str = "") -> None:
    sys.stdout.write(text + "\n")


def _table(rows: Sequence[tuple[str, str]]) -> str:
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"  {k:<{width}}  {v}" for k, v in rows)


def plural(count: int, noun: str, plural_form: str | None = None) -> str:
    """``count`` and ``noun``, the noun in the plural unless the count is one.

    Parameters
    ----------
    count : int
        How many.
    noun : str
        The noun in the singular (``"bond"``).
    plural_form : str, optional
        The plural when it is not ``noun + "s"``.

    Returns
    -------
    str
        ``"1 bond"``, ``"0 bonds"``, ``"3 bonds"``.
    """
    return f"{count} {noun if count == 1 else plural_form or noun + 's'}"


def first_sentence(text: str) -> str:
    """The first sentence of ``text``, whole, its lines joined.

    A sentence ends at ``.``, ``!`` or ``?`` followed by white space and a
    capital letter, a parenthesis or a quote (so ``Fig. 6`` does not end one).

    Parameters
    ----------
    text : str
        A description, possibly over several lines.

    Returns
    -------
    str
        The first sentence, or the whole text if it has one sentence.
    """
    joined = " ".join(text.split())
    return _SENTENCE_END.split(joined, maxsplit=1)[0]


def _wrapped_table(rows: Sequence[tuple[str, str]], width: int) -> str:
    """A two-column table whose second column wraps under itself at ``width`` characters."""
    key_width = max(len(k) for k, _ in rows)
    indent = " " * (key_width + 4)
    lines = []
    for key, text in rows:
        lines += textwrap.wrap(
            text,
            width=max(width, len(indent) + 30),
            initial_indent=f"  {key:<{key_width}}  ",
            subsequent_indent=indent,
        ) or [f"  {key}"]
    return "\n".join(lines)


def cmd_scenes(args: argparse.Namespace) -> int:
    """List shipped scenes with their descriptions.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: none of its options is used.

    Returns
    -------
    int
        Exit status: 0 on success.
    """
    from wire_fmu.master.run import shipped_scenes
    from wire_fmu.master.scene import load_scene

    rows = []
    for name, path in shipped_scenes().items():
        try:
            rows.append((name, first_sentence(load_scene(path).description) or "-"))
        except WireFmuError:
            rows.append((name, "(cannot be read)"))
    width = shutil.get_terminal_size((100, 24)).columns - 1
    _print(_wrapped_table(rows, width) if rows else "no shipped scenes")
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    """Validate a scene and initialise its units as a run would; exit 1 listing every problem.

    Settings the scene's effects leave without influence, bonds that cannot give the
    interface model ``run.interface_models`` asks for, and events after the stop time are
    warnings (exit 0).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``scene`` and ``fmu_dir``.

    Returns
    -------
    int
        Exit status: 0 on success.
    """
    from wire_fmu.master.run import check_scene
    from wire_fmu.master.scene import interface_warnings, late_event_warnings
    from wire_fmu.unit_reference.scene_warnings import inactive_settings

    scene = check_scene(args.scene, args.fmu_dir)
    wired = len(scene.interface_bonds)
    bonds = plural(len(scene.bonds), "bond") + (f" ({wired} with interface model)" if wired else "")
    _print(
        f"scene {scene.name!r}: no problems ({plural(len(scene.units), 'unit')}, "
        f"{bonds}, {plural(len(scene.connections), 'connection')})"
    )
    warnings = inactive_settings(scene) + interface_warnings(scene) + late_event_warnings(scene)
    for warning in warnings:
        _print(f"warning: {warning}")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    """Run a scene and report where the results are.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``scene``, ``output``, ``quiet``, ``fmu_dir``,
        ``stop_time`` (s), ``step`` (s), ``monolithic`` and ``rtol``.

    Returns
    -------
    int
        Exit status: 0 finished, 130 interrupted, 1 otherwise.
    """
    from wire_fmu.unit_reference.scene_warnings import scene_file_warnings

    for warning in scene_file_warnings(args.scene):
        _print(f"warning: {warning}")
    if args.monolithic:
        return _run_monolithic(args)
    from wire_fmu.master.observers import summary_rows
    from wire_fmu.master.run import run_scene

    outcome = run_scene(
        args.scene,
        args.output,
        progress=not args.quiet,
        fmu_dir=args.fmu_dir,
        stop_time=args.stop_time,
        step=args.step,
    )
    _print(f"\nscene {outcome.scene.name!r}")
    _print(_table(summary_rows(outcome.simulation, outcome.result)))
    return _run_files(outcome)


def _run_monolithic(args: argparse.Namespace) -> int:
    """``run --monolithic``: the scene's units as one ODE (:mod:`wire_fmu.study.monolithic_run`)."""
    from wire_fmu.study.monolithic_run import DEFAULT_RTOL, run_scene_monolithic, summary_rows

    outcome = run_scene_monolithic(
        args.scene,
        args.output,
        progress=not args.quiet,
        fmu_dir=args.fmu_dir,
        stop_time=args.stop_time,
        rtol=DEFAULT_RTOL if args.rtol is None else args.rtol,
    )
    _print(f"\nscene {outcome.scene.name!r}")
    _print(_table(summary_rows(outcome)))
    return _run_files(outcome)


def _run_files(outcome: Any) -> int:
    """Say where a run's files are and, last, how it ended unless it finished.

    Parameters
    ----------
    outcome : Outcome or MonolithicOutcome
        The run: its ``result``, ``directory``, ``csv_path`` and ``plots``.

    Returns
    -------
    int
        Exit status: 0 finished, 130 interrupted, 1 otherwise.
    """
    if outcome.csv_path.is_file():
        _print(f"\nresults: {outcome.csv_path.resolve()}")
    _print(f"metadata: {(outcome.directory / 'metadata.json').resolve()}")
    for path in outcome.plots:
        _print(f"plot: {path.resolve()}")
    report = _report(outcome)
    if report is not None:
        _print(f"report: {report.resolve()}")
    status = outcome.result.status
    if status != "finished":  # said once, last, where it is seen
        _print(f"\nrun {status}: {outcome.result.message}")
    return EXIT_INTERRUPTED if status == "interrupted" else 0 if status == "finished" else 1


def _report(outcome: Any) -> Path | None:
    """Write the run's HTML report; None (with a warning) if it cannot be written."""
    from wire_fmu.tools.report import write_report

    if not (outcome.directory / "metadata.json").is_file():
        return None
    try:
        return write_report(outcome.directory, plots=list(outcome.plots) or None)
    except Exception as exc:  # noqa: BLE001 - the run's results stand without their report
        logging.getLogger(__name__).warning("the report could not be written: %s", exc)
        logging.getLogger(__name__).debug("report failure", exc_info=True)
        return None


def cmd_report(args: argparse.Namespace) -> int:
    """Write a results folder as one self-contained HTML page.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``results`` (the folder) and ``output``.

    Returns
    -------
    int
        Exit status: 0 on success.
    """
    from wire_fmu.tools.report import write_report

    path = write_report(args.results, args.output)
    _print(f"report: {path.resolve()}")
    return 0


def cmd_draw(args: argparse.Namespace) -> int:
    """Draw every block train's reeving in a scene.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``scene`` and ``output``.

    Returns
    -------
    int
        Exit status: 0 on success.
    """
    from wire_fmu.master.run import find_scene, make_results_folder
    from wire_fmu.master.scene import SceneError, load_scene
    from wire_fmu.tools.draw import draw_reeving

    scene = load_scene(find_scene(args.scene))
    out = make_results_folder(Path(args.output or Path("results") / scene.name))
    drawn = 0
    for name, unit in scene.units.items():
        reeving = unit.parameters.get("reeving")
        if reeving is None:
            continue
        if isinstance(reeving, str):
            try:
                reeving = json.loads(reeving)
            except ValueError as exc:
                raise SceneError(
                    f"scene {scene.name!r}",
                    [f"unit {name!r}: parameter 'reeving' is not JSON ({exc})"],
                ) from None
        try:
            path = draw_reeving(reeving, out / f"{name}_reeving.png", title=f"{scene.name}: {name}")
        except WireFmuError:
            raise
        except (ValueError, ArithmeticError) as exc:
            raise SceneError(
                f"scene {scene.name!r}", [f"unit {name!r}: the reeving cannot be drawn: {exc}"]
            ) from None
        _print(f"drawn: {path.resolve()}")
        drawn += 1
    if not drawn:
        _print(f"scene {scene.name!r} has no unit with a 'reeving' parameter to draw")
    return 0


def cmd_build(args: argparse.Namespace) -> int:
    """Build our FMUs into a folder.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``output`` and ``fmu_dir``.

    Returns
    -------
    int
        Exit status: 0 on success.
    """
    from wire_fmu.master.catalog import ensure_built
    from wire_fmu.registry import UNIT_TYPES

    for unit in UNIT_TYPES:
        if unit.facade_path.exists():
            path = ensure_built(unit.name, unit.facade_path, args.output or args.fmu_dir)
            _print(f"{unit.name}: {path}")
    return 0


def cmd_sweep(args: argparse.Namespace) -> int:
    """Run a parameter sweep; exit 1 unless every case finished.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``scene``, ``spec``, ``output``, ``workers``,
        ``scheduler``, ``fmu_dir``, ``quiet``, ``rerun_failed`` and ``verbose``.

    Returns
    -------
    int
        Exit status: 0 if every case finished, 130 interrupted, 1 otherwise.
    """
    from wire_fmu.master.run import find_scene
    from wire_fmu.master.scene import load_scene
    from wire_fmu.sweep import load_sweep, run_sweep

    if not args.verbose:  # a local cluster's scheduler runs here and logs every event
        import distributed  # noqa: F401 - sets its loggers' levels on import; then quieten

        logging.getLogger("distributed").setLevel(logging.WARNING)
    scene = load_scene(find_scene(args.scene))
    spec = load_sweep(scene, args.spec, args.fmu_dir)
    out = args.output or Path("results") / "sweeps" / f"{scene.name}_{spec.name}"
    try:
        result = run_sweep(
            scene,
            spec,
            out,
            workers=args.workers,
            scheduler=args.scheduler,
            fmu_dir=args.fmu_dir,
            progress=not args.quiet,
            rerun_failed=args.rerun_failed,
        )
    except KeyboardInterrupt:
        _print(
            f"\ninterrupted; finished cases are kept in {Path(out).resolve()}: run the same "
            "command again to run only the rest"
        )
        return EXIT_INTERRUPTED
    counts = ", ".join(f"{n} {status}" for status, n in sorted(result.counts.items()))
    _print(
        f"\nsweep {spec.name!r} of scene {scene.name!r}: {plural(len(result.rows), 'case')} "
        f"({counts}); "
        f"{result.executed} run now, {result.reused} from earlier, {result.wall_time:.3g} s"
    )
    _print(f"summary: {result.summary_path.resolve()}")
    _print(f"time series: {(result.directory / 'cases').resolve()}/<case_id>/timeseries.csv")
    for path in result.plots:
        _print(f"plot: {path.resolve()}")
    return 0 if result.complete else 1


def _load_any_scene(name: str):
    """A shipped scene, a scene file or an SSP package."""
    from wire_fmu.master.run import find_scene, load_scene_file

    return load_scene_file(find_scene(name))


def cmd_export(args: argparse.Namespace) -> int:
    """Export a scene as an SSP package or an OSP configuration (docs/interop.md).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``scene``, ``format`` (``ssp`` or
        ``osp``), ``output`` and ``fmu_dir``.

    Returns
    -------
    int
        Exit status: 0 on success.
    """
    from wire_fmu.interop import export_osp, export_ssp

    scene = _load_any_scene(args.scene)
    out = Path(args.output or Path("results") / "export")
    if args.format == "ssp":
        path = export_ssp(scene, out, fmu_dir=args.fmu_dir)
    else:
        path = export_osp(
            scene, out / f"{scene.name}_osp" if args.output is None else out, fmu_dir=args.fmu_dir
        )
    _print(f"exported scene {scene.name!r} as {args.format.upper()}: {path.resolve()}")
    return 0


def cmd_study(args: argparse.Namespace) -> int:
    """Run the accuracy or the effects study of a scene and say where its files are.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``study`` (``accuracy`` or ``effects``),
        ``scene``, ``output``, ``quick``, ``grid``, ``couplings``, ``fmu_dir``, ``repeats`` and
        ``stop_time`` (s).

    Returns
    -------
    int
        Exit status: 0 on success.
    """
    from wire_fmu.study import accuracy, effects

    out = args.output or Path("results") / Path(args.scene).stem / args.study
    if args.study == "accuracy":
        study = accuracy.run_accuracy_study(
            args.scene,
            out,
            quick=args.quick,
            grid=args.grid,
            couplings=args.couplings,
            fmu_dir=args.fmu_dir,
            repeats=args.repeats,
            stop_time=args.stop_time,
        )
        _print(accuracy.summary_text(study))
    else:
        study = effects.run_effects_study(
            args.scene,
            out,
            quick=args.quick,
            fmu_dir=args.fmu_dir,
            repeats=args.repeats,
            stop_time=args.stop_time,
        )
        _print(effects.summary_text(study))
    _print(f"\nstudy took {study.elapsed:.0f} s")
    for path in study.files.values():
        _print(f"written: {path.resolve()}")
    return 0

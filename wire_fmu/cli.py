"""The ``wire-fmu`` command.

::

    wire-fmu scenes                 list the shipped scenes
    wire-fmu check SCENE            validate a scene; list every problem, exit 1 if any
    wire-fmu run SCENE [-o DIR]     run it: progress bar, summary table, CSV and PNG plots
    wire-fmu draw SCENE [-o DIR]    render each block train's reeving to a PNG
    wire-fmu build [-o DIR]         build our FMUs

SCENE is a shipped scene's name or a path to a scene file.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from collections.abc import Sequence
from pathlib import Path

from wire_fmu.core.errors import WireFmuError

__all__ = ["main"]

logger = logging.getLogger("wire_fmu")


def _print(text: str = "") -> None:
    sys.stdout.write(text + "\n")


def _table(rows: Sequence[tuple[str, str]]) -> str:
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"  {k:<{width}}  {v}" for k, v in rows)


def cmd_scenes(args: argparse.Namespace) -> int:
    """List shipped scenes with their descriptions."""
    from wire_fmu.master.run import shipped_scenes
    from wire_fmu.master.scene import load_scene

    rows = []
    for name, path in shipped_scenes().items():
        try:
            rows.append((name, load_scene(path).description.strip().splitlines()[0]))
        except (WireFmuError, IndexError):
            rows.append((name, "(cannot be read)"))
    _print(_table(rows) if rows else "no shipped scenes")
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    """Validate a scene; exit 1 listing every problem."""
    from wire_fmu.master.run import find_scene
    from wire_fmu.master.scene import load_scene
    from wire_fmu.master.validate import validate_scene

    scene = load_scene(find_scene(args.scene))
    validate_scene(scene, args.fmu_dir)
    _print(f"scene {scene.name!r}: no problems ({len(scene.units)} units, "
           f"{len(scene.bonds)} bonds, {len(scene.connections)} connections)")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    """Run a scene and report where the results are."""
    from wire_fmu.master.observers import summary_rows
    from wire_fmu.master.run import run_scene

    outcome = run_scene(args.scene, args.output, progress=not args.quiet, fmu_dir=args.fmu_dir,
                        stop_time=args.stop_time, step=args.step)
    _print(f"\nscene {outcome.scene.name!r}")
    _print(_table(summary_rows(outcome.simulation, outcome.result)))
    _print(f"\nresults: {outcome.csv_path.resolve()}")
    _print(f"metadata: {(outcome.directory / 'metadata.json').resolve()}")
    for path in outcome.plots:
        _print(f"plot: {path.resolve()}")
    return 0 if outcome.result.status == "finished" else 1


def cmd_draw(args: argparse.Namespace) -> int:
    """Draw every block train's reeving in a scene."""
    from wire_fmu.master.draw import draw_reeving
    from wire_fmu.master.run import find_scene
    from wire_fmu.master.scene import load_scene

    scene = load_scene(find_scene(args.scene))
    out = Path(args.output or Path("results") / scene.name)
    out.mkdir(parents=True, exist_ok=True)
    drawn = 0
    for name, unit in scene.units.items():
        reeving = unit.parameters.get("reeving")
        if reeving is None:
            continue
        if isinstance(reeving, str):
            reeving = json.loads(reeving)
        path = draw_reeving(reeving, out / f"{name}_reeving.png", title=f"{scene.name}: {name}")
        _print(f"drawn: {path.resolve()}")
        drawn += 1
    if not drawn:
        _print(f"scene {scene.name!r} has no unit with a 'reeving' parameter to draw")
    return 0


def cmd_build(args: argparse.Namespace) -> int:
    """Build our FMUs into a folder."""
    from wire_fmu.master.catalog import OUR_FMUS, ROOT, ensure_built

    for name, script in OUR_FMUS.items():
        path = ROOT / "models" / script
        if path.exists():
            _print(f"{name}: {ensure_built(name, path, args.output or args.fmu_dir)}")
    return 0


def _parser() -> argparse.ArgumentParser:
    from wire_fmu.master.catalog import DEFAULT_FMU_DIR

    parser = argparse.ArgumentParser(prog="wire-fmu", description=__doc__.splitlines()[0])
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    parser.add_argument("--fmu-dir", type=Path, default=DEFAULT_FMU_DIR,
                        help="where our FMUs are built and cached (default: %(default)s)")
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("scenes", help="list the shipped scenes").set_defaults(func=cmd_scenes)
    for name, func, text in (("check", cmd_check, "validate a scene"),
                             ("run", cmd_run, "run a scene"),
                             ("draw", cmd_draw, "draw a scene's reevings")):
        p = sub.add_parser(name, help=text)
        p.add_argument("scene", help="a shipped scene's name or a scene file")
        if name != "check":
            p.add_argument("-o", "--output", type=Path, help="results folder")
        if name == "run":
            p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
            p.add_argument("--stop-time", type=float, help="stop earlier (s), e.g. a quick look")
            p.add_argument("--step", type=float, help="macro step (s) instead of the scene's")
        p.set_defaults(func=func)
    p = sub.add_parser("build", help="build our FMUs")
    p.add_argument("-o", "--output", type=Path, help="output folder")
    p.set_defaults(func=cmd_build)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``wire-fmu`` command."""
    args = _parser().parse_args(argv)
    logging.basicConfig(level=logging.DEBUG if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.func(args)
    except WireFmuError as err:
        _print(f"error: {err}")
        return 1


if __name__ == "__main__":
    sys.exit(main())

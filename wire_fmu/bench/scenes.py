"""Every shipped scene with the compiled and the Python kernel, side by side, and start times.

Run ``python -m wire_fmu.bench.scenes [--stop-time T] [--repeats N] [--scenes NAME ...]
[--out FILE]``.

For each shipped scene and each kernel (``WIRE_FMU_KERNEL``), the scene runs at
its own settings (or up to ``--stop-time``) in a fresh interpreter, without
plots; the figure is the wall time of the master's loop (:attr:`RunResult.wall_time
<wire_fmu.master.run_result.RunResult.wall_time>`, the median of ``--repeats``
runs) and the real-time factor it gives. The start time is the wall time of the
whole command ``wire-fmu run SCENE`` for one macro step: with the Python kernel
(what every run paid before the kernels were compiled), with the compiled kernel
and an empty compiled-code cache (the first run on a machine, *cold*), and again
with that cache filled (*warm*). FMUs are built before anything is timed.
"""

from __future__ import annotations

import json
import logging
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from wire_fmu.core.framework.compiled import CACHE_ENV, KERNEL_ENV

from .scene_options import parse_scene_options, report_table, scene_parser

__all__ = ["SceneFigures", "measure_scene", "start_times", "table", "main"]

logger = logging.getLogger(__name__)

SCENES = (
    "riser_tensioner",
    "drawworks",
    "heave_compensated_hoist",
    "multimass_drive",
    "machine_unit",
    "scissor_jack",
)
_ONE_RUN = r"""
import json, sys
from wire_fmu.master.run import run_scene
name, stop, out = sys.argv[1], sys.argv[2], sys.argv[3]
outcome = run_scene(name, __import__("pathlib").Path(out), plots=False,
                    stop_time=None if stop == "own" else float(stop))
r = outcome.result
sys.stdout.write(json.dumps({"status": r.status, "end": r.end_time, "wall": r.wall_time,
                             "steps": r.steps}) + "\n")
"""


@dataclass(frozen=True)
class SceneFigures:
    """One scene with both kernels.

    Attributes
    ----------
    scene : str
        The shipped scene.
    simulated : float
        Simulated time, s.
    steps : int
        Macro steps taken.
    python_s, compiled_s : float
        Median wall time of the master's loop with each kernel, s.
    """

    scene: str
    simulated: float
    steps: int
    python_s: float
    compiled_s: float

    @property
    def ratio(self) -> float:
        """How many times faster the compiled kernel runs the scene."""
        return self.python_s / self.compiled_s

    def real_time_factor(self, seconds: float) -> float:
        """Simulated seconds per wall-clock second for a wall time ``seconds`` (s).

        Parameters
        ----------
        seconds : float
            Wall time of the run, s.
        """
        return self.simulated / seconds


def _environment(kernel: str, cache: Path | None = None) -> dict[str, str]:
    env = dict(os.environ, **{KERNEL_ENV: kernel})
    if cache is not None:
        env[CACHE_ENV] = str(cache)
    return env


def _run_once(scene: str, kernel: str, stop: str, out: Path) -> dict:
    """One run of ``scene`` in a fresh interpreter: status, end time, loop wall time, steps."""
    done = subprocess.run(
        [sys.executable, "-c", _ONE_RUN, scene, stop, str(out)],
        env=_environment(kernel),
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        raise RuntimeError(f"{scene} ({kernel} kernel) failed:\n{done.stderr[-2000:]}")
    result = json.loads(done.stdout.strip().splitlines()[-1])
    if result["status"] != "finished":
        raise RuntimeError(f"{scene} ({kernel} kernel) ended {result['status']}")
    return result


def measure_scene(scene: str, stop: str, repeats: int, work: Path) -> SceneFigures:
    """Both kernels on ``scene``: median loop wall times.

    Parameters
    ----------
    scene : str
        A shipped scene.
    stop : str
        ``"own"`` for the scene's stop time, else a stop time in s.
    repeats : int
        Runs per kernel (the median counts).
    work : Path
        Folder for the results of the runs.
    """
    walls: dict[str, list[float]] = {"python": [], "compiled": []}
    last: dict = {}
    for i in range(repeats):
        for kernel in walls:
            last = _run_once(scene, kernel, stop, work / f"{scene}-{kernel}-{i}")
            walls[kernel].append(last["wall"])
    return SceneFigures(
        scene,
        last["end"],
        last["steps"],
        statistics.median(walls["python"]),
        statistics.median(walls["compiled"]),
    )


def _command_seconds(scene: str, env: dict[str, str], out: Path) -> float:
    """Wall time of ``wire-fmu run SCENE`` for one macro step, s."""
    start = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "wire_fmu.cli", "run", scene, "-q", "--stop-time", "0.002"]
        + ["-o", str(out)],
        env=env,
        capture_output=True,
        check=True,
    )
    return time.perf_counter() - start


def start_times(scene: str, work: Path, repeats: int = 3) -> dict[str, float]:
    """Start of ``wire-fmu run``: Python kernel, compiled cold and warm (s).

    The Python kernel's and the warm start are the median of ``repeats`` commands, taken
    in alternation (so that a busy moment of the machine does not fall on one of them);
    the cold start is one command on a fresh compiled-code cache.

    Parameters
    ----------
    scene : str
        A shipped scene.
    work : Path
        Folder for results and the fresh compiled-code cache.
    repeats : int
        Commands per warm figure.
    """
    cache = work / "cold-cache"
    cold = _command_seconds(scene, _environment("compiled", cache), work / "start-cold")
    python, warm = [], []
    for i in range(max(1, repeats)):
        python.append(_command_seconds(scene, _environment("python"), work / f"start-python{i}"))
        warm.append(
            _command_seconds(scene, _environment("compiled", cache), work / f"start-warm{i}")
        )
    return {"python": statistics.median(python), "cold": cold, "warm": statistics.median(warm)}


def table(figures: list[SceneFigures], starts: dict[str, float], scene: str) -> str:
    """The Markdown table of the figures and the start times.

    Parameters
    ----------
    figures : list of SceneFigures
        One per scene.
    starts : dict of str to float
        :func:`start_times` of ``scene``.
    scene : str
        The scene the start times are of.
    """
    lines = [
        "| scene | simulated s | macro steps | Python kernel s | compiled s | ratio "
        "| real-time factor, Python | real-time factor, compiled |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for f in figures:
        lines.append(
            f"| {f.scene} | {f.simulated:g} | {f.steps} | {f.python_s:.2f} | {f.compiled_s:.2f} "
            f"| {f.ratio:.1f} | {f.real_time_factor(f.python_s):.1f} "
            f"| {f.real_time_factor(f.compiled_s):.1f} |"
        )
    if not figures:  # --start-only
        lines = []
    lines += [
        "",
        f"Start of `wire-fmu run {scene}` (one macro step, whole command; median of the "
        "warm runs): Python kernel "
        f"{starts['python']:.2f} s, compiled cold {starts['cold']:.2f} s, "
        f"compiled warm {starts['warm']:.2f} s.",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Measure and print the table (and write it with ``--out``).

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default: ``sys.argv[1:]``).
    """
    parser = scene_parser(__doc__.splitlines()[0], SCENES, "runs per kernel (median)")
    parser.add_argument("--stop-time", type=float, help="shorten every scene to this, s")
    parser.add_argument(
        "--start-only", action="store_true", help="only the start of the first scene's command"
    )
    args = parse_scene_options(parser, argv)
    stop = "own" if args.stop_time is None else str(args.stop_time)
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        _run_once(args.scenes[0], "compiled", "0.01", work / "build")  # builds the FMUs
        figures = []
        for scene in args.scenes if not args.start_only else ():
            figures.append(measure_scene(scene, stop, args.repeats, work))
            logger.info("%s: %.1fx", scene, figures[-1].ratio)
        starts = start_times(args.scenes[0], work, args.repeats)
    report_table(table(figures, starts, args.scenes[0]), args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

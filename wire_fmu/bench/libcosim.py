"""Our master against libcosim, a master we did not write, on the same FMUs, side by side.

Run ``python -m wire_fmu.bench.libcosim [--stop-time S] [--repeats N] [--scenes NAME ...]
[--out FILE]``. Each shipped scene (or each one named; shortened to ``--stop-time``,
default 5 s) is run with libcosim's fixed-step algorithm in both masters: every unit
steps on the values its partners gave at the step's start, held
(:data:`~wire_fmu.interop.plan.FIXED_STEP_HOST_RUN`), as in
``tests/test_interop_libcosim.py``, which shows that the two then compute the same
numbers. libcosim (libcosimpy) runs the scene exported as an SSP package, whose
drivers and events are one more FMU (the signals FMU). Neither records anything.
``N`` runs of each master alternate; the median counts. Figures:

* the stepping loop's wall time in each: ours is :class:`~wire_fmu.master.simulation.
  Simulation`'s loop, libcosim's one ``simulate_until`` call, with the same FMUs
  doing the same physics;
* their ratio, ours over libcosim's: below 1 our master costs less per step than
  libcosim's C++ on top of the same FMU work (libcosim also steps the signals FMU,
  where our master evaluates drivers itself);
* our master's own cost per unit and macro step (the loop's wall time beyond the
  time inside FMI calls, as :mod:`wire_fmu.bench.master` measures it, here without
  the recorder), and
* the set-up of each (loading, instantiating and initialising the FMUs), s.

A machine's speed moves both masters' figures together, so the ratio is what this
benchmark carries from one machine to another.
"""

from __future__ import annotations

import logging
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from wire_fmu.interop import export_ssp
from wire_fmu.interop.plan import as_fixed_step_host_runs_it
from wire_fmu.master.catalog import DEFAULT_FMU_DIR
from wire_fmu.master.run import find_scene, load_scene_file, shipped_scenes
from wire_fmu.master.scene import Scene
from wire_fmu.master.simulation import Simulation
from wire_fmu.master.validate import validate_scene

from .scene_options import parse_scene_options, report_table, scene_parser
from .tables import markdown_table

__all__ = ["MasterPair", "jacobi_scene", "measure", "table", "main"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class MasterPair:
    """Figures of one scene in both masters (medians over the runs)."""

    scene: str
    units: int
    steps: int
    ours: float
    theirs: float
    fmi: float
    ours_setup: float
    theirs_setup: float

    @property
    def ratio(self) -> float:
        """Our stepping wall time over libcosim's, 1."""
        return self.ours / self.theirs

    @property
    def overhead_us(self) -> float:
        """Our master's stepping time beyond its FMI calls, per unit and step, µs."""
        return 1e6 * (self.ours - self.fmi) / max(1, self.units * self.steps)


def jacobi_scene(name: str, stop_time: float) -> Scene:
    """Shipped scene ``name`` with libcosim's algorithm, shortened to ``stop_time`` (s).

    Parameters
    ----------
    name : str
        A shipped scene's name.
    stop_time : float
        Simulated time, s (the scene's own if that is shorter).
    """
    scene = load_scene_file(find_scene(name))
    return as_fixed_step_host_runs_it(scene, stop_time=min(scene.run.stop_time, stop_time))


def _ours(scene: Scene, fmu_dir: Path) -> tuple[float, float, float, int]:
    """Our master on ``scene``, recording nothing: stepping wall, its FMI time, set-up (s),
    macro steps."""
    started = time.perf_counter()
    structure = validate_scene(scene, fmu_dir, through_fmi=False)
    sim = Simulation(scene, structure, [])
    result = sim.run()
    if result.status != "finished":
        raise RuntimeError(f"{scene.name}: our master: {result.status}: {result.message}")
    total = time.perf_counter() - started
    setup = total - result.stepping_wall_time
    return result.stepping_wall_time, result.stepping_fmi_time, setup, result.steps


def _theirs(package: Path, scene: Scene) -> tuple[float, float]:
    """The exported ``package`` in libcosim: stepping wall and set-up (s)."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.ERROR)
    started = time.perf_counter()
    step_ns = int(round(scene.run.step * 1e9))
    execution = CosimExecution.from_ssp_file(str(package), step_size=step_ns)
    if not execution.step(1):  # initialises the FMUs: set-up, as ours counts it
        raise RuntimeError(f"{scene.name}: libcosim refused the first step")
    stepping = time.perf_counter()
    if not execution.simulate_until(int(round(scene.run.stop_time * 1e9))):
        raise RuntimeError(f"{scene.name}: libcosim stopped before {scene.run.stop_time} s")
    done = time.perf_counter()
    # the first step is stepping too: counted at the loop's mean rate, not as set-up
    steps = max(1, round(scene.run.stop_time / scene.run.step))
    per_step = (done - stepping) / max(1, steps - 1)
    return done - stepping + per_step, stepping - started - per_step


def measure(name: str, stop_time: float, repeats: int, work: Path) -> MasterPair:
    """Both masters on shipped scene ``name``, ``repeats`` runs each in alternation.

    Parameters
    ----------
    name : str
        A shipped scene's name.
    stop_time : float
        Simulated time, s.
    repeats : int
        Runs per master (the median counts).
    work : Path
        Folder for the exported package.

    Returns
    -------
    MasterPair
    """
    scene = jacobi_scene(name, stop_time)
    package = export_ssp(scene, work / name, fmu_dir=DEFAULT_FMU_DIR)
    ours, fmi, ours_setup, theirs, theirs_setup = [], [], [], [], []
    steps = 0
    for _ in range(repeats):
        wall, inside, setup, steps = _ours(scene, DEFAULT_FMU_DIR)
        ours.append(wall)
        fmi.append(inside)
        ours_setup.append(setup)
        wall, setup = _theirs(package, scene)
        theirs.append(wall)
        theirs_setup.append(setup)
    median = statistics.median
    middle = sorted(range(repeats), key=lambda i: ours[i])[repeats // 2]  # one run's own pair
    return MasterPair(
        name,
        len(scene.units),
        steps,
        ours[middle],
        median(theirs),
        fmi[middle],
        median(ours_setup),
        median(theirs_setup),
    )


def table(rows: list[MasterPair]) -> str:
    """Markdown table of the figures: one row per scene.

    Parameters
    ----------
    rows : list of MasterPair
        One per scene.
    """
    header = (
        "scene | units | macro steps | ours, stepping s | libcosim, stepping s | ours / libcosim "
        "| our master per unit per step | set-up ours s | set-up libcosim s"
    )
    return markdown_table(
        header,
        (
            f"{r.scene} | {r.units} | {r.steps} | {r.ours:.3f} | {r.theirs:.3f} | "
            f"{r.ratio:.2f} | {r.overhead_us:.1f} µs | {r.ours_setup:.2f} | {r.theirs_setup:.2f}"
            for r in rows
        ),
    )


def main(argv: list[str] | None = None) -> None:
    """Command-line entry point.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads the command line.
    """
    parser = scene_parser(
        __doc__.splitlines()[0], list(shipped_scenes()), "runs per master (median)"
    )
    parser.add_argument("--stop-time", type=float, default=5.0, help="simulated time, s")
    args = parse_scene_options(parser, argv)
    if not args.stop_time > 0.0:
        parser.error(f"--stop-time must be above 0 s, got {args.stop_time}")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes:
            rows.append(measure(name, args.stop_time, args.repeats, Path(tmp)))
            logger.info(
                "%s: ours %.3f s, libcosim %.3f s (ratio %.2f)",
                name,
                rows[-1].ours,
                rows[-1].theirs,
                rows[-1].ratio,
            )
    report_table(table(rows), args.out)


if __name__ == "__main__":
    main()

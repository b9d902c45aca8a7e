"""What the master costs beyond the FMUs, and each shipped scene's real-time factor.

Run ``python -m wire_fmu.bench.master [--stop-time S] [--repeats N] [--scenes NAME ...]
[--out FILE]``. Each shipped scene (or each one named) is run ``N`` times (default 3;
the run of median overhead counts; shortened to ``--stop-time`` if given) with the
master; the time spent inside fmpy's calls to the FMUs is measured per call
by the master itself (:class:`~wire_fmu.master.slave.Slave` counts every FMI
call and its time), so

* master overhead per unit per macro step = (wall time of the stepping loop
  − time in FMI calls made by it) / (units × macro steps),
* of which recording: the time the results recorder spent putting rows together
  and writing them as text during the loop, per unit per macro step (it grows
  with the number of recorded values and how often a row is due: about a tenth
  of a microsecond per value for its text, the shortest that reads back to the
  same float, and as much again to put the row together),
* set-up and clean-up = the rest of the run's wall time beyond its FMI calls
  (extracting and loading the FMUs, initialisation, the results' metadata,
  freeing the units): paid once per run, not per step, and
* the real-time factor = simulated time / wall time of the whole run.
"""

from __future__ import annotations

import logging
import tempfile
from dataclasses import dataclass
from pathlib import Path

from wire_fmu.master.observers import CsvRecorder
from wire_fmu.master.run import run_scene, shipped_scenes

from .scene_options import parse_scene_options, report_table, scene_parser
from .tables import markdown_table

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class SceneFigures:
    """Benchmark figures of one scene."""

    scene: str
    units: int
    steps: int
    simulated: float
    wall: float
    fmi_seconds: float
    stepping_wall: float
    stepping_fmi_seconds: float
    recording_seconds: float = 0.0
    recorded_values: int = 0

    @property
    def real_time_factor(self) -> float:
        """Simulated seconds per wall-clock second."""
        return self.simulated / self.wall

    @property
    def overhead_us(self) -> float:
        """Master time per unit per macro step beyond the FMI calls, microseconds."""
        stepping = self.stepping_wall - self.stepping_fmi_seconds
        return 1e6 * stepping / max(1, self.units * self.steps)

    @property
    def recording_us(self) -> float:
        """Of :attr:`overhead_us`, the recorder's share, microseconds per unit per step."""
        return 1e6 * self.recording_seconds / max(1, self.units * self.steps)

    @property
    def coupling_us(self) -> float:
        """:attr:`overhead_us` without the recorder's share, microseconds."""
        return self.overhead_us - self.recording_us

    @property
    def setup_ms(self) -> float:
        """Master time of the run outside the stepping loop beyond the FMI calls, ms."""
        outside = (self.wall - self.stepping_wall) - (self.fmi_seconds - self.stepping_fmi_seconds)
        return 1e3 * outside


def measure(name: str, stop_time: float | None, out: Path) -> SceneFigures:
    """Run one scene and collect its figures.

    Parameters
    ----------
    name : str
        A shipped scene's name.
    stop_time : float or None
        Simulated time, s; None keeps the scene's.
    out : Path
        Folder the scene's results go into (in a subfolder named after it).

    Returns
    -------
    SceneFigures
    """
    outcome = run_scene(name, out / name, plots=False, stop_time=stop_time)
    sim, result = outcome.simulation, outcome.result
    if result.status != "finished":
        raise RuntimeError(f"{name}: {result.status}: {result.message}")
    fmi = sum(sum(s.seconds.values()) for s in sim.slaves.values())
    recorder = next(o for o in sim.observers if isinstance(o, CsvRecorder))
    return SceneFigures(
        name,
        len(sim.slaves),
        result.steps,
        result.end_time,
        result.wall_time,
        fmi,
        result.stepping_wall_time,
        result.stepping_fmi_time,
        recorder.stepping_seconds,
        len(recorder.columns),
    )


def table(rows: list[SceneFigures]) -> str:
    """Markdown table of the figures: one row per scene.

    Parameters
    ----------
    rows : list of SceneFigures
        One per scene.
    """
    header = (
        "scene | units | macro steps | simulated s | wall s | real-time factor | "
        "master overhead per unit per step | of which recording | recorded columns | "
        "without recording | set-up and clean-up"
    )
    return markdown_table(
        header,
        (
            f"{r.scene} | {r.units} | {r.steps} | {r.simulated:g} | {r.wall:.2f} | "
            f"{r.real_time_factor:.3g} | {r.overhead_us:.1f} µs | {r.recording_us:.1f} µs | "
            f"{r.recorded_values} | {r.coupling_us:.1f} µs | {r.setup_ms:.0f} ms"
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
        __doc__.splitlines()[0],
        list(shipped_scenes()),
        "runs per scene; the one of median overhead counts",
    )
    parser.add_argument("--stop-time", type=float, help="shorten every scene to this, s")
    args = parse_scene_options(parser, argv)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes:
            runs = [measure(name, args.stop_time, Path(tmp) / str(i)) for i in range(args.repeats)]
            rows.append(sorted(runs, key=lambda r: r.overhead_us)[len(runs) // 2])
            logger.info(
                "%s: RTF %.3g, overhead %.1f µs per unit per step (recording %.1f), "
                "set-up and clean-up %.0f ms",
                name,
                rows[-1].real_time_factor,
                rows[-1].overhead_us,
                rows[-1].recording_us,
                rows[-1].setup_ms,
            )
    report_table(table(rows), args.out)


if __name__ == "__main__":
    main()

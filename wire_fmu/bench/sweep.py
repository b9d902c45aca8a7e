"""Speed-up of a sweep on two Dask workers over the same sweep run serially.

Run ``python -m wire_fmu.bench.sweep [--stop-time S] [--workers N] [--repeat N] [--out FILE]``.

The sweep is the two-mass oscillator of the master's tests (two small test
FMUs built from ``tests/support``; unit ``b``'s mass x stiffness, 8 x 5 = 40
cases), with a stop time that makes one case last about 0.5-1 s. Or give a
scene and a spec: ``--scene riser_tensioner --spec my_sweep.toml``.

*Serial* runs every case in this process, one after the other, without
Dask (``workers=0``); *parallel* starts a local cluster of N single-thread
worker processes and runs the same cases there. Both write the same results
(the key figures are checked equal). The parallel time is given with and
without starting the cluster (spawning the workers, which then import
numpy, scipy and fmpy, and load the FMUs on their first case).
"""

from __future__ import annotations

import argparse
import logging
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

from wire_fmu.bench.common import ROOT
from wire_fmu.master.scene import Scene, parse_scene
from wire_fmu.sweep import SweepResult, SweepSpec, load_sweep_spec, parse_sweep_spec, run_sweep

logger = logging.getLogger(__name__)

SUPPORT = ROOT / "tests" / "support"
MASSES = [0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0]
STIFFNESSES = [40.0, 50.0, 60.0, 70.0, 80.0]


@dataclass(frozen=True)
class Timing:
    """Figures of one benchmark run, s."""

    cases: int
    workers: int
    cores: int
    serial: float
    parallel: float
    startup: float
    mean_case: float
    mean_case_parallel: float
    load: tuple[float, float] = (0.0, 0.0)

    @property
    def speedup(self) -> float:
        """Serial over parallel wall time, cluster start included."""
        return self.serial / self.parallel

    @property
    def speedup_running(self) -> float:
        """Serial over parallel wall time once the cluster is up."""
        return self.serial / (self.parallel - self.startup)


def two_mass_scene(fmu_dir: Path, stop_time: float) -> Scene:
    """The two-mass oscillator scene, its test FMUs built into ``fmu_dir``.

    Parameters
    ----------
    fmu_dir : Path
        Folder the test FMUs are built into.
    stop_time : float
        Simulated time of each case, s.
    """
    import sys

    from wire_fmu.export.builder import build_fmu

    if not SUPPORT.is_dir():
        raise SystemExit(
            f"the test units are not here ({SUPPORT}); run from a source tree or "
            "give --scene and --spec"
        )
    sys.path.insert(0, str(SUPPORT))
    osc = build_fmu(
        SUPPORT / "facades" / "oscillator.py",
        fmu_dir,
        extra_modules=[SUPPORT / "wire_fmu_test_units.py"],
    )
    mass = build_fmu(
        SUPPORT / "facades" / "coupled_mass.py",
        fmu_dir,
        extra_modules=[SUPPORT / "wire_fmu_master_units.py"],
    )
    return parse_scene(
        {
            "name": "two_mass",
            "run": {"stop_time": stop_time, "step": 0.01},
            "units": {
                "a": {
                    "fmu": str(osc),
                    "parameters": {
                        "mass": 1.0,
                        "stiffness": 40.0,
                        "damping": 0.1,
                        "x0": 0.1,
                        "substeps": 50,
                    },
                },
                "b": {
                    "fmu": str(mass),
                    "parameters": {"mass": 2.0, "stiffness": 60.0, "damping": 0.1, "substeps": 50},
                },
            },
            "bonds": [
                {
                    "name": "spring",
                    "kind": "translational",
                    "effort": "b.force_on_flange -> a.force",
                    "flow": "a.velocity -> b.flange.velocity",
                    "position": "a.position -> b.flange.position",
                }
            ],
            "outputs": {"variables": ["a.position", "b.position"]},
        },
        base_dir=fmu_dir,
    )


def two_mass_spec() -> SweepSpec:
    """Mass x stiffness of unit b: 40 cases, three key figures."""
    return parse_sweep_spec(
        {
            "name": "bench",
            "axes": [
                {"target": "units.b.parameters.mass", "values": MASSES},
                {"target": "units.b.parameters.stiffness", "values": STIFFNESSES},
            ],
            "figures": {
                "peak_b": "max(b.position)",
                "range_a": "range(a.position)",
                "residual": "final(bond.spring.energy_residual)",
            },
        }
    )


def _figures(result: SweepResult, spec: SweepSpec) -> dict[str, tuple]:
    return {r["case_id"]: tuple(r[f.name] for f in spec.figures) for r in result.rows}


def _fastest(
    scene: Scene | str, spec: SweepSpec, workers: int, out: Path, repeat: int
) -> SweepResult:
    """The fastest of ``repeat`` complete runs (each into a fresh folder)."""
    results = []
    for i in range(repeat):
        result = run_sweep(
            scene,
            spec,
            out / f"{workers}_workers_{i}",
            workers=workers,
            progress=False,
            plots=False,
        )
        logger.info(
            "%s: %.2f s (cluster start %.2f s)",
            f"{workers} workers" if workers else "serial",
            result.wall_time,
            result.startup_time,
        )
        results.append(result)
    return min(results, key=lambda r: r.wall_time)


def measure(
    scene: Scene | str, spec: SweepSpec, workers: int, out: Path, repeat: int = 1
) -> Timing:
    """Run the sweep serially, then on ``workers`` workers; check both agree.

    Parameters
    ----------
    scene : Scene or str
        The scene, or a shipped scene's name.
    spec : SweepSpec
        The sweep.
    workers : int
        Worker processes of the local Dask cluster.
    out : Path
        Folder the runs write into.
    repeat : int
        Runs of each, the fastest counts.

    Returns
    -------
    Timing
    """
    load = os.getloadavg()[0]
    serial = _fastest(scene, spec, 0, out, repeat)
    parallel = _fastest(scene, spec, workers, out, repeat)
    if _figures(serial, spec) != _figures(parallel, spec):
        raise SystemExit("serial and parallel key figures differ")
    if not (serial.complete and parallel.complete):
        raise SystemExit(f"cases did not finish: {serial.counts} / {parallel.counts}")
    return Timing(
        len(serial.rows),
        workers,
        os.cpu_count() or 0,
        serial.wall_time,
        parallel.wall_time,
        parallel.startup_time,
        _mean_case(serial),
        _mean_case(parallel),
        (load, os.getloadavg()[0]),
    )


def _mean_case(result: SweepResult) -> float:
    return sum(r["wall_time"] for r in result.rows) / len(result.rows)


def table(t: Timing) -> str:
    """Markdown table of the figures.

    Parameters
    ----------
    t : Timing
        The sweep's timings.
    """
    return "\n".join(
        [
            f"| cases | one case, serial | one case, {t.workers} workers | serial | "
            f"{t.workers} workers | of it cluster start | speed-up | speed-up, cluster up |",
            "|---:|---:|---:|---:|---:|---:|---:|---:|",
            f"| {t.cases} | {t.mean_case:.2f} s | {t.mean_case_parallel:.2f} s | "
            f"{t.serial:.1f} s | "
            f"{t.parallel:.1f} s | {t.startup:.1f} s | {t.speedup:.2f} | {t.speedup_running:.2f} |",
            "",
            f"Machine: {t.cores} cores; load average (1 min) {t.load[0]:.1f} before, "
            f"{t.load[1]:.1f} after (other processes than the benchmark's count in it).",
        ]
    )


def main(argv: list[str] | None = None) -> None:
    """Command-line entry point.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads the command line.
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--stop-time",
        type=float,
        default=4.0,
        help="simulated s per case of the two-mass sweep (default: %(default)s)",
    )
    parser.add_argument("--workers", type=int, default=2, help="default: %(default)s")
    parser.add_argument("--scene", help="a shipped scene or scene file (with --spec)")
    parser.add_argument("--spec", type=Path, help="the sweep spec for --scene")
    parser.add_argument(
        "--repeat",
        type=int,
        default=1,
        help="runs of each; the fastest counts (default: %(default)s)",
    )
    parser.add_argument("--out", type=Path, help="also write the table (Markdown) here")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    import distributed  # noqa: F401 - configures its loggers on import; then quieten them

    logging.getLogger("distributed").setLevel(logging.WARNING)
    with tempfile.TemporaryDirectory(prefix="wire_fmu_bench_sweep_") as tmp:
        if args.scene:
            if args.spec is None:
                parser.error("--scene needs --spec")
            scene, spec = args.scene, load_sweep_spec(args.spec)
        else:
            scene, spec = two_mass_scene(Path(tmp) / "fmus", args.stop_time), two_mass_spec()
        timing = measure(scene, spec, args.workers, Path(tmp), args.repeat)
    text = table(timing)
    logger.info("\n%s", text)
    if args.out:
        args.out.write_text(text + "\n")


if __name__ == "__main__":
    main()

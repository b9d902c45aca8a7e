"""Paper 004's method against a reference: accuracy and cost of the machine unit's steady motion.

The machine (:func:`~wire_fmu.core.units.machine.spec.crank_press` by default)
is solved by the :class:`~wire_fmu.core.units.machine.unit.MachineDriveUnit`
stepped as a master would, with paper 004's energy form (``energy1``: the
first-order step (9)/(15) alone; ``energy``: with successive second-order
refinement (12)/(18)) and, for comparison, classical RK4, at a range of
internal step sizes. The reference is SciPy's DOP853 at ``rtol = 1e-12`` on
the Lagrange equation, independent of the unit.

For each run: the largest speed error at the communication points, the
error of the coefficient of non-uniformity ``delta`` of the last complete
revolution (both computed from samples at the same points, so only the
integrator differs), the torque evaluations and the wall time. The
observed order between successive halvings of the step is reported next to
the order the paper claims (1 and 2).

:func:`steady_motion_study` writes ``steady_motion.csv``, ``steady_motion.md``
and a work-precision plot ``steady_motion.png``; it needs no CLI.
"""

from __future__ import annotations

import csv
import json
import logging
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from wire_fmu.core.units.machine.cycle_statistics import CycleStatistics
from wire_fmu.core.units.machine.spec import crank_press, parse_machine
from wire_fmu.core.units.machine.unit import MachineDriveUnit

__all__ = [
    "CLAIMED_ORDERS",
    "Run",
    "Trajectory",
    "reference_trajectory",
    "unit_trajectory",
    "last_delta",
    "compare",
    "steady_motion_study",
]

logger = logging.getLogger(__name__)

CLAIMED_ORDERS: Mapping[str, int] = MappingProxyType({"energy1": 1, "energy": 2, "rk4": 4})
"""Order each solver claims (paper 004 for the energy form)."""

DEFAULT_MOTOR: Mapping[str, float] = MappingProxyType({"a": 22170.0, "b": 2117.0})
"""The crank press's motor at the crank shaft (see the ``machine_unit`` scene)."""


@dataclass(frozen=True)
class Trajectory:
    """Samples at the communication points: time (s), angle (rad), speed (rad/s)."""

    time: np.ndarray
    phi: np.ndarray
    omega: np.ndarray
    evaluations: int = 0
    wall_time: float = 0.0


@dataclass(frozen=True)
class Run:
    """Accuracy and cost of one solution.

    Attributes
    ----------
    solver : str
        ``energy1``, ``energy`` or ``rk4``.
    max_step : float
        Internal step, s.
    speed_error : float
        Largest ``|omega - omega_ref|`` at the communication points, rad/s.
    delta : float
        Coefficient of non-uniformity of the last complete revolution.
    delta_error : float
        Its error against the reference sampled alike.
    evaluations : int
        Torque evaluations.
    wall_time : float
        s.
    order : float
        Observed order against the previous (twice as long) step; nan for the first.
    """

    solver: str
    max_step: float
    speed_error: float
    delta: float
    delta_error: float
    evaluations: int
    wall_time: float
    order: float = math.nan


def _unit(
    machine: Mapping[str, Any],
    motor: Mapping[str, float],
    solver: str,
    max_step: float,
    initial_speed: float,
) -> MachineDriveUnit:
    unit = MachineDriveUnit("study")
    unit.values.update(
        {
            "machine": json.dumps(machine),
            "motor_slope": motor["b"],
            "motor.command": motor["a"],
            "solver": solver,
            "solver_max_step": max_step,
            "initial_speed": initial_speed,
        }
    )
    unit.configure()
    unit.initialize(0.0)
    return unit


def unit_trajectory(
    solver: str,
    max_step: float,
    *,
    stop_time: float,
    step: float,
    machine: Mapping[str, Any] | None = None,
    motor: Mapping[str, float] | None = None,
    initial_speed: float = 10.0,
) -> Trajectory:
    """Step the machine unit with ``solver``; samples at every communication point.

    Parameters
    ----------
    solver : str
        The unit's solver (``energy1``, ``energy``, ``rk4``, ...).
    max_step : float
        Internal step, s.
    stop_time : float
        End of the simulated window, s.
    step : float
        Communication step, s.
    machine : mapping, optional
        Machine description (default :func:`~wire_fmu.core.units.machine.spec.crank_press`).
    motor : mapping, optional
        Motor characteristic ``a`` (N m) and ``b`` (N m s/rad) at the shaft
        (default :data:`DEFAULT_MOTOR`).
    initial_speed : float
        Shaft speed at t = 0, rad/s.
    """
    unit = _unit(machine or crank_press(), motor or DEFAULT_MOTOR, solver, max_step, initial_speed)
    n = int(round(stop_time / step))
    phi, omega = [unit.values["shaft.angle"]], [unit.values["shaft.speed"]]
    start = time.perf_counter()
    for i in range(n):
        result = unit.advance(i * step, step)
        if not result.success:
            raise RuntimeError(result.message)
        phi.append(unit.values["shaft.angle"])
        omega.append(unit.values["shaft.speed"])
    wall = time.perf_counter() - start
    return Trajectory(
        step * np.arange(n + 1),
        np.array(phi),
        np.array(omega),
        int(unit.values["solver.evaluations"]),
        wall,
    )


def reference_trajectory(
    times: np.ndarray,
    *,
    machine: Mapping[str, Any] | None = None,
    motor: Mapping[str, float] | None = None,
    initial_speed: float = 10.0,
) -> Trajectory:
    """DOP853 at ``rtol = atol = 1e-12`` on the Lagrange equation, sampled at ``times``.

    Parameters
    ----------
    times : ndarray
        Sample times from 0, s.
    machine : mapping, optional
        Machine description (default :func:`~wire_fmu.core.units.machine.spec.crank_press`).
    motor : mapping, optional
        Motor characteristic ``a`` (N m) and ``b`` (N m s/rad) at the shaft
        (default :data:`DEFAULT_MOTOR`).
    initial_speed : float
        Shaft speed at t = 0, rad/s.
    """
    spec, problems = parse_machine(machine or crank_press())
    if spec is None:
        raise ValueError("; ".join(problems))
    motor = motor or DEFAULT_MOTOR
    unit = spec.machine(motor["a"], motor["b"])
    start = time.perf_counter()
    sol = solve_ivp(
        unit.rhs_time,
        (0.0, float(times[-1])),
        [0.0, initial_speed],
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
        t_eval=times,
    )
    wall = time.perf_counter() - start
    if not sol.success:
        raise RuntimeError(f"reference failed: {sol.message}")
    return Trajectory(np.asarray(times), sol.y[0], sol.y[1], int(sol.nfev), wall)


def last_delta(trajectory: Trajectory) -> float:
    """``delta`` of the last complete revolution, from the samples (as the unit reports it).

    Parameters
    ----------
    trajectory : Trajectory
        Samples of angle (rad) and speed (rad/s).
    """
    stats = CycleStatistics()
    t, phi, omega = trajectory.time, trajectory.phi, trajectory.omega
    stats.start(float(t[0]), float(phi[0]), float(omega[0]))
    for i in range(1, t.size):
        stats.update(float(t[i - 1]), (phi[i - 1], omega[i - 1]), float(t[i]), (phi[i], omega[i]))
    return float(stats.last["delta"])


def compare(
    solver: str,
    max_steps: Sequence[float],
    *,
    stop_time: float,
    step: float,
    reference: Trajectory,
    **machine_kw,
) -> list[Run]:
    """Accuracy and cost of ``solver`` at each internal step, with observed orders.

    Parameters
    ----------
    solver : str
        The unit's solver.
    max_steps : sequence of float
        Internal steps, s, largest first (orders between successive ones).
    stop_time : float
        End of the simulated window, s.
    step : float
        Communication step, s.
    reference : Trajectory
        The reference at the same communication points.
    **machine_kw
        ``machine``, ``motor``, ``initial_speed`` of :func:`unit_trajectory`.
    """
    ref_delta = last_delta(reference)
    runs: list[Run] = []
    for h in max_steps:
        traj = unit_trajectory(solver, h, stop_time=stop_time, step=step, **machine_kw)
        error = float(np.max(np.abs(traj.omega - reference.omega)))
        delta = last_delta(traj)
        order = math.nan
        if runs and error > 0.0 and runs[-1].speed_error > 0.0:
            order = math.log(runs[-1].speed_error / error) / math.log(runs[-1].max_step / h)
        runs.append(
            Run(
                solver,
                h,
                error,
                delta,
                abs(delta - ref_delta),
                traj.evaluations,
                traj.wall_time,
                order,
            )
        )
        logger.info(
            "%s h=%.3g: speed error %.3g, delta %.6f, %d evaluations",
            solver,
            h,
            error,
            delta,
            traj.evaluations,
        )
    return runs


def steady_motion_study(
    directory: Path,
    *,
    stop_time: float = 5.0,
    step: float = 0.01,
    max_steps: Sequence[float] = (1e-2, 5e-3, 2.5e-3, 1.25e-3, 6.25e-4),
    solvers: Sequence[str] = ("energy1", "energy", "rk4"),
) -> dict:
    """Run the comparison and write its CSV, Markdown table and work-precision plot.

    Parameters
    ----------
    directory : Path
        Folder for the files (created).
    stop_time : float
        End of the simulated window, s.
    step : float
        Communication step, s.
    max_steps : sequence of float
        Internal steps of each solver, s.
    solvers : sequence of str
        The unit's solvers compared.

    Returns
    -------
    dict
        ``runs`` (list of :class:`Run`), ``reference_delta``, ``files`` (name -> Path).
    """
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    times = step * np.arange(int(round(stop_time / step)) + 1)
    reference = reference_trajectory(times)
    runs = [
        r
        for s in solvers
        for r in compare(s, max_steps, stop_time=stop_time, step=step, reference=reference)
    ]
    files = {
        "csv": directory / "steady_motion.csv",
        "md": directory / "steady_motion.md",
        "png": directory / "steady_motion.png",
    }
    _write_csv(files["csv"], runs)
    files["md"].write_text(_markdown(runs, last_delta(reference), reference))
    _plot(files["png"], runs)
    return {"runs": runs, "reference_delta": last_delta(reference), "files": files}


def _write_csv(path: Path, runs: list[Run]) -> None:
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(asdict(runs[0])))
        writer.writeheader()
        for run in runs:
            writer.writerow(asdict(run))


def _markdown(runs: list[Run], ref_delta: float, reference: Trajectory) -> str:
    lines = [
        "# Machine unit in steady motion: paper 004's method against a reference",
        "",
        f"Reference: DOP853, rtol 1e-12 ({reference.evaluations} evaluations); "
        f"delta of the last revolution {ref_delta:.6f}.",
        "",
        "| solver | claimed order | step (s) | max speed error (rad/s) | observed order "
        "| delta | delta error | evaluations | wall time (s) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in runs:
        order = "" if math.isnan(r.order) else f"{r.order:.2f}"
        lines.append(
            f"| {r.solver} | {CLAIMED_ORDERS.get(r.solver, '')} | {r.max_step:.3g} | "
            f"{r.speed_error:.3e} | {order} | {r.delta:.6f} | {r.delta_error:.2e} | "
            f"{r.evaluations} | {r.wall_time:.3f} |"
        )
    return "\n".join(lines) + "\n"


def _plot(path: Path, runs: list[Run]) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 4.5), dpi=100, layout="constrained")
    left, right = fig.subplots(1, 2)
    for i, solver in enumerate(dict.fromkeys(r.solver for r in runs)):
        mine = [r for r in runs if r.solver == solver]
        label = f"{solver} (order {CLAIMED_ORDERS.get(solver, '?')})"
        left.loglog(
            [r.max_step for r in mine],
            [r.speed_error for r in mine],
            "o-",
            color=f"C{i}",
            label=label,
        )
        right.loglog(
            [r.evaluations for r in mine],
            [r.speed_error for r in mine],
            "o-",
            color=f"C{i}",
            label=label,
        )
    left.set_xlabel("internal step (s)")
    right.set_xlabel("torque evaluations")
    for ax in (left, right):
        ax.set_ylabel("max speed error (rad/s)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize="small")
    left.set_title("Convergence in the step")
    right.set_title("Work-precision")
    fig.suptitle("Machine unit (crank press): paper 004's energy form against a reference")
    fig.savefig(path)

"""Cost of one doStep of the winch, per effect set and per internal solver.

Run ``python -m wire_fmu.bench.winch [--steps N] [--out FILE]``. Every case
steps the same drawworks manoeuvre -- lowering a 120 t hook on 10 lines
(fast-line tension 1.2e5 N) with the motor holding back lightly, then an
emergency stop on the band brake at t = 1 s and holding -- in the core and
through the built FMU; see :mod:`wire_fmu.bench.common` for what is timed.
Without ``drum_inertia`` the drive is speed commanded (5 rad/s, then 0).
The last rows compare the internal solvers on the rigid drum with rope
layers and a soft motor characteristic (b = 50 N m s/rad at the motor, so
the drum spins up to about 25 rad/s in the first second), where paper 004's
energy form applies;
a second table gives their accuracy (rope paid out against Radau at rtol
1e-11) at two internal step sizes.
"""

from __future__ import annotations

import logging

from wire_fmu.bench.common import Case, command_line, run_cases
from wire_fmu.core.units.winch.model import WINCH_EFFECTS
from wire_fmu.core.units.winch.unit import WinchUnit

logger = logging.getLogger(__name__)

STEP = 0.01  # s, communication step
STOP_STEP = 100  # the brake is applied here (t = 1 s)
OUTPUTS = (
    "rope.payout",
    "rope.payout_rate",
    "drum.speed",
    "brake.torque",
    "stored_energy",
    "energy_balance",
)
SOLVERS = ("rk4", "ros2", "radau", "energy", "energy1")
SOLVER_EFFECTS = "drum_inertia,motor_characteristic,rope_layers"
SOLVER_REALS = {"motor_slope": 50.0}  # a soft characteristic: the drum really spins up


def effect_sets() -> list[str]:
    """Kinetostatic alone and with the brake, the drum alone, each effect on the drum, all."""
    on_drum = [e.name for e in WINCH_EFFECTS.effects if e.name != "drum_inertia"]
    sets = ["", "band_brake", "drum_inertia"]
    sets += [f"drum_inertia,{name}" for name in on_drum]
    sets.append(",".join(WINCH_EFFECTS.names))
    return sets


def lowering_then_stop(i: int) -> dict[str, float]:
    """Inputs at step ``i``: lower for 1 s, then brake hard and hold.

    Parameters
    ----------
    i : int
        Step number, from 0.

    Returns
    -------
    dict of str to float
        ``rope.tension`` (N), ``motor.command`` (N m), ``brake.lever_force`` (N)
        and ``drum.speed_command`` (rad/s).
    """
    stopping = i >= STOP_STEP
    return {
        "rope.tension": 1.2e5,
        "motor.command": -300.0,
        "brake.lever_force": 2500.0 if stopping else 0.0,
        "drum.speed_command": 0.0 if stopping else 5.0,
    }


def cases() -> list[Case]:
    """One case per effect set (default solver), then one per solver on the rigid drum."""
    out = [
        Case(
            effects or "(none: kinetostatic)",
            WinchUnit,
            {"effects": effects},
            inputs=lowering_then_stop,
            outputs=OUTPUTS,
            step=STEP,
        )
        for effects in effect_sets()
    ]
    out += [
        Case(
            f"{SOLVER_EFFECTS} [{solver}]",
            WinchUnit,
            {"effects": SOLVER_EFFECTS, "solver": solver},
            SOLVER_REALS,
            inputs=lowering_then_stop,
            outputs=OUTPUTS,
            step=STEP,
        )
        for solver in SOLVERS
    ]
    return out


def _payout_after(
    solver: str, max_step: float, steps: int, rtol: float = 1e-6
) -> tuple[float, float]:
    """Rope paid out after ``steps`` steps of the manoeuvre, and core ms per step."""
    import time

    unit = WinchUnit("accuracy")
    unit.values.update(
        {
            "effects": SOLVER_EFFECTS,
            "solver": solver,
            "solver_max_step": max_step,
            "solver_rtol": rtol,
            "solver_atol": rtol * 1e-3,
            **SOLVER_REALS,
        }
    )
    unit.configure()
    unit.initialize(0.0)
    start = time.perf_counter()
    for i in range(steps):
        unit.values.update(lowering_then_stop(i))
        result = unit.advance(i * STEP, STEP)
        if not result.success:
            raise RuntimeError(result.message)
    return unit.values["rope.payout"], (time.perf_counter() - start) / steps * 1e3


def accuracy_table(steps: int) -> str:
    """Error of the rope paid out against Radau at rtol 1e-11, per solver and step (Markdown).

    Parameters
    ----------
    steps : int
        Steps of the manoeuvre run with each solver.
    """
    reference, _ = _payout_after("radau", 1e-3, steps, rtol=1e-11)
    lines = ["| solver | max step s | payout error m | core ms/step |", "|---|---:|---:|---:|"]
    for solver in SOLVERS:
        for max_step in (4e-3, 1e-3):
            payout, ms = _payout_after(solver, max_step, steps)
            lines.append(f"| {solver} | {max_step:g} | {abs(payout - reference):.2e} | {ms:.3f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    """Command-line entry point.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads the command line.
    """
    args = command_line(__doc__.splitlines()[0], argv)
    text = run_cases(
        "Winch",
        cases(),
        args.steps,
        f"Winch (default drawworks drive train), max internal step 1 ms, "
        f"communication step {STEP:g} s",
    )
    accuracy = accuracy_table(args.steps)
    logger.info(
        "\nAccuracy of the internal solvers on %s after %d steps:\n%s",
        SOLVER_EFFECTS,
        args.steps,
        accuracy,
    )
    text += "\n\n" + accuracy
    if args.out:
        args.out.write_text(text + "\n")


if __name__ == "__main__":
    main()

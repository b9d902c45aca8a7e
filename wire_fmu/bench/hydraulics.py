"""Cost of one doStep of the riser-tensioner cylinder, per effect set, and its FMI overhead.

Run ``python -m wire_fmu.bench.hydraulics [--steps N] [--out FILE]``. Each
effect set steps the same manoeuvre with the unit's defaults (an 80 kip
wire-line tensioner reeved 4:1, starting in equilibrium): the rope force
varies by 2 % at the 0.2 Hz of a heave plus 1 % at 1.3 Hz, so the seals
stick and slip. A second manoeuvre (``impact``) releases 15 % of the load:
the rod runs through the cushion onto the extension stop, where the fixed-step
solver refines. See :mod:`wire_fmu.bench.common` for what is timed.
"""

from __future__ import annotations

import logging
import math

from wire_fmu.bench.common import Case, unit_benchmark
from wire_fmu.core.units.hydraulics.model import HYDRAULICS_EFFECTS
from wire_fmu.core.units.hydraulics.unit import DEFAULT_ROD_FORCE, HydraulicsUnit

logger = logging.getLogger(__name__)

STEP = 0.01  # s, communication step
OUTPUTS = (
    "rod.position",
    "rod.velocity",
    "chamber.pressure",
    "gas.pressure",
    "stored_energy",
    "energy_balance",
)


def effect_sets() -> list[str]:
    """None, each effect alone, and all effects together."""
    names = HYDRAULICS_EFFECTS.names
    return ["", *names, ",".join(names)]


def heave(i: int) -> dict[str, float]:
    """Rope force on the rod at step ``i``: a heave-like variation about the rated load.

    Parameters
    ----------
    i : int
        Step number, from 0.

    Returns
    -------
    dict of str to float
        ``rod.force``, N.
    """
    t = i * STEP
    variation = 0.02 * math.sin(2 * math.pi * 0.2 * t) + 0.01 * math.sin(2 * math.pi * 1.3 * t)
    return {"rod.force": DEFAULT_ROD_FORCE * (1.0 + variation)}


def impact(i: int) -> dict[str, float]:
    """Rated load for 0.2 s, then 15 % of it is lost: the rod runs onto its stop.

    Parameters
    ----------
    i : int
        Step number, from 0.

    Returns
    -------
    dict of str to float
        ``rod.force``, N.
    """
    return {"rod.force": DEFAULT_ROD_FORCE * (1.0 if i < 20 else 0.85)}


def cases() -> list[Case]:
    """One heave case per effect set, and the stop impact with every effect."""
    out = [
        Case(
            effects or "(none)",
            HydraulicsUnit,
            {"effects": effects},
            inputs=heave,
            outputs=OUTPUTS,
            step=STEP,
        )
        for effects in effect_sets()
    ]
    everything = effect_sets()[-1]
    out.append(
        Case(
            "all effects, impact on the stop",
            HydraulicsUnit,
            {"effects": everything},
            inputs=impact,
            outputs=OUTPUTS,
            step=STEP,
        )
    )
    return out


def main(argv: list[str] | None = None) -> None:
    """Command-line entry point.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads the command line.
    """
    title = f"Riser-tensioner cylinder, ros2, max internal step 1 ms, communication step {STEP:g} s"
    unit_benchmark(__doc__.splitlines()[0], "Hydraulics", cases(), title, argv)


if __name__ == "__main__":
    main()

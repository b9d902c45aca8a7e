"""What stops a cylinder: the limits that refuse a step and the starts it cannot take."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from wire_fmu.core.components.end_stops import RETRACTED
from wire_fmu.core.components.gas import isothermal_charge_volume
from wire_fmu.core.errors import ConfigurationError

if TYPE_CHECKING:
    from wire_fmu.core.units.hydraulics.model import HydraulicsModel

__all__ = ["check_start", "limit_message"]


def limit_message(model: HydraulicsModel, kind: str, end: int, x: np.ndarray, t: float) -> str:
    """Why a limit refuses the step, with the quantities involved.

    Parameters
    ----------
    model : HydraulicsModel
        The cylinder.
    kind : str
        The limit's guard: ``gas_dead``, ``gas_empty``, ``cavitation`` or ``stroke``.
    end : int
        For ``stroke``: which end.
    x : numpy.ndarray
        The state at the limit.
    t : float
        Its time, s.
    """
    acc = model.spec.accumulator
    v_gas = model.gas_volume(x)
    if kind == "gas_dead":
        return (
            f"gas volume {v_gas:.6g} m3 reached its dead volume {acc.dead_volume:.6g} m3 "
            f"at t = {t:.9g} s (accumulator full of oil; gas pressure "
            f"{model.gas.pressure(max(v_gas, acc.dead_volume)):.6g} Pa): "
            "the rod is driven towards zero gas volume"
        )
    if kind == "gas_empty":
        return (
            f"gas volume {v_gas:.6g} m3 reached the empty-accumulator volume "
            f"{acc.full_volume:.6g} m3 at t = {t:.9g} s: no oil left to feed the cylinder"
        )
    if kind == "cavitation":
        point = model.evaluate(t, x)
        p_c = model.chamber_pressure(point, model._accelerate(point)[0])
        return (
            f"chamber pressure {p_c:.6g} Pa fell to the cavitation pressure "
            f"{model.spec.oil.cavitation_pressure:.6g} Pa at t = {t:.9g} s "
            f"(rod velocity {x[1]:.6g} m/s)"
        )
    where = "below 0 m" if end == RETRACTED else f"beyond the stroke {model.cyl.stroke:.6g} m"
    return (
        f"rod extension {x[0]:.6g} m went {where} at t = {t:.9g} s; "
        "add the effect 'end_stops' to model cushions and stops"
    )


def check_start(model: HydraulicsModel, pressure: float, position: float, velocity: float) -> None:
    """Refuse a start the cylinder cannot take, naming every problem.

    Parameters
    ----------
    model : HydraulicsModel
        The cylinder.
    pressure : float
        Initial absolute gas pressure, Pa.
    position : float
        Initial rod position, m.
    velocity : float
        Initial rod velocity, m/s.

    Raises
    ------
    ConfigurationError
        Listing every problem.
    """
    problems = []
    acc = model.spec.accumulator
    if not (pressure > 0.0 and math.isfinite(pressure)):
        problems.append(
            f"initial gas pressure must be > 0 Pa, got {pressure:.6g} Pa (the "
            "rod force would pull the rod out against vacuum)"
        )
    elif pressure < acc.precharge_pressure * (1.0 - 1e-12):
        problems.append(
            f"initial gas pressure {pressure:.6g} Pa is below the pre-charge "
            f"{acc.precharge_pressure:.6g} Pa: the accumulator would hold no oil; "
            + _precharge_window(pressure, acc)
        )
    elif (
        isothermal_charge_volume(acc.precharge_pressure, acc.full_volume, pressure)
        <= acc.dead_volume
    ):
        problems.append(
            f"initial gas pressure {pressure:.6g} Pa needs more oil than the "
            f"accumulator holds (pre-charge {acc.precharge_pressure:.6g} Pa); "
            + _precharge_window(pressure, acc)
        )
    if not (0.0 <= position <= model.cyl.stroke):
        problems.append(
            f"parameter 'initial_position' must lie in [0, stroke = "
            f"{model.cyl.stroke:.6g}] m, got {position}"
        )
    if not math.isfinite(velocity):
        problems.append(f"parameter 'initial_velocity' must be finite, got {velocity}")
    if problems:
        raise ConfigurationError("hydraulics", problems)


def _precharge_window(pressure: float, acc) -> str:
    """The pre-charge pressures that start with oil in the accumulator, but not too much.

    Parameters
    ----------
    pressure : float
        Initial absolute gas pressure, Pa.
    acc : AccumulatorSpec
        The accumulator.
    """
    low = pressure * acc.dead_volume / acc.full_volume
    return (
        f"'precharge_pressure' must lie in ({low:.6g}, {pressure:.6g}] Pa for this start "
        "(or change the load, which sets the starting pressure)"
    )

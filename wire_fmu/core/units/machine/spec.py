"""A machine unit's laws together: the specification, read from JSON data, and a default."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from wire_fmu.core.framework.machine_unit import MachineUnit
from wire_fmu.core.units.machine.laws import (
    CrankSliderInertia,
    FourierInertia,
    FourierSeries,
    Polynomial,
)

__all__ = ["MachineSpec", "parse_machine", "crank_press"]

_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class MachineSpec:
    """A machine unit's laws (:mod:`wire_fmu.core.units.machine.model`).

    Parameters
    ----------
    inertia : CrankSliderInertia or FourierInertia
        ``I(phi)``.
    resistance_angle : FourierSeries
        ``M_c(phi)``, N m (period ``2 pi``).
    resistance_speed : Polynomial
        ``M_c(omega)``, N m.
    resistance_time : FourierSeries
        ``M_c(t)``, N m (period in s).
    """

    inertia: CrankSliderInertia | FourierInertia
    resistance_angle: FourierSeries = field(default_factory=FourierSeries)
    resistance_speed: Polynomial = field(default_factory=Polynomial)
    resistance_time: FourierSeries = field(default_factory=lambda: FourierSeries(period=1.0))

    def machine(self, a: float, b: float, load: float = 0.0) -> MachineUnit:
        """Paper 004's :class:`MachineUnit` for motor ``a - b omega`` and an extra load (N m).

        Parameters
        ----------
        a : float
            Motor torque at zero speed, N m.
        b : float
            Slope of the motor characteristic, N m s/rad.
        load : float, optional
            Extra load torque added to ``M_c(t)``, N m.
        """
        time_law = self.resistance_time
        angle_law = self.resistance_angle
        return MachineUnit(
            inertia=self.inertia,
            inertia_slope=self.inertia.derivative,
            a=a,
            b=b,
            resistance_angle=angle_law,
            resistance_angle_work=angle_law.integral,
            resistance_speed=self.resistance_speed,
            resistance_speed_slope=self.resistance_speed.derivative,
            resistance_time=(lambda t: time_law(t) + load) if load else time_law,
        )


def crank_press() -> dict[str, Any]:
    """A crank press (or reciprocating compressor) reduced to its crank shaft.

    Estimated values (paper 004 gives none): a 7.5 kW, 1500 rpm induction
    motor through belt and gears of 1:15 (crank at about 96 rpm); flywheel
    40 kg m^2 plus the rotor's 0.05 kg m^2 times 15^2, about 50 kg m^2; a
    200 kg slider on a 0.1 m crank and a 0.5 m rod, so ``I`` varies between
    50 and 52 kg m^2; the technological load ``550 + 450 cos(phi) + 150
    cos(2 phi)`` N m (working stroke around ``phi = 0``); bearing and
    ventilation losses ``20 omega + omega^2`` N m; a feed that varies with a
    1.5 s period, ``50 sin(2 pi t / 1.5)`` N m.
    """
    return {
        "inertia": {
            "kind": "crank_slider",
            "base": 50.0,
            "crank": 0.1,
            "rod": 0.5,
            "slider_mass": 200.0,
        },
        "resistance_angle": {"mean": 550.0, "cos": [450.0, 150.0]},
        "resistance_speed": {"coefficients": [0.0, 20.0, 1.0]},
        "resistance_time": {"mean": 0.0, "sin": [50.0], "period": 1.5},
    }


# ============================================================== parsing
def _floats(value: Any, where: str, problems: list[str]) -> tuple[float, ...]:
    if value is None:
        return ()
    try:
        out = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        problems.append(f"{where} must be a list of numbers, got {value!r}")
        return ()
    if not all(math.isfinite(v) for v in out):
        problems.append(f"{where} must be finite, got {value!r}")
    return out


def _float(
    item: Mapping[str, Any], key: str, default: float | None, where: str, problems: list[str]
) -> float:
    value = item.get(key, default)
    try:
        out = float(value)
    except (TypeError, ValueError):
        problems.append(f"{where}: {key!r} must be a number, got {value!r}")
        return math.nan
    if not math.isfinite(out):
        problems.append(f"{where}: {key!r} must be finite, got {value!r}")
    return out


def _table(data: Mapping[str, Any], key: str, known: set[str], problems: list[str]) -> dict:
    item = data.get(key, {})
    if not isinstance(item, Mapping):
        problems.append(f"machine: {key!r} must be a table, got {item!r}")
        return {}
    unknown = sorted(set(item) - known)
    if unknown:
        problems.append(f"machine {key}: unknown keys {unknown}; known: {sorted(known)}")
    return dict(item)


def _series(
    item: Mapping[str, Any], where: str, period: float, problems: list[str]
) -> FourierSeries:
    series = FourierSeries(
        _float(item, "mean", 0.0, where, problems),
        _floats(item.get("cos"), f"{where} 'cos'", problems),
        _floats(item.get("sin"), f"{where} 'sin'", problems),
        _float(item, "period", period, where, problems),
    )
    if not series.period > 0.0:
        problems.append(f"{where}: 'period' must be > 0, got {series.period}")
    return series


def _inertia(data: Mapping[str, Any], problems: list[str]):
    item = _table(
        data,
        "inertia",
        {"kind", "base", "crank", "rod", "slider_mass", "mean", "cos", "sin"},
        problems,
    )
    kind = item.get("kind", "crank_slider")
    if kind == "crank_slider":
        law = CrankSliderInertia(
            *(
                _float(item, k, None, "machine inertia", problems)
                for k in ("base", "crank", "rod", "slider_mass")
            )
        )
    elif kind == "fourier":
        law = FourierInertia(_series(item, "machine inertia", _TWO_PI, problems))
    else:
        problems.append(
            f"machine inertia: 'kind' must be 'crank_slider' or 'fourier', got {kind!r}"
        )
        return None
    if not problems:
        problems += law.problems()
    return law


def parse_machine(data: Any) -> tuple[MachineSpec | None, list[str]]:
    """A :class:`MachineSpec` from JSON data (see :func:`crank_press`); every problem found.

    Parameters
    ----------
    data : mapping
        Tables ``inertia``, ``resistance_angle``, ``resistance_speed`` and
        ``resistance_time``.

    Returns
    -------
    spec : MachineSpec or None
        None when there are problems.
    problems : list of str
        Every problem, one sentence each.
    """
    if not isinstance(data, Mapping):
        return None, [f"machine must be a table, got {data!r}"]
    problems: list[str] = []
    unknown = sorted(
        set(data) - {"inertia", "resistance_angle", "resistance_speed", "resistance_time"}
    )
    if unknown:
        problems.append(
            f"machine: unknown keys {unknown}; known: inertia, resistance_angle, "
            "resistance_speed, resistance_time"
        )
    fourier = {"mean", "cos", "sin"}
    angle = _series(
        _table(data, "resistance_angle", fourier, problems),
        "machine resistance_angle",
        _TWO_PI,
        problems,
    )
    speed_item = _table(data, "resistance_speed", {"coefficients"}, problems)
    speed = Polynomial(
        _floats(speed_item.get("coefficients"), "machine resistance_speed 'coefficients'", problems)
    )
    time_item = _table(data, "resistance_time", fourier | {"period"}, problems)
    time_law = _series(time_item, "machine resistance_time", 1.0, problems)
    inertia = _inertia(data, problems)
    if problems or inertia is None:
        return None, problems
    return MachineSpec(inertia, angle, speed, time_law), []

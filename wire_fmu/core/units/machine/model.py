"""Paper 004's machine unit in steady motion: laws of I(phi) and of the resistances, and the model.

A machine unit (SPEC section 9) is one rigid degree of freedom: the main
shaft's angle ``phi`` (rad) and speed ``omega`` (rad/s), everything reduced
to the main shaft. The paper treats it in general; here its ingredients are
configurable laws:

reduced inertia ``I(phi)`` (kg m^2)
    ``crank_slider``: ``I0 + m x'(phi)^2`` for a slider of mass ``m``
    driven by a crank ``r`` through a rod ``l`` (``x = r cos(phi) +
    sqrt(l^2 - r^2 sin^2(phi))``, exact, no series), or ``fourier``:
    ``I0 + sum a_k cos(k phi) + b_k sin(k phi)``;
resistance of the angle ``M_c(phi)`` (N m)
    a Fourier series in ``phi`` with its work integrated exactly (the
    technological load of a cyclic machine);
resistance of the speed ``M_c(omega)`` (N m)
    a polynomial ``sum c_j omega^j`` (bearings, ventilation);
resistance of time ``M_c(t)`` (N m)
    a Fourier series in ``t`` of a given period (a load that varies with
    time, unrelated to the shaft's cycle), plus the ``load.torque`` input.

The motor has the linear characteristic ``M_d = a - b omega`` (paper 004,
eq. 6), ``a`` an input (``motor.command``), ``b`` a parameter.

:class:`MachineDriveModel` is both a :class:`~wire_fmu.core.framework.hybrid.HybridSystem`
(for the reference integrators) and a
:class:`~wire_fmu.core.framework.energy_integrator.RigidMachineSystem` (for paper 004's
energy-form integrator, :class:`~wire_fmu.core.framework.energy_integrator.EnergyFormSolver`),
so the same machine is solved both ways.

Steady motion and its non-uniformity
------------------------------------
:class:`CycleStatistics` watches the main shaft complete each revolution
(``phi`` passing a multiple of ``2 pi``, located by cubic Hermite
interpolation between steps) and reports the revolution's period, mean
speed ``omega_mean = 2 pi / period`` and the coefficient of non-uniformity
(Artobolevsky) ``delta = (omega_max - omega_min) / omega_mean``, the extremes
taken over the step ends.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from wire_fmu.core.framework.energy_integrator import MachineUnit, StepWork

__all__ = [
    "FourierSeries",
    "CrankSliderInertia",
    "FourierInertia",
    "Polynomial",
    "MachineSpec",
    "parse_machine",
    "crank_press",
    "MachineDriveModel",
    "CycleStatistics",
]

_TWO_PI = 2.0 * math.pi


# ============================================================== laws
@dataclass(frozen=True)
class FourierSeries:
    """``mean + sum_k a_k cos(k w x) + b_k sin(k w x)`` with ``w = 2 pi / period``.

    Parameters
    ----------
    mean : float
        Constant term.
    cos, sin : tuple of float
        Coefficients of harmonics 1, 2, ...
    period : float
        Period in ``x`` (``2 pi`` for a law of the shaft angle).
    """

    mean: float = 0.0
    cos: tuple[float, ...] = ()
    sin: tuple[float, ...] = ()
    period: float = _TWO_PI

    @property
    def rate(self) -> float:
        """``w = 2 pi / period``."""
        return _TWO_PI / self.period

    def __call__(self, x: float) -> float:
        """Value at ``x``."""
        w = self.rate
        total = self.mean
        for k, a in enumerate(self.cos, start=1):
            total += a * math.cos(k * w * x)
        for k, b in enumerate(self.sin, start=1):
            total += b * math.sin(k * w * x)
        return total

    def derivative(self, x: float) -> float:
        """``d/dx``."""
        w = self.rate
        total = 0.0
        for k, a in enumerate(self.cos, start=1):
            total -= a * k * w * math.sin(k * w * x)
        for k, b in enumerate(self.sin, start=1):
            total += b * k * w * math.cos(k * w * x)
        return total

    def integral(self, x0: float, x1: float) -> float:
        """``int_x0^x1`` exactly."""
        w = self.rate
        total = self.mean * (x1 - x0)
        for k, a in enumerate(self.cos, start=1):
            total += a * (math.sin(k * w * x1) - math.sin(k * w * x0)) / (k * w)
        for k, b in enumerate(self.sin, start=1):
            total -= b * (math.cos(k * w * x1) - math.cos(k * w * x0)) / (k * w)
        return total

    def amplitude_bound(self) -> float:
        """``sum |a_k| + |b_k|``: the series never strays further from its mean."""
        return float(sum(abs(c) for c in self.cos) + sum(abs(c) for c in self.sin))


@dataclass(frozen=True)
class CrankSliderInertia:
    """``I(phi) = I0 + m x'(phi)^2`` of a central crank-slider mechanism.

    Parameters
    ----------
    base : float
        ``I0``: flywheel, crank and the motor and gears reduced to the shaft, kg m^2.
    crank, rod : float
        Crank radius ``r`` and connecting-rod length ``l > r``, m.
    slider_mass : float
        Mass moving with the slider (with a share of the rod), kg.
    """

    base: float
    crank: float
    rod: float
    slider_mass: float

    def _slider(self, phi: float) -> tuple[float, float]:
        """``(x', x'')``: slider speed and acceleration per crank angle (m/rad, m/rad^2)."""
        r, rod = self.crank, self.rod
        s, c = math.sin(phi), math.cos(phi)
        root = math.sqrt(rod * rod - r * r * s * s)
        x1 = -r * s - r * r * s * c / root
        x2 = -r * c - r * r * (c * c - s * s) / root - r**4 * s * s * c * c / root**3
        return x1, x2

    def __call__(self, phi: float) -> float:
        """``I(phi)``, kg m^2."""
        x1, _ = self._slider(phi)
        return self.base + self.slider_mass * x1 * x1

    def derivative(self, phi: float) -> float:
        """``dI/dphi``, kg m^2/rad."""
        x1, x2 = self._slider(phi)
        return 2.0 * self.slider_mass * x1 * x2

    def problems(self) -> list[str]:
        """Every problem with the mechanism's numbers."""
        out = []
        if not (self.base > 0.0 and math.isfinite(self.base)):
            out.append(f"inertia: 'base' must be > 0 kg m^2, got {self.base}")
        if not (0.0 < self.crank < self.rod):
            out.append(f"inertia: need 0 < crank < rod, got crank {self.crank}, rod {self.rod}")
        if not (self.slider_mass >= 0.0 and math.isfinite(self.slider_mass)):
            out.append(f"inertia: 'slider_mass' must be >= 0 kg, got {self.slider_mass}")
        return out


@dataclass(frozen=True)
class FourierInertia:
    """``I(phi)`` as a Fourier series in the shaft angle (kg m^2)."""

    series: FourierSeries

    def __call__(self, phi: float) -> float:
        """``I(phi)``, kg m^2."""
        return self.series(phi)

    def derivative(self, phi: float) -> float:
        """``dI/dphi``, kg m^2/rad."""
        return self.series.derivative(phi)

    def problems(self) -> list[str]:
        """The inertia must stay positive for every angle."""
        if self.series.mean - self.series.amplitude_bound() > 0.0:
            return []
        return [
            f"inertia: the Fourier series may reach zero or below (mean "
            f"{self.series.mean}, harmonics up to {self.series.amplitude_bound()} kg m^2)"
        ]


@dataclass(frozen=True)
class Polynomial:
    """``sum_j c_j x^j``."""

    coefficients: tuple[float, ...] = ()

    def __call__(self, x: float) -> float:
        """Value at ``x``."""
        total = 0.0
        for c in reversed(self.coefficients):
            total = total * x + c
        return total

    def derivative(self, x: float) -> float:
        """``d/dx``."""
        total = 0.0
        for j in range(len(self.coefficients) - 1, 0, -1):
            total = total * x + j * self.coefficients[j]
        return total


@dataclass(frozen=True)
class MachineSpec:
    """A machine unit's laws (module docstring).

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
        """Paper 004's :class:`MachineUnit` for motor ``a - b omega`` and an extra load (N m)."""
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
    """A :class:`MachineSpec` from JSON data (see :func:`crank_press`); every problem found."""
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


# ============================================================== the model
class MachineDriveModel:
    """The machine unit as a hybrid ODE and as a rigid machine for the energy form.

    State ``[phi, omega, dissipated, external work]`` (rad, rad/s, J, J).
    Dissipated: the work of ``M_c(omega)``; external: the motor's work minus
    that of ``M_c(phi)``, ``M_c(t)`` and the load input.

    Parameters
    ----------
    spec : MachineSpec
        The machine's laws.
    motor_slope : float
        ``b``, N m s/rad.
    """

    def __init__(self, spec: MachineSpec, motor_slope: float) -> None:
        self.spec = spec
        self.b = motor_slope
        self.command = 0.0
        self.load = 0.0
        self.state = np.zeros(4)
        self._machine = spec.machine(0.0, motor_slope)

    def set_inputs(self, command: float, load: float) -> None:
        """Motor ``a`` (N m) and extra load torque (N m), held over a step."""
        if (command, load) != (self.command, self.load):
            self.command, self.load = command, load
            self._machine = self.spec.machine(command, self.b, load)

    @property
    def unit(self) -> MachineUnit:
        """Paper 004's machine unit for the inputs now held."""
        return self._machine

    # -- HybridSystem -----------------------------------------------------------
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[omega, omega', dissipated', external work']``."""
        m = self._machine
        phi, omega = float(x[0]), float(x[1])
        dissipated = m.resistance_speed(omega) * omega
        external = (
            m.driving_torque(omega) - m.resistance_angle(phi) - m.resistance_time(t)
        ) * omega
        return np.array([omega, m.acceleration(t, phi, omega), dissipated, external])

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """None: the machine has no modes."""
        return np.zeros(0)

    def guard_directions(self) -> np.ndarray:
        """None."""
        return np.zeros(0)

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Never called."""
        return x

    def project(self, x: np.ndarray) -> np.ndarray:
        """No invariants."""
        return x

    # -- RigidMachineSystem -----------------------------------------------------
    def machine(self, t: float, x: np.ndarray) -> MachineUnit:
        """The machine for paper 004's integrator (never held at rest)."""
        return self._machine

    def book(self, work: StepWork) -> tuple[float, float]:
        """``M_c(omega)`` dissipates; the motor, ``M_c(phi)`` and ``M_c(t)`` are external."""
        return work.speed, work.driving - work.angle - work.time

    # -- outputs ----------------------------------------------------------------
    def kinetic_energy(self, x: np.ndarray | None = None) -> float:
        """``I(phi) omega^2 / 2``, J."""
        x = self.state if x is None else x
        return self._machine.kinetic_energy(float(x[0]), float(x[1]))


@dataclass
class CycleStatistics:
    """Per-revolution speed statistics of the main shaft (module docstring).

    Attributes
    ----------
    count : int
        Revolutions completed.
    start_time : float
        When the current revolution began, s.
    omega_max, omega_min : float
        Extremes so far in the current revolution, rad/s.
    last : dict
        ``period`` (s), ``omega_mean``, ``omega_max``, ``omega_min`` (rad/s)
        and ``delta`` of the last completed revolution (zeros before the first).
    """

    count: int = 0
    start_time: float = 0.0
    omega_max: float = -math.inf
    omega_min: float = math.inf
    last: dict[str, float] = field(
        default_factory=lambda: dict.fromkeys(
            ("period", "omega_mean", "omega_max", "omega_min", "delta"), 0.0
        )
    )
    _turn: int = field(default=0, repr=False)

    def start(self, t: float, phi: float, omega: float) -> None:
        """Begin counting at ``(t, phi, omega)``; revolutions end at multiples of ``2 pi``."""
        self.count = 0
        self.start_time = t
        self.omega_max = self.omega_min = omega
        self._turn = math.floor(phi / _TWO_PI)

    def update(self, t0: float, x0: Sequence[float], t1: float, x1: Sequence[float]) -> None:
        """Account for the step from ``(t0, x0)`` to ``(t1, x1)`` (states ``[phi, omega, ...]``)."""
        turn = math.floor(x1[0] / _TWO_PI)
        if turn > self._turn:  # a revolution ended within the step
            t_end = _crossing_time(t0, x0, t1, x1, turn * _TWO_PI)
            if self.count > 0 or self.start_time != t_end:
                self._close(t_end)
            self.start_time = t_end
            self.omega_max = self.omega_min = float(x1[1])
        self._turn = turn
        self.omega_max = max(self.omega_max, float(x1[1]))
        self.omega_min = min(self.omega_min, float(x1[1]))

    def _close(self, t_end: float) -> None:
        period = t_end - self.start_time
        mean = _TWO_PI / period
        self.last = {
            "period": period,
            "omega_mean": mean,
            "omega_max": self.omega_max,
            "omega_min": self.omega_min,
            "delta": (self.omega_max - self.omega_min) / mean,
        }
        self.count += 1

    def get_state(self) -> dict[str, Any]:
        """Plain data."""
        return {
            "count": self.count,
            "start_time": self.start_time,
            "omega_max": self.omega_max,
            "omega_min": self.omega_min,
            "last": dict(self.last),
            "turn": self._turn,
        }

    def set_state(self, data: Mapping[str, Any]) -> None:
        """Restore :meth:`get_state`."""
        self.count = int(data["count"])
        self.start_time = float(data["start_time"])
        self.omega_max = float(data["omega_max"])
        self.omega_min = float(data["omega_min"])
        self.last = {k: float(v) for k, v in data["last"].items()}
        self._turn = int(data["turn"])


def _crossing_time(
    t0: float, x0: Sequence[float], t1: float, x1: Sequence[float], level: float
) -> float:
    """When the cubic Hermite interpolant of ``phi`` (with ``omega`` as slope) reaches ``level``."""
    h = t1 - t0
    p0, p1, m0, m1 = float(x0[0]), float(x1[0]), float(x0[1]) * h, float(x1[1]) * h

    def hermite(s: float) -> float:
        s2, s3 = s * s, s * s * s
        return (
            (2 * s3 - 3 * s2 + 1) * p0
            + (s3 - 2 * s2 + s) * m0
            + (-2 * s3 + 3 * s2) * p1
            + (s3 - s2) * m1
        ) - level

    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if hermite(mid) < 0.0:
            lo = mid
        else:
            hi = mid
    return t0 + 0.5 * (lo + hi) * h

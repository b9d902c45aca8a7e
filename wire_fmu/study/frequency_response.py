"""Frequency response of the multi-mass drives: simulation against paper 002's impedances.

For every ``MultiMassDrive`` unit of a scene (or any drive configuration),
the response from a sinusoidal torque on the (first) motor to the motor's
and the load's speed is computed two ways:

* **analytic**, by paper 002's electrical analogy: ``1 / Z_in(j w)`` folded
  from the drive's impedances
  (:meth:`~wire_fmu.core.components.drive_tree.DriveTree.driving_point_impedance`), and
  the load speed from the nodal equations
  (:meth:`~wire_fmu.core.components.drive_tree.DriveTree.speeds_per_torque`); with the
  effect ``motor_characteristic`` each motor's slope ``b`` is a damper on
  its mass;
* **simulated**, by stepping the core unit exactly as a master would (the
  torque held at its mid-step value over each communication step) and
  finding its periodic steady state by shooting: the drive is linear, so
  the map from the state at the start of a period to the state one period
  later is affine; solving ``x(T) = x(0)`` for the shaft twists and speeds
  (the absolute angle is free) gives the steady state without waiting for
  transients to decay. The fundamental harmonic of one simulated period,
  divided by the mid-step hold's gain ``sinc(w H / 2)``, is the response.

:func:`write_frequency_response` draws both (Bode magnitude and phase of the
motor's admittance, magnitude of the transfer to the load) for a scene's
drives into ``frequency_response.png``; it needs no CLI.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from wire_fmu.core.components.drive_tree import DriveTree
from wire_fmu.core.units.multimass_drive.unit import DriveUnit

__all__ = [
    "ResponsePoint",
    "drive_unit",
    "analytic_response",
    "simulated_response",
    "frequency_response",
    "write_frequency_response",
]

logger = logging.getLogger(__name__)

DRIVE_FMU = "MultiMassDrive"


@dataclass(frozen=True)
class ResponsePoint:
    """Complex responses at one frequency, rad/s per N m.

    Attributes
    ----------
    frequency : float
        Hz.
    motor : complex
        Motor speed per motor torque (``1 / Z_in``).
    load : complex
        Load speed per motor torque.
    """

    frequency: float
    motor: complex
    load: complex


def drive_unit(
    parameters: Mapping[str, Any], effects: Sequence[str] = (), name: str = "drive"
) -> DriveUnit:
    """A configured :class:`DriveUnit` (not initialised) from scene-style parameters.

    Parameters
    ----------
    parameters : mapping
        Unit parameters as a scene gives them (tables and lists are passed
        on as JSON); names the unit does not have are ignored.
    effects : sequence of str
        The unit's effects.
    name : str
        Instance name.
    """
    unit = DriveUnit(name)
    for key, value in parameters.items():
        if key in unit.values:
            unit.values[key] = json.dumps(value) if isinstance(value, Mapping | list) else value
    unit.values["effects"] = ",".join(effects)
    unit.configure()
    return unit


def _with_motor_slope(tree: DriveTree, slope: float) -> DriveTree:
    """The tree with each motor's characteristic slope as a damper on its mass."""
    dampings = list(tree.dampings)
    for m in tree.motors:
        dampings[m % tree.n] += slope
    return DriveTree(
        tree.inertias, tuple(dampings), tree.shafts, tree.names, tree.motors, tree.load
    )


def analytic_response(unit: DriveUnit, frequency: float) -> ResponsePoint:
    """Paper 002's impedance formulas for the drive ``unit`` simulates, at ``frequency`` (Hz).

    Parameters
    ----------
    unit : DriveUnit
        A configured drive (its tree, motor slope and load).
    frequency : float
        Excitation frequency, Hz.
    """
    model = unit.model
    tree = _with_motor_slope(model.tree, model.motor_slope)
    omega = 2.0 * math.pi * frequency
    motor = model.motors[0]
    speeds = tree.speeds_per_torque(omega, motor)
    return ResponsePoint(
        frequency, 1.0 / tree.driving_point_impedance(motor, omega), complex(speeds[model.load])
    )


def _period(
    unit: DriveUnit, x0: np.ndarray, omega: float, steps: int, samples: bool = False
) -> np.ndarray:
    """Step ``unit`` over one period from ``x0`` with a unit sine torque on the motor."""
    model = unit.model
    model.state = np.array(x0, dtype=float)
    h = 2.0 * math.pi / omega / steps
    out = []
    for i in range(steps):
        t = i * h
        unit.values["motor.torque"] = math.sin(omega * (t + 0.5 * h))  # the master's hold
        result = unit.advance(t, h)
        if not result.success:
            raise RuntimeError(result.message)
        if samples:
            out.append(model.state.copy())
    return np.array(out) if samples else model.state.copy()


def _periodic_state(unit: DriveUnit, omega: float, steps: int) -> np.ndarray:
    """The state at the start of the periodic steady state, by affine shooting."""
    model = unit.model
    n, load = model.n, model.load
    free = [k for k in range(n) if k != load] + list(range(n, 2 * n))

    def mismatch(z: np.ndarray) -> np.ndarray:
        """Change of the shaft twists and speeds over one period (the load's angle left out).

        Parameters
        ----------
        z : ndarray, shape (2 n - 1,)
            The free start states: twists (rad) and speeds (rad/s).
        """
        x0 = np.zeros(2 * n + 2)
        x0[free] = z
        x1 = _period(unit, x0, omega, steps)
        twist0 = x0[:n] - x0[load]
        twist1 = x1[:n] - x1[load]
        d = np.concatenate([twist1 - twist0, x1[n : 2 * n] - x0[n : 2 * n]])
        return np.delete(d, load)

    base = mismatch(np.zeros(len(free)))
    columns = [mismatch(e) - base for e in np.eye(len(free))]
    z = np.linalg.solve(np.column_stack(columns), -base)
    x0 = np.zeros(2 * n + 2)
    x0[free] = z
    return x0


def simulated_response(unit: DriveUnit, frequency: float, steps: int = 200) -> ResponsePoint:
    """The unit's simulated periodic response to a unit sine torque on the motor.

    Parameters
    ----------
    unit : DriveUnit
        Configured; it is initialised and stepped here (its other inputs 0).
    frequency : float
        Hz.
    steps : int
        Communication steps per period (the hold's gain is divided out).
    """
    for name in ("motor.torque", "motor2.torque", "load.torque"):
        unit.values[name] = 0.0
    unit.initialize(0.0)
    omega = 2.0 * math.pi * frequency
    x0 = _periodic_state(unit, omega, steps)
    states = _period(unit, x0, omega, steps, samples=True)
    model = unit.model
    h = 2.0 * math.pi / omega / steps
    times = h * np.arange(1, steps + 1)
    phase = np.exp(-1j * omega * times)
    hold_gain = math.sin(0.5 * omega * h) / (0.5 * omega * h)

    def harmonic(series: np.ndarray) -> complex:
        """Complex amplitude at the excitation frequency per unit torque, hold gain divided out.

        Parameters
        ----------
        series : ndarray, shape (steps,)
            A speed sampled at the step ends of one period, rad/s.
        """
        coefficient = 2.0 / steps * complex(series @ phase)
        return 1j * coefficient / hold_gain  # input sin(w t) = Re(-j e^{j w t})

    n = model.n
    return ResponsePoint(
        frequency, harmonic(states[:, n + model.motors[0]]), harmonic(states[:, n + model.load])
    )


def frequency_response(
    unit: DriveUnit, frequencies: Sequence[float], simulate: Sequence[float] = ()
) -> dict[str, list[ResponsePoint]]:
    """Analytic responses at ``frequencies`` and simulated ones at ``simulate`` (Hz).

    Parameters
    ----------
    unit : DriveUnit
        A configured drive.
    frequencies : sequence of float
        Frequencies of the analytic response, Hz.
    simulate : sequence of float
        Frequencies at which the unit is also simulated, Hz.
    """
    return {
        "analytic": [analytic_response(unit, f) for f in frequencies],
        "simulated": [simulated_response(unit, f) for f in simulate],
    }


def _scene_drives(scene) -> dict[str, DriveUnit]:
    return {
        name: drive_unit(spec.parameters, spec.effects, name)
        for name, spec in scene.units.items()
        if spec.fmu == DRIVE_FMU
    }


def write_frequency_response(
    scene,
    directory: Path,
    *,
    points: int = 200,
    simulate: Sequence[float] = (2.0, 8.0, 13.0, 20.0, 60.0, 150.0),
) -> Path:
    """Bode plots of every drive in ``scene``: formulas as lines, simulation as markers.

    Parameters
    ----------
    scene : Scene
        A scene with ``MultiMassDrive`` units.
    directory : Path
        Where ``frequency_response.png`` goes (created).
    points : int
        Frequencies of the analytic curves, log-spaced over 0.5-500 Hz.
    simulate : sequence of float
        Frequencies (Hz) simulated by shooting.

    Returns
    -------
    Path
        The PNG.
    """
    from matplotlib.figure import Figure

    drives = _scene_drives(scene)
    if not drives:
        raise ValueError(f"scene {scene.name!r} has no {DRIVE_FMU} unit")
    fig = Figure(figsize=(11, 8), dpi=100, layout="constrained")
    axes = fig.subplots(2, 2)
    grid = np.logspace(math.log10(0.5), math.log10(500.0), points)
    for i, (name, unit) in enumerate(drives.items()):
        result = frequency_response(unit, grid, simulate)
        colour = f"C{i}"
        _plot(axes, result["analytic"], f"{name}: 1/Z_in (paper 002)", colour, "-")
        _plot(axes, result["simulated"], f"{name}: simulated", colour, "o")
        deviation = [
            abs(p.motor / analytic_response(unit, p.frequency).motor - 1.0)
            for p in result["simulated"]
        ]
        axes[1, 1].plot(simulate, np.maximum(deviation, 1e-17), "o-", color=colour, label=name)
        logger.info("frequency response of %s: largest deviation %.3g", name, max(deviation))
    titles = (
        "|motor speed / motor torque| = |1/Z_in|",
        "phase of 1/Z_in (deg)",
        "|load speed / motor torque|",
        "|simulated / formula| - 1 (motor)",
    )
    for ax, title in zip(axes.flat, titles, strict=True):
        ax.set_title(title)
        ax.set_xscale("log")
        ax.set_xlabel("frequency (Hz)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].set_yscale("log")
    axes[1, 0].set_yscale("log")
    axes[0, 0].set_ylabel("rad/s per N m")
    axes[1, 0].set_ylabel("rad/s per N m")
    axes[1, 1].set_yscale("log")
    axes[1, 1].set_ylabel("relative deviation (hold aliasing ~ 1/steps^2)")
    axes[0, 0].legend(fontsize="small")
    fig.suptitle(f"{scene.name}: frequency response, simulated against the impedance formulas")
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    path = directory / "frequency_response.png"
    fig.savefig(path)
    return path


def _plot(axes, points: list[ResponsePoint], label: str, colour: str, style: str) -> None:
    if not points:
        return
    f = [p.frequency for p in points]
    motor = np.array([p.motor for p in points])
    load = np.array([p.load for p in points])
    kwargs = {"color": colour, "label": label}
    if style == "o":
        kwargs.update(marker="o", linestyle="none", markerfacecolor="none")
    axes[0, 0].plot(f, np.abs(motor), **kwargs)
    axes[0, 1].plot(f, np.degrees(np.angle(motor)), **kwargs)
    axes[1, 0].plot(f, np.abs(load), **kwargs)

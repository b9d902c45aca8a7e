"""Integration of hybrid (mode-switching) ODEs over one communication step.

A :class:`HybridSystem` has a continuous state ``x`` and a discrete *mode*
(stick/slip flags, slack flags, broken ropes...). Inside one mode it is a
smooth ODE ``x' = f(t, x)``; *guards* ``g(t, x)`` watch for the mode's end.
The integrators here advance such a system to a target time, locate every
guard crossing to within a small time tolerance by re-stepping (regula falsi
with the Illinois modification), let the system switch mode there, and go on.

Solvers are small objects chosen by name from :data:`SOLVERS`:

``rk4``
    classical explicit Runge-Kutta, fixed step (order 4).
``ros2``
    two-stage linearly implicit Rosenbrock-W method of Verwer et al. (1999),
    L-stable, order 2 for any Jacobian approximation; the finite-difference
    Jacobian is reused within a communication step and refreshed after
    every event. Cheap and robust for stiff ropes and oil columns.
``radau``, ``bdf``, ``lsoda``, ``rk45``, ``dop853``
    SciPy's adaptive solvers with ``rtol``/``atol``, restarted at every
    communication step and every event.

The fixed-step solvers take ``ceil(H / max_step)`` equal steps per
communication step H, so the result never depends on how a master splits
time except through H itself.

This module holds the protocol, the settings and the registry; the solvers
are in :mod:`wire_fmu.core.framework.fixed_step` and
:mod:`wire_fmu.core.framework.scipy_solvers`, the limits every step keeps
(and :class:`IntegrationError`) in :mod:`wire_fmu.core.framework.step_limits`.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from wire_fmu.core.framework.fixed_step import RK4, ROS2, finite_difference_jacobian
from wire_fmu.core.framework.scipy_solvers import ScipySolver
from wire_fmu.core.framework.step_limits import IntegrationError

__all__ = [
    "HybridSystem",
    "SmoothSystem",
    "SolverSettings",
    "IntegrationError",
    "SOLVERS",
    "make_solver",
]


class HybridSystem(Protocol):
    """What an integrator needs from a model.

    Guards come in two kinds, told apart by :meth:`guard_directions`:
    ``-1`` fires when the guard goes from ``>= 0`` to ``< 0`` (leaving a
    mode), ``0`` fires on any change of sign (a kink such as a rope going
    slack, located for accuracy).
    """

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """Time derivative of the state in the current mode.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            Continuous state of the model.
        """
        ...

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """Guard function values in the current mode.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            Continuous state of the model.
        """
        ...

    def guard_directions(self) -> np.ndarray:
        """Per guard: -1 (fires on a downward crossing) or 0 (any crossing)."""
        ...

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Switch mode after the guards ``fired``; return the (projected) state.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            Continuous state of the model.
        fired : list of int
            Indices of the guards that crossed.
        """
        ...

    def project(self, x: np.ndarray) -> np.ndarray:
        """Enforce the current mode's algebraic invariants on ``x`` (exactly).

        Parameters
        ----------
        x : ndarray
            Continuous state, changed in place and returned.
        """
        ...


class SmoothSystem:
    """Base of a :class:`HybridSystem` with one mode: no guards, no events, no invariants.

    A subclass gives :meth:`HybridSystem.rhs`; the rest of the protocol is here.
    """

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """None: the system has no modes.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            Continuous state of the model.
        """
        return np.zeros(0)

    def guard_directions(self) -> np.ndarray:
        """None."""
        return np.zeros(0)

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Never called: without guards nothing fires.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            Continuous state of the model, returned as it is.
        fired : list of int
            Indices of the guards that crossed (none).
        """
        return x

    def project(self, x: np.ndarray) -> np.ndarray:
        """No invariants: ``x`` as it is.

        Parameters
        ----------
        x : ndarray
            Continuous state of the model.
        """
        return x


@dataclass(frozen=True)
class SolverSettings:
    """Choice and settings of the internal solver of a unit.

    Parameters
    ----------
    method : str
        A key of :data:`SOLVERS`.
    max_step : float
        Largest internal step, s (fixed-step methods take equal steps no
        longer than this; adaptive methods never exceed it).
    rtol, atol : float
        Tolerances of the adaptive SciPy methods.
    event_time_tolerance : float
        Guard crossings are located to within this time, s.
    """

    method: str = "ros2"
    max_step: float = 1e-3
    rtol: float = 1e-6
    atol: float = 1e-9
    event_time_tolerance: float = 1e-9

    def problems(self, known: Collection[str] = ()) -> list[str]:
        """Every problem with these settings, as sentences.

        ``known`` adds method names a unit offers beyond :data:`SOLVERS`
        (paper 004's energy-form integrator in the winch and the machine unit).

        Parameters
        ----------
        known : collection of str, optional
            Further method names the unit accepts.
        """
        out = []
        names = set(SOLVERS) | set(known)
        if self.method not in names:
            out.append(f"solver {self.method!r} is unknown; choose one of {sorted(names)}")
        if not (self.max_step > 0 and math.isfinite(self.max_step)):
            out.append(f"solver_max_step must be a positive number of seconds, got {self.max_step}")
        if not (0 < self.rtol < 1):
            out.append(f"solver_rtol must lie in (0, 1), got {self.rtol}")
        if not (self.atol > 0):
            out.append(f"solver_atol must be positive, got {self.atol}")
        return out


RK4_STABILITY = 2.5
"""``|lambda| h`` below which classical RK4 is stable (its limit is 2.78 on the real
axis and 2.83 on the imaginary axis), with a margin."""


def fastest_mode(system: HybridSystem, t: float, x: np.ndarray) -> float:
    """Largest ``|lambda|`` (1/s) of the system's Jacobian at ``(t, x)`` (finite differences).

    Parameters
    ----------
    system : HybridSystem
        The model, in its current mode.
    t : float
        Time, s.
    x : ndarray
        Continuous state of the model.
    """
    if x.size == 0:
        return 0.0
    return float(np.max(np.abs(np.linalg.eigvals(finite_difference_jacobian(system, t, x)))))


SOLVERS = {
    "rk4": lambda s: RK4(s),
    "ros2": lambda s: ROS2(s),
    "radau": lambda s: ScipySolver(s, "Radau"),
    "bdf": lambda s: ScipySolver(s, "BDF"),
    "lsoda": lambda s: ScipySolver(s, "LSODA"),
    "rk45": lambda s: ScipySolver(s, "RK45"),
    "dop853": lambda s: ScipySolver(s, "DOP853"),
}


def make_solver(settings: SolverSettings):
    """A fresh solver object for ``settings`` (raises ValueError if unknown).

    Parameters
    ----------
    settings : SolverSettings
        ``method`` one of :data:`SOLVERS`.
    """
    try:
        factory = SOLVERS[settings.method]
    except KeyError:
        raise ValueError(
            f"solver {settings.method!r} is unknown; choose one of {sorted(SOLVERS)}"
        ) from None
    return factory(settings)

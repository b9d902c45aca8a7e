"""Paper 004's energy-form integrator as a fixed-step solver of hybrid systems.

The ``energy`` and ``energy1`` solvers a unit may offer beside those of
:mod:`wire_fmu.core.framework.hybrid`, for models that are a rigid machine in every mode
(:class:`RigidMachineSystem`); the step itself is
:class:`wire_fmu.core.framework.energy_integrator.EnergyFormIntegrator`'s.
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Protocol

import numpy as np

from wire_fmu.core.framework.energy_integrator import EnergyFormIntegrator
from wire_fmu.core.framework.fixed_step import FixedStepSolver
from wire_fmu.core.framework.hybrid import SolverSettings
from wire_fmu.core.framework.machine_unit import MachineUnit, StepWork

__all__ = ["RigidMachineSystem", "EnergyFormSolver", "ENERGY_SOLVERS", "make_energy_solver"]


class RigidMachineSystem(Protocol):
    """A hybrid system that is a rigid one-degree-of-freedom machine in every mode.

    Its state is ``[phi, omega, dissipated energy, external work]``
    (rad, rad/s, J, J). Besides the
    :class:`~wire_fmu.core.framework.hybrid.HybridSystem` methods it offers:
    """

    def machine(self, t: float, x: np.ndarray) -> MachineUnit | None:
        """The machine unit of the current mode; None while it is held at rest.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            Continuous state of the model.
        """
        ...

    def book(self, work: StepWork) -> tuple[float, float]:
        """Split a step's works into (dissipated, external work), J.

        Parameters
        ----------
        work : StepWork
            The works of the step, J.
        """
        ...


class EnergyFormSolver(FixedStepSolver):
    """Paper 004's integrator as a fixed-step solver of :mod:`wire_fmu.core.framework.hybrid`.

    Takes ``ceil(H / max_step)`` equal time steps per communication step,
    each by :meth:`EnergyFormIntegrator.step_time`; guards and events are
    handled by the shared fixed-step machinery (events located by
    re-stepping). Only for :class:`RigidMachineSystem` models.

    Parameters
    ----------
    settings : SolverSettings
        ``max_step`` is used; the refinement tolerance is 1e-12 (relative),
        near round-off, which costs 2-4 corrections per step.
    refinements : int or None
        0 for the first-order variant, None for refinement to tolerance.
    """

    def __init__(self, settings: SolverSettings, refinements: int | None) -> None:
        super().__init__(settings)
        self.integrator = EnergyFormIntegrator(refinements)
        self.fallbacks = 0

    def _step(self, system: RigidMachineSystem, t: float, x: np.ndarray, h: float) -> np.ndarray:
        machine = system.machine(t, x)
        if machine is None:
            return np.array(x, dtype=float)
        before = self.integrator.torque_evaluations
        result = self.integrator.step_time(machine, t, float(x[0]), float(x[1]), h)
        self.rhs_calls += self.integrator.torque_evaluations - before
        self.fallbacks += result.form == "time"
        dissipated, external = system.book(result.work)
        return np.array([result.phi, result.omega, x[2] + dissipated, x[3] + external])


ENERGY_SOLVERS = MappingProxyType({"energy": None, "energy1": 0})
"""Solver names of paper 004's integrator -> refinements (None: to tolerance)."""


def make_energy_solver(settings: SolverSettings) -> EnergyFormSolver:
    """An :class:`EnergyFormSolver` for ``settings.method`` in :data:`ENERGY_SOLVERS`.

    Parameters
    ----------
    settings : SolverSettings
        ``method`` one of :data:`ENERGY_SOLVERS`; ``max_step`` is used.

    Raises
    ------
    ValueError
        If the method is not an energy-form solver.
    """
    try:
        refinements = ENERGY_SOLVERS[settings.method]
    except KeyError:
        raise ValueError(
            f"solver {settings.method!r} is not an energy-form solver; choose one of "
            f"{sorted(ENERGY_SOLVERS)}"
        ) from None
    return EnergyFormSolver(settings, refinements)

"""Coupling algorithms: small swappable objects with one call-order contract.

A :class:`CouplingAlgorithm` advances every unit over one macro step
``[t, t + h]``: it decides which value each connection holds and in which
order the units step. It never records, never adapts the step and never
rolls back — that is :class:`~wire_fmu.master.simulation.Simulation`'s job
(libcosim's algorithm/observer/manipulator split).

``jacobi``
    every unit steps with values predicted from the past (extrapolation),
    as if in parallel.
``gauss_seidel``
    units step in an order derived from the connection graph — the side
    that outputs flows (velocities, positions: states of inertias) first —
    and later units hold values built from their sources' *new* outputs.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections import defaultdict
from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .simulation import Simulation

__all__ = ["CouplingAlgorithm", "Jacobi", "GaussSeidel", "make_algorithm", "step_order"]


class CouplingAlgorithm(ABC):
    """One sweep over the units for one macro step."""

    name = "algorithm"

    def __init__(self, order: Sequence[str]) -> None:
        self.order = list(order)

    @abstractmethod
    def sweep(
        self, sim: Simulation, t: float, h: float, fresh: dict | None = None
    ) -> dict[str, float]:
        """Set every unit's inputs and step it once over ``[t, t + h]``.

        ``fresh`` (iteration) maps source outputs to their values at ``t + h``
        from the previous sweep; without it values are extrapolated.

        Parameters
        ----------
        sim : Simulation
            The simulation whose units are stepped (through its
            ``set_inputs`` and ``step_unit``, which puts a unit's new source
            outputs into the dict it is given).
        t : float
            Start of the macro step, s.
        h : float
            Macro step, s.
        fresh : dict of str to float, optional
            Source outputs (``"unit.variable"``) at ``t + h`` from the previous
            sweep, in their units.

        Returns
        -------
        dict of str to float
            Every unit's source outputs at ``t + h``, by ``"unit.variable"``, in
            their units (each unit's read after its step).
        """


class Jacobi(CouplingAlgorithm):
    """Every unit steps on extrapolated inputs."""

    name = "jacobi"

    def sweep(self, sim, t, h, fresh=None):
        """Parameters and contract as in :meth:`CouplingAlgorithm.sweep`."""
        for unit in self.order:
            sim.set_inputs(unit, t, h, fresh)
        new: dict[str, float] = {}
        for unit in self.order:
            sim.step_unit(unit, t, h, new)
        return new


class GaussSeidel(CouplingAlgorithm):
    """Units step in order; each uses the new outputs of those before it."""

    name = "gauss_seidel"

    def sweep(self, sim, t, h, fresh=None):
        """Parameters and contract as in :meth:`CouplingAlgorithm.sweep`."""
        new = dict(fresh or {})
        for unit in self.order:
            sim.set_inputs(unit, t, h, new)
            sim.step_unit(unit, t, h, new)  # every unit steps: all of new is now of t + h
        return new


def step_order(
    units: Sequence[str],
    flows_to: dict[str, set[str]],
    feeds: dict[str, set[str]],
    preferred: Sequence[str] = (),
) -> list[str]:
    """Order for Gauss-Seidel: flow sources before the units they feed.

    Parameters
    ----------
    units : sequence of str
        All units, in scene order (the tie-break).
    flows_to : dict
        ``a -> {b}`` when ``a`` outputs a flow or position (or a plain signal)
        that ``b`` takes: ``a`` should step first.
    feeds : dict
        Every ``a -> {b}`` connection (used only to break remaining cycles).
    preferred : sequence of str
        An explicit order from the scene, used as is when given.
    """
    if preferred:
        return list(preferred) + [u for u in units if u not in preferred]
    indegree = defaultdict(int)
    for a, targets in flows_to.items():
        for b in targets:
            if a != b:
                indegree[b] += 1
    order, placed = [], set()
    while len(order) < len(units):
        ready = [u for u in units if u not in placed and indegree[u] == 0]
        if not ready:  # a cycle of flows: take the unit that feeds most, in scene order
            ready = sorted(
                (u for u in units if u not in placed), key=lambda u: -len(feeds.get(u, ()))
            )[:1]
        unit = ready[0]
        order.append(unit)
        placed.add(unit)
        for b in flows_to.get(unit, ()):
            indegree[b] -= 1
    return order


ALGORITHMS = {"jacobi": Jacobi, "gauss_seidel": GaussSeidel}


def make_algorithm(name: str, order: Sequence[str]) -> CouplingAlgorithm:
    """The algorithm called ``name`` (raises ValueError naming the known ones).

    Parameters
    ----------
    name : str
        One of :data:`ALGORITHMS`: ``"jacobi"`` or ``"gauss_seidel"``.
    order : sequence of str
        The units in the order they step (see :func:`step_order`).

    Returns
    -------
    CouplingAlgorithm
    """
    try:
        return ALGORITHMS[name](order)
    except KeyError:
        raise ValueError(
            f"algorithm {name!r} is unknown; choose one of {sorted(ALGORITHMS)}"
        ) from None

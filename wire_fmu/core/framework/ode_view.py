"""A unit seen as a hybrid ODE, so that several units can be solved as one (the monolithic
reference of :mod:`wire_fmu.study.monolithic`)."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any

import numpy as np

__all__ = ["ModelOdeView", "OdeView"]


class OdeView(ABC):
    """A configured, initialised unit seen as a hybrid ODE (see :mod:`~.framework.hybrid`).

    ``bind_inputs(t)`` reads the unit's inputs from its ``values`` as their
    instantaneous values at ``t``; ``rhs``, ``guards``, ``guard_directions``,
    ``handle_events`` and ``project`` are those of a
    :class:`~wire_fmu.core.framework.hybrid.HybridSystem`; ``publish(t, x)`` writes the
    outputs for state ``x`` into ``values``; ``state``/``set_state`` move the
    continuous state in and out of the unit.
    """

    @property
    @abstractmethod
    def state(self) -> Any:
        """Continuous state vector (a copy)."""

    @abstractmethod
    def set_state(self, x: Any, t: float) -> None:
        """Adopt ``x`` at time ``t`` (and refresh the outputs).

        Parameters
        ----------
        x : array_like
            Continuous state (see :attr:`state`).
        t : float
            Time, s.
        """

    @abstractmethod
    def bind_inputs(self, t: float) -> None:
        """Take the inputs now in ``values`` as their values at ``t``.

        Parameters
        ----------
        t : float
            Time the inputs hold at, s.
        """

    @abstractmethod
    def publish(self, t: float, x: Any) -> None:
        """Write the outputs of state ``x`` at ``t`` into ``values``.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            Continuous state (see :attr:`state`).
        """

    @abstractmethod
    def rhs(self, t: float, x: Any) -> Any:
        """State derivative.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            Continuous state (see :attr:`state`).

        Returns
        -------
        numpy.ndarray
            ``dx/dt``, in the layout of ``x``.
        """

    @abstractmethod
    def guards(self, t: float, x: Any) -> Any:
        """Guard values.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            Continuous state (see :attr:`state`).

        Returns
        -------
        numpy.ndarray
            One value per guard; a guard fires when it crosses zero in its direction
            (:meth:`guard_directions`).
        """

    @abstractmethod
    def guard_directions(self) -> Any:
        """Guard directions."""

    @abstractmethod
    def handle_events(self, t: float, x: Any, fired: list[int]) -> Any:
        """Switch modes; return the projected state.

        Parameters
        ----------
        t : float
            Time, s.
        x : array_like
            Continuous state (see :attr:`state`).
        fired : list of int
            Indices of the guards that fired at ``t``.

        Returns
        -------
        numpy.ndarray
            The state after the switches, projected.
        """

    @abstractmethod
    def project(self, x: Any) -> Any:
        """Enforce the mode's invariants.

        Parameters
        ----------
        x : array_like
            Continuous state (see :attr:`state`).

        Returns
        -------
        numpy.ndarray
            The state satisfying the invariants (it may be ``x``, changed in place).
        """

    def reconcile(self, t: float, x: Any) -> Any:
        """Inputs jumped at ``t`` (an event): settle modes, act on commands; return the state.

        The default changes nothing.

        Parameters
        ----------
        t : float
            Time of the input jump, s.
        x : array_like
            Continuous state at ``t`` (see :attr:`state`).

        Returns
        -------
        numpy.ndarray
            The state to continue from.
        """
        return x


class ModelOdeView(OdeView):
    """An :class:`OdeView` of a unit whose model is a hybrid system over the unit's state.

    The model keeps its continuous state in ``model.state``; the unit keeps
    its time in ``unit.time`` and fills its outputs with
    ``unit._update_outputs()``. The hybrid-system methods are the model's.
    Subclasses add ``bind_inputs`` (and ``reconcile`` where inputs can switch
    modes) and override what differs.
    """

    def __init__(self, unit: Any, model: Any) -> None:
        self.unit = unit
        self.model = model

    @property
    def state(self) -> Any:
        """Continuous state (a copy)."""
        return self.model.state.copy()

    def set_state(self, x: Any, t: float) -> None:
        """Adopt ``x`` at ``t`` and refresh the outputs.

        Implements :meth:`OdeView.set_state`.
        """
        self.model.state = np.array(x, dtype=float)
        self.unit.time = t
        self.bind_inputs(t)
        self.unit._update_outputs()

    def publish(self, t: float, x: Any) -> None:
        """Outputs of ``x`` at ``t`` into ``values``; the state is left alone.

        Implements :meth:`OdeView.publish`.
        """
        saved, self.model.state = self.model.state, np.asarray(x, dtype=float)
        saved_time, self.unit.time = self.unit.time, t
        try:
            self.unit._update_outputs()
        finally:
            self.model.state, self.unit.time = saved, saved_time

    def rhs(self, t: float, x: Any) -> Any:
        """The model's state derivative.

        Implements :meth:`OdeView.rhs`.
        """
        return self.model.rhs(t, x)

    def guards(self, t: float, x: Any) -> Any:
        """The model's guards.

        Implements :meth:`OdeView.guards`.
        """
        return self.model.guards(t, x)

    def guard_directions(self) -> Any:
        """The model's guard directions."""
        return self.model.guard_directions()

    def handle_events(self, t: float, x: Any, fired: list[int]) -> Any:
        """The model's mode switches.

        Implements :meth:`OdeView.handle_events`.
        """
        return self.model.handle_events(t, x, fired)

    def project(self, x: Any) -> Any:
        """The model's invariants.

        Implements :meth:`OdeView.project`.
        """
        return self.model.project(x)

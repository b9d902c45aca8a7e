"""Seal friction on a rod: Coulomb + viscous (+ Stribeck) that really sticks (``seal_friction``).

The rod and piston seals resist sliding with ``F_s(v) + c v``: a sliding part
that falls from the breakaway force to the Coulomb force over the Stribeck
velocity, and a viscous part. Below the breakaway force the seals hold the
rod (stick) exactly, by :class:`~wire_fmu.core.components.friction.StickSlip`
on one link to ground, and the rod is held where it stuck.

One :class:`RodSeal` holds the stick/slip mode and the held position and gives
the rod's acceleration, the friction force, its loss power, the guard that
switches the mode and the event text. A model without the effect has no seal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wire_fmu.core.components.friction import GROUND, FrictionLink, StickSlip
from wire_fmu.core.errors import check_positive

__all__ = ["RodSeal", "SealSpec"]


@dataclass(frozen=True)
class SealSpec:
    """Rod and piston seal friction.

    Parameters
    ----------
    static : float
        Breakaway force (static capacity), N.
    coulomb : float
        Sliding (Coulomb) force at high speed, N.
    viscous : float
        Viscous coefficient, N s/m.
    stribeck_velocity : float
        Stribeck velocity, m/s; 0 switches the Stribeck decay off (the
        sliding force is then ``coulomb``).
    """

    static: float
    coulomb: float
    viscous: float = 0.0
    stribeck_velocity: float = 0.0

    def problems(self) -> list[str]:
        """Every problem with the parameters, as sentences."""
        out: list[str] = []
        check_positive("seal_static_friction", self.static, out, "N", zero_ok=True)
        check_positive("seal_coulomb_friction", self.coulomb, out, "N", zero_ok=True)
        check_positive("seal_viscous_friction", self.viscous, out, "N.s/m", zero_ok=True)
        check_positive("seal_stribeck_velocity", self.stribeck_velocity, out, "m/s", zero_ok=True)
        if self.coulomb > self.static:
            out.append(
                f"parameter 'seal_coulomb_friction' ({self.coulomb} N) must not exceed "
                f"'seal_static_friction' ({self.static} N)"
            )
        return out

    def sliding(self, velocity: float) -> float:
        """Sliding friction magnitude at ``velocity`` (m/s), N (viscous part excluded).

        Parameters
        ----------
        velocity : float
            Rod sliding velocity, m/s.
        """
        if self.stribeck_velocity <= 0.0:
            return self.coulomb
        decay = math.exp(-((velocity / self.stribeck_velocity) ** 2))
        return self.coulomb + (self.static - self.coulomb) * decay


class RodSeal:
    """The seals of one rod sliding against ground: mode, force, loss, guard.

    Parameters
    ----------
    spec : SealSpec
        Validated parameters.
    mass : float
        Mass of the rod the seals act on, kg.
    """

    def __init__(self, spec: SealSpec, mass: float) -> None:
        self.spec = spec
        self.friction = StickSlip(np.array([mass]), (FrictionLink("rod seals", 0, GROUND),))
        self.capacity = np.array([spec.static])
        """Breakaway force, N (as the friction solver takes it)."""
        self.viscous = spec.viscous
        """Viscous coefficient, N s/m (its force is part of the rod's smooth forces)."""
        self.held_position = 0.0
        """Where a stuck rod is held, m."""

    @property
    def stuck(self) -> bool:
        """Whether the seals hold the rod."""
        return self.friction.mode[0] == 0

    @property
    def mode(self) -> int:
        """0 while the seals hold the rod, +1 or -1 the direction it slides in."""
        return int(self.friction.mode[0])

    def start(self, velocity: float) -> None:
        """Mode at the start: a moving rod slides.

        Parameters
        ----------
        velocity : float
            Rod velocity, m/s.
        """
        moving = int(math.copysign(1, velocity)) if velocity != 0.0 else 0
        self.friction.set_mode([moving])

    def accelerate(self, force: float, velocity: float) -> tuple[float, float, float]:
        """Acceleration (m/s^2), friction force on the rod (N) and its loss (W).

        Parameters
        ----------
        force : float
            Every other force on the rod (viscous seal force included), N.
        velocity : float
            Rod velocity, m/s.
        """
        sliding = np.array([self.spec.sliding(velocity)])
        acc, link = self.friction.accelerations(np.array([force]), self.capacity, sliding=sliding)
        loss = self.friction.loss_power(np.array([velocity]), link)
        return float(acc[0]), float(link[0]), float(loss)

    def guard(self, velocity: float, link: float) -> float:
        """The stick/slip guard (>= 0 while the mode holds).

        Parameters
        ----------
        velocity : float
            Rod velocity, m/s.
        link : float
            Friction force from :meth:`accelerate`, N.
        """
        return float(self.friction.guards(np.array([velocity]), np.array([link]), self.capacity)[0])

    def settle(
        self, position: float, velocity: float, force: float, fired: list[int]
    ) -> tuple[float, str | None]:
        """Make the mode consistent with ``force``; the rod's velocity and the event text.

        Parameters
        ----------
        position : float
            Rod position (held there if it sticks), m.
        velocity : float
            Rod velocity, m/s.
        force : float
            Every other force on the rod, N.
        fired : list of int
            ``[0]`` when the seal's guard fired, else ``[]``.
        """
        if not fired and not (self.stuck and abs(force) > self.spec.static):
            # nothing fired and the seals can hold what they hold: no mode changes
            self.held_position = float(position)
            return float(velocity), None
        before = self.friction.get_mode()
        v = self.friction.switch(np.array([velocity]), np.array([force]), self.capacity, fired)
        self.held_position = float(position)
        if self.friction.get_mode() == before:
            return float(v[0]), None
        return float(v[0]), f"rod seals {'stuck' if self.stuck else 'sliding'}"

    def snapshot(self) -> tuple[int, float]:
        """Mode and held position, to :meth:`restore` in this process (cheaper than
        :meth:`get_state`)."""
        return self.mode, self.held_position

    def restore(self, snapshot: tuple[int, float]) -> None:
        """Restore from :meth:`snapshot`.

        Parameters
        ----------
        snapshot : tuple
            As :meth:`snapshot` returned it.
        """
        mode, self.held_position = snapshot
        self.friction.set_mode([mode])

    def get_state(self) -> dict:
        """Mode and held position, as JSON data."""
        return {"mode": self.friction.get_mode(), "held_position": self.held_position}

    def set_state(self, state: dict) -> None:
        """Restore from :meth:`get_state`.

        Parameters
        ----------
        state : dict
            As :meth:`get_state` returned it.
        """
        self.friction.set_mode(list(state["mode"]))
        self.held_position = float(state["held_position"])

"""End stops of a stroke: hydraulic cushions and stiff stops at both ends (effect ``end_stops``).

Near each end of the stroke a cushion zone of length ``l_c`` brakes the rod
running into it with ``c v^2``; at the end a stiff stop (spring ``k`` and the
dashpot that gives the set restitution, :func:`damping_ratio_for_restitution`)
holds it. The stop acts only while in contact, a mode entered when the pad is
compressed and left when its force would pull (a force-release contact); an
unloaded pad that is still compressed relaxes behind a rod that leaves faster.

One :class:`EndStops` holds the modes (contact, inside a cushion) and gives
the force on the rod, the pad energy stored, the power lost, the guards that
switch the modes and the texts of those events. A model without the effect
has no :class:`EndStops` and does none of this work.

Sign convention: positions along extension from fully retracted (0) to the
stroke; forces on the rod along extension.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from wire_fmu.core.errors import check_positive

__all__ = [
    "END_NAMES",
    "EXTENDED",
    "RETRACTED",
    "EndStopSpec",
    "EndStops",
    "damping_ratio_for_restitution",
    "restitution_of_damping_ratio",
]

RETRACTED, EXTENDED = 0, 1
"""The two ends of the stroke, as indices."""
END_NAMES = ("retraction", "extension")
"""Names of the ends in messages."""


@dataclass(frozen=True)
class EndStopSpec:
    """Hydraulic cushions and stiff stops at both ends of the stroke.

    Parameters
    ----------
    cushion_length : float
        Length of the cushion zone at each end, m (0: no cushion).
    cushion_coefficient : float
        ``c`` of the cushion force ``c v^2``, N s^2/m^2.
    stiffness : float
        Stop stiffness, N/m.
    restitution : float
        Coefficient of restitution of a free rod bouncing off a stop, 1.
    """

    cushion_length: float
    cushion_coefficient: float
    stiffness: float
    restitution: float

    def problems(self, stroke: float) -> list[str]:
        """Every problem with the parameters, as sentences.

        Parameters
        ----------
        stroke : float
            Cylinder stroke, m.
        """
        out: list[str] = []
        check_positive("cushion_length", self.cushion_length, out, "m", zero_ok=True)
        check_positive(
            "cushion_coefficient", self.cushion_coefficient, out, "N.s2/m2", zero_ok=True
        )
        check_positive("stop_stiffness", self.stiffness, out, "N/m")
        if not (0.0 < self.restitution <= 1.0):
            out.append(f"parameter 'stop_restitution' must lie in (0, 1], got {self.restitution}")
        if 2.0 * self.cushion_length >= stroke > 0.0:
            out.append(
                f"parameter 'cushion_length' ({self.cushion_length} m) must be less than "
                f"half the stroke ({stroke} m)"
            )
        return out

    def damping(self, mass: float) -> float:
        """Stop dashpot ``2 zeta sqrt(k m)`` giving the set restitution for ``mass`` (kg), N s/m.

        Parameters
        ----------
        mass : float
            Moving mass that meets the stop, kg.
        """
        zeta = damping_ratio_for_restitution(self.restitution)
        return 2.0 * zeta * math.sqrt(self.stiffness * mass)


def restitution_of_damping_ratio(zeta: float) -> float:
    """Restitution of a linear spring-dashpot contact released when its force vanishes.

    ``e = exp(-2 zeta arccos(zeta) / sqrt(1 - zeta^2))`` for ``zeta < 1``,
    ``exp(-2)`` at ``zeta = 1`` and ``exp(-2 zeta arccosh(zeta) / sqrt(zeta^2 - 1))``
    above (Schwager and Poeschel 2007).

    Parameters
    ----------
    zeta : float
        Damping ratio ``c / (2 sqrt(k m))`` (>= 0), 1.
    """
    if zeta < 1.0:
        return math.exp(-2.0 * zeta * math.acos(zeta) / math.sqrt(1.0 - zeta * zeta))
    if zeta == 1.0:
        return math.exp(-2.0)
    return math.exp(-2.0 * zeta * math.acosh(zeta) / math.sqrt(zeta * zeta - 1.0))


def damping_ratio_for_restitution(restitution: float) -> float:
    """Damping ratio whose force-release contact has ``restitution`` (0 < e <= 1), 1.

    Parameters
    ----------
    restitution : float
        Coefficient of restitution, 1.
    """
    if restitution >= 1.0:
        return 0.0
    upper = 1.0
    while restitution_of_damping_ratio(upper) > restitution:
        upper *= 4.0
    return brentq(
        lambda z: restitution_of_damping_ratio(z) - restitution,
        0.0,
        upper,
        xtol=1e-15,
        rtol=4 * np.finfo(float).eps,
    )


class EndStops:
    """Cushions and stops at both ends of a stroke: modes, force, energy, loss, guards.

    Parameters
    ----------
    spec : EndStopSpec
        Validated parameters.
    stroke : float
        Length of the stroke, m.
    mass : float
        Mass that runs into the stops (sets the dashpot for the restitution), kg.
    """

    def __init__(self, spec: EndStopSpec, stroke: float, mass: float) -> None:
        self.spec = spec
        self.stroke = stroke
        self.damping = spec.damping(mass)
        """Stop dashpot, N s/m."""
        self.guard_kinds: list[tuple[str, int]] = []
        """The guards, as ``(kind, end)``: ``contact``, ``pad`` (a kink) and ``cushion``."""
        for end in (RETRACTED, EXTENDED):
            self.guard_kinds += [("contact", end), ("pad", end)]
            if spec.cushion_length > 0.0:
                self.guard_kinds.append(("cushion", end))
        self.contact = [False, False]
        self.in_cushion = [False, False]
        self.contact_since = -math.inf
        """When the rod last came onto a stop, s (-inf: never)."""

    def start(self, position: float) -> None:
        """Modes at the start: off the stops, inside a cushion zone if there.

        Parameters
        ----------
        position : float
            Rod position along the stroke, m.
        """
        self.contact = [False, False]
        self.contact_since = -math.inf
        cushioned = self.spec.cushion_length > 0.0
        self.in_cushion = [
            cushioned and position < self.cushion_boundary(RETRACTED),
            cushioned and position > self.cushion_boundary(EXTENDED),
        ]

    def cushion_boundary(self, end: int) -> float:
        """Position where the cushion zone of ``end`` begins, m.

        Parameters
        ----------
        end : int
            :data:`RETRACTED` or :data:`EXTENDED`.
        """
        length = self.spec.cushion_length
        return length if end == RETRACTED else self.stroke - length

    def forces(self, pos: float, vel: float):
        """Force on the rod (N), pad depths (m), trial stop forces (N), loss (W), pad energy (J).

        Parameters
        ----------
        pos : float
            Rod position, m.
        vel : float
            Rod velocity along extension, m/s.
        """
        k, c = self.spec.stiffness, self.damping
        depth = (-pos, pos - self.stroke)
        inward = (-vel, vel)  # rate of penetration at each end
        trial = (k * depth[0] + c * inward[0], k * depth[1] + c * inward[1])
        force = loss = energy = 0.0
        for end, direction in ((RETRACTED, 1.0), (EXTENDED, -1.0)):
            if self.in_cushion[end]:
                speed = max(inward[end], 0.0)
                cushion = self.spec.cushion_coefficient * speed * speed
                force += direction * cushion
                loss += cushion * speed
            if self.contact[end]:  # smooth inside the mode, whatever the sign of the depth
                energy += 0.5 * k * depth[end] ** 2
                force += direction * trial[end]
                loss += c * inward[end] ** 2
            elif depth[end] > 0.0:  # the unloaded pad relaxes behind a rod that leaves faster
                energy += 0.5 * k * depth[end] ** 2
                loss -= k * depth[end] * inward[end]
        return force, depth, trial, loss, energy

    def guard(self, kind: str, end: int, pos: float, depth: tuple, trial: tuple) -> float:
        """Value of one guard (>= 0 inside the mode; pads: the kink at zero depth).

        Parameters
        ----------
        kind : str
            ``"contact"``, ``"pad"`` or ``"cushion"``.
        end : int
            Which end.
        pos : float
            Rod position, m.
        depth, trial : tuple of float
            Pad depths (m) and trial stop forces (N) from :meth:`forces`.
        """
        if kind == "pad":  # a kink, located for accuracy: the pad is loaded or relaxed
            return -depth[end]
        if kind == "contact":
            if self.contact[end]:
                return trial[end]
            return max(-self.spec.stiffness * depth[end], -trial[end])
        boundary = self.cushion_boundary(end)  # cushion zone
        inside = pos - boundary if end == EXTENDED else boundary - pos
        return inside if self.in_cushion[end] else -inside

    def switch(self, kind: str, end: int, t: float) -> str | None:
        """Switch the mode a fired guard stands for; the event's text (None for a pad kink).

        Parameters
        ----------
        kind : str
            The guard's kind.
        end : int
            Which end.
        t : float
            Time of the event, s.
        """
        if kind == "contact":
            self.contact[end] = not self.contact[end]
            self.contact_since = t if self.contact[end] else self.contact_since
            what = "reaches" if self.contact[end] else "leaves"
            return f"rod {what} the {END_NAMES[end]} end stop"
        if kind == "cushion":
            self.in_cushion[end] = not self.in_cushion[end]
            what = "enters" if self.in_cushion[end] else "leaves"
            return f"rod {what} the {END_NAMES[end]} cushion"
        return None

    def cushion_speed(self, vel: float) -> float:
        """Speed (m/s) at which the rod runs into a cushion it is in; 0 otherwise.

        Parameters
        ----------
        vel : float
            Rod velocity along extension, m/s.
        """
        speed = 0.0
        if self.in_cushion[RETRACTED]:
            speed = max(speed, -vel)
        if self.in_cushion[EXTENDED]:
            speed = max(speed, vel)
        return speed

    def contact_frequency(self, mass: float) -> tuple[float, float]:
        """Angular frequency (rad/s) and damping ratio (1) of ``mass`` (kg) on a stop.

        Parameters
        ----------
        mass : float
            The mass on the stop, kg.
        """
        omega = math.sqrt(self.spec.stiffness / mass)
        return omega, damping_ratio_for_restitution(self.spec.restitution)

    def snapshot(self) -> tuple:
        """The modes, to :meth:`restore` in this process (cheaper than :meth:`get_state`)."""
        return tuple(self.contact), tuple(self.in_cushion), self.contact_since

    def restore(self, snapshot: tuple) -> None:
        """Restore the modes from :meth:`snapshot`.

        Parameters
        ----------
        snapshot : tuple
            As :meth:`snapshot` returned it.
        """
        contact, in_cushion, self.contact_since = snapshot
        self.contact, self.in_cushion = list(contact), list(in_cushion)

    def get_state(self) -> dict:
        """The modes, as JSON data."""
        since = self.contact_since
        return {
            "contact": [bool(b) for b in self.contact],
            "in_cushion": [bool(b) for b in self.in_cushion],
            "contact_since": since if math.isfinite(since) else None,
        }

    def set_state(self, state: dict) -> None:
        """Restore modes from :meth:`get_state`.

        Parameters
        ----------
        state : dict
            As :meth:`get_state` returned it.
        """
        self.contact = [bool(b) for b in state["contact"]]
        self.in_cushion = [bool(b) for b in state["in_cushion"]]
        since = state["contact_since"]
        self.contact_since = -math.inf if since is None else float(since)

"""The coupling energy guard: a blow-up across a bond stops the run, with a message.

A power bond couples two units through held values: over a macro step the
flow side is given ``e_held`` and the effort side ``f_held`` while both move
on. The energy the coupling creates (positive) or destroys over the step is
its *residual* ``dE`` (:meth:`~wire_fmu.master.simulation.Simulation.bond_residuals`,
SPEC section 15): what the flow side received minus what the effort side
gave. It is zero for the exact (monolithic) solution, and for lossless
units it is the energy the pair gains (within 1 % on the two-mass
oscillator, against the energy computed from its states).

A stable coupling creates and destroys a little, of either sign, at the
order of its scheme. A coupling that is unstable at the macro step (a mode
across the bond with omega H of order one, explicit coupling) grows by
*creating* energy; one that rings in a slack-and-snap limit cycle creates
and destroys large amounts with little net. Either way the coupling's
energy error ``E_err = sum(|dE|)`` becomes comparable to the energy the bond
carries, ``W = sum(h |P|)`` with ``P`` the power it transmits. A step across
a mode event of either unit (a break, slack to taut, stick to slip) has a
first-order residual by construction (an effort that jumps inside a step
cannot be held right): it counts in the net, not in ``E_err``. The run stops
when, for some bond,

    E_err > max(energy_guard * W, energy_tolerance)

with ``energy_guard`` a run setting (default :data:`DEFAULT_SHARE`; ``inf``
turns the guard off) and the run's ``energy_tolerance`` (J) as a floor below
which nothing is called a blow-up (round-off at a bond that carries nothing,
or the one zero-order step after a start from rest, whose residual is the
whole energy it carried).

Measured, peak ``E_err / W`` once ``E_err`` passes 1 J: the shipped scenes at
their settings 1e-5 to 5e-4; the riser tensioner at four times its step
(Gauss-Seidel, 8 ms) 2e-3, with Jacobi and constant hold at 4 ms 6e-3 (a
bounded if inaccurate run: its tension stays in 330-384 kN). Blow-ups: the riser
tensioner with Jacobi coupling at 8 ms (constant, linear and quadratic hold;
the last a limit cycle of slack and 0.8 MN snaps whose net created energy is
negative) pass 0.1 and are stopped 0.1-0.2 s after the tension first leaves
its physical band; the winch-and-fall hard case (a 510 rad/s mode across
the rope bond) at omega H = 1 and 10 within a few steps of the hoist. A share
of 0.1 leaves a margin of over 15 to the worst stable run. It is a blow-up
detector, not an accuracy control (for that, ``adaptive``).
"""

from __future__ import annotations

import math
from collections.abc import Collection, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .scene import RunSettings

__all__ = ["DEFAULT_SHARE", "BondEnergy", "EnergyGuard"]

DEFAULT_SHARE = 0.1
"""Largest share of the energy a bond carried that its coupling's energy error may reach."""


@dataclass
class BondEnergy:
    """What one bond's coupling has done since the start.

    Attributes
    ----------
    created : float
        Net energy the coupling created (positive) or destroyed (negative), J.
    error : float
        Energy the coupling created or destroyed, summed in magnitude step by step
        over the steps that crossed no mode event, J.
    carried : float
        Energy that passed through the bond, either way, J.
    """

    created: float = 0.0
    error: float = 0.0
    carried: float = 0.0


class EnergyGuard:
    """Books every bond's coupling energy error and carried energy; says when one blows up.

    Parameters
    ----------
    bonds : iterable of str
        The bonds' names.
    share : float
        ``energy_guard``: largest ``error / carried`` ratio, dimensionless
        (``inf``: never stop).
    floor : float
        Energy error below which no bond is called unstable, J.
    remedies : sequence of str
        What the user could change, for the stop message.
    """

    def __init__(
        self,
        bonds: Iterable[str],
        share: float,
        floor: float,
        remedies: Sequence[str] = ("a smaller step",),
    ) -> None:
        self.share = share
        self.floor = floor
        self.remedies = tuple(remedies)
        self.bonds = {name: BondEnergy() for name in bonds}

    def book(
        self,
        residuals: Mapping[str, float],
        powers: Mapping[str, float],
        h: float,
        across_events: Collection[str] = (),
    ) -> None:
        """Add one accepted step's residuals (J) and transmitted powers (W) over ``h`` (s).

        Bonds in ``across_events`` took the step across a mode event of one of
        their units (a break, slack to taut, stick to slip): an effort that jumps
        inside a step cannot be held right, so its residual counts in ``created``
        but not in ``error``.

        Parameters
        ----------
        residuals : mapping of str to float
            Energy each bond's coupling created over the step, by bond name, J.
        powers : mapping of str to float
            Power each bond transmitted over the step, by bond name, W.
        h : float
            The macro step, s.
        across_events : collection of str
            Names of the bonds whose step crossed a mode event.
        """
        for name, residual in residuals.items():
            bond = self.bonds[name]
            bond.created += residual
            bond.carried += abs(powers[name]) * h
            if name not in across_events:
                bond.error += abs(residual)

    def limit(self, name: str) -> float:
        """Energy error at which bond ``name`` stops the run now, J.

        Parameters
        ----------
        name : str
            The bond's name.
        """
        return max(self.share * self.bonds[name].carried, self.floor)

    def blow_up(self, t: float, h: float) -> str | None:
        """The stop message if some bond's coupling energy error is too large, else None.

        Parameters
        ----------
        t : float
            Time reached, s.
        h : float
            The macro step just taken, s.
        """
        if math.isinf(self.share) or self._within_limits():
            return None
        unstable = [
            (name, bond) for name, bond in self.bonds.items() if not bond.error <= self.limit(name)
        ]  # a NaN residual is unstable too
        details = "; ".join(_describe(name, bond) for name, bond in unstable)
        return (
            f"t = {t:.6g} s: the coupling blows up at the macro step {h:.3g} s: {details} "
            f"(limit: energy_guard = {self.share:g} of the carried energy, at least "
            f"energy_tolerance {self.floor:g} J). The dynamics coupled across the bond "
            f"are too fast for this step: use {' or '.join(self.remedies)}"
        )

    def _within_limits(self) -> bool:
        """Whether every bond's error is within its limit (a NaN is not); after every step."""
        share, floor = self.share, self.floor
        for bond in self.bonds.values():
            limit = share * bond.carried  # max(limit, floor), as the builtin (a NaN stays)
            if floor > limit:
                limit = floor
            if not bond.error <= limit:
                return False
        return True


def _describe(name: str, bond: BondEnergy) -> str:
    text = f"bond '{name}' created and destroyed {bond.error:.3g} J (net {bond.created:+.3g} J)"
    if bond.carried > 0.0 and math.isfinite(bond.error):
        share = 100 * bond.error / bond.carried
        return text + f", {share:.3g} % of the {bond.carried:.3g} J it carried"
    return text + f" while it carried {bond.carried:.3g} J"


def _remedies(s: RunSettings) -> list[str]:
    """What the energy guard's message suggests, given the run settings."""
    remedies = ["a smaller step" if not s.adaptive else "a smaller energy_tolerance"]
    if s.iterations == 1:
        remedies.append("iterations > 1")
    if not s.adaptive:
        remedies.append("adaptive = true")
    return remedies

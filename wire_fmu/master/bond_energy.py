"""Energy residual of a bond over a macro step: energy its coupling created or destroyed.

Energy residual of a bond over a step (SPEC section 15): the flow side got
``e_held * dx`` (``dx`` its displacement: exact from a position link, else
``h * mean(flow)``) while the effort side gave ``mean(effort) * f_held * h``
and, with a position link, ``e1 * (dx - f_held * h)`` more when its position
input is set to the source's new value at the next step (the jump its own
integration of ``f_held`` missed). Their difference is energy the coupling
created (positive) or destroyed.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .scene import Bond

__all__ = ["BondKeys", "step_energy"]


@dataclass(frozen=True)
class BondKeys:
    """The ``"unit.variable"`` names a bond's energy residual reads, worked out once.

    Parameters
    ----------
    name : str
        The bond's name.
    effort, flow : str
        Sources of the effort and flow links.
    effort_target, flow_target : str
        Inputs the effort and the flow are held at.
    position : str or None
        Source of the position link, if the bond has one.
    """

    name: str
    effort: str
    flow: str
    effort_target: str
    flow_target: str
    position: str | None

    @classmethod
    def of(cls, bond: Bond) -> BondKeys:
        """The names of ``bond``'s links.

        Parameters
        ----------
        bond : Bond
            The bond, with its effort, flow and (optional) position links.

        Returns
        -------
        BondKeys
        """
        position = None if bond.position is None else str(bond.position.source)
        return cls(
            bond.name,
            str(bond.effort.source),
            str(bond.flow.source),
            str(bond.effort.target),
            str(bond.flow.target),
            position,
        )


def step_energy(
    keys: BondKeys,
    latest: Mapping[str, float],
    held: Mapping[str, float],
    new: Mapping[str, float],
    h: float,
) -> tuple[float, float]:
    """Energy the coupling of a bond created over the step just taken, and its power.

    Parameters
    ----------
    keys : BondKeys
        The bond's link names (:meth:`BondKeys.of`).
    latest : mapping of str to float
        Each source output's value at the start of the step, by ``"unit.variable"``,
        in its unit.
    held : mapping of str to float
        What each input (``"unit.variable"``) held over the step; an input not
        in it held its source's latest value.
    new : mapping of str to float
        Each source output at the end of the step.
    h : float
        The step just taken, s.

    Returns
    -------
    residual : float
        Energy the coupling created (positive) or destroyed, J.
    power : float
        Power the bond transmitted over the step (held effort times the mean
        flow), W.
    """
    e_key, f_key = keys.effort, keys.flow
    e0, e1 = latest[e_key], new[e_key]
    f_held = held.get(keys.flow_target, latest[f_key])
    e_held = held.get(keys.effort_target, e0)
    if keys.position is None:  # the flow side's displacement, by the trapezoidal rule
        moved, jump = 0.5 * (latest[f_key] + new[f_key]) * h, 0.0
    else:  # exactly; the effort side's position input will jump by what it missed
        p_key = keys.position
        moved = new[p_key] - latest[p_key]
        jump = moved - f_held * h
    power = e_held * moved / h
    # received by the flow side - given by the effort side over the step and the jump
    return e_held * moved - 0.5 * (e0 + e1) * f_held * h - e1 * jump, power

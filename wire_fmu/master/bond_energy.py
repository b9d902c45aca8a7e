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
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .extrapolation import History
    from .scene import Bond

__all__ = ["bond_step_energy"]


def bond_step_energy(
    bond: Bond,
    histories: Mapping[str, History],
    held: Mapping[str, float],
    new: Mapping[str, float],
    h: float,
) -> tuple[float, float]:
    """Energy the coupling of ``bond`` created over the step just taken, and its power.

    Parameters
    ----------
    bond : Bond
        The bond, with its effort, flow and (optional) position links.
    histories : mapping of str to History
        Each source output's history (``"unit.variable"``); its latest point is
        the value at the start of the step.
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
    e_key, f_key = str(bond.effort.source), str(bond.flow.source)
    e0, e1 = histories[e_key].latest, new[e_key]
    f_held = held.get(str(bond.flow.target), histories[f_key].latest)
    e_held = held.get(str(bond.effort.target), e0)
    if bond.position is None:  # the flow side's displacement, by the trapezoidal rule
        moved, jump = 0.5 * (histories[f_key].latest + new[f_key]) * h, 0.0
    else:  # exactly; the effort side's position input will jump by what it missed
        p_key = str(bond.position.source)
        moved = new[p_key] - histories[p_key].latest
        jump = moved - f_held * h
    power = e_held * moved / h
    # received by the flow side - given by the effort side over the step and the jump
    return e_held * moved - 0.5 * (e0 + e1) * f_held * h - e1 * jump, power

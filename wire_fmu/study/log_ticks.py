"""Tick labels of the studies' log axes that never collide: decades, or 1-2-5 over few decades."""

from __future__ import annotations

import math

__all__ = ["log_ticks", "power_of_ten"]


def log_ticks(ax, *, x: bool = True, y: bool = True, most: int = 8) -> None:
    """Label a log axis at 1, 2 and 5 of each decade when it spans at most 2.5, else at decades.

    Minor ticks stay unlabelled; at most about ``most`` labels per axis (decades
    are thinned beyond that). Call once everything is drawn: it reads the limits.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes with a log scale on the chosen axes.
    x, y : bool
        Which axes to label.
    most : int
        Largest number of labelled ticks.
    """
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    chosen = [(ax.xaxis, ax.get_xlim())] * x + [(ax.yaxis, ax.get_ylim())] * y
    for axis, limits in chosen:
        low, high = sorted(limits)
        decades = math.log10(high / low) if low > 0 and high > 0 else math.inf
        subs = (1.0, 2.0, 5.0) if decades <= 2.5 else (1.0,)
        axis.set_major_locator(LogLocator(base=10.0, subs=subs, numticks=most))
        axis.set_major_formatter(FuncFormatter(power_of_ten))
        axis.set_minor_formatter(NullFormatter())


def power_of_ten(value: float, _position: object = None) -> str:
    """A log-axis tick as ``10^-3`` or ``2 x 10^-3`` (mathtext); empty for no positive value.

    Parameters
    ----------
    value : float
        The tick's value.
    _position : object
        The tick's position (unused; matplotlib passes it).
    """
    if not value > 0:
        return ""
    exponent = math.floor(math.log10(value) + 1e-9)
    coefficient = round(value / 10.0**exponent)
    power = f"10^{{{exponent}}}"
    return f"${power}$" if coefficient == 1 else f"${coefficient}\\times{power}$"

"""Tick labels of the plots' value axes: the numbers themselves, in plain text.

matplotlib's ``ScalarFormatter(useMathText=True)`` writes the power of ten above an axis
as ``×10⁶`` rather than ``1e6``, but it also sets every tick label in mathtext, whose
parser is built at the first label a process draws: half a second of every
``wire-fmu run`` on the project's slower machine, for labels that look the same in
plain text. :class:`PlainTicks` keeps plain labels and writes the power of ten with
Unicode superscripts.
"""

from __future__ import annotations

import re

from matplotlib.ticker import ScalarFormatter

__all__ = ["PlainTicks", "power_of_ten"]

_SUPERSCRIPTS = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
_PLAIN_POWER = re.compile(r"1e([-\u2212]?\d+)")
"""The power of ten as ``ScalarFormatter`` writes it in plain text (``1e6``, ``1e−3``)."""


def power_of_ten(exponent: int) -> str:
    """``×10`` and ``exponent`` as superscript digits (``×10⁶``, ``×10⁻³``); ``""`` for 0.

    Parameters
    ----------
    exponent : int
        The power of ten.
    """
    return "×10" + str(exponent).translate(_SUPERSCRIPTS) if exponent else ""


class PlainTicks(ScalarFormatter):
    """Tick labels as the numbers themselves, never less an offset; a power of ten stands
    above very small or large ones, as ``×10ⁿ``."""

    def __init__(self) -> None:
        super().__init__(useOffset=False, useMathText=False)

    def get_offset(self) -> str:
        """The power of ten the tick labels are in (``×10ⁿ``), or ``""``.

        Extends :meth:`matplotlib.ticker.ScalarFormatter.get_offset`, whose plain-text
        form is ``1eN``.
        """
        plain = super().get_offset()
        found = _PLAIN_POWER.fullmatch(plain)
        if found is None:
            return plain
        return power_of_ten(int(found.group(1).replace("\u2212", "-")))

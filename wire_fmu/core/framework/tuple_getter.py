"""Take several values out of one object in one call, in C, always as a tuple.

:func:`operator.itemgetter` and :func:`operator.attrgetter` do it without a Python
loop, which matters for what runs every step (a unit's batch of outputs, the
facade's batch reads); but with one key they answer the bare value and with none
they cannot be made. :func:`tuple_getter` wraps those two cases.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

__all__ = ["tuple_getter"]


def tuple_getter(make: Callable[..., Callable[[Any], Any]], keys: Sequence[str]):
    """``make(*keys)`` (``operator.itemgetter`` or ``attrgetter``), answering a tuple for
    any number of keys.

    Parameters
    ----------
    make : callable
        :func:`operator.itemgetter` or :func:`operator.attrgetter`.
    keys : sequence of str
        The items or attributes, in the order of the answer.

    Returns
    -------
    callable
        ``getter(obj)``: the tuple of the keys' values in ``obj``.
    """
    if len(keys) > 1:
        return make(*keys)
    if keys:
        one = make(keys[0])
        return lambda obj: (one(obj),)
    return lambda obj: ()

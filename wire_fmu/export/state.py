"""JSON-compatible deep copies for FMU states.

An FMU state must not alias live model data (a saved ``ndarray`` that the
model keeps integrating in place would change the saved state) and must
serialise through pythonfmu's JSON helpers without loss. Normalising the
state through JSON once, when it is taken, gives both: the in-memory state
is then exactly what deserialisation returns, so a restored state behaves
identically whether or not it went through bytes.
"""

from __future__ import annotations

import json
from typing import Any

__all__ = ["json_copy"]


def _to_builtin(obj: Any) -> Any:
    # numpy arrays and scalars (and anything else array-like) expose tolist();
    # checked by duck typing so this module does not need numpy.
    tolist = getattr(obj, "tolist", None)
    if callable(tolist):
        return tolist()
    raise TypeError(f"object of type {type(obj).__name__} is not JSON-compatible")


def json_copy(data: Any) -> Any:
    """Deep copy of ``data`` as plain JSON types.

    Arrays and numpy scalars become lists and Python scalars, tuples become
    lists; floats (including NaN and infinities) round-trip bit for bit.

    Parameters
    ----------
    data : Any
        Nested dicts (string keys), lists, tuples, numbers, strings, None,
        numpy arrays and scalars.

    Returns
    -------
    Any
        An independent copy made of dict, list, str, int, float, bool, None.

    Raises
    ------
    TypeError
        If ``data`` holds an object JSON cannot represent.
    """
    return json.loads(json.dumps(data, default=_to_builtin, allow_nan=True))

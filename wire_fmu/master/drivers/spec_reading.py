"""Reading a driver's scene table: typed keys, every problem collected, short quotes."""

from __future__ import annotations

import difflib
import math
from collections.abc import Collection, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

_SHOWN = 60  # characters of a spec value quoted in a problem
_MAX_HINT_WORD = 100  # longer words get no "did you mean" (difflib is quadratic)


def _close_hint(word: str, choices: Collection[str]) -> str:
    if len(word) > _MAX_HINT_WORD:
        return ""
    close = difflib.get_close_matches(word, list(choices), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def _real(x: Any) -> float | None:
    """``x`` as a finite float; None if it is no finite number (or an int too large)."""
    if not _is_number(x):
        return None
    try:
        value = float(x)
    except OverflowError:
        return None
    return value if math.isfinite(value) else None


def _show(value: Any) -> str:
    """``repr(value)`` for a problem, shortened (a spec may hold a huge array)."""
    if isinstance(value, str) and len(value) > 10_000:
        return f"a text of {len(value)} characters"
    if isinstance(value, list | tuple | dict) and len(value) > 10_000:
        return f"a {type(value).__name__} of {len(value)} items"
    text = repr(value)
    return text if len(text) <= _SHOWN else f"{text[: _SHOWN - 5]} ..."


class _Reader:
    """Reads keys of one driver table, collecting every problem."""

    def __init__(self, spec: Mapping[str, Any], where: str) -> None:
        self.spec = spec
        self.where = where
        self.problems: list[str] = []

    def add(self, text: str) -> None:
        """Record a problem, prefixed with where it is.

        Parameters
        ----------
        text : str
            The problem, e.g. ``"'period' must be > 0 s, got -1"``.
        """
        self.problems.append(f"{self.where}: {text}")

    def has(self, key: str) -> bool:
        """Whether the table sets ``key``.

        Parameters
        ----------
        key : str
            A key of the driver table.
        """
        return key in self.spec

    def number(
        self,
        key: str,
        default: float | None = None,
        *,
        unit: str = "",
        minimum: float | None = None,
        positive: bool = False,
    ) -> float:
        """A finite number (NaN after a problem); ``default`` None means required.

        Parameters
        ----------
        key : str
            A key of the driver table.
        default : float, optional
            Value when the key is absent; None makes the key required.
        unit : str
            Unit of the number, for problems (``"s"``, ``"m"``, ``"Hz"``).
        minimum : float, optional
            Smallest value allowed, in ``unit``.
        positive : bool
            Whether the value must be > 0.
        """
        if key not in self.spec:
            if default is None:
                self.add(f"'{key}' is required")
                return math.nan
            return default
        raw = self.spec[key]
        suffix = f" {unit}" if unit else ""
        value = _real(raw)
        if value is None:
            in_unit = f" in {unit}" if unit else ""
            self.add(f"'{key}' must be a finite number{in_unit}, got {_show(raw)}")
            return math.nan
        if positive and not value > 0:
            self.add(f"'{key}' must be > 0{suffix}, got {_show(raw)}")
            return math.nan
        if minimum is not None and value < minimum:
            self.add(f"'{key}' must be >= {minimum:g}{suffix}, got {_show(raw)}")
            return math.nan
        return value

    def integer(self, key: str, default: int, *, minimum: int, maximum: int | None = None) -> int:
        """An integer in [``minimum``, ``maximum``] (``default`` after a problem).

        Parameters
        ----------
        key : str
            A key of the driver table.
        default : int
            Value when the key is absent or wrong.
        minimum : int
            Smallest value allowed.
        maximum : int, optional
            Largest value allowed (None: no bound).
        """
        raw = self.spec.get(key, default)
        if not isinstance(raw, int) or isinstance(raw, bool):
            self.add(f"'{key}' must be an integer, got {_show(raw)}")
            return default
        if raw < minimum:
            self.add(f"'{key}' must be an integer >= {minimum}, got {_show(raw)}")
            return default
        if maximum is not None and raw > maximum:
            self.add(f"'{key}' must be an integer <= {maximum}, got {_show(raw)}")
            return default
        return raw

    def choice(self, key: str, default: str, choices: Collection[str]) -> str:
        """One of ``choices`` (``default`` after a problem).

        Parameters
        ----------
        key : str
            A key of the driver table.
        default : str
            Value when the key is absent or wrong.
        choices : collection of str
            The values allowed.
        """
        raw = self.spec.get(key, default)
        if not isinstance(raw, str) or raw not in choices:
            hint = _close_hint(raw, choices) if isinstance(raw, str) else ""
            self.add(f"'{key}' must be one of {', '.join(choices)}, got {_show(raw)}{hint}")
            return default
        return raw

    def text(self, key: str, default: str | None = None) -> str:
        """A non-empty string ('' after a problem).

        Parameters
        ----------
        key : str
            A key of the driver table.
        default : str, optional
            Value when the key is absent; None makes the key required.
        """
        raw = self.spec.get(key, default)
        if raw is None:
            self.add(f"'{key}' is required")
            return ""
        if not isinstance(raw, str) or not raw.strip():
            self.add(f"'{key}' must be a non-empty string, got {_show(raw)}")
            return ""
        return raw

    def unknown_keys(self, allowed: Collection[str]) -> None:
        """Report keys the kind does not know.

        Parameters
        ----------
        allowed : collection of str
            The keys the driver's kind reads, ``kind`` included.
        """
        for key in self.spec:
            if key not in allowed:
                hint = _close_hint(str(key), allowed)
                self.add(
                    f"unknown key {_show(key)} for kind {self.spec['kind']!r}{hint}; "
                    f"known keys: {', '.join(sorted(allowed))}"
                )


def _finite_slopes(times: np.ndarray, values: np.ndarray, label: str, r: _Reader) -> bool:
    """Check every segment's slope is finite (no overflow); report the first offence."""
    with np.errstate(all="ignore"):
        slopes = np.diff(values) / np.diff(times)
    bad = np.flatnonzero(~np.isfinite(slopes))
    if bad.size == 0:
        return True
    k = int(bad[0])
    r.add(
        f"{label}: the slope between entries {k} and {k + 1} (t = {times[k]:g} s and "
        f"{times[k + 1]:g} s) is too large to represent"
    )
    return False


def _increasing(times: np.ndarray, label: str, r: _Reader) -> bool:
    """Check times are strictly increasing; report the first offence and the count."""
    bad = np.flatnonzero(np.diff(times) <= 0.0)
    if bad.size == 0:
        return True
    k = int(bad[0])
    more = f" ({bad.size - 1} more)" if bad.size > 1 else ""
    r.add(
        f"{label} must be strictly increasing: entry {k + 1} (t = {times[k + 1]:g} s) does not "
        f"follow entry {k} (t = {times[k]:g} s){more}"
    )
    return False


@dataclass(frozen=True)
class _Context:
    """What a builder may need besides the table."""

    base_dir: Path

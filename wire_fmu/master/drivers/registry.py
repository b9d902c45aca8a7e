"""The driver kinds a scene may name, and :func:`make_driver`, which builds one."""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

from .builders import _RAMP_SHORT, _build_constant, _build_ramp, _build_sea_state, _build_sine
from .protocol import Driver
from .spec_reading import _close_hint, _Context, _Reader, _show
from .table import _build_table

__all__ = ["DriverKind", "DRIVER_KINDS", "make_driver"]


@dataclass(frozen=True)
class DriverKind:
    """One kind of driver a scene may name.

    Attributes
    ----------
    name : str
        The ``kind`` value in a scene.
    summary : str
        One line on what it does.
    keys : tuple of str
        Keys the table may set besides ``kind``.
    build : callable
        Builds the driver from a key reader; records problems on it.
    """

    name: str
    summary: str
    keys: tuple[str, ...]
    build: Callable[[_Reader, _Context], Driver | None]


_FADE_KEYS = ("start_time", "ramp_time")

DRIVER_KINDS: Mapping[str, DriverKind] = MappingProxyType(
    {
        k.name: k
        for k in (
            DriverKind("constant", "a constant value", ("value",), _build_constant),
            DriverKind(
                "ramp",
                "piecewise linear through points, held outside them",
                ("points", *_RAMP_SHORT),
                _build_ramp,
            ),
            DriverKind(
                "sine",
                "offset + amplitude sin(2 pi t / period + phase), optional fade-in",
                ("amplitude", "period", "frequency", "phase_deg", "offset", *_FADE_KEYS),
                _build_sine,
            ),
            DriverKind(
                "sea_state",
                "irregular heave from a JONSWAP or Pierson-Moskowitz wave spectrum",
                (
                    "significant_height",
                    "peak_period",
                    "spectrum",
                    "gamma",
                    "components",
                    "seed",
                    "cutoff",
                    "heave_rao",
                    *_FADE_KEYS,
                ),
                _build_sea_state,
            ),
            DriverKind(
                "table",
                "linear interpolation in a CSV file's columns",
                ("file", "time_column", "value_column"),
                _build_table,
            ),
        )
    }
)
"""Driver kinds by name (read-only)."""


def _kind_of(spec: Mapping[str, Any], r: _Reader) -> DriverKind | None:
    known = ", ".join(sorted(DRIVER_KINDS))
    kind = spec.get("kind")
    if kind is None:
        r.add(f"'kind' is required; known kinds: {known}")
        return None
    if not isinstance(kind, str) or kind not in DRIVER_KINDS:
        hint = _close_hint(kind, DRIVER_KINDS) if isinstance(kind, str) else ""
        r.add(f"unknown kind {_show(kind)}{hint}; known kinds: {known}")
        return None
    return DRIVER_KINDS[kind]


def make_driver(
    spec: Mapping[str, Any],
    *,
    where: str,
    base_dir: Path,
    ignore: Collection[str] = (),
) -> tuple[Driver | None, list[str]]:
    """Build a driver from a scene table, or list every problem with it.

    Parameters
    ----------
    spec : mapping
        The table: ``kind`` and that kind's keys (see the module docstring
        and :data:`DRIVER_KINDS`).
    where : str
        Prefix of every problem, e.g. ``"driver 3 (rope.mover_b.position)"``.
    base_dir : Path
        Folder of the scene file; relative table files are found there.
    ignore : collection of str, optional
        Keys that belong to the caller (e.g. the scene's ``target``), neither
        read nor reported as unknown.

    Returns
    -------
    driver : Driver or None
        None if there is any problem.
    problems : list of str
        Every problem found, each prefixed with ``where``; empty on success.
        Bad input never raises.
    """
    if not isinstance(spec, Mapping):
        return None, [f"{where}: a driver must be a table with a 'kind', got {_show(spec)}"]
    r = _Reader({k: v for k, v in spec.items() if k not in ignore}, where)
    kind = _kind_of(r.spec, r)
    if kind is None:
        return None, r.problems
    r.unknown_keys(("kind", *kind.keys))
    driver = kind.build(r, _Context(Path(base_dir)))
    if r.problems:
        return None, r.problems
    return driver, []

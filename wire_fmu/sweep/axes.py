"""The axes of a sweep: listed values (a grid) or a distribution sampled together.

What an ``[[axes]]`` table and ``[sampling]`` may say is described in
:mod:`wire_fmu.sweep.spec`; the parsers here add every problem they find
to a list.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np
from scipy.special import ndtri

__all__ = [
    "Axis",
    "Sampling",
    "DISTRIBUTIONS",
    "SAMPLING_METHODS",
    "TARGET_ROOTS",
    "GRID_KEYS",
    "MAX_AXIS_VALUES",
    "well_formed_targets",
]

DISTRIBUTIONS: Mapping[str, tuple[str, str]] = MappingProxyType(
    {
        "uniform": ("low", "high"),
        "log_uniform": ("low", "high"),
        "normal": ("mean", "std"),
    }
)
"""Distribution of a sampled axis -> the two keys that parametrise it."""

SAMPLING_METHODS = ("latin_hypercube", "random")
TARGET_ROOTS = ("units", "drivers", "events", "run")
GRID_KEYS = ("values", "linspace", "logspace")
MAX_AXIS_VALUES = 100_000
"""Most values one ``linspace`` or ``logspace`` axis may list."""
_AXIS_KEYS = frozenset(
    {
        "target",
        "values",
        "linspace",
        "logspace",
        "distribution",
        "low",
        "high",
        "mean",
        "std",
        "integer",
    }
)
_SAMPLING_KEYS = frozenset({"samples", "method", "seed"})


@dataclass(frozen=True)
class Axis:
    """One swept quantity.

    Attributes
    ----------
    target : str
        What it changes (see the module docstring), e.g.
        ``"units.b.parameters.mass"``.
    values : tuple
        The grid values (grid axes only).
    distribution : str or None
        ``"uniform"``, ``"log_uniform"`` or ``"normal"`` (sampled axes only).
    arguments : tuple of float
        ``(low, high)`` or ``(mean, std)`` of the distribution.
    integer : bool
        Values are whole numbers (rounded after spacing or sampling).
    log_scale : bool
        Spaced or drawn geometrically (``logspace``, ``log_uniform``):
        plots put this parameter on a log axis.
    """

    target: str
    values: tuple[Any, ...] = ()
    distribution: str | None = None
    arguments: tuple[float, ...] = ()
    integer: bool = False
    log_scale: bool = False

    @property
    def is_grid(self) -> bool:
        """Whether the axis lists its values (else it is sampled)."""
        return self.distribution is None

    @property
    def kind(self) -> str:
        """Type of the values: ``"int"``, ``"float"``, ``"bool"``, ``"str"`` or ``"json"``."""
        if not self.is_grid:
            return "int" if self.integer else "float"
        return _kind_of(self.values)

    def draw(self, unit: np.ndarray) -> list[float | int]:
        """Map points of the unit interval ``[0, 1)`` onto this axis' distribution.

        Parameters
        ----------
        unit : ndarray, shape (n,)
            Uniform points in ``[0, 1)``.

        Returns
        -------
        list of float (or int with ``integer``)
            The ``n`` values.
        """
        a, b = self.arguments
        if self.distribution == "uniform":
            raw = a + unit * (b - a)
        elif self.distribution == "log_uniform":
            raw = np.exp(math.log(a) + unit * (math.log(b) - math.log(a)))
        else:
            raw = a + b * ndtri(np.clip(unit, 1e-12, 1.0 - 1e-12))
        return [round(float(v)) if self.integer else float(v) for v in raw]


@dataclass(frozen=True)
class Sampling:
    """How sampled axes are drawn: ``samples`` points by ``method`` from ``seed``."""

    samples: int
    method: str = "latin_hypercube"
    seed: int = 0

    def unit_points(self, dimensions: int) -> np.ndarray:
        """Points in the unit hypercube, shape ``(samples, dimensions)``.

        ``latin_hypercube`` puts exactly one point in each of ``samples``
        equal strata of every dimension (strata permuted independently,
        point uniform within its stratum); ``random`` draws independently.
        Both are reproducible from ``seed`` (numpy's PCG64).

        Parameters
        ----------
        dimensions : int
            Number of sampled axes.
        """
        rng = np.random.default_rng(self.seed)
        n = self.samples
        if self.method == "random":
            return rng.random((n, dimensions))
        points = np.empty((n, dimensions))
        for j in range(dimensions):
            points[:, j] = (rng.permutation(n) + rng.random(n)) / n
        return points


# -- axes -----------------------------------------------------------------------------
def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _kind_of(values: tuple[Any, ...]) -> str:
    if values and all(isinstance(v, bool) for v in values):
        return "bool"
    if values and all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        return "int"
    if values and all(_number(v) for v in values):
        return "float"
    if values and all(isinstance(v, str) for v in values):
        return "str"
    return "json"


def _check_target(target: Any, where: str, problems: list[str]) -> bool:
    if not isinstance(target, str) or "." not in target:
        problems.append(
            f"{where}: 'target' must be a dotted path such as "
            f"'units.<unit>.parameters.<name>', got {target!r}"
        )
        return False
    root, _, rest = target.partition(".")
    if root not in TARGET_ROOTS:
        problems.append(
            f"{where}: target {target!r} must start with one of {', '.join(TARGET_ROOTS)}"
        )
        return False
    parts = rest.split(".")
    shapes = {
        "units": len(parts) >= 3 and parts[1] == "parameters" or parts[1:] == ["effects"],
        "drivers": len(parts) >= 2 and parts[0].isdigit(),
        "events": parts[0].isdigit()
        and (parts[1:] == ["time"] or (len(parts) >= 4 and parts[1] == "set")),
        "run": len(parts) == 1,
    }
    if not shapes[root]:
        problems.append(
            f"{where}: target {target!r} must read 'units.<unit>.parameters.<name>', "
            "'units.<unit>.effects', 'drivers.<i>.<key>', 'events.<i>.time', "
            "'events.<i>.set.<unit>.<input>' or 'run.<setting>'"
        )
        return False
    return True


def _spaced(spec: Mapping[str, Any], key: str, where: str, problems: list[str]) -> list[float]:
    raw = spec[key]
    if (
        not isinstance(raw, list)
        or len(raw) != 3
        or not all(_number(v) for v in raw[:2])
        or not isinstance(raw[2], int)
        or isinstance(raw[2], bool)
        or raw[2] < 1
    ):
        problems.append(
            f"{where}: '{key}' must be [start, stop, count] with a whole count >= 1, got {raw!r}"
        )
        return []
    start, stop, count = raw
    if count > MAX_AXIS_VALUES:
        problems.append(f"{where}: '{key}' asks for {count} values, more than {MAX_AXIS_VALUES}")
        return []
    if key == "logspace":
        if start <= 0 or stop <= 0:
            problems.append(f"{where}: 'logspace' needs start and stop > 0, got {raw!r}")
            return []
        return [float(v) for v in np.geomspace(start, stop, count)]
    return [float(v) for v in np.linspace(start, stop, count)]


def _grid_values(
    spec: Mapping[str, Any], key: str, where: str, problems: list[str]
) -> tuple[Any, ...]:
    integer = spec.get("integer", False) is True
    if key != "values":
        values = _spaced(spec, key, where, problems)
        return tuple(round(v) if integer else v for v in values)
    values = spec["values"]
    if not isinstance(values, list) or not values:
        problems.append(f"{where}: 'values' must be a non-empty list")
        return ()
    if any(isinstance(v, float) and not math.isfinite(v) for v in values):
        problems.append(f"{where}: 'values' must be finite")
    if _kind_of(tuple(values)) == "float":  # mixed whole and fractional numbers: all float
        values = [float(v) for v in values]
    if integer:
        values = [round(v) if _number(v) else v for v in values]
    return tuple(values)


def _distribution(
    spec: Mapping[str, Any], where: str, problems: list[str]
) -> tuple[str | None, tuple[float, ...]]:
    name = spec["distribution"]
    if name not in DISTRIBUTIONS:
        problems.append(
            f"{where}: 'distribution' must be one of {', '.join(DISTRIBUTIONS)}, got {name!r}"
        )
        return None, ()
    keys = DISTRIBUTIONS[name]
    args = [spec.get(k) for k in keys]
    if not all(_number(a) for a in args):
        problems.append(f"{where}: a {name} distribution needs numbers {' and '.join(keys)}")
        return None, ()
    a, b = (float(v) for v in args)
    if name == "normal" and b <= 0:
        problems.append(f"{where}: 'std' must be > 0, got {b!r}")
    elif name != "normal" and not a < b:
        problems.append(f"{where}: 'low' must be below 'high', got {a!r} and {b!r}")
    elif name == "log_uniform" and a <= 0:
        problems.append(f"{where}: a log_uniform distribution needs 'low' > 0, got {a!r}")
    spread = (a - 8.0 * b, a + 8.0 * b) if name == "normal" else (a, b - a)
    if not all(math.isfinite(v) and abs(v) < 1e300 for v in spread):
        problems.append(
            f"{where}: the {name} distribution's samples would overflow "
            f"({' and '.join(keys)} {a!r}, {b!r})"
        )
    return str(name), (a, b)


def _parse_axis(i: int, spec: Any, problems: list[str]) -> Axis | None:
    where = f"axis {i}"
    if not isinstance(spec, Mapping):
        problems.append(f"{where}: must be a table ([[axes]])")
        return None
    target = spec.get("target")
    if isinstance(target, str):
        where = f"axis {i} ({target})"
    unknown = set(spec) - _AXIS_KEYS
    if unknown:
        problems.append(f"{where}: unknown keys {sorted(unknown)}; known: {sorted(_AXIS_KEYS)}")
    ok = _check_target(target, where, problems)
    if "integer" in spec and not isinstance(spec["integer"], bool):
        problems.append(f"{where}: 'integer' must be true or false")
    given = [k for k in (*GRID_KEYS, "distribution") if k in spec]
    if len(given) != 1:
        problems.append(
            f"{where}: give exactly one of 'values', 'linspace', 'logspace' or "
            f"'distribution', got {given or 'none'}"
        )
        return None
    key, integer = given[0], spec.get("integer", False) is True
    if key == "distribution":
        distribution, arguments = _distribution(spec, where, problems)
        if distribution is None or not ok:
            return None
        return Axis(
            target,
            distribution=distribution,
            arguments=arguments,
            integer=integer,
            log_scale=distribution == "log_uniform",
        )
    values = _grid_values(spec, key, where, problems)
    _check_duplicates(values, where, problems)
    if not values or not ok:
        return None
    return Axis(target, values=values, integer=integer, log_scale=key == "logspace")


def _check_duplicates(values: tuple[Any, ...], where: str, problems: list[str]) -> None:
    seen: set[str] = set()  # by their JSON text: linear, and unhashable values compare too
    for value in values:
        key = json.dumps(value, sort_keys=True, default=repr)
        if key in seen:
            problems.append(f"{where}: value {value!r} appears twice (each case must differ)")
        seen.add(key)


def _parse_axes(data: Any, problems: list[str]) -> list[Axis]:
    if not isinstance(data, list) or not data:
        problems.append("the spec needs at least one [[axes]] table")
        return []
    axes = [_parse_axis(i, spec, problems) for i, spec in enumerate(data)]
    targets = [a.target for a in axes if a is not None]
    for target in sorted({t for t in targets if targets.count(t) > 1}):
        problems.append(f"target {target!r} is swept by more than one axis")
    return [a for a in axes if a is not None]


def well_formed_targets(data: Any) -> list[str]:
    """The targets of the ``[[axes]]`` tables that are well formed, whatever else is amiss.

    Parameters
    ----------
    data : Any
        The spec's ``axes``, as read.
    """
    if not isinstance(data, list):
        return []
    specs = [spec for spec in data if isinstance(spec, Mapping)]
    return [spec["target"] for spec in specs if _check_target(spec.get("target"), "", problems=[])]


def _parse_sampling(data: Any, axes: list[Axis], problems: list[str]) -> Sampling | None:
    sampled = [a.target for a in axes if not a.is_grid]
    if data is None:
        if sampled:
            problems.append(f"axes {sampled} are sampled: the spec needs [sampling] with 'samples'")
        return None
    if not isinstance(data, Mapping):
        problems.append("[sampling] must be a table")
        return None
    unknown = set(data) - _SAMPLING_KEYS
    if unknown:
        problems.append(
            f"sampling: unknown keys {sorted(unknown)}; known: {sorted(_SAMPLING_KEYS)}"
        )
    if not sampled:
        problems.append("[sampling] is given but no axis has a 'distribution'")
    samples, method, seed = (
        data.get("samples"),
        data.get("method", "latin_hypercube"),
        data.get("seed", 0),
    )
    if not isinstance(samples, int) or isinstance(samples, bool) or samples < 1:
        problems.append(f"sampling.samples must be a whole number >= 1, got {samples!r}")
        return None
    if samples > MAX_AXIS_VALUES:
        problems.append(f"sampling.samples = {samples}: more than {MAX_AXIS_VALUES}")
        return None
    if method not in SAMPLING_METHODS:
        problems.append(
            f"sampling.method must be one of {', '.join(SAMPLING_METHODS)}, got {method!r}"
        )
        return None
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        problems.append(f"sampling.seed must be a whole number >= 0, got {seed!r}")
        return None
    return Sampling(samples, method, seed)

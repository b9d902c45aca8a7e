"""SWEEP_SPEC files: what a parameter sweep varies and what it measures per case.

A sweep spec is a TOML file (data only, nothing is executed).
:func:`load_sweep_spec` reads it and :func:`parse_sweep_spec` checks the
data, listing every problem at once (:class:`SweepSpecError`). Whether the
targets exist in a given scene is checked by
:func:`wire_fmu.sweep.cases.check_targets`.

Format::

    name = "gas_volume_vs_sea_state"      # default: the file's name
    description = "Tensioner stroke against gas volume and sea state"

    # A grid axis lists its values (or spaces them); the grid is the
    # Cartesian product of all grid axes, the first axis varying slowest.
    [[axes]]
    target = "units.cylinder.parameters.gas_volume"
    values = [0.5, 1.0, 2.0]

    [[axes]]
    target = "drivers.0.significant_height"
    linspace = [1.0, 4.0, 4]              # start, stop, count (inclusive)
    # logspace = [1.0e-3, 1.0e-1, 5]      # start, stop, count, geometric

    # A sampled axis draws from a distribution; all sampled axes are drawn
    # together, [sampling] samples times, and every sample is combined with
    # every grid point.
    [[axes]]
    target = "units.cylinder.parameters.precharge"
    distribution = "uniform"              # low, high
    low = 1.0e6
    high = 2.0e6
    # distribution = "log_uniform"        # low, high (both > 0)
    # distribution = "normal"             # mean, std
    # integer = true                      # round to whole numbers

    [sampling]
    samples = 20
    method = "latin_hypercube"            # or "random"
    seed = 1

    # Key figures, one summary column each: name = "function(column)".
    [figures]
    peak_tension = "max(rope.path_end.tension)"
    tension_range = "range(rope.path_end.tension)"
    final_stroke = 'final("cylinder.rod.position")'

Targets (what an axis changes):

* ``units.<unit>.parameters.<name>`` - a unit parameter; a name that is a
  table (or list) in the scene may be followed by a path into it, e.g.
  ``units.rope.parameters.reeving.sheaves.2.radius`` (list items by index);
* ``units.<unit>.effects`` - the unit's effect list (a list of names);
* ``drivers.<i>.<key>`` - a key of the scene's ``i``-th driver (from 0, in
  file order), e.g. ``drivers.0.significant_height``;
* ``events.<i>.time`` or ``events.<i>.set.<unit>.<input>`` - the ``i``-th
  scheduled event (in time order, as the scene lists them after parsing);
* ``run.<setting>`` - a run setting, e.g. ``run.step``.

Key figure functions, over every recorded sample of the column:
``max`` (the peak), ``min``, ``absmax`` (largest magnitude), ``range``
(max - min), ``final`` (the last recorded value), ``mean`` (time-weighted,
trapezoidal, over the recorded span). The column is a recorded output
``unit.variable`` (the sweep makes sure it is recorded), a bond channel
``bond.<name>.energy_residual`` / ``.energy_carried`` / ``.power`` or
``energy.units_balance``.
"""

from __future__ import annotations

import json
import math
import re
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from scipy.special import ndtri

from wire_fmu.core.errors import ConfigurationError, WireFmuError
from wire_fmu.master.files import UnreadableFileError, read_regular
from wire_fmu.master.scene import MAX_SCENE_BYTES, is_plain_name

__all__ = [
    "Axis",
    "Figure",
    "Sampling",
    "SweepSpec",
    "SweepSpecError",
    "SweepError",
    "load_sweep_spec",
    "parse_sweep_spec",
    "FUNCTIONS",
    "DISTRIBUTIONS",
    "SAMPLING_METHODS",
    "TARGET_ROOTS",
    "RESERVED_COLUMNS",
]


class SweepSpecError(ConfigurationError):
    """A sweep spec with problems; ``problems`` lists every one."""


class SweepError(WireFmuError, RuntimeError):
    """A sweep that cannot go on: workers that differ, an output folder of another sweep."""


def _peak(time: np.ndarray, values: np.ndarray) -> float:
    return float(np.max(values))


def _low(time: np.ndarray, values: np.ndarray) -> float:
    return float(np.min(values))


def _absmax(time: np.ndarray, values: np.ndarray) -> float:
    return float(np.max(np.abs(values)))


def _range(time: np.ndarray, values: np.ndarray) -> float:
    return float(np.max(values) - np.min(values))


def _final(time: np.ndarray, values: np.ndarray) -> float:
    return float(values[-1])


def _mean(time: np.ndarray, values: np.ndarray) -> float:
    span = float(time[-1] - time[0])
    if len(values) < 2 or span <= 0.0:
        return float(values[-1])
    area = np.sum(0.5 * (values[1:] + values[:-1]) * np.diff(time))
    return float(area / span)


FUNCTIONS: Mapping[str, Callable[[np.ndarray, np.ndarray], float]] = MappingProxyType(
    {
        "max": _peak,
        "min": _low,
        "absmax": _absmax,
        "range": _range,
        "final": _final,
        "mean": _mean,
    }
)
"""Key figure functions: ``f(time, values) -> float`` over the recorded samples."""

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
RESERVED_COLUMNS = frozenset(
    {
        "case_id",
        "index",
        "status",
        "error",
        "wall_time",
        "end_time",
        "worker",
        "attempts",
        "finished_at",
    }
)
"""Columns every summary row has; a key figure may not take one of these names."""

_TOP_KEYS = frozenset({"name", "description", "axes", "sampling", "figures", "max_cases"})
MAX_CASES = 10_000
"""Default most cases a sweep may have (``max_cases`` in the spec allows more)."""
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
_FIGURE_RE = re.compile(r"""^\s*([A-Za-z_]+)\s*\(\s*(["']?)([^"'()\s]+)\2\s*\)\s*$""")


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
class Figure:
    """A key figure: one function of one recorded column, one number per case.

    Attributes
    ----------
    name : str
        Summary column name (an identifier).
    function : str
        One of :data:`FUNCTIONS`.
    column : str
        The recorded column, e.g. ``"rope.path_end.tension"``.
    """

    name: str
    function: str
    column: str

    @property
    def expression(self) -> str:
        """``function(column)``, as written in a spec."""
        return f"{self.function}({self.column})"

    def evaluate(self, columns: Mapping[str, np.ndarray]) -> float | None:
        """The figure from recorded columns; None when the column has no samples.

        Parameters
        ----------
        columns : mapping of str to ndarray
            Recorded columns by name, with ``"time"`` (s).
        """
        values = columns.get(self.column)
        if values is None or len(values) == 0:
            return None
        return FUNCTIONS[self.function](np.asarray(columns["time"]), np.asarray(values))


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
        """
        rng = np.random.default_rng(self.seed)
        n = self.samples
        if self.method == "random":
            return rng.random((n, dimensions))
        points = np.empty((n, dimensions))
        for j in range(dimensions):
            points[:, j] = (rng.permutation(n) + rng.random(n)) / n
        return points


@dataclass(frozen=True)
class SweepSpec:
    """A parsed sweep spec.

    Attributes
    ----------
    axes : tuple of Axis
        In file order; grid axes form a Cartesian product.
    figures : tuple of Figure
        Key figures computed per case.
    sampling : Sampling or None
        Present when there are sampled axes.
    name, description : str
        What the sweep is for.
    source : Path or None
        The file it was read from.
    data : mapping
        The file's data, kept for the sweep's manifest.
    """

    axes: tuple[Axis, ...]
    figures: tuple[Figure, ...]
    sampling: Sampling | None = None
    name: str = "sweep"
    description: str = ""
    source: Path | None = None
    data: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)

    @property
    def grid_axes(self) -> tuple[Axis, ...]:
        """Axes with listed values."""
        return tuple(a for a in self.axes if a.is_grid)

    @property
    def sampled_axes(self) -> tuple[Axis, ...]:
        """Axes drawn from a distribution."""
        return tuple(a for a in self.axes if not a.is_grid)

    @property
    def case_count(self) -> int:
        """Number of cases: grid points times samples."""
        count = math.prod(len(a.values) for a in self.grid_axes)
        return count * (self.sampling.samples if self.sampling else 1)


def load_sweep_spec(path: Path) -> SweepSpec:
    """Read and parse a sweep spec file.

    Raises
    ------
    SweepSpecError
        Listing every problem found.
    """
    path = Path(path)
    try:
        data = tomllib.loads(read_regular(path, MAX_SCENE_BYTES).decode("utf-8"))
    except UnreadableFileError as err:
        raise SweepSpecError(str(path), [f"cannot read the sweep spec: {err}"]) from None
    except UnicodeDecodeError:
        raise SweepSpecError(str(path), ["cannot read the sweep spec: not UTF-8 text"]) from None
    except tomllib.TOMLDecodeError as err:
        raise SweepSpecError(str(path), [f"not valid TOML: {err}"]) from None
    except RecursionError:
        raise SweepSpecError(str(path), ["nested too deeply to be a sweep spec"]) from None
    return parse_sweep_spec(data, source=path)


def parse_sweep_spec(data: Mapping[str, Any], *, source: Path | None = None) -> SweepSpec:
    """Build a :class:`SweepSpec` from plain data; raise :class:`SweepSpecError` with every problem.

    Parameters
    ----------
    data : mapping
        The spec as read from TOML.
    source : Path, optional
        The file it came from (names the spec in messages).
    """
    problems: list[str] = []
    for key in data:
        if key not in _TOP_KEYS:
            problems.append(f"unknown top-level key {key!r}; known: {', '.join(sorted(_TOP_KEYS))}")
    axes = _parse_axes(data.get("axes"), problems)
    sampling = _parse_sampling(data.get("sampling"), axes, problems)
    figures = _parse_figures(data.get("figures", {}), problems)
    name = data.get("name", source.stem if source else "sweep")
    if not (isinstance(name, str) and is_plain_name(name)):
        problems.append(
            f"'name' {name!r}: must be a plain file name (letters, digits, '_', "
            "'-', '.', no '..'), since it names the sweep's results folder"
        )
        name = "sweep"
    if not problems:
        _check_case_count(data.get("max_cases", MAX_CASES), axes, sampling, problems)
    if problems:
        raise SweepSpecError(f"sweep spec {name!r}", problems)
    return SweepSpec(
        tuple(axes),
        tuple(figures),
        sampling,
        name,
        str(data.get("description", "")),
        source,
        dict(data),
    )


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


def _check_case_count(limit: Any, axes: list, sampling: Any, problems: list[str]) -> None:
    """Refuse a sweep of more cases than ``max_cases``, saying how many and how to allow it."""
    if isinstance(limit, bool) or not isinstance(limit, int) or limit < 1:
        problems.append(f"'max_cases' must be a whole number >= 1, got {limit!r}")
        return
    count = math.prod(len(a.values) for a in axes if a.values)
    count *= sampling.samples if sampling else 1
    if count > limit:
        problems.append(
            f"the sweep has {count} cases, more than max_cases = {limit}; set max_cases in the "
            "spec to allow it, or take fewer values"
        )


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


# -- key figures ----------------------------------------------------------------------
def _parse_figure(name: str, text: Any, problems: list[str]) -> Figure | None:
    where = f"figure {name!r}"
    if not name.isidentifier():
        problems.append(f"{where}: a figure name must be an identifier (letters, digits, _)")
    elif name in RESERVED_COLUMNS:
        problems.append(
            f"{where}: the name is a summary column already; reserved: "
            f"{', '.join(sorted(RESERVED_COLUMNS))}"
        )
    match = _FIGURE_RE.match(text) if isinstance(text, str) else None
    if match is None:
        problems.append(
            f"{where}: must read 'function(unit.variable)', e.g. "
            f"'max(rope.path_end.tension)', got {text!r}"
        )
        return None
    function, _, column = match.groups()
    if function not in FUNCTIONS:
        problems.append(f"{where}: unknown function {function!r}; known: {', '.join(FUNCTIONS)}")
        return None
    if "." not in column:
        problems.append(f"{where}: the column must be 'unit.variable', got {column!r}")
        return None
    return Figure(name, function, column)


def _parse_figures(data: Any, problems: list[str]) -> list[Figure]:
    if not isinstance(data, Mapping):
        problems.append('[figures] must be a table of name = "function(unit.variable)"')
        return []
    figures = [_parse_figure(str(name), text, problems) for name, text in data.items()]
    return [f for f in figures if f is not None]

"""SWEEP_SPEC files: what a parameter sweep varies and what it measures per case.

A sweep spec is a TOML file (data only, nothing is executed).
:func:`load_sweep_spec` reads it and :func:`parse_sweep_spec` checks the
data, listing every problem at once (:class:`SweepSpecError`). Whether the
targets exist in a given scene is checked by
:func:`wire_fmu.sweep.cases.check_targets`; :func:`wire_fmu.sweep.runner.load_sweep`
reads a spec for a scene and says the problems of both at once.

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

import math
import tomllib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from wire_fmu.core.errors import ConfigurationError, WireFmuError
from wire_fmu.master.files import UnreadableFileError, read_regular
from wire_fmu.master.scene import MAX_SCENE_BYTES, is_plain_name

from .axes import Axis, Sampling, _parse_axes, _parse_sampling, well_formed_targets
from .figures import Figure, _parse_figures, well_formed_figures

__all__ = [
    "SweepSpec",
    "SweepSpecError",
    "SweepError",
    "load_sweep_spec",
    "parse_sweep_spec",
    "MAX_CASES",
]


class SweepSpecError(ConfigurationError):
    """A sweep spec with problems; ``problems`` lists every one.

    Parameters
    ----------
    where : str
        The spec (or the sweep) the problems belong to.
    problems : iterable of str
        One sentence per problem.
    targets : iterable of str, optional
        The spec's axis targets that are well formed, also those of axes with
        other problems, and
    figures : iterable of Figure, optional
        its key figures that read ``function(unit.variable)``, also those with
        other problems: what can still be checked against a scene
        (:func:`wire_fmu.sweep.runner.load_sweep` does), so that a spec's
        problems are all said at once.
    """

    def __init__(
        self,
        where: str,
        problems: Iterable[str],
        *,
        targets: Iterable[str] = (),
        figures: Iterable[Figure] = (),
    ) -> None:
        super().__init__(where, problems)
        self.targets = tuple(targets)
        self.figures = tuple(figures)


class SweepError(WireFmuError, RuntimeError):
    """A sweep that cannot go on: workers that differ, an output folder of another sweep."""


_TOP_KEYS = frozenset({"name", "description", "axes", "sampling", "figures", "max_cases"})
MAX_CASES = 10_000
"""Default most cases a sweep may have (``max_cases`` in the spec allows more)."""


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

    Parameters
    ----------
    path : Path
        The TOML file.

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
    before = len(problems)
    axes = _parse_axes(data.get("axes"), problems)
    sampling = _parse_sampling(data.get("sampling"), axes, problems)
    cases_known = len(problems) == before  # every axis, and the sampling, as given
    figures = _parse_figures(data.get("figures", {}), problems)
    name = data.get("name", source.stem if source else "sweep")
    if not (isinstance(name, str) and is_plain_name(name)):
        problems.append(
            f"'name' {name!r}: must be a plain file name (letters, digits, '_', "
            "'-', '.', no '..'), since it names the sweep's results folder"
        )
        name = "sweep"
    limit = _max_cases(data.get("max_cases", MAX_CASES), problems)
    if limit is not None and cases_known:
        _check_case_count(limit, axes, sampling, problems)
    if problems:
        raise SweepSpecError(
            f"sweep spec {name!r}",
            problems,
            targets=well_formed_targets(data.get("axes")),
            figures=well_formed_figures(data.get("figures", {})),
        )
    return SweepSpec(
        tuple(axes),
        tuple(figures),
        sampling,
        name,
        str(data.get("description", "")),
        source,
        dict(data),
    )


def _max_cases(limit: Any, problems: list[str]) -> int | None:
    """``max_cases`` as given, or None (and a problem) if it is not a whole number >= 1."""
    if isinstance(limit, bool) or not isinstance(limit, int) or limit < 1:
        problems.append(f"'max_cases' must be a whole number >= 1, got {limit!r}")
        return None
    return limit


def _check_case_count(limit: int, axes: list, sampling: Any, problems: list[str]) -> None:
    """Refuse a sweep of more cases than ``max_cases``, saying how many and how to allow it."""
    count = math.prod(len(a.values) for a in axes if a.values)
    count *= sampling.samples if sampling else 1
    if count > limit:
        problems.append(
            f"the sweep has {count} cases, more than max_cases = {limit}; set max_cases in the "
            "spec to allow it, or take fewer values"
        )

"""Parameter sweeps: many runs of one scene, on one machine or a Dask cluster.

>>> from wire_fmu.sweep import run_sweep                       # doctest: +SKIP
>>> result = run_sweep("riser_tensioner", "gas_volume.toml",   # doctest: +SKIP
...                    "results/gas_volume", workers=2)
>>> result.summary_path, result.counts                         # doctest: +SKIP

Modules
-------
:mod:`~wire_fmu.sweep.spec`
    the SWEEP_SPEC file: axes (grid, random sample), key figures.
:mod:`~wire_fmu.sweep.axes`, :mod:`~wire_fmu.sweep.figures`
    a spec's axes and sampling, its key figures, and their parsing.
:mod:`~wire_fmu.sweep.cases`
    expanding a spec into cases with stable ids, applying one to a scene.
:mod:`~wire_fmu.sweep.runner`
    running the cases on dask.distributed (or serially), resuming.
:mod:`~wire_fmu.sweep.worker`, :mod:`~wire_fmu.sweep.cluster`
    what a worker runs for one case; the Dask client and its workers.
:mod:`~wire_fmu.sweep.results`
    the output folder: Parquet records and summary, time series, plots.

See ``docs/sweeps.md``.
"""

from .cases import Case, apply_case, expand
from .runner import SweepResult, load_sweep, run_sweep
from .spec import SweepError, SweepSpec, SweepSpecError, load_sweep_spec, parse_sweep_spec

__all__ = [
    "run_sweep",
    "load_sweep",
    "SweepResult",
    "SweepSpec",
    "SweepSpecError",
    "SweepError",
    "load_sweep_spec",
    "parse_sweep_spec",
    "Case",
    "expand",
    "apply_case",
]

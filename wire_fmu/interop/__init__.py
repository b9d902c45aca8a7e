"""Our scenes and FMUs in other tools: SSP 1.0 and OSP export, SSP import.

* :func:`export_ssp` writes an SSP 1.0 package (:mod:`.ssp`);
* :func:`export_osp` writes an Open Simulation Platform configuration
  (:mod:`.osp`), which libcosim runs;
* :func:`read_ssp` turns an SSP package into a scene our master runs
  (:mod:`.ssp_read`);
* drivers and scheduled events travel as a generated signals FMU
  (:mod:`.signals`), since neither format has time signals.

See ``docs/interop.md`` for the mapping, what other tools do differently,
and how to run our FMUs in a non-Python host.
"""

from .osp import export_osp, write_osp
from .plan import ExportError, ExportPlan, plan_export
from .ssp import export_ssp, write_ssp
from .ssp_read import read_ssp

__all__ = [
    "export_ssp",
    "write_ssp",
    "export_osp",
    "write_osp",
    "read_ssp",
    "plan_export",
    "ExportPlan",
    "ExportError",
]

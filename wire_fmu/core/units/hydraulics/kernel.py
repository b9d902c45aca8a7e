"""The hydraulic cylinder's compiled kernel: its equations as plain functions over flat arrays.

The same physics as :class:`~wire_fmu.core.units.hydraulics.model.HydraulicsModel`
(``evaluate``, ``rhs``, ``guards``, ``project``, ``report``: the readable
reference), for every effect set of the package, in four modules:

=========================  ===========================================================
module                     what it holds
=========================  ===========================================================
:mod:`.kernel_arrays`      the tuple ``data = (parameters, layout, held)`` every
                           entry point takes: its indices and how it is built from
                           the model (:func:`kernel_data`)
:mod:`.kernel_physics`     the model at one state: pressures, flow, forces, losses,
                           acceleration and stored energy, in scalars read once
                           from ``data``
:mod:`.kernel_hybrid`      derivative, guards, projection, limits and report, each
                           written from one evaluation into an array given
:mod:`.kernel_quiet_step`  a whole step in which nothing happens, in one call
=========================  ===========================================================

What Python calls, all here: :func:`rhs` and :func:`guards` (the hybrid protocol, for
the SciPy solvers and a monolithic model), :func:`limits_and_force` (at the start of a
step), :func:`report` (the outputs), :func:`advance` (the entry point of
:class:`~wire_fmu.core.framework.compiled_step.CompiledFixedStep`) and
:func:`quiet_step_outputs` (a quiet step, :func:`quiet_step`, with the outputs it
changes). Events, their words and the reasons of refused steps stay in Python.
"""

from __future__ import annotations

from wire_fmu.core.framework.compiled import kernel_decorators
from wire_fmu.core.framework.compiled_step import advance_to_event
from wire_fmu.core.units.hydraulics.kernel_arrays import (
    QUIET_OUTPUTS,
    REPORT,
    kernel_data,
    kernel_layout,
    kernel_parameters,
)
from wire_fmu.core.units.hydraulics.kernel_hybrid import (
    guard_count,
    guards,
    limits_and_force,
    project,
    report,
    rhs,
    rhs_guards,
)
from wire_fmu.core.units.hydraulics.kernel_quiet_step import quiet_step, quiet_step_outputs

jit = kernel_decorators(__file__).jit

__all__ = [
    "QUIET_OUTPUTS",
    "REPORT",
    "advance",
    "guard_count",
    "guards",
    "kernel_data",
    "kernel_layout",
    "kernel_parameters",
    "limits_and_force",
    "project",
    "quiet_step",
    "quiet_step_outputs",
    "resume",
    "report",
    "rhs",
]


@jit
def advance(method, t0, t1, n, k, t, x, directions, tol, data):
    """:func:`~wire_fmu.core.framework.compiled_step.advance_to_event` over this kernel.

    Parameters
    ----------
    method, t0, t1, n, k, t, x, directions, tol, data
        As :func:`~wire_fmu.core.framework.compiled_step.advance_to_event` takes them.
    """
    return advance_to_event(
        rhs, guards, rhs_guards, project, method, t0, t1, n, k, t, x, directions, tol, data
    )


resume = advance
"""The entry point the solver calls after an event: :func:`advance` itself (the quiet
step, :func:`quiet_step`, is a loop of its own)."""

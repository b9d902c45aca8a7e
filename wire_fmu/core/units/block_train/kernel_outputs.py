"""The block train's outputs after a quiet step, in compiled form: one vector, one call.

:func:`output_vector` is what :meth:`BlockTrainUnit._update_outputs
<wire_fmu.core.units.block_train.unit.BlockTrainUnit._update_outputs>` writes after a
step in which no mode changed, with the same operations in the same order, so the two
give the same numbers to the last bit: the line-end tensions, the driven bodies'
forces, the blocks' positions and velocities, the path's end tensions and the largest
one, the energy ledger, and each published port's interface model. The outputs a
quiet step cannot change (the slack-span count, the broken flag, the mode changes)
are not in it. Which value goes where is the unit's :class:`~.quiet_step.OutputPlan`.
"""

from __future__ import annotations

import math

import numpy as np

from wire_fmu.core.framework.compiled import kernel_decorators
from wire_fmu.core.framework.compiled_step import STATUS_DONE, STATUS_PYTHON
from wire_fmu.core.units.block_train.kernel import quiet_step, summary
from wire_fmu.core.units.block_train.kernel_interface import port_linearisations

jit = kernel_decorators(__file__).jit

__all__ = [
    "EVALUATE",
    "FIXED_OUTPUTS",
    "RESUME",
    "STEP",
    "STEP_WITH_OUTPUTS",
    "output_vector",
    "quiet_step_outputs",
]

STEP_WITH_OUTPUTS = 0
"""What :func:`quiet_step_outputs` does: a quiet step and its outputs."""
EVALUATE = 1
"""What :func:`quiet_step_outputs` does: the summary and the ports' interface models at the
start of the interval, no step."""
STEP = 2
"""What :func:`quiet_step_outputs` does: :func:`.kernel.quiet_step` alone (the general way's
attempt, which Python goes on from after an event)."""
RESUME = 3
"""What :func:`quiet_step_outputs` does: the loop after an event Python switched
(:func:`.kernel.quiet_step` with ``resume``)."""

FIXED_OUTPUTS = (
    "path_start.tension",
    "path_end.tension",
    "tension_max",
    "stored_energy",
    "dissipated_energy",
    "external_work",
    "energy_balance",
)
"""The outputs every block train has, in the order :func:`output_vector` writes them
after the ports' forces and the blocks' motion."""


@jit
def output_vector(
    x: np.ndarray,
    values: np.ndarray,
    n_spans: int,
    table: np.ndarray,
    masses: np.ndarray,
    line_spans: np.ndarray,
    driver_bodies: np.ndarray,
    block_coords: np.ndarray,
    block_starts: np.ndarray,
    initial_energy: float,
):
    """The outputs' values after a step, and whether all of them are finite.

    Parameters
    ----------
    x : numpy.ndarray
        State at the step's end ``[q, v, dissipated, external work]`` (m, m/s, J, J).
    values : numpy.ndarray
        :func:`.kernel.summary` at the step's end: strain energy (J), potential (J),
        each span's tension (N), each body's force (N).
    n_spans : int
        The number of spans.
    table : numpy.ndarray
        The published ports' interface models, one row a port
        (:func:`.kernel_interface.port_linearisations`); no rows for none.
    masses : numpy.ndarray
        Mass of each coordinate, kg.
    line_spans : numpy.ndarray
        int, per line-end output: the span whose tension it is.
    driver_bodies : numpy.ndarray
        int, per driven body's force output: the body's index among the bodies.
    block_coords : numpy.ndarray
        int, per block with a port: its coordinate.
    block_starts : numpy.ndarray
        Per block with a port: its position with the coordinate at 0, m.
    initial_energy : float
        The stored energy at the start, J (the ledger's reference).

    Returns
    -------
    vector : numpy.ndarray
        The line-end tensions (N), the driven bodies' forces (N), each block's position
        (m) and velocity (m/s), the :data:`FIXED_OUTPUTS` (N, N, N, J, J, J, J), then
        the table's rows.
    finite : bool
        Whether every value is finite (else the step is taken the general way, which
        names what failed).
    """
    n = masses.size
    out = np.empty(
        line_spans.size
        + driver_bodies.size
        + 2 * block_coords.size
        + len(FIXED_OUTPUTS)
        + table.size
    )
    k = 0
    for span in line_spans:
        out[k] = values[2 + span]
        k += 1
    for body in driver_bodies:
        out[k] = values[2 + n_spans + body]
        k += 1
    for j in range(block_coords.size):
        out[k] = block_starts[j] + x[block_coords[j]]
        out[k + 1] = x[n + block_coords[j]]
        k += 2
    largest = 0.0  # as Python's max: the first, replaced by each one larger
    if n_spans:
        largest = values[2]
        for i in range(3, 2 + n_spans):
            if values[i] > largest:
                largest = values[i]
    kinetic = 0.0
    for i in range(n):
        kinetic += masses[i] * (x[n + i] * x[n + i])
    stored = 0.5 * kinetic + values[0] + values[1]
    out[k] = values[2]
    out[k + 1] = values[1 + n_spans]
    out[k + 2] = largest
    out[k + 3] = stored
    out[k + 4] = x[2 * n]
    out[k + 5] = x[2 * n + 1]
    out[k + 6] = stored - initial_energy + x[2 * n] - x[2 * n + 1]
    k += len(FIXED_OUTPUTS)
    for row in range(table.shape[0]):
        for column in range(table.shape[1]):
            out[k] = table[row, column]
            k += 1
    finite = True
    for value in out:
        finite = finite and math.isfinite(value)
    return out, finite


@jit
def quiet_step_outputs(
    method,
    t0,
    t1,
    n,
    tol,
    x,
    directions,
    data,
    held,
    held_positions,
    hold_start,
    interface_rows,
    relative_step,
    time_step,
    no_ports,
    n_spans,
    masses,
    line_spans,
    driver_bodies,
    block_coords,
    block_starts,
    initial_energy,
    mode,
    k,
    t,
):
    """A quiet step and its outputs in one call: :func:`.kernel.quiet_step`, then the
    ports' interface models (:func:`.kernel_interface.port_linearisations`) and
    :func:`output_vector`, the three calls
    :meth:`~wire_fmu.core.units.block_train.compiled_model.CompiledBlockTrain.quiet_step_outputs`
    would otherwise make from Python, each with numba's dispatch on a tuple of some
    thirty arrays. The same calls in the same order, so the same numbers to the bit.

    The block train's one compiled entry point: with another ``mode`` it evaluates the
    start (:data:`EVALUATE`), takes the general way's step (:data:`STEP`) or goes on after
    an event (:data:`RESUME`), so that one compiled function is loaded from the cache,
    not two. Every mode takes arguments of the same types (those it does not use too),
    so that one specialisation serves them all.

    Parameters
    ----------
    method, t0, t1, n, tol, x, directions, data, held
        As :func:`.kernel.quiet_step` takes them (``k = 0``, ``t = t0``, no resume).
    held_positions : numpy.ndarray
        The stuck coordinates' held positions the model holds now.
    hold_start : bool
        Whether the step holds them where it starts (the unit has friction links)
        rather than at ``held_positions``.
    interface_rows, relative_step, time_step
        As :func:`.kernel_interface.port_linearisations` takes them (``slots``); no
        rows, no interface models.
    no_ports : numpy.ndarray
        The table of no ports (shape ``(0, 5)``), the table when there are no rows.
    n_spans, masses, line_spans, driver_bodies, block_coords, block_starts, initial_energy
        As :func:`output_vector` takes them.
    mode : int
        :data:`STEP_WITH_OUTPUTS`; :data:`EVALUATE`: take no step, only evaluate at
        ``(t0, x)`` with ``data`` as the model holds it, :func:`.kernel.summary` as the
        values and the ports' interface models, a row of five after another, as the
        outputs (the start's outputs come from this call, which is also what loads this
        function before the first step); :data:`STEP` or :data:`RESUME`:
        :func:`.kernel.quiet_step` without or with ``resume``, its values the summary.
    k, t
        With :data:`RESUME`: the interval the loop goes on in and the time (s) it goes
        on from, as :func:`.kernel.quiet_step` takes them; else unused.

    Returns
    -------
    tuple
        ``(status, x, t, k, fired, steps, rhs_calls, h, values, held_positions,
        outputs, finite)``: the loop's ``(status, x, t, k, fired, steps, rhs_calls, h)``
        (:data:`STATUS_DONE` when the step was taken without an event), the summary at
        ``t1``, the held positions the model holds from now on, :func:`output_vector`'s
        vector and whether it is finite; with :data:`STEP_WITH_OUTPUTS`, nothing after
        the status is meaningful unless it is :data:`STATUS_DONE`.
    """
    nothing = np.zeros(0)
    if mode == STEP or mode == RESUME:
        status, x, t, k, fired, steps, calls, h, values = quiet_step(
            method, t0, t1, n, tol, x, directions, data, held, k, t, mode == RESUME
        )
        return status, x, t, k, fired, steps, calls, h, values, held_positions, nothing, False
    no_fire = np.zeros(directions.size, dtype=np.bool_)
    if mode == EVALUATE:
        values = summary(t0, x, data)
        table = no_ports
        if interface_rows.shape[0]:
            table = port_linearisations(t0, x, data, interface_rows, relative_step, time_step)
        finite = True
        for value in values:
            finite = finite and math.isfinite(value)
        for value in table.ravel():
            finite = finite and math.isfinite(value)
        flat = table.ravel()
        return STATUS_PYTHON, x, t0, 0, no_fire, 0, 0, 0.0, values, held_positions, flat, finite
    result = quiet_step(method, t0, t1, n, tol, x, directions, data, held, 0, t0, False)
    if result[0] != STATUS_DONE:
        return result[0], x, t0, 0, no_fire, 0, 0, 0.0, nothing, held_positions, nothing, False
    end, values = result[1], result[8]
    positions = x[: data[0][0]].copy() if hold_start else held_positions
    table = no_ports
    if interface_rows.shape[0]:
        # data as the model holds it after the step: held inputs (11), held positions (23)
        holding = data[:11] + (held,) + data[12:23] + (positions,) + data[24:]
        table = port_linearisations(t1, end, holding, interface_rows, relative_step, time_step)
    out, finite = output_vector(
        end,
        values,
        n_spans,
        table,
        masses,
        line_spans,
        driver_bodies,
        block_coords,
        block_starts,
        initial_energy,
    )
    t, k, fired, steps, calls, h = result[2], result[3], result[4], result[5], result[6], result[7]
    return STATUS_DONE, end, t, k, fired, steps, calls, h, values, positions, out, finite

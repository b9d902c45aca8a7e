"""Which of a block train's outputs a quiet step writes, and where each one's value comes from.

A quiet step -- one in which no mode changes -- is taken by
:meth:`~wire_fmu.core.units.block_train.compiled_model.CompiledBlockTrain.quiet_step_outputs`
in a few compiled calls, the last of which (:func:`.kernel_outputs.output_vector`) gives
the outputs as one vector. :class:`OutputPlan` names the vector's entries and holds the
index arrays that say which span, body or coordinate each comes from; the unit makes one
per model and set of published ports, and reuses it every step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wire_fmu.core.framework.ports import INTERFACE_QUANTITIES
from wire_fmu.core.units.block_train.interface import interface_plan
from wire_fmu.core.units.block_train.kernel_outputs import FIXED_OUTPUTS

__all__ = ["OutputPlan", "output_plan"]


@dataclass(frozen=True, eq=False)
class OutputPlan:
    """The outputs of a quiet step, in the order :func:`.kernel_outputs.output_vector`
    writes them.

    Attributes
    ----------
    model : BlockTrainModel
        The model the plan was made for.
    ports : tuple of str
        The ports whose interface model was asked for.
    names : tuple of str
        Every output the vector holds, in its order.
    line_spans, driver_bodies, block_coords, block_starts, interface_rows : numpy.ndarray
        What :func:`.kernel_outputs.output_vector` and
        :func:`.kernel_interface.port_linearisations` take.
    no_ports : numpy.ndarray
        An interface table of no rows, for a plan without ports.
    """

    model: object
    ports: tuple[str, ...]
    names: tuple[str, ...]
    line_spans: np.ndarray
    driver_bodies: np.ndarray
    block_coords: np.ndarray
    block_starts: np.ndarray
    interface_rows: np.ndarray
    no_ports: np.ndarray


def output_plan(
    model, lines: list, drivers: list, blocks: list, ports: tuple[str, ...]
) -> OutputPlan:
    """The plan of a model's quiet-step outputs.

    Parameters
    ----------
    model : BlockTrainModel
        The block train.
    lines : list of (str, int)
        Each line end's tension output and its span.
    drivers : list of (str, int)
        Each driven body's force output and the body's index among the bodies.
    blocks : list of (str, str, int, float)
        Each block port's position and velocity outputs, its coordinate and its
        position with that coordinate at 0 (m).
    ports : tuple of str
        The ports whose interface model is published (those the reeving uses count).
    """
    interface = interface_plan(model, ports) if ports else None
    interface_names = (
        tuple(f"{p}.{q}" for p in interface.names for q in INTERFACE_QUANTITIES)
        if interface is not None
        else ()
    )
    names = (
        *(name for name, _ in lines),
        *(name for name, _ in drivers),
        *(name for position, velocity, _, _ in blocks for name in (position, velocity)),
        *FIXED_OUTPUTS,
        *interface_names,
    )
    return OutputPlan(
        model,
        ports,
        names,
        np.array([span for _, span in lines], dtype=np.int64),
        np.array([body for _, body in drivers], dtype=np.int64),
        np.array([coordinate for _, _, coordinate, _ in blocks], dtype=np.int64),
        np.array([start for _, _, _, start in blocks], dtype=float),
        interface.rows if interface is not None else np.zeros((0, 6)),
        np.zeros((0, len(INTERFACE_QUANTITIES))),
    )

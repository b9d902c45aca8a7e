"""FMI facade of the block train: rope reeved over sheaves and anchors.

The reeving (JSON text) and the effects are string parameters, so one FMU
serves every reeving; see :mod:`wire_fmu.core.units.block_train.unit` for ports.
"""

from wire_fmu.core.units.block_train.unit import BlockTrainUnit
from wire_fmu.export.facade import CoreFacade


class BlockTrain(CoreFacade):
    """Block train FMU (pythonfmu facade over :class:`BlockTrainUnit`)."""

    unit_class = BlockTrainUnit

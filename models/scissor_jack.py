"""FMI facade of paper 003's scissor jack: a screw-nut pair with dry thread friction.

See :mod:`wire_fmu.core.units.scissor_jack.unit` for ports and parameters; the
defaults are the paper's jack (130 mm rods, 306 kg / 3000 N, 2 mm per turn).
"""

from wire_fmu.core.units.scissor_jack.unit import ScissorJackUnit
from wire_fmu.export.facade import CoreFacade


class ScissorJack(CoreFacade):
    """Scissor jack FMU (pythonfmu facade over :class:`ScissorJackUnit`)."""

    unit_class = ScissorJackUnit

"""wire_fmu: hoisting gear (winch, block train, hydraulics) as FMI co-simulation units.

Layers
------
``wire_fmu.core``
    The physics: pure Python with numpy/scipy, no FMI, no module-level
    mutable state.
``wire_fmu.export``
    Maps core units onto pythonfmu facades and finishes the FMUs'
    model descriptions.
"""

__version__ = "0.1.0"

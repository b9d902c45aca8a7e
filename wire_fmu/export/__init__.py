"""Export core units as FMI 2.0 co-simulation FMUs (pythonfmu 0.7).

Modules
-------
``facade``
    :class:`~wire_fmu.export.facade.CoreFacade`, the generic pythonfmu
    slave that maps a core unit's declarations onto FMI variables.
``model_description``
    Completes pythonfmu's ``modelDescription.xml`` (units, dependencies,
    initial unknowns, capability flags); ``units`` is its SI unit table.
``builder``
    :func:`~wire_fmu.export.builder.build_fmu`: facade script -> ``.fmu``.
``guard``
    The core-version guard run at instantiation.
``state``
    JSON deep copies for FMU states.
``binary``
    Compiles the FMU binary (``native/fmi2_python.c``) that forwards FMI calls to the facade.

This package runs inside FMUs, so nothing here imports fmpy, and this
``__init__`` imports nothing (the builder pulls in pythonfmu's build tools,
which an FMU does not need).
"""

"""Physics core: no FMI, no fmpy, no module-level mutable state.

``framework/``
    What every unit is built on: the unit base class and its declarations
    (``unit.py``), hybrid integration with event location (``hybrid.py``),
    the effect catalogue (``effects.py``), solver parameters
    (``solver_options.py``) and paper 004's energy-form integrator
    (``energy_integrator.py``).
``components/``
    Physics pieces units are assembled from: rope spans, stick-slip friction,
    gas, drum, hydraulic line, sheave tangent-point geometry, drive trains and
    drive trees, the screw-nut connection.
``units/<unit>/``
    One folder per unit type: ``model.py`` holds its physics, ``unit.py`` the
    co-simulation unit (variables, life cycle, state) the FMU facade maps.
``errors.py``
    The exceptions every layer shares.
"""

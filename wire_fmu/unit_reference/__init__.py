"""The units' parameter reference, from their own declarations.

:mod:`.catalogue` reads what a unit type declares (parameters, inputs,
outputs, ports, effects, the fields of structured parameters);
:mod:`.text` and :mod:`.markdown` write it for the terminal
(``wire-fmu info UNIT``) and for ``docs/units.md``;
:mod:`.scene_warnings` finds what a scene sets that its effects leave without
influence (``wire-fmu check``). Nothing is imported here, so that the command
line, which registers :mod:`.command`, does not load the physics core to start.
"""

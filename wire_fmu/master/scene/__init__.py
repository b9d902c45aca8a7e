"""Scenes: which units, how they connect, what drives them, how to run.

A scene is a TOML file (data only, nothing is executed). :func:`load_scene`
reads it and :func:`parse_scene` turns the data into a :class:`Scene`,
collecting every problem it can see without opening an FMU; the checks that
need the units' model descriptions are in :mod:`wire_fmu.master.validate`.

Format::

    name = "riser_tensioner"
    description = "..."

    [run]
    stop_time = 60.0          # s
    step = 0.01               # s, macro (communication) step
    algorithm = "gauss_seidel"        # or "jacobi"
    extrapolation = "linear"          # "constant", "linear" or "quadratic"
    output_interval = 0.05    # s
    iterations = 1            # > 1: iterate each step with rollback
    iteration_tolerance = 1e-6
    adaptive = false          # macro step from the bonds' energy residual
    synchronise_events = false  # a mode change inside a step: every unit steps to it
    interface_models = false  # true: bonds whose two ports declare an interface model
                              # carry it (see wire_fmu.master.scene.bonds)
    ramped_flows = false      # true: a bond whose effort side takes a flow ramp gets the
                              # flow at the step's start and its slope over the step
    energy_tolerance = 10.0   # J per step, with adaptive; the energy guard's floor
    energy_guard = 0.1        # stop once a bond's coupling created this share of
                              # the energy it carried (inf: off); see energy_guard.py
    min_step = 1e-4
    max_step = 0.05
    max_steps = 10000000      # a run of more macro steps is refused (adaptive: stop / min_step)

    [units.rope]
    fmu = "BlockTrain"        # one of ours by name, or a path to any FMI 2.0 CS FMU
    effects = ["rope_damping"]
    [units.rope.parameters]
    pretension = 2.0e5
    reeving = { ... }         # a table is passed to a String parameter as JSON

    [[bonds]]                 # a power bond: effort one way, flow (and position) back
    name = "rod"
    kind = "translational"    # "translational", "rotational" or "rope"
    effort = "rope.mover_a.force -> cylinder.rod.force"
    flow = "cylinder.rod.velocity -> rope.mover_a.velocity"
    position = "cylinder.rod.position -> rope.mover_a.position"
    interface = []            # optional: an interface model's links, effort side to flow side

    [[bonds]]                 # the same, as the two ports it joins (links and kind from the
    name = "rod"              # ports the FMUs declare; see wire_fmu.master.scene.bonds)
    ports = "cylinder.rod <-> rope.mover_a"
    interface_model = true    # optional: this bond's coupling whatever run.interface_models
                              # says (true: its interface model's links too; false: none)

    [[connections]]           # plain signals
    from = "a.x"
    to = "b.y"

    [[drivers]]               # see wire_fmu.master.drivers
    target = "rope.mover_b.position"
    rate_target = "rope.mover_b.velocity"
    kind = "sine"
    amplitude = 1.5
    period = 10.0

    [[events]]
    time = 30.0
    label = "brake applied"
    set = { "winch.brake.lever_force" = 2000.0 }

    [outputs]
    variables = ["rope.line_a.tension"]      # or "all"

    [[plots]]
    title = "Riser tension"
    variables = ["rope.line_b.tension"]

    [study]                   # optional, for wire-fmu study (wire_fmu.study.accuracy)
    key_outputs = ["rope.line_b.tension"]    # default: the plots' variables
    stop_time = 10.0          # s, of every study run
    steps = [0.02, 0.01, 0.005]              # macro steps, s
    output_interval = 0.02    # s, a multiple of every step
    quick_window = [3.8, 4.8] # s, what --quick compares: where the scene's action is

Modules: :mod:`.data` (what a scene holds), :mod:`.reading` (files and
plain data to a scene), :mod:`.sections` (one parser per section of the
file) and :mod:`.checks` (values, names, unit references, run settings).
"""

from __future__ import annotations

from .checks import (
    interface_warnings,
    is_plain_name,
    is_scalar,
    late_event_warnings,
    unknown_unit_problems,
    valid_time,
)
from .data import (
    ALGORITHMS,
    BOND_KINDS,
    EXTRAPOLATIONS,
    HELD,
    INTERFACE_ROLE,
    Bond,
    Connection,
    DriverSpec,
    EventSpec,
    PlotSpec,
    RunSettings,
    Scene,
    SceneError,
    UnitSpec,
    VarRef,
)
from .reading import MAX_SCENE_BYTES, load_scene, parse_scene, read_scene, read_scene_data

__all__ = [
    "VarRef",
    "UnitSpec",
    "Connection",
    "Bond",
    "DriverSpec",
    "EventSpec",
    "RunSettings",
    "PlotSpec",
    "Scene",
    "SceneError",
    "load_scene",
    "parse_scene",
    "read_scene",
    "read_scene_data",
    "is_plain_name",
    "unknown_unit_problems",
    "interface_warnings",
    "late_event_warnings",
    "valid_time",
    "is_scalar",
    "MAX_SCENE_BYTES",
    "ALGORITHMS",
    "EXTRAPOLATIONS",
    "BOND_KINDS",
    "HELD",
    "INTERFACE_ROLE",
]

"""Hard cases of whole scenes (SPEC section 17, issue 7).

The shipped riser tensioner's blow-up at a macro step far too large is stopped
soon after it shows; a deliberate algebraic loop is refused before anything
runs; every shipped hoisting scene starts in static equilibrium. Through the
real FMUs in our master, under the global criteria of
:mod:`~tests.hard_case_helpers` (see ``test_hard_cases``).

As in ``test_hard_cases``, each test's docstring ends with its mutation
experiment (``Mutation:``): the protection removed, and what failed then.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from wire_fmu.master.observers import CsvRecorder
from wire_fmu.master.plots import read_results
from wire_fmu.master.run import find_scene, run_scene, with_run_settings
from wire_fmu.master.run_result import RunResult
from wire_fmu.master.scene import SceneError, load_scene
from wire_fmu.master.simulation import Simulation
from wire_fmu.master.validate import validate_scene

from .hard_case_helpers import (
    build_our_fmus,
    check_global_criteria,
    master_scene,
)

pytestmark = pytest.mark.integration


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, Path]:
    """Our three hoisting FMUs, built once for the module."""
    return build_our_fmus(tmp_path_factory.mktemp("hard_case_fmus"))


# ================================ 7. a macro step far too large: a shipped scene
def shipped_scene(name: str, fmus):
    """A shipped scene on our built FMUs."""
    scene = load_scene(find_scene(name))
    return replace(
        scene, units={n: replace(u, fmu=str(fmus[u.fmu])) for n, u in scene.units.items()}
    )


def shipped_run(name: str, fmus, directory: Path, **run_settings) -> tuple[RunResult, dict]:
    """A shipped scene on our built FMUs with some run settings replaced; its result and table."""
    scene = with_run_settings(shipped_scene(name, fmus), **run_settings)
    recorder = CsvRecorder(directory, scene.run.output_interval)
    result = Simulation(scene, validate_scene(scene), [recorder]).run()
    return result, read_results(recorder.csv_path)


RISER_BAND = (3.2e5, 4.0e5)  # N: the riser tension of the scene's own run, with margin


def test_shipped_riser_tensioner_blow_up_is_stopped_soon_after_it_shows(fmus, tmp_path):
    """The riser tensioner with Jacobi coupling, constant hold and the rope's force held
    (no interface model) at 8 ms, four times its step: unguarded, the rod-on-wire mode
    grows until the riser tension leaves its physical band (the scene's own run: 345-364
    kN) near 6.2 s and then swings between slack and 1.4 MN; guarded, the run stops within
    0.25 s of the tension leaving the band, naming the bond, with every row before kept. At
    the scene's own settings the guard lets it finish; with the interface model, so does
    the 8 ms explicit coupling.

    Mutation: the guard removed (EnergyGuard.blow_up returning None): the guarded run
    'finished' at 12 s: the status assertion failed.
    """
    jacobi = {
        "algorithm": "jacobi",
        "extrapolation": "constant",
        "step": 0.008,
        "stop_time": 12.0,
        "interface_models": False,
    }
    _, unguarded = shipped_run(
        "riser_tensioner", fmus, tmp_path / "unguarded", energy_guard=math.inf, **jacobi
    )
    tension = unguarded["rope.path_end.tension"]
    outside = np.flatnonzero((tension < RISER_BAND[0]) | (tension > RISER_BAND[1]))
    assert outside.size and tension.min() == 0.0 and tension.max() > 1e6  # a blow-up
    leaves = unguarded["time"][outside[0]]
    result, columns = shipped_run("riser_tensioner", fmus, tmp_path / "guarded", **jacobi)
    assert result.status == "stopped"
    assert "the coupling blows up" in result.message and "bond 'rod'" in result.message
    assert leaves <= result.end_time <= leaves + 0.25
    assert columns["time"][-1] == pytest.approx(result.end_time)
    np.testing.assert_array_equal(
        columns["rope.path_end.tension"], tension[: len(columns["time"])]
    )  # the same run, cut short
    own, columns = shipped_run("riser_tensioner", fmus, tmp_path / "own", stop_time=12.0)
    assert own.status == "finished", own.message
    tension = columns["rope.path_end.tension"]
    assert RISER_BAND[0] < tension.min() and tension.max() < RISER_BAND[1]
    # the same explicit coupling at 8 ms with the rope's interface model: no blow-up
    modelled = {**jacobi, "interface_models": True}
    result, columns = shipped_run("riser_tensioner", fmus, tmp_path / "modelled", **modelled)
    assert result.status == "finished", result.message
    tension = columns["rope.path_end.tension"]
    assert RISER_BAND[0] < tension.min() and tension.max() < RISER_BAND[1]


# ============================================================= 8. algebraic loop
def test_a_deliberate_algebraic_loop_is_detected_and_named(fmus, tmp_path):
    """Two cylinders pushing rod on rod, each taking the other's oil force as its rod
    force: both claim the compliance (a cut through a stiff element, not at an inertia),
    and hydraulic_force feeds through from rod.force. Validation refuses the scene before
    anything runs, naming every variable of the loop; the same pair cut at the rod's
    inertia (a proper bond with a block train) validates.

    Mutation: loop detection disabled (validate.feedthrough_loops returning []); the
    scene validated and no SceneError was raised.
    """
    loop = {
        "name": "loop",
        "units": {"a": {"fmu": "Hydraulics"}, "b": {"fmu": "Hydraulics"}},
        "connections": [
            {"from": "a.hydraulic_force", "to": "b.rod.force"},
            {"from": "b.hydraulic_force", "to": "a.rod.force"},
        ],
    }
    with pytest.raises(SceneError) as info:
        validate_scene(master_scene(loop, fmus, tmp_path))
    problems = [p for p in info.value.problems if "algebraic loop" in p]
    assert len(problems) == 1
    for variable in ("a.rod.force", "a.hydraulic_force", "b.rod.force", "b.hydraulic_force"):
        assert variable in problems[0]
    with pytest.raises(SceneError, match="algebraic loop"):
        run_scene(master_scene(loop, fmus, tmp_path), tmp_path / "never", plots=False)
    assert not (tmp_path / "never" / "timeseries.csv").exists()
    proper = {
        "name": "cut_at_the_rod",
        "units": {"rope": {"fmu": "BlockTrain"}, "cyl": {"fmu": "Hydraulics"}},
        "bonds": [
            {
                "name": "rod",
                "kind": "translational",
                "effort": "rope.mover_a.force -> cyl.rod.force",
                "flow": "cyl.rod.velocity -> rope.mover_a.velocity",
                "position": "cyl.rod.displacement -> rope.mover_a.position",
            }
        ],
    }
    validate_scene(master_scene(proper, fmus, tmp_path), through_fmi=False)


# ====================================================== 9. start in static equilibrium
SHIPPED = ("drawworks", "riser_tensioner", "heave_compensated_hoist")


def quiet_shipped_scene(name: str, fmus, step_factor: float):
    """A shipped scene for its first second, drivers and events off, every output recorded."""
    scene = replace(shipped_scene(name, fmus), drivers=(), events=(), outputs=None, plots=())
    return with_run_settings(
        scene, stop_time=1.0, step=scene.run.step * step_factor, output_interval=None
    )


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_scene_starts_in_static_equilibrium(fmus, tmp_path, name):
    """Each shipped hoisting scene, drivers and events off: every recorded output (tensions,
    positions, pressures, brake torque, energies) stays within 1 ppm of its start value over
    the first second and every velocity within 1e-9 m/s of 0, at the scene's step and at
    twice it.

    Mutation: equilibrium initialisation skipped in the BlockTrain (initialize ignoring
    'equilibrium': the rope starts at its 1 kN pretension); drawworks failed (the hook
    dropped onto the rope, the brake torque moved by 96 kN) and heave_compensated_hoist
    failed (its compensator could not start). The cylinder's equilibrium without the
    rod's weight (HydraulicsModel.equilibrium_pressure): riser_tensioner failed (the
    rope's force on the rod moved by 33 kN) and so did heave_compensated_hoist.
    """
    for factor in (1.0, 2.0):
        scene = quiet_shipped_scene(name, fmus, factor)
        recorder = CsvRecorder(tmp_path / f"x{factor}", None)
        result = Simulation(scene, validate_scene(scene), [recorder]).run()
        assert result.status == "finished", result.message
        columns = read_results(recorder.csv_path)
        for column, values in columns.items():
            if column == "time":
                continue
            scale = max(1.0, float(np.max(np.abs(values))))
            assert np.ptp(values) <= 1e-6 * scale, f"{column} moved by {np.ptp(values):.3g}"
            if column.endswith("velocity") or column.endswith(".speed"):
                assert np.max(np.abs(values)) <= 1e-9, column
        check_global_criteria(columns, ledger_tolerance=1e-6, energy_scale=1.0, passive=True)

"""FMPy's own SSP runner (``fmpy.ssp.simulate_ssp``) runs our exported packages.

FMPy's runner is a Jacobi loop with inputs held over each step, as our master
with ``algorithm = "jacobi"``, ``extrapolation = "constant"``: on a system it
can configure, and whose connected inputs start at zero (it starts every
connector at 0.0, see :mod:`wire_fmu.interop.fmpy_ssp`), it must give our
numbers at every step, to round-off. The step is 1/128 s so that FMPy's time,
counted by adding the step, lands on the same instants as ours.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest

from wire_fmu.interop import export_ssp
from wire_fmu.interop.fmpy_ssp import FmpyRunnerError, fmpy_parameter_set
from wire_fmu.master.run import shipped_scenes, with_run_settings
from wire_fmu.master.scene import load_scene, parse_scene

from .interop_helpers import build_test_fmus, run_ours, two_mass_scene

pytestmark = pytest.mark.integration

STEP = 1.0 / 128.0
"""s: a binary fraction, so that adding it up is exact."""

ROUND_OFF = 1e-12
"""Allowed difference relative to max(1, the signal's largest magnitude)."""


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, Path]:
    return build_test_fmus(tmp_path_factory.mktemp("fmus"))


def _pushed_chain(fmus: dict[str, Path], base_dir: Path):
    """Three masses at rest, undisplaced; pushed by scheduled forces; every input starts at 0.

    ``c`` is pushed (events at 0.25 s and 0.625 s, through the signals unit);
    the spring-damper ``d`` pulls ``a`` towards ``c``; ``b`` hangs from ``a``.
    """
    data = {
        "name": "pushed_chain",
        "description": "Three masses at rest, pushed by scheduled forces (test scene)",
        "run": {
            "stop_time": 1.0,
            "step": STEP,
            "algorithm": "jacobi",
            "extrapolation": "constant",
        },
        "units": {
            "c": {
                "fmu": str(fmus["osc"]),
                "parameters": {"mass": 0.5, "stiffness": 20.0, "damping": 0.3, "x0": 0.0},
            },
            "d": {"fmu": str(fmus["spring"]), "parameters": {"stiffness": 30.0, "damping": 0.5}},
            "a": {
                "fmu": str(fmus["osc"]),
                "parameters": {"mass": 1.0, "stiffness": 40.0, "damping": 0.1, "x0": 0.0},
            },
            "b": {
                "fmu": str(fmus["mass"]),
                "parameters": {"mass": 2.0, "stiffness": 60.0, "damping": 0.2, "x0": 0.0},
            },
        },
        "connections": [
            {"from": "a.position", "to": "d.position_a"},
            {"from": "a.velocity", "to": "d.velocity_a"},
            {"from": "c.position", "to": "d.position_b"},
            {"from": "c.velocity", "to": "d.velocity_b"},
            {"from": "d.force", "to": "a.force"},
            {"from": "a.position", "to": "b.flange.position"},
            {"from": "a.velocity", "to": "b.flange.velocity"},
        ],
        "events": [
            {"time": 0.25, "label": "push", "set": {"c.force": 1.5}},
            {"time": 0.625, "label": "pull", "set": {"c.force": -0.8}},
        ],
        "outputs": {"variables": "all"},
    }
    return parse_scene(data, base_dir=base_dir)


def _fmpy_rows(package: Path, names, stop: float, step: float) -> np.ndarray:
    """FMPy's results as rows of (end of step, ``names``...), like :func:`run_ours`."""
    from fmpy.ssp.simulation import simulate_ssp

    result = simulate_ssp(
        str(package),
        stop_time=stop,
        step_size=step,
        parameter_set=fmpy_parameter_set(package),
    )
    columns = [result["time"] + step] + [result[f"{u}.{n}"] for u, n in names]
    return np.column_stack(columns)


def _worst(names, ours: np.ndarray, theirs: np.ndarray) -> tuple[float, str]:
    assert theirs.shape == ours.shape, (theirs.shape, ours.shape)
    np.testing.assert_array_equal(theirs[:, 0], ours[:, 0])  # the same instants
    scale = np.maximum(1.0, np.abs(ours[:, 1:]).max(axis=0))
    relative = np.abs(theirs[:, 1:] - ours[:, 1:]).max(axis=0) / scale
    i = int(np.argmax(relative))
    return float(relative[i]), "{}.{}".format(*names[i])


def test_fmpy_runner_gives_our_jacobi_results_step_for_step(fmus, tmp_path):
    scene = _pushed_chain(fmus, tmp_path)
    package = export_ssp(scene, tmp_path / "ssp", fmu_dir=fmus["osc"].parent)
    names, ours = run_ours(scene)
    theirs = _fmpy_rows(package, names, scene.run.stop_time, STEP)
    worst, where = _worst(names, ours, theirs)
    assert worst < ROUND_OFF, f"{where} differs by {worst:.3g} (relative)"
    # and the comparison has teeth: both pushes, the spring and the hanging mass act
    column = {f"{u}.{n}": ours[:, i + 1] for i, (u, n) in enumerate(names)}
    assert np.ptp(column["c.acceleration"]) > 1.0
    assert np.ptp(column["d.force"]) > 0.1 and np.ptp(column["b.force_on_flange"]) > 0.01


def test_fmpy_runner_holds_every_connected_input_at_zero_in_its_first_step(fmus, tmp_path):
    """What FMPy's runner cannot do: hand initial outputs over before the first step.

    ``b`` starts displaced (x0 = 0.1 m), so its coupling spring pulls ``a``
    from the start (b.force_on_flange = 6 N). Our master and libcosim hold that
    force over the first step; FMPy's runner holds 0.0 there, and its ``a``
    starts out as if nothing pulled it.
    """
    scene = two_mass_scene(fmus, tmp_path, a_x0=0.0, b_x0=0.1, signals=False)
    label = dict(scene.units["a"].parameters)
    label.pop("label")  # a String: FMPy's runner cannot set one (see the next test)
    from dataclasses import replace

    scene = replace(scene, units={**scene.units, "a": replace(scene.units["a"], parameters=label)})
    scene = with_run_settings(scene, step=STEP)
    package = export_ssp(scene, tmp_path / "ssp", fmu_dir=fmus["osc"].parent)
    names, ours = run_ours(scene)
    theirs = _fmpy_rows(package, names, scene.run.stop_time, STEP)
    acceleration = names.index(("a", "acceleration")) + 1
    held = 60.0 * 0.1  # N, b's spring on a's flange at the start
    assert ours[0, acceleration] == pytest.approx(
        held - 40.0 * ours[0, names.index(("a", "position")) + 1], rel=1e-6
    )
    assert abs(theirs[0, acceleration] - ours[0, acceleration]) > 0.5 * held


def test_fmpy_parameter_set_refuses_a_string_the_fmu_does_not_start_with(fmus, tmp_path):
    """A package whose parameter set was edited after export (a String other than the
    configured FMU's start value) cannot be configured in FMPy's runner: refused, named."""
    scene = two_mass_scene(fmus, tmp_path, signals=False)  # a's 'label' is a String
    package = export_ssp(scene, tmp_path / "ssp", fmu_dir=fmus["osc"].parent)
    assert all(p.name != "a.label" for p in fmpy_parameter_set(package).parameters)
    edited = tmp_path / "edited.ssp"
    with zipfile.ZipFile(package) as src, zipfile.ZipFile(edited, "w") as dst:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename == "resources/a.ssv":
                data = data.replace(b"&quot;quoted&quot;", b"&quot;edited&quot;")
                assert b"edited" in data
            dst.writestr(item, data)
    with pytest.raises(FmpyRunnerError) as caught:
        fmpy_parameter_set(edited)
    assert len(caught.value.problems) == 1
    assert caught.value.problems[0].startswith("a.label is a String")
    assert "Real, Integer and Boolean" in caught.value.problems[0]


@pytest.fixture(scope="module")
def shipped_packages(tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("shipped")
    packages = {}
    for name, path in shipped_scenes().items():
        scene = with_run_settings(load_scene(path), algorithm="jacobi", extrapolation="constant")
        packages[name] = export_ssp(scene, out / name, fmu_dir=out / "fmus")
    return packages


def test_fmpy_reads_the_connections_of_every_shipped_package(shipped_packages):
    """FMPy's runner pairs every declared input connector with a connection; none is left over.

    (It failed with UnboundLocalError in ``get_connections`` when an input
    that nothing feeds was declared as a connector.)
    """
    from fmpy.ssp.simulation import add_path
    from fmpy.ssp.ssd import get_connections, read_ssd

    assert shipped_packages
    for name, package in shipped_packages.items():
        ssd = read_ssd(str(package))
        add_path(ssd.system)
        inputs = {
            f"{e.name}.{c.name}"
            for e in ssd.system.elements
            for c in e.connectors
            if c.kind == "input"
        }
        connections = get_connections(ssd.system)
        fed = [f"{end.parent.name}.{end.name}" for _, end in connections]
        assert sorted(fed) == sorted(inputs), name
        for start, end in connections:
            assert start.kind == "output" and end.kind == "input", (name, start, end)


def test_every_shipped_package_needs_no_parameter_set_in_fmpy_runner(shipped_packages):
    """Each unit's FMU starts with the scene's values (Strings too: effects, a reeving, a
    drive train, a solver), so the parameter set made from the package sets no String."""
    for name, package in shipped_packages.items():
        parameters = fmpy_parameter_set(package).parameters
        assert parameters, name
        assert all(p.type != "String" for p in parameters), name


AT_REST = ("drawworks", "machine_unit", "multimass_drive", "scissor_jack")
"""Shipped scenes whose states do not feel FMPy's start (every connected input 0.0 during
initialisation and the first step): their connected inputs start at zero, or what the
first step drops does not move a state (the drawworks' drum held by its motor and brake
whatever the rope's tension, the scissor jack's self-locking screw)."""
LOADED = ("heave_compensated_hoist", "riser_tensioner")
"""Shipped scenes that start loaded (a riser's tension, a hook load on a compensator):
FMPy's runner starts them with the rope slack for one step, a different run."""
FMPY_CHECK_TIME = 2.0
"""Simulated seconds of each shipped scene in FMPy's runner, s (the drawworks' brake
releases at 1 s)."""


def _shipped_in_fmpy(name: str, tmp_path: Path):
    """The scene (Jacobi, constant), FMPy's rows (no parameter set) and our names and rows."""
    from fmpy.ssp.simulation import simulate_ssp

    scene = load_scene(shipped_scenes()[name])
    scene = with_run_settings(
        scene,
        algorithm="jacobi",
        extrapolation="constant",
        stop_time=min(scene.run.stop_time, FMPY_CHECK_TIME),
    )
    package = export_ssp(scene, tmp_path / "ssp", fmu_dir=tmp_path / "fmus")
    step = scene.run.step
    result = simulate_ssp(str(package), stop_time=scene.run.stop_time, step_size=step)
    return scene, result, step


@pytest.mark.parametrize("name", AT_REST)
def test_fmpy_runner_runs_shipped_scenes_like_our_master(name, tmp_path):
    """Configured by the package alone, FMPy's runner gives our Jacobi master's numbers.

    (Round-off: FMPy counts time by adding the step, so a driver or an event is met at
    an instant a few ulps from ours.)
    """
    scene, result, step = _shipped_in_fmpy(name, tmp_path)
    names, ours = run_ours(scene)
    n = len(ours)
    assert len(result) >= n
    # mode_change_time remembers when a mode last changed: in FMPy's first step (every
    # connected input at 0.0: the drawworks' brake lever let go for one step) the winch's
    # brake slips and holds again, two switches our run never has
    named = [
        (u, v) for u, v in names if f"{u}.{v}" in result.dtype.names and v != "mode_change_time"
    ]
    # FMPy adds up its time: the same instants to a few ulps
    np.testing.assert_allclose(result["time"][:n] + step, ours[:, 0], rtol=0, atol=1e-12)
    theirs = np.column_stack([ours[:, 0]] + [result[f"{u}.{v}"][:n] for u, v in named])
    keep = [0, *(names.index(pair) + 1 for pair in named)]
    ours = ours[:, keep]
    # a unit's energy_balance is a residual near 0 J: its scale is the unit's energies
    for i, (unit, variable) in enumerate(named):
        if variable == "energy_balance":
            energies = [j for j, (u, v) in enumerate(named) if u == unit and "energy" in v]
            scale = max(1.0, np.abs(ours[:, [j + 1 for j in energies]]).max())
            ours[:, i + 1] /= scale
            theirs[:, i + 1] /= scale
    # FMPy's first step holds every connected input at 0.0 (a brake lever, a handle's
    # torque); in these scenes that changes that step's outputs and no state
    worst, where = _worst(named, ours[1:], theirs[1:])
    assert worst < 1e-8, f"{name}: {where} differs by {worst:.3g} (relative)"
    moving = [np.ptp(ours[:, i]) for i in range(1, ours.shape[1])]  # the compared columns
    assert max(moving) > 1.0, name  # something happens in the window


@pytest.mark.parametrize("name", LOADED)
def test_fmpy_runner_runs_the_loaded_shipped_scenes_to_the_end(name, tmp_path):
    """They run, configured; their first step is FMPy's (rope force 0), so not ours."""
    scene, result, step = _shipped_in_fmpy(name, tmp_path)
    assert result["time"][-1] + step == pytest.approx(scene.run.stop_time, abs=1.5 * step)
    for column in result.dtype.names:
        if result.dtype[column].kind == "f":
            assert np.isfinite(result[column]).all(), (name, column)

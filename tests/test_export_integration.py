"""Build the test FMUs and run them in fmpy and libcosimpy (a master we did not write)."""

from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
import textwrap
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

SUPPORT = Path(__file__).resolve().parent / "support"
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

from fmi_test_tools import FACADES, UNITS_MODULE, FmiLog, LoadedFmu  # noqa: E402
from fmpy import simulate_fmu  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402
from wire_fmu_test_units import OscillatorUnit, oscillator_position  # noqa: E402

from wire_fmu.export.binary import platform_folder  # noqa: E402
from wire_fmu.export.builder import build_fmu  # noqa: E402
from wire_fmu.export.fmu_archive import FACADE_FILE  # noqa: E402
from wire_fmu.export.guard import BUILD_INFO_FILE, BuildInfo, imported_core  # noqa: E402

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[1]
DEFAULTS = {v.name: v.start for v in OscillatorUnit.VARIABLES}
FMI_ERROR, FMI_FATAL, FMI_DISCARD = 3, 4, 2


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("fmus")
    return {
        name: build_fmu(FACADES / f"{name}.py", out, extra_modules=[UNITS_MODULE])
        for name in ("oscillator", "spring_damper")
    }


@pytest.fixture(scope="module")
def oscillator(fmus) -> LoadedFmu:
    return LoadedFmu(fmus["oscillator"])


@pytest.fixture
def fmi_log():
    log = FmiLog()
    yield log
    FmiLog.restore()


def closed_form(times, **overrides) -> np.ndarray:
    p = {**DEFAULTS, **overrides}
    return oscillator_position(
        np.asarray(times), p["mass"], p["stiffness"], p["damping"], p["x0"], p["v0"], p["force"]
    )


# -- what was built ---------------------------------------------------------------
def test_fmu_bundles_core_under_a_unique_module_name(fmus):
    with zipfile.ZipFile(fmus["oscillator"]) as archive:
        names = set(archive.namelist())
        module, facade, guid = archive.read(FACADE_FILE).decode().split("\n")[:3]
        record = json.loads(archive.read(f"resources/{BUILD_INFO_FILE}"))
        md = archive.read("modelDescription.xml").decode()
    assert module.startswith("wire_fmu_oscillator_") and f"resources/{module}.py" in names
    assert facade == "Oscillator" and f'guid="{guid}"' in md
    binaries = sorted(n for n in names if n.startswith("binaries/"))
    assert binaries == [f"binaries/{platform_folder()[0]}/Oscillator{platform_folder()[1]}"]
    assert "resources/slavemodule.txt" not in names
    assert "resources/wire_fmu/core/framework/unit.py" in names
    assert "resources/wire_fmu/export/facade.py" in names
    assert not any("__pycache__" in n or "/master/" in n or n.endswith("cli.py") for n in names)
    version, core_print, _ = imported_core()
    assert BuildInfo(**record) == BuildInfo("Oscillator", module, version, core_print)


def test_model_description_is_complete_and_validates(fmus, oscillator):
    md = oscillator.model_description
    units = {u.name for u in md.unitDefinitions}
    variables = {v.name: v for v in md.modelVariables}
    for var in md.modelVariables:
        assert var.description
        if var.type == "Real":
            assert var.unit in units
    outputs = {u.variable.name: u for u in md.outputs}
    assert outputs["position"].dependencies == [] and outputs["velocity"].dependencies == []
    assert outputs["acceleration"].dependencies == [variables["force"]]
    expected = [v for v in md.modelVariables if v.causality == "output"]
    assert [u.variable for u in md.initialUnknowns] == expected
    for unknown in md.initialUnknowns:
        assert {d.causality for d in unknown.dependencies} <= {"parameter", "input"}
    cosim = md.coSimulation
    assert cosim.canGetAndSetFMUstate and cosim.canSerializeFMUstate
    assert cosim.canHandleVariableCommunicationStepSize
    assert validate_fmu(str(fmus["oscillator"])) == []
    assert validate_fmu(str(fmus["spring_damper"])) == []


# -- fmpy -----------------------------------------------------------------------
def test_fmpy_simulation_matches_the_closed_form(fmus):
    start = {"force": 3.0, "mass": 2.0, "x0": 0.2, "v0": -0.5}
    result = simulate_fmu(
        str(fmus["oscillator"]),
        stop_time=2.0,
        step_size=0.01,
        start_values=start,
        output=["position", "velocity"],
    )
    assert result["time"][-1] == pytest.approx(2.0)
    error = np.max(np.abs(result["position"] - closed_form(result["time"], **start)))
    assert error < 1e-9


def _outputs(fmu, loaded: LoadedFmu, t0: float, steps: int, h: float = 0.01) -> np.ndarray:
    outputs = loaded.model_description.outputs
    refs = [u.variable.valueReference for u in outputs if u.variable.type == "Real"]
    rows = []
    for k in range(steps):
        fmu.doStep(t0 + k * h, h)
        rows.append(fmu.getReal(refs))
    return np.array(rows)


def test_fmu_state_restores_bit_identically_also_serialised(oscillator, fmi_log):
    fmu = oscillator.start("osc", fmi_log, {"force": 1.25, "damping": 0.7})
    _outputs(fmu, oscillator, 0.0, 25)
    state = fmu.getFMUState()
    first = _outputs(fmu, oscillator, 0.25, 25)
    fmu.setFMUState(state)
    assert _outputs(fmu, oscillator, 0.25, 25).tobytes() == first.tobytes()
    data = fmu.serializeFMUState(state)
    fresh = oscillator.instantiate("fresh", fmi_log)  # never initialised
    restored = fresh.deserializeFMUState(data)
    fresh.setFMUState(restored)
    assert _outputs(fresh, oscillator, 0.25, 25).tobytes() == first.tobytes()
    for instance, saved in ((fmu, state), (fresh, restored)):
        instance.freeFMUState(saved)
        instance.terminate()
        instance.freeInstance()


def test_bad_parameters_fail_cleanly_with_every_problem_logged(oscillator, fmi_log):
    for attempt in range(4):  # freeing after an error used to corrupt the heap by the 2nd-4th
        fmi_log.records.clear()
        fmu = oscillator.instantiate(f"bad{attempt}", fmi_log)
        fmu.setReal([oscillator.vr("mass"), oscillator.vr("stiffness")], [-1.0, -2.0])
        fmu.setupExperiment(startTime=0.0)
        with pytest.raises(FMICallException) as caught:
            fmu.enterInitializationMode()
        assert caught.value.status == FMI_ERROR  # an error, not fatal: the instance lives on
        (error,) = fmi_log.messages(FMI_ERROR)  # said once
        assert "mass = -1.0 must be > 0" in error and "stiffness = -2.0 must be >= 0" in error
        assert not fmi_log.messages(FMI_FATAL)
        fmu.reset()  # and is usable again after fmi2Reset
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.doStep(0.0, 0.01)
        fmu.freeInstance()


def test_bad_parameter_in_simulate_fmu_raises_not_crashes(fmus):
    said = []

    def collect(env, instance, status, category, message):
        said.append((status, message.decode()))

    with pytest.raises(FMICallException, match="error"):
        simulate_fmu(
            str(fmus["oscillator"]), stop_time=0.1, start_values={"mass": -1.0}, logger=collect
        )
    # fmpy switches the FMU's logging off by default; a message of status Error reaches
    # the host all the same, once
    (error,) = [m for s, m in said if s == FMI_ERROR]
    assert "mass = -1.0 must be > 0" in error


def test_refused_step_ends_the_run_with_the_reason_logged(fmus, fmi_log, caplog):
    with caplog.at_level(logging.WARNING):
        result = simulate_fmu(
            str(fmus["oscillator"]),
            stop_time=2.0,
            step_size=0.01,
            start_values={"force": 10.0, "max_position": 0.15},
            debug_logging=True,
        )
    assert result["time"][-1] < 1.0  # fmpy stops at the refused step without raising
    (message,) = fmi_log.messages(FMI_DISCARD)
    assert "refused" in message and "max_position = 0.15 m" in message
    # fmpy asks fmi2Terminated and fmi2LastSuccessfulTime: the refused step's start
    assert result["time"][-1] == pytest.approx(result["time"][-2], abs=0.0100001)


def test_two_fmus_and_repeated_instances_share_one_process(fmus, oscillator, fmi_log):
    spring = LoadedFmu(fmus["spring_damper"])
    k, h, steps = 4 * np.pi**2, 1e-3, 1000
    mass = oscillator.start("mass", fmi_log, {"stiffness": 0.0, "damping": 0.0})
    link = spring.start("spring", fmi_log, {"stiffness": k, "damping": 0.4})
    x_ref, v_ref, force_ref = (oscillator.vr(n) for n in ("position", "velocity", "force"))
    xb, vb, f_ref = (spring.vr(n) for n in ("position_b", "velocity_b", "force"))
    positions = []
    for n in range(steps):
        x, v = mass.getReal([x_ref, v_ref])
        link.setReal([xb, vb], [x, v])
        (tension,) = link.getReal([f_ref])  # direct feedthrough, no step needed
        mass.setReal([force_ref], [-tension])
        mass.doStep(n * h, h)
        link.doStep(n * h, h)
        positions.append(mass.getReal([x_ref])[0])
    times = h * np.arange(1, steps + 1)
    assert np.max(np.abs(np.array(positions) - closed_form(times))) < 5e-3  # explicit coupling
    for instance in (mass, link):
        instance.terminate()
        instance.freeInstance()
    for n in range(5):  # pythonfmu 0.7 failed the 2nd instantiation of a thin script
        again = oscillator.start(f"again{n}", fmi_log)
        again.doStep(0.0, 0.01)
        again.freeInstance()


def test_core_version_guard_refuses_a_mismatched_fmu(fmus, tmp_path, fmi_log, caplog):
    tampered = tmp_path / "Oscillator.fmu"
    with zipfile.ZipFile(fmus["oscillator"]) as src, zipfile.ZipFile(tampered, "w") as dst:
        for item in src.infolist():
            data = src.read(item.filename)
            if item.filename == f"resources/{BUILD_INFO_FILE}":
                record = json.loads(data)
                record["fingerprint"] = "0" * 64
                data = json.dumps(record).encode()
            dst.writestr(item, data)
    loaded = LoadedFmu(tampered)
    with caplog.at_level(logging.ERROR), pytest.raises(Exception, match="Failed to instantiate"):
        loaded.instantiate("guarded", fmi_log)
    (fatal,) = fmi_log.messages(FMI_FATAL)
    assert "CoreVersionError" in fatal and "'Oscillator'" in fatal and "000000000000" in fatal
    assert "Rebuild all FMUs" in fatal
    assert any("was built with wire_fmu" in r.getMessage() for r in caplog.records)
    LoadedFmu(fmus["oscillator"]).start("untampered", fmi_log).freeInstance()


# -- libcosimpy --------------------------------------------------------------------
def test_libcosimpy_runs_the_fmu(fmus):
    from libcosimpy.CosimEnums import CosimExecutionState
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_step_size(step_size=int(1e7))  # 10 ms in ns
    slave = CosimLocalSlave(fmu_path=str(fmus["oscillator"]), instance_name="osc")
    index = execution.add_local_slave(local_slave=slave)
    refs = {v.name.decode(): v.reference for v in execution.slave_variables(index)}
    start = {"force": 2.0, "x0": -0.1, "mass": 1.5}
    for name, value in start.items():
        assert execution.real_initial_value(index, refs[name], value)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer=observer)
    assert execution.simulate_until(target_time=int(2e9))
    status = execution.status()
    assert status.state == CosimExecutionState.STOPPED.value and status.current_time == int(2e9)
    (position,) = observer.last_real_values(index, [refs["position"]])
    assert position == pytest.approx(closed_form([2.0], **start)[0], abs=1e-9)


# -- outside this repository ----------------------------------------------------------
ISOLATED_RUN = textwrap.dedent(
    """
    import json, sys
    sys.meta_path[:] = [f for f in sys.meta_path if "editable" not in repr(f).lower()]
    sys.path[:] = [p for p in sys.path if p != {root!r} and "__editable__" not in p]
    try:
        import wire_fmu
        raise SystemExit("wire_fmu importable before the FMU runs")
    except ModuleNotFoundError:
        pass
    from fmpy import simulate_fmu
    runs = [simulate_fmu({fmu!r}, stop_time=1.0, step_size=0.01, start_values={{"force": 1.0}})
            for _ in range(2)]  # fmpy deletes the folder the first run imported from
    import wire_fmu
    print(json.dumps({{"file": wire_fmu.__file__, "x": float(runs[1]["position"][-1])}}))
    """
)


def test_bundled_core_runs_without_the_repository(fmus):
    code = ISOLATED_RUN.format(root=str(ROOT), fmu=str(fmus["oscillator"]))
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd="/", timeout=60
    )
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert "resources" in report["file"] and not report["file"].startswith(str(ROOT))
    assert report["x"] == pytest.approx(closed_form([1.0], force=1.0)[0], abs=1e-9)


INLINE_MODEL = textwrap.dedent(
    '''
    """A gain as a self-contained facade script."""
    from wire_fmu.core.framework.unit import StepResult, Unit, input_, output, parameter
    from wire_fmu.export.facade import CoreFacade


    class GainUnit(Unit):
        NAME = "Gain"
        DESCRIPTION = "y = k u"
        VARIABLES = (
            parameter("k", 2.0, "1", "Gain"),
            input_("u", 0.0, "N", "Input force"),
            output("y", "N", "Output force", depends_on=("u",)),
        )

        def configure(self): pass
        def initialize(self, start_time): self.advance(start_time, 0.0)
        def get_state(self): return {{}}
        def set_state(self, state): pass

        def advance(self, time, step):
            self.values["y"] = self.values["k"] * self.values["u"]
            return StepResult(True)


    class Gain(CoreFacade):
        unit_class = GainUnit
    '''
)


def test_build_fmus_script_builds_validates_and_reports_failures(tmp_path):
    models, out = tmp_path / "models", tmp_path / "out"
    models.mkdir()
    (models / "gain.py").write_text(INLINE_MODEL.format())
    (models / "_helper.py").write_text("raise RuntimeError('not a facade script')\n")
    command = [sys.executable, str(ROOT / "build_fmus.py"), "--models", str(models)]
    start = time.perf_counter()
    done = subprocess.run([*command, "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert time.perf_counter() - start < 40
    assert "built Gain.fmu" in done.stderr and validate_fmu(str(out / "Gain.fmu")) == []
    (models / "broken.py").write_text("class Broken(:\n")
    failed = subprocess.run([*command, "--out", str(out)], capture_output=True, text=True)
    assert failed.returncode == 1
    assert "broken.py" in failed.stderr and "importing the script failed" in failed.stderr
    assert "of 2 FMUs failed" in failed.stderr

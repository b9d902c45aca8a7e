"""Processes that ran our FMUs end with the status they report, and never abort at exit.

With pythonfmu's prebuilt wrapper, processes aborted after their results were
written ("corrupted double-linked list", exit 134): the wrapper released the
script module's borrowed ``__dict__`` on every instantiation and released an
instance twice after any Python exception. Our own binary
(``wire_fmu/export/native/fmi2_python.c``) owns its references exactly. Here
24 fresh processes run scenes through the Python API and the command line,
on finishing, failing and refusing paths, each checked for its exit status,
no traceback and no heap message; ``scripts`` in the closing note ran the
same 200 times each.

The command-line runs of an interrupted scene also check Ctrl-C: exit 130,
status ``interrupted`` in ``metadata.json``, rows kept.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from wire_fmu.master.run import SCENE_DIR

pytestmark = pytest.mark.integration

HEAP_WORDS = ("corrupted", "double free", "free():", "malloc", "Segmentation", "Aborted")
RISER = SCENE_DIR / "riser_tensioner.toml"

API_RUN = """
import sys
from pathlib import Path
from wire_fmu.master.run import run_scene
outcome = run_scene(sys.argv[1], Path(sys.argv[2]), fmu_dir=Path(sys.argv[3]), stop_time=0.2,
                    plots=False)
print("status", outcome.result.status)
sys.exit(0 if outcome.result.status == "finished" else 1)
"""

API_CHECK = """
import sys
from pathlib import Path
from wire_fmu.master.run import check_scene
from wire_fmu.master.scene import SceneError
try:
    check_scene(sys.argv[1], Path(sys.argv[3]))
except SceneError as err:
    print(err)
    sys.exit(1)
print("no problems")
"""


@pytest.fixture(scope="module")
def fmu_dir(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("exit_fmus")
    subprocess.run(
        [sys.executable, "-m", "wire_fmu.cli", "--fmu-dir", str(folder), "build"],
        check=True,
        capture_output=True,
    )
    return folder


@pytest.fixture(scope="module")
def failing_scene(tmp_path_factory) -> Path:
    text = (
        RISER.read_text(encoding="utf-8")
        .replace('"rod.force" = -1.424e6', '"rod.force" = -5.0e6')
        .replace('name = "riser_tensioner"', 'name = "failing"')
    )
    path = tmp_path_factory.mktemp("exit_scenes") / "failing.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _environment() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("OPENBLAS_NUM_THREADS", None)  # no thread setting of ours hides anything
    return env


def _checked(run: subprocess.CompletedProcess, expected: int) -> str:
    said = run.stdout + run.stderr
    assert run.returncode == expected, (run.returncode, said[-2000:])
    assert "Traceback" not in said, said[-2000:]
    assert not any(word in said for word in HEAP_WORDS), said[-2000:]
    return said


def _python(script: str, scene: Path, out: Path, fmu_dir: Path, expected: int) -> str:
    run = subprocess.run(
        [sys.executable, "-c", script, str(scene), str(out), str(fmu_dir)],
        capture_output=True,
        text=True,
        env=_environment(),
        timeout=300,
    )
    return _checked(run, expected)


def _cli(args: list[str], fmu_dir: Path, expected: int) -> str:
    run = subprocess.run(
        [sys.executable, "-m", "wire_fmu.cli", "--fmu-dir", str(fmu_dir), *args],
        capture_output=True,
        text=True,
        env=_environment(),
        timeout=300,
    )
    return _checked(run, expected)


FMPY_ONE_AFTER_ANOTHER = """
import sys
from pathlib import Path
from fmpy import simulate_fmu
for name in ("Winch", "Hydraulics", "BlockTrain", "Winch"):
    result = simulate_fmu(str(Path(sys.argv[3]) / f"{name}.fmu"), stop_time=0.02,
                          output_interval=0.01)
    print(name, "rows", len(result))
"""


def test_fmus_run_one_after_another_by_fmpy_in_one_process(tmp_path, fmu_dir):
    """The runner ``fmpy.simulate_fmu`` removes each FMU's extraction folder when done, and the
    first FMU's ``wire_fmu`` serves every later one: a later FMU imports what the first
    never did from its own identical copy (``guard.follow_bundled_copy``), where it had
    failed with ``No module named 'wire_fmu.core.units.hydraulics'``."""
    said = _python(FMPY_ONE_AFTER_ANOTHER, RISER, tmp_path, fmu_dir, 0)
    for name in ("Winch", "Hydraulics", "BlockTrain"):
        assert f"{name} rows 3" in said, said[-2000:]


@pytest.mark.parametrize("attempt", range(5))
def test_python_api_runs_and_checks_exit_cleanly(tmp_path, fmu_dir, failing_scene, attempt):
    assert "status finished" in _python(API_RUN, RISER, tmp_path / "ok", fmu_dir, 0)
    assert "status failed" in _python(API_RUN, failing_scene, tmp_path / "bad", fmu_dir, 1)
    said = _python(API_CHECK, failing_scene, tmp_path, fmu_dir, 1)
    assert said.count("precharge_pressure") == 1


@pytest.mark.parametrize("attempt", range(3))
def test_command_line_runs_and_checks_exit_cleanly(tmp_path, fmu_dir, failing_scene, attempt):
    _cli(
        ["run", "-q", "--stop-time", "0.2", "-o", str(tmp_path / "ok"), "riser_tensioner"],
        fmu_dir,
        0,
    )
    said = _cli(["check", str(failing_scene)], fmu_dir, 1)
    assert said.count("precharge_pressure") == 1
    _cli(["run", "-q", "-o", str(tmp_path / "bad"), str(failing_scene)], fmu_dir, 1)
    meta = json.loads((tmp_path / "bad" / "metadata.json").read_text())
    assert meta["result"]["status"] == "failed"


def test_ctrl_c_ends_a_run_interrupted_with_exit_130_and_rows_kept(tmp_path, fmu_dir):
    out = tmp_path / "interrupted"
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "wire_fmu.cli",
            "--fmu-dir",
            str(fmu_dir),
            "run",
            "-q",
            "-o",
            str(out),
            "riser_tensioner",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_environment(),
    )
    csv = out / "timeseries.csv"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and (not csv.exists() or csv.stat().st_size < 20_000):
        time.sleep(0.1)  # well inside the run: rows are being written
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=120)
    run = subprocess.CompletedProcess(process.args, process.returncode, stdout, stderr)
    said = _checked(run, 130)
    assert "run interrupted" in said
    meta = json.loads((out / "metadata.json").read_text())
    assert meta["result"]["status"] == "interrupted"
    rows = csv.read_text().splitlines()
    assert len(rows) > 10 and float(rows[-1].split(",")[0]) > 0.0

"""Our FMU in a non-Python host: the documented command, run for real.

``tests/data/c_host/fmu_host.c`` is a minimal FMI 2.0 co-simulation host in
C (dlopen, instantiate, initialise, step, get). Compiled with gcc against
FMPy's copy of the FMI 2.0 headers, it loads the BlockTrain binary with
libpython preloaded and the environment's site-packages on ``PYTHONPATH``
(docs/interop.md), and must read the same numbers fmpy reads.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import fmpy
import pytest

from wire_fmu.export.builder import build_fmu
from wire_fmu.master.slave import Slave

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[1]
HOST_SOURCE = ROOT / "tests" / "data" / "c_host" / "fmu_host.c"
FMI_HEADERS = Path(fmpy.__file__).parent / "c-code"
VARIABLE, STEPS, STEP = "line_a.tension", 5, 0.01


def libpython() -> Path:
    """The shared libpython of the interpreter running the tests."""
    return Path(sysconfig.get_config_var("LIBDIR")) / sysconfig.get_config_var("LDLIBRARY")


def host_environment() -> dict[str, str]:
    """What a C host needs: libpython preloaded, this environment's packages importable."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONHOME", "PYTHONPATH")}
    env["LD_PRELOAD"] = str(libpython())
    env["PYTHONPATH"] = sysconfig.get_paths()["purelib"]
    return env


def _missing() -> str | None:
    if shutil.which("gcc") is None:
        return "gcc is not installed"
    if not (FMI_HEADERS / "fmi2Functions.h").exists():
        return f"FMPy's FMI 2.0 headers are not in {FMI_HEADERS}"
    if not sys.platform.startswith("linux"):
        return "the host loads binaries/linux64"
    if not libpython().exists():
        return f"this Python has no shared libpython ({libpython()})"
    return None


@pytest.fixture(scope="module")
def host(tmp_path_factory) -> tuple[Path, Path]:
    reason = _missing()
    if reason:
        pytest.skip(reason)
    folder = tmp_path_factory.mktemp("c_host")
    exe = folder / "fmu_host"
    subprocess.run(
        [
            "gcc",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-o",
            str(exe),
            str(HOST_SOURCE),
            f"-I{FMI_HEADERS}",
            "-ldl",
            "-lpthread",
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    fmu = build_fmu(ROOT / "models" / "block_train.py", folder)
    unzipped = folder / "BlockTrain"
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(unzipped)
    return exe, unzipped


def _fmpy_values(unzipped: Path) -> list[float]:
    slave = Slave("bt", unzipped.parent / "BlockTrain.fmu")
    slave.instantiate(str(unzipped))
    slave.initialize(0.0, {})
    slave.exit_initialization()
    values = []
    for i in range(STEPS):
        slave.do_step(i * STEP, STEP)
        values.append(slave.get([VARIABLE])[VARIABLE])
    slave.terminate()
    return values


def test_c_host_runs_the_block_train_with_libpython_preloaded(host):
    exe, unzipped = host
    run = subprocess.run(
        [str(exe), str(unzipped), VARIABLE, str(STEPS), str(STEP)],
        env=host_environment(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    values = [float(line.split()[1]) for line in run.stdout.splitlines()]
    assert len(values) == STEPS
    assert values[0] == pytest.approx(1.2e5 * 9.81 / 4, rel=1e-12)  # hook in equilibrium
    assert values == _fmpy_values(unzipped)  # bit for bit what a Python host reads


def test_a_host_thread_steps_the_unit_and_keeps_one_python_thread_state(host):
    """A C++ master steps its units on worker threads of its own (libcosim does). Each
    such thread keeps the one Python thread state its first call made: made and freed on
    every call, it cost libcosim about a quarter of its time on the drawworks."""
    exe, unzipped = host
    run = subprocess.run(
        [str(exe), str(unzipped), VARIABLE, str(STEPS), str(STEP), "thread"],
        env=host_environment(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    *lines, last = run.stdout.splitlines()
    assert [float(line.split()[1]) for line in lines] == _fmpy_values(unzipped)
    assert last == "thread_states 2"  # the host's main thread's, and its worker's, kept


def test_without_libpython_the_binary_does_not_load(host):
    exe, unzipped = host
    env = host_environment()
    del env["LD_PRELOAD"]
    run = subprocess.run(
        [str(exe), str(unzipped), VARIABLE, "1"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 1
    assert "undefined symbol" in run.stderr and "Py" in run.stderr

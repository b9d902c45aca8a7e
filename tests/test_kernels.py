"""The compiled kernels against the Python kernel (issue 16).

The Python kernel (``WIRE_FMU_KERNEL=python``) is the readable reference that the
closed-form checks elsewhere hold to the physics; the compiled kernels must give
the same numbers. Every shipped scene's first seconds and the hard cases are run
twice, once with each kernel, through our FMUs and master, and every recorded
column must agree to a relative 1e-10 of its largest magnitude. Energies are sums
of terms much larger than themselves (a hook's potential energy against its small
net stored energy), so an energy column may also differ by up to 1e-7 J.
"""

from __future__ import annotations

import logging
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework import compiled
from wire_fmu.core.framework.compiled import KERNEL_ENV, use_compiled
from wire_fmu.master.observers import CsvRecorder
from wire_fmu.master.plots import read_results
from wire_fmu.master.run import find_scene, with_run_settings
from wire_fmu.master.scene import load_scene
from wire_fmu.master.simulation import Simulation
from wire_fmu.master.validate import validate_scene

from .block_train_helpers import make_unit
from .hard_case_helpers import build_our_fmus, run_case
from .hard_case_scenes import (
    brake_scene,
    break_scene,
    impact_scene,
    snap_scene,
    stiff_pulley_scene,
    winch_and_fall_scene,
)

pytestmark = pytest.mark.skipif(not compiled.numba_available(), reason="numba is not installed")

RELATIVE = 1e-10
"""Largest difference between the kernels, relative to a column's largest magnitude."""
ENERGY_FLOOR = 1e-7
"""J: what an energy column (``*energy*``, ``*work*``, ``*balance*``) may differ by in any case."""


@pytest.fixture(scope="module")
def fmus(tmp_path_factory) -> dict[str, Path]:
    """Our hoisting FMUs, built once for this module."""
    return build_our_fmus(tmp_path_factory.mktemp("fmus"))


def assert_tables_agree(python: dict, compiled_run: dict, what: str) -> None:
    """Every column of two result tables agrees to :data:`RELATIVE` of its magnitude."""
    assert python.keys() == compiled_run.keys(), what
    for column, reference in python.items():
        other = compiled_run[column]
        assert reference.shape == other.shape, f"{what}: {column} has other rows"
        difference = float(np.max(np.abs(reference - other), initial=0.0))
        scale = float(np.max(np.abs(reference), initial=0.0))
        energy = any(word in column for word in ("energy", "work", "balance"))
        allowed = max(RELATIVE * scale, ENERGY_FLOOR if energy else 0.0)
        assert difference <= allowed, (
            f"{what}: {column} differs by {difference:.3g} (largest magnitude {scale:.3g})"
        )


def both_kernels(monkeypatch, run) -> tuple[dict, dict]:
    """``run()`` with the Python kernel, then with the compiled one: their tables."""
    monkeypatch.setenv(KERNEL_ENV, "python")
    python = run("python")
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    return python, run("compiled")


SHIPPED = (
    "drawworks",
    "riser_tensioner",
    "heave_compensated_hoist",
    "multimass_drive",
    "machine_unit",
    "scissor_jack",
)


@pytest.mark.integration
@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_scenes_first_seconds_agree(fmus, tmp_path, monkeypatch, name):
    """Each shipped scene's first 1.5 s (drivers and events as shipped): both kernels agree.

    Mutation: the block train kernel's damper term dropped (``t_d = 0``): riser_tensioner
    failed (path_end.tension differs by 4.67e+03 N).
    """
    scene = load_scene(find_scene(name))
    built = {n: replace(u, fmu=str(fmus.get(u.fmu, u.fmu))) for n, u in scene.units.items()}
    scene = with_run_settings(replace(scene, units=built, plots=()), stop_time=1.5)

    def run(kernel: str) -> dict:
        recorder = CsvRecorder(tmp_path / kernel, scene.run.output_interval)
        result = Simulation(scene, validate_scene(scene), [recorder]).run()
        assert result.status == "finished", result.message
        return read_results(recorder.csv_path)

    python, compiled_run = both_kernels(monkeypatch, run)
    assert_tables_agree(python, compiled_run, name)


HARD_CASES = {
    "stiff pulley": lambda: stiff_pulley_scene(1e-4),
    "winch and fall": lambda: winch_and_fall_scene(2.5e-4),
    "band brake": lambda: brake_scene(2e-3),
    "slack and snap": lambda: snap_scene(1e-3),
    "rope break (commanded)": lambda: break_scene(1e-3, "commanded"),
    "rope break (overload)": lambda: break_scene(1e-3, "overload"),
    "end-stop impact": lambda: impact_scene(1e-3, 1e-4),
}


@pytest.mark.integration
@pytest.mark.parametrize("case", sorted(HARD_CASES))
def test_hard_cases_agree(fmus, tmp_path, monkeypatch, case):
    """The hard cases (snaps, breaks, brake stick-slip, stops): both kernels agree."""
    data = HARD_CASES[case]()

    def run(kernel: str) -> dict:
        outcome = run_case(data, fmus, tmp_path / kernel)
        assert outcome.result.status == "finished", outcome.result.message
        return outcome.columns

    python, compiled_run = both_kernels(monkeypatch, run)
    assert_tables_agree(python, compiled_run, case)


def test_block_train_runs_the_compiled_kernel_only_where_it_applies(monkeypatch):
    """Fixed geometry and planar moving geometry compile, with or without friction links
    (bearing friction, rope slip); moving spatial geometry runs the Python kernel;
    ``WIRE_FMU_KERNEL=python`` turns compiling off."""
    from wire_fmu.core.units.block_train.reevings import drilling_block_train, single_fall

    reeving = single_fall(mass=1000.0, length=10.0)
    sheaves = drilling_block_train(2)
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    assert make_unit(reeving, "rope_damping").model.compiled
    assert make_unit(reeving, "moving_geometry").model.compiled
    assert make_unit(sheaves, "sheave_inertia,moving_geometry").model.compiled
    assert not make_unit(reeving, "moving_geometry,spatial_geometry").model.compiled
    assert make_unit(sheaves, "sheave_inertia,bearing_friction").model.compiled
    assert make_unit(sheaves, "sheave_inertia,rope_slip,moving_geometry").model.compiled
    monkeypatch.setenv(KERNEL_ENV, "python")
    assert not make_unit(sheaves, "sheave_inertia,bearing_friction,rope_slip").model.compiled
    assert not make_unit(reeving, "rope_damping").model.compiled
    assert not make_unit(reeving, "moving_geometry").model.compiled


def test_a_change_in_a_module_a_kernel_imports_compiles_it_afresh(tmp_path, monkeypatch):
    """The block-train kernel calls compiled helpers in ``kernel_friction``: a change there
    (a changed capacity formula would otherwise run stale machine code) gives the kernel's
    entry points a new cache, while an unrelated module of the unit does not."""
    import wire_fmu.core.units.block_train.kernel as kernel

    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path / "cache"))
    package = Path(compiled.__file__).parents[2]
    unit = "core/units/block_train/"
    sources = [unit + "kernel.py", unit + "kernel_friction.py", unit + "kernel_geometry.py"]
    sources += [unit + "model.py", *compiled.SHARED_KERNEL_SOURCES]
    root = tmp_path / "fmu" / "resources" / "wire_fmu"
    for source in sources:
        (root / source).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(package / source, root / source)

    def cache_path() -> str:
        locator = compiled._ContentCacheLocator.from_function(
            kernel.rhs.py_func, str(root / sources[0])
        )
        return locator.get_cache_path()

    first = cache_path()
    model = root / unit / "model.py"
    model.write_text(model.read_text() + "\n# changed\n")
    assert cache_path() == first
    helper = root / unit / "kernel_friction.py"
    helper.write_text(helper.read_text() + "\n# changed\n")
    assert cache_path() != first


def test_a_misspelt_kernel_choice_is_a_clear_error(monkeypatch):
    """``WIRE_FMU_KERNEL=numba`` names the variable and the choices."""
    monkeypatch.setenv(KERNEL_ENV, "numba")
    with pytest.raises(ConfigurationError) as info:
        use_compiled("block train")
    assert KERNEL_ENV in str(info.value)
    assert "compiled, python" in str(info.value)


def test_without_numba_units_fall_back_with_one_log_line(monkeypatch, caplog):
    """No numba: the Python kernel runs, and the log says so once per unit built."""
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    monkeypatch.setattr(compiled, "numba", None)
    with caplog.at_level(logging.INFO, logger=compiled.__name__):
        assert not use_compiled("block train")
    lines = [r.getMessage() for r in caplog.records if r.name == compiled.__name__]
    assert lines == ["block train: numba is not installed; running the Python kernel"]


def test_a_cache_folder_that_cannot_be_written_is_said_once_per_unit(tmp_path, monkeypatch, caplog):
    """Numba would go on silently caching elsewhere (for an extracted FMU: anew every run);
    the unit's log names the variable, the folder and why."""
    (tmp_path / "a_file").write_text("")
    monkeypatch.setenv(KERNEL_ENV, "compiled")
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path / "a_file" / "cache"))
    problem = compiled.cache_problem()
    assert problem is not None and compiled.CACHE_ENV in problem and "a_file" in problem
    with caplog.at_level(logging.WARNING, logger=compiled.__name__):
        assert use_compiled("block train") is compiled.numba_available()
    lines = [r.getMessage() for r in caplog.records if r.name == compiled.__name__]
    assert len(lines) == (1 if compiled.numba_available() else 0)
    assert all(line.startswith(f"block train: {problem}") for line in lines)


def test_the_cache_variable_takes_the_home_and_relative_paths(tmp_path, monkeypatch):
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.setenv(compiled.CACHE_ENV, "~/kernels")
    assert compiled.cache_directory() == tmp_path / "home" / "kernels"
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(compiled.CACHE_ENV, "relative/kernels")
    assert compiled.cache_directory() == tmp_path / "relative" / "kernels"


def test_a_writable_cache_folder_is_made_and_no_problem(tmp_path, monkeypatch):
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path / "new" / "cache"))
    assert compiled.cache_problem() is None
    assert (tmp_path / "new" / "cache").is_dir()
    assert list((tmp_path / "new" / "cache").iterdir()) == []  # the probe file is gone


def test_every_copy_of_the_sources_shares_one_cache(tmp_path, monkeypatch):
    """Two copies of the sources at different paths (as two extracted FMUs) have one cache
    folder, inside ``WIRE_FMU_CACHE_DIR``; a change of the kernel, or of the shared loop its
    entry point inlines, gets another."""
    import wire_fmu.core.units.block_train.kernel as kernel

    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path / "cache"))
    package = Path(compiled.__file__).parents[2]
    sources = ["core/units/block_train/kernel.py", *compiled.SHARED_KERNEL_SOURCES]
    copies = []
    for name in ("fmu_a", "fmu_b"):
        root = tmp_path / name / "resources" / "wire_fmu"
        for source in sources:
            (root / source).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(package / source, root / source)
        copies.append(root)
    locate = compiled._ContentCacheLocator.from_function

    def cache_of(root: Path) -> str:
        return locate(kernel.rhs.py_func, str(root / sources[0])).get_cache_path()

    first = cache_of(copies[0])
    assert cache_of(copies[1]) == first
    assert first.startswith(str(tmp_path / "cache"))
    loop = copies[1] / "core/framework/compiled_step.py"
    loop.write_text(loop.read_text() + "\n# changed\n")
    assert cache_of(copies[1]) != first
    own = copies[0] / sources[0]
    own.write_text(own.read_text() + "\n# changed\n")
    assert cache_of(copies[0]) not in (first, cache_of(copies[1]))


def test_a_kernel_modules_decorators_key_its_functions_once_and_as_the_locator_would(
    monkeypatch, tmp_path
):
    """``kernel_decorators`` computes the module's cache key once for all its functions, and
    the cache folder a function so keyed gets is the one the key computed afresh gives."""
    import wire_fmu.core.units.winch.kernel as kernel

    if not compiled.numba_available():
        pytest.skip("numba is not installed")
    monkeypatch.setenv(compiled.CACHE_ENV, str(tmp_path / "cache"))
    digests = []
    computed = compiled.source_digest
    monkeypatch.setattr(compiled, "source_digest", lambda f: digests.append(f) or computed(f))
    jit, jit_inline = compiled.kernel_decorators(kernel.__file__)

    @jit
    def add_one(x):
        return x + 1.0

    @jit
    def add_two(x):
        return x + 2.0

    @jit_inline
    def same(x):
        return x

    assert digests == [kernel.__file__]
    assert (add_one(1.0), add_two(1.0), same(1.0)) == (2.0, 3.0, 1.0)
    locate = compiled._ContentCacheLocator.from_function
    keyed = locate(kernel.rhs.py_func, kernel.__file__).get_cache_path()
    assert len(digests) == 1  # the kernel's functions carry their module's key
    fresh = locate(lambda x: x, kernel.__file__).get_cache_path()  # no key: computed afresh
    assert len(digests) == 2 and keyed == fresh

"""The instruction-count benchmark: its window on the stepping loop, the totals it reads
from callgrind, and the refusal of what it cannot run.

The counted run itself needs valgrind and takes minutes (the process runs some fifty
times slower), so it is a ``slow`` test; the rest runs everywhere.
"""

from __future__ import annotations

import shutil
from pathlib import Path
from types import SimpleNamespace

import pytest

from wire_fmu.bench import callgrind_window
from wire_fmu.bench import instructions as bench_instructions


class _Control:
    """Records the client requests a window sends."""

    def __init__(self) -> None:
        self.sent: list[str] = []
        self.on = lambda: self.sent.append("on")
        self.off = lambda: self.sent.append("off")
        self.dump = lambda: self.sent.append("dump")


def test_the_window_counts_the_steps_after_the_warm_up_and_dumps_once_at_the_end():
    control = _Control()
    window = callgrind_window.CallgrindWindow(0.01, control)
    settings = SimpleNamespace(stop_time=0.02)
    for k in range(1, 5):  # steps ending at 4, 8, 12, 16 ms of a 20 ms run
        window.on_step(SimpleNamespace(time=0.004 * k, run_settings=settings))
        if k == 2:
            assert control.sent == []  # 8 ms: still warming up
    assert control.sent == ["on"]  # switched on at the end of the step ending at 12 ms
    window.on_step(SimpleNamespace(time=0.02, run_settings=settings))  # the last step
    assert control.sent == ["on", "off", "dump"]  # off before the results are written
    assert window.steps == 2  # the steps ending at 16 and 20 ms
    window.on_end(SimpleNamespace(time=0.02), None)
    assert control.sent == ["on", "off", "dump"]  # nothing more


def test_a_run_that_ends_in_its_warm_up_switches_nothing():
    control = _Control()
    window = callgrind_window.CallgrindWindow(1.0, control)
    window.on_step(SimpleNamespace(time=0.004, run_settings=SimpleNamespace(stop_time=0.004)))
    with window.loading():
        pass  # a load before counting starts: nothing to switch off
    window.on_end(SimpleNamespace(time=0.004), None)
    assert control.sent == [] and window.steps == 0 and window.kernel_loads == 0


def test_a_kernel_load_while_counting_is_left_out():
    numba = pytest.importorskip("numba")
    control = _Control()
    window = callgrind_window.CallgrindWindow(0.0, control)
    window.on_step(SimpleNamespace(time=0.004, run_settings=SimpleNamespace(stop_time=1.0)))

    @numba.njit
    def twice(x):
        return 2.0 * x

    with callgrind_window.kernel_loads_left_out(window):
        assert twice(1.5) == 3.0  # the first call with floats: numba compiles it
        assert twice(2.5) == 5.0  # loaded: no load
    assert control.sent == ["on", "off", "on"]
    assert window.kernel_loads == 1
    load = numba.core.dispatcher._DispatcherBase._compile_for_args
    assert load.__name__ == "_compile_for_args"  # numba's own again after the block


def test_per_step_figures_divide_by_steps_and_units():
    row = bench_instructions.SceneInstructions(
        "riser_tensioner", 2, 100, 3_000_000, in_fmi_calls=2_400_000, arrays_made=12_500
    )
    assert row.per_step == 30_000 and row.per_unit_step == 15_000
    assert row.master_per_unit_step == 3_000  # (3e6 - 2.4e6) / (100 steps x 2 units)
    assert row.arrays_per_step == 125
    table = bench_instructions.table([row])
    assert "| riser_tensioner | 2 | 100 | 30,000 | 15,000 | 3,000 | 125 | 0 |" in table
    assert "where the instructions ran" not in table  # no libraries read: no second table


def test_the_libraries_shares_are_tabled_per_scene():
    kernels = "the compiled kernels (numba's machine code)"
    rows = [
        bench_instructions.SceneInstructions(
            "riser_tensioner",
            2,
            100,
            1000,
            by_library={"the Python interpreter": 750, kernels: 250},
        ),
        bench_instructions.SceneInstructions(
            "drawworks", 2, 100, 2000, by_library={"the Python interpreter": 1000, kernels: 1000}
        ),
    ]
    table = bench_instructions.table(rows)
    assert "| where the instructions ran | riser_tensioner | drawworks |" in table
    assert "| the Python interpreter | 75.0 % | 50.0 % |" in table
    assert f"| {kernels} | 25.0 % | 50.0 % |" in table
    assert "numpy" not in table  # a library no scene ran in is left out


def test_bad_options_are_refused_all_at_once(capsys):
    with pytest.raises(SystemExit) as stopped:
        bench_instructions.main(["--stop-time", "0", "--warm-up", "1"])
    assert stopped.value.code == 2
    err = capsys.readouterr().err
    assert "--stop-time must be positive" in err and "--warm-up must be at least 0" in err


def test_without_valgrind_the_command_says_what_is_missing(monkeypatch, capsys):
    monkeypatch.setattr(bench_instructions.shutil, "which", lambda tool: None)
    with pytest.raises(SystemExit) as stopped:
        bench_instructions.main(["--scenes", "riser_tensioner"])
    assert stopped.value.code == 2
    assert "valgrind not found" in capsys.readouterr().err
    with pytest.raises(RuntimeError, match="install valgrind"):
        bench_instructions.measure(["riser_tensioner"], 0.02, 0.01)


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed")
def test_the_count_is_the_same_in_two_runs():
    first, second = (
        bench_instructions.measure(["riser_tensioner"], 0.06, 0.03)[0] for _ in range(2)
    )
    assert first.steps == second.steps > 0
    assert first.instructions > 10_000 * first.steps  # a step runs the units, not nothing
    # most of a step runs inside the units' FMI calls, some of it in the master
    assert 0.5 * first.instructions < first.in_fmi_calls < first.instructions
    # the kernels make arrays (numba's allocator is found by name), and as many each run
    assert first.arrays_made == second.arrays_made > first.steps
    # to the instruction with the address space fixed (setarch); else objects' addresses,
    # and the hashes made from them, may move from run to run
    allowed = 0 if shutil.which("setarch") else 5e-3 * first.instructions
    assert abs(first.instructions - second.instructions) <= allowed


@pytest.mark.skipif(
    not Path("/usr/include/valgrind/callgrind.h").exists() or shutil.which("cc") is None,
    reason="needs a C compiler and valgrind's callgrind.h",
)
def test_the_client_requests_build_and_do_nothing_outside_valgrind(tmp_path):
    control = callgrind_window.CallgrindControl(tmp_path)
    control.on()
    control.off()
    control.dump()

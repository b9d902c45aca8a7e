"""The master's calls every macro step: the FMU's C functions made ready once.

:meth:`Slave.reader <wire_fmu.master.slave.Slave.reader>` and
:meth:`Slave.writer <wire_fmu.master.slave.Slave.writer>` call the C functions of the
library fmpy loaded directly, untyped, with C values made once; an fmpy that does not
keep its library as expected goes through its own wrappers. Both ways give the same
run, and a call that fails names the unit.
"""

from __future__ import annotations

import ctypes
from pathlib import Path

import pytest

from wire_fmu.master import slave as slave_module
from wire_fmu.master.observers import Observer
from wire_fmu.master.run import run_scene
from wire_fmu.master.slave import UnitFailedError

pytestmark = pytest.mark.integration

STOP = 0.2  # s of the riser tensioner: 50 macro steps, every one recorded


@pytest.fixture(scope="module")
def fmu_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("fmi_call_fmus")


def _run(scene: str, out: Path, fmu_dir: Path, observers=()) -> tuple[str, dict]:
    outcome = run_scene(
        scene, out, plots=False, fmu_dir=fmu_dir, stop_time=STOP, observers=observers
    )
    assert outcome.result.status == "finished", outcome.result.message
    calls = {name: dict(s.calls) for name, s in outcome.simulation.slaves.items()}
    return outcome.csv_path.read_text(), calls


def test_direct_calls_and_fmpys_wrappers_give_the_same_run(tmp_path, fmu_dir, monkeypatch):
    direct, direct_calls = _run("riser_tensioner", tmp_path / "direct", fmu_dir)
    monkeypatch.setattr(slave_module._HotCalls, "of", classmethod(lambda cls, fmu: None))
    wrapped, wrapped_calls = _run("riser_tensioner", tmp_path / "wrapped", fmu_dir)
    assert direct == wrapped  # the same text, bit for bit
    assert direct_calls == wrapped_calls
    for calls in direct_calls.values():  # one batched set, step and Real get per macro step
        assert calls["doStep"] == round(STOP / 0.004)
        assert calls["setReal"] >= calls["doStep"]
        assert calls["getReal"] >= calls["doStep"]


class _HotCallsSeen(Observer):
    """Keeps each unit's hot calls as the run makes them."""

    def __init__(self) -> None:
        self.seen: dict[str, object] = {}

    def on_step(self, sim) -> None:
        self.seen = {name: unit._hot for name, unit in sim.slaves.items()}


def test_the_hot_calls_are_the_libraries_own_functions_called_untyped(tmp_path, fmu_dir):
    seen = _HotCallsSeen()
    _run("riser_tensioner", tmp_path / "seen", fmu_dir, observers=[seen])
    assert set(seen.seen) == {"rope", "cylinder"}
    for hot in seen.seen.values():
        assert isinstance(hot.component, ctypes.c_void_p) and hot.component.value
        assert set(hot.functions) == set(slave_module._HOT_FUNCTIONS)
        for function in hot.functions.values():  # no from_param conversion per argument
            assert function.argtypes is None
            assert function.restype is ctypes.c_int


class _Probe(Observer):
    """Makes the calls a broken host would, once, in the middle of a run."""

    def __init__(self) -> None:
        self.raised: dict[str, BaseException] = {}

    def on_step(self, sim) -> None:
        if self.raised:
            return
        unit = sim.slaves["cylinder"]
        real_in = unit.vr("rod.velocity")
        for label, call in (
            ("unknown reference", unit.reader("Real", [10**6])),
            ("short list", lambda: unit.writer([real_in, real_in])([1.0])),
        ):
            try:
                call()
            except Exception as exc:  # noqa: BLE001 - what it raises is the point
                self.raised[label] = exc


def test_a_failing_call_names_the_unit_and_a_wrong_length_is_refused(tmp_path, fmu_dir):
    probe = _Probe()
    _run("riser_tensioner", tmp_path / "probe", fmu_dir, observers=[probe])
    failed = probe.raised["unknown reference"]
    assert isinstance(failed, UnitFailedError)
    assert "'cylinder'" in str(failed) and "1000000" in str(failed)
    assert isinstance(probe.raised["short list"], ValueError)


def test_a_call_after_the_unit_is_freed_says_so(tmp_path, fmu_dir):
    outcome = run_scene(
        "riser_tensioner", tmp_path / "freed", plots=False, fmu_dir=fmu_dir, stop_time=0.008
    )
    unit = outcome.simulation.slaves["rope"]  # terminated and freed at the run's end
    for call in (unit.reader("Real", [0]), lambda: unit.writer([0])([1.0])):
        with pytest.raises(UnitFailedError, match="'rope' is not instantiated"):
            call()
    with pytest.raises(UnitFailedError, match="'rope' is not instantiated"):
        unit.do_step(0.0, 0.004)

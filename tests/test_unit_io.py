"""The master's end-of-step reads: sources, mode markers and watched values from one read."""

from __future__ import annotations

from array import array
from types import SimpleNamespace

import numpy as np
import pytest

from wire_fmu.master.unit_io import EndValues, Watch, read_plan

_VARIABLES = {  # name: (FMI type, value reference)
    "force": ("Real", 1),
    "velocity": ("Real", 2),
    "stroke": ("Real", 3),
    "pressure": ("Real", 4),
    "mode_change_time": ("Real", 5),
    "mode_changes": ("Integer", 6),
    "brake.state": ("Integer", 7),
}


class _Unit:
    """A stand-in for a Slave: its variables' values, read the ways the master reads them."""

    def __init__(self) -> None:
        self.variables = {
            name: SimpleNamespace(type=kind, valueReference=ref)
            for name, (kind, ref) in _VARIABLES.items()
        }
        self.values = {ref: 0.0 for _, ref in _VARIABLES.values()}
        self.calls = 0

    def set_time(self, t: float) -> None:
        for kind, ref in _VARIABLES.values():
            self.values[ref] = int(10 * t) if kind == "Integer" else t * ref + 0.1

    def reader(self, kind, refs):
        def read():
            self.calls += 1
            return [self.values[r] for r in refs]

        return read

    def packed_reader(self, refs):
        read = self.reader("Real", refs)
        return lambda: array("d", read()).tobytes()

    def get(self, names):
        return {name: self.values[self.variables[name].valueReference] for name in names}


def _plan(unit, watch=None, mode="mode_change_time"):
    keys, refs = ["u.force", "u.velocity"], [1, 2]
    return read_plan("u", unit, keys, refs, mode, [watch] if watch else [])


def test_the_sources_and_the_mode_marker_come_from_one_read():
    unit = _Unit()
    unit.set_time(0.7)
    end = _plan(unit).read()
    into = {"other.x": 3.0}
    end.add_sources(into)
    assert into == {"other.x": 3.0, "u.force": 0.7 * 1 + 0.1, "u.velocity": 0.7 * 2 + 0.1}
    assert end.mode == 0.7 * 5 + 0.1
    assert unit.calls == 1
    counted = _plan(unit, mode="mode_changes").read()
    assert counted.mode == 7 and isinstance(counted.mode, int)
    assert unit.calls == 3  # the Reals, then the Integers


@pytest.mark.parametrize("names", [["stroke", "force", "pressure"], ["pressure", "brake.state"]])
def test_watched_values_unpack_alike_one_read_at_a_time_and_many_at_once(names):
    unit = _Unit()
    watch = Watch({"u": names}, lambda t: True)
    plan = _plan(unit, watch)
    taken = []
    for t in (0.0, 0.25, 1.5, 2.0):
        unit.set_time(t)
        end = plan.read()
        assert watch.unpack("u", end) == [unit.get(names)[n] for n in names]
        assert watch.take("u", unit, end) is end  # kept, not read again
        taken.append(end)
    taken.append(watch.take("u", unit, None))  # no end-of-step read: read now
    assert type(taken[-1]) is list
    rows = watch.unpack_rows("u", taken)
    expected = np.array([watch.unpack("u", t) for t in taken], dtype=float)
    assert rows.shape == (5, len(names))
    assert rows.tobytes() == expected.tobytes()
    assert watch.unpack_rows("u", taken[:-1]).tobytes() == expected[:-1].tobytes()


def test_reads_of_different_lengths_are_not_joined_as_one_array():
    unit = _Unit()
    watch = Watch({"u": ["pressure"]}, lambda t: True)
    unit.set_time(1.0)
    wide = _plan(unit, watch).read()
    longer = EndValues(wide.plan, wide.reals + array("d", [9.5]).tobytes(), wide.others, None)
    rows = watch.unpack_rows("u", [wide, longer, wide])
    pressure = watch.unpack("u", wide)[0]
    assert rows[:, 0].tolist() == [pressure, pressure, pressure]

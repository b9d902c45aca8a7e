"""The master's batched set of a unit's inputs: which value goes to which input.

A unit's links are taken in :func:`~wire_fmu.master.unit_io.input_order` (held
constant, positions, ramped by source, extrapolated), and
:meth:`~wire_fmu.master.exchange.UnitExchange.set_inputs` must send each value to its
own value reference and hold it as the extrapolation says: checked here against
:func:`~wire_fmu.master.extrapolation.held_value` and
:func:`~wire_fmu.master.extrapolation.ramp` called by hand.
"""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from wire_fmu.master.exchange import UnitExchange
from wire_fmu.master.extrapolation import History, held_value, ramp
from wire_fmu.master.scene.data import RAMP_ROLE, Connection, VarRef
from wire_fmu.master.unit_io import InputPlan, Link, input_order

_T, _H = 0.3, 0.01


def _link(source: str, target: str, role: str, scheme: str, vr: int, histories) -> Link:
    connection = Connection(VarRef("src", source), VarRef("u", target), role=role, bond="b")
    ramp_kind = {"flow": "start", RAMP_ROLE: "slope"}.get(role, "")
    link = Link(connection, f"src.{source}", vr, scheme, ramp=ramp_kind)
    if link.extrapolated:
        link.history = histories.setdefault(link.key, History())
    return link


def _links(histories):
    # interleaved on purpose: two ramped sources, a position, a constant, an extrapolated
    return [
        _link("v1", "rate_1", "flow", "linear", 10, histories),
        _link("x1", "position_1", "position", "linear", 11, histories),
        _link("v2", "acceleration_2", RAMP_ROLE, "linear", 12, histories),
        _link("f", "force", "effort", "constant", 13, histories),
        _link("v1", "acceleration_1", RAMP_ROLE, "linear", 14, histories),
        _link("s", "signal", "signal", "quadratic", 15, histories),
        _link("v2", "rate_2", "flow", "linear", 16, histories),
        _link("x2", "position_2", "position", "linear", 17, histories),
        _link("v1", "rate_1b", "flow", "linear", 18, histories),  # v1: two starts, a loop
    ]


def _latest(histories):
    latest = {"src.f": 4.0, "src.x1": 0.25, "src.x2": -0.5}
    for key, value in {"src.v1": 1.5, "src.v2": -2.0, "src.s": 7.0}.items():
        history = histories[key]
        for i, t in enumerate((_T - 2 * _H, _T - _H, _T)):
            history.push(t, value + 0.1 * i * value + 0.03 * i * i)
        latest[key] = history.latest
    return latest


def test_the_order_groups_links_by_kind_and_ramped_source():
    histories: dict[str, History] = {}
    ordered = input_order(_links(histories))
    assert [link.target for link in ordered] == [
        "u.force",
        "u.position_1",
        "u.position_2",
        "u.rate_1",
        "u.rate_1b",
        "u.acceleration_1",
        "u.rate_2",
        "u.acceleration_2",
        "u.signal",
    ]
    assert input_order(ordered) == ordered


def test_a_plan_refuses_links_out_of_order():
    links = tuple(_links({}))
    with pytest.raises(ValueError, match="input_order"):
        InputPlan(links, (), [], True, False, print, {})


@pytest.mark.parametrize("fresh", [None, {"src.v2": -1.75, "src.s": 7.5}])
def test_each_input_gets_its_own_value(fresh):
    histories: dict[str, History] = {}
    links = input_order(_links(histories))
    latest = _latest(histories)
    sent: list[list[float]] = []
    plan = InputPlan(
        links, (), [link.target_vr for link in links], True, False, sent.append, latest
    )
    exchange = SimpleNamespace(
        _ends={}, _inputs={"u": plan}, held={}, latest=latest, slaves={"u": None}
    )
    UnitExchange.set_inputs(exchange, "u", _T, _H, fresh)

    def given(key):
        return None if fresh is None else fresh.get(key)

    start_1, slope_1 = ramp(histories["src.v1"], _T, _H, "linear", given("src.v1"))
    start_2, slope_2 = ramp(histories["src.v2"], _T, _H, "linear", given("src.v2"))
    signal = held_value(histories["src.s"], _T, _H, "quadratic", given("src.s"))
    expected = {  # value reference: (value sent, value held over the step)
        13: (4.0, 4.0),
        11: (0.25, 0.25),
        17: (-0.5, -0.5),
        10: (start_1, start_1 + 0.5 * slope_1 * _H),
        18: (start_1, start_1 + 0.5 * slope_1 * _H),
        14: (slope_1, slope_1),
        16: (start_2, start_2 + 0.5 * slope_2 * _H),
        12: (slope_2, slope_2),
        15: (signal, signal),
    }
    assert len(sent) == 1
    assert dict(zip(plan.refs, sent[0], strict=True)) == {r: v for r, (v, _) in expected.items()}
    by_vr = {link.target_vr: link.target for link in links}
    assert exchange.held == {by_vr[r]: held for r, (_, held) in expected.items()}
    assert slope_2 != 0.0 and start_2 != latest["src.v2"]  # the ramp is not trivially held
    assert [source.pair is None for source in plan.ramps] == [True, False]

"""The shared compiled loop evaluates each state once: derivative and guards together.

The loop (:func:`~wire_fmu.core.framework.compiled_step.advance_to_event`) is run as
plain Python (``NUMBA_DISABLE_JIT=1``, in a child process) over ``x' = -x`` with one
guard, with kernel functions that count their calls. An RK4 step of ``x' = -x``
multiplies the state by ``R(h) = 1 - h + h^2/2 - h^3/6 + h^4/24``: the closed form the
states are held to.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import textwrap

import pytest
from scipy.optimize import brentq

_CHILD = textwrap.dedent(
    """
    import json, sys
    from collections import Counter
    import numpy as np
    from wire_fmu.core.framework import compiled_step as cs

    calls = Counter()

    def rhs(t, x, data):
        calls["rhs"] += 1
        return -x

    def guards(t, x, data):
        calls["guards"] += 1
        return np.array([x[0] - data[0]])

    def rhs_guards(t, x, data):
        calls["rhs_guards"] += 1
        return -x, np.array([x[0] - data[0]])

    def project(x, data):
        return x

    runs = []
    for t1, n, level in json.loads(sys.argv[1]):
        calls.clear()
        status, x, t, k, fired, steps, rhs_calls, h = cs.advance_to_event(
            rhs, guards, rhs_guards, project, cs.COMPILED_METHODS["rk4"], 0.0, t1, n, 0,
            0.0, np.array([1.0]), np.array([-1.0]), 1e-12, (level,)
        )
        runs.append(dict(status=int(status), x=float(x[0]), t=float(t), steps=int(steps),
                         calls=dict(calls)))
    print(json.dumps(runs))
    """
)


def _run(cases: list[tuple[float, int, float]]) -> list[dict]:
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    done = subprocess.run(
        [sys.executable, "-c", _CHILD, json.dumps(cases)],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
        check=True,
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def _rk4_factor(h: float) -> float:
    return 1.0 - h + h**2 / 2.0 - h**3 / 6.0 + h**4 / 24.0


@pytest.fixture(scope="module")
def runs() -> list[dict]:
    # quiet runs of 1, 2 and 5 internal steps, then one whose guard fires in its first
    return _run([(0.5, 1, 0.1), (1.0, 2, 0.1), (1.0, 5, 0.1), (4.0, 4, 0.5)])


@pytest.mark.parametrize(("index", "t1", "n"), [(0, 0.5, 1), (1, 1.0, 2), (2, 1.0, 5)])
def test_a_quiet_step_evaluates_each_state_once(runs, index, t1, n):
    run = runs[index]
    assert run["status"] == 0 and run["steps"] == n
    # the start and every step's end but the last: derivative and guards together
    assert run["calls"] == {"rhs_guards": n, "rhs": 3 * n, "guards": 1}
    assert run["x"] == pytest.approx(_rk4_factor(t1 / n) ** n, rel=1e-14)


def test_event_location_reuses_the_first_stage(runs):
    run = runs[3]
    assert run["status"] == 1  # an event, in the first of four steps of 1 s
    trials = run["steps"] - 1
    assert trials >= 3
    # the first stage at the step's start is evaluated once for the step and every trial
    assert run["calls"] == {"rhs_guards": 2, "rhs": 3 * run["steps"], "guards": trials}
    # located where the RK4 step from the start reaches the guard's level
    crossing = brentq(lambda h: _rk4_factor(h) - 0.5, 0.0, 1.0, xtol=1e-15)
    assert run["t"] == pytest.approx(crossing, abs=1e-9)
    assert run["x"] == pytest.approx(_rk4_factor(run["t"]), rel=1e-12)
    assert run["x"] <= 0.5 + 1e-9
    assert math.isclose(crossing, math.log(2.0), rel_tol=0.01)  # and near the exact ln 2

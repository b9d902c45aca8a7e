"""How many internal steps a fixed-step loop takes over a communication step."""

from __future__ import annotations

import pytest

from wire_fmu.core.framework.step_limits import (
    MAX_INTERNAL_STEPS,
    IntegrationError,
    internal_step_count,
)


@pytest.mark.parametrize(
    ("t0", "t1", "max_step", "count"),
    [
        (0.0, 0.07, 0.01, 7),  # 0.07 / 0.01 is 7.000000000000001 in floating point
        (0.0, 0.0041, 0.001, 5),  # a part of a step is a whole one
        (0.3, 0.7, 0.1, 4),  # 0.4 / 0.1 a hair under 4 in floating point
        (1.0, 1.0 + 1e-6, 0.001, 1),  # at least one
        (2.0, 2.0, 0.001, 1),  # an empty step, too
    ],
)
def test_the_count_is_the_span_over_the_largest_step_rounded_up(t0, t1, max_step, count):
    assert internal_step_count(t0, t1, max_step) == count


def test_a_step_too_long_is_refused_with_the_longest_step_it_may_take():
    with pytest.raises(IntegrationError, match=r"at most 100 s"):
        internal_step_count(0.0, 1000.0, 100.0 / MAX_INTERNAL_STEPS)

"""The block train's structured Jacobian and bordered band solve (issue 16: linear cost).

ROS2 takes the block train's Jacobian from a few coloured evaluations and solves
``(I - g h J)`` as a band with the blocks as its border
(:mod:`~wire_fmu.core.units.block_train.kernel_jacobian`,
:mod:`~wire_fmu.core.framework.bordered_band`). These tests hold it to the plain
forward-difference Jacobian of every state and to numpy's dense solve, in stuck and
sliding friction modes, and check that the structure's size per state does not grow
with the number of lines -- what makes the step's cost linear.
"""

from __future__ import annotations

import numpy as np
import pytest

from wire_fmu.core.framework import bordered_band
from wire_fmu.core.framework.fixed_step import finite_difference_jacobian
from wire_fmu.core.units.block_train.reevings import drilling_block_train, riser_tensioner

from .block_train_helpers import make_unit, run

ALL_PLANAR = "rope_damping,sheave_inertia,bearing_friction,rope_slip,moving_geometry"
FIXED = "rope_damping,sheave_inertia,bearing_friction,rope_slip"


def lowered(lines: int, effects: str, duration: float = 0.3):
    """A drilling block train with ``lines`` lines, lowered at 0.5 m/s for ``duration`` s."""

    def lower(t, unit):
        unit.values["line_a.payout_rate"] = -0.5

    unit = make_unit(drilling_block_train(lines), effects, initial_equilibrium=True, solver="ros2")
    run(unit, duration, 0.01, lower)
    return unit.model, duration


def structured_and_dense(model, t: float) -> tuple[np.ndarray, np.ndarray]:
    """The structured Jacobian in state order (the ledgers' rows from its tail), and the
    forward-difference one."""
    x = model.state.copy()
    s = model.kernel_jacobian_structure
    jac, _ = model.linear_algebra().linearise(t, x)
    structured = np.zeros((x.size, x.size))
    structured[np.ix_(s[1], s[1])] = bordered_band.to_dense(jac, s)
    structured[np.ix_(np.arange(s[0][5], x.size), s[1])] = jac[4]
    return structured, finite_difference_jacobian(model, t, x)


def assert_rows_agree(structured: np.ndarray, dense: np.ndarray, rel: float) -> None:
    """Every row agrees to ``rel`` of that row's largest entry."""
    scale = np.max(np.abs(dense), axis=1) + 1e-300
    worst = np.max(np.abs(structured - dense), axis=1) / scale
    assert np.all(worst <= rel), f"row {int(np.argmax(worst))} differs by {worst.max():.3g}"


@pytest.mark.parametrize("effects", [ALL_PLANAR, FIXED, "rope_damping,sheave_inertia"])
@pytest.mark.parametrize("lines", [2, 6, 12])
def test_coloured_jacobian_is_the_forward_difference_one(lines, effects):
    """Each entry agrees with one column differenced alone, to 1e-8 of its row -- the
    energy ledgers' rows too -- while links stick and slide (both modes present) and
    the block moves."""
    model, t = lowered(lines, effects)
    structured, dense = structured_and_dense(model, t)
    assert np.count_nonzero(dense[:-2]) > 3 * model.n_coords  # coupled, not diagonal
    assert np.count_nonzero(dense[-2:]) > model.n_coords  # the ledgers feel every state
    assert_rows_agree(structured, dense, 1e-8)
    if "bearing_friction" in effects:
        modes = set(model.friction.mode.tolist())
        assert 0 in modes and modes & {-1, 1}, modes


def test_the_comparison_can_fail():
    """A colouring that puts two neighbouring rope coordinates together is caught."""
    model, t = lowered(6, FIXED)
    structure = list(model.kernel_jacobian_structure)
    start = structure[3].copy()
    start[1] += 1  # the first member of colour 1 joins colour 0
    structure[3] = start
    model.kernel_jacobian_structure = tuple(structure)
    structured, dense = structured_and_dense(model, t)
    with pytest.raises(AssertionError, match="differs by"):
        assert_rows_agree(structured, dense, 1e-8)


def test_riser_tensioner_jacobian_without_a_border():
    """The riser's rope between a driven rod and a driven ring: no block, so no border;
    the moving bodies enter through the held inputs only."""
    unit = make_unit(
        riser_tensioner(),
        "rope_damping,sheave_inertia,bearing_friction,moving_geometry",
        initial_equilibrium=False,
        pretension=5.0e5,
        solver="ros2",
    )

    def heave(t, unit):
        unit.values["mover_b.velocity"] = 0.5

    run(unit, 0.2, 0.01, heave)
    assert unit.model.kernel_jacobian_structure[0][1] == 0
    structured, dense = structured_and_dense(unit.model, 0.2)
    assert_rows_agree(structured, dense, 1e-8)


@pytest.mark.parametrize("gh", [1e-4, 1e-3, 3e-2])
def test_bordered_band_solve_is_numpys(gh):
    """``(I - gh J)^-1 b`` by the bordered band elimination equals numpy's dense solve."""
    model, t = lowered(8, ALL_PLANAR)
    s = model.kernel_jacobian_structure
    jac, _ = model.linear_algebra().linearise(t, model.state)
    fac = bordered_band.factor(jac, gh, s)
    assert fac[4].size == 0, "the band elimination itself must be tested"
    b = np.random.default_rng(1).normal(size=model.state.size)
    w = np.eye(s[0][5]) - gh * bordered_band.to_dense(jac, s)
    expected = b.copy()
    expected[s[1]] = np.linalg.solve(w, b[s[1]])
    expected[s[0][5] :] += gh * jac[4] @ expected[s[1]]  # the ledgers: [-gh tail, I]
    np.testing.assert_allclose(bordered_band.solve(fac, b, s), expected, rtol=1e-10, atol=1e-12)


def test_a_vanishing_pivot_falls_back_to_the_dense_inverse():
    """A band whose first pivot ``1 - gh J[0, 0]`` is zero is solved densely, correctly."""
    sizes = np.array([3, 1, 1, 1, 0, 4], dtype=np.int64)
    order = np.arange(4, dtype=np.int64)
    s = (sizes, order, order.copy())
    band = np.array([[0.0, 10.0, 1.0], [2.0, 3.0, 1.0], [1.0, 1.0, 0.0]])
    cols, rows, corner = np.ones((3, 1)), np.ones((1, 3)), np.array([[2.0]])
    tail = np.zeros((0, 4))
    gh = 0.1
    fac = bordered_band.factor((band, cols, rows, corner, tail), gh, s)
    assert fac[4].shape == (4, 4)
    w = np.eye(4) - gh * bordered_band.to_dense((band, cols, rows, corner), s)
    b = np.array([1.0, -2.0, 0.5, 3.0])
    np.testing.assert_allclose(bordered_band.solve(fac, b, s), np.linalg.solve(w, b), rtol=1e-12)


def test_structure_per_state_does_not_grow_with_the_lines():
    """Colours (evaluations per Jacobian) and band widths are the same from 4 to 32 lines:
    a Jacobian costs a fixed number of evaluations and the solve a fixed number of
    operations per state."""
    seen = set()
    for lines in (4, 8, 16, 32):
        model = make_unit(drilling_block_train(lines), ALL_PLANAR, solver="ros2").model
        sizes = model.kernel_jacobian_structure[0]
        assert sizes[0] + sizes[1] == 2 * model.n_coords
        seen.add((int(sizes[1]), int(sizes[2]), int(sizes[3]), int(sizes[4])))
    assert len(seen) == 1, seen
    nb, kl, ku, colours = seen.pop()
    assert kl <= 8 and ku <= 8 and colours <= 12

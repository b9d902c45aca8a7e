"""Convergence orders of the study's families, and their costs at equal error.

See the accuracy study (:mod:`wire_fmu.study.accuracy`, "Families, orders,
equal error") for what is fitted and compared.

The asymptotic range
--------------------
An order is a slope fitted where the error behaves like ``C H^p``: over a
family's runs in the *asymptotic range* (:func:`asymptotic_runs`), the
longest stretch of consecutive macro steps (no failed or skipped run in
between) in which

* each run finished with an error at most :data:`ASYMPTOTIC_LIMIT` (a
  larger error is the pre-asymptotic, or blown-up, regime);
* each error is above :data:`DOMINANCE` times the solver's own error and
  above the reference's own (below them the solver or the reference, not
  the coupling, sets the error); the solver's own error is the monolithic
  model's with that solver, unless a run of the family is more accurate
  than that (the estimate is then no floor and is not used, and the row
  says so);
* the error decreases monotonically as the step decreases (an error that
  grows as the step halves is no convergence at all: a transient the runs
  resolve differently, a kink, a plateau).

With fewer than :data:`MIN_ASYMPTOTIC_RUNS` runs in that range no order is
fitted: two points always lie on a line, and the table says "not fitted (n
runs in the asymptotic range)" instead of a number.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from wire_fmu.master.scene import Scene
from wire_fmu.master.scene.data import INTERFACE_ROLE, RAMP_ROLE

from .measures import RunRow
from .plan import coupled_scene

__all__ = [
    "THEORY",
    "ASYMPTOTIC_LIMIT",
    "DOMINANCE",
    "MIN_ASYMPTOTIC_RUNS",
    "OrderRow",
    "asymptotic_runs",
    "not_fitted",
    "theoretical_order",
    "observed_orders",
    "EqualErrorRow",
    "default_targets",
    "equal_error",
]

THEORY = {"constant": 1, "linear": 2, "quadratic": 2}
"""Order of a held effort or signal per extrapolation (SPEC section 15)."""

ASYMPTOTIC_LIMIT = 0.3
"""Runs with a larger error (a fraction of the output's range) are not asymptotic."""

DOMINANCE = 4.0
"""A run counts for the order only if its error is this many times the solver's floor."""

MIN_ASYMPTOTIC_RUNS = 3
"""Fewest runs in the asymptotic range an order is fitted on."""


# --------------------------------------------------------------------- orders
@dataclass
class OrderRow:
    """Observed convergence order of one family."""

    family: str
    algorithm: str
    extrapolation: str
    solver: str
    theory: int | None
    observed: float
    points: int
    steps_used: tuple[float, ...] = ()
    note: str = ""


def theoretical_order(scene: Scene, extrapolation: str) -> int | None:
    """Order the coupling of ``scene`` should show with ``extrapolation`` (SPEC section 15).

    Position links of a bond are exact at every step start; the flow of such
    a bond is integrated into that position, so its hold costs one order
    less than an effort's: second order even held constant. The effort of a
    bond whose interface model is wired, and the model's links, are second
    order too: the flow side integrates against the effort's first-order
    expansion in position, velocity and time about the step's start. Every
    other held input (efforts, plain signals) has :data:`THEORY`'s order.
    None when nothing is held (no connections).

    Parameters
    ----------
    scene : Scene
        The scene; its connections and bonds say what is held.
    extrapolation : str
        The scheme of the connections that do not set their own.
    """
    with_position = {b.name for b in scene.bonds if b.position is not None}
    modelled = {b.name for b in scene.interface_bonds}
    orders = []
    for c in scene.all_connections:
        if c.role == "position":
            continue
        scheme = c.extrapolation or extrapolation
        if c.role in ("flow", RAMP_ROLE) and c.bond in with_position:
            orders.append(2)
        elif c.bond in modelled and c.role in ("effort", INTERFACE_ROLE):
            orders.append(2)  # the effort's first-order model in x, v and t over the step
        else:
            orders.append(THEORY[scheme])
    return min(orders) if orders else None


def _slope(steps: Sequence[float], errors: Sequence[float]) -> float:
    x, y = np.log(np.asarray(steps)), np.log(np.asarray(errors))
    return float(np.polyfit(x, y, 1)[0])


def asymptotic_runs(runs: Sequence[RunRow], floor: float) -> list[RunRow]:
    """A family's runs in the asymptotic range (module docstring), largest step first.

    The longest stretch of consecutive runs (by decreasing macro step) that
    are usable, have an error in ``(floor, ASYMPTOTIC_LIMIT]`` and whose error
    decreases at every step; of two as long, the one at smaller steps.

    Parameters
    ----------
    runs : sequence of RunRow
        The family's co-simulation runs (any order).
    floor : float
        Errors at or below it are the solver's or the reference's own.
    """
    ordered = sorted((r for r in runs if math.isfinite(r.step)), key=lambda r: -r.step)
    best: list[RunRow] = []
    stretch: list[RunRow] = []
    for r in ordered:
        if not (r.usable and floor < r.error <= ASYMPTOTIC_LIMIT):
            stretch = []
            continue
        stretch = stretch + [r] if stretch and r.error < stretch[-1].error else [r]
        if len(stretch) >= len(best):
            best = stretch
    return best


def not_fitted(points: int) -> str:
    """``"not fitted (2 runs in the asymptotic range)"``.

    Parameters
    ----------
    points : int
        Runs in the asymptotic range.
    """
    return f"not fitted ({points} run{'' if points == 1 else 's'} in the asymptotic range)"


def observed_orders(rows: Sequence[RunRow], scene: Scene, min_error: float = 0.0) -> list[OrderRow]:
    """The order of every family over its runs in the asymptotic range.

    Parameters
    ----------
    rows : sequence of RunRow
        Every run of the study, the monolithic ones (the solvers' floors)
        included.
    scene : Scene
        The study scene (for the theoretical orders).
    min_error : float
        Errors at or below it are the reference's own (the study passes 100
        times the reference's tolerance); a fraction of the outputs' range.
    """
    floors = {
        r.solver: r.error for r in rows if r.family == f"monolithic / {r.solver}" and r.usable
    }
    out = []
    for family, runs in _families(rows).items():
        first = runs[0]
        if first.algorithm == "monolithic":
            continue
        own, remark = _solver_floor(runs, floors.get(first.solver, 0.0))
        floor = max(DOMINANCE * own, min_error)
        kept = asymptotic_runs(runs, floor)
        order = OrderRow(
            family,
            first.algorithm,
            first.extrapolation,
            first.solver,
            theoretical_order(coupled_scene(scene, first.coupling), first.extrapolation),
            math.nan,
            len(kept),
            tuple(r.step for r in kept),
            remark,
        )
        if len(kept) < MIN_ASYMPTOTIC_RUNS:
            order.note = "; ".join(
                filter(
                    None,
                    [
                        f"{not_fitted(len(kept))}: at least {MIN_ASYMPTOTIC_RUNS} consecutive "
                        f"steps with errors decreasing between {floor:.2g} and "
                        f"{ASYMPTOTIC_LIMIT:g} are needed",
                        remark,
                    ],
                )
            )
        else:
            order.observed = _slope([r.step for r in kept], [r.error for r in kept])
        out.append(order)
    return out


def _solver_floor(runs: Sequence[RunRow], own: float) -> tuple[float, str]:
    """The solver's own error, unless the family's runs contradict it (then 0, and why).

    The monolithic model solved with a unit's solver estimates that solver's
    own error on the scene. A co-simulation run with a smaller error shows
    that the estimate is no floor for these runs (one solver over the whole
    stiff system is not the units' solvers each over its own part); the
    monotone decrease of the errors then says where coupling dominates.
    """
    reached = min((r.error for r in runs if r.usable and r.error > 0.0), default=math.inf)
    if own <= reached:
        return own, ""
    return 0.0, (
        f"the monolithic model with this solver (error {own:.2g}) is no floor here: "
        f"co-simulation runs reach {reached:.2g}"
    )


def _families(rows: Sequence[RunRow]) -> dict[str, list[RunRow]]:
    out: dict[str, list[RunRow]] = defaultdict(list)
    for r in rows:
        out[r.family].append(r)
    for runs in out.values():
        runs.sort(
            key=lambda r: (
                -r.step if math.isfinite(r.step) else 0.0,
                -r.error if math.isfinite(r.error) else 0.0,
            )
        )
    return dict(out)


# ---------------------------------------------------------------- equal error
@dataclass
class EqualErrorRow:
    """Cost of each family at one target error, and the cheapest."""

    target: float
    costs: dict[str, float]
    cheapest: str
    cheapest_cost: float

    def reached(self) -> int:
        """How many families reach the target."""
        return sum(1 for c in self.costs.values() if math.isfinite(c))


def _cost_at(runs: Sequence[RunRow], target: float) -> float:
    """Wall per simulated second at ``target`` error, interpolated log-log along the family."""
    points = [(r.error, r.wall_per_sim_s) for r in runs if r.usable and r.wall_per_sim_s > 0]
    points.sort(key=lambda p: -p[0])  # from large error (cheap) to small
    previous = None
    for error, cost in points:
        if error <= target:
            if previous is None or previous[0] <= error:
                return cost
            e0, c0 = previous
            w = (math.log(target) - math.log(e0)) / (math.log(error) - math.log(e0))
            return math.exp(math.log(c0) + w * (math.log(cost) - math.log(c0)))
        previous = (error, cost)
    return math.inf


def default_targets(rows: Sequence[RunRow], count: int = 4) -> list[float]:
    """Decades between the largest and the smallest achieved error (at most ``count``).

    Parameters
    ----------
    rows : sequence of RunRow
        The study's runs; only usable ones count.
    count : int
        Most targets.
    """
    errors = [r.error for r in rows if r.usable and r.error > 0]
    if not errors:
        return []
    top = math.floor(math.log10(max(errors)))
    bottom = math.log10(min(errors))
    return [10.0**k for k in range(top, top - count, -1) if k >= bottom]


def equal_error(rows: Sequence[RunRow], targets: Sequence[float]) -> list[EqualErrorRow]:
    """For each target error: every family's interpolated cost and the cheapest family.

    Parameters
    ----------
    rows : sequence of RunRow
        The study's runs.
    targets : sequence of float
        Target errors (fractions of the outputs' range).
    """
    families = _families(rows)
    out = []
    for target in targets:
        costs = {name: _cost_at(runs, target) for name, runs in families.items()}
        finite = {k: v for k, v in costs.items() if math.isfinite(v)}
        cheapest = min(finite, key=finite.get) if finite else ""
        out.append(EqualErrorRow(target, costs, cheapest, finite.get(cheapest, math.inf)))
    return out

"""Convergence orders of the study's families, and their costs at equal error.

See the accuracy study (:mod:`wire_fmu.study.accuracy`, "Families, orders,
equal error") for what is fitted and compared.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from wire_fmu.master.scene import Scene

from .measures import RunRow

__all__ = [
    "THEORY",
    "ASYMPTOTIC_LIMIT",
    "DOMINANCE",
    "OrderRow",
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
    less than an effort's: second order even held constant. Every other
    held input (efforts, plain signals) has :data:`THEORY`'s order. None
    when nothing is held (no connections).

    Parameters
    ----------
    scene : Scene
        The scene; its connections and bonds say what is held.
    extrapolation : str
        The scheme of the connections that do not set their own.
    """
    with_position = {b.name for b in scene.bonds if b.position is not None}
    orders = []
    for c in scene.all_connections:
        if c.role == "position":
            continue
        scheme = c.extrapolation or extrapolation
        if c.role == "flow" and c.bond in with_position:
            orders.append(2)
        else:
            orders.append(THEORY[scheme])
    return min(orders) if orders else None


def _slope(steps: Sequence[float], errors: Sequence[float]) -> float:
    x, y = np.log(np.asarray(steps)), np.log(np.asarray(errors))
    return float(np.polyfit(x, y, 1)[0])


def observed_orders(rows: Sequence[RunRow], scene: Scene, min_error: float = 0.0) -> list[OrderRow]:
    """The order of every family over its runs where coupling error dominates.

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
        floor = max(DOMINANCE * floors.get(first.solver, 0.0), min_error)
        kept = [r for r in runs if r.usable and floor < r.error <= ASYMPTOTIC_LIMIT]
        theory = theoretical_order(scene, first.extrapolation)
        if len(kept) < 2:
            note = (
                f"{len(kept)} run(s) with an error between {DOMINANCE:g} x the solver's own "
                f"error and {ASYMPTOTIC_LIMIT:g}: not measurable"
            )
            out.append(
                OrderRow(
                    family,
                    first.algorithm,
                    first.extrapolation,
                    first.solver,
                    theory,
                    math.nan,
                    len(kept),
                    note=note,
                )
            )
            continue
        observed = _slope([r.step for r in kept], [r.error for r in kept])
        out.append(
            OrderRow(
                family,
                first.algorithm,
                first.extrapolation,
                first.solver,
                theory,
                observed,
                len(kept),
                tuple(r.step for r in kept),
            )
        )
    return out


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

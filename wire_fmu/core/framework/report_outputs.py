"""A unit's outputs copied from its model's report, with the energy ledger booked once.

A model that answers ``report()`` with one object holding every output
quantity at an instant needs no assignment per output in its unit. The
report's fields are named after the unit's output variables, dots written
as underscores (output ``drum.speed``, field ``drum_speed``), and include
``stored_energy``, ``dissipated_energy`` and ``external_work`` (J). The unit
builds a :class:`ReportOutputs` from its output declarations once and calls
:meth:`ReportOutputs.publish`, which also books the ledger outputs the same
way for every such unit: ``energy_balance`` (stored change + dissipated -
external work, J; zero while the books close) and ``mode_changes``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, MutableMapping
from dataclasses import dataclass, field
from operator import attrgetter
from typing import Any

from wire_fmu.core.framework.tuple_getter import tuple_getter
from wire_fmu.core.framework.unit import MODE_CHANGE_TIME, Causality, Variable

__all__ = ["ReportOutputs", "LEDGER_OUTPUTS"]

LEDGER_OUTPUTS = (
    "stored_energy",
    "dissipated_energy",
    "external_work",
    "energy_balance",
    "mode_changes",
)
"""Outputs :meth:`ReportOutputs.publish` books from the ledger, not copied field by field."""


@dataclass(frozen=True)
class ReportOutputs:
    """Which report field feeds which output variable, and which outputs must be finite.

    Parameters
    ----------
    fields : tuple of (str, str)
        ``(output variable, report field)`` pairs, copied as they are.
    finite : tuple of str
        Output variables that must be finite once written; a non-finite one
        raises :class:`FloatingPointError`.
    """

    fields: tuple[tuple[str, str], ...]
    finite: tuple[str, ...] = ()
    _names: tuple[str, ...] = field(init=False, repr=False, compare=False)
    _take: Callable[[Any], tuple] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        # the copy of every field in C (attrgetter): publish runs after every step
        names = tuple(name for name, _ in self.fields)
        take = tuple_getter(attrgetter, [f for _, f in self.fields])
        object.__setattr__(self, "_names", names)
        object.__setattr__(self, "_take", take)

    @classmethod
    def of(cls, variables: Iterable[Variable], finite: tuple[str, ...] = ()) -> ReportOutputs:
        """Every declared output but the ledger's, each from its report field.

        Parameters
        ----------
        variables : iterable of Variable
            The unit's declarations; only outputs are used.
        finite : tuple of str
            Output variables that must be finite.

        Returns
        -------
        ReportOutputs
            Output ``a.b`` copied from report field ``a_b``.
        """
        names = [
            v.name
            for v in variables
            if v.causality is Causality.output
            and v.name not in LEDGER_OUTPUTS
            and v.name != MODE_CHANGE_TIME  # the unit base writes it after each step
        ]
        return cls(tuple((name, name.replace(".", "_")) for name in names), finite)

    def publish(
        self,
        values: MutableMapping[str, Any],
        report: Any,
        initial_energy: float,
        mode_changes: int,
        who: str,
    ) -> None:
        """Write the report's fields and the energy ledger into ``values``.

        Parameters
        ----------
        values : mutable mapping
            The unit's variable values, by name.
        report : object
            The model's report: every field of :attr:`fields`, and
            ``stored_energy``, ``dissipated_energy``, ``external_work`` (J).
        initial_energy : float
            Stored energy at the start of the ledger, J.
        mode_changes : int
            Mode events so far.
        who : str
            The unit, for the message of a non-finite output.

        Raises
        ------
        FloatingPointError
            If an output named in :attr:`finite` is not finite (all are written first).
        """
        # one value per name by construction (_take gets the fields _names are copied from)
        values.update(zip(self._names, self._take(report)))  # noqa: B905
        values["stored_energy"] = report.stored_energy
        values["dissipated_energy"] = report.dissipated_energy
        values["external_work"] = report.external_work
        values["energy_balance"] = (
            report.stored_energy - initial_energy + report.dissipated_energy - report.external_work
        )
        values["mode_changes"] = int(mode_changes)
        if not all(map(math.isfinite, map(values.__getitem__, self.finite))):
            raise FloatingPointError(f"{who}: non-finite outputs")

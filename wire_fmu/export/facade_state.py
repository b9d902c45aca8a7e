"""A facade's FMU state: saved as JSON data, checked and restored (fmi2Get/SetFMUstate).

:class:`FacadeState` is the part of :class:`~wire_fmu.export.facade.CoreFacade`
that answers ``fmi2GetFMUstate`` with the unit's full ``get_state()`` plus every
variable value and the facade's phase and times, as JSON data tagged
:data:`STATE_FORMAT`, and restores such a state (refusing, with a logged message,
one of another format, unit or set of variables).
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Mapping
from typing import Any

from wire_fmu.core.framework.unit import Causality
from wire_fmu.export.facade_calls import FacadeError, Phase, fmi_entry
from wire_fmu.export.state import json_copy

__all__ = ["STATE_FORMAT", "FacadeState"]

STATE_FORMAT = "wire_fmu.fmu_state/1"
"""Tag of the FMU state layout written by :meth:`FacadeState._get_fmu_state`."""


class FacadeState:
    """Getting, checking and setting the FMU state (a mixin of the facade).

    The facade provides ``unit``, ``instance_name``, ``_phase``, ``_start_time``,
    ``_time``, ``_reconfigure``, ``_inputs_changed``, ``_unit_class``,
    ``_rebuild_unit`` and ``_report``.
    """

    @fmi_entry("fmi2GetFMUstate")
    def _get_fmu_state(self) -> dict[str, Any]:
        settled = self._phase in (Phase.step, Phase.terminated)
        raw = {
            "format": STATE_FORMAT,
            "unit": self.unit.NAME,
            "phase": self._phase.value,
            "start_time": self._start_time,
            "time": self._time,
            "reconfigure": self._reconfigure,
            "inputs_changed": self._inputs_changed,
            "values": self.unit.values,
            "core": self.unit.get_state() if settled else None,
        }
        try:
            return json_copy(raw)
        except (TypeError, ValueError) as exc:
            raise FacadeError(
                f"FMU state is not JSON-compatible ({exc}); {type(self.unit).__name__}"
                ".get_state() and unit.values must hold JSON data"
            ) from exc

    @fmi_entry("fmi2SetFMUstate")
    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        self._check_state(state)
        values = copy.deepcopy(state["values"])
        phase = Phase(state["phase"])
        if phase is Phase.instantiated:
            self.unit = self._unit_class()(instance_name=self.instance_name)
            self.unit.values.update(values)
        elif phase is Phase.initialization:
            self._rebuild_unit(values)
        else:
            if self._needs_configure(values):
                self._rebuild_unit(values)
            self.unit.values.update(values)
            self.unit.set_state(copy.deepcopy(state["core"]))
            self.unit.values.update(values)  # exactly the saved outputs
        self._phase = phase
        self._start_time = float(state["start_time"])
        self._time = float(state.get("time", self._start_time))
        self._reconfigure = bool(state["reconfigure"])
        self._inputs_changed = bool(state["inputs_changed"])

    @staticmethod
    def _fmu_state_from_bytes(state: bytes) -> dict[str, Any]:
        # Unreadable bytes become a state that _set_fmu_state refuses with a
        # logged message (fmi2SetFMUstate), so deserialising never fails.
        try:
            return json.loads(state.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            return {"format": None, "unreadable": f"not a serialised wire_fmu state ({exc})"}

    def _needs_configure(self, values: Mapping[str, Any]) -> bool:
        if self._phase not in (Phase.step, Phase.terminated):
            return True
        names = [v.name for v in self.unit.VARIABLES if v.causality is Causality.parameter]
        return any(self.unit.values[n] != values[n] for n in names)

    def _check_state(self, state: Any) -> None:
        if not isinstance(state, dict) or state.get("format") != STATE_FORMAT:
            reason = state.get("unreadable", "") if isinstance(state, dict) else ""
            raise FacadeError(f"not an FMU state of format {STATE_FORMAT!r} {reason}".strip())
        if state.get("unit") != self.unit.NAME:
            raise FacadeError(
                f"the FMU state belongs to unit {state.get('unit')!r}, not {self.unit.NAME!r}"
            )
        times = [state.get("start_time"), state.get("time", state.get("start_time"))]
        if not all(isinstance(t, int | float) and math.isfinite(t) for t in times):
            raise FacadeError(f"the FMU state's times {times} are not finite numbers")
        expected = {v.name for v in self.unit.VARIABLES}
        if set(state["values"]) != expected:
            raise FacadeError("the FMU state's variables differ from this FMU's variables")

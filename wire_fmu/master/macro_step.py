"""One macro step: the sweeps, their iteration, the bonds' energy, rejection and rollback.

:class:`MacroStep` is the part of :class:`~wire_fmu.master.simulation.Simulation`
that takes one macro step and decides on it: the coupling algorithm's sweep
(repeated from saved FMU states with ``iterations > 1`` until the inputs stop
changing), the bonds' energy residuals (:mod:`~wire_fmu.master.bond_energy`),
the rollback of a refused, non-finite or (``adaptive``) rejected step, the
acceptance that advances the histories and books the energy, and the next
step's size (:mod:`~wire_fmu.master.step_size`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .bond_energy import step_energy
from .run_result import SimulationStoppedError
from .step_size import _PI, _ns, new_h
from .unit_errors import StepRefusedError

__all__ = ["MacroStep", "MODE_CHANGE_TIME", "SYNC_RESOLUTION_NS"]

MODE_CHANGE_TIME = "mode_change_time"
"""The output a unit tells the time of its first mode change inside the last step by, s."""
SYNC_RESOLUTION_NS = 1000
"""A mode change closer than this to either end of a step is not synchronised to (1 us)."""


@dataclass
class _Attempt:
    """One try at a macro step."""

    accepted: bool
    residuals: dict[str, float]
    sweeps: int
    new: dict[str, float] = field(default_factory=dict)
    retry_step: float = 0.0
    message: str = ""
    event_end_ns: int | None = None  # a unit's mode changed here: step everyone to it


class MacroStep:
    """Taking, judging, accepting and rolling back a macro step (a mixin of the simulation).

    The simulation provides ``scene``, ``run_settings``, ``slaves``, ``algorithm``,
    ``energy``, ``latest``, ``histories``, ``held``, ``bond_power``, ``mode_marks``,
    ``mode_markers``, ``source_keys``, ``time``, ``_bond_keys``, ``_error_prev``,
    ``_reads``, ``_ends``, ``_build_plans``, ``_keep_sources`` and ``_mode_mark``.
    """

    def _save(self):
        return {name: s.get_state() for name, s in self.slaves.items()}

    def _restore(self, states) -> None:
        self._ends.clear()
        for name, state in states.items():
            self.slaves[name].set_state(state)

    def _free(self, states) -> None:
        for name, state in states.items():
            self.slaves[name].free_state(state)

    def _sweep_iterated(self, t: float, h: float, states) -> tuple[dict[str, float], int]:
        new = self.algorithm.sweep(self, t, h)
        sweeps, changes = 1, []
        for _ in range(self.run_settings.iterations - 1):
            if not all(map(math.isfinite, new.values())):
                return new, sweeps  # never handed on: the caller rejects the step
            before = dict(self.held)
            self._restore(states)
            new = self.algorithm.sweep(self, t, h, fresh=new)
            sweeps += 1
            changes.append(
                max(
                    (
                        abs(self.held[k] - before.get(k, 0.0)) / max(1.0, abs(self.held[k]))
                        for k in self.held
                    ),
                    default=0.0,
                )
            )
            if changes[-1] < self.run_settings.iteration_tolerance:
                return new, sweeps
        if len(changes) >= 3 and changes[-1] > changes[0]:  # the fixed point runs away
            raise SimulationStoppedError(
                f"t = {t:.6g} s: the iteration over the step of {h:.3g} s diverges (input "
                f"change {changes[0]:.3g} after the second sweep, {changes[-1]:.3g} after the "
                f"last of {sweeps}): the coupling cannot be resolved at this step; use a "
                "smaller step or adaptive steps"
            )
        return new, sweeps

    def bond_residuals(self, new: dict[str, float], h: float) -> dict[str, float]:
        """Energy each bond's coupling created over the step just taken, J.

        Parameters
        ----------
        new : dict of str to float
            Source outputs (``"unit.variable"``) at the end of the step.
        h : float
            The step just taken, s.

        Returns
        -------
        dict of str to float
            The energy residual by bond name, J (positive: created).
        """
        out = {}
        latest, held, power = self.latest, self.held, self.bond_power
        for keys in self._bond_keys:
            out[keys.name], power[keys.name] = step_energy(keys, latest, held, new, h)
        return out

    def _attempt(self, t: float, h: float) -> _Attempt:
        """Take one macro step, rolling back when it is refused or rejected."""
        if not self._reads:  # planned once, after the observers' watches
            self._build_plans()
        s = self.run_settings
        rollback = s.iterations > 1 or s.adaptive or s.synchronise_events
        states = self._save() if rollback else None
        try:
            if states is not None:
                new, sweeps = self._sweep_iterated(t, h, states)
            else:
                new, sweeps = self.algorithm.sweep(self, t, h), 1
        except StepRefusedError as exc:
            if states is None:
                raise SimulationStoppedError(str(exc)) from None
            self._restore(states)
            self._free(states)
            return _Attempt(False, {}, 0, retry_step=new_h(h, 4.0), message=str(exc))
        if not all(map(math.isfinite, new.values())):  # never accepted, never recorded
            bad = ", ".join(
                f"{key} = {value!r}" for key, value in new.items() if not math.isfinite(value)
            )
            message = f"t = {t:.6g} s: after the step of {h:.3g} s, {bad}"
            if states is None:
                raise SimulationStoppedError(
                    f"{message}: not finite; the run stops here, "
                    "everything before is kept; try a smaller step"
                )
            self._restore(states)
            self._free(states)
            return _Attempt(False, {}, sweeps, retry_step=new_h(h, 4.0), message=message)
        if s.synchronise_events:
            event_end_ns = self._first_mode_change_ns(t, h)
            if event_end_ns is not None:
                self._restore(states)
                self._free(states)
                message = f"a mode changed at t = {event_end_ns / 1e9:.9g} s"
                return _Attempt(False, {}, sweeps, message=message, event_end_ns=event_end_ns)
        residuals = self.bond_residuals(new, h)
        if self.run_settings.adaptive:
            error = max((abs(r) for r in residuals.values()), default=0.0)
            error /= self.run_settings.energy_tolerance
            if error > 1.0 and h > self.run_settings.min_step * (1 + 1e-9):
                self._restore(states)
                self._free(states)
                return _Attempt(
                    False,
                    residuals,
                    sweeps,
                    retry_step=new_h(h, error),
                    message=f"bond energy residual {error:.3g} x tolerance",
                )
            if error > 1.0:
                self._free(states)
                raise SimulationStoppedError(
                    f"t = {t:.6g} s: the bonds' energy residual is {error:.3g} times "
                    f"energy_tolerance even at the minimum step {h:.3g} s: the coupling "
                    "cannot meet the tolerance; lower min_step or raise energy_tolerance"
                )
        if states is not None:
            self._free(states)
        return _Attempt(True, residuals, sweeps, new)

    def _first_mode_change_ns(self, t: float, h: float) -> int | None:
        """End (ns) of the step that places the earliest mode change inside ``(t, t + h)``.

        Units that tell when their mode changes
        (:data:`~wire_fmu.core.framework.unit.MODE_CHANGE_TIME`, which moves in exactly
        the steps where their ``mode_changes`` does) are asked; None when no
        such change lies more than :data:`SYNC_RESOLUTION_NS` inside the step. The end
        is rounded up to the nanosecond, so that stepping to it takes the change in.
        """
        start_ns, end_ns = _ns(t), _ns(t + h)
        earliest = None
        for name, before in self.mode_marks.items():
            if self.mode_markers[name] != MODE_CHANGE_TIME:  # a counter tells no time
                continue
            when = float(self._mode_mark(name))  # the unit's mode_change_time
            if when == before or not math.isfinite(when):
                continue
            candidate = math.ceil(when * 1e9 - 1e-3)  # a change at the step's start is older
            inside = start_ns + SYNC_RESOLUTION_NS <= candidate <= end_ns - SYNC_RESOLUTION_NS
            if inside and (earliest is None or candidate < earliest):
                earliest = candidate
        return earliest

    def _accept(self, t: float, h: float, new: dict[str, float], residuals) -> None:
        self._keep_sources(new, t + h)
        switched = set()
        for name, before in self.mode_marks.items():
            now = self._mode_mark(name)
            if now != before:
                switched.add(name)
                self.mode_marks[name] = now
                for key in self.source_keys.get(name, ()):
                    if key in self.histories:
                        self.histories[key].reset()
        across = (
            {
                b.name
                for b in self.scene.bonds
                if b.effort.source.unit in switched or b.flow.source.unit in switched
            }
            if switched
            else ()
        )
        self.energy.book(residuals, self.bond_power, h, across_events=across)
        self.time = t + h

    def _next_step(self, h: float, residuals) -> float:
        s = self.run_settings
        if not s.adaptive:
            return s.step
        error = max((abs(r) for r in residuals.values()), default=0.0) / s.energy_tolerance
        error = max(error, 1e-10)
        factor = _PI["safety"] * error ** -_PI["k_i"] * (self._error_prev / error) ** _PI["k_p"]
        self._error_prev = error
        factor = min(_PI["grow"], max(_PI["shrink"], factor))
        return min(s.max_step or math.inf, max(s.min_step, h * factor))

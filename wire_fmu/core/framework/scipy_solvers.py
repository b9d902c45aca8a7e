"""SciPy's adaptive solvers for hybrid systems, restarted at every event.

``radau``, ``bdf``, ``lsoda``, ``rk45`` and ``dop853`` of
:data:`wire_fmu.core.framework.hybrid.SOLVERS`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from wire_fmu.core.framework.step_limits import (
    MAX_EVENTS_PER_STEP,
    IntegrationError,
    internal_steps,
)

if TYPE_CHECKING:
    from wire_fmu.core.framework.hybrid import SolverSettings

__all__ = ["ScipySolver"]


class ScipySolver:
    """SciPy's ``solve_ivp`` per communication step, restarted at events.

    Like the fixed-step solvers, an event is taken just *after* the crossing
    (the dense output of the last step, ``event_time_tolerance`` past the
    located root), so the guard that fired is past its zero when the mode
    switches and cannot fire again at the restart.
    """

    def __init__(self, settings: SolverSettings, method: str) -> None:
        self.settings = settings
        self.method = method
        self.rhs_calls = 0
        self.steps = 0

    def advance(self, system, t0, x0, t1):
        """Integrate from ``t0`` to ``t1``; return the state and the number of events.

        Parameters
        ----------
        system : HybridSystem
            The model.
        t0 : float
            Start time, s.
        x0 : ndarray
            State at ``t0``.
        t1 : float
            End time, s.
        """
        from scipy.integrate import solve_ivp  # here: most runs never need it (0.1 s to import)

        internal_steps(t0, t1, self.settings.max_step)
        tol = self.settings.event_time_tolerance
        t, x = t0, np.array(x0, dtype=float)
        events = 0
        while t < t1 - tol:
            sol = solve_ivp(
                system.rhs,
                (t, t1),
                x,
                method=self.method,
                rtol=self.settings.rtol,
                atol=self.settings.atol,
                max_step=self.settings.max_step,
                events=self._event_functions(system) or None,
                dense_output=True,
            )
            self.rhs_calls += sol.nfev
            self.steps += max(0, sol.t.size - 1)
            if sol.status == -1:
                raise IntegrationError(f"{self.method}: {sol.message}")
            if sol.status == 0:
                return system.project(sol.y[:, -1]), events
            times = {i: float(te[0]) for i, te in enumerate(sol.t_events) if te.size}
            t_root = min(times.values())
            fired = [i for i, te in times.items() if te <= t_root + tol]
            t = min(t_root + tol, t1)
            x_after = sol.sol(t)
            if not np.all(np.isfinite(x_after)):
                raise IntegrationError(f"{self.method}: non-finite state at an event, t = {t}")
            events += 1
            if events > MAX_EVENTS_PER_STEP:
                raise IntegrationError(f"more than {MAX_EVENTS_PER_STEP} events in one step")
            x = system.handle_events(t, x_after, fired)
        return x, events

    @staticmethod
    def _event_functions(system):
        directions = system.guard_directions()
        cache: dict = {}

        def guards(t, x):
            """The system's guards at ``(t, x)``, computed once per point for all event functions.

            Parameters
            ----------
            t : float
                Time, s.
            x : ndarray
                Continuous state of the model.
            """
            key = (t, x.tobytes())
            if cache.get("key") != key:
                cache["key"], cache["g"] = key, system.guards(t, x)
            return cache["g"]

        functions = []
        for i, direction in enumerate(directions):

            def event(t, x, i=i):
                """Guard ``i`` at ``(t, x)`` for ``solve_ivp``, a zero read as ``+0``.

                Parameters
                ----------
                t : float
                    Time, s.
                x : ndarray
                    Continuous state of the model.
                i : int
                    The guard.
                """
                # our guards hold while >= 0 and fire when < 0; SciPy would also fire on
                # a guard resting at exactly 0 (a released brake), so a zero counts as +0
                g = guards(t, x)[i]
                return g if g != 0.0 else 1e-300

            event.terminal = True
            event.direction = float(direction)
            functions.append(event)
        return functions

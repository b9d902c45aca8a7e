"""The block train's modes: rope spans slack or taut, blocks on their floors, sheaves and
grooves stuck or slipping, spans broken; their guards, switches and projections.

:class:`ModeSwitching` is the part of
:class:`~wire_fmu.core.units.block_train.model.BlockTrainModel` that locates and
switches modes (the hybrid protocol's ``guards``, ``handle_events``, ``project``).
"""

from __future__ import annotations

import numpy as np

from wire_fmu.core.components.rope import slack_guard, taut_guard
from wire_fmu.core.units.block_train import kernel

__all__ = ["ModeSwitching"]


class ModeSwitching:
    """Guards, mode switches and projection of a block train (a mixin of the model)."""

    def _guard_directions(self) -> np.ndarray:
        n_links = len(self.friction.links)
        dirs = [-1] * n_links + [0] * len(self.spans) + [0] * len(self.blocks)
        dirs += [-1] * len(self.spans)
        return np.array(dirs, dtype=float)

    def guard_directions(self) -> np.ndarray:
        """See :class:`~wire_fmu.core.framework.hybrid.HybridSystem`."""
        return self._guard_dirs

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """Friction links, slack/taut ropes, floor contact, rope break (all fire below 0).

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[q, v, dissipated, external work]`` (m, m/s, J, J).

        Returns
        -------
        numpy.ndarray
            Guard values: friction links, then rope spans (slack/taut), floors and
            breaking loads (N).
        """
        if self.compiled:
            return kernel.guards(t, x, self.kernel_data())
        n = self.n_coords
        ev = self.evaluate(t, x)
        caps = self._capacities(ev["tension"])
        _, link_force = self.friction.accelerations(ev["forces"], caps)
        g_links = self.friction.guards(x[n : 2 * n], link_force, caps)
        rf = ev["rope"]
        g_rope = np.where(self.taut_mask, taut_guard(rf), slack_guard(rf))
        g_rope = np.where(self.broken_mask, 1.0, g_rope)
        stiffness = np.array([b.floor.stiffness if b.floor else 0.0 for b in self.blocks])
        g_floor = np.where(
            self.contact_mask,
            ev["trial_contact"],
            np.maximum(-stiffness * ev["depth"], -ev["trial_contact"]),
        )
        g_floor = np.where(stiffness > 0.0, g_floor, 1.0)
        breaking = self.rope.breaking_load - ev["tension"]
        breaking = np.where(np.isfinite(breaking), breaking, 1.0)
        return np.concatenate([g_links, g_rope, g_floor, breaking])

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Switch friction, slack/taut and contact modes; break ropes.

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[q, v, dissipated, external work]`` (m, m/s, J, J).
        fired : list of int
            Indices of the guards that fired at ``t`` (order of :meth:`guards`).

        Returns
        -------
        numpy.ndarray
            The state after the switches, projected; a broken span's strain energy is
            booked as dissipated.
        """
        self.first_event_time = min(self.first_event_time, t)
        n_links = len(self.friction.links)
        n_spans = len(self.spans)
        x = np.array(x, dtype=float)
        link_fired = [i for i in fired if i < n_links]
        first_break = n_links + n_spans + len(self.blocks)
        for i in fired:
            if i >= first_break:
                self._break_span(i - first_break, x, t)
            elif i >= n_links + n_spans:
                j = i - n_links - n_spans
                self.contact_mask[j] = not self.contact_mask[j]
                what = "lands on" if self.contact_mask[j] else "lifts off"
                self.last_events.append(f"block {self.blocks[j].name!r} {what} its floor")
            elif i >= n_links:
                k = i - n_links
                self.taut_mask[k] = not self.taut_mask[k]
                what = "taut" if self.taut_mask[k] else "slack"
                self.last_events.append(f"rope span {k} {what}")
        x = self._settle_modes(t, x, link_fired)
        self.mode_changes += 1
        return self.project(x)

    def _settle_contact_modes(self, t: float, x: np.ndarray) -> bool:
        """After inputs jump: make slack/taut and floor modes fit (t, x); True if any changed."""
        changed = False
        for _ in range(len(self.spans) + len(self.blocks) + 1):
            g = self.guards(t, x)
            n_links = len(self.friction.links)
            g_modes = g[n_links : n_links + len(self.spans) + len(self.blocks)]
            wrong = np.flatnonzero(g_modes < 0.0)
            if wrong.size == 0:
                break
            self.handle_events(t, x, [int(i) + n_links for i in wrong[:1]])
            self.mode_changes -= 1  # counted once by the caller
            changed = True
        return changed

    def _settle_modes(self, t: float, x: np.ndarray, fired: list[int] | None = None):
        """Make the friction modes consistent with the forces at (t, x)."""
        if not self.friction.links:
            return x
        n = self.n_coords
        x = np.array(x, dtype=float)
        ev = self.evaluate(t, x)
        caps = self._capacities(ev["tension"])
        before = self.friction.get_mode()
        x[n : 2 * n] = self.friction.switch(x[n : 2 * n], ev["forces"], caps, fired or [])
        changed = False
        for k, (old, new) in enumerate(zip(before, self.friction.get_mode(), strict=True)):
            if old != new:
                changed = True
                state = "stuck" if new == 0 else "sliding"
                self.last_events.append(f"{self.friction.links[k].name} {state}")
        if changed and fired is None:
            self.mode_changes += 1
        self._held_positions = x[:n].copy()
        return self.project(x)

    def _break_span(self, i: int, x: np.ndarray, t: float) -> None:
        if self.broken[i]:
            return
        released = self.evaluate(t, x)["span_energy"][i]
        self.broken_mask[i] = True
        x[2 * self.n_coords] += released  # the strain energy is released and lost
        self.last_events.append(f"rope span {i} broke")

    def project(self, x: np.ndarray) -> np.ndarray:
        """Hold coordinates stuck to the ground exactly where they stuck, at rest.

        Parameters
        ----------
        x : numpy.ndarray
            State ``[q, v, dissipated, external work]``, changed in place.

        Returns
        -------
        numpy.ndarray
            ``x``.
        """
        if self.friction.links:
            held = self.friction.stuck_to_ground()
            if held.size:
                x[held] = self._held_positions[held]
                x[self.n_coords + held] = 0.0
        return x

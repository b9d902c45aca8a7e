"""The block train's initial state: rope coordinates, static equilibrium, modes at the start.

:class:`StartingState` is the part of
:class:`~wire_fmu.core.units.block_train.model.BlockTrainModel` that sets it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from wire_fmu.core.errors import ConfigurationError

if TYPE_CHECKING:
    from wire_fmu.core.units.block_train.model import BlockTrainInputs

__all__ = ["START_TENSION_TOLERANCE", "StartingState"]


START_TENSION_TOLERANCE = 1e-3
"""Largest relative difference between the starting tension asked for and the one the
spans carry once their unstretched lengths are set (round-off in a rope of realistic
stiffness leaves about 1e-13)."""


class StartingState:
    """Initial state of a block train (a mixin of the model)."""

    def initialize(
        self, t0: float, inputs: BlockTrainInputs, *, equilibrium: bool, pretension: float
    ) -> float:
        """Set the rope's unstretched lengths and the state at rest.

        With ``equilibrium`` and at least one block, the rope is stretched so
        that every block hangs at rest where the reeving puts it; otherwise
        every span starts at ``pretension`` (N). Returns the initial tension.

        Parameters
        ----------
        t0 : float
            Start time, s.
        inputs : BlockTrainInputs
            Inputs at ``t0``.
        equilibrium : bool
            Stretch the rope so that the blocks hang at rest.
        pretension : float
            Tension of every span without ``equilibrium`` (or without blocks), N.

        Returns
        -------
        float
            The initial rope tension, N.

        Raises
        ------
        ConfigurationError
            If no single rope tension holds every block at rest.
        """
        self.set_inputs(t0, inputs)
        self.state = np.zeros(2 * self.n_coords + 2)
        self.broken = [False] * len(self.spans)
        nb = len(self.blocks)
        held = self.held_parts()
        y = np.concatenate((np.zeros(nb), held.mover_positions))
        big_l, dl_dy = self.span_lengths(y)
        tension = pretension
        if equilibrium and self.blocks:
            tension = self._equilibrium_tension(dl_dy)
        ea = self.rope.axial_stiffness
        flow = np.concatenate((self.q, held.line_positions))
        self.offsets = big_l * ea / (ea + tension) - self.flow_matrix @ flow
        self._check_start_tension(big_l, flow, tension)
        self._check_breaking_load(tension)
        self.taut_mask = np.full(len(self.spans), tension > 0.0)
        self.contact_mask = np.array(
            [b.floor is not None and b.position < b.floor.position for b in self.blocks], dtype=bool
        )
        self.friction.set_mode([0] * len(self.friction.links))
        self.state = self._settle_modes(t0, self.state, [])
        self.preload_kernel(t0)
        return tension

    def _check_start_tension(self, big_l: np.ndarray, flow: np.ndarray, tension: float) -> None:
        """Refuse a start whose spans do not carry ``tension`` (N) once the unstretched
        lengths are set: a rope so stiff that the strain ``tension / EA`` is lost to the
        round-off of the span lengths (about 1e-16 of them).

        Each span's tension is worked out as the kernels do, from its length ``big_l`` (m)
        and its unstretched length (the offsets and the line ends' ``flow``, m).
        """
        if not tension > 0.0:
            return
        ea = self.rope.axial_stiffness
        small_l = self.offsets + self.flow_matrix @ flow
        carried = ea * ((big_l - small_l) / small_l)
        worst = float(np.max(np.abs(carried - tension))) / tension
        if worst > START_TENSION_TOLERANCE:
            raise ConfigurationError(
                "block train",
                [
                    f"starting tension {tension:.6g} N: its strain in a rope of "
                    f"'axial_stiffness' {ea:.6g} N, {tension / ea:.3g}, is below what the span "
                    f"lengths resolve, so the spans would start at {float(carried.min()):.6g} N; "
                    "give the rope a stiffness it has (steel wire rope: about 1e7 to 1e9 N) or "
                    "the start a larger tension (the pretension, or with initial_equilibrium the "
                    "blocks' weight)"
                ],
            )

    def _check_breaking_load(self, tension: float) -> None:
        """Refuse a start at or above the rope's breaking load: a span breaks when its
        tension rises through the breaking load, which a span that starts above it never
        does, so such a rope would carry any load unbroken.

        Parameters
        ----------
        tension : float
            The starting tension of every span, N.
        """
        breaking = self.rope.breaking_load
        if tension >= breaking:
            raise ConfigurationError(
                "block train",
                [
                    f"starting tension {tension:.6g} N is at or above the rope's "
                    f"'breaking_load' {breaking:.6g} N: the rope would break at the start; give "
                    "it a breaking load above the starting tension (the pretension, or with "
                    "initial_equilibrium the blocks' weight per line) or start with less"
                ],
            )

    def _equilibrium_tension(self, dl_dy: np.ndarray) -> float:
        gravity = np.array(self.reeving.gravity)
        needed = []
        for j, block in enumerate(self.blocks):
            lift = -float(dl_dy[:, j].sum())  # rope force on the block per newton of tension
            weight = block.mass * float(gravity @ np.array(block.direction))
            if lift <= 0.0:
                raise ConfigurationError(
                    "block train",
                    [f"block {block.name!r} hangs on no rope: it cannot start in equilibrium"],
                )
            needed.append((block.name, -weight / lift))
        tensions = [t for _, t in needed]
        if max(tensions) - min(tensions) > 1e-9 * max(1.0, max(abs(t) for t in tensions)):
            listed = ", ".join(f"{n!r} needs {t:.6g} N" for n, t in needed)
            raise ConfigurationError(
                "block train",
                [
                    f"initial_equilibrium: no single rope tension holds every block ({listed}); "
                    "set initial_equilibrium false or change the masses"
                ],
            )
        if tensions[0] < 0.0:
            raise ConfigurationError(
                "block train",
                [
                    f"initial_equilibrium: block {needed[0][0]!r} would need the rope to push "
                    f"({tensions[0]:.6g} N)"
                ],
            )
        return tensions[0]

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

__all__ = ["StartingState"]


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
        self.taut_mask = np.full(len(self.spans), tension > 0.0)
        self.contact_mask = np.array(
            [b.floor is not None and b.position < b.floor.position for b in self.blocks], dtype=bool
        )
        self.friction.set_mode([0] * len(self.friction.links))
        self.state = self._settle_modes(t0, self.state, [])
        self.preload_kernel(t0)
        return tension

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

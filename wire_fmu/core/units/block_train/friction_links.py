"""The block train's friction links: sheave bearings and rope on grooves that stick.

:class:`FrictionLinks` is the part of
:class:`~wire_fmu.core.units.block_train.model.BlockTrainModel` that builds the
:class:`~wire_fmu.core.components.friction.StickSlip` links the effects
``bearing_friction`` and ``rope_slip`` call for, their parameters as flat arrays
for the compiled kernel, and their holding capacities from the span tensions.
"""

from __future__ import annotations

import math

import numpy as np

from wire_fmu.core.components.friction import GROUND, FrictionLink, StickSlip

__all__ = ["FrictionLinks"]


class FrictionLinks:
    """Bearing and groove friction links (a mixin of the model)."""

    def _build_friction(self) -> None:
        links = []
        self.link_kind: list[tuple[str, int]] = []
        if "bearing_friction" in self.effects:
            for k, idx in self.rim_index.items():
                links.append(FrictionLink(f"sheave {self.nodes[k].name!r} bearing", idx, GROUND))
                self.link_kind.append(("bearing", k))
        if "rope_slip" in self.effects:
            for k, idx in self.rope_index.items():
                name = f"rope on sheave {self.nodes[k].name!r}"
                links.append(FrictionLink(name, idx, self.rim_index[k]))
                self.link_kind.append(("groove", k))
        self.friction = StickSlip(self.masses, tuple(links))
        sheaves = self.reeving.sheaves
        self._bearing_c = np.zeros(len(links))
        self._bearing_m0 = np.zeros(len(links))
        self._capstan = np.zeros(len(links))
        for i, (kind, k) in enumerate(self.link_kind):
            s = sheaves[self.nodes[k].name]
            if kind == "bearing":
                self._bearing_m0[i] = s.bearing_torque / s.radius
                self._bearing_c[i] = (1.0 - s.efficiency) / (1.0 + s.efficiency)
            else:
                self._capstan[i] = math.expm1(s.groove_friction * self.wrap_angles[k])
        self._link_span_in = np.array(
            [self.span_of_segment[k - 1] for _, k in self.link_kind], dtype=int
        )
        self._link_span_out = np.array(
            [self.span_of_segment[k] for _, k in self.link_kind], dtype=int
        )
        self.kernel_link_index = np.array(
            [
                (link.body, link.other, self._link_span_in[i], self._link_span_out[i])
                for i, link in enumerate(links)
            ],
            dtype=np.int64,
        ).reshape(len(links), 4)
        self.kernel_link_params = np.column_stack(
            (self._bearing_m0, self._bearing_c, self._capstan)
        ).reshape(len(links), 3)

    def _capacities(self, tension: np.ndarray) -> np.ndarray:
        t_in, t_out = tension[self._link_span_in], tension[self._link_span_out]
        return (
            self._bearing_m0
            + self._bearing_c * (t_in + t_out)
            + self._capstan * np.minimum(t_in, t_out)
        )

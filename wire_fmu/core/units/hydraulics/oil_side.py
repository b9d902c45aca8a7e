"""The oil between the accumulator's gas and the cylinder's chamber, for the effects chosen.

Four forms, one chosen when the model is built: incompressible oil with a
lossless line (the chamber at the gas pressure), incompressible oil with line
losses, compressible oil with a lossless massless line (oil and gas in
parallel at one pressure), and compressible oil in the chamber with the line
(losses, inertance) between it and the gas. Each gives the chamber pressure,
the line flow, the line's loss and the energy in oil and line.
:class:`OilSide` is that part of
:class:`~wire_fmu.core.units.hydraulics.model.HydraulicsModel`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["OIL_LOSSLESS_RIGID", "OIL_ONE_NODE", "OIL_RIGID", "OIL_TWO_NODES", "OilSide"]

OIL_LOSSLESS_RIGID, OIL_RIGID, OIL_ONE_NODE, OIL_TWO_NODES = 0, 1, 2, 3
"""The four forms, as codes: incompressible oil with a lossless line, with line losses;
compressible oil with a lossless massless line (one pressure node), with the line between
chamber and gas (two pressure nodes)."""


class OilSide:
    """The oil side's equations (a mixin of the model, which provides the layout and sizes)."""

    def oil_form(self) -> int:
        """Which of the four forms the effects chosen give, as an ``OIL_*`` code."""
        if not self.compressible:
            return OIL_RIGID if self.losses else OIL_LOSSLESS_RIGID
        if self.layout.chamber_pressure < 0:
            return OIL_ONE_NODE
        return OIL_TWO_NODES

    def _choose_oil_side(self):
        """The oil side's equations for the effects chosen (chosen once, at build).

        Each gives, at a state, the chamber pressure (Pa), the line flow (m^3/s), the line's
        loss (W) and the energy stored in oil and line (J).
        """
        forms = {
            OIL_LOSSLESS_RIGID: self._lossless_rigid_column,
            OIL_RIGID: self._rigid_column,
            OIL_ONE_NODE: self._one_pressure_node,
            OIL_TWO_NODES: self._two_pressure_nodes,
        }
        return forms[self.oil_form()]

    def _lossless_rigid_column(self, x: np.ndarray, vel: float, v_gas: float, p_g: float):
        """Incompressible oil, lossless line: the chamber is at the gas pressure."""
        return p_g, self.sa * vel, 0.0, 0.0

    def _rigid_column(self, x: np.ndarray, vel: float, v_gas: float, p_g: float):
        """Incompressible oil: the line's drop at the rod's flow."""
        flow = self.sa * vel
        drop = (self.r_l + self.r_t * abs(flow)) * flow
        return p_g - drop, flow, drop * flow, 0.0

    def _one_pressure_node(self, x: np.ndarray, vel: float, v_gas: float, p_g: float):
        """Compressible oil with a lossless, massless line: oil and gas in parallel."""
        c_gas = v_gas / (self.exponent * p_g)
        flow = self.sa * vel * c_gas / (c_gas + self.compliance)
        return p_g, flow, 0.0, 0.5 * self.compliance * p_g * p_g

    def _two_pressure_nodes(self, x: np.ndarray, vel: float, v_gas: float, p_g: float):
        """Compressible oil in the chamber, the line between it and the gas (losses, mass)."""
        lay = self.layout
        p_c = float(x[lay.chamber_pressure])
        stored = 0.5 * self.compliance * p_c * p_c
        if lay.flow >= 0:
            flow = float(x[lay.flow])
            stored += 0.5 * self.inertance * flow * flow
        else:
            flow = self.line.flow(p_g - p_c)
        drop = (self.r_l + self.r_t * abs(flow)) * flow
        return p_c, flow, drop * flow, stored

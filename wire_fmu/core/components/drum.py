"""Rope on a winch drum: winding radius per layer and the drum's I(phi).

Angles and signs
----------------
The drum angle ``phi`` (rad) counts rotation in the *paying-out* sense
from the start, so the rope paid out is a growing function of ``phi``.
The rope on the drum is described by its *wound angle* ``theta`` (rad,
total angle of rope wrapped on the barrel): ``theta = theta0 - phi``.

Layers (effect ``rope_layers``)
-------------------------------
Layer ``k`` (0-based) holds ``wraps_per_layer`` turns, i.e. the wound
angle ``theta`` in ``[k Theta, (k + 1) Theta]`` with
``Theta = 2 pi wraps_per_layer``, at the winding radius (rope centreline)

    r_k = radius + k d            (d: rope diameter, one diameter per layer)

Layer-change rule: the rope steps onto the next layer when a layer is
full, at once (the crossover/riser at the flange, a fraction of a turn in
Lebus grooving, is neglected). So the radius is piecewise constant in
``phi``, the rope length on the drum is piecewise linear and continuous,
and the fast-line speed ``r(phi) omega`` steps by ``r_{k+1}/r_k`` at a
layer change while ``omega`` does not jump.

The rope on the drum adds ``rho r_k^2`` per metre (``rho`` linear mass,
kg/m) to the drum's inertia, so ``I(phi) = J + rho sum r_j^3 theta_j``
(``theta_j`` the wound angle on layer ``j``) -- paper 004's variable reduced
inertia, continuous in ``phi`` with slope ``dI/dphi = -rho r_k^3`` on
layer ``k``. Rope that leaves the drum keeps its kinetic energy inside the
drum's ``I(phi) omega^2 / 2`` (the conservative Lagrangian of a variable
reduced inertia), since the block train's rope is massless.

Without layers (:class:`Drum`) the radius is ``radius`` everywhere, the rope
adds no inertia and there are no layer edges; the effect ``rope_layers``
builds a :class:`LayeredDrum` instead. A winch asks its drum, never a flag.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import ClassVar

import numpy as np

__all__ = ["Drum", "LayeredDrum"]

_NO_GUARDS = np.zeros(0)


@dataclass(frozen=True)
class Drum:
    """A drum that winds its rope in one layer: constant radius, no rope inertia.

    Parameters
    ----------
    radius : float
        Rope centreline radius, m.
    """

    radius: float

    layer_guard_count: ClassVar[int] = 0
    """Guards :meth:`layer_guards` gives: none, the rope never changes layer."""

    @property
    def max_layers(self) -> int:
        """Layers the drum holds: one."""
        return 1

    def layer_radius(self, k: int) -> float:
        """Winding radius, m: ``radius`` on every layer.

        Parameters
        ----------
        k : int
            The layer (only 0 occurs).
        """
        return self.radius

    def initial_layer(self) -> int:
        """The layer the rope leaves from at the start: 0."""
        return 0

    def phi_bounds(self, k: int) -> tuple[float, float]:
        """Drum angles between which layer ``k`` is the outer one: all, rad.

        Parameters
        ----------
        k : int
            The layer (only 0 occurs).
        """
        return -math.inf, math.inf

    def layer_guards(self, phi: float, k: int) -> np.ndarray:
        """The layer's edge guards at drum angle ``phi``: none.

        Parameters
        ----------
        phi : float
            Drum angle, rad.
        k : int
            The outer layer.
        """
        return _NO_GUARDS

    def payout(self, phi: float, k: int) -> float:
        """Rope paid out at drum angle ``phi``, m (0 at ``phi = 0``).

        Parameters
        ----------
        phi : float
            Drum angle since the start, rad (positive paying out).
        k : int
            The layer the rope leaves from.
        """
        return self.radius * phi

    def rope_inertia(self, phi: float, k: int) -> float:
        """Inertia of the rope on the drum: 0 kg m^2 (its mass is not modelled).

        Parameters
        ----------
        phi : float
            Drum angle since the start, rad.
        k : int
            The outer layer.
        """
        return 0.0

    def rope_inertia_slope(self, k: int) -> float:
        """``dI/dphi`` of the rope: 0 kg m^2/rad.

        Parameters
        ----------
        k : int
            The outer layer.
        """
        return 0.0

    def problems(self) -> list[str]:
        """Every problem with this geometry, as sentences naming the parameter."""
        if self.radius > 0 and math.isfinite(self.radius):
            return []
        return [f"parameter 'drum_radius' must be > 0 m, got {self.radius}"]


@dataclass(frozen=True)
class LayeredDrum(Drum):
    """A drum whose winding radius grows one rope diameter per layer (effect ``rope_layers``).

    Parameters
    ----------
    radius : float
        Rope centreline radius on the first layer, m.
    rope_diameter : float
        Rope diameter, m; the radius grows by this per layer.
    rope_linear_mass : float
        Rope mass per metre, kg/m (adds to the inertia).
    wraps_per_layer : int
        Turns per layer.
    max_layers : int
        Layers the flanges allow.
    initial_rope : float
        Rope on the drum at the start, m.
    """

    rope_diameter: float = 0.0349
    rope_linear_mass: float = 5.06
    wraps_per_layer: int = 40
    max_layers: int = 4
    initial_rope: float = 150.0

    layer_guard_count: ClassVar[int] = 2
    """Guards :meth:`layer_guards` gives: the layer's two edges."""

    # ----------------------------------------------------------- geometry
    @property
    def layer_angle(self) -> float:
        """Wound angle one layer holds, rad."""
        return 2.0 * math.pi * self.wraps_per_layer

    def layer_radius(self, k: int) -> float:
        """Winding radius of layer ``k`` (0-based), m.

        Parameters
        ----------
        k : int
            The layer, 0 on the barrel.
        """
        return self.radius + k * self.rope_diameter

    def capacity(self) -> float:
        """Rope the drum holds when every layer is full, m."""
        return sum(self.layer_angle * self.layer_radius(k) for k in range(self.max_layers))

    def _below(self, k: int, power: int) -> float:
        """``sum_{j<k} Theta r_j^power``: length (power 1) or inertia/rho (3) of full layers."""
        return sum(self.layer_angle * self.layer_radius(j) ** power for j in range(k))

    def wound_angle(self, length: float) -> float:
        """Wound angle holding ``length`` metres of rope, rad.

        Parameters
        ----------
        length : float
            Rope on the drum, m.
        """
        k = 0
        while k < self.max_layers - 1 and length > self._below(k + 1, 1):
            k += 1
        return k * self.layer_angle + (length - self._below(k, 1)) / self.layer_radius(k)

    @property
    def initial_wound_angle(self) -> float:
        """Wound angle at ``phi = 0``, rad."""
        return self.wound_angle(self.initial_rope)

    def initial_layer(self) -> int:
        """The layer the rope leaves from at the start.

        On a layer boundary it is the full layer below (the next one starts
        empty); winding in then crosses at once into the new layer.
        """
        k = math.ceil(self.initial_wound_angle / self.layer_angle - 1e-12) - 1
        return min(max(k, 0), self.max_layers - 1)

    # -------------------------------------------------- in one layer (a mode)
    def phi_bounds(self, k: int) -> tuple[float, float]:
        """Drum angles ``(low, high)`` between which layer ``k`` is the outer one, rad.

        Below ``low`` the rope winds onto layer ``k + 1``; above ``high`` it
        pays out from layer ``k - 1``.

        Parameters
        ----------
        k : int
            The layer, 0 on the barrel.
        """
        theta0 = self.initial_wound_angle
        return theta0 - (k + 1) * self.layer_angle, theta0 - k * self.layer_angle

    def layer_guards(self, phi: float, k: int) -> np.ndarray:
        """``[phi - low, high - phi]``: both fire on a downward crossing of a layer edge.

        Parameters
        ----------
        phi : float
            Drum angle, rad.
        k : int
            The outer layer.
        """
        low, high = self.phi_bounds(k)
        return np.array([phi - low, high - phi])

    @cached_property
    def _lines(self) -> tuple[tuple[float, float, float, float], ...]:
        """Per layer ``(payout offset, radius, inertia offset, inertia slope)``.

        On layer ``k`` the payout is ``p_k + r_k phi`` and the rope inertia
        ``q_k + s_k phi``; the offsets are chained from the initial layer
        (where ``p = 0`` exactly) so both are continuous at every boundary.
        """
        n, k0 = self.max_layers, self.initial_layer()
        radii = [self.layer_radius(k) for k in range(n)]
        slopes = [-self.rope_linear_mass * r**3 for r in radii]
        theta0 = self.initial_wound_angle
        p, q = [0.0] * n, [0.0] * n
        q[k0] = self.rope_linear_mass * (
            self._below(k0, 3) + (theta0 - k0 * self.layer_angle) * radii[k0] ** 3
        )
        for k in range(k0 + 1, n):  # boundary between k - 1 and k at phi_low(k - 1)
            edge = self.phi_bounds(k - 1)[0]
            p[k] = p[k - 1] + (radii[k - 1] - radii[k]) * edge
            q[k] = q[k - 1] + (slopes[k - 1] - slopes[k]) * edge
        for k in range(k0 - 1, -1, -1):  # boundary between k and k + 1 at phi_high(k + 1)
            edge = self.phi_bounds(k + 1)[1]
            p[k] = p[k + 1] + (radii[k + 1] - radii[k]) * edge
            q[k] = q[k + 1] + (slopes[k + 1] - slopes[k]) * edge
        return tuple(zip(p, radii, q, slopes, strict=True))

    def payout(self, phi: float, k: int) -> float:
        """Rope paid out at drum angle ``phi`` while on layer ``k``, m (0 at ``phi = 0``).

        Parameters
        ----------
        phi : float
            Drum angle since the start, rad (positive paying out).
        k : int
            The layer the rope leaves from.
        """
        offset, radius, _, _ = self._lines[k]
        return offset + radius * phi

    def rope_inertia(self, phi: float, k: int) -> float:
        """Inertia of the rope on the drum at ``phi`` on layer ``k``, kg m^2.

        Parameters
        ----------
        phi : float
            Drum angle since the start, rad.
        k : int
            The outer layer.
        """
        _, _, offset, slope = self._lines[k]
        return offset + slope * phi

    def rope_inertia_slope(self, k: int) -> float:
        """``dI/dphi`` of the rope on layer ``k``, kg m^2/rad (<= 0: paying out unwinds).

        Parameters
        ----------
        k : int
            The outer layer.
        """
        return self._lines[k][3]

    def problems(self) -> list[str]:
        """Every problem with this geometry, as sentences naming the parameter."""
        out = super().problems()
        if not (self.rope_diameter > 0 and math.isfinite(self.rope_diameter)):
            out.append(f"parameter 'rope_diameter' must be > 0 m, got {self.rope_diameter}")
        if not (self.rope_linear_mass >= 0 and math.isfinite(self.rope_linear_mass)):
            out.append(
                f"parameter 'rope_linear_mass' must be >= 0 kg/m, got {self.rope_linear_mass}"
            )
        if self.wraps_per_layer < 1:
            out.append(f"parameter 'drum_wraps_per_layer' must be >= 1, got {self.wraps_per_layer}")
        if self.max_layers < 1:
            out.append(f"parameter 'drum_layers' must be >= 1, got {self.max_layers}")
        if out:
            return out
        if not 0.0 < self.initial_rope <= self.capacity():
            out.append(
                f"parameter 'rope_on_drum' must lie in (0, {self.capacity():.6g}] m (the "
                f"drum's capacity with {self.max_layers} layers), got {self.initial_rope}"
            )
        return out

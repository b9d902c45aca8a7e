"""Rope segments: Hooke and Kelvin-Voigt, variable unstretched length, slack.

SPEC section 3 (paper 000, eq. 1-8). A segment (or a chain of segments
joined over massless frictionless sheaves, which act as one spring) has
geometric length ``L`` between its end points and unstretched length
``l``, which changes as rope flows in or out through its ends (eq. 6).

Constitutive law, with engineering strain ``eps = (L - l) / l``::

    T = EA * eps + c * deps/dt      while taut                (eq. 3-5)
    T = 0                           while slack (a rope never pushes)

A taut spring goes slack when ``T`` would turn negative; a slack one
engages when it is stretched and ``T`` would be positive. Treating the two
as modes (rather than clamping with ``max``) keeps the force smooth inside
each mode, which implicit integrators and their Jacobians need.

``EA = A_w * E_w * k_f`` (eq. 4 with k = 1/EA) and ``c = eta * A_w * k_f``
(eq. 5). The clamp at zero means damping can neither push nor pull a slack
rope taut; a slack rope that is re-tensioned picks its load up again
through the elastic term, which is what produces a snap load.

Energy: the strain energy ``U = EA (L - l)^2 / (2 l)`` (for ``L > l``). Its
partial derivatives give the generalised forces on everything the rope is
attached to::

    dU/dL = T_el                    dU/dl = -T_el (1 + eps/2)

The second is larger than the tension by the strain energy carried by the
rope that flows through an end (``EA eps^2 / 2`` per metre of unstretched
rope). The damper's force follows from the dissipation function
``D = c l deps^2 / 2``: generalised force ``-T_d (dL/dq - (1 + eps) dl/dq)``,
loss power ``T_d l deps/dt`` (>= 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["RopeProperties", "RopeForces", "rope_forces", "slack_guard", "taut_guard", "snap_load"]


@dataclass(frozen=True)
class RopeProperties:
    """Material and section of a wire rope.

    Parameters
    ----------
    axial_stiffness : float
        ``EA = A_w E_w k_f``, N (force per unit strain).
    damping : float
        Kelvin-Voigt coefficient ``c = eta A_w k_f``, N s (force per unit
        strain rate); 0 for a pure Hooke rope.
    breaking_load : float
        Tension at which the rope breaks, N (``inf``: never).
    linear_mass : float
        Mass per metre, kg/m (used for rope on a sheave groove when the
        rope may slip).
    """

    axial_stiffness: float
    damping: float = 0.0
    breaking_load: float = math.inf
    linear_mass: float = 0.0

    @classmethod
    def from_section(
        cls,
        metallic_area: float,
        modulus: float,
        fill_factor: float = 1.0,
        viscosity: float = 0.0,
        breaking_load: float = math.inf,
        linear_mass: float = 0.0,
    ) -> RopeProperties:
        """Build from the paper's parameters (eq. 4, 5).

        Parameters
        ----------
        metallic_area : float
            Cross-section ``A_w``, m^2.
        modulus : float
            Young's modulus of the rope ``E_w``, Pa.
        fill_factor : float
            ``k_f``, metal area over section area, 1.
        viscosity : float
            Kelvin-Voigt coefficient ``eta``, Pa s.
        """
        area = metallic_area * fill_factor
        return cls(area * modulus, area * viscosity, breaking_load, linear_mass)


@dataclass(frozen=True)
class RopeForces:
    """Forces of rope springs at one instant (arrays: one entry per spring).

    Attributes
    ----------
    tension : ndarray
        Physical tension ``T``, N (0 for a slack spring).
    force_on_length : ndarray
        ``dU/dL`` plus damping: the generalised force conjugate to ``L``, N.
    force_on_unstretched : ndarray
        Minus the generalised force conjugate to ``l``, N (see module doc).
    energy : ndarray
        Strain energy, J.
    loss_power : ndarray
        Power dissipated by the damper, W (>= 0).
    trial_tension : ndarray
        ``EA eps + c deps/dt`` whether taut or not, N: the tension the
        spring would carry if it were taut (used to switch modes).
    elastic_tension : ndarray
        ``EA eps``, N.
    """

    tension: np.ndarray
    force_on_length: np.ndarray
    force_on_unstretched: np.ndarray
    energy: np.ndarray
    loss_power: np.ndarray
    trial_tension: np.ndarray
    elastic_tension: np.ndarray


def rope_forces(
    props: RopeProperties,
    length: np.ndarray,
    unstretched: np.ndarray,
    length_rate: np.ndarray,
    unstretched_rate: np.ndarray,
    taut: np.ndarray,
) -> RopeForces:
    """Tension, generalised forces, energy and loss of rope springs.

    Whether each spring is taut is a *mode*, switched by the caller where
    :func:`slack_guard` or :func:`taut_guard` crosses zero; inside a mode the
    forces are smooth, which is what implicit integrators need.

    Parameters
    ----------
    props : RopeProperties
        The rope.
    length, unstretched : array_like
        Geometric length ``L`` and unstretched length ``l`` of each spring,
        m (``l > 0``).
    length_rate, unstretched_rate : array_like
        Their time derivatives, m/s.
    taut : array_like of bool
        Mode of each spring.
    """
    big_l = np.asarray(length, dtype=float)
    small_l = np.asarray(unstretched, dtype=float)
    stretch = big_l - small_l
    eps = stretch / small_l
    t_el = props.axial_stiffness * eps
    if props.damping == 0.0:
        t_d = np.zeros_like(t_el)
        eps_rate = t_d
    else:
        eps_rate = (np.asarray(length_rate) - (1.0 + eps) * np.asarray(unstretched_rate)) / small_l
        t_d = props.damping * eps_rate
    trial = t_el + t_d
    on = np.asarray(taut, dtype=bool)
    tension = np.where(on, trial, 0.0)
    # A slack spring may still be stretched while its damper unloads it (zero
    # total force): its strain energy is still there and drains through the
    # damper, at the rate the stretch falls. A slack spring whose stretch grows
    # is one just past engaging (an event is located just past its root): that
    # energy is the location's error, left to the ledger, never a negative loss.
    relaxing = ~on & (stretch > 0.0)
    energy = np.where(on | relaxing, 0.5 * t_el * stretch, 0.0)
    strain_rate = t_el * np.asarray(length_rate) - t_el * (1.0 + 0.5 * eps) * np.asarray(
        unstretched_rate
    )
    loss = np.where(
        on, t_d * small_l * eps_rate, np.where(relaxing, np.maximum(-strain_rate, 0.0), 0.0)
    )
    return RopeForces(
        tension,
        tension,
        np.where(on, t_el * (1.0 + 0.5 * eps) + t_d * (1.0 + eps), 0.0),
        energy,
        loss,
        trial,
        t_el,
    )


def taut_guard(forces: RopeForces) -> np.ndarray:
    """Positive while a taut spring stays taut; crosses zero when it goes slack, N.

    Parameters
    ----------
    forces : RopeForces
        The springs' forces at the state (:func:`rope_forces`).
    """
    return forces.trial_tension


def slack_guard(forces: RopeForces) -> np.ndarray:
    """Positive while a slack spring stays slack; crosses zero when it engages, N.

    A spring engages when it is stretched *and* the damper would not pull it
    apart, i.e. when both ``EA eps`` and the trial tension are positive.

    Parameters
    ----------
    forces : RopeForces
        The springs' forces at the state (:func:`rope_forces`).
    """
    return np.maximum(-forces.elastic_tension, -forces.trial_tension)


def snap_load(mass: float, stiffness: float, speed: float, gravity: float = 9.81) -> float:
    """Peak tension when a mass falling at ``speed`` engages a slack rope.

    Closed form ``T_max = m g (1 + sqrt(1 + k v0^2 / (m g^2)))`` (SPEC section 17)
    for a linear spring of stiffness ``k`` (N/m) engaged at zero stretch.

    Parameters
    ----------
    mass : float
        The falling mass, kg.
    stiffness : float
        Rope stiffness ``k``, N/m.
    speed : float
        Speed of the mass when the rope engages, m/s.
    gravity : float, optional
        Gravitational acceleration, m/s^2.

    Returns
    -------
    float
        Peak rope tension, N.
    """
    weight = mass * gravity
    return weight * (1.0 + math.sqrt(1.0 + stiffness * speed**2 / (mass * gravity**2)))

"""The winch (drawworks): drum, band brake, motor and drive train (SPEC sections 7-9).

Sign convention, stated once
----------------------------
Every angle, speed and torque of the winch is measured about one axis,
positive in the *paying-out* (lowering) sense: the drum angle ``phi`` grows
as rope leaves the drum, ``rope.payout`` grows with it and
``payout_rate = r(phi) omega``. The rope pulls the drum with ``+T r``
(paying out under tension drives the drum; power in ``T payout_rate``);
a hoisting motor gives a negative torque; the brake's torque opposes motion.

Effects (SPEC section 12)
-------------------------
=======================  ====================================================
``drum_inertia``         the drum (and drive train) has inertia:
                         ``J omega' = M_motor + T r + M_brake`` with the
                         signed torques above (the SPEC's ``J omega' = M -
                         T r_b - M_brake`` read with omega positive when
                         hoisting). Absent: kinetostatic (32), see
                         :mod:`~wire_fmu.core.units.winch.kinetostatic`.
``band_brake``           dry friction band brake (34), direction dependent
``motor_characteristic`` ``M = a - b omega`` (004, eq. 6) with ``a`` the
                         command; absent: the command is the motor torque
``elastic_drive_train``  n-mass chain (002), reducible by delta-star
``rope_layers``          radius grows per layer, ``I(phi)`` (004)
=======================  ====================================================

Energy
------
Stored: kinetic energy of every mass (the drum's with ``I(phi)``) plus
shaft strain energy. Dissipated: brake sliding, every viscous damper
(shafts and ground). External work: rope port (``T r omega_drum``) plus
the motor (its whole torque, ``a - b omega`` included: the characteristic
is a source whose losses are not the winch's). In kinetostatic mode the
motor work is what (32) requires and stored energy is zero.

Modules
-------
:mod:`~wire_fmu.core.units.winch.brake`
    The band brake (34): capacities and states.
:mod:`~wire_fmu.core.units.winch.base`
    Inputs, configuration, report and what both models share.
:mod:`~wire_fmu.core.units.winch.drive`
    The winch with drum inertia: a hybrid ODE of the drive train.
:mod:`~wire_fmu.core.units.winch.kinetostatic`
    The winch without inertia (32): a speed-commanded drive.
"""

from __future__ import annotations

import numpy as np

from wire_fmu.core.components.drive_train import DriveChain
from wire_fmu.core.framework.effects import Effect, EffectCatalogue
from wire_fmu.core.framework.hybrid import SolverSettings
from wire_fmu.core.units.winch.base import WinchConfig
from wire_fmu.core.units.winch.drive import WinchModel
from wire_fmu.core.units.winch.kinetostatic import KinetostaticWinch

__all__ = ["WINCH_EFFECTS", "build_winch", "fastest_rate"]

WINCH_EFFECTS = EffectCatalogue(
    "winch",
    (
        Effect(
            "drum_inertia",
            "kinetostatic drum (eq. 32), speed commanded",
            "drum and drive-train inertia J",
        ),
        Effect("band_brake", "no brake", "band brake (eq. 34), dry friction, direction dependent"),
        Effect(
            "motor_characteristic",
            "motor torque input",
            "motor characteristic a - b omega",
            requires=("drum_inertia",),
        ),
        Effect(
            "elastic_drive_train",
            "rigid drive train",
            "n-mass elastic chain (paper 002)",
            requires=("drum_inertia",),
        ),
        Effect("rope_layers", "constant winding radius", "radius grows per layer, inertia I(phi)"),
    ),
)


def fastest_rate(chain: DriveChain, motor_slope: float = 0.0) -> float:
    """Largest ``|lambda|`` (1/s) of the chain with the motor characteristic, brake released.

    The eigenvalues of ``[[0, I], [-M^-1 K, -M^-1 (B + b_red e0 e0^T)]]`` with the
    chain's own inertias (rope on the drum only adds inertia, lowering them).

    Parameters
    ----------
    chain : DriveChain
        Reduced to the drum shaft.
    motor_slope : float
        ``b`` of the motor characteristic at the motor shaft, N m s/rad (0: torque input).
    """
    n = chain.n
    damping = chain.damping_matrix()
    damping[0, 0] += motor_slope * chain.motor_ratio**2
    inv_mass = 1.0 / np.asarray(chain.inertias, dtype=float)
    system = np.block(
        [
            [np.zeros((n, n)), np.eye(n)],
            [-inv_mass[:, None] * chain.stiffness_matrix(), -inv_mass[:, None] * damping],
        ]
    )
    return float(np.abs(np.linalg.eigvals(system)).max())


def build_winch(config: WinchConfig, solver: SolverSettings) -> WinchModel | KinetostaticWinch:
    """The model the effects call for: with ``drum_inertia`` a hybrid ODE, else kinetostatic.

    Parameters
    ----------
    config : WinchConfig
        The winch.
    solver : SolverSettings
        Internal solver (used with ``drum_inertia``).
    """
    if "drum_inertia" in config.effects:
        return WinchModel(config, solver)
    return KinetostaticWinch(config)

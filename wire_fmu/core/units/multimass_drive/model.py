"""Paper 002's multi-mass elastic drive as a hybrid system: ``J w' = -K theta - B w + torques``.

The drive (a chain or tree of :mod:`wire_fmu.core.components.drive_tree`, every
quantity reduced to the motor shaft) is linear and has no modes; its ports and
parameters are described in :mod:`wire_fmu.core.units.multimass_drive.unit`.
"""

from __future__ import annotations

import math

import numpy as np

from wire_fmu.core.components.drive_tree import DriveTree
from wire_fmu.core.framework.hybrid import SmoothSystem, SolverSettings, make_solver

__all__ = ["DriveModel"]


class DriveModel(SmoothSystem):
    """The drive's linear ODE as a hybrid system without modes.

    State ``[theta (n), omega (n), dissipated, external work]`` (rad,
    rad/s, J, J). Torques: ``motor`` (n_motors,), ``load`` (N m), held over a step.

    Parameters
    ----------
    tree : DriveTree
        The drive (already reduced if asked).
    motor_slope : float
        ``b`` of every motor, N m s/rad (0: torque inputs).
    settings : SolverSettings
        Internal solver.
    """

    def __init__(self, tree: DriveTree, motor_slope: float, settings: SolverSettings) -> None:
        self.tree = tree
        self.n = tree.n
        self.inertia = np.asarray(tree.inertias, dtype=float)
        self.stiffness = tree.stiffness_matrix()
        self.damping = tree.damping_matrix()
        self.motor_slope = motor_slope
        self.motors = [m % self.n for m in tree.motors]
        self.load = tree.load_index
        self.commands = np.zeros(len(self.motors))
        self.load_torque = 0.0
        self.state = np.zeros(2 * self.n + 2)
        self.solver = make_solver(settings)
        self.modes = self._modes()

    def motor_torques(self, omega: np.ndarray) -> np.ndarray:
        """Torque each motor develops at the masses' speeds, N m.

        Parameters
        ----------
        omega : ndarray, shape (n,)
            Speeds of the masses, rad/s.
        """
        return self.commands - self.motor_slope * omega[self.motors]

    def _torques(self, omega: np.ndarray) -> np.ndarray:
        f = np.zeros(self.n)
        f[self.motors] += self.motor_torques(omega)
        f[self.load] -= self.load_torque
        return f

    def shaft_torques(self, x: np.ndarray) -> np.ndarray:
        """Torque in each shaft (drives its second mass forward), N m.

        Parameters
        ----------
        x : ndarray
            State ``[theta (rad), omega (rad/s), dissipated (J), external work (J)]``.
        """
        theta, omega = x[: self.n], x[self.n : 2 * self.n]
        return np.array(
            [
                s.stiffness * (theta[s.a] - theta[s.b]) + s.damping * (omega[s.a] - omega[s.b])
                for s in self.tree.shafts
            ]
        )

    # -- HybridSystem (no modes: the rest is SmoothSystem's) -----------------
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[theta', omega', dissipated', external work']``.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[theta (rad), omega (rad/s), dissipated (J), external work (J)]``.
        """
        n = self.n
        theta, omega = x[:n], x[n : 2 * n]
        external = self._torques(omega)
        out = np.empty_like(x)
        out[:n] = omega
        out[n : 2 * n] = (external - self.stiffness @ theta - self.damping @ omega) / self.inertia
        out[2 * n] = float(omega @ self.damping @ omega)
        out[2 * n + 1] = float(external @ omega)
        return out

    # -- life cycle -------------------------------------------------------------
    def initialize(self, speed: float) -> None:
        """All masses at ``speed``, shafts twisted as in rigid acceleration (no ringing).

        Parameters
        ----------
        speed : float
            Speed of every mass at the start, rad/s.
        """
        n = self.n
        omega = np.full(n, speed)
        f = self._torques(omega) - self.damping @ omega
        acc = f.sum() / self.inertia.sum()
        residual = f - self.inertia * acc  # what the shafts must carry
        theta = np.zeros(n)
        keep = [k for k in range(n) if k != self.load]
        if keep:
            theta[keep] = np.linalg.solve(self.stiffness[np.ix_(keep, keep)], residual[keep])
        self.state = np.concatenate([theta, omega, [0.0, 0.0]])

    def advance(self, t: float, h: float) -> None:
        """Advance by ``h`` with the torques held.

        Parameters
        ----------
        t : float
            Start of the step, s.
        h : float
            Step length, s.
        """
        self.state, _ = self.solver.advance(self, t, self.state, t + h)

    def stored_energy(self, x: np.ndarray | None = None) -> float:
        """``omega^T J omega / 2 + theta^T K theta / 2``, J.

        Parameters
        ----------
        x : ndarray, optional
            State (default: the current one).
        """
        x = self.state if x is None else x
        theta, omega = x[: self.n], x[self.n : 2 * self.n]
        return 0.5 * float(self.inertia @ omega**2) + 0.5 * float(theta @ self.stiffness @ theta)

    def state_matrix(self) -> np.ndarray:
        """``A`` of the drive with each motor's characteristic slope, shape (2n, 2n)."""
        a = self.tree.state_matrix()
        for m in self.motors:
            a[self.n + m, self.n + m] -= self.motor_slope / self.inertia[m]
        return a

    def fastest_rate(self) -> float:
        """Largest ``|lambda|`` of :meth:`state_matrix`, 1/s."""
        return float(np.max(np.abs(np.linalg.eigvals(self.state_matrix()))))

    def _modes(self) -> tuple[np.ndarray, np.ndarray]:
        """Damped frequencies (Hz) and damping ratios of the oscillatory modes, ascending."""
        lam = np.linalg.eigvals(self.state_matrix())
        lam = lam[lam.imag > 1e-9 * max(1.0, float(np.max(np.abs(lam))))]
        lam = lam[np.argsort(lam.imag)]
        return lam.imag / (2.0 * math.pi), -lam.real / np.abs(lam)

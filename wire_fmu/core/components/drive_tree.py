"""Branched multi-mass drives (paper 002): rotating masses joined by elastic shafts in a tree.

:class:`~wire_fmu.core.components.drive_train.DriveChain` is a chain; paper 002's
two-motor drive is a tree: two motors (masses 1 and 2) drive a common mass
3 through their own shafts, which drives the load (mass 4)::

    M1 - Z13 (w1 - w3) = Z1 w1
    M2 - Z23 (w2 - w3) = Z2 w2
    Z13 (w1 - w3) + Z23 (w2 - w3) - Z34 (w3 - w4) = Z3 w3
    Z34 (w3 - w4) - M_c = Z4 w4

with the impedances of paper 002 (Laplace operator ``p``): a mass
``Z_k = J_k p + beta_k``, a shaft ``Z_ij = c_ij / p + beta_ij`` (all
reduced to one shaft). A :class:`DriveTree` holds any such tree (a chain
is the special case) and gives its matrices, natural frequencies and
impedances; a chain converts to and from :class:`DriveChain`, whose
delta-star elimination reduces it to fewer masses.

Impedances by the electrical analogy
------------------------------------
Speeds play currents and torques voltages (paper 002, Fig. 2): seen from
mass ``k`` with every other torque source off, the tree is a ladder. A
branch hanging from ``k`` through shaft ``Z_kj`` is ``Z_kj`` in parallel
with the branch's own impedance ``Z_j + sum over j's children``, so::

    Z_in,k = Z_k + sum_j  Z_kj Z_j^tree / (Z_kj + Z_j^tree)

which for two masses is paper 002's ``(Z1 Z2 + Z1 Z12 + Z12 Z2)/(Z2 + Z12)``.
``1 / Z_in,k(j w)`` is the frequency response from a torque at ``k`` to the
speed of ``k``; :meth:`DriveTree.speeds_per_torque` solves the same from
the matrices directly, and the tests compare both with simulation.

Drives written as data (JSON), their reader and the example drives are in
:mod:`wire_fmu.core.components.drive_data`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from wire_fmu.core.components.drive_train import DriveChain

__all__ = ["Shaft", "DriveTree"]


@dataclass(frozen=True)
class Shaft:
    """An elastic shaft between masses ``a`` and ``b`` (indices).

    Parameters
    ----------
    a, b : int
        The masses it joins.
    stiffness : float
        ``c``, N m/rad (> 0).
    damping : float
        Internal damping ``beta``, N m s/rad.
    name : str
        For messages.
    """

    a: int
    b: int
    stiffness: float
    damping: float = 0.0
    name: str = ""


@dataclass(frozen=True)
class DriveTree:
    """Masses joined by shafts forming a tree, reduced to one shaft.

    Parameters
    ----------
    inertias, dampings : tuple of float, length n
        ``J_k`` (kg m^2, > 0) and ground dampers ``beta_k`` (N m s/rad).
    shafts : tuple of Shaft, length n - 1
        They must connect all masses without a loop.
    names : tuple of str, length n
        Mass names.
    motors : tuple of int
        Masses the motor torque inputs act on (paper 002: one or two).
    load : int
        Mass the load torque ``M_c`` acts on.
    """

    inertias: tuple[float, ...]
    dampings: tuple[float, ...]
    shafts: tuple[Shaft, ...]
    names: tuple[str, ...]
    motors: tuple[int, ...] = (0,)
    load: int = -1

    @property
    def n(self) -> int:
        """Number of masses."""
        return len(self.inertias)

    @property
    def load_index(self) -> int:
        """The load mass as a non-negative index."""
        return self.load % self.n

    # ------------------------------------------------------------ chains
    @classmethod
    def from_chain(cls, chain: DriveChain, motors: tuple[int, ...] = (0,)) -> DriveTree:
        """The chain as a tree (motor at mass 0, load at the last mass).

        Parameters
        ----------
        chain : DriveChain
            The chain, masses in order.
        motors : tuple of int, optional
            Masses the motors act on.
        """
        shafts = tuple(
            Shaft(k, k + 1, c, b, f"shaft {k + 1}-{k + 2}")
            for k, (c, b) in enumerate(zip(chain.stiffnesses, chain.link_dampings, strict=True))
        )
        return cls(
            tuple(chain.inertias),
            tuple(chain.dampings),
            shafts,
            tuple(chain.names),
            motors,
            chain.n - 1,
        )

    def is_chain(self) -> bool:
        """Whether shaft ``k`` joins masses ``k`` and ``k + 1`` for every ``k``."""
        return all({s.a, s.b} == {k, k + 1} for k, s in enumerate(self.shafts))

    def to_chain(self) -> DriveChain:
        """The equivalent :class:`DriveChain` (raises ValueError unless :meth:`is_chain`)."""
        if not self.is_chain():
            raise ValueError(
                "only a chain (shaft k joins masses k and k+1) converts to a "
                "DriveChain; this drive is branched"
            )
        return DriveChain(
            self.inertias,
            self.dampings,
            tuple(s.stiffness for s in self.shafts),
            tuple(s.damping for s in self.shafts),
            self.names,
        )

    # ------------------------------------------------------------ matrices
    def mass_matrix(self) -> np.ndarray:
        """Diagonal inertia matrix, kg m^2."""
        return np.diag(self.inertias)

    def stiffness_matrix(self) -> np.ndarray:
        """Graph Laplacian of the shaft stiffnesses, N m/rad."""
        return self._laplacian([s.stiffness for s in self.shafts], np.zeros(self.n))

    def damping_matrix(self) -> np.ndarray:
        """Shaft dampings' Laplacian plus the ground dampers on the diagonal, N m s/rad."""
        return self._laplacian(
            [s.damping for s in self.shafts], np.asarray(self.dampings, dtype=float)
        )

    def _laplacian(self, values: Sequence[float], ground: np.ndarray) -> np.ndarray:
        out = np.diag(ground.astype(float))
        for shaft, value in zip(self.shafts, values, strict=True):
            a, b = shaft.a, shaft.b
            out[a, a] += value
            out[b, b] += value
            out[a, b] -= value
            out[b, a] -= value
        return out

    def state_matrix(self) -> np.ndarray:
        """``A`` of ``d[theta, omega]/dt = A [theta, omega] + ...``, shape (2n, 2n)."""
        n = self.n
        m_inv = np.diag(1.0 / np.asarray(self.inertias))
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = np.eye(n)
        a[n:, :n] = -m_inv @ self.stiffness_matrix()
        a[n:, n:] = -m_inv @ self.damping_matrix()
        return a

    # ------------------------------------------------------------ frequencies
    def natural_frequencies(self) -> np.ndarray:
        """Undamped natural frequencies, rad/s, ascending (the first is 0: free rotation)."""
        eig = scipy.linalg.eigh(self.stiffness_matrix(), self.mass_matrix(), eigvals_only=True)
        return np.sqrt(np.clip(eig, 0.0, None))

    def damped_modes(self) -> tuple[np.ndarray, np.ndarray]:
        """Oscillatory modes of ``A``: damped frequencies (rad/s) and damping ratios, ascending."""
        lam = scipy.linalg.eigvals(self.state_matrix())
        lam = lam[lam.imag > 1e-9 * max(1.0, float(np.max(np.abs(lam))))]
        order = np.argsort(lam.imag)
        lam = lam[order]
        return lam.imag, -lam.real / np.abs(lam)

    # ------------------------------------------------------------ impedances
    def mass_impedance(self, k: int, omega: float) -> complex:
        """``Z_k = J_k p + beta_k`` at ``p = j omega``, N m s/rad.

        Parameters
        ----------
        k : int
            The mass (an index into :attr:`inertias`).
        omega : float
            Angular frequency, rad/s.
        """
        return self.inertias[k] * 1j * omega + self.dampings[k]

    def driving_point_impedance(self, k: int, omega: float) -> complex:
        """``Z_in`` seen from mass ``k``, folded by the electrical analogy (module docstring).

        Parameters
        ----------
        k : int
            The mass the torque acts on (negative counts from the end).
        omega : float
            Angular frequency, rad/s.

        Returns
        -------
        complex
            Torque per speed of mass ``k``, N m s/rad.
        """
        k = k % self.n
        neighbours: dict[int, list[Shaft]] = {i: [] for i in range(self.n)}
        for s in self.shafts:
            neighbours[s.a].append(s)
            neighbours[s.b].append(s)

        def branch(node: int, parent: int | None) -> complex:
            """Impedance of ``node`` with everything beyond it seen from ``parent``, N m s/rad.

            Parameters
            ----------
            node : int
                The mass at the root of the branch.
            parent : int or None
                The mass the branch hangs from (None at the driving point).
            """
            z = self.mass_impedance(node, omega)
            for s in neighbours[node]:
                child = s.b if s.a == node else s.a
                if child == parent:
                    continue
                link = s.stiffness / (1j * omega) + s.damping
                sub = branch(child, node)
                z += link * sub / (link + sub)
            return z

        return branch(k, None)

    def speeds_per_torque(self, omega: float, at: int = 0) -> np.ndarray:
        """Speed of every mass per unit torque on mass ``at`` at ``j omega`` (rad/s/(N m)).

        Solves ``(j omega M + B + K / (j omega)) w = e_at``; entry ``at`` is
        ``1 / Z_in,at``.

        Parameters
        ----------
        omega : float
            Angular frequency, rad/s.
        at : int, optional
            The mass the unit torque acts on.

        Returns
        -------
        ndarray of complex, shape (n,)
            Speed of each mass per N m on mass ``at``, rad/s/(N m).
        """
        p = 1j * omega
        system = p * self.mass_matrix() + self.damping_matrix() + self.stiffness_matrix() / p
        rhs = np.zeros(self.n, dtype=complex)
        rhs[at % self.n] = 1.0
        return np.linalg.solve(system, rhs)

    # ------------------------------------------------------------ checks
    def problems(self) -> list[str]:
        """Every structural problem: sizes, signs, connectivity, loops, indices."""
        out = []
        n = self.n
        if n < 1:
            return ["a drive needs at least one mass"]
        for k, (j, b) in enumerate(zip(self.inertias, self.dampings, strict=True)):
            if not (j > 0.0 and math.isfinite(j)):
                out.append(f"mass {self.names[k]!r}: inertia must be > 0 kg m^2, got {j}")
            if not (b >= 0.0 and math.isfinite(b)):
                out.append(f"mass {self.names[k]!r}: damping must be >= 0, got {b}")
        for s in self.shafts:
            if not (s.stiffness > 0.0 and math.isfinite(s.stiffness)):
                out.append(f"shaft {s.name!r}: stiffness must be > 0 N m/rad, got {s.stiffness}")
            if not (s.damping >= 0.0 and math.isfinite(s.damping)):
                out.append(f"shaft {s.name!r}: damping must be >= 0, got {s.damping}")
        if len(self.shafts) != n - 1:
            out.append(f"{n} masses in a tree need {n - 1} shafts, got {len(self.shafts)}")
        elif not _connected(n, self.shafts):
            out.append("the shafts must join every mass to every other without a loop")
        for k in (*self.motors, self.load):
            if not -n <= k < n:
                out.append(f"mass index {k} does not exist (masses 0..{n - 1})")
        if len(set(m % n for m in self.motors)) != len(self.motors):
            out.append("two motors act on the same mass")
        return out


def _connected(n: int, shafts: Sequence[Shaft]) -> bool:
    parent = list(range(n))

    def find(i: int) -> int:
        """The representative of mass ``i``'s set (union-find with path halving).

        Parameters
        ----------
        i : int
            A mass.
        """
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for s in shafts:
        if not (0 <= s.a < n and 0 <= s.b < n) or s.a == s.b:
            return False
        ra, rb = find(s.a), find(s.b)
        if ra == rb:
            return False
        parent[ra] = rb
    return True

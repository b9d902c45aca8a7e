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
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from wire_fmu.core.components.drive_train import DriveChain

__all__ = ["Shaft", "DriveTree", "parse_drive", "default_multimass_drive", "two_motor_drive"]


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
        """The chain as a tree (motor at mass 0, load at the last mass)."""
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
        """``Z_k = J_k p + beta_k`` at ``p = j omega``, N m s/rad."""
        return self.inertias[k] * 1j * omega + self.dampings[k]

    def driving_point_impedance(self, k: int, omega: float) -> complex:
        """``Z_in`` seen from mass ``k``, folded by the electrical analogy (module docstring)."""
        k = k % self.n
        neighbours: dict[int, list[Shaft]] = {i: [] for i in range(self.n)}
        for s in self.shafts:
            neighbours[s.a].append(s)
            neighbours[s.b].append(s)

        def branch(node: int, parent: int | None) -> complex:
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


# ---------------------------------------------------------------- examples
def default_multimass_drive() -> dict[str, Any]:
    """A four-mass conveyor or hoist drive, every quantity reduced to the motor shaft.

    Estimated values (paper 002 gives none): a 30 kW, 1470 rpm induction
    motor rotor (0.5 kg m^2); a flexible jaw coupling and the gearbox's
    first stage (0.02 kg m^2); the gearbox output and a brake disc reduced
    through 1:20 (0.1 kg m^2); the driven machine (2.0 kg m^2 reduced),
    with a speed-proportional load characteristic linearised as 0.8 N m s/rad.
    Stiffnesses: coupling 1.5e4, gear shaft 6e4, long output shaft 4e3 N m/rad
    at the motor shaft; shaft damping a few per cent of critical.
    """
    return {
        "masses": [
            {"name": "motor rotor", "inertia": 0.5, "damping": 0.02},
            {"name": "coupling", "inertia": 0.02, "damping": 0.0},
            {"name": "gearbox", "inertia": 0.1, "damping": 0.05},
            {"name": "machine", "inertia": 2.0, "damping": 0.8},
        ],
        "shafts": [
            {"name": "coupling", "stiffness": 1.5e4, "damping": 2.0},
            {"name": "gear shaft", "stiffness": 6.0e4, "damping": 3.0},
            {"name": "output shaft", "stiffness": 4.0e3, "damping": 2.5},
        ],
    }


def two_motor_drive() -> dict[str, Any]:
    """Paper 002's branched drive (Fig. 7): two motors into one gear, then the load.

    Estimated values: two 0.4 kg m^2 motor rotors on couplings of 1.2e4 and
    1.0e4 N m/rad (slightly unequal, so the motors share the load unevenly
    during transients) into a common gear mass of 0.3 kg m^2, driving a
    4 kg m^2 machine through a 6e3 N m/rad shaft, all at motor speed.
    """
    return {
        "masses": [
            {"name": "motor 1", "inertia": 0.4, "damping": 0.02},
            {"name": "motor 2", "inertia": 0.4, "damping": 0.02},
            {"name": "gear", "inertia": 0.3, "damping": 0.05},
            {"name": "machine", "inertia": 4.0, "damping": 1.0},
        ],
        "shafts": [
            {
                "name": "coupling 1",
                "from": "motor 1",
                "to": "gear",
                "stiffness": 1.2e4,
                "damping": 2.0,
            },
            {
                "name": "coupling 2",
                "from": "motor 2",
                "to": "gear",
                "stiffness": 1.0e4,
                "damping": 2.0,
            },
            {
                "name": "output shaft",
                "from": "gear",
                "to": "machine",
                "stiffness": 6.0e3,
                "damping": 3.0,
            },
        ],
        "motors": ["motor 1", "motor 2"],
        "load": "machine",
    }


# ---------------------------------------------------------------- parsing
def _number(
    item: Mapping[str, Any], key: str, default: float | None, where: str, problems: list[str]
) -> float:
    value = item.get(key, default)
    try:
        return float(value)
    except (TypeError, ValueError):
        problems.append(f"{where}: {key!r} must be a number, got {value!r}")
        return math.nan


def _index(ref: Any, names: list[str], where: str, problems: list[str]) -> int:
    if isinstance(ref, int) and not isinstance(ref, bool) and -len(names) <= ref < len(names):
        return ref % len(names)
    if isinstance(ref, str) and ref in names:
        return names.index(ref)
    problems.append(f"{where}: {ref!r} names no mass; masses: {', '.join(names)}")
    return 0


def _masses(data: Any, problems: list[str]) -> tuple[list[str], list[float], list[float]]:
    names, inertias, dampings = [], [], []
    if not isinstance(data, list) or not data:
        problems.append("drive: 'masses' must be a non-empty list of tables")
        return names, inertias, dampings
    for i, item in enumerate(data):
        where = f"drive masses[{i}]"
        if not isinstance(item, Mapping):
            problems.append(f"{where} must be a table with name, inertia, damping")
            continue
        unknown = sorted(set(item) - {"name", "inertia", "damping"})
        if unknown:
            problems.append(f"{where}: unknown keys {unknown}; known: name, inertia, damping")
        names.append(str(item.get("name", f"mass {i + 1}")))
        inertias.append(_number(item, "inertia", None, where, problems))
        dampings.append(_number(item, "damping", 0.0, where, problems))
    if len(set(names)) != len(names):
        problems.append(f"drive: mass names must be unique, got {names}")
    return names, inertias, dampings


def _shafts(data: Any, names: list[str], problems: list[str]) -> list[Shaft]:
    out = []
    if not isinstance(data, list):
        problems.append("drive: 'shafts' must be a list of tables")
        return out
    for i, item in enumerate(data):
        where = f"drive shafts[{i}]"
        if not isinstance(item, Mapping):
            problems.append(f"{where} must be a table")
            continue
        unknown = sorted(set(item) - {"name", "from", "to", "stiffness", "damping"})
        if unknown:
            problems.append(
                f"{where}: unknown keys {unknown}; known: name, from, to, stiffness, damping"
            )
        a = _index(item.get("from", i), names, f"{where} 'from'", problems) if names else 0
        b = _index(item.get("to", i + 1), names, f"{where} 'to'", problems) if names else 0
        out.append(
            Shaft(
                a,
                b,
                _number(item, "stiffness", None, where, problems),
                _number(item, "damping", 0.0, where, problems),
                str(item.get("name", f"shaft {i + 1}")),
            )
        )
    return out


def parse_drive(data: Any) -> tuple[DriveTree | None, list[str]]:
    """A :class:`DriveTree` from JSON data; every problem found.

    Parameters
    ----------
    data : dict
        ``{"masses": [{"name", "inertia", "damping"}, ...], "shafts":
        [{"name", "from", "to", "stiffness", "damping"}, ...], "motors":
        [mass, ...], "load": mass}``; masses are referred to by name or
        index. Shafts without ``from``/``to`` join consecutive masses (a
        chain); ``motors`` defaults to the first mass, ``load`` to the last.

    Returns
    -------
    drive : DriveTree or None
        None if there are problems.
    problems : list of str
    """
    if not isinstance(data, Mapping):
        return None, [f"drive must be a table with 'masses' and 'shafts', got {data!r}"]
    problems: list[str] = []
    unknown = sorted(set(data) - {"masses", "shafts", "motors", "load"})
    if unknown:
        problems.append(f"drive: unknown keys {unknown}; known: masses, shafts, motors, load")
    names, inertias, dampings = _masses(data.get("masses"), problems)
    shafts = _shafts(data.get("shafts", []), names, problems)
    motors_data = data.get("motors", [0])
    if not isinstance(motors_data, list) or not 1 <= len(motors_data) <= 2:
        problems.append(f"drive: 'motors' must list one or two masses, got {motors_data!r}")
        motors_data = [0]
    motors = (
        tuple(_index(m, names, "drive 'motors'", problems) for m in motors_data) if names else (0,)
    )
    load = _index(data.get("load", -1), names, "drive 'load'", problems) if names else 0
    if problems:
        return None, problems
    tree = DriveTree(tuple(inertias), tuple(dampings), tuple(shafts), tuple(names), motors, load)
    problems = tree.problems()
    return (None, problems) if problems else (tree, [])

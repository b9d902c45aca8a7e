"""Elastic multi-mass drive trains (SPEC section 8, paper 002).

A drive train is a *chain* of rotating masses joined by elastic shafts:
the motor rotor is mass 0, the winch drum is the last mass. Every quantity
is reduced to the drum shaft through the speed ratios of a gearbox, so the
chain is one set of ordinary 1-D rotational equations:

* mass ``k``: inertia ``J_k`` (kg m^2) and a viscous damper to the ground
  ``beta_k`` (N m s/rad: bearing and windage losses);
* shaft between ``k`` and ``k + 1``: stiffness ``c`` (N m/rad) and internal
  damping ``beta`` (N m s/rad), a Kelvin-Voigt link.

Mechanical impedances (torque over angular velocity, Laplace operator
``p``, paper 002): a mass ``Z_k = J_k p + beta_k``, a shaft
``Z_k,k+1 = c/p + beta``. The chain's equations are::

    M - Z12 (w1 - w2) = Z1 w1
    Z_{k-1,k}(w_{k-1} - w_k) - Z_{k,k+1}(w_k - w_{k+1}) = Z_k w_k
    Z_{n-1,n}(w_{n-1} - w_n) - M_c = Z_n w_n

Reduction through a gearbox
---------------------------
An element that turns ``ratio`` times as fast as the drum (ratio = its
speed / drum speed, a positive magnitude) appears on the drum shaft with
``J ratio^2``, ``c ratio^2``, ``beta ratio^2``; a torque ``M`` on it acts
as ``M ratio``; its angle is the drum-shaft angle times ``ratio``. The
gear mesh itself is rigid: a gearbox is a mass (its gears lumped) between
two shafts with different ratios.

Mass elimination (delta-star, paper 002)
----------------------------------------
Eliminating interior mass ``k`` between ``k-1`` and ``k+1`` with
compliances ``e = 1/c`` and ``S = e_{k-1,k} + e_{k,k+1}``::

    J'_{k-1} = J_{k-1} + J_k e_{k,k+1}/S      J'_{k+1} = J_{k+1} + J_k e_{k-1,k}/S
    b'_{k-1} = b_{k-1} + b_k e_{k,k+1}/S      b'_{k+1} = b_{k+1} + b_k e_{k-1,k}/S
    e' = S
    b'_link = (b_{k-1,k} e_{k-1,k} + b_{k,k+1} e_{k,k+1})/S
              - e_{k-1,k} e_{k,k+1} (b_{k-1,k} + b_k + b_{k,k+1})/S^2

(the SPEC's reconstruction of the garbled print). It is exact in the
quasi-static limit: with ``J_k = 0`` and ``b_k = 0`` the two shafts are a
series spring and the reduced chain has exactly the full chain's
frequencies. The last line can make a link damping negative when a mass
damper is eliminated; the chain's total dissipation ``w^T B w`` stays
non-negative (it is the star's own dissipation), which is what the energy
ledger books.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.linalg import eigvalsh_tridiagonal

__all__ = [
    "ChainElement",
    "DriveChain",
    "parse_drive_train",
    "default_drive_train",
]


@dataclass(frozen=True)
class ChainElement:
    """One mass or one shaft of a drive train, in its own shaft's units.

    Parameters
    ----------
    name : str
        For messages, e.g. ``"motor rotor"``.
    value : float
        Inertia (kg m^2) of a mass or stiffness (N m/rad) of a shaft.
    damping : float
        Viscous damping to the ground (mass) or internal (shaft), N m s/rad.
    ratio : float
        Speed of this element over the drum's speed (> 0).
    """

    name: str
    value: float
    damping: float = 0.0
    ratio: float = 1.0

    @property
    def reduced_value(self) -> float:
        """Inertia or stiffness reduced to the drum shaft."""
        return self.value * self.ratio**2

    @property
    def reduced_damping(self) -> float:
        """Damping reduced to the drum shaft, N m s/rad."""
        return self.damping * self.ratio**2


@dataclass(frozen=True)
class DriveChain:
    """An n-mass chain, every quantity reduced to the drum shaft.

    Parameters
    ----------
    inertias : tuple of float, length n
        ``J_k``, kg m^2 (all > 0).
    dampings : tuple of float, length n
        Ground dampers ``beta_k``, N m s/rad.
    stiffnesses : tuple of float, length n - 1
        Shaft stiffnesses ``c_k,k+1``, N m/rad (all > 0).
    link_dampings : tuple of float, length n - 1
        Shaft dampings ``beta_k,k+1``, N m s/rad.
    names : tuple of str, length n
        Names of the masses (an eliminated mass's name is dropped).
    motor_ratio : float
        Speed of the motor rotor over the drum's speed (the motor acts on
        mass 0 with ``motor_ratio`` times its own torque).
    """

    inertias: tuple[float, ...]
    dampings: tuple[float, ...]
    stiffnesses: tuple[float, ...]
    link_dampings: tuple[float, ...]
    names: tuple[str, ...]
    motor_ratio: float = 1.0

    # ------------------------------------------------------------ building
    @classmethod
    def from_elements(
        cls, masses: Sequence[ChainElement], shafts: Sequence[ChainElement]
    ) -> DriveChain:
        """Reduce masses and shafts (own units, own ratios) to the drum shaft.

        Parameters
        ----------
        masses : sequence of ChainElement
            The masses from the motor rotor to the drum, each in its own units
            with its speed ratio to the drum.
        shafts : sequence of ChainElement
            The shafts between consecutive masses, likewise.

        Returns
        -------
        DriveChain
            Inertias, dampings and stiffnesses reduced to the drum shaft.
        """
        return cls(
            tuple(m.reduced_value for m in masses),
            tuple(m.reduced_damping for m in masses),
            tuple(s.reduced_value for s in shafts),
            tuple(s.reduced_damping for s in shafts),
            tuple(m.name for m in masses),
            masses[0].ratio,
        )

    @property
    def n(self) -> int:
        """Number of masses."""
        return len(self.inertias)

    # ------------------------------------------------------------ reduction
    def eliminate(self, k: int) -> DriveChain:
        """The chain without interior mass ``k`` (delta-star, module docstring).

        Parameters
        ----------
        k : int
            Index of an interior mass, ``0 < k < n - 1``.
        """
        if not 0 < k < self.n - 1:
            raise ValueError(f"only interior masses can be eliminated (1..{self.n - 2}), got {k}")
        j, b = list(self.inertias), list(self.dampings)
        c, bl = list(self.stiffnesses), list(self.link_dampings)
        e_left, e_right = 1.0 / c[k - 1], 1.0 / c[k]
        s = e_left + e_right
        j[k - 1] += j[k] * e_right / s
        j[k + 1] += j[k] * e_left / s
        b[k - 1] += b[k] * e_right / s
        b[k + 1] += b[k] * e_left / s
        link = (bl[k - 1] * e_left + bl[k] * e_right) / s - e_left * e_right * (
            bl[k - 1] + self.dampings[k] + bl[k]
        ) / s**2
        c[k - 1 : k + 1] = [1.0 / s]
        bl[k - 1 : k + 1] = [link]
        del j[k], b[k]
        names = self.names[:k] + self.names[k + 1 :]
        return DriveChain(tuple(j), tuple(b), tuple(c), tuple(bl), names, self.motor_ratio)

    def rigid(self) -> DriveChain:
        """All masses locked together: one mass, every inertia and ground damper summed."""
        return DriveChain(
            (math.fsum(self.inertias),),
            (math.fsum(self.dampings),),
            (),
            (),
            (" + ".join(self.names),),
            self.motor_ratio,
        )

    def reduced(self, masses: int) -> DriveChain:
        """The chain reduced to ``masses`` masses (0: keep the full chain).

        Interior masses are eliminated smallest inertia first (they carry
        the highest frequencies); motor and drum are never eliminated.
        ``masses = 1`` gives :meth:`rigid`.

        Parameters
        ----------
        masses : int
            Masses to keep, 0 (all) or 1 .. ``n``.
        """
        if masses == 0 or masses >= self.n:
            return self
        if masses == 1:
            return self.rigid()
        if masses < 0:
            raise ValueError(f"a chain cannot have {masses} masses")
        chain = self
        while chain.n > masses:
            interior = range(1, chain.n - 1)
            chain = chain.eliminate(min(interior, key=lambda i: chain.inertias[i]))
        return chain

    # ------------------------------------------------------------ matrices
    def mass_matrix(self) -> np.ndarray:
        """Diagonal inertia matrix, kg m^2, shape (n, n)."""
        return np.diag(self.inertias)

    def stiffness_matrix(self) -> np.ndarray:
        """Tridiagonal stiffness matrix ``K``, N m/rad: shaft torques are ``-K theta``."""
        return _laplacian(self.stiffnesses, np.zeros(self.n))

    def damping_matrix(self) -> np.ndarray:
        """Tridiagonal damping matrix ``B`` (shafts and ground), N m s/rad."""
        return _laplacian(self.link_dampings, np.asarray(self.dampings, dtype=float))

    # ------------------------------------------------------------ frequencies
    def natural_frequencies(self) -> np.ndarray:
        """Undamped natural frequencies, rad/s, ascending (the first is 0: free rotation).

        Solved as the symmetric tridiagonal problem ``M^-1/2 K M^-1/2``.
        """
        if self.n == 1:
            return np.zeros(1)
        inv_sqrt = 1.0 / np.sqrt(self.inertias)
        k = self.stiffness_matrix()
        diag = np.diag(k) * inv_sqrt**2
        off = np.diag(k, 1) * inv_sqrt[:-1] * inv_sqrt[1:]
        eig = eigvalsh_tridiagonal(diag, off)
        return np.sqrt(np.clip(eig, 0.0, None))

    def mass_impedance(self, k: int, omega: complex) -> complex:
        """``Z_k = J_k p + beta_k`` at ``p = j omega``, N m s/rad.

        Parameters
        ----------
        k : int
            The mass, from 0 (the motor rotor) to ``n - 1`` (the drum).
        omega : float
            Angular frequency, rad/s.
        """
        return self.inertias[k] * 1j * omega + self.dampings[k]

    def link_impedance(self, k: int, omega: complex) -> complex:
        """``Z_k,k+1 = c/p + beta`` at ``p = j omega``, N m s/rad.

        Parameters
        ----------
        k : int
            The shaft between masses ``k`` and ``k + 1``.
        omega : float
            Angular frequency, rad/s.
        """
        return self.stiffnesses[k] / (1j * omega) + self.link_dampings[k]

    def input_impedance(self, omega: float) -> complex:
        """``Z_in(j omega) = M / w_1`` with no load torque, N m s/rad (reduced).

        Folded from the drum end as a ladder: ``Z = Z_k + (Z_link Z_next) /
        (Z_link + Z_next)``; for two masses this is paper 002's
        ``(Z1 Z2 + Z1 Z12 + Z12 Z2) / (Z2 + Z12)``. ``1 / Z_in`` is the
        frequency response from motor torque to motor speed.

        Parameters
        ----------
        omega : float
            Angular frequency, rad/s.
        """
        z = self.mass_impedance(self.n - 1, omega)
        for k in range(self.n - 2, -1, -1):
            link = self.link_impedance(k, omega)
            z = self.mass_impedance(k, omega) + link * z / (link + z)
        return z

    def output_impedance(self, omega: float) -> complex:
        """``Z_out(j omega) = M_c / w_n`` with no motor torque, N m s/rad (reduced).

        Parameters
        ----------
        omega : float
            Angular frequency, rad/s.
        """
        z = self.mass_impedance(0, omega)
        for k in range(1, self.n):
            link = self.link_impedance(k - 1, omega)
            z = self.mass_impedance(k, omega) + link * z / (link + z)
        return z

    def speeds_per_torque(self, omega: float) -> np.ndarray:
        """Speed of every mass per unit motor torque at ``j omega`` (complex, rad/s/(N m)).

        Solves ``(j omega M + B + K / (j omega)) w = e_0`` directly; entry 0
        is ``1 / Z_in``, the last the transfer to the drum.

        Parameters
        ----------
        omega : float
            Angular frequency, rad/s.

        Returns
        -------
        ndarray of complex, shape (n,)
            Speed of each mass per N m of motor torque, rad/s/(N m).
        """
        p = 1j * omega
        system = p * self.mass_matrix() + self.damping_matrix() + self.stiffness_matrix() / p
        rhs = np.zeros(self.n, dtype=complex)
        rhs[0] = 1.0
        return np.linalg.solve(system, rhs)


def _laplacian(links: Sequence[float], ground: np.ndarray) -> np.ndarray:
    """Tridiagonal matrix of a chain of links plus ground terms on the diagonal."""
    n = ground.size
    out = np.diag(ground.astype(float))
    for k, value in enumerate(links):
        out[k, k] += value
        out[k + 1, k + 1] += value
        out[k, k + 1] -= value
        out[k + 1, k] -= value
    assert out.shape == (n, n)
    return out


# ---------------------------------------------------------------- parsing
def default_drive_train() -> dict[str, Any]:
    """A 1500-2000 hp drawworks: AC motor, gearbox, drum (estimated values).

    Order-of-magnitude estimates, not a datasheet: a 1150 hp AC drilling
    motor rotor (~12 kg m^2) turning 6 times as fast as the drum; the
    gearbox's bull gear and output shaft (~150 kg m^2 at drum speed); a
    0.8 m x 1.5 m grooved drum with its brake rims (~1200 kg m^2, steel
    shell and rims of about 3.5 t at radii of 0.4-0.65 m). Shaft
    stiffnesses are those of a flexible motor coupling (2e5 N m/rad at
    motor speed) and a 0.25 m solid drum-shaft stub (about 1.5e7 N m/rad);
    dampings are a few per cent of critical.
    """
    return {
        "masses": [
            {"name": "motor rotor", "inertia": 12.0, "damping": 2.0, "ratio": 6.0},
            {"name": "gearbox", "inertia": 150.0, "damping": 20.0, "ratio": 1.0},
            {"name": "drum", "inertia": 1200.0, "damping": 50.0, "ratio": 1.0},
        ],
        "shafts": [
            {"name": "motor coupling", "stiffness": 2.0e5, "damping": 60.0, "ratio": 6.0},
            {"name": "drum shaft", "stiffness": 1.5e7, "damping": 3.0e3, "ratio": 1.0},
        ],
    }


def _number(
    item: Mapping[str, Any],
    key: str,
    default: float | None,
    where: str,
    problems: list[str],
    positive: bool,
) -> float:
    value = item.get(key, default)
    try:
        number = float(value)
    except (TypeError, ValueError):
        problems.append(f"{where}: {key!r} must be a number, got {value!r}")
        return math.nan
    ok = number > 0.0 if positive else number >= 0.0
    if not (ok and math.isfinite(number)):
        bound = "> 0" if positive else ">= 0"
        problems.append(f"{where}: {key!r} must be finite and {bound}, got {value!r}")
    return number


def _elements(data: Any, kind: str, key: str, problems: list[str]) -> list[ChainElement]:
    if not isinstance(data, list):
        problems.append(f"drive train: {kind!r} must be a list, got {type(data).__name__}")
        return []
    out = []
    for i, item in enumerate(data):
        where = f"drive train {kind}[{i}]"
        if not isinstance(item, Mapping):
            problems.append(f"{where} must be an object")
            continue
        where = f"{where} ({item.get('name', '?')!r})"
        unknown = sorted(set(item) - {"name", key, "damping", "ratio"})
        if unknown:
            problems.append(f"{where}: unknown keys {unknown}; known: name, {key}, damping, ratio")
        value = _number(item, key, None, where, problems, positive=True)
        damping = _number(item, "damping", 0.0, where, problems, positive=False)
        ratio = _number(item, "ratio", 1.0, where, problems, positive=True)
        out.append(ChainElement(str(item.get("name", f"{kind} {i}")), value, damping, ratio))
    return out


def parse_drive_train(data: Any) -> tuple[DriveChain | None, list[str]]:
    """A :class:`DriveChain` from JSON data; every problem found.

    Parameters
    ----------
    data : dict
        ``{"masses": [{"name", "inertia", "damping", "ratio"}, ...],
        "shafts": [{"name", "stiffness", "damping", "ratio"}, ...]}``, masses
        from the motor rotor to the drum, one shaft between consecutive
        masses; ``damping`` defaults to 0, ``ratio`` (speed over the drum's
        speed) to 1. The drum (last mass) must have ratio 1.

    Returns
    -------
    chain : DriveChain or None
        None if there are problems.
    problems : list of str
    """
    problems: list[str] = []
    if not isinstance(data, Mapping):
        return None, [f"drive train must be an object with 'masses' and 'shafts', got {data!r}"]
    unknown = sorted(set(data) - {"masses", "shafts"})
    if unknown:
        problems.append(f"drive train: unknown keys {unknown}; known: masses, shafts")
    masses = _elements(data.get("masses"), "masses", "inertia", problems)
    shafts = _elements(data.get("shafts", []), "shafts", "stiffness", problems)
    if not masses and not problems:
        problems.append("drive train: at least one mass (the drum) is required")
    if masses and len(shafts) != len(masses) - 1:
        problems.append(
            f"drive train: {len(masses)} masses need {len(masses) - 1} shafts, got {len(shafts)}"
        )
    if masses and math.isfinite(masses[-1].ratio) and masses[-1].ratio != 1.0:
        problems.append(
            f"drive train: the drum (last mass, {masses[-1].name!r}) must have ratio 1, "
            f"got {masses[-1].ratio}"
        )
    if problems:
        return None, problems
    return DriveChain.from_elements(masses, shafts), []

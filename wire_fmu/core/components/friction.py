"""Dry friction that really sticks, for 1-D coordinates with lumped masses.

Bearing friction of a sheave, rope slip on a groove, the band brake and
cylinder seals are all *friction links* between a coordinate and the ground
or between two coordinates. Each link is either *stuck* (no relative
motion; the link carries whatever force holds it, up to its capacity) or
*sliding* in a direction ``+1``/``-1`` (it carries its capacity against the
motion). This is the Karnopp idea made exact with modes: while stuck, the
relative velocity is not merely small, it is zero, and a stuck coordinate
does not creep.

The force a stuck link must carry is computed from the known net forces,
which is what makes holding exact and breakaway happen exactly at capacity.
Transitions are guards for :mod:`wire_fmu.core.framework.hybrid`:

* stuck link: ``capacity - |holding force|`` goes negative -> breakaway;
* sliding link: ``direction * relative velocity`` goes negative -> the
  motion stops; the link sticks if its capacity can hold, else it slides on
  the other way.

Sign convention: a link force is the force *on* ``body`` (its partner
``other`` receives the opposite); relative velocity is
``v[body] - v[other]`` (``other = -1`` is the ground).

Capacities may depend on direction (a band brake is self-energising one
way only): pass them with shape ``(n_links, 2)``, column 0 opposing
positive relative motion and column 1 opposing negative relative motion,
or with shape ``(n_links,)`` when both are equal. A link may also slide
with a force other than its static capacity (Stribeck friction): pass the
sliding magnitudes separately, in the same shape.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["FrictionLink", "StickSlip", "GROUND"]

GROUND = -1
PLANS_KEPT = 256
"""Stuck-group plans a :class:`StickSlip` keeps, one per distinct mode it has seen."""


def _by_direction(capacities: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(capacity against positive motion, capacity against negative motion)."""
    caps = np.asarray(capacities, dtype=float)
    if caps.ndim == 2:
        return caps[:, 0], caps[:, 1]
    return caps, caps


def _against(caps: tuple[np.ndarray, np.ndarray], k: int, direction: float) -> float:
    """Capacity of link ``k`` against motion in ``direction`` (+1 or -1)."""
    return caps[0][k] if direction > 0 else caps[1][k]


@dataclass(frozen=True)
class FrictionLink:
    """A dry-friction contact between coordinate ``body`` and ``other``.

    Parameters
    ----------
    name : str
        Human-readable name used in messages, e.g. ``"sheave 'crown_1' bearing"``.
    body : int
        Index of the coordinate the link force acts on.
    other : int
        Index of the partner coordinate, or -1 for the ground.
    """

    name: str
    body: int
    other: int = GROUND


class StickSlip:
    """Mode bookkeeping and accelerations for a set of friction links.

    Parameters
    ----------
    masses : array_like, shape (n,)
        Mass (or rotational inertia) of each coordinate, kg (kg m^2).
    links : sequence of FrictionLink
        The friction links; stuck links must never form a cycle.
    """

    def __init__(self, masses: np.ndarray, links: tuple[FrictionLink, ...]) -> None:
        self.masses = np.asarray(masses, dtype=float)
        self.links = tuple(links)
        self.mode = np.zeros(len(self.links), dtype=np.int64)  # all stuck at rest
        self._mass_list = self.masses.tolist()
        self._plans: dict[bytes, list] = {}  # by mode: modes recur as links stick and slip
        self._arrays = None

    # -- state ---------------------------------------------------------------
    def get_mode(self) -> list[int]:
        """The modes as plain ints (0 stuck, +1/-1 sliding direction)."""
        return [int(m) for m in self.mode]

    def set_mode(self, mode: Sequence[int] | np.ndarray) -> None:
        """Restore modes saved by :meth:`get_mode` (or a copy of :attr:`mode`).

        Parameters
        ----------
        mode : sequence of int
            Per link: 0 stuck, +1 or -1 the sliding direction.
        """
        self.mode = np.array(mode, dtype=np.int64)

    # -- dynamics --------------------------------------------------------------
    def relative_velocity(self, v: np.ndarray, k: int) -> float:
        """Relative velocity of link ``k``, m/s (or rad/s).

        Parameters
        ----------
        v : ndarray
            Velocities of the bodies, m/s (or rad/s).
        k : int
            The link.
        """
        link = self.links[k]
        rel = v[link.body]
        if link.other != GROUND:
            rel -= v[link.other]
        return rel

    def accelerations(
        self,
        forces: np.ndarray,
        capacities: np.ndarray,
        mode: np.ndarray | None = None,
        sliding: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Accelerations and link forces in the current mode.

        Parameters
        ----------
        forces : ndarray, shape (n,)
            All non-friction forces on each coordinate, N (or N m).
        capacities : ndarray, shape (n_links,) or (n_links, 2)
            Static friction capacity of each link (>= 0), N (or N m); see
            the module docstring for direction-dependent capacities.
        mode : ndarray, optional
            Modes to use instead of the current ones.
        sliding : ndarray, optional
            Friction magnitude while sliding (default: the capacities).

        Returns
        -------
        acc : ndarray, shape (n,)
            Accelerations, m/s^2 (or rad/s^2).
        link_force : ndarray, shape (n_links,)
            Force each link exerts on its ``body``: the holding force of a
            stuck link, ``-direction * capacity`` of a sliding one.
        """
        mode = self.mode if mode is None else mode
        slide = _by_direction(capacities if sliding is None else sliding)
        total = np.array(forces, dtype=float)
        link_force = np.zeros(len(self.links))
        for k, link in enumerate(self.links):
            if mode[k] != 0:
                f = -mode[k] * _against(slide, k, mode[k])
                link_force[k] = f
                total[link.body] += f
                if link.other != GROUND:
                    total[link.other] -= f
        acc = total / self.masses
        plan = self._plan_for(mode)
        forces_on = total.tolist()  # plain floats: a group is a handful of coordinates
        masses = self._mass_list
        for members, grounded, edges in plan:
            if grounded:
                a = 0.0
            else:
                a = sum(forces_on[i] for i in members) / sum(masses[i] for i in members)
            required = {}
            for i in members:
                acc[i] = a
                required[i] = masses[i] * a - forces_on[i]
            for k, child, parent in edges:  # leaves first
                carried = required[child]
                link_force[k] = carried if self.links[k].body == child else -carried
                if parent != GROUND:
                    required[parent] += carried
        return acc, link_force

    def loss_power(self, v: np.ndarray, link_force: np.ndarray) -> float:
        """Power dissipated by the sliding links, W (>= 0 while the modes hold).

        Parameters
        ----------
        v : ndarray
            Velocities.
        link_force : ndarray
            Link forces from :meth:`accelerations`.
        """
        total = 0.0
        for k in range(len(self.links)):
            if self.mode[k] != 0:
                total -= link_force[k] * self.relative_velocity(v, k)
        return total

    def guards(self, v: np.ndarray, link_force: np.ndarray, capacities: np.ndarray) -> np.ndarray:
        """Guard values per link (see module docstring); all >= 0 inside the mode.

        Parameters
        ----------
        v : ndarray
            Velocities of the bodies, m/s (or rad/s).
        link_force : ndarray
            Force (N, or torque N m) each link transmits in its mode.
        capacities : ndarray, shape (n_links,) or (n_links, 2)
            Friction capacity of each link, N (or N m); two columns for
            capacities against positive and negative motion.
        """
        caps = _by_direction(capacities)
        g = np.empty(len(self.links))
        for k in range(len(self.links)):
            if self.mode[k] == 0:
                g[k] = _holding_margin(caps, k, link_force[k])
            else:
                g[k] = self.mode[k] * self.relative_velocity(v, k)
        return g

    def switch(
        self,
        v: np.ndarray,
        forces: np.ndarray,
        capacities: np.ndarray,
        fired: list[int],
    ) -> np.ndarray:
        """Change the modes of the links in ``fired``; return projected velocities.

        A sliding link whose motion stopped is set to zero relative velocity
        (momentum conserving) and sticks if it can hold; a stuck link that
        cannot hold starts sliding in the direction the net force drives it.
        The modes of all links are then made consistent with each other.

        Parameters
        ----------
        v : ndarray
            Velocities of the bodies, m/s (or rad/s).
        forces : ndarray
            All forces on the bodies but the links' friction, N (or N m).
        capacities : ndarray, shape (n_links,) or (n_links, 2)
            Friction capacity of each link, N (or N m); two columns for
            capacities against positive and negative motion.
        fired : list of int
            Links whose guard fired.

        Returns
        -------
        ndarray
            The velocities with stuck links at zero relative velocity.
        """
        v = np.array(v, dtype=float)
        for k in fired:
            if self.mode[k] != 0:
                v = self._stop(v, k)
                self.mode[k] = 0
        for _ in range(2 * len(self.links) + 1):
            _, link_force = self.accelerations(forces, capacities)
            caps = _by_direction(capacities)
            margin = {
                k: _holding_margin(caps, k, link_force[k])
                for k in range(len(self.links))
                if self.mode[k] == 0
            }
            over = [k for k, m in margin.items() if m < 0.0]
            if not over:
                break
            worst = min(over, key=lambda k: margin[k])
            self.mode[worst] = -1 if link_force[worst] > 0 else 1
        return v

    def _stop(self, v: np.ndarray, k: int) -> np.ndarray:
        link = self.links[k]
        if link.other == GROUND:
            v[link.body] = 0.0
        else:
            m1, m2 = self.masses[link.body], self.masses[link.other]
            common = (m1 * v[link.body] + m2 * v[link.other]) / (m1 + m2)
            v[link.body] = v[link.other] = common
        return v

    def stuck_to_ground(self) -> np.ndarray:
        """Indices of coordinates held by stuck links to the ground."""
        held = []
        for members, grounded, _ in self._plan_for(self.mode):
            if grounded:
                held.extend(members)
        return np.array(sorted(held), dtype=int)

    def plan_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The groups of coordinates joined by stuck links, as flat integer arrays.

        The same plan :meth:`accelerations` follows, for compiled kernels; made
        again only after the modes change.

        Returns
        -------
        clusters : numpy.ndarray, shape (n_groups, 5)
            Per group: first and end index into ``members``, first and end index
            into ``edges``, 1 if the group is held by the ground.
        members : numpy.ndarray
            The groups' coordinates, each group sorted.
        edges : numpy.ndarray, shape (n_stuck, 3)
            Per stuck link: the link, the child and the parent coordinate (-1: the
            ground), leaves first within each group.
        grounded : numpy.ndarray
            The coordinates held to the ground, sorted (:meth:`stuck_to_ground`).
        """
        plan = self._plan_for(self.mode)
        if self._arrays is not None and self._arrays[0] is plan:
            return self._arrays[1]
        clusters = np.zeros((len(plan), 5), dtype=np.int64)
        members: list[int] = []
        edges: list[tuple[int, int, int]] = []
        for c, (group, grounded, group_edges) in enumerate(plan):
            clusters[c] = len(members), len(members) + len(group), len(edges), 0, int(grounded)
            members.extend(int(i) for i in group)
            edges.extend(group_edges)
            clusters[c, 3] = len(edges)
        arrays = (
            clusters,
            np.array(members, dtype=np.int64),
            np.array(edges, dtype=np.int64).reshape(len(edges), 3),
            self.stuck_to_ground().astype(np.int64),
        )
        self._arrays = (plan, arrays)
        return arrays

    # -- structure of the stuck links -----------------------------------------
    def _plan_for(self, mode: np.ndarray):
        """The stuck groups for ``mode``, made once per distinct mode (at most
        :data:`PLANS_KEPT` kept)."""
        key = mode.tobytes()
        plan = self._plans.get(key)
        if plan is None:
            if len(self._plans) >= PLANS_KEPT:
                self._plans.clear()
            plan = self._plans[key] = _stuck_clusters(self.links, mode)
        return plan


def _holding_margin(caps, k: int, holding: float) -> float:
    """Capacity left when link ``k`` holds ``holding`` (force on its body).

    A negative holding force stops positive motion, so it is compared with
    the capacity against positive motion, and vice versa.
    """
    return _against(caps, k, -holding if holding != 0.0 else 1.0) - abs(holding)


def _stuck_clusters(links: tuple[FrictionLink, ...], mode: np.ndarray):
    """Group coordinates joined by stuck links into trees.

    Returns a list of ``(members, grounded, edges)``; ``edges`` lists
    ``(link index, child, parent)`` from the leaves towards the root
    (the ground when the cluster is grounded).
    """
    adjacency: dict[int, list[tuple[int, int]]] = {}
    for k, link in enumerate(links):
        if mode[k] == 0:
            adjacency.setdefault(link.body, []).append((k, link.other))
            adjacency.setdefault(link.other, []).append((k, link.body))
    seen: set[int] = set()
    clusters = []
    roots = ([GROUND] if GROUND in adjacency else []) + sorted(n for n in adjacency if n != GROUND)
    for root in roots:
        if root in seen:
            continue
        order: list[tuple[int, int, int]] = []
        stack = [(root, None)]
        seen.add(root)
        while stack:
            node, via = stack.pop()
            for k, nxt in adjacency.get(node, []):
                if k == via:
                    continue
                if nxt in seen:
                    raise ValueError("stuck friction links form a cycle")
                seen.add(nxt)
                order.append((k, nxt, node))
                stack.append((nxt, k))
        members = sorted({c for _, c, _ in order} | ({root} - {GROUND}))
        clusters.append((members, root == GROUND, list(reversed(order))))
    return clusters

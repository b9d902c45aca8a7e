"""The rope's path through a block train: nodes, rope coordinates, spans and their lengths.

Along the path, node ``k`` joins segment ``k-1`` to segment ``k``; nodes that
carry a rope coordinate (line ends, and sheaves with inertia) split the rope
into *spans*, each one spring. The lengths of the segments follow from the
tangent-point geometry of :mod:`~wire_fmu.core.components.sheave_geometry`
as the bodies move (effect ``moving_geometry``), by a fast planar path where
the reeving is planar. :class:`ReevedPath` is the part of
:class:`~wire_fmu.core.units.block_train.model.BlockTrainModel` that builds
and evaluates all this.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wire_fmu.core.components.sheave_geometry.circles import Circle, PathNode
from wire_fmu.core.components.sheave_geometry.path import path_geometry
from wire_fmu.core.components.sheave_geometry.planar_path import planar_frame, planar_path_lengths
from wire_fmu.core.errors import ConfigurationError

__all__ = ["ReevedPath", "LARGE_WRAP"]

LARGE_WRAP = math.radians(200.0)
"""Wrap angle above which a sheave's wrap is warned of, rad.

In one plane a rope turning round a sheave by theta > 180 deg crosses itself: the span
leaving it meets the span coming in r |tan(theta / 2)| from where that one touches the
sheave (5.7 r at 200 deg, 2.7 r at the 221 deg of a riser tensioner's fixed sheave given
``wrap = "cw"`` instead of "ccw", r at 270 deg), far closer than the spans of a block train
are long. A sheave of a plain reeving turns the rope by at most 180 deg (a U-turn between
two blocks); 200 deg leaves room for round-off and small fleet angles. A wrap direction
given the wrong way round sends the rope round the other side, 360 deg less the turn
meant. A capstan, whose rope leaves the plane groove by groove, may wrap further on
purpose, so this is a warning, not a problem."""


@dataclass(frozen=True)
class _Span:
    """Consecutive segments between two nodes that carry rope coordinates."""

    segments: tuple[int, ...]
    start_node: int
    end_node: int


class ReevedPath:
    """Nodes, coordinates, spans and segment lengths of a reeving (a mixin of the model).

    The model provides ``reeving``, ``effects`` and ``GEOMETRY_STEP``.
    """

    def _build_nodes(self) -> None:
        r = self.reeving
        self.nodes = r.path
        self.n_nodes = len(r.path)
        self.n_segments = self.n_nodes - 1

    def _build_coordinates(self) -> None:
        """Coordinates: blocks, then sheave rims, then rope on grooves (slip)."""
        r, fx = self.reeving, self.effects
        self.blocks = r.bodies_of_kind("block")
        self.drivers = r.bodies_of_kind("driven")
        masses = [b.mass for b in self.blocks]
        self.block_index = {b.name: i for i, b in enumerate(self.blocks)}
        self.rim_index: dict[int, int] = {}
        self.rope_index: dict[int, int] = {}  # node -> coordinate carrying its rope
        inertia = "sheave_inertia" in fx
        slip = "rope_slip" in fx
        for k, node in enumerate(self.nodes):
            if node.kind != "sheave" or not inertia:
                continue
            sheave = r.sheaves[node.name]
            self.rim_index[k] = len(masses)
            masses.append(sheave.inertia / sheave.radius**2)
        if slip:
            for k in list(self.rim_index):
                self.rope_index[k] = len(masses)
                masses.append(math.nan)  # set once wrap angles are known
        else:
            self.rope_index = dict(self.rim_index)
        self.masses = np.array(masses, dtype=float)
        self.n_coords = len(masses)
        self.body_dof = [b.name for b in self.blocks] + [b.name for b in self.drivers]

    def _build_spans(self) -> None:
        flow_nodes = [k for k, n in enumerate(self.nodes) if n.kind != "sheave"] + list(
            self.rope_index
        )
        flow_nodes = sorted(set(flow_nodes))
        spans = []
        for a, b in zip(flow_nodes[:-1], flow_nodes[1:], strict=True):
            spans.append(_Span(tuple(range(a, b)), a, b))
        self.spans = tuple(spans)
        self.span_of_segment = {}
        for i, sp in enumerate(self.spans):
            for k in sp.segments:
                self.span_of_segment[k] = i

    def _node_circle(self, k: int, displacement: dict[str, float]) -> tuple[Circle, int]:
        r = self.reeving
        node = self.nodes[k]
        shift = np.zeros(3)
        for name in r.carriers(r.node_body(node)):
            shift += np.array(r.bodies[name].direction) * displacement.get(name, 0.0)
        if node.kind == "sheave":
            s = r.sheaves[node.name]
            centre = tuple(np.array(s.centre) + shift)
            return Circle(s.name, centre, s.axis, s.radius), node.sense
        point = r.anchors[node.name].point if node.kind == "anchor" else node.point
        axis = (0.0, 0.0, 1.0)
        return Circle(f"{node.kind} {node.name!r}", tuple(np.array(point) + shift), axis, 0.0), 0

    def path_nodes(self, displacement: dict[str, float]) -> list[PathNode]:
        """Geometric path nodes for given body displacements (m).

        Parameters
        ----------
        displacement : dict of str to float
            Displacement of each body along its direction, m (absent bodies: 0).
        """
        return [PathNode(*self._node_circle(k, displacement)) for k in range(self.n_nodes)]

    def _segment_lengths(self, displacement: dict[str, float], validate: bool = False):
        geo = path_geometry(
            self.path_nodes(displacement),
            max_fleet_angle=self.reeving.max_fleet_angle,
            validate=validate,
        )
        half_arcs = np.zeros(self.n_segments)
        for j, arc in enumerate(geo.arc_lengths):  # interior node j + 1
            half_arcs[j] += 0.5 * arc
            half_arcs[j + 1] += 0.5 * arc
        return np.asarray(geo.lengths) + half_arcs, geo

    def _build_geometry(self) -> None:
        """Initial geometry; the linear length model for fixed line directions."""
        try:
            lengths, geo = self._segment_lengths({}, validate=True)
        except ConfigurationError as err:
            raise ConfigurationError("block train reeving geometry", err.problems) from None
        self.geometry0 = geo
        if "spatial_geometry" not in self.effects:
            self._require_planar(geo)
        self.wrap_angles = np.zeros(self.n_nodes)
        self.wrap_angles[1:-1] = geo.wrap_angles
        self.wrap_warnings = self._large_wraps()
        self.segment_length0 = lengths
        n_dof = len(self.body_dof)
        jac = np.zeros((self.n_segments, n_dof))
        dirs = np.asarray(geo.directions)
        for b, name in enumerate(self.body_dof):
            d = np.array(self.reeving.bodies[name].direction)
            for k in range(self.n_segments):
                if name in self.reeving.carriers(self.reeving.node_body(self.nodes[k + 1])):
                    jac[k, b] += dirs[k] @ d
                if name in self.reeving.carriers(self.reeving.node_body(self.nodes[k])):
                    jac[k, b] -= dirs[k] @ d
        self.length_jacobian0 = jac
        self.span_matrix = np.zeros((len(self.spans), self.n_segments))
        for i, sp in enumerate(self.spans):
            self.span_matrix[i, list(sp.segments)] = 1.0
        # fixed line directions: span lengths linear in the body displacements
        self.span_length0 = self.span_matrix @ self.segment_length0
        self.span_jacobian = self.span_matrix @ self.length_jacobian0
        self.moving = "moving_geometry" in self.effects
        self._planar = None
        if self.moving and "spatial_geometry" not in self.effects:
            self._build_planar_fast_path()
        self._choose_span_geometry()
        for k, idx in self.rope_index.items():
            if idx != self.rim_index[k]:
                s = self.reeving.sheaves[self.nodes[k].name]
                self.masses[idx] = self.rope.linear_mass * s.radius * self.wrap_angles[k]

    def _large_wraps(self) -> list[str]:
        """A warning for each sheave the rope wraps by more than :data:`LARGE_WRAP`.

        Returns
        -------
        list of str
            One sentence per such sheave: its name and path node, the wrap angle (deg),
            and the other wrap direction to try.
        """
        warnings = []
        for k, node in enumerate(self.nodes):
            if node.kind != "sheave" or not self.wrap_angles[k] > LARGE_WRAP:
                continue
            given, other = ("ccw", "cw") if node.sense > 0 else ("cw", "ccw")
            warnings.append(
                f"sheave {node.name!r} (path node {k}): the rope wraps it by "
                f"{math.degrees(self.wrap_angles[k]):.1f} deg, more than "
                f"{math.degrees(LARGE_WRAP):.0f} deg, so in the sheave's plane the rope "
                f"leaving it crosses the rope coming in; wrap = {given!r} may be the wrong way "
                f"round: with wrap = {other!r} the rope goes round the other side (a capstan, "
                "its rope leaving the plane, may wrap this far on purpose)"
            )
        return warnings

    def _choose_span_geometry(self) -> None:
        """Choose the span geometry the effects call for, once."""
        if not self.moving:
            self._span_geometry = self._fixed_span_lengths
            return
        planar = self._planar is not None
        self._moving_segment_lengths = (
            self._planar_segment_lengths if planar else self._spatial_segment_lengths
        )
        self._span_geometry = self._moving_span_lengths

    def _build_planar_fast_path(self) -> None:
        """2-D coordinates for recomputing a planar path cheaply as bodies move."""
        nodes = self.path_nodes({})
        frame = planar_frame(nodes, max_fleet_angle=self.reeving.max_fleet_angle)
        xy0 = [frame.project(n.circle.centre) for n in nodes]
        dof_of_node, dirs = [], []
        for b, name in enumerate(self.body_dof):
            d = self.reeving.bodies[name].direction
            dirs.append(
                (
                    sum(a * c for a, c in zip(d, frame.u, strict=True)),
                    sum(a * c for a, c in zip(d, frame.v, strict=True)),
                )
            )
            del b
        for k in range(self.n_nodes):
            carriers = self.reeving.carriers(self.reeving.node_body(self.nodes[k]))
            dof_of_node.append(tuple(self.body_dof.index(b) for b in carriers))
        self._planar = (
            xy0,
            np.array(frame.signed_radii),
            dof_of_node,
            dirs,
            tuple(n.circle.name for n in nodes),
        )

    def _planar_segment_lengths(self, y) -> np.ndarray:
        xy0, radii, dof_of_node, dirs, names = self._planar
        xy = [
            (x + sum(y[b] * dirs[b][0] for b in dofs), z + sum(y[b] * dirs[b][1] for b in dofs))
            for (x, z), dofs in zip(xy0, dof_of_node, strict=True)
        ]
        lengths, wraps = planar_path_lengths(xy, radii, names=names)
        seg = np.array(lengths)
        half_arcs = 0.5 * np.abs(radii[1:-1]) * np.array(wraps)
        seg[:-1] += half_arcs
        seg[1:] += half_arcs
        return seg

    def _require_planar(self, geo) -> None:
        fleet = np.asarray(geo.fleet_angles)
        axes = {
            tuple(np.round(self.reeving.sheaves[n.name].axis, 9))
            for n in self.nodes
            if n.kind == "sheave"
        }
        problems = []
        if fleet.size and np.max(np.abs(fleet)) > 1e-9:
            k = int(np.argmax(np.max(np.abs(fleet), axis=1)))
            problems.append(
                f"segment {k} (between {self._node_label(k)} and {self._node_label(k + 1)}) "
                f"leaves the plane (fleet angle {math.degrees(np.max(np.abs(fleet[k]))):.3f} deg); "
                "add the effect 'spatial_geometry' for a non-planar reeving"
            )
        if len({tuple(abs(c) for c in a) for a in axes}) > 1:
            problems.append("sheave axes are not all parallel; add the effect 'spatial_geometry'")
        if problems:
            raise ConfigurationError("block train", problems)

    def _node_label(self, k: int) -> str:
        node = self.nodes[k]
        return f"{node.kind} {node.name!r}"

"""Ready-made reevings, as plain data for :func:`~.block_train.reeving_parse.parse_reeving`.

Parameter sources
-----------------
Drilling line 1-1/2 in (38.1 mm), 6x19 IWRC, EIPS: metallic area about
0.40 d^2 = 5.8e-4 m^2 and an effective rope modulus of about 1.0e11 Pa give
EA = 5.8e7 N; minimum breaking force about 1.0 MN; mass about 6.2 kg/m
(manufacturers' tables for 1-1/2 in 6x19 IWRC). Sheaves: 60 in (1.524 m)
tread diameter, about 40 rope diameters as API 9B recommends for crown and
travelling blocks; a sheave of about 700 kg with most mass in the rim has
J = 0.8 m R^2 = 190 kg m^2 (estimate). Roller-bearing sheave efficiency
K = 0.9615 (the value drilling textbooks use with E = 0.81 for 10 lines).
Rope damping is chosen for about 2 % of critical damping of the hook mode.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "drilling_line",
    "drilling_block_train",
    "heave_compensated_block_train",
    "single_fall",
    "riser_tensioner",
    "tensioner_line",
]

GRAVITY = (0.0, -9.81, 0.0)


def drilling_line(damping: float = 1.2e5) -> dict[str, float]:
    """A 1-1/2 in 6x19 IWRC drilling line (see module docstring).

    Parameters
    ----------
    damping : float
        Kelvin-Voigt coefficient of the rope, N s.
    """
    return {
        "axial_stiffness": 5.8e7,
        "damping": damping,
        "breaking_load": 1.0e6,
        "linear_mass": 6.2,
    }


def drilling_block_train(
    n_lines: int = 10,
    *,
    hook_mass: float = 1.2e5,
    crown_height: float = 45.0,
    block_height: float = 15.0,
    radius: float = 0.762,
    inertia: float = 190.0,
    efficiency: float = 0.9615,
    floor: dict[str, float] | None = None,
) -> dict[str, Any]:
    """Crown block, travelling block with hook load, fast line and dead line.

    Drawn in the x-y plane (y up, sheave axes along +z) with the sheaves of
    each block unfolded side by side so that every line is vertical, the
    usual drawworks assumption. The fast line comes up from the drum at
    ``line_a``; the dead line goes down to the anchor ``deadline``.

    Parameters
    ----------
    n_lines : int
        Even number of lines between crown and travelling block.
    hook_mass : float
        Travelling block plus hook load, kg.
    crown_height, block_height : float
        Heights of the crown and travelling-block sheave centres, m.
    radius : float
        Sheave working (pitch) radius, m.
    inertia : float
        Sheave inertia about its axle, kg m^2.
    efficiency : float
        Tension ratio across one sheave when the rope moves, 1.
    floor : dict, optional
        Support the block lands on (position, stiffness, damping).
    """
    if n_lines < 2 or n_lines % 2:
        raise ValueError(f"n_lines must be an even number >= 2, got {n_lines}")
    sheaves: dict[str, dict[str, Any]] = {}
    path: list[dict[str, Any]] = [{"line_end": "line_a", "point": [-radius, 0.0, 0.0]}]
    for i in range(n_lines // 2 + 1):
        sheaves[f"crown_{i}"] = _sheave(
            "ground", 4 * i * radius, crown_height, radius, inertia, efficiency
        )
    for i in range(n_lines // 2):
        sheaves[f"travel_{i}"] = _sheave(
            "travelling_block", (4 * i + 2) * radius, block_height, radius, inertia, efficiency
        )
    for i in range(n_lines // 2):
        path.append({"sheave": f"crown_{i}", "wrap": "cw"})
        path.append({"sheave": f"travel_{i}", "wrap": "ccw"})
    path.append({"sheave": f"crown_{n_lines // 2}", "wrap": "cw"})
    path.append({"anchor": "deadline"})
    block: dict[str, Any] = {
        "kind": "block",
        "mass": hook_mass,
        "direction": [0.0, 1.0, 0.0],
        "position": block_height,
        "port": "block_a",
    }
    if floor is not None:
        block["floor"] = dict(floor)
    return {
        "name": f"{n_lines}-line drilling block train",
        "rope": drilling_line(),
        "gravity": list(GRAVITY),
        "bodies": {"travelling_block": block},
        "sheaves": sheaves,
        "anchors": {
            "deadline": {"body": "ground", "point": [(2 * n_lines) * radius + radius, 0.0, 0.0]}
        },
        "path": path,
    }


def heave_compensated_block_train(n_lines: int = 10, **kwargs: Any) -> dict[str, Any]:
    """A drilling block train whose crown block rides on compensator cylinders on a heaving deck.

    Written in the earth frame: the deck (derrick, drawworks, dead-line
    anchor) heaves through ``mover_b``; the crown block rides on the deck
    on the rods of a crown-mounted passive heave compensator, through
    ``mover_a`` (rod displacement relative to the deck, up); the travelling
    block with the hook load hangs in the rope. Keyword arguments go to
    :func:`drilling_block_train`.

    Parameters
    ----------
    n_lines : int
        Even number of lines between crown and travelling block.
    **kwargs : Any
        Further arguments of :func:`drilling_block_train` (masses in kg, lengths in m).
    """
    reeving = drilling_block_train(n_lines, **kwargs)
    reeving["name"] = f"{n_lines}-line block train with crown-mounted heave compensator"
    reeving["bodies"]["deck"] = {"kind": "driven", "direction": [0.0, 1.0, 0.0], "port": "mover_b"}
    reeving["bodies"]["crown"] = {
        "kind": "driven",
        "direction": [0.0, 1.0, 0.0],
        "port": "mover_a",
        "on": "deck",
    }
    for name, sheave in reeving["sheaves"].items():
        if name.startswith("crown"):
            sheave["body"] = "crown"
    reeving["anchors"]["deadline"]["body"] = "deck"
    reeving["path"][0]["body"] = "deck"
    return reeving


def tensioner_line() -> dict[str, float]:
    """A 2-1/4 in (57 mm) 6x41 IWRC tensioner wire: EA about 1.3e8 N, MBL about 2.8 MN,
    about 13.5 kg/m (manufacturers' tables for 2-1/4 in 6x36/6x41 IWRC); damping for a few
    per cent of critical damping of the line spans."""
    return {"axial_stiffness": 1.3e8, "damping": 2.0e5, "breaking_load": 2.8e6, "linear_mass": 13.5}


def riser_tensioner(
    *,
    radius: float = 0.75,
    cluster_gap: float = 4.0,
    guide_height: float = 14.0,
    riser_depth: float = 10.0,
    inertia: float = 250.0,
    efficiency: float = 0.98,
) -> dict[str, Any]:
    """Single wire-line riser tensioner (paper 000, Fig. 6), drawn in the x-y plane.

    Two fixed sheaves at the bottom and two moving sheaves on the rod of a
    vertical hydraulic cylinder (body ``rod``, driven through ``mover_a``,
    extension upwards) give a 4:1 reeving: the dead end is anchored at the
    bottom, the rope goes up and down between the clusters four times, then
    up over a guide sheave and down to the riser's tension ring (body
    ``riser``, driven through ``mover_b`` by the vessel's heave: its direction
    points down, so a vessel heaving up moves the ring down relative to the
    deck). Rope force on the rod (``mover_a.force``) is minus four times the
    tension; the riser tension is the tension at the path's end.

    Parameters
    ----------
    radius : float
        Sheave pitch radius, m (60 in sheaves for a 2-1/4 in wire: about
        27 rope diameters; tensioner sheaves are commonly 60-72 in).
    cluster_gap : float
        Vertical distance between fixed and moving sheave centres at mid stroke, m.
    guide_height : float
        Height of the guide sheave centre above the fixed sheaves, m.
    riser_depth : float
        Depth of the riser's tension ring below the fixed sheaves, m.
    inertia : float
        Sheave inertia, kg m^2.
    efficiency : float
        Tension ratio across one moving sheave, 1.
    """
    r = radius
    sheave = {
        "radius": r,
        "axis": [0.0, 0.0, 1.0],
        "inertia": inertia,
        "efficiency": efficiency,
        "groove_friction": 0.1,
    }
    sheaves = {
        "moving_1": {**sheave, "body": "rod", "centre": [1 * r, cluster_gap, 0.0]},
        "fixed_1": {**sheave, "body": "ground", "centre": [3 * r, 0.0, 0.0]},
        "moving_2": {**sheave, "body": "rod", "centre": [5 * r, cluster_gap, 0.0]},
        "fixed_2": {**sheave, "body": "ground", "centre": [7 * r, 0.0, 0.0]},
        "guide": {**sheave, "body": "ground", "centre": [9 * r, guide_height, 0.0]},
    }
    return {
        "name": "single wire-line riser tensioner (4:1)",
        "rope": tensioner_line(),
        "gravity": list(GRAVITY),
        "bodies": {
            "rod": {"kind": "driven", "direction": [0.0, 1.0, 0.0], "port": "mover_a"},
            "riser": {"kind": "driven", "direction": [0.0, -1.0, 0.0], "port": "mover_b"},
        },
        "sheaves": sheaves,
        "anchors": {
            "dead_end": {"body": "ground", "point": [0.0, -2.0, 0.0]},
            "tension_ring": {"body": "riser", "point": [10 * r, -riser_depth, 0.0]},
        },
        "path": [
            {"anchor": "dead_end"},
            {"sheave": "moving_1", "wrap": "cw"},
            {"sheave": "fixed_1", "wrap": "ccw"},
            {"sheave": "moving_2", "wrap": "cw"},
            {"sheave": "fixed_2", "wrap": "ccw"},
            {"sheave": "guide", "wrap": "cw"},
            {"anchor": "tension_ring"},
        ],
    }


def single_fall(
    *,
    mass: float = 1000.0,
    length: float = 10.0,
    axial_stiffness: float = 1.0e7,
    damping: float = 0.0,
    line_end: bool = True,
) -> dict[str, Any]:
    """One vertical rope from a line end (or anchor) at the top to a hanging block.

    The simplest reeving: a mass ``mass`` (kg) hangs ``length`` (m) below
    the top on a rope of stiffness ``axial_stiffness`` (N).

    Parameters
    ----------
    mass : float
        Hanging mass, kg.
    length : float
        Rope length from the top down to the block, m.
    axial_stiffness : float
        Rope axial stiffness ``EA``, N.
    damping : float
        Kelvin-Voigt coefficient of the rope, N s.
    line_end : bool
        True: the top is the line end ``line_a``; False: the anchor ``top``.
    """
    top = {"line_end": "line_a", "point": [0.0, length, 0.0]} if line_end else {"anchor": "top"}
    return {
        "name": "single fall",
        "rope": {"axial_stiffness": axial_stiffness, "damping": damping},
        "gravity": list(GRAVITY),
        "bodies": {
            "load": {
                "kind": "block",
                "mass": mass,
                "direction": [0.0, 1.0, 0.0],
                "position": 0.0,
                "port": "block_a",
            }
        },
        "sheaves": {},
        "anchors": {
            "top": {"body": "ground", "point": [0.0, length, 0.0]},
            "hook": {"body": "load", "point": [0.0, 0.0, 0.0]},
        },
        "path": [top, {"anchor": "hook"}],
    }


def _sheave(
    body: str, x: float, y: float, radius: float, inertia: float, efficiency: float
) -> dict[str, Any]:
    return {
        "body": body,
        "centre": [x, y, 0.0],
        "radius": radius,
        "axis": [0.0, 0.0, 1.0],
        "inertia": inertia,
        "efficiency": efficiency,
        "groove_friction": 0.1,
    }

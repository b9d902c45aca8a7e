"""The figures the shipped hoisting scenes state are right.

Each figure a scene's comments or description give is computed here independently:
closed forms from the scene's own data (the rope's path from its reeving, pressures from
the loads, periods from masses and springs, the textbook block-train efficiency), or
eigenvalues with scipy.linalg; measured figures (the compensator's isolation, the
drawworks' tensions, the riser's step-size behaviour) from runs of the scene. Each test
also requires the scene's text to state the figure it checks.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import scipy.linalg

from wire_fmu.core.units.hydraulics.unit import HydraulicsUnit
from wire_fmu.master.run import find_scene, run_scene
from wire_fmu.master.scene import load_scene

G = 9.81
HYDRAULICS = {v.name: v.start for v in HydraulicsUnit.VARIABLES}


def _text(name: str) -> str:
    """The scene file, its comments' line breaks and '#' marks folded into spaces."""
    lines = find_scene(name).read_text(encoding="utf-8").splitlines()
    return " ".join(" ".join(ln.lstrip("# ").split()) for ln in lines)


def _data(name: str) -> dict:
    return tomllib.loads(find_scene(name).read_text(encoding="utf-8"))


def _states(name: str, *figures: str) -> None:
    text = _text(name)
    for figure in figures:
        assert figure in text, f"scene {name!r} does not state {figure!r}"


def _cylinder(parameters: dict) -> dict:
    """The cylinder's parameters: the unit's declared defaults with the scene's."""
    return HYDRAULICS | parameters


def _bore_area(cyl: dict) -> float:
    return math.pi / 4.0 * cyl["bore_diameter"] ** 2


def _equilibrium_pressure(cyl: dict, rope_force: float) -> float:
    """Absolute gas pressure holding the rod against the rope and its own weight, Pa."""
    return cyl["ambient_pressure"] + (rope_force + cyl["moving_mass"] * G) / _bore_area(cyl)


def _gas_volume(cyl: dict, pressure: float) -> float:
    """Gas volume after an isothermal charge from the pre-charge to ``pressure``, m^3."""
    full = cyl["accumulator_volume"] + cyl["gas_bank_volume"]
    return cyl["precharge_pressure"] * full / pressure


# ----------------------------------------------------------------- rope path, by hand
def _tangent(a, ra: float, b, rb: float):
    """The rope's straight line from circle a to circle b (signed radii: + ccw, - cw).

    With ``n`` the unit normal from a centre to its tangent point and ``u`` the direction of
    travel, ``n`` is ``u`` turned clockwise by 90 deg and the tangent points are
    ``c + rho n``; the line is ``u . (p_b - p_a)`` long, and ``(b - a) . n = rho_a - rho_b``.
    """
    d = np.subtract(b, a)
    angle = math.atan2(d[1], d[0])
    for sign in (1.0, -1.0):
        phi = angle + sign * math.acos((ra - rb) / math.hypot(*d))
        n = np.array([math.cos(phi), math.sin(phi)])
        u = np.array([-n[1], n[0]])
        chord = (np.asarray(b) + rb * n) - (np.asarray(a) + ra * n)
        length = float(u @ chord)
        if length > 0.0 and np.allclose(chord, length * u):
            return length, n, u
    raise AssertionError("no tangent")


def _path_circles(reeving: dict) -> list[tuple[tuple[float, float], float, str]]:
    """(centre, signed radius, body) of every path node, in the plane z = 0."""
    out = []
    for node in reeving["path"]:
        if "sheave" in node:
            s = reeving["sheaves"][node["sheave"]]
            sign = 1.0 if node["wrap"] == "ccw" else -1.0
            out.append((tuple(s["centre"][:2]), sign * s["radius"], s.get("body", "ground")))
        elif "anchor" in node:
            a = reeving["anchors"][node["anchor"]]
            out.append((tuple(a["point"][:2]), 0.0, a.get("body", "ground")))
        else:
            out.append((tuple(node["point"][:2]), 0.0, node.get("body", "ground")))
    return out


def _rope_path(reeving: dict, mover: str) -> tuple[float, float, float]:
    """Straight length, length on the sheaves, and d(length)/d(displacement of ``mover``)."""
    circles = _path_circles(reeving)
    lines = [_tangent(c[0], c[1], d[0], d[1]) for c, d in zip(circles, circles[1:], strict=False)]
    straight = sum(line[0] for line in lines)
    arcs = 0.0
    for k in range(1, len(circles) - 1):
        rho, n_in, n_out = circles[k][1], lines[k - 1][1], lines[k][1]
        turn = math.atan2(n_in[0] * n_out[1] - n_in[1] * n_out[0], n_in @ n_out)
        arcs += abs(rho) * ((turn if rho > 0 else -turn) % (2.0 * math.pi))
    direction = np.asarray(reeving["bodies"][mover]["direction"][:2], dtype=float)
    gain = 0.0
    for k, (_, _, u) in enumerate(lines):
        moves = [circles[j][2] == mover for j in (k, k + 1)]
        gain += float(u @ direction) * (float(moves[1]) - float(moves[0]))
    return straight, arcs, gain


# ------------------------------------------------------------------------------ riser
def test_riser_stiffest_mode_is_the_rod_on_one_67_8_m_span():
    data = _data("riser_tensioner")
    reeving = data["units"]["rope"]["parameters"]["reeving"]
    straight, arcs, gain = _rope_path(reeving, "rod")
    span = straight + arcs
    assert (round(straight, 1), round(arcs, 1), round(span, 1), gain) == (56.0, 11.8, 67.8, 4.0)
    ea = reeving["rope"]["axial_stiffness"]
    rope = gain**2 * ea / span
    cyl = _cylinder(data["units"]["cylinder"]["parameters"])
    p = _equilibrium_pressure(cyl, -cyl["rod.force"])
    gas = 1.4 * p * _bore_area(cyl) ** 2 / _gas_volume(cyl, p)
    # the rod (its mass) between the wire and the gas: the state matrix's eigenvalues
    m = cyl["moving_mass"]
    lam = scipy.linalg.eigvals(np.array([[0.0, 1.0], [-(rope + gas) / m, 0.0]]))
    omega = float(np.max(np.abs(lam.imag)))
    assert ea / span == pytest.approx(1.92e6, rel=2e-3)
    assert rope == pytest.approx(3.07e7, rel=2e-3) and gas == pytest.approx(6e4, rel=0.05)
    assert round(omega, 1) == 93.7
    assert round(omega * 0.002, 2) == 0.19 and round(omega * 0.004, 2) == 0.37
    assert round(omega * 0.01, 2) == 0.94
    assert (p / 1e6, (p - cyl["ambient_pressure"]) / 6894.757) == pytest.approx((14.75, 2125), 1e-3)
    _states(
        "riser_tensioner",
        "one span of 67.8 m (56 m of straight lines and 11.8 m on the sheaves)",
        "EA / L = 1.92e6 N/m",
        "16 EA / L = 3.07e7 N/m (the gas spring adds 6e4 N/m): 93.7 rad/s",
        "omega H = 0.37 (0.19 at 2 ms)",
        "at 10 ms (omega H = 0.94)",
        "14.75 MPa absolute (2125 psi gauge)",
    )


# ---------------------------------------------------------------------- compensator
def test_compensator_spring_and_hook_period():
    data = _data("heave_compensated_hoist")
    cyl = _cylinder(data["units"]["compensator"]["parameters"])
    reeving = data["units"]["rope"]["parameters"]["reeving"]
    hook = reeving["bodies"]["travelling_block"]["mass"]
    crown_load = -cyl["rod.force"]
    assert crown_load == pytest.approx(12 * hook * G / 10)  # 12 lines at W/n each
    area = _bore_area(cyl)
    p = _equilibrium_pressure(cyl, crown_load)
    gas = _gas_volume(cyl, p)
    oil = cyl["accumulator_volume"] + cyl["gas_bank_volume"] - gas
    spring = 1.4 * p * area**2 / gas
    # kinematics from the path: the hook's rise per unit of crown rise, at fixed rope length
    _, _, crown_gain = _rope_path(reeving, "crown")
    _, _, hook_gain = _rope_path(reeving, "travelling_block")
    assert (crown_gain, hook_gain) == pytest.approx((12.0, -10.0))
    ratio = -crown_gain / hook_gain
    crown = cyl["moving_mass"]
    mass = crown + ratio**2 * hook
    period = 2.0 * math.pi * math.sqrt(mass / spring)
    # the same from the two-body eigenproblem: crown and hook on the rope (one span) and gas
    straight, arcs, _ = _rope_path(reeving, "crown")
    rope = reeving["rope"]["axial_stiffness"] / (straight + arcs)
    lengthening = np.array([crown_gain, hook_gain])  # path length per metre of crown, hook rise
    stiffness = rope * np.outer(lengthening, lengthening) + np.diag([spring, 0.0])
    omegas = np.sqrt(scipy.linalg.eigh(stiffness, np.diag([crown, hook]), eigvals_only=True))
    assert 2.0 * math.pi / omegas[0] == pytest.approx(period, rel=1e-3)
    transmitted = 1.0 / ((period / 10.0) ** 2 - 1.0)
    assert (round(area, 4), round(p / 1e6, 1), round(gas, 2), round(oil, 2)) == (
        0.0995,
        15.8,
        20.25,
        0.35,
    )
    assert (round(spring, -2), round(mass / 1e3), round(period, 1)) == (1.08e4, 188, 26.2)
    assert round(100 * transmitted) == 17
    _states(
        "heave_compensated_hoist",
        "at 15.8 MPa absolute",
        "charged to 20.25 m^3 of gas, leaving 0.35 m^3 of oil",
        "= 1.08e4 N/m",
        "the hook rises 1.2 y",
        "15 t + 1.2^2 x 120 t = 188 t: a natural period of 26.2 s",
        "would pass 17 % of a 10 s heave",
    )


# ------------------------------------------------------------------------ drawworks
def test_drawworks_textbook_tensions_brake_and_floor():
    data = _data("drawworks")
    reeving = data["units"]["rope"]["parameters"]["reeving"]
    weight = reeving["bodies"]["travelling_block"]["mass"] * G
    (k,) = {s["efficiency"] for s in reeving["sheaves"].values()}
    n = 10
    hoist = weight / sum(k**i for i in range(1, n + 1))  # line i carries K^i of the fast line
    lower = weight / sum(k**-i for i in range(1, n + 1))
    e = k * (1 - k**n) / (n * (1 - k))
    assert hoist == pytest.approx(weight / (n * e))
    floor = reeving["bodies"]["travelling_block"]["floor"]
    zeta = floor["damping"] / (2.0 * math.sqrt(floor["stiffness"] * weight / G))
    winch = {v.name: v.start for v in _winch_variables()}
    capacity = (
        winch["brake_rim_radius"]
        * winch["brake_lever_ratio"]
        * winch["brake_efficiency"]
        * math.expm1(winch["brake_friction"] * winch["brake_wrap_angle"])
    )
    assert (round(hoist / 1e3, 1), round(lower / 1e3, 1), round(e, 3)) == (145.2, 94.3, 0.811)
    assert (round(100 * (hoist * n / weight - 1)), round(100 * (1 - lower * n / weight))) == (
        23,
        20,
    )
    assert (round(100 * zeta), round(capacity, 1), round(100 * (1 - k), 2)) == (29, 59.7, 3.85)
    _states(
        "drawworks",
        "W/(n E) = 145.2 kN with E = K (1 - K^n)/(n (1 - K)) = 0.811 (23 %",
        "W / sum(K^-i) = 94.3 kN (20 % below)",
        "damped to 29 % of critical",
        "59.7 N m per N of lever force",
        "lose 3.85 % per sheave",
    )


def test_drawworks_rope_is_not_stiff_for_its_rk4():
    """The fastest mode of the 10-line block train at its start, bearings slipping and
    stuck: eigenvalues (scipy.linalg) of a central-difference Jacobian of its equations."""
    import json

    from wire_fmu.core.units.block_train.unit import BlockTrainUnit

    data = _data("drawworks")
    rope = data["units"]["rope"]
    assert rope["parameters"]["solver"] == "rk4"
    unit = BlockTrainUnit("rope")
    unit.values["reeving"] = json.dumps(rope["parameters"]["reeving"])
    unit.values["effects"] = ",".join(rope["effects"])
    unit.configure()
    unit.initialize(0.0)
    model = unit.model
    x, n = model.state.copy(), model.n_coords

    def fastest() -> float:
        jac = np.empty((2 * n, 2 * n))
        for j in range(2 * n):
            dx = np.zeros_like(x)
            dx[j] = 1e-6
            jac[:, j] = (model.rhs(0.0, x + dx) - model.rhs(0.0, x - dx))[: 2 * n] / 2e-6
        return float(np.max(np.abs(scipy.linalg.eigvals(jac))))

    stuck = fastest()
    model.friction.set_mode([1] * len(model.friction.get_mode()))
    slipping = fastest()
    assert (round(stuck), round(slipping)) == (12, 147)
    assert slipping * 1e-3 < 2.78 / 10  # RK4's stability limit on the imaginary axis
    _states("drawworks", "147 rad/s, omega h = 0.15", "it is the hook's, 12 rad/s")


def _winch_variables():
    from wire_fmu.core.units.winch.unit import WinchUnit

    return WinchUnit.VARIABLES


# ------------------------------------------------------------------------------ runs
@pytest.fixture(scope="module")
def fmu_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("scene_figures_fmus")


def _run(scene, fmu_dir: Path, out: Path, **settings) -> pd.DataFrame:
    """Run a shipped scene (by name) or a parsed one; its results, indexed by time (s)."""
    outcome = run_scene(scene, out, plots=False, fmu_dir=fmu_dir, **settings)
    assert outcome.result.status == "finished", outcome.result.message
    return outcome.frame()


def _mean(frame: pd.DataFrame, column: str, start: float, end: float) -> float:
    window = frame[(frame.index >= start) & (frame.index <= end)]
    return float(window[column].mean())


@pytest.mark.integration
def test_drawworks_run_hoists_and_lowers_with_the_textbook_tensions(fmu_dir, tmp_path):
    frame = _run("drawworks", fmu_dir, tmp_path)
    weight = 120e3 * G
    tension = "rope.line_a.tension"
    assert _mean(frame, tension, 0.2, 0.9) == pytest.approx(weight / 10, rel=1e-9)  # stuck
    assert _mean(frame, tension, 17.0, 20.0) == pytest.approx(145.2e3, rel=0.02)
    assert _mean(frame, tension, 7.0, 10.0) == pytest.approx(94.3e3, rel=0.03)
    landed = frame.index[frame["rope.block_a.position"] <= 12.0][0]
    assert landed == pytest.approx(10.7, abs=0.15)
    slack = frame.index[(frame["rope.slack_spans"] > 0) & (frame.index < 4.0)]
    assert 1.0 < slack[0] and slack[-1] < 1.25
    snap = frame.loc[1.0:2.0, "rope.tension_max"].max()
    assert 1.7 < snap / (weight / 10) < 2.3  # "about 250 kN, twice W/n"
    _states("drawworks", "lands (about 10.7 s)", "slack for about 0.1 s", "about 250 kN")


def _detrended_std(frame: pd.DataFrame, column: str, start: float) -> float:
    window = frame[frame.index >= start]
    t, y = window.index.to_numpy(), window[column].to_numpy()
    return float(np.std(y - np.polyval(np.polyfit(t, y, 1), t)))


@pytest.mark.integration
def test_compensator_isolation_measured_as_stated(fmu_dir, tmp_path):
    """Hook against deck heave after the 10 s fade-in, each without its linear trend."""
    frame = _run("heave_compensated_hoist", fmu_dir, tmp_path / "seals")
    deck = _detrended_std(frame, "rope.mover_b.position", 10.0)
    hook = _detrended_std(frame, "rope.block_a.position", 10.0)
    assert deck == pytest.approx(0.68, abs=0.01) and hook == pytest.approx(0.27, abs=0.01)
    assert hook / deck == pytest.approx(0.39, abs=0.01)
    heave = frame.loc[10.0:, "rope.mover_b.position"].to_numpy()
    step = float(np.diff(frame.index[:2])[0])
    acceleration = np.diff(heave, 2) / step**2
    assert np.std(acceleration) == pytest.approx(0.58, abs=0.02)
    scene = load_scene(find_scene("heave_compensated_hoist"))
    compensator = scene.units["compensator"]
    effects = tuple(e for e in compensator.effects if e != "seal_friction")
    units = scene.units | {"compensator": replace(compensator, effects=effects)}
    free = _run(replace(scene, units=units), fmu_dir, tmp_path / "free")
    ratio = _detrended_std(free, "rope.block_a.position", 10.0) / _detrended_std(
        free, "rope.mover_b.position", 10.0
    )
    assert ratio == pytest.approx(0.15, abs=0.01)
    _states(
        "heave_compensated_hoist",
        "deck heave 0.68 m standard deviation, hook 0.27 m, 39 %",
        "without seal_friction the hook moves 15 % of the deck",
        "about 39 % of the deck's",
        "(0.58 m/s^2 standard deviation, 6 % of g",
    )


@pytest.mark.integration
def test_riser_step_sizes_behave_as_stated(fmu_dir, tmp_path):
    """Held force and rod velocity: rings at 10 ms, close at 2 ms; the interface model and
    the ramped rod velocity: close at the scene's 4 ms and even at 10 ms."""
    common = {"output_interval": 0.02}  # a time every run records
    held = {
        h: _run(
            "riser_tensioner",
            fmu_dir,
            tmp_path / f"held{h}",
            step=h,
            interface_models=False,
            ramped_flows=False,
            **common,
        )
        for h in (1e-3, 2e-3, 0.01)
    }
    modelled = {
        h: _run("riser_tensioner", fmu_dir, tmp_path / str(h), step=h, **common)
        for h in (1e-3, 0.01)
    }
    modelled[0.004] = _run("riser_tensioner", fmu_dir, tmp_path / "scene", **common)
    tension = "rope.path_end.tension"

    def rms_apart(runs: dict, h: float) -> float:
        series = {k: f[tension].set_axis(np.round(f.index, 6)) for k, f in runs.items()}
        apart = (series[h] - series[1e-3]).dropna()
        assert len(apart) > 0.9 * len(series[h])
        return float(np.sqrt(np.mean(apart**2)))

    assert rms_apart(held, 0.002) < 1.5e3 and 4.0e3 < rms_apart(held, 0.01) < 8.0e3
    assert rms_apart(modelled, 0.004) < 30.0 and rms_apart(modelled, 0.01) < 150.0
    residual = "bond.rod.energy_residual"
    assert abs(held[0.01][residual].iloc[-1]) > 5e3 and abs(held[0.002][residual].iloc[-1]) < 1e3
    assert abs(modelled[0.01][residual].iloc[-1]) < 1e3
    assert "rope.mover_b.position" in modelled[0.004].columns  # the vessel heave is recorded
    _states(
        "riser_tensioner",
        "(5.6 kN rms apart)",
        "energy residual reaches 10 kJ",
        "0.9 kN rms of the 1 ms run",
        "within 0.12 kN rms of its 1 ms run at 10 ms",
        "within 25 N at 4 ms",
    )

"""The effects study: which runs it makes, and a real (quick) one on a block train."""

from __future__ import annotations

from pathlib import Path

import pytest

from wire_fmu.cli import _parser
from wire_fmu.core.units.block_train.reevings import drilling_block_train
from wire_fmu.master.scene import parse_scene
from wire_fmu.study.effects import (
    EffectCase,
    effect_cases,
    run_effects_study,
    verdict,
    without,
)

EFFECTS = ["rope_damping", "sheave_inertia", "bearing_friction"]


def hoist_scene(effects=EFFECTS):
    """A 4-line drilling block train, its fast line paid out and in by a sine."""
    return parse_scene(
        {
            "name": "hoist",
            "run": {"stop_time": 1.0, "step": 0.01},
            "units": {
                "rope": {
                    "fmu": "BlockTrain",
                    "effects": list(effects),
                    "parameters": {"reeving": drilling_block_train(4)},
                }
            },
            "drivers": [
                {
                    "target": "rope.line_a.payout",
                    "rate_target": "rope.line_a.payout_rate",
                    "kind": "sine",
                    "amplitude": 0.2,
                    "period": 2.0,
                    "ramp_time": 0.5,
                }
            ],
            "study": {"key_outputs": ["rope.block_a.position", "rope.line_a.tension"]},
        },
        base_dir=Path("."),
    )


def test_an_effect_goes_with_the_effects_that_need_it():
    cases = effect_cases(hoist_scene())
    assert cases == [
        EffectCase("rope", "rope_damping"),
        EffectCase("rope", "sheave_inertia", ("bearing_friction",)),
        EffectCase("rope", "bearing_friction"),
    ]
    assert without(hoist_scene(), cases[1]).units["rope"].effects == ("rope_damping",)
    assert cases[1].label == "rope: sheave_inertia (+ bearing_friction)"
    assert effect_cases(hoist_scene(effects=[])) == []


def test_time_verdict_weighs_the_saving_against_the_spread_of_repeats():
    assert verdict(0.3, 0.1) == "saves"
    assert verdict(-0.05, 0.1) == "within noise"
    assert verdict(-0.3, 0.1) == "costs"
    assert verdict(0.3, float("nan")) == "saves (one run: noise unknown)"


def test_study_command_line():
    args = _parser().parse_args(["study", "effects", "hoist.toml", "--quick", "-o", "out"])
    assert (args.study, args.quick, args.output) == ("effects", True, Path("out"))
    args = _parser().parse_args(["study", "accuracy", "riser_tensioner", "--repeats", "2"])
    assert (args.study, args.quick, args.repeats) == ("accuracy", False, 2)


@pytest.mark.integration
def test_price_list_of_a_block_trains_effects(tmp_path):
    study = run_effects_study(hoist_scene(), tmp_path, quick=True, repeats=2, progress=False)
    assert [(r.unit, r.effect) for r in study.rows] == [("rope", e) for e in EFFECTS]
    assert all(r.status == "finished" for r in study.rows)
    for r in study.rows:  # the time books (not the speed: leaving damping out can add events)
        assert r.wall_per_sim_s > 0.0 and study.baseline_wall_per_sim_s > 0.0, r
        assert r.saved_per_sim_s == pytest.approx(study.baseline_wall_per_sim_s - r.wall_per_sim_s)
        assert r.saved_share == pytest.approx(r.saved_per_sim_s / study.baseline_wall_per_sim_s)
        assert r.output_change > 0.0, r
    damping = study.rows[0]
    assert 1e-4 < damping.output_change < 1.0  # damping changes the tension, not wildly
    for name in ("effects.csv", "effects.md", "effects.png"):
        assert (tmp_path / name).stat().st_size > 0
    assert "rope: sheave_inertia (+ bearing_friction)" in (tmp_path / "effects.md").read_text()

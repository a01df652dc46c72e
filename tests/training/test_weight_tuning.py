"""Weight tuning: scoring, search space checks, TPE on a synthetic objective, one real run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from semexplore_gym.training.weight_tuning import (
    PAPER_WEIGHTS,
    SearchSpace,
    StudySettings,
    evaluate_weights,
    mission_objective,
    mission_score,
    resolve_world,
    tune_weights,
)


def test_mission_score_penalises_missing_coverage_only() -> None:
    assert mission_score(100.0, 0.99, 0.97, 600.0) == 100.0
    assert mission_score(100.0, 0.87, 0.97, 600.0) == pytest.approx(160.0)
    with pytest.raises(ValueError, match="mission_time_s"):
        mission_score(float("nan"), 1.0)
    with pytest.raises(ValueError, match="target_coverage"):
        mission_score(1.0, 1.0, target_coverage=1.5)


def test_search_space_validation_and_contains() -> None:
    space = SearchSpace()
    assert space.contains(PAPER_WEIGHTS)
    assert not space.contains({"cost.w_v": 50.0})
    assert not space.contains({"cost.unknown": 1.0})
    assert "potential_field.f_g" in SearchSpace.with_field().ranges
    with pytest.raises(ValueError, match="low < high"):
        SearchSpace(ranges={"cost.w_v": (2.0, 1.0)})
    with pytest.raises(ValueError, match="low > 0"):
        SearchSpace(ranges={"cost.w_v": (0.0, 1.0)}, log_keys=("cost.w_v",))


def test_resolve_world_replaces_seed_placeholder() -> None:
    assert resolve_world("maze:seed=*,size_m=4", 7) == "maze:seed=7,size_m=4"
    assert resolve_world("maze1", 7) == "maze1"


def _bowl(w: dict[str, float]) -> float:
    """Synthetic objective with its minimum 0 at w_v=2, w_p=0.5, w_i=0.25."""
    return (
        (w["cost.w_v"] - 2.0) ** 2
        + 10 * (w["cost.w_p"] - 0.5) ** 2
        + 10 * (w["cost.w_i"] - 0.25) ** 2
    )


def test_tuner_improves_on_a_bad_start_and_is_seeded(tmp_path: Path) -> None:
    bad = {"cost.w_v": 10.0, "cost.w_p": 0.0, "cost.w_i": 1.0}
    res = tune_weights(
        _bowl,
        30,
        study_settings=StudySettings(seed=3, jsonl_path=tmp_path / "t.jsonl"),
        enqueue=[bad],
    )
    first_value = res.trials[0][2]
    assert res.trials[0][1] == bad and first_value == pytest.approx(_bowl(bad))
    assert res.best_value < 0.1 * first_value
    assert res.best_value == min(v for _, _, v in res.trials)
    lines = [json.loads(s) for s in (tmp_path / "t.jsonl").read_text().splitlines()]
    assert len(lines) == 30 and lines[0]["weights"] == bad
    again = tune_weights(_bowl, 30, study_settings=StudySettings(seed=3), enqueue=[bad])
    assert again.best_weights == res.best_weights


def test_tuner_resumes_from_sqlite(tmp_path: Path) -> None:
    db = tmp_path / "study.sqlite"
    calls: list[int] = []

    def counted(w: dict[str, float]) -> float:
        calls.append(1)
        return _bowl(w)

    tune_weights(counted, 4, study_settings=StudySettings(seed=0, storage_path=db))
    res = tune_weights(counted, 6, study_settings=StudySettings(seed=0, storage_path=db))
    assert len(calls) == 6 and len(res.trials) == 6


def test_tuner_rejects_bad_arguments() -> None:
    with pytest.raises(ValueError, match="n_trials"):
        tune_weights(_bowl, 0)
    with pytest.raises(ValueError, match="not in the search space"):
        tune_weights(_bowl, 1, enqueue=[{"cost.bogus": 1.0}])


def test_real_two_trial_tuning_run(tmp_path: Path) -> None:
    objective = mission_objective(["maze:seed=*,size_m=4"], [1], max_time_s=60.0)
    res = tune_weights(
        objective,
        2,
        study_settings=StudySettings(seed=0, jsonl_path=tmp_path / "t.jsonl"),
        enqueue=[PAPER_WEIGHTS],
    )
    assert len(res.trials) == 2
    rows = evaluate_weights(PAPER_WEIGHTS, ["maze:seed=*,size_m=4"], [1], max_time_s=60.0)
    assert rows[0]["world"].startswith("maze") and rows[0]["seed"] == 1
    expected = mission_score(rows[0]["mission_time_s"], rows[0]["coverage"])
    assert res.trials[0][2] == pytest.approx(expected)
    assert 0.0 < rows[0]["mission_time_s"] <= 60.0 + 1e-6

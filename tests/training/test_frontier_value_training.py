"""Fitting the learned frontier value (``training/frontier_value_search.py``), with stand-in missions."""

from __future__ import annotations

import json
import math

import pytest
from semexplore_gym.policies.learned_frontier_value import FrontierValuePolicy
from semexplore_gym.policies.registry import make_policy

from semexplore_gym.training.frontier_value_search import (
    FrontierValueTrainConfig,
    SearchParam,
    batch_score,
    load_frontier_value_config,
    train_frontier_value,
)

PARAMS = (
    SearchParam("value.w_path_m", 0.0, 0.2, -1.0, 1.0),
    SearchParam("expert.switch_margin", 0.5, 0.2, 0.0, 2.0),
)


def _fake_runner(calls: list) -> object:
    """Missions whose time is smallest at w_path_m = 0.3, switch_margin = 1.0 (the expert: 100 s)."""

    def run(jobs):
        calls.append(jobs)
        out = []
        for world, seed, spec, ov in jobs:
            assert "seed=*" in world and 0 <= seed <= 99
            assert spec == "frontier-value"
            if not ov:  # the reference: the value at zero weights, the expert it re-ranks
                out.append((100.0, 0.99))
                continue
            err = (ov["value.w_path_m"] - 0.3) ** 2 + 0.1 * (ov["expert.switch_margin"] - 1.0) ** 2
            out.append((80.0 * math.exp(err), 0.99))
        return out

    return run


def test_the_search_moves_towards_faster_missions_and_writes_a_loadable_model(tmp_path) -> None:
    cfg = FrontierValueTrainConfig(
        worlds=("maze:seed=*,size_m=4",),
        train_seeds=(0, 99),
        worlds_per_generation=2,
        population=8,
        elite=3,
        generations=12,
        params=PARAMS,
    )
    calls: list = []
    final = train_frontier_value(cfg, tmp_path, runner=_fake_runner(calls), log=lambda s: None)
    assert len(calls) == 12 and len(calls[0]) == 2 * (1 + 8)
    assert abs(final["value.w_path_m"] - 0.3) < 0.1
    lines = [json.loads(x) for x in (tmp_path / "generations.jsonl").read_text().splitlines()]
    assert len(lines) == 12 and lines[-1]["mean_score"] < lines[0]["mean_score"]
    policy = make_policy("frontier-value", params=tmp_path / "model.yaml")
    assert isinstance(policy, FrontierValuePolicy)
    assert policy.value_params.value.w_path_m == pytest.approx(final["value.w_path_m"], abs=1e-5)


def test_the_same_seed_gives_the_same_search(tmp_path) -> None:
    cfg = FrontierValueTrainConfig(
        worlds=("maze:seed=*,size_m=4",), train_seeds=(0, 99), generations=3, params=PARAMS
    )
    a = train_frontier_value(cfg, tmp_path / "a", runner=_fake_runner([]), log=lambda s: None)
    b = train_frontier_value(cfg, tmp_path / "b", runner=_fake_runner([]), log=lambda s: None)
    assert a == b


def test_score_is_the_log_time_ratio_plus_the_coverage_shortfall() -> None:
    assert batch_score([50.0, 200.0], [1, 1], [100.0, 100.0], [1, 1], 20.0, 0.0) == pytest.approx(
        0.0
    )
    assert batch_score([50.0], [1.0], [100.0], [1.0], 20.0, 0.0) == pytest.approx(math.log(0.5))
    assert batch_score([100.0], [0.9], [100.0], [1.0], 20.0, 0.05) == pytest.approx(20.0 * 0.05)


def test_the_shipped_config_loads_and_bad_configs_fail() -> None:
    cfg = load_frontier_value_config("configs/agents/frontier_value.yml", ["workers=1"])
    assert cfg.workers == 1 and cfg.train_seeds[1] < 1000 and cfg.params
    with pytest.raises(ValueError, match="seed="):
        FrontierValueTrainConfig(worlds=("maze1",), params=PARAMS)
    with pytest.raises(ValueError, match="elite"):
        FrontierValueTrainConfig(population=3, elite=3, params=PARAMS)
    with pytest.raises(ValueError, match="nothing to search"):
        FrontierValueTrainConfig()
    with pytest.raises(ValueError, match="low <= init"):
        SearchParam("value.w_path_m", 2.0, 0.1, 0.0, 1.0)


@pytest.mark.slow
def test_semexplore_train_runs_real_missions_and_the_model_runs(tmp_path) -> None:
    from semexplore_gym.cli import main
    from semexplore_gym.evaluation.rollout import make_mission_env, run_mission

    out = tmp_path / "fv"
    settings = [
        "generations=1",
        "worlds_per_generation=1",
        "population=2",
        "elite=1",
        "workers=1",
        "max_time_s=15",
        'worlds=["maze:seed=*,size_m=4"]',
    ]
    argv = ["train", "--algo", "frontier_value", "--out", str(out)]
    argv += ["--train-config", "configs/agents/frontier_value.yml", "--no-progress"]
    for s in settings:
        argv += ["--train-set", s]
    assert main(argv) == 0
    for name in ("model.yaml", "config.yaml", "args.json", "metrics.json", "generations.jsonl"):
        assert (out / name).is_file()
    record = json.loads((out / "generations.jsonl").read_text().splitlines()[0])
    assert len(record["scores"]) == 2 and record["scores"][0] == 0.0  # the mean is the expert
    env = make_mission_env("maze:seed=0,size_m=4", overrides=["episode.max_time_s=10"])
    try:
        res = run_mission(env, make_policy("frontier-value", params=out / "model.yaml"), seed=0)
    finally:
        env.close()
    assert res.steps > 0 and res.coverage > 0

"""The pretrained models shipped in ``policies/pretrained``: small, described, and runnable."""

from __future__ import annotations

import pytest
from semexplore_gym.policies.pretrained import MAX_MODEL_BYTES, get_pretrained, pretrained_models
from semexplore_gym.policies.registry import make_policy

NAMES = [m.name for m in pretrained_models()]


def test_the_dagger_model_and_the_best_agent_ship() -> None:
    assert {"dagger_maze", "frontier_choice_maze"} <= set(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_each_model_is_small_and_fully_described(name: str) -> None:
    model = get_pretrained(name)
    assert model.model_path.is_file()
    assert model.model_path.stat().st_size <= MAX_MODEL_BYTES
    assert (model.model_path.parent / "config.yaml").is_file()
    assert model.command.startswith("semexplore train ") and model.config in model.command
    assert "PENDING" not in model.results and model.results


@pytest.mark.parametrize("name", NAMES)
def test_each_model_runs_a_short_mission(name: str, one_torch_thread: None) -> None:
    pytest.importorskip("stable_baselines3")
    from semexplore_gym.evaluation.rollout import make_mission_env, run_mission

    policy = make_policy(f"pretrained:{name}")
    assert policy.name == f"pretrained:{name}"
    env = make_mission_env("maze:seed=0,size_m=4", overrides=["episode.max_time_s=20"])
    try:
        res = run_mission(env, policy, seed=0, max_time_s=5.0)
    finally:
        env.close()
    assert res.steps > 0 and res.coverage > 0
    assert res.policy == f"pretrained:{name}"


def test_unknown_name_lists_the_shipped_models() -> None:
    with pytest.raises(ValueError, match="unknown pretrained model") as err:
        make_policy("pretrained:no_such_model")
    for name in NAMES:
        assert f"pretrained:{name}" in str(err.value)

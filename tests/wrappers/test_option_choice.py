"""SemanticExploreOptions-v0: the agent chooses among every reachable frontier option."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from semexplore_gym.core.coverage_tour import PRIVILEGED_INFO_KEY
from semexplore_gym.core.features.frontier_option_features import OPTION_FEATURE_NAMES
from semexplore_gym.core.features.option_observation import (
    OPTION_FEATURE_SCALES,
    option_observation,
)
from semexplore_gym.expert_driven_envs import make_option_choice_env
from semexplore_gym.wrappers.option_choice import OptionParams

WORLD = "maze:seed=3,size_m=6"
SHORT = ["episode.max_time_s=120"]


def _feats(paths: list[float]) -> np.ndarray:
    f = np.ones((len(paths), len(OPTION_FEATURE_NAMES)))
    f[:, 0] = paths
    return f


def test_observation_keeps_the_nearest_options_and_pads() -> None:
    grid = np.zeros((4, 4), dtype=np.int8)
    ob = option_observation(_feats([9.0, 1.0, 5.0]), grid, 30.0, max_options=2)
    assert list(ob.slots) == [1, 2]  # the two shortest paths, nearest first
    assert ob.options.shape == (2, len(OPTION_FEATURE_NAMES))
    assert ob.options[0, 0] == pytest.approx(1.0 / OPTION_FEATURE_SCALES[0])
    assert list(ob.valid) == [1.0, 1.0]
    ob = option_observation(_feats([3.0]), grid, 30.0, max_options=4)
    assert list(ob.valid) == [1.0, 0.0, 0.0, 0.0]
    assert not ob.options[1:].any()
    assert ob.global_features[2] == pytest.approx(0.25)


def test_observation_rejects_bad_shapes() -> None:
    with pytest.raises(ValueError, match="features must be"):
        option_observation(np.zeros((3, 2)), np.zeros((2, 2)), 0.0, 4)
    with pytest.raises(ValueError, match="max_options must be >= 1, got 0"):
        option_observation(_feats([1.0]), np.zeros((2, 2)), 0.0, 0)


def test_params_errors_name_the_value() -> None:
    with pytest.raises(ValueError, match="max_options must be an integer >= 2, got 1"):
        OptionParams(max_options=1)
    with pytest.raises(ValueError, match="goal_bonus must be a finite number >= 0, got -1"):
        OptionParams(goal_bonus=-1)


def _run(env: gym.Env, seed: int) -> list[tuple[dict, np.ndarray, dict]]:
    seen = []
    obs, info = env.reset(seed=seed)
    seen.append((obs, env.action_masks(), info))
    for _ in range(40):
        mask = env.action_masks()
        obs, _, term, trunc, info = env.step(int(np.flatnonzero(mask)[-1]))
        seen.append((obs, env.action_masks(), info))
        if term or trunc:
            break
    return seen


def test_mask_padding_and_no_privileged_key_at_test_time() -> None:
    env = make_option_choice_env(
        WORLD, overrides=SHORT, option={"max_options": 6}, student="frontier-student"
    )
    try:
        assert set(env.observation_space.spaces) == {"options", "valid", "global"}
        seen = _run(env, seed=0)
    finally:
        env.close()
    assert len(seen) >= 3  # real choices were handed to the agent
    for obs, mask, info in seen[:-1]:
        assert "privileged" not in obs and PRIVILEGED_INFO_KEY not in info
        assert obs["options"].shape == (6, len(OPTION_FEATURE_NAMES))
        assert np.array_equal(mask, obs["valid"] > 0) and mask.sum() >= 2
        assert not obs["options"][~mask].any()  # padding rows are zero
        assert env.observation_space.contains(obs)
    with pytest.raises(ValueError, match=r"action must be in \[0, 6\), got 6"):
        env.step(6)


def test_privileged_key_in_training_only_and_never_the_drivers() -> None:
    env = make_option_choice_env(
        WORLD, overrides=SHORT, option={"max_options": 6}, student="frontier-student",
        privileged=True,
    )  # fmt: skip
    infos: list[dict] = []
    real_act = env.driver.act
    env.driver.act = lambda obs, info: infos.append(info) or real_act(obs, info)  # type: ignore[method-assign]
    try:
        obs, info = env.reset(seed=0)
        assert PRIVILEGED_INFO_KEY not in info
        priv = obs["privileged"]
        assert priv.shape == (7, 2)
        assert priv[-1, 0] > 0  # the world is not all seen yet
        assert (priv[:6][obs["valid"] == 0] == 0).all()
        assert priv[:6][obs["valid"] > 0].sum() > 0  # unseen area behind the options
        env.step(0)
    finally:
        env.close()
    assert infos and all(PRIVILEGED_INFO_KEY not in i for i in infos)


def test_the_agents_choice_is_driven_and_rewarded() -> None:
    env = make_option_choice_env(WORLD, overrides=SHORT, student="frontier-student")
    try:
        obs, _ = env.reset(seed=1)
        decision = env.decision
        row = int(np.flatnonzero(env.action_masks())[-1])
        chosen = decision.options.goal_xy_m[env._slots[row]]
        _, reward, _, _, info = env.step(row)
    finally:
        env.close()
    assert info["chosen_row"] == row and info["decision_time_s"] > 0
    p = OptionParams()
    expect = (
        p.area_reward_per_m2 * info["area_gain_m2"] - p.time_penalty_per_s * info["decision_time_s"]
    )
    assert reward == pytest.approx(expect, abs=1e-6) or reward == pytest.approx(
        expect + p.goal_bonus
    )
    assert np.isfinite(chosen).all()


def test_reset_mid_episode_ends_the_mission_thread() -> None:
    env = make_option_choice_env(WORLD, overrides=SHORT, student="frontier-student")
    try:
        env.reset(seed=0)
        first = env._thread
        env.reset(seed=0)
        assert first is not None and not first.is_alive()
    finally:
        env.close()
    assert env._thread is None


def test_gym_make_and_bad_student() -> None:
    import semexplore_gym

    semexplore_gym.register_envs()
    env = gym.make("SemanticExploreOptions-v0", world=WORLD, overrides=SHORT,
                   student="frontier-student", disable_env_checker=True)  # fmt: skip
    env.close()
    with pytest.raises(ValueError, match="student must be a frontier-student spec, got 'nearest'"):
        make_option_choice_env(WORLD, overrides=SHORT, student="nearest")

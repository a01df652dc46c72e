"""The expert with a learned frontier value (``policies/learned_frontier_value.py``)."""

from __future__ import annotations

import numpy as np
import pytest
from semexplore_gym.policies.learned_frontier_value import (
    FrontierValueParams,
    FrontierValuePolicy,
    FrontierValueWeights,
)
from semexplore_gym.policies.registry import make_policy

from semexplore_gym.evaluation.rollout import make_mission_env, run_mission

WORLD = "maze:seed=3,size_m=6"


def _trajectory(spec: str | object, max_time_s: float, **overrides: float) -> np.ndarray:
    env = make_mission_env(WORLD, overrides=[f"episode.max_time_s={max_time_s}"])
    policy = make_policy(spec, **overrides) if isinstance(spec, str) else spec
    try:
        res = run_mission(env, policy, seed=1, max_time_s=max_time_s)
    finally:
        env.close()
    return np.asarray(res.trajectory)


def test_with_every_weight_at_zero_it_is_the_expert_step_for_step() -> None:
    # The expert it re-ranks: Algorithm 1's choice, without the grid candidate, along the map's
    # paths (as the learned value was measured).
    from semexplore_gym.policies.expert.expert import SemanticExpertPolicy
    from semexplore_gym.policies.expert.recipes import OUTSIDE_CHOICE

    expert = _trajectory(SemanticExpertPolicy(recipe=OUTSIDE_CHOICE), 40.0)
    learned = _trajectory("frontier-value", 40.0)
    assert len(expert) > 10
    np.testing.assert_array_equal(learned, expert)


def test_weights_change_the_choice_of_frontier_and_the_mission() -> None:
    expert = _trajectory("semantic", 60.0)
    learned = _trajectory(
        "frontier-value", 60.0, **{"value.w_path_m": 1.0, "value.w_unknown_frac": -3.0}
    )
    assert learned.shape != expert.shape or not np.array_equal(learned, expert)


def test_rescoring_ranks_by_the_paper_cost_plus_the_value() -> None:
    env = make_mission_env(WORLD, overrides=["episode.max_time_s=120"])
    policy = FrontierValuePolicy(FrontierValueParams(value=FrontierValueWeights(w_path_m=100.0)))
    try:
        obs, info = env.reset(seed=1)
        policy.reset(obs, info, seed=1)
        for _ in range(2000):
            obs, _, term, trunc, info = env.step(policy.act(obs, info))
            if len(policy.candidates) >= 2 or term or trunc:
                break
    finally:
        env.close()
    cands = policy.candidates
    if len(cands) < 2:
        pytest.skip("this maze never showed two frontiers at once")
    ranked = policy.rescored(cands)
    assert sorted(c.goal_xy_m for c in ranked) == sorted(c.goal_xy_m for c in cands)
    assert ranked[0].d_m == min(c.d_m for c in cands)
    for old in cands:
        new = next(c for c in ranked if c.goal_xy_m == old.goal_xy_m)
        assert new.cost == pytest.approx(old.cost + 100.0 * old.d_m)
    assert [c.cost for c in ranked] == sorted(c.cost for c in ranked)


def test_params_come_from_dotted_overrides_and_bad_weights_fail() -> None:
    policy = make_policy("frontier-value", **{"value.w_detour": -0.5, "expert.cost.w_v": 2.0})
    assert isinstance(policy, FrontierValuePolicy)
    assert policy.value_params.value.w_detour == -0.5 and policy.params.cost.w_v == 2.0
    with pytest.raises(ValueError, match="w_path_m"):
        make_policy("frontier-value", **{"value.w_path_m": float("nan")})
    with pytest.raises(ValueError, match="no argument"):
        make_policy("frontier-value:x")


def test_the_shipped_model_is_a_learned_value() -> None:
    from semexplore_gym.policies.pretrained import get_pretrained

    model = get_pretrained("frontier_value")
    assert model.model_path.name == "model.yaml"
    policy = make_policy("pretrained:frontier_value")
    assert isinstance(policy, FrontierValuePolicy)
    assert not policy.value_params.value.is_zero()

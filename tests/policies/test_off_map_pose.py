"""A pose estimate off the map's grid (a SLAM back end that diverged, as on the real suite's
nav2-depot) never raises from inside a policy: the frontier baselines stop at once and say
why, the expert and its students say why when they stop."""

from __future__ import annotations

import numpy as np
import pytest
from semexplore_gym.policies.base import OFF_MAP_REASON
from semexplore_gym.policies.registry import make_policy

from semexplore_gym.evaluation.rollout import make_mission_env, map_observation_for

WORLD = "maze:seed=3,size_m=4"
STOP_AT_ONCE = ("frontier", "nearest")
EXPERTS = ("semantic", "semantic-v2", "frontier-student", "pretrained:oracle_student")
NO_STOP_RULE = ("semantic-paper",)  # the paper's method: it keeps its plan, and must not raise


def _off_map_acts(spec: str, n_acts: int) -> tuple[object, int]:
    """The policy after 20 real steps, then up to ``n_acts`` acts with the pose moved off the
    grid (a little further each time); the number of acts until it stopped."""
    policy = make_policy(spec)
    env = make_mission_env(WORLD, "default", **map_observation_for(policy))
    obs, info = env.reset(seed=0)
    policy.reset(obs, info, seed=0)
    for _ in range(20):
        obs, _, _, _, info = env.step(policy.act(obs, info))
    left_edge_m = env.unwrapped.map_geometry.origin_x_m
    for k in range(n_acts):
        pose = np.array(obs["pose"], dtype=np.float64)
        pose[0] = left_edge_m - 0.5 - 0.01 * k
        action = policy.act({**obs, "pose": pose.astype(obs["pose"].dtype)}, info)
        assert np.all(np.isfinite(action)) and action.shape == (2,)
        if policy.done:
            return policy, k + 1
    return policy, n_acts


@pytest.mark.parametrize("spec", STOP_AT_ONCE)
def test_the_frontier_baselines_stop_at_once_and_say_why(spec: str) -> None:
    policy, n = _off_map_acts(spec, 50)
    assert policy.done and n == 1
    assert policy.stop_reason.startswith(OFF_MAP_REASON + " at (")


@pytest.mark.parametrize("spec", EXPERTS)
def test_the_expert_and_its_students_say_why_they_stopped(spec: str) -> None:
    policy, _ = _off_map_acts(spec, 400)
    assert policy.done, f"{spec} did not stop with its pose off the map"
    assert policy.stop_reason.startswith(OFF_MAP_REASON + " at (")
    assert "no frontier left" in policy.stop_reason  # the expert's own reason follows


@pytest.mark.parametrize("spec", NO_STOP_RULE)
def test_a_policy_without_that_stop_rule_still_does_not_raise(spec: str) -> None:
    _off_map_acts(spec, 100)

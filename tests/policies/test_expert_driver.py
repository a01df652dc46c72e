"""ExpertDriver: the expert follows a commanded frontier and outside cost weights."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from semexplore_gym.policies.expert.driver import ExpertDriver

import semexplore_gym  # noqa: F401  (registers the env)
from semexplore_gym.core.planning.graph_search import FrontierCostWeights


def _env_with_two_candidates() -> tuple[gym.Env, ExpertDriver, dict, dict, list]:
    # Seeds of a small maze where the start already shows at least two frontiers.
    for seed in range(6):
        env = gym.make("SemanticExplore-v0", world=f"maze:seed={seed},size_m=5")
        obs, info = env.reset(seed=seed)
        driver = ExpertDriver()
        driver.reset(obs, info, seed=seed)
        cands = driver.frontier_candidates(obs)
        if len(cands) >= 2:
            return env, driver, obs, info, cands
        env.close()
    pytest.skip("no small maze start with two frontier candidates")


def test_commanded_frontier_is_pursued_instead_of_the_cheapest() -> None:
    env, driver, obs, info, cands = _env_with_two_candidates()
    assert [c.cost for c in cands] == sorted(c.cost for c in cands)
    target = cands[-1]
    driver.command_goal(target)
    driver.act(obs, info)
    goal = driver.overlay()["goal_m"]
    assert math.dist(goal, target.goal_xy_m) <= driver.params.commitment_radius_m
    assert math.dist(goal, cands[0].goal_xy_m) > 1e-6
    assert not driver.goal_finished
    # Without a command the expert picks its own argmin C.
    driver.command_goal(None)
    driver.act(obs, info)
    assert (
        math.dist(driver.overlay()["goal_m"], cands[0].goal_xy_m)
        <= driver.params.commitment_radius_m
    )
    env.close()


def test_goal_finishes_when_reached_within_the_mission() -> None:
    env, driver, obs, info, cands = _env_with_two_candidates()
    driver.command_goal(cands[0])
    for _ in range(300):  # 60 s simulated
        action = driver.act(obs, info)
        if driver.goal_finished or driver.done:
            break
        obs, _, term, trunc, info = env.step(action)
        if term or trunc:
            break
    assert driver.goal_finished
    env.close()


def test_set_cost_weights_and_scoring_weights() -> None:
    env, driver, obs, info, cands = _env_with_two_candidates()
    driver.set_cost_weights(1.0, 0.0, 0.5)
    assert (driver.params.cost.w_v, driver.params.cost.w_p, driver.params.cost.w_i) == (
        1.0,
        0.0,
        0.5,
    )
    with pytest.raises(ValueError, match="w_v"):
        driver.set_cost_weights(-1.0, 0.0, 0.0)
    # Scoring with explicit weights ignores the driver's own.
    paper = driver.frontier_candidates(obs, FrontierCostWeights())
    assert np.allclose(sorted(c.cost for c in paper), sorted(c.cost for c in cands))
    env.close()


def test_frontier_candidates_needs_reset() -> None:
    with pytest.raises(ValueError, match="reset"):
        ExpertDriver().frontier_candidates({"map": np.zeros((2, 2), np.uint8), "pose": np.zeros(3)})

"""Macro-action wrappers: features, weight mapping, decision loop (fake driver), real env ids."""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces

from semexplore_gym.core.grid import FREE, UNKNOWN
from semexplore_gym.core.planning.graph_search import FrontierCandidate, FrontierCostWeights
from semexplore_gym.core.topometric.types import Frontier
from semexplore_gym.wrappers.frontier_choice import (
    N_CANDIDATE_FEATURES,
    N_GLOBAL_FEATURES,
    FrontierChoice,
    MacroParams,
    PlannerWeights,
    action_to_weights,
    candidate_features,
)


def _cand(
    goal: tuple[float, float], d_m: float, cost: float, width_m: float = 1.0
) -> FrontierCandidate:
    f = Frontier(
        area_id=1,
        opening_id=2,
        midpoint_m=goal,
        width_m=width_m,
        intersection_id=3,
        path_length_m=5.0,
    )
    return FrontierCandidate(
        frontier=f,
        goal_xy_m=goal,
        path_m=np.array([[0.0, 0.0], goal]),
        opening_ids=(2,),
        d_m=d_m,
        v_rad=math.pi / 2,
        p_l_m=5.0,
        n_openings=4,
        n_frontier_pathways=2,
        l_path_m=2.0,
        metric_cost=0.0,
        semantic_gain=0.0,
        cost=cost,
    )


def test_candidate_features_scale_and_pad() -> None:
    params = MacroParams(n_candidates=3)
    feats, mask = candidate_features(
        [_cand((1.0, 2.0), 10.0, 0.0, width_m=1.0), _cand((3.0, 0.0), 40.0, 10.0, width_m=5.0)],
        params,
    )
    assert feats.shape == (3, N_CANDIDATE_FEATURES) and feats.dtype == np.float32
    np.testing.assert_allclose(feats[0], [1.0, 0.5, 0.5, 0.25, 0.5, 0.25, 0.0, 0.5], atol=1e-6)
    np.testing.assert_allclose(
        feats[1], [1.0, 1.0, 0.5, 0.25, 0.5, 0.25, math.tanh(1.0), 1.0], atol=1e-6
    )
    assert not feats[2].any()
    assert mask.tolist() == [True, True, False]


def test_action_to_weights_maps_zero_to_paper_and_ends_to_ranges() -> None:
    assert action_to_weights(np.zeros(3)) == pytest.approx((4.0, 0.2, 0.1))
    assert action_to_weights(-np.ones(3)) == pytest.approx((0.0, 0.0, 0.0))
    assert action_to_weights(np.ones(3)) == pytest.approx((10.0, 1.0, 1.0))
    assert action_to_weights([0.5, -0.5, 0.5]) == pytest.approx((7.0, 0.1, 0.55))
    assert action_to_weights([5.0, -5.0, 0.0]) == pytest.approx((10.0, 0.0, 0.1))  # clipped
    with pytest.raises(ValueError, match="finite"):
        action_to_weights([np.nan, 0.0, 0.0])
    with pytest.raises(ValueError, match="3 values"):
        action_to_weights([0.0, 0.0])


def test_macro_params_reject_bad_values() -> None:
    with pytest.raises(ValueError, match="n_candidates"):
        MacroParams(n_candidates=0)
    with pytest.raises(ValueError, match="max_macro_time_s"):
        MacroParams(max_macro_time_s=0.0)
    with pytest.raises(ValueError, match="time_penalty_per_s"):
        MacroParams(time_penalty_per_s=-1.0)


# ---------------------------------------------------------------------- fake env + driver
class _LineEnv(gym.Env):
    """Each step takes 0.2 s and maps 0.1 m^2 more; terminates at ``end_s``."""

    def __init__(self, end_s: float = 100.0) -> None:
        self.end_s = end_s
        self.observation_space = spaces.Dict({"map": spaces.Box(0, 255, (4, 4), np.uint8)})
        self.action_space = spaces.Box(-1.0, 1.0, (2,), np.float32)

    def _obs(self) -> dict[str, np.ndarray]:
        grid = np.full((4, 4), UNKNOWN, np.uint8)
        grid[0, :] = FREE  # 4 of 16 cells known
        return {"map": grid, "pose": np.zeros(3, np.float32), "scan": np.zeros(8, np.float32)}

    def _info(self) -> dict[str, Any]:
        return {"sim_time_s": self.t_s, "explored_area_m2": self.area_m2}

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        super().reset(seed=seed)
        self.t_s, self.area_m2 = 0.0, 1.0
        return self._obs(), self._info()

    def step(self, action: Any) -> tuple[dict, float, bool, bool, dict]:
        self.t_s = round(self.t_s + 0.2, 6)
        self.area_m2 += 0.1
        return self._obs(), 0.0, self.t_s >= self.end_s - 1e-9, False, self._info()


class _FakeDriver:
    """Offers two candidates; a commanded goal finishes after ``goal_steps`` acts."""

    def __init__(self, goal_steps: int = 3, n_cands: int = 2, done_after: int = 10**9) -> None:
        self.goal_steps, self.n_cands, self.done_after = goal_steps, n_cands, done_after
        self.done = False
        self.goal_finished = False
        self.commanded: list[Any] = []
        self.weights: list[tuple[float, float, float]] = []
        self.scored_with: list[FrontierCostWeights | None] = []

    def reset(self, obs: dict, info: dict, seed: int | None = None) -> None:
        self.acts = 0

    def act(self, obs: dict, info: dict) -> np.ndarray:
        self.acts += 1
        self._since += 1
        self.goal_finished = self._since >= self.goal_steps
        self.done = self.acts > self.done_after
        return np.zeros(2, np.float32)

    def overlay(self) -> dict:
        return {}

    def frontier_candidates(
        self, obs: dict, weights: FrontierCostWeights | None = None
    ) -> list[FrontierCandidate]:
        self.scored_with.append(weights)
        return [_cand((float(i), 0.0), 1.0 + i, float(i)) for i in range(self.n_cands)]

    def command_goal(self, candidate: FrontierCandidate | None) -> None:
        self.commanded.append(candidate)
        self._since = 0
        self.goal_finished = False

    def set_cost_weights(self, w_v: float, w_p: float, w_i: float) -> None:
        self.weights.append((w_v, w_p, w_i))
        self._since = 0


def test_frontier_choice_drives_until_goal_finished_and_rewards_area_minus_time() -> None:
    driver = _FakeDriver(goal_steps=3)
    env = FrontierChoice(_LineEnv(), driver, MacroParams(n_candidates=4, time_penalty_per_s=0.5))
    obs, info = env.reset(seed=0)
    assert obs.shape == (4 * N_CANDIDATE_FEATURES + N_GLOBAL_FEATURES,)
    assert env.action_masks().tolist() == [True, True, False, False]
    np.testing.assert_allclose(obs[-N_GLOBAL_FEATURES:], [0.25, 0.0, 0.5, 2 / 16], atol=1e-6)
    obs, reward, term, trunc, info = env.step(1)
    assert driver.commanded[-1].goal_xy_m == (1.0, 0.0)
    assert info["decision_steps"] == 3
    # 3 steps: +0.3 m^2, 0.6 s at 0.5 per s.
    assert reward == pytest.approx(0.3 - 0.3)
    assert not term and not trunc
    with pytest.raises(ValueError, match="action must be in"):
        env.step(4)


def test_frontier_choice_time_budget_and_no_candidate_action() -> None:
    driver = _FakeDriver(goal_steps=10**6, n_cands=0)
    env = FrontierChoice(_LineEnv(), driver, MacroParams(n_candidates=3, max_macro_time_s=1.0))
    env.reset(seed=0)
    assert env.action_masks().tolist() == [True, False, False]  # action 0 = driver's own choice
    _, _, _, _, info = env.step(0)
    assert driver.commanded[-1] is None
    assert info["decision_steps"] == 5  # 1 s budget / 0.2 s


def test_macro_episode_ends_when_driver_or_env_is_done() -> None:
    env = FrontierChoice(
        _LineEnv(), _FakeDriver(goal_steps=100, done_after=4), MacroParams(max_macro_time_s=50.0)
    )
    env.reset(seed=0)
    obs, _, term, trunc, info = env.step(0)
    assert term and not trunc and info["driver_done"] and info["decision_steps"] == 4
    assert not obs[:-N_GLOBAL_FEATURES].any()
    env = PlannerWeights(_LineEnv(end_s=1.0), _FakeDriver(), MacroParams(decision_period_s=5.0))
    env.reset(seed=0)
    _, _, term, _, info = env.step(np.zeros(3, np.float32))
    assert term and info["decision_steps"] == 5


def test_planner_weights_sets_weights_and_scores_with_paper() -> None:
    driver = _FakeDriver()
    env = PlannerWeights(_LineEnv(), driver, MacroParams(decision_period_s=2.0))
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.array([1.0, 0.0, -1.0], np.float32))
    assert driver.weights == [pytest.approx((10.0, 0.2, 0.0))]
    assert info["decision_steps"] == 10
    assert all(w == FrontierCostWeights() for w in driver.scored_with)


# ---------------------------------------------------------------------- real env ids
WORLD = "maze:seed=0,size_m=4"
SMALL = {"n_candidates": 4, "max_macro_time_s": 3.0, "decision_period_s": 3.0}


@pytest.mark.parametrize("env_id", ["SemanticExploreFrontier-v0", "SemanticExploreWeights-v0"])
def test_registered_macro_envs_pass_check_env(env_id: str) -> None:
    from gymnasium.utils.env_checker import check_env

    import semexplore_gym  # noqa: F401

    env = gym.make(env_id, world=WORLD, overrides=["episode.max_time_s=30"], macro=SMALL)
    check_env(env.unwrapped, skip_render_check=True)
    obs, _ = env.reset(seed=1)
    obs2, _ = env.reset(seed=1)
    np.testing.assert_array_equal(obs, obs2)
    assert env.observation_space.contains(obs)
    if env_id.startswith("SemanticExploreFrontier"):
        mask = env.get_wrapper_attr("action_masks")()
        assert mask.dtype == bool and mask[0]
    env.close()


def test_observation_vector_shows_the_first_k_and_counts_all() -> None:
    from semexplore_gym.core.features.macro import observation_size, observation_vector
    from semexplore_gym.core.grid import FREE, UNKNOWN

    params = MacroParams(n_candidates=2, time_scale_s=100.0)
    cands = [_cand((float(i), 0.0), 1.0 + i, float(i)) for i in range(5)]
    grid = np.full((4, 5), UNKNOWN, np.uint8)
    grid[:2] = FREE  # 10 of 20 cells known
    vec, shown = observation_vector(cands, grid, 25.0, params)
    assert vec.shape == (observation_size(params),) == (2 * N_CANDIDATE_FEATURES + 4,)
    assert shown == cands[:2]
    np.testing.assert_allclose(vec[-4:], [0.5, 0.25, 1.0, 5 / 8], atol=1e-6)
    vec0, shown0 = observation_vector([], grid, 500.0, params)
    assert shown0 == [] and not vec0[:-4].any()
    np.testing.assert_allclose(vec0[-4:], [0.5, 1.0, 0.0, 0.0], atol=1e-6)

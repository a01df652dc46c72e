"""Macro-action wrappers: choose a frontier, or choose the planner's weights; a driver drives.

Both wrappers turn ``SemanticExplore-v0`` into a decision process at a coarser time scale. At
each decision the agent sees features of the top-``K`` frontier candidates of the semantic
topometric map (Algorithm 1, ranked by the frontier cost ``C``) plus a few global features; then
a **driver** (the scripted expert's navigation stack) steps the base env until the decision ends.

* :class:`FrontierChoice` (``SemanticExploreFrontier-v0``): action ``Discrete(K)``, the index of
  the candidate to explore; :meth:`FrontierChoice.action_masks` marks the real candidates (for
  sb3-contrib ``MaskablePPO``). The decision ends when the chosen frontier is reached, vanishes
  or is given up, or after ``max_macro_time_s``.
* :class:`PlannerWeights` (``SemanticExploreWeights-v0``): action ``Box(-1, 1, (3,))`` mapped to
  the cost weights ``(w_v, w_p, w_I)`` (:func:`action_to_weights`); the expert plans with them
  for ``decision_period_s``.

Layering: wrappers may not import ``policies``, so the driver is injected. Any object with the
:class:`FrontierDriver` methods works; ``semexplore_gym.policies.expert.driver.ExpertDriver`` is the expert's, and
the entry points in :mod:`semexplore_gym.expert_driven_envs` build base env + driver + wrapper.

Reward of a decision: ``area_reward_per_m2 * (new mapped free area, m^2) - time_penalty_per_s *
(simulated seconds it took)``. Episode end: terminated when the base env terminates (coverage
goal) or the driver finds no frontier left; truncated when the base env truncates.

Observation (``Box(-1, 1, (K * 8 + 4,), float32)``): see :mod:`semexplore_gym.core.features.macro`,
where the features, :class:`MacroParams` and :func:`action_to_weights` live (re-exported here).
"""

from __future__ import annotations

from typing import Any, Protocol, cast

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from semexplore_gym.core.features.macro import (  # noqa: F401  (re-exported)
    N_CANDIDATE_FEATURES,
    N_GLOBAL_FEATURES,
    WEIGHT_RANGES,
    MacroParams,
    action_mask,
    action_to_weights,
    candidate_features,
    observation_size,
    observation_vector,
)
from semexplore_gym.core.grid import UNKNOWN
from semexplore_gym.core.planning.graph_search import FrontierCandidate, FrontierCostWeights


class FrontierDriver(Protocol):
    """What the wrappers need from a driver (``semexplore_gym.policies.expert.driver.ExpertDriver`` has it)."""

    done: bool
    goal_finished: bool

    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None: ...

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray: ...

    def overlay(self) -> dict[str, Any]: ...

    def frontier_candidates(
        self, obs: dict[str, np.ndarray], weights: FrontierCostWeights | None = None
    ) -> list[FrontierCandidate]: ...

    def command_goal(self, candidate: FrontierCandidate | None) -> None: ...

    def set_cost_weights(self, w_v: float, w_p: float, w_i: float) -> None: ...


class _MacroWrapper(gym.Wrapper):
    """Shared machinery: candidate observation, driving the base env, reward bookkeeping."""

    def __init__(self, env: gym.Env, driver: FrontierDriver, params: MacroParams | None) -> None:
        super().__init__(env)
        self.driver = driver
        self.params = params or MacroParams()
        n = observation_size(self.params)
        self.observation_space = spaces.Box(-1.0, 1.0, shape=(n,), dtype=np.float32)
        self._obs: dict[str, np.ndarray] | None = None
        self._info: dict[str, Any] = {}
        self.candidates: list[FrontierCandidate] = []
        self._n_all = 0

    # The candidates are scored with these weights (None: the driver's current ones).
    def _scoring_weights(self) -> FrontierCostWeights | None:
        return None

    def _refresh(self) -> np.ndarray:
        assert self._obs is not None
        cands = self.driver.frontier_candidates(self._obs, self._scoring_weights())
        self._n_all = len(cands)
        vec, self.candidates = observation_vector(
            cands, self._obs["map"], float(self._info.get("sim_time_s", 0.0)), self.params
        )
        return vec

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        self.driver.reset(obs, info, seed=seed)
        self._obs, self._info = obs, info
        return self._refresh(), dict(info, decision_steps=0, n_candidates=len(self.candidates))

    def _drive(
        self, budget_s: float, stop_on_goal: bool
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        assert self._obs is not None
        obs, info = self._obs, self._info
        area0 = float(info.get("explored_area_m2", 0.0))
        t0 = float(info.get("sim_time_s", 0.0))
        terminated = truncated = False
        steps = 0
        base = self.env.unwrapped
        while True:
            action = self.driver.act(obs, info)
            if self.driver.done:
                terminated = True  # no frontier left: the mission is over
                break
            obs, _, terminated, truncated, info = self.env.step(action)
            steps += 1
            if getattr(base, "render_mode", None) is not None and hasattr(base, "set_overlay"):
                base.set_overlay(self.driver.overlay())
            if terminated or truncated:
                break
            if stop_on_goal and self.driver.goal_finished:
                break
            if float(info["sim_time_s"]) - t0 >= budget_s - 1e-9:
                break
        self._obs, self._info = obs, info
        p = self.params
        area_gain = float(info.get("explored_area_m2", 0.0)) - area0
        elapsed_s = float(info.get("sim_time_s", 0.0)) - t0
        reward = p.area_reward_per_m2 * area_gain - p.time_penalty_per_s * elapsed_s
        out_info = dict(
            info,
            decision_steps=steps,
            decision_time_s=elapsed_s,
            area_gain_m2=area_gain,
            driver_done=bool(self.driver.done),
        )
        obs_vec = self._refresh() if not (terminated or truncated) else self._last_vector()
        out_info["n_candidates"] = len(self.candidates)
        return obs_vec, float(reward), bool(terminated), bool(truncated), out_info

    def _last_vector(self) -> np.ndarray:
        # The episode is over: the candidate search would be wasted work.
        self.candidates = []
        self._n_all = 0
        vec = np.zeros(cast(tuple[int, ...], self.observation_space.shape), dtype=np.float32)
        grid = self._obs["map"] if self._obs is not None else None
        if grid is not None:
            vec[-N_GLOBAL_FEATURES] = 1.0 - float(np.count_nonzero(grid == UNKNOWN)) / grid.size
            vec[-N_GLOBAL_FEATURES + 1] = min(
                float(self._info.get("sim_time_s", 0.0)) / self.params.time_scale_s, 1.0
            )
        return vec


class FrontierChoice(_MacroWrapper):
    """Choose which of the top-``K`` frontier candidates to explore; the driver drives there.

    Action ``k < len(candidates)`` commands candidate ``k`` (ranked by ``C``, cheapest first).
    With no semantic candidate at all (the expert is on its grid-frontier fallback) only action
    0 is valid and means "the driver's own choice". Invalid actions (masked out) are treated as
    action 0.

    Args:
        env: A ``SemanticExplore-v0`` env.
        driver: A :class:`FrontierDriver`.
        params: :class:`MacroParams`.
    """

    def __init__(
        self, env: gym.Env, driver: FrontierDriver, params: MacroParams | None = None
    ) -> None:
        super().__init__(env, driver, params)
        self.action_space = spaces.Discrete(self.params.n_candidates)

    def action_masks(self) -> np.ndarray:
        """``(K,)`` bool: True for the actions that name a real candidate (at least action 0)."""
        return action_mask(len(self.candidates), self.params)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        k = int(np.asarray(action).reshape(-1)[0]) if np.ndim(action) else int(action)
        if not 0 <= k < self.params.n_candidates:
            raise ValueError(f"action must be in [0, {self.params.n_candidates}), got {action!r}")
        chosen = (
            self.candidates[k]
            if k < len(self.candidates)
            else (self.candidates[0] if self.candidates else None)
        )
        self.driver.command_goal(chosen)
        obs, reward, terminated, truncated, info = self._drive(
            self.params.max_macro_time_s, stop_on_goal=chosen is not None
        )
        info["chosen_goal_m"] = chosen.goal_xy_m if chosen is not None else None
        return obs, reward, terminated, truncated, info


class PlannerWeights(_MacroWrapper):
    """Choose the frontier cost weights ``(w_v, w_p, w_I)``; the expert plans and drives with them.

    The observation's candidates are ranked and scored with the paper's weights (so they do not
    depend on the previous action). Each decision lasts ``decision_period_s`` simulated seconds.

    Args:
        env: A ``SemanticExplore-v0`` env.
        driver: A :class:`FrontierDriver`.
        params: :class:`MacroParams`.
    """

    def __init__(
        self, env: gym.Env, driver: FrontierDriver, params: MacroParams | None = None
    ) -> None:
        super().__init__(env, driver, params)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(3,), dtype=np.float32)
        self._paper = FrontierCostWeights()

    def _scoring_weights(self) -> FrontierCostWeights | None:
        return self._paper

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        w = action_to_weights(action)
        self.driver.set_cost_weights(*w)
        obs, reward, terminated, truncated, info = self._drive(
            self.params.decision_period_s, stop_on_goal=False
        )
        info["weights"] = w
        return obs, reward, terminated, truncated, info

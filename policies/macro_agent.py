"""Run a trained macro-action agent (frontier choice or planner weights) as a step policy.

``semexplore train`` on ``SemanticExploreFrontier-v0`` (``--algo maskable_ppo``) or
``SemanticExploreWeights-v0`` (``--algo ppo``) saves an SB3 model whose actions are decisions,
not wheel commands: which of the top-``K`` frontier candidates to explore next, or which cost
weights ``(w_v, w_p, w_I)`` the expert plans with for the next ``decision_period_s``. Between
decisions the expert's navigation stack drives (:class:`~semexplore_gym.policies.expert.driver.ExpertDriver`).

:class:`MacroAgentPolicy` replays exactly that decision loop inside the ordinary
:class:`~semexplore_gym.policies.base.Policy` interface, so a macro agent runs wherever a policy spec is
accepted (``semexplore explore``, ``benchmark``, ``compare-weights --agents``) and is compared
with the expert on the same worlds and seeds. It decides when the macro env would: at the
first step, and afterwards once the commanded frontier is finished (reached, mapped, given up
or gone) or the decision's time budget (``max_macro_time_s`` / ``decision_period_s``) is used
up. The observation vector comes from :mod:`semexplore_gym.core.features.macro`, the same
code the env wrappers use.

The model's settings are read from the ``config.yaml`` that ``semexplore train`` writes beside
``model.zip`` (``env.env_id``, ``env.macro``, ``env.expert``); ``args.json`` names the algorithm.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import Any

import numpy as np
from semexplore_gym.policies.base import Policy
from semexplore_gym.policies.expert.driver import ExpertDriver
from semexplore_gym.policies.expert.expert import SemanticExpertParams

from semexplore_gym.config import build_params
from semexplore_gym.config.extras import require_extra
from semexplore_gym.core.features.macro import (
    MacroParams,
    action_mask,
    action_to_weights,
    observation_size,
    observation_vector,
)
from semexplore_gym.core.planning.graph_search import FrontierCandidate, FrontierCostWeights

#: Macro env ids and the kind of decision their agents make.
MACRO_ENV_KINDS = {
    "SemanticExploreFrontier-v0": "frontier",
    "SemanticExploreWeights-v0": "weights",
}


def read_macro_run(model_path: str | os.PathLike) -> dict[str, Any] | None:
    """The macro settings of a model saved by ``semexplore train``, or None if it is not one.

    Returns ``{"kind", "env_id", "algo", "macro", "expert"}`` read from ``config.yaml`` (and
    ``args.json``) in the model's directory; None when there is no ``config.yaml`` or its
    ``env.env_id`` is not a macro env id.

    Raises:
        ValueError: ``config.yaml`` exists but cannot be read.
    """
    run_dir = Path(model_path).resolve().parent
    cfg_path = run_dir / "config.yaml"
    if not cfg_path.is_file():
        return None
    from semexplore_gym.config.loading import load_yaml_file

    cfg = load_yaml_file(cfg_path, "run config") or {}  # bounded; ValueError names the file
    if not isinstance(cfg, dict) or not isinstance(cfg.get("env") or {}, dict):
        raise ValueError(f"{cfg_path} must hold a mapping with an 'env' mapping")
    env = cfg.get("env") or {}
    env_id = env.get("env_id")
    if env_id not in MACRO_ENV_KINDS:
        return None
    algo = None
    args_path = run_dir / "args.json"
    if args_path.is_file():
        try:
            algo = json.loads(args_path.read_text()).get("args", {}).get("algo")
        except (json.JSONDecodeError, AttributeError):
            algo = None
    kind = MACRO_ENV_KINDS[env_id]
    if algo is None:
        algo = "maskable_ppo" if kind == "frontier" else "ppo"
    return {
        "kind": kind,
        "env_id": env_id,
        "algo": algo,
        "macro": dict(env.get("macro") or {}),
        "expert": dict(env.get("expert") or {}),
    }


class MacroAgentPolicy(Policy):
    """A trained frontier-choice or planner-weights agent with the expert driving between decisions.

    Args:
        model_path: ``model.zip`` from ``semexplore train`` on a macro env id (its directory
            holds the run's ``config.yaml``).
        deterministic: Use the agent's most likely decision (True) or sample it.
        num_threads: ``torch.set_num_threads`` applied at load (process-wide); None leaves it.
        run: Settings to use instead of reading ``config.yaml`` (keys as returned by
            :func:`read_macro_run`).

    Attributes:
        decisions: Decisions taken this episode.
        last_decision: The last decision: ``{"time_s", "candidate", "goal_m"}`` (frontier) or
            ``{"time_s", "weights"}`` (weights).

    Raises:
        ValueError: the model is not a macro agent, or its observation size does not match the
            run's ``MacroParams``.
        FileNotFoundError: no such model file.
    """

    def __init__(
        self,
        model_path: str | os.PathLike,
        deterministic: bool = True,
        num_threads: int | None = 1,
        run: dict[str, Any] | None = None,
    ) -> None:
        super().__init__()
        path = Path(model_path)
        require_extra("rl", f"the macro-action agent {str(path)!r}", "torch", "stable_baselines3")
        if not path.is_file():
            raise FileNotFoundError(f"no model file at {path}")
        run = run if run is not None else read_macro_run(path)
        if run is None:
            raise ValueError(
                f"{path} is not a macro-action agent: its directory has no config.yaml with "
                f"env.env_id in {sorted(MACRO_ENV_KINDS)}"
            )
        if num_threads is not None:
            import torch as th

            th.set_num_threads(int(num_threads))
        algo_cls: Any
        if run["algo"] == "maskable_ppo":
            require_extra("rl", f"the macro-action agent {str(path)!r}", "sb3_contrib")
            from sb3_contrib import MaskablePPO

            algo_cls = MaskablePPO
        else:
            from stable_baselines3 import PPO

            algo_cls = PPO
        self.kind: str = run["kind"]
        self.macro_params: MacroParams = build_params(MacroParams, run["macro"])
        self.model = algo_cls.load(str(path), device="cpu")
        n_obs = observation_size(self.macro_params)
        if tuple(self.model.observation_space.shape or ()) != (n_obs,):
            raise ValueError(
                f"{path}: the model observes {self.model.observation_space.shape} values but "
                f"MacroParams(n_candidates={self.macro_params.n_candidates}) gives ({n_obs},)"
            )
        self.driver = ExpertDriver(build_params(SemanticExpertParams, run["expert"]))
        self.deterministic = bool(deterministic)
        self.name = f"macro-{self.kind}:{path.name}"
        self._paper = FrontierCostWeights()
        self._decision_t0_s = 0.0
        self._need_decision = True
        self.decisions = 0
        self.last_decision: dict[str, Any] = {}

    # ------------------------------------------------------------------ lifecycle
    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        super().reset(obs, info, seed=seed)
        self.driver.reset(obs, info, seed=seed)
        self._need_decision = True
        self._decision_t0_s = float(info.get("sim_time_s", 0.0))
        self.decisions = 0
        self.last_decision = {}

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        now_s = float(info.get("sim_time_s", 0.0))
        decide_ms = 0.0
        if self._decision_over(now_s):
            t0 = time.perf_counter()
            self._decide(obs, now_s)
            decide_ms = (time.perf_counter() - t0) * 1e3
        action = self.driver.act(obs, info)
        self.last_stats = self.driver.last_stats
        self.last_stats.extra["decision_ms"] = decide_ms
        if self.driver.done:
            self.done = True
            self.stop_reason = self.driver.stop_reason
        return action

    def overlay(self) -> dict[str, Any]:
        ov = dict(self.driver.overlay())
        if self.kind == "weights" and "weights" in self.last_decision:
            w_v, w_p, w_i = self.last_decision["weights"]
            ov["text"] = (
                ov.get("text", "") + f"\nweights w_v={w_v:.2f} w_p={w_p:.2f} w_I={w_i:.2f}"
            ).strip()
        return ov

    # ------------------------------------------------------------------ decisions
    def _decision_over(self, now_s: float) -> bool:
        if self._need_decision:
            return True
        elapsed = now_s - self._decision_t0_s
        if self.kind == "frontier":
            return self.driver.goal_finished or elapsed >= self.macro_params.max_macro_time_s - 1e-9
        return elapsed >= self.macro_params.decision_period_s - 1e-9

    def _decide(self, obs: dict[str, np.ndarray], now_s: float) -> None:
        # Weights agents were trained on candidates scored with the paper's weights (so the
        # observation does not depend on their own previous action); frontier agents on the
        # driver's current ones.
        scoring = self._paper if self.kind == "weights" else None
        cands = self.driver.frontier_candidates(obs, scoring)
        vec, shown = observation_vector(cands, obs["map"], now_s, self.macro_params)
        if self.kind == "frontier":
            mask = action_mask(len(shown), self.macro_params)
            raw, _ = self.model.predict(vec, deterministic=self.deterministic, action_masks=mask)
            k = int(np.asarray(raw).reshape(-1)[0])
            chosen: FrontierCandidate | None = (
                shown[k] if k < len(shown) else (shown[0] if shown else None)
            )
            self.driver.command_goal(chosen)
            self.last_decision = {
                "time_s": now_s,
                "candidate": k,
                "goal_m": chosen.goal_xy_m if chosen is not None else None,
            }
        else:
            raw, _ = self.model.predict(vec, deterministic=self.deterministic)
            weights = action_to_weights(np.asarray(raw, dtype=np.float64).reshape(-1))
            self.driver.set_cost_weights(*weights)
            self.last_decision = {"time_s": now_s, "weights": weights}
        self.decisions += 1
        self._need_decision = False
        self._decision_t0_s = now_s

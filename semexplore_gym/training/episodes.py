"""One labelled roll-out: the expert (or a beta-mix of expert and learner) drives and labels.

The expert is any :class:`semexplore_gym.policies.base.Policy` (normally the scripted semantic expert); it sees
the raw observation, the learner the egocentric features computed from that same observation
(:class:`EgocentricEncoder`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from semexplore_gym.core.features.egocentric import EgocentricEncoder, EgocentricParams
from semexplore_gym.policies.base import Policy
from semexplore_gym.policies.sb3_model import learner_action
from semexplore_gym.training.dataset import ImitationDataset


@dataclass
class EpisodeRecord:
    """One roll-out: the egocentric observations, the expert's labels and outcome facts.

    ``steps`` counts the labelled states; ``expert_fraction`` the share of steps that executed
    the expert's action.
    """

    data: ImitationDataset
    steps: int
    return_: float
    coverage: float
    expert_fraction: float
    end_reason: str


def _stack_obs(obs_list: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    return {k: np.stack([o[k] for o in obs_list]) for k in obs_list[0]}


@dataclass(frozen=True)
class EpisodeSpec:
    """What one roll-out does, besides env, expert and learner.

    Attributes:
        seed: Seed for ``env.reset`` and ``expert.reset``.
        max_steps: Step cap of the episode.
        episode_id: Episode id stored with the samples.
        noise_std: DART noise on the executed expert actions (0: none).
        beta: Probability of executing the expert's action (else the learner's).
    """

    seed: int | None = None
    max_steps: int = 1000
    episode_id: int = 0
    noise_std: float = 0.0
    beta: float = 1.0

    def check(self, has_learner: bool) -> None:
        """Raise a ValueError naming the first bad field."""
        if not (0.0 <= self.noise_std and math.isfinite(self.noise_std)):
            raise ValueError(f"noise_std must be a finite number >= 0, got {self.noise_std!r}")
        if not 0.0 <= self.beta <= 1.0:
            raise ValueError(f"beta must be in [0, 1], got {self.beta!r}")
        if not has_learner and self.beta < 1.0:
            raise ValueError("a learner is needed when beta < 1")
        if self.max_steps < 1:
            raise ValueError(f"max_steps must be >= 1, got {self.max_steps!r}")


def rollout_episode(
    env: Any,
    expert: Policy,
    params: EgocentricParams,
    spec: EpisodeSpec | None = None,
    learner: Any = None,
    rng: np.random.Generator | None = None,
) -> EpisodeRecord:
    """Run one episode, labelling every visited state with the expert's action.

    Each step executes the expert's action with probability ``spec.beta`` and the learner's
    otherwise (``learner`` may be None only when ``beta == 1``). The expert is asked every step,
    also when the learner drives, so its internal plan follows the visited states.

    With ``spec.noise_std > 0`` the executed expert action gets zero-mean Gaussian noise of that
    standard deviation per component (drawn from ``rng``, then clipped to [-1, 1]) while the
    label stays the clean action (DART, Laskey et al. 2017): the data then shows how the expert
    recovers from the small drifts a learner makes.

    Args:
        env: The raw ``SemanticExplore-v0`` env (not wrapped).
        expert: The labelling policy.
        params: Egocentric feature parameters (what the learner sees).
        spec: Seed, step cap, episode id, noise and beta (None: the defaults).
        learner: An SB3 policy (``predict``) or None.
        rng: Generator for the beta coin flips and the noise (default: from ``spec.seed``).
    """
    spec = spec if spec is not None else EpisodeSpec()
    spec.check(learner is not None)
    beta, noise_std, seed = spec.beta, spec.noise_std, spec.seed
    rng = rng if rng is not None else np.random.default_rng(seed)
    if learner is not None and hasattr(learner, "set_training_mode"):
        learner.set_training_mode(False)
    obs, info = env.reset(seed=seed)
    expert.reset(obs, info, seed=seed)
    encoder = EgocentricEncoder.from_info(params, info)
    feats: list[dict[str, np.ndarray]] = []
    labels: list[np.ndarray] = []
    ret, n_expert, end_reason = 0.0, 0, "max_steps"
    for _ in range(spec.max_steps):
        if not encoder.matches(info):
            encoder = EgocentricEncoder.from_info(params, info)
        f = encoder.encode(obs)
        a_expert = np.clip(
            np.asarray(expert.act(obs, info), dtype=np.float32).reshape(-1), -1.0, 1.0
        )
        feats.append(f)
        labels.append(a_expert)
        if expert.done:
            end_reason = f"expert_done:{expert.stop_reason}"
            break
        use_expert = beta >= 1.0 or rng.random() < beta
        n_expert += int(use_expert)
        if not use_expert:
            action = learner_action(learner, f)
        elif noise_std > 0.0:
            noise = rng.normal(0.0, noise_std, a_expert.shape).astype(np.float32)
            action = np.clip(a_expert + noise, -1.0, 1.0)
        else:
            action = a_expert
        obs, reward, terminated, truncated, info = env.step(action)
        ret += float(reward)
        if terminated or truncated:
            end_reason = "terminated" if terminated else "truncated"
            break
    n = len(labels)
    data = ImitationDataset(
        _stack_obs(feats),
        np.stack(labels).astype(np.float32),
        np.full(n, spec.episode_id, np.int64),
    )
    return EpisodeRecord(
        data, n, ret, float(info.get("coverage", math.nan)), n_expert / max(1, n), end_reason
    )

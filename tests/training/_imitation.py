"""Shared pieces of the training tests: a tiny world, small features, stand-in experts."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from semexplore_gym.policies.base import Policy

from semexplore_gym.training.dataset import ImitationDataset
from semexplore_gym.wrappers.egocentric import EgocentricParams

WORLD = "maze:size_m=5,seed=1"
# Small crop (NatureCNN needs >= 36 px) and coarse cells keep the tests fast.
PARAMS = EgocentricParams(crop_cells=36, crop_resolution_m=0.15, n_scan_bins=60)


def fake_episode(n: int, episode_id: int, rng: np.random.Generator) -> ImitationDataset:
    """``n`` random samples of one episode (no env needed)."""
    obs = {
        "image": rng.integers(0, 256, (n, 1, 8, 8), dtype=np.uint8),
        "scan": rng.random((n, 6), dtype=np.float32),
    }
    return ImitationDataset(
        obs, rng.uniform(-1, 1, (n, 2)).astype(np.float32), np.full(n, episode_id, np.int64)
    )


class ReactiveExpert(Policy):
    """Stand-in expert: a deterministic function of the scan (drive forward, steer to open space)."""

    name = "reactive"

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        scan = obs["scan"]
        max_r = float(info["lidar"]["max_range_m"])
        r = np.where(scan > 0, scan, max_r)
        ang = (np.arange(r.size) * 2 * math.pi / r.size + math.pi) % (2 * math.pi) - math.pi
        front = r[np.abs(ang) < 0.5].min()
        left = r[(ang > 0.3) & (ang < 1.6)].mean()
        right = r[(ang < -0.3) & (ang > -1.6)].mean()
        if front < 0.45:
            return np.array([0.0, 1.0 if left >= right else -1.0], np.float32)
        return np.array([min(1.0, front / 1.5), np.clip(0.8 * (left - right), -1, 1)], np.float32)


class ConstantExpert(Policy):
    """Always drives straight at half speed."""

    name = "constant"

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        return np.array([0.5, 0.0], np.float32)


def imitation_env() -> Any:
    """The raw env on :data:`WORLD` (random start), or a skip without the rl extra."""
    pytest.importorskip("torch")
    pytest.importorskip("stable_baselines3")
    import gymnasium as gym

    try:
        import semexplore_gym  # noqa: F401

        return gym.make("SemanticExplore-v0", world=WORLD, overrides=["episode.random_start=true"])
    except ImportError as e:  # the env's dependencies may still be landing
        pytest.skip(f"SemanticExplore-v0 not importable: {e}")


def learner_policy(seed: int = 0) -> Any:
    """A small fresh SB3 learner for :data:`PARAMS` features."""
    from gymnasium import spaces

    from semexplore_gym.training.learner import make_learner_policy
    from semexplore_gym.wrappers.egocentric import egocentric_observation_space

    return make_learner_policy(
        egocentric_observation_space(PARAMS),
        spaces.Box(-1.0, 1.0, (2,), np.float32),
        seed=seed,
        net_arch=[64, 64],
        log_std_init=-0.5,
        features_extractor_kwargs={"cnn_output_dim": 32},
    )

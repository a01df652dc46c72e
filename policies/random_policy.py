"""A random policy: uniform actions, a sanity baseline for rollouts and benchmarks."""

from __future__ import annotations

from typing import Any

import numpy as np
from semexplore_gym.policies.base import Policy, StepStats


class RandomPolicy(Policy):
    """Draws each action uniformly from ``[-1, 1]^2`` with the policy's ``rng`` (seeded by ``reset``).

    It never stops by itself (``done`` stays False); the env's truncation ends its missions.
    """

    name = "random"

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        self.last_stats = StepStats()
        return self.rng.uniform(-1.0, 1.0, size=2).astype(np.float32)

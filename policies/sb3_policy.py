"""Run a trained SB3 model (PPO, or a policy saved by BC/DAgger) as a :class:`Policy`."""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from policies.base import Policy, StepStats
from policies.sb3_model import learner_action, load_model
from semexplore_gym.core.features.egocentric import EgocentricEncoder


class SB3Policy(Policy):
    """A learned agent: egocentric features of the raw observation -> SB3 policy -> action.

    The model zip records the egocentric parameters it was trained with (written by
    ``semexplore train``), so the same features are computed here from the raw observation.

    Args:
        model_path: A model zip from ``semexplore train`` (PPO zip or BC/DAgger policy zip).
        deterministic: Use the mean action (True) or sample from the policy (False).
        device: torch device.
        num_threads: ``torch.set_num_threads`` value applied when the model loads (process-wide);
            None leaves torch's setting alone. One thread is the default because a batch-one
            forward pass of these small nets runs about 5-10x faster single-threaded on a busy
            2-core machine than with torch's default of one thread per core.
    """

    name = "sb3"

    def __init__(
        self,
        model_path: str | os.PathLike,
        deterministic: bool = True,
        device: str = "cpu",
        num_threads: int | None = 1,
    ) -> None:
        super().__init__()
        if num_threads is not None:
            if not isinstance(num_threads, int) or num_threads < 1:
                raise ValueError(
                    f"num_threads must be a positive integer or None, got {num_threads!r}"
                )
            import torch as th

            th.set_num_threads(num_threads)

        self.model_path = Path(model_path)
        self.deterministic = bool(deterministic)
        self.policy, self.params = load_model(self.model_path, device=device)
        self.name = f"sb3:{self.model_path.name}"
        self._encoder: EgocentricEncoder | None = None

    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        super().reset(obs, info, seed=seed)
        self._encoder = EgocentricEncoder.from_info(self.params, info)
        if not self.deterministic:
            import torch as th

            # Sampling draws from torch's global generator; seed it from the episode seed.
            th.manual_seed(int(self.rng.integers(0, 2**31 - 1)))

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        t0 = time.perf_counter()
        if self._encoder is None or ("map_geometry" in info and not self._encoder.matches(info)):
            self._encoder = EgocentricEncoder.from_info(self.params, info)
        features = self._encoder.encode(obs)
        t1 = time.perf_counter()
        action = learner_action(self.policy, features, deterministic=self.deterministic)
        t2 = time.perf_counter()
        self.last_stats = StepStats(
            map_generation_ms=(t1 - t0) * 1e3, local_planning_ms=(t2 - t1) * 1e3
        )
        return action

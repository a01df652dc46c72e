"""The SB3 learner of BC / DAgger: a fresh policy, and saving it as a model zip.

The learner is an SB3 actor-critic policy (``MultiInputActorCriticPolicy`` for the Dict
observation of :class:`semexplore_gym.wrappers.egocentric.EgocentricObservation`), so a
behaviour-cloned model can be fine-tuned with PPO. The zips written here are read by
:func:`semexplore_gym.policies.sb3_model.load_model`, which defines the format.
"""

from __future__ import annotations

import io
import json
import os
import zipfile
from pathlib import Path
from typing import Any

from semexplore_gym.core.features.egocentric import EgocentricParams
from semexplore_gym.policies.sb3_model import (
    FORMAT_POLICY,
    FORMAT_SB3_ALGORITHM,
    MODEL_META_NAME,
    POLICY_ENTRY_NAME,
)


def make_learner_policy(
    observation_space: Any, action_space: Any, lr: float = 3e-4, seed: int = 0, **policy_kwargs: Any
) -> Any:
    """A fresh SB3 actor-critic policy for the spaces (multi-input for Dict observations)."""
    import torch as th
    from gymnasium import spaces
    from stable_baselines3.common.policies import ActorCriticPolicy, MultiInputActorCriticPolicy

    th.manual_seed(seed)
    cls = (
        MultiInputActorCriticPolicy
        if isinstance(observation_space, spaces.Dict)
        else ActorCriticPolicy
    )
    return cls(observation_space, action_space, lambda _progress: lr, **policy_kwargs)


def save_policy(policy: Any, path: str | os.PathLike, params: EgocentricParams) -> Path:
    """Save a bare SB3 policy as a zip that ``semexplore_gym.policies.sb3_model.load_model`` and ``SB3Policy`` read."""
    import torch as th

    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    buf = io.BytesIO()
    th.save({"state_dict": policy.state_dict(), "data": policy._get_constructor_parameters()}, buf)
    meta = {
        "format": FORMAT_POLICY,
        "policy_class": type(policy).__name__,
        "egocentric": params.to_dict(),
    }
    with zipfile.ZipFile(p, "w") as z:
        z.writestr(POLICY_ENTRY_NAME, buf.getvalue())
        z.writestr(MODEL_META_NAME, json.dumps(meta, sort_keys=True))
    return p


def tag_model_zip(path: str | os.PathLike, params: EgocentricParams, algo: str) -> None:
    """Add the egocentric parameters to an SB3 algorithm zip (SB3 ignores the extra entry)."""
    meta = {"format": FORMAT_SB3_ALGORITHM, "algo": algo, "egocentric": params.to_dict()}
    with zipfile.ZipFile(path, "a") as z:
        if MODEL_META_NAME not in z.namelist():
            z.writestr(MODEL_META_NAME, json.dumps(meta, sort_keys=True))

"""Trained SB3 models as the policies see them: the model zip format, loading, acting.

A model zip is either an SB3 algorithm zip (PPO, A2C, SAC ...) or a bare policy saved by
behaviour cloning / DAgger (``policy.pt``: constructor arguments and weights). Both carry a
JSON record :data:`MODEL_META_NAME` naming the format and the :class:`EgocentricParams` the model
was trained with, so the same features can be computed from a raw observation. The writers
(``semexplore_gym.training.learner``) use the constants defined here.

torch and stable-baselines3 (the ``rl`` extra) are imported inside the functions that need them.
"""

from __future__ import annotations

import io
import json
import os
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.core.features.egocentric import EgocentricParams

#: Name of the JSON record stored inside model zips: format, policy class and feature parameters.
MODEL_META_NAME = "semexplore.json"
#: Entry of a bare-policy zip holding the torch-saved constructor arguments and weights.
POLICY_ENTRY_NAME = "policy.pt"
#: ``format`` of a bare policy saved by BC / DAgger.
FORMAT_POLICY = "policy"
#: ``format`` of an SB3 algorithm zip tagged with the egocentric parameters.
FORMAT_SB3_ALGORITHM = "sb3_algorithm"


def learner_action(
    policy: Any, features: dict[str, np.ndarray], deterministic: bool = True
) -> np.ndarray:
    """Action of an SB3 policy for one egocentric observation, clipped to [-1, 1].

    Calls the policy's network directly: SB3's ``predict`` also toggles the training mode and
    re-validates the observation each call, which costs more than the forward pass itself.
    The policy must already be in evaluation mode (``set_training_mode(False)``).
    """
    import torch as th

    with th.inference_mode():
        obs_t = {k: th.as_tensor(v, device=policy.device).unsqueeze(0) for k, v in features.items()}
        action = policy._predict(obs_t, deterministic=deterministic)
    return np.clip(action.cpu().numpy().astype(np.float32).reshape(-1), -1.0, 1.0)


def load_model(path: str | os.PathLike, device: str = "cpu") -> tuple[Any, EgocentricParams]:
    """Load ``(sb3_policy, egocentric_params)`` from a PPO/A2C/SAC zip or a ``save_policy`` zip."""
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"model not found: {str(p)!r}")
    if not zipfile.is_zipfile(p):
        raise ValueError(f"{str(p)!r} is not a model zip")
    with zipfile.ZipFile(p) as z:
        names = z.namelist()
        meta = json.loads(z.read(MODEL_META_NAME)) if MODEL_META_NAME in names else {}
        policy_bytes = z.read(POLICY_ENTRY_NAME) if POLICY_ENTRY_NAME in names else None
        is_algorithm_zip = "data" in names
    params = EgocentricParams.from_dict(meta.get("egocentric"))
    if policy_bytes is not None:
        import torch as th
        from stable_baselines3.common import policies as sb3_policies

        cls = getattr(
            sb3_policies, str(meta.get("policy_class", "MultiInputActorCriticPolicy")), None
        )
        if cls is None:
            raise ValueError(f"{str(p)!r}: unknown policy class {meta.get('policy_class')!r}")
        saved = th.load(io.BytesIO(policy_bytes), map_location=device, weights_only=False)
        policy = cls(**saved["data"])
        policy.load_state_dict(saved["state_dict"])
        policy.to(device)
        policy.set_training_mode(False)
        return policy, params
    if not is_algorithm_zip:
        raise ValueError(f"{str(p)!r} is neither an SB3 model zip nor a saved policy")
    import stable_baselines3

    algo_name = str(meta.get("algo", "ppo")).upper()
    algo_cls = getattr(stable_baselines3, algo_name, None) if algo_name.isalnum() else None
    if algo_cls is None:
        raise ValueError(f"{str(p)!r}: unknown SB3 algorithm {algo_name!r}")
    model = algo_cls.load(p, device=device)
    model.policy.set_training_mode(False)
    return model.policy, params

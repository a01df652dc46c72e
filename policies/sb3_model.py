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


#: Environment variable that lets :func:`load_policy_entry` unpickle classes outside its
#: allowlist (a custom feature extractor, say): full pickle, for files you trust only.
TRUST_ENV_VAR = "SEMEXPLORE_TRUST_MODEL_PICKLE"


def _safe_globals() -> list[Any]:
    """Classes a ``policy.pt`` of an SB3 policy needs, and nothing that runs arbitrary code.

    The constructor arguments saved next to the weights hold gymnasium spaces (numpy arrays
    and dtypes inside), the activation and optimizer classes, the feature-extractor class and
    the learning-rate schedule, which SB3 saves as ``getattr(BasePolicy, "_dummy_schedule")``:
    ``builtins.getattr`` is replaced by :func:`_schedule_getattr`, which resolves only that.
    """
    import inspect

    import gymnasium.spaces as gs
    import numpy as np
    import torch as th
    from stable_baselines3.common import policies as sb3_policies
    from stable_baselines3.common import torch_layers

    out: list[Any] = [
        gs.Dict,
        gs.Box,
        gs.Discrete,
        gs.MultiDiscrete,
        gs.MultiBinary,
        np.ndarray,
        np.dtype,
        sb3_policies.BasePolicy,
        (_schedule_getattr, "builtins.getattr"),
    ]
    try:  # numpy >= 2 moved the reconstructor
        from numpy._core.multiarray import _reconstruct
    except ImportError:  # pragma: no cover - numpy 1.x
        from numpy.core.multiarray import _reconstruct  # type: ignore[no-redef]
    out.append(_reconstruct)
    # A space that has sampled carries its numpy Generator (rebuilt from a bit-generator state).
    import numpy.random._pickle as rng_pickle
    from numpy.random import bit_generator

    out += [
        getattr(rng_pickle, "__generator_ctor"),
        getattr(rng_pickle, "__bit_generator_ctor"),
        np.random.Generator,
        np.random.SeedSequence,
        np.random.PCG64,
        np.random.PCG64DXSM,
        np.random.MT19937,
        np.random.Philox,
        np.random.SFC64,
    ]
    unpickle_seq = getattr(bit_generator, "__pyx_unpickle_SeedSequence", None)
    if unpickle_seq is not None:
        out.append(unpickle_seq)
    out += [
        c
        for c in vars(np.dtypes).values()
        if isinstance(c, type) and c.__name__.endswith("DType") and c is not np.dtype
    ]
    for module, base in (
        (th.nn.modules.activation, th.nn.Module),
        (th.optim, th.optim.Optimizer),
        (torch_layers, th.nn.Module),
    ):
        out += [
            c
            for _, c in inspect.getmembers(module, inspect.isclass)
            if issubclass(c, base) and c.__module__.startswith(("torch.", "stable_baselines3."))
        ]
    return out


def _schedule_getattr(obj: Any, name: str) -> Any:
    """``getattr`` as a ``policy.pt`` may use it: only SB3's dummy learning-rate schedule."""
    from stable_baselines3.common.policies import BasePolicy

    if isinstance(obj, type) and issubclass(obj, BasePolicy) and name == "_dummy_schedule":
        return getattr(obj, name)
    raise ValueError(f"policy.pt asks for {getattr(obj, '__name__', obj)!r}.{name}; refused")


def load_policy_entry(data: bytes, source: Path, device: str = "cpu") -> Any:
    """Unpickle a ``policy.pt`` with ``torch.load(weights_only=True)`` and an allowlist.

    The entry holds the policy's constructor arguments as well as its weights, so a plain
    ``weights_only=True`` load refuses it; the allowlist (:func:`_safe_globals`) admits the
    spaces, layer, optimizer and extractor classes of SB3 and torch and nothing that can run
    code. A model whose arguments need another class (a custom extractor) is refused with its
    name, unless :data:`TRUST_ENV_VAR` is set to 1 (full pickle: for trusted files only).
    """
    import pickle

    import torch as th

    try:
        with th.serialization.safe_globals(_safe_globals()):
            return th.load(io.BytesIO(data), map_location=device, weights_only=True)
    except pickle.UnpicklingError as e:
        if os.environ.get(TRUST_ENV_VAR) == "1":
            return th.load(io.BytesIO(data), map_location=device, weights_only=False)
        import re

        found = re.search(
            r"(?:unsupported|Unsupported global:) GLOBAL ([\w.]+)|but got <class '([\w.]+)'>",
            str(e),
        )
        what = (
            f"it needs {found.group(1) or found.group(2)}"
            if found
            else str(e).strip()[:200] or type(e).__name__
        )
        raise ValueError(
            f"{str(source)!r}: policy.pt holds more than weights and SB3's own classes ({what}); "
            f"if you trust this file, set {TRUST_ENV_VAR}=1 to load it anyway"
        ) from None


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
        from stable_baselines3.common import policies as sb3_policies

        cls = getattr(
            sb3_policies, str(meta.get("policy_class", "MultiInputActorCriticPolicy")), None
        )
        if cls is None:
            raise ValueError(f"{str(p)!r}: unknown policy class {meta.get('policy_class')!r}")
        saved = load_policy_entry(policy_bytes, p, device)
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

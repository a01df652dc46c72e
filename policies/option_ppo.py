"""An SB3 explorer over frontier options: a set scorer as actor, a privileged critic.

The network of ``pretrained:option_ppo`` (trained by :mod:`semexplore_gym.training.option_ppo`
on ``SemanticExploreOptions-v0``, :mod:`semexplore_gym.wrappers.option_choice`):

* **Actor**: one small MLP shared by every option row, over that row's scaled features and the
  global features, gives the row's logit; padding rows are masked. Permuting the options
  permutes the logits. The actor reads ``options``, ``valid`` and ``global`` only.
* **Critic**: a per-option MLP over the row's features, its privileged features (true unseen
  area near the goal, training only) and the global features, mean-pooled over the valid rows,
  then an MLP with the privileged global feature (unseen share of the world) gives the value.

:class:`OptionPPOPolicy` drives: the frontier student's navigation, and at each choice among
two or more options the actor's most likely row. It never sees privileged features.

torch, SB3 and sb3-contrib are imported when a network is built or loaded (the ``rl`` extra);
the SB3 classes are built on first use and served by this module's ``__getattr__``, so models
saved by SB3 load by reference.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
from semexplore_gym.policies.frontier_student import (
    FrontierStudentParams,
    FrontierStudentPolicy,
    StudentDecision,
)

from semexplore_gym.core.features.frontier_option_features import OPTION_FEATURE_NAMES
from semexplore_gym.core.features.option_observation import (
    GLOBAL_FEATURE_NAMES,
    PRIVILEGED_FEATURE_NAMES,
    option_observation,
)

__all__ = ["OptionPPOPolicy", "option_network_classes"]

K = len(OPTION_FEATURE_NAMES)
G = len(GLOBAL_FEATURE_NAMES)
P = len(PRIVILEGED_FEATURE_NAMES)


def _option_nets_class() -> type:
    """The actor-critic module (torch imported here)."""
    import torch as th
    from torch import nn

    def mlp(sizes: list[int], last_act: bool = False) -> nn.Sequential:
        layers: list[nn.Module] = []
        for i in range(len(sizes) - 1):
            layers.append(nn.Linear(sizes[i], sizes[i + 1]))
            if i < len(sizes) - 2 or last_act:
                layers.append(nn.Tanh())
        return nn.Sequential(*layers)

    class OptionNets(nn.Module):
        """The actor's per-option scorer and the privileged critic (see the module)."""

        def __init__(self, n_options: int, privileged: bool, hidden: int) -> None:
            super().__init__()
            self.n, self.privileged, self.hidden = n_options, privileged, hidden
            self.latent_dim_pi, self.latent_dim_vf = n_options, hidden
            self.actor = mlp([K + G, hidden, hidden, 1])
            p_row = P if privileged else 0
            self.critic_rows = mlp([K + p_row + G, hidden, hidden], last_act=True)
            self.critic_head = mlp([hidden + G + (P if privileged else 0), hidden], last_act=True)

        def split(self, features: Any) -> tuple[Any, Any, Any, Any]:
            n, b = self.n, features.shape[0]
            opts = features[:, : n * K].reshape(b, n, K)
            valid = features[:, n * K : n * K + n]
            glob = features[:, n * K + n : n * K + n + G]
            priv = features[:, n * K + n + G :].reshape(b, n + 1, P) if self.privileged else None
            return opts, valid, glob, priv

        def actor_logits(self, opts: Any, valid: Any, glob: Any) -> Any:
            """``(B, n)`` logits of ``(B, n, K)`` rows; padding rows get -1e8."""
            g = glob[:, None, :].expand(-1, opts.shape[1], -1)
            logits = self.actor(th.cat([opts, g], dim=2)).squeeze(2)
            return th.where(valid > 0, logits, th.full_like(logits, -1e8))

        def forward_actor(self, features: Any) -> Any:
            opts, valid, glob, _ = self.split(features)  # never the privileged part
            return self.actor_logits(opts, valid, glob)

        def forward_critic(self, features: Any) -> Any:
            opts, valid, glob, priv = self.split(features)
            g = glob[:, None, :].expand(-1, self.n, -1)
            rows = [opts] + ([priv[:, : self.n]] if priv is not None else []) + [g]
            h = self.critic_rows(th.cat(rows, dim=2))
            w = valid[:, :, None]
            pooled = (h * w).sum(1) / w.sum(1).clamp(min=1.0)
            tail = [pooled, glob] + ([priv[:, self.n]] if priv is not None else [])
            return self.critic_head(th.cat(tail, dim=1))

        def forward(self, features: Any) -> tuple[Any, Any]:
            return self.forward_actor(features), self.forward_critic(features)

    return OptionNets


@cache
def option_network_classes() -> dict[str, type]:
    """``{"OptionExtractor", "OptionNets", "OptionActorCriticPolicy"}`` (torch imported here)."""
    import torch as th
    from sb3_contrib.common.maskable.policies import MaskableActorCriticPolicy
    from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
    from torch import nn

    OptionNets = _option_nets_class()

    class OptionExtractor(BaseFeaturesExtractor):
        """Flattens ``options``, ``valid``, ``global`` (and ``privileged``) in that order."""

        def __init__(self, observation_space: Any) -> None:
            n = observation_space["valid"].shape[0]
            self.n_options = n
            self.privileged = "privileged" in observation_space.spaces
            dim = n * K + n + G + ((n + 1) * P if self.privileged else 0)
            super().__init__(observation_space, features_dim=dim)

        def forward(self, obs: dict[str, Any]) -> Any:
            keys = ["options", "valid", "global"] + (["privileged"] if self.privileged else [])
            return th.cat([obs[k].reshape(obs[k].shape[0], -1) for k in keys], dim=1)

    class OptionActorCriticPolicy(MaskableActorCriticPolicy):
        """MaskablePPO's policy with :class:`OptionNets`; the action head is the identity."""

        def __init__(self, *args: Any, hidden: int = 64, **kwargs: Any) -> None:
            self.hidden = hidden
            kwargs.setdefault("features_extractor_class", OptionExtractor)
            super().__init__(*args, **kwargs)

        def _build_mlp_extractor(self) -> None:
            ext: Any = self.features_extractor
            nets: Any = OptionNets(ext.n_options, ext.privileged, self.hidden)
            self.mlp_extractor = nets

        def _build(self, lr_schedule: Any) -> None:
            self._build_mlp_extractor()
            self.action_net = nn.Identity()
            self.value_net = nn.Linear(self.mlp_extractor.latent_dim_vf, 1)
            make_optimizer: Any = self.optimizer_class
            self.optimizer = make_optimizer(
                self.parameters(), lr=lr_schedule(1), **self.optimizer_kwargs
            )

        def _get_constructor_parameters(self) -> dict[str, Any]:
            return {**super()._get_constructor_parameters(), "hidden": self.hidden}

    classes = (OptionExtractor, OptionNets, OptionActorCriticPolicy)
    for cls in classes:  # importable by reference (this module's __getattr__)
        cls.__module__ = __name__
        cls.__qualname__ = cls.__name__
    return {cls.__name__: cls for cls in classes}


def __getattr__(name: str) -> Any:
    if name in ("OptionExtractor", "OptionNets", "OptionActorCriticPolicy"):
        return option_network_classes()[name]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def load_option_model(path: str | Path) -> Any:
    """A MaskablePPO model saved by :mod:`semexplore_gym.training.option_ppo` (CPU).

    Raises:
        FileNotFoundError: no file at ``path``.
    """
    from sb3_contrib import MaskablePPO

    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"option_ppo model {p} does not exist")
    cls = option_network_classes()["OptionActorCriticPolicy"]
    return MaskablePPO.load(str(p), device="cpu", custom_objects={"policy_class": cls})


class OptionPPOPolicy(FrontierStudentPolicy):
    """The frontier student whose choices are the option actor's (most likely valid row).

    Args:
        model: A path to the model zip, or a loaded MaskablePPO model.
        params: The student's parameters (navigation; its linear model is not used).
    """

    name = "option-ppo"

    def __init__(self, model: Any, params: FrontierStudentParams | None = None) -> None:
        super().__init__(params)
        import torch as th

        self._th = th
        loaded = load_option_model(model) if isinstance(model, (str, Path)) else model
        self.nets = loaded.policy.mlp_extractor
        self.max_options = int(self.nets.n)
        self.time_scale_s = float(getattr(loaded, "option_time_scale_s", 1500.0))
        self.chooser = self._pick

    def row_logits(self, decision: StudentDecision) -> tuple[np.ndarray, np.ndarray]:
        """The actor's ``(max_options,)`` logits and the option index of each valid row."""
        th = self._th
        ob = option_observation(
            decision.features, decision.grid, decision.time_s, self.max_options, self.time_scale_s
        )
        with th.no_grad():
            logits = self.nets.actor_logits(
                th.as_tensor(ob.options[None]),
                th.as_tensor(ob.valid[None]),
                th.as_tensor(ob.global_features[None]),
            )
        return logits[0].numpy(), ob.slots

    def _pick(self, decision: StudentDecision) -> int | None:
        if len(decision.options) < 2:
            return None
        logits, slots = self.row_logits(decision)
        return int(slots[int(np.argmax(logits[: len(slots)]))])

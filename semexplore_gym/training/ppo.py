"""PPO and MaskablePPO set-up and training for ``semexplore train --algo ppo|maskable_ppo``.

On the base env the learner is a ``MultiInputPolicy`` over the egocentric observation (a
BC/DAgger model can be its starting point, ``ppo.init_from``); on a macro-action env id it is an
MLP over that env's own observation, and MaskablePPO uses the env's ``action_masks``.
"""

from __future__ import annotations

import os
import time
from functools import partial
from pathlib import Path
from typing import Any

from semexplore_gym.core.features.egocentric import EgocentricParams
from semexplore_gym.training.factories import make_learner_env
from semexplore_gym.training.train_config import TrainConfig, is_macro, maskable_needs_macro


def policy_kwargs(cfg: TrainConfig) -> dict[str, Any]:
    """SB3 ``policy_kwargs`` of the egocentric learner (MLP heads, CNN size, initial log std)."""
    p = cfg.policy
    return {
        "net_arch": {"pi": list(p.net_arch), "vf": list(p.net_arch)},
        "log_std_init": p.log_std_init,
        "features_extractor_kwargs": {"cnn_output_dim": p.cnn_output_dim},
    }


def new_ppo(cfg: TrainConfig, vec_env: Any, tensorboard_log: str | None, algo: str = "ppo") -> Any:
    """A fresh PPO (or, with ``algo="maskable_ppo"``, sb3-contrib MaskablePPO) for ``vec_env``."""
    pc = cfg.ppo
    algo_cls: Any
    if algo == "maskable_ppo":
        if not is_macro(cfg):
            raise maskable_needs_macro(cfg)
        from sb3_contrib import MaskablePPO

        algo_cls = MaskablePPO
    else:
        from stable_baselines3 import PPO

        algo_cls = PPO
    if is_macro(cfg):
        policy_name = "MlpPolicy"
        kwargs: dict[str, Any] = {
            "net_arch": {"pi": list(cfg.policy.net_arch), "vf": list(cfg.policy.net_arch)}
        }
        if algo != "maskable_ppo":
            kwargs["log_std_init"] = cfg.policy.log_std_init
    else:
        policy_name, kwargs = "MultiInputPolicy", policy_kwargs(cfg)
    return algo_cls(
        policy_name,
        vec_env,
        learning_rate=pc.learning_rate,
        n_steps=pc.n_steps,
        batch_size=pc.batch_size,
        n_epochs=pc.n_epochs,
        gamma=pc.gamma,
        ent_coef=pc.ent_coef,
        policy_kwargs=kwargs,
        tensorboard_log=tensorboard_log,
        seed=cfg.seed,
        device="cpu",
        verbose=0,
    )


def auto_vec_env(n_envs: int, cpu_count: int | None = None) -> str:
    """``ppo.vec_env: auto``: a worker process per env (``"subproc"``) only when the machine has
    a core for each env and one for the learner; otherwise all envs in the learner's process
    (``"dummy"``), which measured faster on 2 cores for 2 and 4 envs (its batched forward pass
    and no inter-process messaging outweigh the parallel env steps)."""
    cores = (os.cpu_count() or 1) if cpu_count is None else cpu_count
    return "subproc" if n_envs > 1 and cores > n_envs else "dummy"


def make_vec_env(cfg: TrainConfig, n_envs: int | None = None, vec_env: str | None = None) -> Any:
    """``n_envs`` learner envs, seeded, episodes capped at ``ppo.max_episode_steps``, stepped
    in worker processes or in this one; ``n_envs`` and ``vec_env`` default to ``cfg.ppo``'s."""
    from stable_baselines3.common.env_util import make_vec_env as sb3_make_vec_env
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    n = cfg.ppo.n_envs if n_envs is None else int(n_envs)
    kind = cfg.ppo.vec_env if vec_env is None else vec_env
    if kind == "auto":
        kind = auto_vec_env(n)
    return sb3_make_vec_env(
        partial(make_learner_env, cfg, cfg.ppo.max_episode_steps),
        n_envs=n,
        seed=cfg.seed,
        vec_env_cls=SubprocVecEnv if kind == "subproc" else DummyVecEnv,
    )


def save_tagged_model(model: Any, path: Path, params: EgocentricParams) -> None:
    """Save an SB3 algorithm with its egocentric parameters (``SB3Policy`` reads them back)."""
    from semexplore_gym.training.learner import tag_model_zip

    model.save(str(path))
    tag_model_zip(path, params, algo="ppo")


def _load_init_weights(cfg: TrainConfig, model: Any, init_from: str) -> None:
    """Start ``model`` from the BC/DAgger model ``init_from`` (same features and network)."""
    from semexplore_gym.policies.sb3_model import load_model

    if is_macro(cfg):
        raise ValueError(
            f"ppo.init_from (a BC/DAgger model) only fits the egocentric env, not env.env_id={cfg.env.env_id!r}"
        )
    params = cfg.egocentric
    init_policy, init_params = load_model(init_from)
    if init_params != params:
        raise ValueError(
            f"ppo.init_from model uses egocentric {init_params.to_dict()} but this config uses {params.to_dict()}"
        )
    missing = model.policy.load_state_dict(init_policy.state_dict(), strict=False)
    if missing.missing_keys or missing.unexpected_keys:
        raise ValueError(f"ppo.init_from model does not match the policy network: {missing}")


def train_ppo(cfg: TrainConfig, algo: str, out: Path, progress: bool = False) -> dict[str, Any]:
    """Train ``algo`` (``ppo`` or ``maskable_ppo``) and save ``out/model.zip``; returns metrics.

    SB3's own logger writes TensorBoard logs to ``out/tb/<algo>_N``.
    """
    vec_env = make_vec_env(cfg)
    model = new_ppo(cfg, vec_env, str(out / "tb"), algo=algo)
    if cfg.ppo.init_from:
        _load_init_weights(cfg, model, cfg.ppo.init_from)
    t0 = time.perf_counter()
    model.learn(total_timesteps=cfg.ppo.total_timesteps, progress_bar=progress, tb_log_name=algo)
    metrics = {"ppo_s": time.perf_counter() - t0, "timesteps": int(model.num_timesteps)}
    if is_macro(cfg):
        # Not an egocentric-observation model: no tag, it is loaded with the algorithm's own load().
        model.save(str(out / "model.zip"))
    else:
        save_tagged_model(model, out / "model.zip", cfg.egocentric)
    vec_env.close()
    return metrics

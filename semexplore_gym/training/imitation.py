"""The ``bc`` and ``dagger`` runs of ``semexplore train``: record, behaviour-clone, DAgger, save.

The learner is the policy object of a fresh PPO model, so the saved ``model.zip`` is an SB3
algorithm zip that ``semexplore train --algo ppo`` (``ppo.init_from``) can fine-tune.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.training.bc import action_error, train_bc
from semexplore_gym.training.config import TrainConfig
from semexplore_gym.training.dagger import run_dagger
from semexplore_gym.training.dataset import ImitationDataset
from semexplore_gym.training.factories import make_expert, make_raw_env
from semexplore_gym.training.ppo import make_vec_env, new_ppo, save_tagged_model
from semexplore_gym.training.recording import record_expert_dataset

LogFn = Callable[[str, float, int], None]


def check_mirror(cfg: TrainConfig, raw_env: Any) -> None:
    """``bc.mirror`` needs a scan that mirrors exactly: centred bins of an odd beam count."""
    params = cfg.egocentric
    n_beams = raw_env.unwrapped.config.lidar.n_beams
    per_bin = n_beams // params.n_scan_bins
    if not params.scan_bins_centred or per_bin % 2 == 0:
        raise ValueError(
            "bc.mirror needs egocentric.scan_bins_centred=true and an odd number of beams per "
            f"scan bin; got scan_bins_centred={params.scan_bins_centred}, "
            f"{n_beams} beams / {params.n_scan_bins} bins = {per_bin}"
        )


def bc_kwargs(cfg: TrainConfig, progress: bool) -> dict[str, Any]:
    """:func:`train_bc` keyword arguments of the ``bc`` section (all but epochs and data)."""
    bc = cfg.bc
    return {
        "batch_size": bc.batch_size,
        "lr": bc.lr,
        "ent_weight": bc.ent_weight,
        "l2_weight": bc.l2_weight,
        "progress": progress,
        "mirror_params": cfg.egocentric if bc.mirror else None,
        "select_best": bc.select_best,
        "lr_final_fraction": bc.lr_final_fraction,
    }


def record(
    cfg: TrainConfig, raw_env: Any, expert: Any, path: Path, log: LogFn, progress: bool
) -> ImitationDataset:
    """The expert dataset of the ``expert`` section, written to ``path``."""
    return record_expert_dataset(
        raw_env,
        expert,
        path,
        cfg.expert.episodes,
        cfg.egocentric,
        seed=cfg.seed,
        max_steps=cfg.expert.max_steps,
        meta={"world": cfg.env.world, "expert_spec": cfg.expert.spec},
        progress=progress,
        log_fn=log,
        noise_std=cfg.expert.noise_std,
        noise_fraction=cfg.expert.noise_fraction,
        save_interval_s=cfg.expert.save_interval_s,
        workers=cfg.expert.workers,
        make_env=functools.partial(make_raw_env, cfg),
        make_expert=functools.partial(make_expert, cfg),
    )


def dagger_rounds(
    cfg: TrainConfig,
    raw_env: Any,
    expert: Any,
    policy: Any,
    train: ImitationDataset,
    eval_data: ImitationDataset | None,
    out: Path,
    log: LogFn,
    progress: bool,
) -> list[dict[str, float]]:
    """The ``dagger`` section's rounds on top of the BC fit; returns the per-round facts."""
    d = cfg.dagger
    result = run_dagger(
        raw_env,
        expert,
        policy,
        cfg.egocentric,
        rounds=d.rounds,
        beta=list(d.beta),
        episodes_per_round=d.episodes_per_round,
        dataset=train,
        dataset_path=out / "dagger_dataset.npz",
        bc_kwargs={
            **bc_kwargs(cfg, progress),
            "epochs": d.epochs_per_round,
            "progress": False,
            "eval_data": eval_data,
            "select_best": d.select_best,
        },
        seed=cfg.seed,
        max_steps=cfg.expert.max_steps,
        progress=progress,
        log_fn=log,
        save_interval_s=cfg.expert.save_interval_s,
        workers=d.workers,
        make_env=functools.partial(make_raw_env, cfg),
        make_expert=functools.partial(make_expert, cfg),
    )
    return result.rounds


def train_imitation(
    cfg: TrainConfig, algo: str, out: Path, log: LogFn, progress: bool = False
) -> dict[str, Any]:
    """Record, behaviour-clone and (``algo="dagger"``) run DAgger; save ``out/model.zip``.

    Args:
        cfg: The run's configuration.
        algo: ``"bc"`` or ``"dagger"``.
        out: Run directory (``dataset.npz``, ``dagger_dataset.npz``, ``model.zip``).
        log: ``log(tag, value, step)`` for scalars.
        progress: tqdm bars.

    Returns:
        The run's metrics (sizes, timings, held-out action errors, DAgger rounds).
    """
    raw_env = make_raw_env(cfg)
    if cfg.bc.mirror:
        check_mirror(cfg, raw_env)
    expert = make_expert(cfg)
    t0 = time.perf_counter()
    data = record(cfg, raw_env, expert, out / "dataset.npz", log, progress)
    record_s = time.perf_counter() - t0
    train, held = data.split_by_episode(
        cfg.expert.holdout_fraction, np.random.default_rng(cfg.seed)
    )
    # PPO's policy object is the learner, so a BC model can be fine-tuned by `train --algo ppo`.
    # One env in this process: the vec env only gives the learner its spaces.
    model = new_ppo(cfg, make_vec_env(cfg, n_envs=1, vec_env="dummy"), None)
    policy = model.policy
    metrics: dict[str, Any] = {
        "dataset_samples": len(data),
        "dataset_episodes": data.n_episodes,
        "record_s": record_s,
    }
    if len(held):
        metrics["heldout_action_error_before"] = action_error(policy, held)
        # Reference: always answering the training set's mean action.
        mean_action = train.actions.mean(axis=0)
        metrics["heldout_action_error_mean_action"] = float(
            np.abs(held.actions - mean_action).mean()
        )
    t0 = time.perf_counter()
    eval_data = held if len(held) else None
    hist = train_bc(
        train,
        policy,
        epochs=cfg.bc.epochs,
        seed=cfg.seed,
        log_fn=log,
        eval_data=eval_data,
        **bc_kwargs(cfg, progress),
    )
    metrics["bc_s"] = time.perf_counter() - t0
    metrics["bc_final_loss"] = hist["loss"][-1]
    if "best_epoch" in hist:
        metrics["bc_best_epoch"] = int(hist["best_epoch"][0])
    if len(held):
        metrics["heldout_action_error_after_bc"] = action_error(policy, held)
        log("bc/heldout_action_error", metrics["heldout_action_error_after_bc"], cfg.bc.epochs)
    if algo == "dagger":
        t0 = time.perf_counter()
        rounds = dagger_rounds(cfg, raw_env, expert, policy, train, eval_data, out, log, progress)
        metrics["dagger_s"] = time.perf_counter() - t0
        metrics["dagger_rounds"] = rounds
        if len(held):
            metrics["heldout_action_error_after_dagger"] = action_error(policy, held)
    save_tagged_model(model, out / "model.zip", cfg.egocentric)
    raw_env.close()
    return metrics

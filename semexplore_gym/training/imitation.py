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
from semexplore_gym.training.dagger import run_dagger
from semexplore_gym.training.dataset import ImitationDataset
from semexplore_gym.training.factories import make_expert, make_raw_env
from semexplore_gym.training.ppo import make_vec_env, new_ppo, save_tagged_model
from semexplore_gym.training.recording import record_expert_dataset
from semexplore_gym.training.train_config import TrainConfig
from semexplore_gym.training.workers import EpisodeActors

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


def actors(cfg: TrainConfig, raw_env: Any, expert: Any) -> EpisodeActors:
    """The run's env and expert, and the workers' factories of their own."""
    return EpisodeActors(
        raw_env,
        expert,
        make_env=functools.partial(make_raw_env, cfg),
        make_expert=functools.partial(make_expert, cfg),
    )


def record(
    cfg: TrainConfig, raw_env: Any, expert: Any, path: Path, log: LogFn, progress: bool
) -> ImitationDataset:
    """The expert dataset of the ``expert`` section, written to ``path``."""
    return record_expert_dataset(
        actors(cfg, raw_env, expert),
        path,
        cfg.egocentric,
        cfg.expert,
        seed=cfg.seed,
        meta={"world": cfg.env.world, "expert_spec": cfg.expert.spec},
        progress=progress,
        log_fn=log,
    )


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
        cfg.bc,
        seed=cfg.seed,
        eval_data=eval_data,
        egocentric=cfg.egocentric,
        progress=progress,
        log_fn=log,
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
        rounds = run_dagger(
            actors(cfg, raw_env, expert),
            policy,
            cfg,
            dataset=train,
            dataset_path=out / "dagger_dataset.npz",
            eval_data=eval_data,
            progress=progress,
            log_fn=log,
        ).rounds
        metrics["dagger_s"] = time.perf_counter() - t0
        metrics["dagger_rounds"] = rounds
        if len(held):
            metrics["heldout_action_error_after_dagger"] = action_error(policy, held)
    save_tagged_model(model, out / "model.zip", cfg.egocentric)
    raw_env.close()
    return metrics

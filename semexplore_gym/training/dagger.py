"""DAgger: roll out the learner with beta-mixing, label with the expert, aggregate, refit."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from semexplore_gym.core.features.egocentric import EgocentricParams
from semexplore_gym.policies.base import Policy
from semexplore_gym.training.bc import train_bc
from semexplore_gym.training.dataset import DatasetWriter, ImitationDataset
from semexplore_gym.training.progress import with_progress
from semexplore_gym.training.workers import (
    DAGGER_STREAM,
    EpisodeJob,
    check_workers,
    run_jobs,
    worker_pool,
)


def beta_schedule(spec: float | Sequence[float] | Callable[[int], float]) -> Callable[[int], float]:
    """Turn a schedule spec into ``round -> beta``.

    A float ``p`` gives ``beta_i = p ** i`` (round 0 is pure expert, then exponential decay,
    as in Ross et al.); a sequence gives ``beta_i = seq[min(i, len-1)]``; a callable is used as is.
    """
    if callable(spec):
        return spec
    if isinstance(spec, (int, float)):
        p = float(spec)
        if not 0.0 <= p <= 1.0:
            raise ValueError(f"beta decay must be in [0, 1], got {spec!r}")
        return lambda i: p**i
    seq = [float(b) for b in spec]
    if not seq or any(not 0.0 <= b <= 1.0 for b in seq):
        raise ValueError(f"beta sequence must be non-empty with values in [0, 1], got {spec!r}")
    return lambda i: seq[min(i, len(seq) - 1)]


@dataclass
class DaggerResult:
    """Outcome of :func:`run_dagger`: the aggregated data and per-round facts."""

    dataset: ImitationDataset
    rounds: list[dict[str, float]]


def run_dagger(
    env: Any,
    expert: Policy,
    learner: Any,
    params: EgocentricParams,
    rounds: int = 3,
    beta: float | Sequence[float] | Callable[[int], float] = 0.5,
    episodes_per_round: int = 2,
    dataset: ImitationDataset | None = None,
    dataset_path: str | os.PathLike | None = None,
    bc_kwargs: dict[str, Any] | None = None,
    seed: int = 0,
    max_steps: int = 1000,
    progress: bool = False,
    log_fn: Callable[[str, float, int], None] | None = None,
    save_interval_s: float = 0.0,
    workers: int = 1,
    make_env: Callable[[], Any] | None = None,
    make_expert: Callable[[], Policy] | None = None,
) -> DaggerResult:
    """DAgger: roll out the learner with beta-mixing, label with the expert, aggregate, refit.

    Args:
        env: The raw env.
        expert: Labelling policy.
        learner: SB3 actor-critic policy, refit in place after each round.
        params: Egocentric parameters of the learner's input.
        rounds: Number of collect-and-refit rounds.
        beta: Schedule of the probability of executing the expert's action (see :func:`beta_schedule`).
        episodes_per_round: Episodes collected per round.
        dataset: Initial data (e.g. the BC dataset) to aggregate with.
        dataset_path: When given, the aggregate is rewritten there after every episode.
        bc_kwargs: Keyword arguments of :func:`train_bc` for each refit.
        seed: Base seed: DAgger episode ``k`` (counted over all rounds) resets with seed
            ``seed + 10000 + k`` and flips its beta coins with ``episode_rng(seed, k,
            DAGGER_STREAM)``; round ``r`` refits with seed ``seed + r``.
        max_steps: Step cap per episode.
        progress: tqdm bars.
        log_fn: ``log_fn(tag, value, step)`` for per-round scalars.
        save_interval_s: Minimum time between rewrites of ``dataset_path`` (it is always
            written at the end of every round).
        workers: Processes the episodes of a round run in (see :func:`record_expert_dataset`;
            the learner's weights are shipped to them every round). The learner drives with one
            torch thread in any case, so the data does not depend on ``workers``.
        make_env: Factory of the workers' envs (default: copies of ``env``).
        make_expert: Factory of the workers' experts (default: copies of ``expert``).
    """
    if rounds < 1 or episodes_per_round < 1:
        raise ValueError(
            f"rounds and episodes_per_round must be >= 1, got {rounds}, {episodes_per_round}"
        )
    workers = check_workers(workers)
    sched = beta_schedule(beta)
    data = (
        dataset if dataset is not None else ImitationDataset.empty({"egocentric": params.to_dict()})
    )
    writer = (
        DatasetWriter(dataset_path, data.meta, min_interval_s=save_interval_s)
        if dataset_path is not None
        else None
    )
    if writer is not None and len(data):
        writer.replace(data)
        writer.flush()
    bc_kwargs = dict(bc_kwargs or {})
    epochs = int(bc_kwargs.get("epochs", 10))
    history: list[dict[str, float]] = []
    with worker_pool(workers, episodes_per_round) as pool:
        for r in with_progress(range(rounds), progress, "DAgger rounds"):
            b = float(sched(r))
            t0 = time.perf_counter()
            first_id = int(data.episode_ids.max()) + 1 if len(data) else 0
            jobs = _round_jobs(r, episodes_per_round, seed, first_id, b, max_steps)
            parts, covs, fracs = [], [], []
            for rec in run_jobs(jobs, env, expert, params, learner, pool, make_env, make_expert):
                parts.append(rec.data)
                if writer is not None:
                    writer.add(rec.data)
                covs.append(rec.coverage)
                fracs.append(rec.expert_fraction)
            # The writer already holds the aggregate: share it rather than copy it again.
            data = (
                writer.data
                if writer is not None
                else ImitationDataset.concatenate_all([data, *parts])
            )
            if writer is not None:
                writer.flush()
            fit = train_bc(
                data, learner, seed=seed + r, log_fn=log_fn, step_offset=r * epochs, **bc_kwargs
            )
            facts = {
                "round": r,
                "beta": b,
                "coverage": float(np.mean(covs)),
                "expert_fraction": float(np.mean(fracs)),
                "new_samples": sum(len(p) for p in parts),
                "dataset_size": len(data),
                "bc_loss": fit["loss"][-1],
                "seconds": time.perf_counter() - t0,
            }
            history.append(facts)
            if log_fn is not None:
                for k in ("beta", "coverage", "expert_fraction", "dataset_size", "bc_loss"):
                    log_fn(f"dagger/{k}", float(facts[k]), r)
    return DaggerResult(data, history)


def _round_jobs(
    round_index: int, episodes_per_round: int, seed: int, first_id: int, beta: float, max_steps: int
) -> list[EpisodeJob]:
    """The episodes of DAgger round ``round_index`` (see :func:`run_dagger` for the seeds)."""
    first_seed = seed + 10_000  # away from the seeds an expert dataset usually uses
    jobs = []
    for j in range(episodes_per_round):
        k = round_index * episodes_per_round + j
        jobs.append(
            EpisodeJob(
                seed=first_seed + k,
                rng_key=(seed, k, DAGGER_STREAM),
                max_steps=max_steps,
                episode_id=first_id + j,
                beta=beta,
            )
        )
    return jobs

"""DAgger: roll out the learner with beta-mixing, label with the expert, aggregate, refit."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from semexplore_gym.training.bc import train_bc
from semexplore_gym.training.dataset import DatasetWriter, ImitationDataset
from semexplore_gym.training.episodes import EpisodeRecord
from semexplore_gym.training.progress import with_progress
from semexplore_gym.training.train_config import TrainConfig
from semexplore_gym.training.workers import (
    DAGGER_STREAM,
    EpisodeActors,
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
    actors: EpisodeActors,
    learner: Any,
    cfg: TrainConfig,
    *,
    dataset: ImitationDataset | None = None,
    dataset_path: str | os.PathLike | None = None,
    eval_data: ImitationDataset | None = None,
    progress: bool = False,
    log_fn: Callable[[str, float, int], None] | None = None,
) -> DaggerResult:
    """DAgger: roll out the learner with beta-mixing, label with the expert, aggregate, refit.

    Args:
        actors: The raw env and the labelling expert (and the workers' factories).
        learner: SB3 actor-critic policy, refit in place after each round (its weights go to
            the workers each round; it drives with one torch thread, whatever the workers).
        cfg: ``dagger`` (rounds, episodes, :func:`beta_schedule`, workers), ``bc`` (each
            refit, with ``dagger.epochs_per_round`` and ``dagger.select_best``),
            ``expert.max_steps``, ``expert.save_interval_s`` (between rewrites of
            ``dataset_path``), ``egocentric`` and ``seed``: episode ``k`` (over all rounds)
            resets with ``seed + 10000 + k`` and flips its beta coins with
            ``episode_rng(seed, k, DAGGER_STREAM)``; round ``r`` refits with ``seed + r``.
        dataset: Initial data (e.g. the BC dataset) to aggregate with.
        dataset_path: When given, the aggregate is rewritten there after every episode.
        eval_data: Held-out samples each refit measures (see :func:`train_bc`).
        progress: tqdm bars.
        log_fn: ``log_fn(tag, value, step)`` for per-round scalars (and each refit's epochs,
            counted on over the rounds).
    """
    d, params = cfg.dagger, cfg.egocentric
    if d.rounds < 1 or d.episodes_per_round < 1:
        raise ValueError(
            f"rounds and episodes_per_round must be >= 1, got {d.rounds}, {d.episodes_per_round}"
        )
    check_workers(d.workers)
    sched = beta_schedule(list(d.beta) if isinstance(d.beta, tuple) else d.beta)
    data = (
        dataset if dataset is not None else ImitationDataset.empty({"egocentric": params.to_dict()})
    )
    writer = _aggregate_writer(dataset_path, data, cfg.expert.save_interval_s)
    refit = replace(cfg.bc, epochs=d.epochs_per_round, select_best=d.select_best)
    history: list[dict[str, float]] = []
    with worker_pool(d.workers, d.episodes_per_round) as pool:
        for r in with_progress(range(d.rounds), progress, "DAgger rounds"):
            b = float(sched(r))
            t0 = time.perf_counter()
            first_id = int(data.episode_ids.max()) + 1 if len(data) else 0
            jobs = _round_jobs(r, d.episodes_per_round, cfg.seed, first_id, b, cfg.expert.max_steps)
            parts, covs, fracs = _collect(run_jobs(jobs, actors, params, learner, pool), writer)
            # The writer already holds the aggregate: share it rather than copy it again.
            data = (
                writer.data
                if writer is not None
                else ImitationDataset.concatenate_all([data, *parts])
            )
            if writer is not None:
                writer.flush()
            fit = train_bc(
                data,
                learner,
                refit,
                seed=cfg.seed + r,
                eval_data=eval_data,
                egocentric=params,
                log_fn=_shifted(log_fn, r * refit.epochs),
            )
            facts = {
                **{"round": r, "beta": b, "coverage": float(np.mean(covs))},
                **{"expert_fraction": float(np.mean(fracs)), "dataset_size": len(data)},
                **{"new_samples": sum(len(p) for p in parts), "bc_loss": fit["loss"][-1]},
                "seconds": time.perf_counter() - t0,
            }
            history.append(facts)
            if log_fn is not None:
                for k in ("beta", "coverage", "expert_fraction", "dataset_size", "bc_loss"):
                    log_fn(f"dagger/{k}", float(facts[k]), r)
    return DaggerResult(data, history)


def _aggregate_writer(
    path: str | os.PathLike | None, data: ImitationDataset, min_interval_s: float
) -> DatasetWriter | None:
    """The writer of the aggregate at ``path`` (None: no file), holding ``data`` already."""
    if path is None:
        return None
    writer = DatasetWriter(path, data.meta, min_interval_s=min_interval_s)
    if len(data):
        writer.replace(data)
        writer.flush()
    return writer


def _collect(
    records: Iterable[EpisodeRecord], writer: DatasetWriter | None
) -> tuple[list[ImitationDataset], list[float], list[float]]:
    """A round's episodes (written as they come): data, coverages, expert fractions."""
    parts, covs, fracs = [], [], []
    for rec in records:
        parts.append(rec.data)
        if writer is not None:
            writer.add(rec.data)
        covs.append(rec.coverage)
        fracs.append(rec.expert_fraction)
    return parts, covs, fracs


def _shifted(
    log_fn: Callable[[str, float, int], None] | None, offset: int
) -> Callable[[str, float, int], None] | None:
    """``log_fn`` with ``offset`` added to every step (a refit's epochs, counted on)."""
    if log_fn is None:
        return None
    return lambda tag, value, step: log_fn(tag, value, step + offset)


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

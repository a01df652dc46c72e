"""Recording expert datasets: many labelled expert episodes into one ``.npz``.

Recording can inject DART noise into the executed expert actions (labels stay clean); the
episodes can run in worker processes (:mod:`semexplore_gym.training.workers`) with the same
data as in one.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

from semexplore_gym.core.features.egocentric import EgocentricParams
from semexplore_gym.training.dataset import DatasetWriter, ImitationDataset
from semexplore_gym.training.progress import with_progress
from semexplore_gym.training.train_config import ExpertSection
from semexplore_gym.training.workers import (
    EXPERT_STREAM,
    EpisodeActors,
    EpisodeJob,
    check_workers,
    run_jobs,
    worker_pool,
)


def record_expert_dataset(
    actors: EpisodeActors,
    path: str | os.PathLike | None,
    params: EgocentricParams,
    recording: ExpertSection,
    *,
    seed: int = 0,
    meta: dict[str, Any] | None = None,
    progress: bool = False,
    log_fn: Callable[[str, float, int], None] | None = None,
) -> ImitationDataset:
    """Roll out the expert for ``recording.episodes`` episodes (seeds ``seed``, ``seed+1``,
    ...) of at most ``recording.max_steps`` steps and record them.

    When ``path`` is given the ``.npz`` is rewritten after an episode when
    ``recording.save_interval_s`` passed since the last write (0: after every episode), and at
    the end. ``log_fn(tag, value, step)`` receives per-episode coverage and length. The first
    ``round(noise_fraction * episodes)`` episodes execute the expert's actions with DART noise
    ``noise_std`` (see :func:`rollout_episode`); episode ``k`` draws it from
    ``episode_rng(seed, k)``. The rest are clean.

    With ``recording.workers > 1`` the episodes run in that many spawned processes, each
    episode on a fresh env and expert (see :class:`EpisodeActors`). The data is the same as
    with one process (env and expert must reset completely on a seeded reset); episodes reach
    the file, the progress bar and ``log_fn`` in episode order. Each worker needs a few
    seconds to start (imports, numba caches), and a script that uses workers must run under
    ``if __name__ == "__main__":``, as the spawned workers import the main module.
    """
    n_episodes, max_steps = recording.episodes, recording.max_steps
    noise_std, noise_fraction = recording.noise_std, recording.noise_fraction
    expert = actors.expert
    if n_episodes < 1:
        raise ValueError(f"n_episodes must be >= 1, got {n_episodes!r}")
    if not 0.0 <= noise_fraction <= 1.0:
        raise ValueError(f"noise_fraction must be in [0, 1], got {noise_fraction!r}")
    workers = check_workers(recording.workers)
    full_meta = {
        "egocentric": params.to_dict(),
        "expert": getattr(expert, "name", type(expert).__name__),
        **(meta or {}),
    }
    if noise_std > 0:
        full_meta["dart_noise_std"] = float(noise_std)
        full_meta["dart_noise_fraction"] = float(noise_fraction)
    writer = (
        DatasetWriter(path, full_meta, min_interval_s=recording.save_interval_s)
        if path is not None
        else None
    )
    n_noisy = round(noise_fraction * n_episodes) if noise_std > 0 else 0
    jobs = [
        EpisodeJob(
            seed=seed + ep,
            rng_key=(seed, ep, EXPERT_STREAM),
            max_steps=max_steps,
            episode_id=ep,
            noise_std=noise_std if ep < n_noisy else 0.0,
        )
        for ep in range(n_episodes)
    ]
    parts: list[ImitationDataset] = []
    with worker_pool(workers, n_episodes) as pool:
        records = run_jobs(jobs, actors, params, None, pool)
        for ep, rec in enumerate(with_progress(records, progress, "expert episodes", n_episodes)):
            parts.append(rec.data)
            if writer is not None:
                writer.add(rec.data)
            if log_fn is not None:
                log_fn("expert/coverage", rec.coverage, ep)
                log_fn("expert/steps", rec.steps, ep)
    if writer is not None:
        writer.flush()
    # One concatenation at the end: growing the arrays per episode is quadratic.
    data = ImitationDataset.concatenate_all(parts)
    data.meta = full_meta
    return data

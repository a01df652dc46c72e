"""Per-episode random streams and the process pool that runs roll-out episodes.

Every episode draws its randomness (DART noise, beta coin flips) from its own generator,
:func:`episode_rng` of (seed, episode index), and resets env and expert with its own seed, so
its data does not depend on the episodes run before it. That lets recording and DAgger spread
episodes over ``workers`` processes with the same result as one process; :func:`run_jobs`
still yields the episodes in job order.
"""

from __future__ import annotations

import contextlib
import io
import os
import pickle
import sys
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from semexplore_gym.core.features.egocentric import EgocentricParams
from semexplore_gym.policies.base import Policy
from semexplore_gym.training.episodes import EpisodeRecord, EpisodeSpec, rollout_episode

#: Spawn-key streams of :func:`episode_rng`: expert recording and DAgger never share numbers.
EXPERT_STREAM = 0
DAGGER_STREAM = 1


def episode_rng(seed: int, episode: int, stream: int = EXPERT_STREAM) -> np.random.Generator:
    """The generator of one episode's randomness (DART noise, beta coin flips).

    It depends on ``(seed, stream, episode)`` only (a :class:`numpy.random.SeedSequence` with
    spawn key ``(stream, episode)``), so an episode draws the same numbers whichever episodes
    ran before it, in this process or in a worker. ``stream`` is :data:`EXPERT_STREAM` for
    :func:`record_expert_dataset` and :data:`DAGGER_STREAM` for :func:`run_dagger`, whose
    ``episode`` counts the DAgger episodes over all rounds.
    """
    for name, v in (("seed", seed), ("episode", episode), ("stream", stream)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0:
            raise ValueError(f"{name} must be an integer >= 0, got {v!r}")
    return np.random.default_rng(
        np.random.SeedSequence(int(seed), spawn_key=(int(stream), int(episode)))
    )


def check_workers(workers: Any, name: str = "workers") -> int:
    """``workers`` as an int, or a ValueError naming ``name`` unless it is an integer >= 1."""
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise ValueError(f"{name} must be an integer >= 1, got {workers!r}")
    return int(workers)


@dataclass(frozen=True)
class _Source:
    """A picklable recipe for an object a worker needs: a pickle of it, or of its factory."""

    blob: bytes
    is_factory: bool

    @classmethod
    def of(cls, obj: Any, factory: Callable[[], Any] | None, what: str) -> _Source:
        target = factory if factory is not None else obj
        try:
            return cls(pickle.dumps(target), factory is not None)
        except Exception as e:
            arg = f"make_{what}" if factory is not None else what
            raise ValueError(
                f"workers > 1 runs episodes in other processes, which need a picklable {arg} "
                f"(a module-level function or functools.partial for make_{what}); "
                f"pickling {type(target).__name__} failed: {e}"
            ) from e

    def build(self) -> Any:
        obj = pickle.loads(self.blob)
        return obj() if self.is_factory else obj


@dataclass(frozen=True)
class EpisodeJob:
    """The arguments of one :func:`rollout_episode` call, minus env, expert and learner."""

    seed: int
    rng_key: tuple[int, int, int]  # episode_rng(seed, episode, stream)
    max_steps: int
    episode_id: int
    noise_std: float = 0.0
    beta: float = 1.0

    def run(
        self, env: Any, expert: Policy, params: EgocentricParams, learner: Any
    ) -> EpisodeRecord:
        spec = EpisodeSpec(self.seed, self.max_steps, self.episode_id, self.noise_std, self.beta)
        return rollout_episode(env, expert, params, spec, learner, episode_rng(*self.rng_key))


def _zero_schedule(_progress: float) -> float:
    """Learning-rate schedule of the workers' learner copies (they never train)."""
    return 0.0


def _policy_blob(policy: Any) -> bytes:
    """The learner's class, constructor arguments and weights, for the worker processes."""
    import torch as th

    data = dict(policy._get_constructor_parameters())
    # SB3 stores a bound method of the policy here, which would pickle the whole policy.
    data["lr_schedule"] = _zero_schedule
    buf = io.BytesIO()
    th.save({"cls": type(policy), "data": data, "state_dict": policy.state_dict()}, buf)
    return buf.getvalue()


def _policy_from_blob(blob: bytes) -> Any:
    import torch as th

    saved = th.load(io.BytesIO(blob), map_location="cpu", weights_only=False)
    policy = saved["cls"](**saved["data"])
    policy.load_state_dict(saved["state_dict"])
    policy.set_training_mode(False)
    return policy


def _init_worker() -> None:
    """Worker processes: one thread each, the cores are shared by the workers."""
    os.environ["OMP_NUM_THREADS"] = "1"
    os.environ["MKL_NUM_THREADS"] = "1"
    th = sys.modules.get("torch")
    if th is not None:
        th.set_num_threads(1)


def _run_job_in_worker(
    job: EpisodeJob,
    env_source: _Source,
    expert_source: _Source,
    params: EgocentricParams,
    learner_blob: bytes | None,
) -> EpisodeRecord:
    """One episode on fresh copies of env, expert and learner (runs in a worker process)."""
    learner = None
    if learner_blob is not None:
        import torch as th

        th.set_num_threads(1)
        learner = _policy_from_blob(learner_blob)
    env = env_source.build()
    try:
        return job.run(env, expert_source.build(), params, learner)
    finally:
        env.close()


@contextlib.contextmanager
def worker_pool(workers: int, n_jobs: int) -> Iterator[Any]:
    """A process pool of ``min(workers, n_jobs)`` workers, or None for one process.

    Workers are spawned (never forked): a fork of a process whose torch already ran OpenMP
    threads can hang in the child.
    """
    n = min(workers, n_jobs)
    if n <= 1:
        yield None
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    pool = ProcessPoolExecutor(
        max_workers=n, mp_context=multiprocessing.get_context("spawn"), initializer=_init_worker
    )
    try:
        yield pool
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


@contextlib.contextmanager
def _one_torch_thread() -> Iterator[None]:
    """One torch thread while rolling out in this process (as in the workers).

    A batch-of-one forward pass gains nothing from threads, and the same thread count as the
    workers keeps the learner's actions, hence the data, the same for any ``workers``.
    """
    th = sys.modules.get("torch")
    if th is None:
        yield
        return
    n = th.get_num_threads()
    th.set_num_threads(1)
    try:
        yield
    finally:
        th.set_num_threads(n)


@dataclass(frozen=True)
class EpisodeActors:
    """The env and expert that episodes run with in this process, and how worker processes
    get their own: ``make_env()`` / ``make_expert()`` when given (picklable: module-level
    functions or ``functools.partial``), else unpickled copies of ``env`` / ``expert``."""

    env: Any
    expert: Policy
    make_env: Callable[[], Any] | None = None
    make_expert: Callable[[], Policy] | None = None


def run_jobs(
    jobs: Sequence[EpisodeJob],
    actors: EpisodeActors,
    params: EgocentricParams,
    learner: Any,
    pool: Any,
) -> Iterator[EpisodeRecord]:
    """The jobs' episode records in job order: in this process, or from ``pool`` as they finish."""
    if pool is None:
        with _one_torch_thread():
            for job in jobs:
                yield job.run(actors.env, actors.expert, params, learner)
        return
    env_source = _Source.of(actors.env, actors.make_env, "env")
    expert_source = _Source.of(actors.expert, actors.make_expert, "expert")
    learner_blob = (
        _policy_blob(learner) if learner is not None and any(j.beta < 1.0 for j in jobs) else None
    )
    futures = [
        pool.submit(_run_job_in_worker, job, env_source, expert_source, params, learner_blob)
        for job in jobs
    ]
    from concurrent.futures.process import BrokenProcessPool

    try:
        for f in futures:
            yield f.result()
    except BrokenProcessPool as e:
        raise RuntimeError(
            "a roll-out worker process died; a script that uses workers > 1 must start its "
            "work under `if __name__ == '__main__':` (the spawned workers import the main module)"
        ) from e
    finally:
        for f in futures:
            f.cancel()

"""Imitation learning without the ``imitation`` package: expert datasets, BC and DAgger.

The learner is an SB3 actor-critic policy (``MultiInputActorCriticPolicy`` for the Dict
observation of :class:`semexplore_gym.wrappers.egocentric.EgocentricObservation`), so a
behaviour-cloned model can be fine-tuned with PPO. The expert is any :class:`policies.base.Policy`
(normally the scripted semantic expert); it sees the raw observation, the learner the
egocentric features computed from that same observation (:class:`EgocentricEncoder`).

Recording can inject DART noise into the executed expert actions (labels stay clean), and
:func:`train_bc` can mirror samples left-right, keep the best epoch by held-out action error
and decay the learning rate; ``scripts/bench_imitation.py`` compares a trained model with the
expert at the expert's own mission time on held-out worlds.

Datasets are ``.npz`` files holding the egocentric observations (``obs__<key>``), the expert's
actions, an episode id per sample and a JSON ``meta`` record; :class:`DatasetWriter` rewrites
the file atomically after every episode, so an interrupted recording keeps its finished
episodes.

Every episode draws its randomness (DART noise, beta coin flips) from its own generator,
:func:`episode_rng` of (seed, episode index), and resets env and expert with its own seed, so
its data does not depend on the episodes run before it. That lets :func:`record_expert_dataset`
and :func:`run_dagger` spread episodes over ``workers`` processes with the same result as one
process; the episodes still reach the dataset file in episode order.

torch and stable-baselines3 (the ``rl`` extra) are imported inside the functions that need them.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import pickle
import sys
import time
import zipfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from policies.base import Policy
from semexplore_gym.core.features.egocentric import (
    EgocentricEncoder,
    EgocentricParams,
    mirror_observations,
)

#: Name of the JSON record stored inside model zips: policy class and feature parameters.
MODEL_META_NAME = "semexplore.json"


# --------------------------------------------------------------------------- dataset
@dataclass
class ImitationDataset:
    """Egocentric observations with the expert's action for each.

    Attributes:
        obs: Observation arrays by key, each with the sample axis first.
        actions: ``(N, 2)`` float32 expert actions.
        episode_ids: ``(N,)`` int64 episode index of each sample.
        meta: JSON-safe facts (egocentric parameters, expert, world ...).
    """

    obs: dict[str, np.ndarray]
    actions: np.ndarray
    episode_ids: np.ndarray
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        n = len(self.actions)
        if self.actions.ndim != 2:
            raise ValueError(f"actions must be (N, action_dim), got shape {self.actions.shape}")
        if self.episode_ids.shape != (n,):
            raise ValueError(f"episode_ids must have shape ({n},), got {self.episode_ids.shape}")
        for k, v in self.obs.items():
            if len(v) != n:
                raise ValueError(f"obs[{k!r}] has {len(v)} samples but there are {n} actions")

    def __len__(self) -> int:
        return len(self.actions)

    @property
    def n_episodes(self) -> int:
        return len(np.unique(self.episode_ids))

    @classmethod
    def empty(cls, meta: dict[str, Any] | None = None) -> ImitationDataset:
        return cls({}, np.zeros((0, 2), np.float32), np.zeros(0, np.int64), dict(meta or {}))

    def concatenate(self, other: ImitationDataset) -> ImitationDataset:
        """Both datasets' samples; ``other``'s episode ids are shifted past this one's."""
        if len(self) == 0:
            return ImitationDataset(
                dict(other.obs), other.actions, other.episode_ids, {**other.meta, **self.meta}
            )
        if len(other) == 0:
            return self
        if set(self.obs) != set(other.obs):
            raise ValueError(f"observation keys differ: {sorted(self.obs)} vs {sorted(other.obs)}")
        shift = int(self.episode_ids.max()) + 1 - int(other.episode_ids.min())
        return ImitationDataset(
            {k: np.concatenate([self.obs[k], other.obs[k]]) for k in self.obs},
            np.concatenate([self.actions, other.actions]),
            np.concatenate([self.episode_ids, other.episode_ids + shift]),
            dict(self.meta),
        )

    @staticmethod
    def concatenate_all(parts: Sequence[ImitationDataset]) -> ImitationDataset:
        """Like chained :meth:`concatenate` calls (ids shifted part by part), in one copy."""
        meta: dict[str, Any] = {}
        for p in reversed(parts):  # earlier parts' facts win, as in concatenate
            meta.update(p.meta)
        parts = [p for p in parts if len(p)]
        if not parts:
            return ImitationDataset.empty(meta)
        if len(parts) == 1:
            return ImitationDataset(parts[0].obs, parts[0].actions, parts[0].episode_ids, meta)
        keys = set(parts[0].obs)
        for p in parts[1:]:
            if set(p.obs) != keys:
                raise ValueError(f"observation keys differ: {sorted(keys)} vs {sorted(p.obs)}")
        ids, next_id = [], int(parts[0].episode_ids.min())
        for p in parts:
            ids.append(p.episode_ids - int(p.episode_ids.min()) + next_id)
            next_id = int(ids[-1].max()) + 1
        return ImitationDataset(
            {k: np.concatenate([p.obs[k] for p in parts]) for k in parts[0].obs},
            np.concatenate([p.actions for p in parts]),
            np.concatenate(ids),
            meta,
        )

    def subset(self, mask: np.ndarray) -> ImitationDataset:
        return ImitationDataset(
            {k: v[mask] for k, v in self.obs.items()},
            self.actions[mask],
            self.episode_ids[mask],
            dict(self.meta),
        )

    def split_by_episode(
        self, holdout_fraction: float, rng: np.random.Generator
    ) -> tuple[ImitationDataset, ImitationDataset]:
        """(train, held-out) with whole episodes held out, at least one each when possible."""
        if not 0.0 <= holdout_fraction < 1.0:
            raise ValueError(f"holdout_fraction must be in [0, 1), got {holdout_fraction!r}")
        eps = np.unique(self.episode_ids)
        n_hold = round(holdout_fraction * len(eps))
        if holdout_fraction > 0 and len(eps) >= 2:
            n_hold = min(max(n_hold, 1), len(eps) - 1)
        held = rng.permutation(eps)[:n_hold]
        mask = np.isin(self.episode_ids, held)
        return self.subset(~mask), self.subset(mask)

    def save(self, path: str | os.PathLike, compress: bool = True) -> Path:
        """Write atomically (temporary file, then rename) to ``path`` (``.npz``).

        ``compress`` deflates at level 1: the maps shrink 8-fold (level 6: 9-fold), and level
        1 writes about 3 times faster than numpy's ``savez_compressed`` (level 6), which
        matters when a large dataset is rewritten during a recording.
        """
        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        arrays: dict[str, Any] = {f"obs__{k}": v for k, v in self.obs.items()}
        arrays.update(
            actions=self.actions,
            episode_ids=self.episode_ids,
            meta=np.array(json.dumps(self.meta, sort_keys=True)),
        )
        tmp = p.with_name(p.name + ".tmp")
        method, level = (zipfile.ZIP_DEFLATED, 1) if compress else (zipfile.ZIP_STORED, None)
        with zipfile.ZipFile(tmp, "w", method, compresslevel=level) as z:
            for name, value in arrays.items():
                with z.open(f"{name}.npy", "w", force_zip64=True) as f:
                    np.lib.format.write_array(f, np.asanyarray(value), allow_pickle=False)
        os.replace(tmp, p)
        return p

    @classmethod
    def load(cls, path: str | os.PathLike) -> ImitationDataset:
        """Read a dataset written by :meth:`save` (no pickles are loaded)."""
        p = Path(path)
        if not p.is_file():
            raise FileNotFoundError(f"dataset not found: {str(p)!r}")
        with np.load(p, allow_pickle=False) as z:
            missing = {"actions", "episode_ids", "meta"} - set(z.files)
            if missing:
                raise ValueError(
                    f"{str(p)!r} is not an imitation dataset (missing {sorted(missing)})"
                )
            obs = {k[len("obs__") :]: z[k] for k in z.files if k.startswith("obs__")}
            return cls(
                obs,
                z["actions"].astype(np.float32),
                z["episode_ids"].astype(np.int64),
                json.loads(str(z["meta"])),
            )


class DatasetWriter:
    """Accumulates episodes and rewrites the ``.npz`` file after each one.

    Args:
        path: Output ``.npz`` path; an existing file is extended when ``append`` is True.
        meta: JSON-safe facts stored with the data.
        append: Start from the samples already in ``path``.
        min_interval_s: Skip the rewrite when the last one was less than this long ago (call
            :meth:`flush` at the end); 0 rewrites after every episode. Rewriting a large
            compressed file after every short episode would cost more than recording it.
    """

    def __init__(
        self,
        path: str | os.PathLike,
        meta: dict[str, Any] | None = None,
        append: bool = False,
        min_interval_s: float = 0.0,
    ) -> None:
        self.path = Path(path)
        self.min_interval_s = float(min_interval_s)
        self._last_save = -math.inf
        self._dirty = False
        self._data = (
            ImitationDataset.load(self.path)
            if append and self.path.is_file()
            else ImitationDataset.empty(meta)
        )
        if meta:
            self._data.meta.update(meta)
        # Episodes not yet merged into _data: merging all at once is linear, per episode quadratic.
        self._pending: list[ImitationDataset] = []

    @property
    def data(self) -> ImitationDataset:
        """All samples so far (the file's content after the next :meth:`flush`)."""
        if self._pending:
            self._data = ImitationDataset.concatenate_all([self._data, *self._pending])
            self._pending = []
        return self._data

    def add(self, episode: ImitationDataset) -> None:
        """Append an episode; write the file unless the last write was too recent."""
        self._pending.append(episode)
        self._mark_dirty()

    def replace(self, data: ImitationDataset) -> None:
        """Make ``data`` the file's content; write it unless the last write was too recent."""
        self._data, self._pending = data, []
        self._mark_dirty()

    def _mark_dirty(self) -> None:
        self._dirty = True
        if time.perf_counter() - self._last_save >= self.min_interval_s:
            self.flush()

    def flush(self) -> None:
        """Write the file now if episodes were added since the last write."""
        if self._dirty:
            self.data.save(self.path)
            self._last_save = time.perf_counter()
            self._dirty = False


# ---------------------------------------------------------------------- roll-outs
@dataclass
class EpisodeRecord:
    """One roll-out: the egocentric observations, the expert's labels and outcome facts.

    ``steps`` counts the labelled states; ``expert_fraction`` the share of steps that executed
    the expert's action.
    """

    data: ImitationDataset
    steps: int
    return_: float
    coverage: float
    expert_fraction: float
    end_reason: str


def _stack_obs(obs_list: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    return {k: np.stack([o[k] for o in obs_list]) for k in obs_list[0]}


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


def rollout_episode(
    env: Any,
    expert: Policy,
    params: EgocentricParams,
    learner: Any = None,
    beta: float = 1.0,
    rng: np.random.Generator | None = None,
    seed: int | None = None,
    max_steps: int = 1000,
    episode_id: int = 0,
    noise_std: float = 0.0,
) -> EpisodeRecord:
    """Run one episode, labelling every visited state with the expert's action.

    Each step executes the expert's action with probability ``beta`` and the learner's
    otherwise (``learner`` may be None only when ``beta == 1``). The expert is asked every step,
    also when the learner drives, so its internal plan follows the visited states.

    With ``noise_std > 0`` the executed expert action gets zero-mean Gaussian noise of that
    standard deviation per component (drawn from ``rng``, then clipped to [-1, 1]) while the
    label stays the clean action (DART, Laskey et al. 2017): the data then shows how the expert
    recovers from the small drifts a learner makes.

    Args:
        env: The raw ``SemanticExplore-v0`` env (not wrapped).
        expert: The labelling policy.
        params: Egocentric feature parameters (what the learner sees).
        learner: An SB3 policy (``predict``) or None.
        beta: Probability of executing the expert's action.
        rng: Generator for the beta coin flips.
        seed: Seed for ``env.reset`` and ``expert.reset``.
        max_steps: Step cap of the episode.
        episode_id: Episode id stored with the samples.
        noise_std: DART noise on the executed expert actions (0: none).
    """
    if not (0.0 <= noise_std and math.isfinite(noise_std)):
        raise ValueError(f"noise_std must be a finite number >= 0, got {noise_std!r}")
    if not 0.0 <= beta <= 1.0:
        raise ValueError(f"beta must be in [0, 1], got {beta!r}")
    if learner is None and beta < 1.0:
        raise ValueError("a learner is needed when beta < 1")
    if max_steps < 1:
        raise ValueError(f"max_steps must be >= 1, got {max_steps!r}")
    rng = rng if rng is not None else np.random.default_rng(seed)
    if learner is not None and hasattr(learner, "set_training_mode"):
        learner.set_training_mode(False)
    obs, info = env.reset(seed=seed)
    expert.reset(obs, info, seed=seed)
    encoder = EgocentricEncoder.from_info(params, info)
    feats: list[dict[str, np.ndarray]] = []
    labels: list[np.ndarray] = []
    ret, n_expert, end_reason = 0.0, 0, "max_steps"
    for _ in range(max_steps):
        if not encoder.matches(info):
            encoder = EgocentricEncoder.from_info(params, info)
        f = encoder.encode(obs)
        a_expert = np.clip(
            np.asarray(expert.act(obs, info), dtype=np.float32).reshape(-1), -1.0, 1.0
        )
        feats.append(f)
        labels.append(a_expert)
        if expert.done:
            end_reason = f"expert_done:{expert.stop_reason}"
            break
        use_expert = beta >= 1.0 or rng.random() < beta
        n_expert += int(use_expert)
        if not use_expert:
            action = learner_action(learner, f)
        elif noise_std > 0.0:
            noise = rng.normal(0.0, noise_std, a_expert.shape).astype(np.float32)
            action = np.clip(a_expert + noise, -1.0, 1.0)
        else:
            action = a_expert
        obs, reward, terminated, truncated, info = env.step(action)
        ret += float(reward)
        if terminated or truncated:
            end_reason = "terminated" if terminated else "truncated"
            break
    n = len(labels)
    data = ImitationDataset(
        _stack_obs(feats), np.stack(labels).astype(np.float32), np.full(n, episode_id, np.int64)
    )
    return EpisodeRecord(
        data, n, ret, float(info.get("coverage", math.nan)), n_expert / max(1, n), end_reason
    )


def _progress(iterable: Any, enabled: bool, desc: str, total: int | None = None) -> Any:
    if not enabled:
        return iterable
    from tqdm.auto import tqdm

    return tqdm(iterable, desc=desc, total=total, leave=False)


# -------------------------------------------------------------- parallel roll-outs
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
class _EpisodeJob:
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
        return rollout_episode(
            env,
            expert,
            params,
            learner,
            self.beta,
            episode_rng(*self.rng_key),
            seed=self.seed,
            max_steps=self.max_steps,
            episode_id=self.episode_id,
            noise_std=self.noise_std,
        )


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
    job: _EpisodeJob,
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
def _worker_pool(workers: int, n_jobs: int) -> Iterator[Any]:
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


def _run_jobs(
    jobs: Sequence[_EpisodeJob],
    env: Any,
    expert: Policy,
    params: EgocentricParams,
    learner: Any,
    pool: Any,
    make_env: Callable[[], Any] | None,
    make_expert: Callable[[], Policy] | None,
) -> Iterator[EpisodeRecord]:
    """The jobs' episode records in job order: in this process, or from ``pool`` as they finish."""
    if pool is None:
        with _one_torch_thread():
            for job in jobs:
                yield job.run(env, expert, params, learner)
        return
    env_source = _Source.of(env, make_env, "env")
    expert_source = _Source.of(expert, make_expert, "expert")
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


def record_expert_dataset(
    env: Any,
    expert: Policy,
    path: str | os.PathLike | None,
    n_episodes: int,
    params: EgocentricParams,
    seed: int = 0,
    max_steps: int = 1000,
    meta: dict[str, Any] | None = None,
    progress: bool = False,
    log_fn: Callable[[str, float, int], None] | None = None,
    noise_std: float = 0.0,
    noise_fraction: float = 1.0,
    save_interval_s: float = 0.0,
    workers: int = 1,
    make_env: Callable[[], Any] | None = None,
    make_expert: Callable[[], Policy] | None = None,
) -> ImitationDataset:
    """Roll out the expert for ``n_episodes`` (seeds ``seed``, ``seed+1``, ...) and record them.

    When ``path`` is given the ``.npz`` is rewritten after an episode when ``save_interval_s``
    passed since the last write (0: after every episode), and at the end. ``log_fn(tag, value,
    step)`` receives per-episode coverage and length. The first ``round(noise_fraction *
    n_episodes)`` episodes execute the expert's actions with DART noise ``noise_std`` (see
    :func:`rollout_episode`); episode ``k`` draws it from ``episode_rng(seed, k)``. The rest
    are clean.

    With ``workers > 1`` the episodes run in that many spawned processes, each episode on a
    fresh env and expert: ``make_env()`` / ``make_expert()`` when given (picklable: module-level
    functions or ``functools.partial``), else unpickled copies of ``env`` / ``expert``. The data
    is the same as with one process (env and expert must reset completely on a seeded reset);
    episodes reach the file, the progress bar and ``log_fn`` in episode order. Each worker needs
    a few seconds to start (imports, numba caches), and a script that uses workers must run
    under ``if __name__ == "__main__":``, as the spawned workers import the main module.
    """
    if n_episodes < 1:
        raise ValueError(f"n_episodes must be >= 1, got {n_episodes!r}")
    if not 0.0 <= noise_fraction <= 1.0:
        raise ValueError(f"noise_fraction must be in [0, 1], got {noise_fraction!r}")
    workers = check_workers(workers)
    full_meta = {
        "egocentric": params.to_dict(),
        "expert": getattr(expert, "name", type(expert).__name__),
        **(meta or {}),
    }
    if noise_std > 0:
        full_meta["dart_noise_std"] = float(noise_std)
        full_meta["dart_noise_fraction"] = float(noise_fraction)
    writer = (
        DatasetWriter(path, full_meta, min_interval_s=save_interval_s) if path is not None else None
    )
    n_noisy = round(noise_fraction * n_episodes) if noise_std > 0 else 0
    jobs = [
        _EpisodeJob(
            seed=seed + ep,
            rng_key=(seed, ep, EXPERT_STREAM),
            max_steps=max_steps,
            episode_id=ep,
            noise_std=noise_std if ep < n_noisy else 0.0,
        )
        for ep in range(n_episodes)
    ]
    parts: list[ImitationDataset] = []
    with _worker_pool(workers, n_episodes) as pool:
        records = _run_jobs(jobs, env, expert, params, None, pool, make_env, make_expert)
        for ep, rec in enumerate(_progress(records, progress, "expert episodes", n_episodes)):
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


# ----------------------------------------------------------------------------- BC
def make_policy(
    observation_space: Any, action_space: Any, lr: float = 3e-4, seed: int = 0, **policy_kwargs: Any
) -> Any:
    """A fresh SB3 actor-critic policy for the spaces (multi-input for Dict observations)."""
    import torch as th
    from gymnasium import spaces
    from stable_baselines3.common.policies import ActorCriticPolicy, MultiInputActorCriticPolicy

    th.manual_seed(seed)
    cls = (
        MultiInputActorCriticPolicy
        if isinstance(observation_space, spaces.Dict)
        else ActorCriticPolicy
    )
    return cls(observation_space, action_space, lambda _progress: lr, **policy_kwargs)


def _to_tensors(obs: dict[str, np.ndarray], idx: np.ndarray, device: Any) -> dict[str, Any]:
    import torch as th

    return {k: th.as_tensor(v[idx], device=device) for k, v in obs.items()}


def action_error(policy: Any, dataset: ImitationDataset, batch_size: int = 512) -> float:
    """Mean absolute difference between the policy's deterministic actions and the labels."""
    import torch as th

    if len(dataset) == 0:
        raise ValueError("action_error needs a non-empty dataset")
    policy.set_training_mode(False)
    errs = []
    with th.no_grad():
        for start in range(0, len(dataset), batch_size):
            idx = np.arange(start, min(start + batch_size, len(dataset)))
            dist = policy.get_distribution(_to_tensors(dataset.obs, idx, policy.device))
            act = dist.get_actions(deterministic=True).cpu().numpy()
            errs.append(np.abs(np.clip(act, -1, 1) - dataset.actions[idx]).mean(axis=1))
    return float(np.concatenate(errs).mean())


def train_bc(
    dataset: ImitationDataset,
    policy: Any,
    epochs: int = 10,
    batch_size: int = 64,
    lr: float = 3e-4,
    seed: int = 0,
    ent_weight: float = 1e-3,
    l2_weight: float = 0.0,
    progress: bool = False,
    log_fn: Callable[[str, float, int], None] | None = None,
    step_offset: int = 0,
    eval_data: ImitationDataset | None = None,
    mirror_params: EgocentricParams | None = None,
    select_best: bool = False,
    lr_final_fraction: float = 1.0,
) -> dict[str, list[float]]:
    """Behaviour cloning: minimise ``-log pi(a_expert | o) - ent_weight * entropy`` with Adam.

    Args:
        dataset: Egocentric observations and expert actions.
        policy: An SB3 ``ActorCriticPolicy`` (changed in place).
        epochs: Passes over the dataset.
        batch_size: Samples per gradient step.
        lr: Adam learning rate.
        seed: Seeds the minibatch order (numpy Generator) and torch.
        ent_weight: Entropy bonus weight (keeps the action std from collapsing too early).
        l2_weight: Adam weight decay.
        progress: Show a tqdm bar over epochs.
        log_fn: ``log_fn(tag, value, step)`` for per-epoch scalars.
        step_offset: Added to the epoch index passed to ``log_fn`` (DAgger rounds).
        eval_data: Held-out samples; their :func:`action_error` is recorded after each epoch.
        mirror_params: When given, each minibatch sample is replaced by its left-right mirror
            image (:func:`~semexplore_gym.core.egocentric.mirror_observations`) with
            probability 1/2, doubling the data for free; these are the data's parameters.
        select_best: With ``eval_data``, restore the weights of the epoch with the lowest
            held-out action error at the end (early stopping without stopping).
        lr_final_fraction: The learning rate decays along a cosine from ``lr`` to
            ``lr * lr_final_fraction`` over the epochs (1: constant).

    Returns:
        ``{"loss": [...], "neglogp": [...], "entropy": [...]}`` one value per epoch, plus
        ``"eval_action_error"`` when ``eval_data`` is given (and ``"best_epoch"``, a
        one-element list, when ``select_best`` restored a checkpoint).
    """
    import copy

    import torch as th

    if len(dataset) == 0:
        raise ValueError("train_bc needs a non-empty dataset")
    if not 0.0 < lr_final_fraction <= 1.0:
        raise ValueError(f"lr_final_fraction must be in (0, 1], got {lr_final_fraction!r}")
    if epochs < 1 or batch_size < 1 or not lr > 0:
        raise ValueError(
            f"epochs, batch_size and lr must be positive, got {epochs}, {batch_size}, {lr}"
        )
    th.manual_seed(seed)
    rng = np.random.default_rng(seed)
    optimizer = th.optim.Adam(policy.parameters(), lr=lr, weight_decay=l2_weight)
    history: dict[str, list[float]] = {"loss": [], "neglogp": [], "entropy": []}
    best_err, best_state, best_epoch = math.inf, None, -1
    for epoch in _progress(range(epochs), progress, "BC epochs"):
        frac = 0.5 * (1.0 + math.cos(math.pi * epoch / max(1, epochs - 1))) if epochs > 1 else 1.0
        for group in optimizer.param_groups:
            group["lr"] = lr * (lr_final_fraction + (1.0 - lr_final_fraction) * frac)
        policy.set_training_mode(True)
        order = rng.permutation(len(dataset))
        sums = np.zeros(3)
        for start in range(0, len(order), batch_size):
            idx = np.sort(order[start : start + batch_size])  # sorted: faster gathers
            obs_b = {k: v[idx] for k, v in dataset.obs.items()}
            act_b = dataset.actions[idx]
            if mirror_params is not None:
                flip = rng.random(len(idx)) < 0.5
                if flip.any():
                    m_obs, m_act = mirror_observations(
                        {k: v[flip] for k, v in obs_b.items()}, act_b[flip], mirror_params
                    )
                    for k in obs_b:
                        obs_b[k][flip] = m_obs[k]
                    act_b[flip] = m_act
            _values, log_prob, entropy = policy.evaluate_actions(
                {k: th.as_tensor(v, device=policy.device) for k, v in obs_b.items()},
                th.as_tensor(act_b, device=policy.device),
            )
            neglogp = -log_prob.mean()
            ent = entropy.mean() if entropy is not None else th.zeros(())
            loss = neglogp - ent_weight * ent
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()
            sums += np.array([loss.item(), neglogp.item(), ent.item()]) * len(idx)
        means = sums / len(order)
        for k, v in zip(("loss", "neglogp", "entropy"), means, strict=True):
            history[k].append(float(v))
            if log_fn is not None:
                log_fn(f"bc/{k}", float(v), step_offset + epoch)
        if eval_data is not None and len(eval_data):
            err = action_error(policy, eval_data)
            history.setdefault("eval_action_error", []).append(err)
            if log_fn is not None:
                log_fn("bc/eval_action_error", err, step_offset + epoch)
            if select_best and err < best_err:
                best_err, best_epoch = err, epoch
                best_state = copy.deepcopy(policy.state_dict())
    if best_state is not None:
        policy.load_state_dict(best_state)
        history["best_epoch"] = [float(best_epoch)]
    policy.set_training_mode(False)
    return history


# -------------------------------------------------------------------------- DAgger
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
    first_seed = seed + 10_000  # away from the seeds an expert dataset usually uses
    with _worker_pool(workers, episodes_per_round) as pool:
        for r in _progress(range(rounds), progress, "DAgger rounds"):
            b = float(sched(r))
            t0 = time.perf_counter()
            first_id = int(data.episode_ids.max()) + 1 if len(data) else 0
            jobs = []
            for j in range(episodes_per_round):
                k = r * episodes_per_round + j
                jobs.append(
                    _EpisodeJob(
                        seed=first_seed + k,
                        rng_key=(seed, k, DAGGER_STREAM),
                        max_steps=max_steps,
                        episode_id=first_id + j,
                        beta=b,
                    )
                )
            parts, covs, fracs = [], [], []
            for rec in _run_jobs(jobs, env, expert, params, learner, pool, make_env, make_expert):
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


# ------------------------------------------------------------------- model files
def save_policy(policy: Any, path: str | os.PathLike, params: EgocentricParams) -> Path:
    """Save a bare SB3 policy as a zip readable by :func:`load_model` / ``SB3Policy``."""
    import torch as th

    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    buf = io.BytesIO()
    th.save({"state_dict": policy.state_dict(), "data": policy._get_constructor_parameters()}, buf)
    meta = {
        "format": "policy",
        "policy_class": type(policy).__name__,
        "egocentric": params.to_dict(),
    }
    with zipfile.ZipFile(p, "w") as z:
        z.writestr("policy.pt", buf.getvalue())
        z.writestr(MODEL_META_NAME, json.dumps(meta, sort_keys=True))
    return p


def tag_model_zip(path: str | os.PathLike, params: EgocentricParams, algo: str) -> None:
    """Add the egocentric parameters to an SB3 algorithm zip (SB3 ignores the extra entry)."""
    meta = {"format": "sb3_algorithm", "algo": algo, "egocentric": params.to_dict()}
    with zipfile.ZipFile(path, "a") as z:
        if MODEL_META_NAME not in z.namelist():
            z.writestr(MODEL_META_NAME, json.dumps(meta, sort_keys=True))


def load_model(path: str | os.PathLike, device: str = "cpu") -> tuple[Any, EgocentricParams]:
    """Load ``(sb3_policy, egocentric_params)`` from a PPO/A2C/SAC zip or a :func:`save_policy` zip."""
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"model not found: {str(p)!r}")
    if not zipfile.is_zipfile(p):
        raise ValueError(f"{str(p)!r} is not a model zip")
    with zipfile.ZipFile(p) as z:
        names = z.namelist()
        meta = json.loads(z.read(MODEL_META_NAME)) if MODEL_META_NAME in names else {}
        policy_bytes = z.read("policy.pt") if "policy.pt" in names else None
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

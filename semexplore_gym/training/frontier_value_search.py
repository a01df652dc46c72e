"""Fit the learned frontier value (:mod:`semexplore_gym.policies.learned_frontier_value`) by a cross-entropy method.

The searched parameters are dotted overrides of
:class:`~semexplore_gym.policies.learned_frontier_value.FrontierValueParams` (the value's feature weights, the
expert's cost weights and switch margin), each with a start value, a start spread and bounds.
Every generation:

1. draws a fresh batch of training worlds (each family's spelling with a seed drawn from the
   training seeds, which must be disjoint from the evaluation seeds) and start poses;
2. runs the expert on them once (the reference), the current mean and ``population - 1``
   samples of a diagonal Gaussian round it;
3. scores each parameter set by the mean over the batch of ``log(T / T_expert)`` (mission time
   relative to the expert's on the same world and start) plus ``coverage_penalty`` per unit of
   coverage below the expert's (less a small tolerance);
4. moves the mean to the rank-weighted mean of the ``elite`` best and refits the spread.

Batches change each generation, so a parameter set that only fits a few worlds does not
survive; the result is the final mean. Missions run in ``workers`` processes; every draw comes
from one ``np.random.Generator`` seeded by ``seed``. Each generation is appended to
``generations.jsonl``; the result is written as ``model.yaml`` (a
:class:`~semexplore_gym.policies.learned_frontier_value.FrontierValueParams` layer, the file ``pretrained:`` reads).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "FrontierValueTrainConfig",
    "SearchParam",
    "batch_score",
    "load_frontier_value_config",
    "train_frontier_value",
]


@dataclass(frozen=True)
class SearchParam:
    """One searched parameter: a dotted override key of ``FrontierValueParams``.

    Attributes:
        key: e.g. ``"value.w_path_m"`` or ``"expert.cost.w_v"``.
        init: Start of the mean (the expert's value, or 0 for a new feature).
        sigma: Start of the spread.
        low: Lower bound (samples are clipped).
        high: Upper bound.
    """

    key: str
    init: float
    sigma: float
    low: float
    high: float

    def __post_init__(self) -> None:
        vals = (self.init, self.sigma, self.low, self.high)
        if not all(math.isfinite(float(v)) for v in vals) or not self.low <= self.init <= self.high:
            raise ValueError(f"search parameter {self.key!r}: need low <= init <= high, finite")
        if self.sigma <= 0:
            raise ValueError(f"search parameter {self.key!r}: sigma must be > 0")


@dataclass(frozen=True)
class FrontierValueTrainConfig:
    """Settings of :func:`train_frontier_value` (the YAML ``configs/agents/frontier_value.yml``).

    Attributes:
        seed: Seed of the one random generator (batches, start poses, samples).
        worlds: World spellings with ``seed=*`` (one per family and size), drawn uniformly.
        train_seeds: ``[first, last]`` world seeds to draw from (disjoint from evaluation).
        worlds_per_generation: Missions per parameter set and generation.
        population: Parameter sets per generation (the mean included).
        elite: How many of the best move the mean.
        generations: Upper bound on generations.
        wall_budget_s: No generation starts after this much wall time.
        workers: Missions in parallel (processes).
        max_time_s: Simulated time limit of each mission.
        coverage_penalty: Score per unit of coverage below the expert's.
        coverage_tolerance: Coverage shortfall that costs nothing.
        min_sigma_fraction: Floor of each spread, as a fraction of its start.
        params: The searched parameters.
    """

    seed: int = 0
    worlds: tuple[str, ...] = (
        "maze:seed=*,size_m=8",
        "maze:seed=*,size_m=10",
        "maze:seed=*,size_m=12",
        "office:seed=*,size_m=12",
        "office:seed=*,size_m=14",
        "office:seed=*,size_m=16",
    )
    train_seeds: tuple[int, int] = (0, 999)
    worlds_per_generation: int = 12
    population: int = 8
    elite: int = 3
    generations: int = 30
    wall_budget_s: float = 3000.0
    workers: int = 2
    max_time_s: float = 1500.0
    coverage_penalty: float = 20.0
    coverage_tolerance: float = 0.002
    min_sigma_fraction: float = 0.2
    params: tuple[SearchParam, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        if not self.worlds or not all("seed=*" in w for w in self.worlds):
            raise ValueError("worlds must be spellings with seed=* (one per family and size)")
        lo, hi = self.train_seeds
        if not 0 <= lo <= hi:
            raise ValueError(
                f"train_seeds must be [first, last] with 0 <= first <= last, got {self.train_seeds}"
            )
        if not 1 <= self.elite < self.population:
            raise ValueError("need 1 <= elite < population")
        for name in ("worlds_per_generation", "generations", "workers"):
            if int(getattr(self, name)) < 1:
                raise ValueError(f"{name} must be >= 1")
        if not self.params:
            raise ValueError("params is empty: nothing to search")


def load_frontier_value_config(path: str | None, overrides: list[str]) -> FrontierValueTrainConfig:
    """Config from YAML ``path`` (or defaults) with ``key=value`` overrides applied."""
    from semexplore_gym.config import build_params

    return build_params(FrontierValueTrainConfig, path, overrides=overrides)


def batch_score(
    times_s: Sequence[float],
    coverages: Sequence[float],
    ref_times_s: Sequence[float],
    ref_coverages: Sequence[float],
    coverage_penalty: float,
    coverage_tolerance: float,
) -> float:
    """Mean ``log(T / T_ref)`` plus the coverage penalty (lower is better)."""
    t = np.maximum(np.asarray(times_s, dtype=np.float64), 1e-3)
    r = np.maximum(np.asarray(ref_times_s, dtype=np.float64), 1e-3)
    short = np.asarray(ref_coverages, dtype=np.float64) - np.asarray(coverages, dtype=np.float64)
    short = np.maximum(0.0, short - coverage_tolerance)
    return float(np.mean(np.log(t / r)) + coverage_penalty * np.mean(short))


def _sample(
    rng: np.random.Generator,
    mean: np.ndarray,
    sigma: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    n: int,
) -> np.ndarray:
    pop = mean[None, :] + sigma[None, :] * rng.standard_normal((n, len(mean)))
    return np.clip(pop, lo, hi)


MissionRunner = Callable[[list[tuple[str, int, str, dict[str, float]]]], list[tuple[float, float]]]


def _process_runner(cfg: FrontierValueTrainConfig) -> tuple[MissionRunner, Callable[[], None]]:
    """Run (world, seed, policy, overrides) missions in ``cfg.workers`` processes."""
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    from semexplore_gym.envs.env_config import load_env_config

    env_config = load_env_config(
        None, ["episode.random_start=true", f"episode.max_time_s={cfg.max_time_s!r}"]
    )
    pool = ProcessPoolExecutor(max_workers=cfg.workers, mp_context=mp.get_context("fork"))

    def run(jobs: list[tuple[str, int, str, dict[str, float]]]) -> list[tuple[float, float]]:
        from semexplore_gym.evaluation.harness import Task

        tasks = [Task(w, p, s, cfg.max_time_s, env_config, dict(o)) for w, s, p, o in jobs]
        return list(pool.map(_run_one, tasks))

    return run, lambda: pool.shutdown(cancel_futures=True)


def _run_one(task: Any) -> tuple[float, float]:
    from semexplore_gym.evaluation.harness import run_task

    row = run_task(task)["row"]
    return float(row["mission_time_s"]), float(row["coverage"])


def _draw_batch(cfg: FrontierValueTrainConfig, rng: np.random.Generator) -> list[tuple[str, int]]:
    """A generation's training missions: ``(world, seed)`` drawn from ``rng``."""
    idx = rng.integers(0, len(cfg.worlds), size=cfg.worlds_per_generation)
    seeds = rng.integers(cfg.train_seeds[0], cfg.train_seeds[1] + 1, size=len(idx))
    return [(cfg.worlds[i], int(s)) for i, s in zip(idx, seeds, strict=True)]


def _population_scores(
    cfg: FrontierValueTrainConfig, res: list[tuple[float, float]], n: int, n_pop: int
) -> list[float]:
    """Each parameter set's :func:`batch_score` against the expert's missions (``res[:n]``)."""
    ref_t = [r[0] for r in res[:n]]
    ref_c = [r[1] for r in res[:n]]
    scores = []
    for j in range(n_pop):
        part = res[n * (j + 1) : n * (j + 2)]
        scores.append(
            batch_score(
                [r[0] for r in part],
                [r[1] for r in part],
                ref_t,
                ref_c,
                cfg.coverage_penalty,
                cfg.coverage_tolerance,
            )
        )
    return scores


def train_frontier_value(
    cfg: FrontierValueTrainConfig,
    out_dir: str | Path,
    runner: MissionRunner | None = None,
    log: Callable[[str], None] = print,
) -> dict[str, float]:
    """Search the parameters; write ``model.yaml`` and ``generations.jsonl`` into ``out_dir``.

    Args:
        cfg: The settings.
        out_dir: Output folder (created).
        runner: Runs a list of ``(world, seed, policy spec, overrides)`` missions and returns
            ``(mission_time_s, coverage)`` of each (default: ``cfg.workers`` processes).
        log: Progress lines.

    Returns:
        The final mean as dotted overrides (also in ``model.yaml``).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(cfg.seed)
    keys = [p.key for p in cfg.params]
    mean = np.array([p.init for p in cfg.params], dtype=np.float64)
    sigma0 = np.array([p.sigma for p in cfg.params], dtype=np.float64)
    sigma = sigma0.copy()
    lo = np.array([p.low for p in cfg.params], dtype=np.float64)
    hi = np.array([p.high for p in cfg.params], dtype=np.float64)
    close: Callable[[], None] = lambda: None  # noqa: E731
    if runner is None:
        runner, close = _process_runner(cfg)
    ranks = np.log(cfg.elite + 0.5) - np.log(np.arange(1, cfg.elite + 1))
    rank_w = ranks / ranks.sum()
    t0 = time.monotonic()
    history = out / "generations.jsonl"
    history.write_text("")
    try:
        for gen in range(cfg.generations):
            if time.monotonic() - t0 > cfg.wall_budget_s:
                log(f"wall budget reached after {gen} generations")
                break
            batch = _draw_batch(cfg, rng)
            pop = np.vstack([mean, _sample(rng, mean, sigma, lo, hi, cfg.population - 1)])
            # The reference: the expert the value re-ranks (the value at zero weights, the
            # outside-choice recipe's Algorithm 1 choice), so the mean at zero weights scores 0.
            jobs: list[tuple[str, int, str, dict[str, float]]] = [
                (w, s, "frontier-value", {}) for w, s in batch
            ]
            for row in pop:
                ov = {k: float(v) for k, v in zip(keys, row, strict=True)}
                jobs += [(w, s, "frontier-value", ov) for w, s in batch]
            scores = _population_scores(cfg, runner(jobs), len(batch), len(pop))
            order = np.argsort(scores)
            elite = pop[order[: cfg.elite]]
            new_mean = rank_w @ elite
            spread = np.sqrt(rank_w @ (elite - new_mean) ** 2)
            sigma = np.maximum(0.5 * sigma + 0.5 * spread, cfg.min_sigma_fraction * sigma0)
            record = {
                "generation": gen,
                "wall_s": round(time.monotonic() - t0, 1),
                "batch": batch,
                "mean_score": scores[0],
                "best_score": float(scores[order[0]]),
                "mean": dict(zip(keys, map(float, mean), strict=True)),
                "best": dict(zip(keys, map(float, pop[order[0]]), strict=True)),
                "scores": [float(s) for s in scores],
            }
            with history.open("a") as fh:
                fh.write(json.dumps(record) + "\n")
            log(
                f"gen {gen}: mean's score {scores[0]:+.4f} (ratio {math.exp(scores[0]):.3f}), "
                f"best {scores[order[0]]:+.4f}, {record['wall_s']:.0f} s"
            )
            mean = new_mean
    finally:
        close()
    final = dict(zip(keys, map(float, mean), strict=True))
    write_model(final, out / "model.yaml", wall_s=time.monotonic() - t0)
    return final


def write_model(overrides: dict[str, float], path: Path, wall_s: float) -> None:
    """Write dotted overrides as a nested ``FrontierValueParams`` YAML layer."""
    import yaml

    nested: dict[str, Any] = {}
    for key, value in overrides.items():
        node = nested
        parts = key.split(".")
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = round(float(value), 6)
    head = (
        "# Learned frontier value (semexplore_gym.policies.learned_frontier_value.FrontierValueParams layer), fitted by\n"
        f"# semexplore_gym.training.frontier_value_search in {wall_s:.0f} s wall.\n"
    )
    path.write_text(head + yaml.safe_dump(nested, sort_keys=True))

"""The benchmark harness: every (world, policy, seed) mission, resumable, in parallel if asked.

Results go to an output directory as they arrive, so a killed run loses at most the missions
in flight, and running the same command again resumes:

- ``runs.csv``: one row per finished mission (:data:`CSV_COLUMNS`), appended and flushed as
  each mission ends;
- ``traces/<world>__<policy>__<seed>.csv``: the coverage trace (sim time, coverage, area);
- ``trajectories/<world>__<policy>__<seed>.npy``: the poses, for trajectory pictures;
- ``benchmark.json``: the resolved command (worlds, policies, seeds, config).

Seeds are shared across policies, so comparisons are paired: the same seed gives the same
start pose (and the same procedural world for ``family:seed=*`` spellings) to every policy.
"""

from __future__ import annotations

import csv
import json
import math
import os
import re
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

CSV_COLUMNS: tuple[str, ...] = (
    "world",
    "policy",
    "seed",
    "mission_time_s",
    "coverage",
    "self_stopped",
    "stop_reason",
    "path_length_m",
    "collisions",
    "T90_s",
    "T99_s",
    "mean_map_generation_ms",
    "mean_global_planning_ms",
    "wall_time_s",
    "explored_area_m2",
    "steps",
)


@dataclass(frozen=True)
class Task:
    """One mission to run."""

    world: str
    policy: str
    seed: int
    max_time_s: float | None = None
    env_config: Any = None
    policy_overrides: dict[str, Any] = field(default_factory=dict)

    @property
    def key(self) -> tuple[str, str, int]:
        return (self.world, self.policy, self.seed)

    @property
    def resolved_world(self) -> str:
        """The world spelling with a ``seed=*`` placeholder replaced by this task's seed."""
        return self.world.replace("seed=*", f"seed={self.seed}")


def expand_tasks(
    worlds: Sequence[str],
    policies: Sequence[str],
    seeds: Sequence[int],
    max_time_s: float | None = None,
    env_config: Any = None,
    policy_overrides: dict[str, Any] | None = None,
) -> list[Task]:
    """Every (world, policy, seed), ordered seed-major so early results are already paired."""
    if not worlds:
        raise ValueError("no worlds given")
    if not policies:
        raise ValueError("no policies given")
    if not seeds:
        raise ValueError("no seeds given (runs must be >= 1)")
    for p in policies:
        if not isinstance(p, str) or not p.strip():
            raise ValueError(f"bad policy name {p!r}")
    return [
        Task(w, p, int(s), max_time_s, env_config, dict(policy_overrides or {}))
        for s in seeds
        for w in worlds
        for p in policies
    ]


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9._=-]+", "_", text).strip("_")[:120] or "x"


def task_stem(world: str, policy: str, seed: int) -> str:
    return f"{_slug(world)}__{_slug(policy)}__{seed}"


def run_task(task: Task) -> dict[str, Any]:
    """Run one mission in this process; returns a picklable record (row + trace + trajectory)."""
    import gymnasium as gym

    import semexplore_gym  # noqa: F401  (registers the env)
    from policies.registry import make_policy
    from policies.rollout import run_mission
    from semexplore_gym.evaluation.warmup import warm_up

    # Kernels compiled or loaded before the mission's clocks start.
    warm_up(
        lambda: make_policy(task.policy, **task.policy_overrides),
        task.env_config,
        key=(task.policy, repr(task.env_config), repr(task.policy_overrides)),
    )
    env = gym.make("SemanticExplore-v0", world=task.resolved_world, config=task.env_config)
    try:
        policy = make_policy(task.policy, **task.policy_overrides)
        # Missions end when the policy stops itself (or at the time limit), not at the env's
        # coverage goal: mission time is each method's own exploration time; T90/T99 compare
        # all methods on the same coverage levels.
        res = run_mission(
            env,
            policy,
            seed=task.seed,
            max_time_s=task.max_time_s,
            progress=False,
            ignore_terminated=True,
        )
    finally:
        env.close()
    row = {
        "world": task.world,
        "policy": task.policy,
        "seed": task.seed,
        "mission_time_s": res.mission_time_s,
        "coverage": res.coverage,
        "self_stopped": res.self_stopped,
        "stop_reason": res.stop_reason,
        "path_length_m": res.path_length_m,
        "collisions": res.collisions,
        "T90_s": res.t90_s,
        "T99_s": res.t99_s,
        "mean_map_generation_ms": res.mean_map_generation_ms,
        "mean_global_planning_ms": res.mean_global_planning_ms,
        "wall_time_s": res.wall_time_s,
        "explored_area_m2": res.explored_area_m2,
        "steps": res.steps,
    }
    return {
        "row": row,
        "trace": np.asarray(res.coverage_trace, dtype=np.float64),
        "trajectory": np.asarray(res.trajectory),
    }


def read_runs(path: str | os.PathLike) -> list[dict[str, Any]]:
    """Rows of a ``runs.csv`` with numbers parsed (empty cells become None)."""
    p = Path(path)
    if not p.exists():
        return []
    out = []
    with p.open(newline="") as f:
        for raw in csv.DictReader(f):
            row: dict[str, Any] = {}
            for k, v in raw.items():
                if k in ("world", "policy", "stop_reason"):
                    row[k] = v
                elif k == "self_stopped":
                    row[k] = v == "True"
                elif v in ("", "None", None):
                    row[k] = None
                elif k in ("seed", "collisions", "steps"):
                    row[k] = int(float(v))
                else:
                    row[k] = float(v)
            out.append(row)
    return out


class ResultWriter:
    """Appends finished missions to ``runs.csv`` (flushed per row) and their traces."""

    def __init__(self, out_dir: str | os.PathLike) -> None:
        self.out = Path(out_dir)
        (self.out / "traces").mkdir(parents=True, exist_ok=True)
        (self.out / "trajectories").mkdir(parents=True, exist_ok=True)
        self.csv_path = self.out / "runs.csv"
        new = not self.csv_path.exists() or self.csv_path.stat().st_size == 0
        if not new:
            with self.csv_path.open(newline="") as f:
                header = next(csv.reader(f), [])
            if tuple(header) != CSV_COLUMNS:
                raise ValueError(
                    f"{self.csv_path} has columns {header}, expected {list(CSV_COLUMNS)}; use a new --out directory"
                )
        self._f = self.csv_path.open("a", newline="")
        self._w = csv.DictWriter(self._f, fieldnames=list(CSV_COLUMNS))
        if new:
            self._w.writeheader()
            self._f.flush()

    def write(self, record: dict[str, Any]) -> None:
        row = record["row"]
        stem = task_stem(row["world"], row["policy"], int(row["seed"]))
        # Trace and trajectory first: a row in runs.csv promises they exist.
        trace_path = self.out / "traces" / f"{stem}.csv"
        np.savetxt(
            trace_path,
            record["trace"],
            delimiter=",",
            header="sim_time_s,coverage,explored_area_m2",
            comments="",
            fmt="%.6g",
        )
        np.save(self.out / "trajectories" / f"{stem}.npy", record["trajectory"])
        self._w.writerow({k: ("" if row.get(k) is None else row[k]) for k in CSV_COLUMNS})
        self._f.flush()
        os.fsync(self._f.fileno())

    def close(self) -> None:
        self._f.close()


def _run_sequential(
    tasks: list[Task], fn: Callable[[Task], dict[str, Any]]
) -> Iterable[tuple[Task, dict[str, Any] | BaseException]]:
    for t in tasks:
        try:
            yield t, fn(t)
        except Exception as e:  # noqa: BLE001 - reported per mission, the sweep goes on
            yield t, e


def _run_processes(
    tasks: list[Task], workers: int
) -> Iterable[tuple[Task, dict[str, Any] | BaseException]]:
    import concurrent.futures as cf
    import multiprocessing as mp

    # Fork would copy numba/pymunk state of the parent; spawn gives clean workers.
    ctx = mp.get_context("spawn")
    with cf.ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        futures = {pool.submit(run_task, t): t for t in tasks}
        for fut in cf.as_completed(futures):
            t = futures[fut]
            try:
                yield t, fut.result()
            except Exception as e:  # noqa: BLE001
                yield t, e


def _run_ray(
    tasks: list[Task], address: str | None, workers: int
) -> Iterable[tuple[Task, dict[str, Any] | BaseException]]:
    try:
        import ray
    except ImportError as e:
        raise ImportError('--backend ray needs Ray: pip install "semexplore-gym[ray]"') from e
    started = False
    if not ray.is_initialized():
        kwargs: dict[str, Any] = (
            {"address": address}
            if address
            else {"num_cpus": max(1, workers), "include_dashboard": False}
        )
        ray.init(ignore_reinit_error=True, log_to_driver=False, **kwargs)
        started = True
    try:
        remote = ray.remote(num_cpus=1)(run_task)
        refs = {remote.remote(t): t for t in tasks}
        pending = list(refs)
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            for ref in done:
                t = refs[ref]
                try:
                    yield t, ray.get(ref)
                except Exception as e:  # noqa: BLE001
                    yield t, e
    finally:
        if started:
            ray.shutdown()


def run_benchmark(
    tasks: list[Task],
    out_dir: str | os.PathLike,
    workers: int = 1,
    backend: str = "process",
    ray_address: str | None = None,
    progress: bool = True,
    task_fn: Callable[[Task], dict[str, Any]] = run_task,
) -> dict[str, Any]:
    """Run the missions not yet in ``out_dir/runs.csv``; write each as it finishes.

    Args:
        tasks: From :func:`expand_tasks`.
        out_dir: Output directory (created).
        workers: Parallel missions (processes, or Ray CPUs for a local Ray instance).
        backend: ``"process"`` (local processes; 1 worker runs in this process) or ``"ray"``.
        ray_address: Address of an existing Ray cluster (``"auto"``), or None for a local one.
        progress: Show a progress bar over missions on stderr.
        task_fn: The mission runner (tests substitute a fake one; only the sequential path uses it).

    Returns:
        ``{"ran": n, "skipped": n, "failed": [(key, message), ...]}``.
    """
    if backend not in ("process", "ray"):
        raise ValueError(f"backend must be 'process' or 'ray', got {backend!r}")
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers!r}")
    writer = ResultWriter(out_dir)
    done = {(r["world"], r["policy"], int(r["seed"])) for r in read_runs(writer.csv_path)}
    todo = [t for t in tasks if t.key not in done]
    skipped = len(tasks) - len(todo)
    failed: list[tuple[tuple[str, str, int], str]] = []
    ran = 0
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(
            total=len(tasks),
            initial=skipped,
            desc="missions",
            unit="mission",
            file=sys.stderr,
            dynamic_ncols=True,
        )
    try:
        if backend == "ray":
            stream = _run_ray(todo, ray_address, workers)
        elif workers > 1 and len(todo) > 1:
            stream = _run_processes(todo, workers)
        else:
            stream = _run_sequential(todo, task_fn)
        for task, result in stream:
            if isinstance(result, BaseException):
                failed.append((task.key, f"{type(result).__name__}: {result}"))
                print(
                    f"mission {task.key} failed: {type(result).__name__}: {result}", file=sys.stderr
                )
            else:
                writer.write(result)
                ran += 1
            if bar is not None:
                bar.update(1)
                bar.set_postfix_str(f"{task.world} {task.policy} seed={task.seed}", refresh=False)
    finally:
        writer.close()
        if bar is not None:
            bar.close()
    return {"ran": ran, "skipped": skipped, "failed": failed}


def parse_seeds(runs: int, seed0: int = 0) -> list[int]:
    if runs < 1:
        raise ValueError(f"--runs must be >= 1, got {runs}")
    return list(range(seed0, seed0 + runs))


def finite_or_none(v: Any) -> float | None:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def write_manifest(out_dir: str | os.PathLike, manifest: dict[str, Any]) -> None:
    p = Path(out_dir) / "benchmark.json"
    manifest = dict(manifest, written_at=time.strftime("%Y-%m-%dT%H:%M:%S"))
    p.write_text(json.dumps(manifest, indent=2, default=str))

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
import io
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

from semexplore_gym.core.validation import short_repr

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
    "scored_replans",
    "semantic_share",
)

#: Columns added after the first release: rows of older ``runs.csv`` files lack them (None).
OPTIONAL_COLUMNS: frozenset[str] = frozenset({"scored_replans", "semantic_share"})


def resolve_world(world: str, seed: int) -> str:
    """A world spelling with a ``seed=*`` placeholder replaced by ``seed``."""
    return world.replace("seed=*", f"seed={int(seed)}")


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
        return resolve_world(self.world, self.seed)


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
            raise ValueError(f"bad policy name {short_repr(p)}")
    for what, items in (("worlds", worlds), ("policies", policies), ("seeds", seeds)):
        seen: set = set()
        for item in items:
            if item in seen:
                raise ValueError(
                    f"--{what} lists {short_repr(item)} twice; each must appear once "
                    "(a repeat would count the same missions twice)"
                )
            seen.add(item)
    return [
        Task(w, p, int(s), max_time_s, env_config, dict(policy_overrides or {}))
        for s in seeds
        for w in worlds
        for p in policies
    ]


def file_slug(text: str) -> str:
    """``text`` made safe as part of a file name (at most 120 characters)."""
    return re.sub(r"[^A-Za-z0-9._=-]+", "_", text).strip("_")[:120] or "x"


def task_stem(world: str, policy: str, seed: int) -> str:
    return f"{file_slug(world)}__{file_slug(policy)}__{seed}"


def _warm_up_config_key(env_config: Any) -> str:
    """The env config without its episode section: the warm-up sets its own time limit, so
    suite worlds that differ only in ``episode.max_time_s`` warm up once."""
    if env_config is None or isinstance(env_config, str):
        return repr(env_config)
    from semexplore_gym.config import to_dict

    d = to_dict(env_config)
    if not isinstance(d, dict):
        return repr(env_config)
    return json.dumps({k: v for k, v in d.items() if k != "episode"}, sort_keys=True, default=str)


def run_task(task: Task) -> dict[str, Any]:
    """Run one mission in this process; returns a picklable record (row + trace + trajectory)."""
    from semexplore_gym.evaluation.rollout import (
        make_mission_env,
        map_observation_for,
        run_mission,
    )
    from semexplore_gym.evaluation.warmup import warm_up
    from semexplore_gym.policies.registry import make_policy

    # Kernels compiled or loaded before the mission's clocks start.
    warm_up(
        lambda: make_policy(task.policy, **task.policy_overrides),
        task.env_config,
        key=(task.policy, _warm_up_config_key(task.env_config), repr(task.policy_overrides)),
    )
    policy = make_policy(task.policy, **task.policy_overrides)
    env = make_mission_env(task.resolved_world, task.env_config, **map_observation_for(policy))
    try:
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
        **semantic_share_cells(res.policy_counters),
    }
    return {
        "row": row,
        "trace": np.asarray(res.coverage_trace, dtype=np.float64),
        "trajectory": np.asarray(res.trajectory),
    }


def semantic_share_cells(counters: dict[str, int]) -> dict[str, Any]:
    """The semantic expert's replans with scored frontiers, and the share of them in which the
    semantic gain changed the chosen frontier (None for policies that do not count them)."""
    scored = counters.get("scored_replans")
    if scored is None:
        return {"scored_replans": None, "semantic_share": None}
    decisive = counters.get("semantic_decisive", 0)
    return {
        "scored_replans": int(scored),
        "semantic_share": (decisive / scored) if scored > 0 else None,
    }


def _parse_row(raw: dict[str, Any], where: str) -> dict[str, Any]:
    if None in raw or any(raw.get(k) is None for k in CSV_COLUMNS if k not in OPTIONAL_COLUMNS):
        raise ValueError(f"{where}: expected {len(CSV_COLUMNS)} cells")
    row: dict[str, Any] = {}
    for k, v in raw.items():
        if k in ("world", "policy", "stop_reason"):
            row[k] = v
        elif k == "self_stopped":
            if v not in ("True", "False"):
                raise ValueError(
                    f"{where}: self_stopped must be True or False, got {short_repr(v)}"
                )
            row[k] = v == "True"
        elif v in ("", "None"):
            if k in ("world", "policy", "seed"):
                raise ValueError(f"{where}: empty {k}")
            row[k] = None
        else:
            try:
                row[k] = (
                    int(v) if k in ("seed", "collisions", "steps", "scored_replans") else float(v)
                )
            except ValueError:
                raise ValueError(f"{where}: {k} is not a number: {short_repr(v)}") from None
    return row


def complete_csv_bytes(path: Path) -> int:
    """Length of ``path`` up to its last newline: a row cut by a kill has no newline yet."""
    data = path.read_bytes()
    return data.rfind(b"\n") + 1


def read_runs(path: str | os.PathLike) -> list[dict[str, Any]]:
    """Rows of a ``runs.csv`` with numbers parsed (empty cells become None).

    A last line without its newline (the process was killed while writing it) is not a
    finished mission and is ignored; any other malformed row raises a ValueError naming it.
    """
    p = Path(path)
    if not p.exists():
        return []
    text = p.read_bytes()[: complete_csv_bytes(p)].decode("utf-8", errors="replace")
    out = []
    reader = csv.DictReader(io.StringIO(text, newline=""))
    for i, raw in enumerate(reader, start=2):
        out.append(_parse_row(raw, f"{p} line {i}"))
    return out


class ResultWriter:
    """Appends finished missions to ``runs.csv`` (flushed per row) and their traces."""

    def __init__(self, out_dir: str | os.PathLike) -> None:
        self.out = Path(out_dir)
        (self.out / "traces").mkdir(parents=True, exist_ok=True)
        (self.out / "trajectories").mkdir(parents=True, exist_ok=True)
        self.csv_path = self.out / "runs.csv"
        if self.csv_path.exists():
            # Drop a row torn by a kill mid-write, so that mission runs again.
            keep = complete_csv_bytes(self.csv_path)
            if keep < self.csv_path.stat().st_size:
                with self.csv_path.open("r+b") as f:
                    f.truncate(keep)
        new = not self.csv_path.exists() or self.csv_path.stat().st_size == 0
        if not new:
            with self.csv_path.open(newline="") as f:
                header = next(csv.reader(f), [])
            if tuple(header) != CSV_COLUMNS:
                raise ValueError(
                    f"{self.csv_path} has columns {short_repr(header)}, expected {list(CSV_COLUMNS)}; use a new --out directory"
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


FINGERPRINT_FILE = "fingerprint.json"


def _canon(value: Any) -> Any:
    return json.loads(json.dumps(value, sort_keys=True, default=str))


def run_fingerprint(
    tasks: Sequence[Task], suites: Sequence[dict[str, Any]] | None = None
) -> dict[str, Any]:
    """What makes rows comparable beyond (world, policy, seed): the time limit, the env config,
    each policy's overrides and the suites run. Stored next to ``runs.csv``, checked on resume.

    When every mission shares one time limit and env config they are stored once
    (``max_time_s``, ``env_config``); a suite's per-world limits go to ``world_settings``.
    """
    from semexplore_gym.config import to_dict

    per_world: dict[str, Any] = {}
    for t in tasks:
        s = _canon(
            {
                "max_time_s": t.max_time_s,
                "env_config": to_dict(t.env_config) if t.env_config is not None else None,
            }
        )
        if per_world.setdefault(t.world, s) != s:
            raise ValueError(
                f"world {short_repr(t.world)} is listed with two time limits or env configs"
            )
    shared = {json.dumps(v, sort_keys=True) for v in per_world.values()}
    fp: dict[str, Any] = {}
    if len(shared) == 1:
        fp.update(json.loads(next(iter(shared))))
    elif shared:
        fp["world_settings"] = {w: per_world[w] for w in sorted(per_world)}
    overrides: dict[str, Any] = {}
    for t in tasks:
        o = _canon(t.policy_overrides)
        if overrides.setdefault(t.policy, o) != o:
            raise ValueError(f"policy {short_repr(t.policy)} is listed with two sets of overrides")
    fp["policy_overrides"] = {k: overrides[k] for k in sorted(overrides)}
    if suites:
        fp["suites"] = [_canon(dict(s)) for s in suites]
    return fp


def _settings_of(fp: dict[str, Any], world: str) -> dict[str, Any] | None:
    """The (max_time_s, env_config) a fingerprint records for ``world``, or None if unknown."""
    if "world_settings" in fp:
        return fp["world_settings"].get(world)
    return {"max_time_s": fp.get("max_time_s"), "env_config": fp.get("env_config")}


def check_fingerprint(out_dir: Path, fingerprint: dict[str, Any], has_rows: bool) -> None:
    """Store ``fingerprint`` in ``out_dir``, or refuse to resume rows made with other settings.

    Adding worlds, seeds or policies to a run is fine; changing ``max_time_s``, the env config,
    the overrides of a policy that already has rows, or a suite's version is not.
    """
    path = out_dir / FINGERPRINT_FILE
    old: dict[str, Any] | None = None
    if has_rows and path.exists():
        try:
            old = json.loads(path.read_text())
        except (ValueError, OSError):
            old = {}
    if old is not None:
        changed: list[tuple[str, Any, Any]] = []
        if "world_settings" not in old and "world_settings" not in fingerprint:
            changed += [
                (k, old.get(k), fingerprint.get(k))
                for k in ("max_time_s", "env_config")
                if old.get(k) != fingerprint.get(k)
            ]
        else:
            worlds = sorted(fingerprint.get("world_settings") or {}) or sorted(
                old.get("world_settings") or {}
            )
            for w in worlds:
                a, b = _settings_of(old, w), _settings_of(fingerprint, w)
                if a is None or b is None:
                    continue
                changed += [
                    (f"{k} of {w}", a.get(k), b.get(k))
                    for k in ("max_time_s", "env_config")
                    if a.get(k) != b.get(k)
                ]
        old_over = old.get("policy_overrides") or {}
        new_over = fingerprint["policy_overrides"]
        changed += [
            (f"overrides of {p}", old_over[p], new_over[p])
            for p in sorted(set(old_over) & set(new_over))
            if old_over[p] != new_over[p]
        ]
        old_suites = {s.get("name"): s for s in old.get("suites") or []}
        for s in fingerprint.get("suites") or []:
            o = old_suites.get(s.get("name"))
            if o is not None and o != s:
                changed.append((f"suite {s.get('name')}", o, s))
        if changed:
            detail = ", ".join(
                f"{k}: {short_repr(a, 60)} -> {short_repr(b, 60)}" for k, a, b in changed
            )
            raise ValueError(
                f"{out_dir} holds missions run with different settings ({detail}); "
                "rerun with the same settings to resume, or use a new --out directory"
            )
        merged = dict(fingerprint, policy_overrides={**old_over, **new_over})
        if "world_settings" in old and "world_settings" in fingerprint:
            merged["world_settings"] = {**old["world_settings"], **fingerprint["world_settings"]}
        if old.get("suites") or fingerprint.get("suites"):
            names = {
                s.get("name"): s
                for s in [*(old.get("suites") or []), *(fingerprint.get("suites") or [])]
            }
            merged["suites"] = list(names.values())
        fingerprint = merged
    path.write_text(json.dumps(fingerprint, indent=2, sort_keys=True))


def _die_with_parent() -> None:
    """Worker initializer: end this process when the benchmark process dies, even by SIGKILL.

    Linux ``prctl(PR_SET_PDEATHSIG, SIGKILL)``; elsewhere (and as a backstop) a thread that
    exits when the parent process id changes.
    """
    import signal
    import threading

    parent = os.getppid()
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG = 1
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent:  # the parent died before prctl took effect
        os._exit(1)

    def watch() -> None:
        while True:
            time.sleep(1.0)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, daemon=True, name="die-with-parent").start()


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
    with cf.ProcessPoolExecutor(
        max_workers=workers, mp_context=ctx, initializer=_die_with_parent
    ) as pool:
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
    progress: bool = False,
    task_fn: Callable[[Task], dict[str, Any]] = run_task,
    *,
    suites: Sequence[dict[str, Any]] | None = None,
) -> dict[str, Any]:
    """Run the missions not yet in ``out_dir/runs.csv``; write each as it finishes.

    Args:
        tasks: From :func:`expand_tasks`.
        out_dir: Output directory (created).
        workers: Parallel missions (processes, or Ray CPUs for a local Ray instance).
        backend: ``"process"`` (local processes; 1 worker runs in this process) or ``"ray"``.
        ray_address: Address of an existing Ray cluster (``"auto"``), or None for a local one.
        progress: Show a progress bar over missions on stderr (off by default; the CLI turns it on).
        task_fn: The mission runner (tests substitute a fake one; only the sequential path uses it).
        suites: ``{"name", "version"}`` of the suites the tasks come from, kept in the run's
            fingerprint (a suite's version may not change between runs into one directory).

    Returns:
        ``{"ran": n, "skipped": n, "failed": [(key, message), ...]}``.
    """
    if backend not in ("process", "ray"):
        raise ValueError(f"backend must be 'process' or 'ray', got {backend!r}")
    if workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers!r}")
    if len({t.key for t in tasks}) != len(tasks):
        raise ValueError("the same (world, policy, seed) mission is listed twice")
    fingerprint = run_fingerprint(tasks, suites)
    writer = ResultWriter(out_dir)
    try:
        rows = read_runs(writer.csv_path)
        check_fingerprint(writer.out, fingerprint, has_rows=bool(rows))
    except BaseException:
        writer.close()
        raise
    done = {(r["world"], r["policy"], int(r["seed"])) for r in rows}
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

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

The parts, one module each: the missions (:mod:`.tasks`), one mission in this process
(:mod:`.mission_task`), the row schema and its parsing (:mod:`.run_row`), the output directory
(:mod:`.run_writer`), resuming (:mod:`.resume`), where missions run (:mod:`.backends`) and the
progress bar (:mod:`.progress_bar`). This module runs them together and re-exports the names
callers use.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Sequence
from typing import Any

from semexplore_gym.config.extras import require_extra
from semexplore_gym.evaluation.backends import mission_stream
from semexplore_gym.evaluation.errors import ParameterError
from semexplore_gym.evaluation.mission_task import mission_row, run_task, warm_up_task
from semexplore_gym.evaluation.progress_bar import MissionsBar
from semexplore_gym.evaluation.resume import (
    FINGERPRINT_FILE,
    check_fingerprint,
    run_fingerprint,
)
from semexplore_gym.evaluation.run_row import (
    CSV_COLUMNS,
    OPTIONAL_COLUMNS,
    RunRow,
    complete_csv_bytes,
    finite_or_none,
    read_runs,
)
from semexplore_gym.evaluation.run_writer import (
    ResultWriter,
    file_slug,
    task_stem,
    write_manifest,
)
from semexplore_gym.evaluation.tasks import Task, expand_tasks, parse_seeds, resolve_world

__all__ = [
    "CSV_COLUMNS",
    "FINGERPRINT_FILE",
    "OPTIONAL_COLUMNS",
    "ResultWriter",
    "RunRow",
    "Task",
    "check_fingerprint",
    "complete_csv_bytes",
    "expand_tasks",
    "file_slug",
    "finite_or_none",
    "mission_row",
    "parse_seeds",
    "read_runs",
    "resolve_world",
    "run_benchmark",
    "run_fingerprint",
    "run_task",
    "task_stem",
    "write_manifest",
]


def _check_run_args(tasks: list[Task], workers: int, backend: str) -> None:
    if backend not in ("process", "ray"):
        raise ParameterError("backend", f"{{param}} must be 'process' or 'ray', got {backend!r}")
    if backend == "ray":
        require_extra("ray", 'backend "ray"', "ray")  # before any output or mission
    if workers < 1:
        raise ParameterError("workers", f"{{param}} must be >= 1, got {workers!r}")
    if len({t.key for t in tasks}) != len(tasks):
        raise ParameterError(
            "tasks", "the same (world, policy, seed) mission is listed twice in {param}"
        )


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

    Raises:
        ParameterError: a bad ``backend``, ``workers`` or ``tasks``, or an ``out_dir`` holding
            missions run with other settings (see :func:`.resume.check_fingerprint`).
    """
    _check_run_args(tasks, workers, backend)
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
    if progress and backend == "process" and task_fn is run_task:
        # Compile here, before the bar is drawn: the compile notice gets lines of its own, and
        # worker processes load the kernels from the disk cache instead of compiling them each.
        for task in todo:
            try:
                warm_up_task(task)
            except Exception:  # noqa: BLE001 - the mission itself fails and is reported
                continue
    bar = MissionsBar(progress, total=len(tasks), done=skipped)
    try:
        for task, result in mission_stream(todo, backend, workers, ray_address, task_fn, run_task):
            if isinstance(result, BaseException):
                failed.append((task.key, f"{type(result).__name__}: {result}"))
                print(
                    f"mission {task.key} failed: {type(result).__name__}: {result}", file=sys.stderr
                )
            else:
                writer.write(result)
                ran += 1
            bar.finished(task)
    finally:
        writer.close()
        bar.close()
    return {"ran": ran, "skipped": skipped, "failed": failed}

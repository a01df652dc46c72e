"""Where benchmark missions run: in this process, in local worker processes, or on Ray.

Each backend takes the missions still to run and yields ``(task, record or exception)`` as
missions finish, in whatever order they finish; a failed mission is reported, not raised, so
one bad mission does not end a sweep.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from typing import Any, TypeVar

from semexplore_gym.config.extras import require_extra

#: A mission to run: the single-robot benchmark's ``Task`` or the team benchmark's
#: ``TeamTask`` (frozen dataclasses, so they pickle and hash).
Task = TypeVar("Task")
#: What a backend yields per mission: the task and its record, or the exception it raised.
Outcome = tuple[Task, dict[str, Any] | BaseException]
MissionRunner = Callable[[Task], dict[str, Any]]


def die_with_parent() -> None:
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


def run_sequential(tasks: list[Task], fn: MissionRunner[Task]) -> Iterator[Outcome[Task]]:
    """Each mission in this process, in order."""
    for t in tasks:
        try:
            yield t, fn(t)
        except Exception as e:  # noqa: BLE001 - reported per mission, the sweep goes on
            yield t, e


def run_processes(
    tasks: list[Task], workers: int, fn: MissionRunner[Task]
) -> Iterator[Outcome[Task]]:
    """Missions in ``workers`` spawned processes that die with this one; ``fn`` must pickle."""
    import concurrent.futures as cf
    import multiprocessing as mp

    # Fork would copy numba/pymunk state of the parent; spawn gives clean workers.
    ctx = mp.get_context("spawn")
    with cf.ProcessPoolExecutor(
        max_workers=workers, mp_context=ctx, initializer=die_with_parent
    ) as pool:
        futures = {pool.submit(fn, t): t for t in tasks}
        for fut in cf.as_completed(futures):
            t = futures[fut]
            try:
                yield t, fut.result()
            except Exception as e:  # noqa: BLE001
                yield t, e


def run_ray(
    tasks: list[Task], address: str | None, workers: int, fn: MissionRunner[Task]
) -> Iterator[Outcome[Task]]:
    """Missions as Ray tasks of one CPU each, on the cluster at ``address`` or a local Ray with
    ``workers`` CPUs (started here and shut down when the stream ends)."""
    require_extra("ray", 'backend "ray"', "ray")
    import ray

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
        remote = ray.remote(num_cpus=1)(fn)
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


def mission_stream(
    todo: list[Task],
    backend: str,
    workers: int,
    ray_address: str | None,
    task_fn: MissionRunner[Task],
    parallel_fn: MissionRunner[Task],
) -> Iterable[Outcome[Task]]:
    """The backend for these settings: Ray, worker processes (more than one worker and
    mission), or this process. ``task_fn`` runs in this process; ``parallel_fn`` (picklable by
    reference) in workers."""
    if backend == "ray":
        return run_ray(todo, ray_address, workers, parallel_fn)
    if workers > 1 and len(todo) > 1:
        return run_processes(todo, workers, parallel_fn)
    return run_sequential(todo, task_fn)

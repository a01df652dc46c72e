"""Bringing the shipped result tables to today's code: which kind of table a CSV is, and one
job per start run in worker processes into a cache CSV that a rerun resumes
(``scripts/recompute_bounds.py``: today's bound; ``scripts/rerun_oracle.py``: today's oracle)."""

from __future__ import annotations

import csv
from collections.abc import Callable, Iterable, Sequence
from multiprocessing import Pool
from pathlib import Path
from typing import Any

BEST_KNOWN = "best-known"
CHECKED_MISSIONS = "checked missions"
RUNS = "runs"


def table_kind(path: Path, runs_columns: Sequence[str] = ()) -> str:
    """``"best-known"`` (:data:`~.best_known.COLUMNS`), ``"checked missions"``
    (:data:`~.bound_check.MISSION_COLUMNS`) or, when ``runs_columns`` are given and all in its
    header, ``"runs"`` (a benchmark's ``runs.csv``, trimmed).

    Raises:
        ValueError: one line: the file does not exist, or its header is none of these.
    """
    from semexplore_gym.evaluation.best_known import COLUMNS
    from semexplore_gym.evaluation.bound_check import MISSION_COLUMNS

    if not path.is_file():
        raise ValueError(f"{path} does not exist")
    with path.open(newline="", encoding="utf-8", errors="replace") as fh:
        header = next(csv.reader(fh), [])
    if all(c in header for c in COLUMNS):
        return BEST_KNOWN
    if all(c in header for c in MISSION_COLUMNS):
        return CHECKED_MISSIONS
    if runs_columns and all(c in header for c in runs_columns):
        return RUNS
    kinds = "a best-known table nor a checked-missions CSV"
    if runs_columns:
        kinds = "a best-known table, a checked-missions CSV nor a runs.csv"
    raise ValueError(f"{path} is neither {kinds}")


def run_into_cache(
    job: Callable[[Any], Sequence[Any]],
    tasks: Iterable[Any],
    cache: Path,
    columns: Sequence[str],
    workers: int,
    *,
    progress: bool = True,
    desc: str = "",
    unit: str = "start",
) -> None:
    """``job(task)`` for every task in ``workers`` processes; each returned row (its cells in
    the order of ``columns``) is appended to ``cache`` and flushed as it comes, the header
    first when the file is new, so that an interrupted run keeps what it did."""
    from tqdm import tqdm

    tasks = list(tasks)
    new = not cache.is_file()
    cache.parent.mkdir(parents=True, exist_ok=True)
    with cache.open("a", newline="", encoding="utf-8") as fh, Pool(workers) as pool:
        w = csv.writer(fh)
        if new:
            w.writerow(columns)
        bar = tqdm(total=len(tasks), desc=desc, unit=unit, disable=not progress)
        for row in pool.imap_unordered(job, tasks):
            w.writerow(row)
            fh.flush()
            bar.update()
        bar.close()


def add_refresh_arguments(ap: Any, cache: str, what: str) -> None:
    """The options both refresh scripts take: ``--workers``, ``--cache`` (default ``cache``,
    holding ``what`` per start), ``--fresh``, ``--dry-run``, ``--no-progress``."""
    ap.add_argument("--workers", type=int, default=1, help="processes (default 1)")
    ap.add_argument(
        "--cache",
        type=Path,
        default=Path(cache),
        help=f"each start's {what}, as it comes (default {cache})",
    )
    ap.add_argument("--fresh", action="store_true", help="discard the cache first")
    ap.add_argument("--dry-run", action="store_true", help="report only; write no table")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")

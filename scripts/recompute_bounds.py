"""Recompute the certified lower bound of every start of best-known and checked-missions tables
with today's bound, check it against every mission in them and write it into their columns.

    SEMEXPLORE_MAPS_DIR=../shared/maps python scripts/recompute_bounds.py \\
        configs/best_known/best_known.csv docs/results/oracle/missions.csv --workers 2
    python scripts/recompute_bounds.py my_missions.csv --dry-run   # report, write nothing

After a change to the bound (``semexplore_gym.core.coverage_tour``), the tables that ship a
bound per start go stale: the best-known table (``scripts/update_best_known.py``) and the
checked missions (``scripts/check_lower_bound.py --missions-out``). This computes the bound of
each (world, seed, start) once, from the start ``env.reset(seed=seed)`` draws with the default
env config (``seed=*`` worlds take the row's seed), in ``--workers`` processes, each as it
comes into ``--cache`` (rerunning resumes; ``--fresh`` starts over, as after another change).
It then counts the rows whose T99 or drive to 99 % lies below the new bound; with any such
violation it writes nothing and exits 1 (the bound would be wrong). Otherwise it rewrites the
bound columns (best known: 3 decimals, checked missions: 4), keeps every other cell, and
prints per table the rows changed and the new bound over the old (least, median, largest).
Team tables have their own bound: ``scripts/update_team_bounds.py``. The shipped tables hold
real maps (``map:NAME``): point ``SEMEXPLORE_MAPS_DIR`` at a folder that has them, or fetch
them first (``semexplore maps get NAME``); a map not found stops the run with one line.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.evaluation.table_refresh import (
    BEST_KNOWN,
    add_refresh_arguments,
    run_into_cache,
    table_kind,
)

#: One start: (world spelling, seed, random start).
Start = tuple[str, int, bool]
CACHE_COLUMNS = ("world", "seed", "random_start", "lower_bound_s", "lower_bound_m", "seconds")


def start_bound(task: tuple[Start, int | None]) -> tuple[Start, float, float, float]:
    """``(start, lower_bound_s, lower_bound_m, seconds)`` of one start (a worker's task: the
    start and the bound's threads, None for one per CPU)."""
    from semexplore_gym.cli.oracle import certified_bound
    from semexplore_gym.evaluation.tasks import resolve_world

    start, threads = task
    world, seed, random_start = start
    t0 = time.perf_counter()
    overrides = [f"episode.random_start={'true' if random_start else 'false'}"]
    world = resolve_world(world, seed)
    bound = certified_bound(world, seed, env_overrides=overrides, threads=threads)
    return start, bound.time_s, bound.distance_m, time.perf_counter() - t0


class Table:
    """One table's rows as ``(start, T99_s, drive_m, bound_s, bound_m)`` and how to write it."""

    def __init__(self, path: Path) -> None:
        from semexplore_gym.evaluation.best_known import read_table
        from semexplore_gym.evaluation.bound_check import read_missions

        self.path = path
        self.kind = table_kind(path)
        if self.kind == BEST_KNOWN:
            self.digits = 3
            self.entries: Any = read_table(path)
            self.rows = [
                ((w, s, st == "random"), e["T99_s"], e["D99_m"], e["lower_bound_s"], e["lower_bound_m"])
                for (w, s, st), e in self.entries.items()
            ]  # fmt: skip
        else:
            self.digits = 4
            self.entries = read_missions(path)
            self.rows = [
                (m["start"], m["T99_s"], m["drive_m"], m["bound_s"], m["bound_m"])
                for m in self.entries
            ]

    def write(self, bounds: dict[Start, tuple[float, float]]) -> None:
        """Write the table with ``bounds`` in its bound columns (rounded to its digits)."""
        from semexplore_gym.evaluation.best_known import write_table
        from semexplore_gym.evaluation.bound_check import write_missions

        def cell(x: float) -> float:
            return round(x, self.digits) if math.isfinite(x) else math.inf

        if self.kind == BEST_KNOWN:
            for (w, s, st), e in self.entries.items():
                bound_s, bound_m = bounds[(w, s, st == "random")]
                e["lower_bound_s"], e["lower_bound_m"] = cell(bound_s), cell(bound_m)
            write_table(self.path, self.entries)
        else:
            for m in self.entries:
                m["bound_s"], m["bound_m"] = (cell(x) for x in bounds[m["start"]])
            write_missions(self.path, self.entries)


def read_cache(path: Path) -> dict[Start, tuple[float, float]]:
    """The bounds already in the cache CSV (none when it does not exist)."""
    if not path.is_file():
        return {}
    with path.open(newline="", encoding="utf-8") as fh:
        return {
            (r["world"], int(r["seed"]), r["random_start"] == "True"): (
                float(r["lower_bound_s"]),
                float(r["lower_bound_m"]),
            )
            for r in csv.DictReader(fh)
        }


def start_bound_row(task: tuple[Start, int | None]) -> list[str]:
    """A cache row (:data:`CACHE_COLUMNS`) of one start's bound (a worker's task)."""
    start, bound_s, bound_m, seconds = start_bound(task)
    return [start[0], str(start[1]), str(start[2]), repr(bound_s), repr(bound_m), f"{seconds:.1f}"]


def compute(todo: list[Start], cache: Path, workers: int, progress: bool) -> None:
    """Each start's bound appended to ``cache`` as it comes (largest worlds first)."""
    todo = sorted(todo, key=lambda s: (not s[0].startswith("map:"), s))
    threads = None if workers == 1 else 1  # one worker: its searches on every CPU
    tasks = [(start, threads) for start in todo]
    run_into_cache(
        start_bound_row, tasks, cache, CACHE_COLUMNS, workers, progress=progress, desc="bounds"
    )


def report(table: Table, bounds: dict[Start, tuple[float, float]]) -> tuple[list[str], int]:
    """Lines on ``table`` with ``bounds``, and how many of its rows violate them."""
    lines, violations, ratios, changed = [], 0, [], 0
    for start, t99_s, drive_m, _old_s, old_m in table.rows:
        new_s, new_m = bounds[start]
        if (t99_s is not None and t99_s < new_s) or (drive_m is not None and drive_m < new_m):
            violations += 1
            lines.append(
                f"  VIOLATION {start[0]} seed {start[1]}: T99 {t99_s} s, drive {drive_m} m "
                f"< bound {new_s:.3f} s, {new_m:.3f} m"
            )
        if old_m is None or round(new_m, table.digits) != old_m:
            changed += 1
        if old_m and math.isfinite(old_m) and math.isfinite(new_m):
            ratios.append(new_m / old_m)
    spread = (
        f"new / old {min(ratios):.3f}, median {np.median(ratios):.3f}, {max(ratios):.3f}"
        if ratios
        else "no old bounds"
    )
    n = len(table.rows)
    lines.insert(
        0,
        f"{table.path} ({table.kind}): {n} rows, {len({r[0] for r in table.rows})} starts, "
        f"{changed} changed, {spread}; {violations} violations",
    )
    return lines, violations


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("tables", nargs="+", type=Path, help="best-known or checked-missions CSVs")
    add_refresh_arguments(ap, "runs/recomputed_bounds.csv", "new bound")
    args = ap.parse_args(argv)
    if args.workers < 1:
        print(f"error: --workers must be at least 1, got {args.workers}", file=sys.stderr)
        return 2
    try:
        tables = [Table(p) for p in args.tables]
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.fresh:
        args.cache.unlink(missing_ok=True)
    starts = sorted({row[0] for t in tables for row in t.rows})
    done = read_cache(args.cache)
    todo = [s for s in starts if s not in done]
    print(f"{len(starts)} starts, {len(starts) - len(todo)} in {args.cache}, {len(todo)} to do")
    try:
        compute(todo, args.cache, args.workers, not args.no_progress)
    except (ValueError, FileNotFoundError) as e:  # a world the env refuses, a map not here
        print(f"error: {e}", file=sys.stderr)
        return 2
    bounds = read_cache(args.cache)
    total = 0
    for t in tables:
        lines, violations = report(t, bounds)
        total += violations
        print("\n".join(lines))
    if total:
        print(f"{total} rows below the new bound: no table written", file=sys.stderr)
        return 1
    if not args.dry_run:
        for t in tables:
            t.write(bounds)
            print(f"wrote {t.path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

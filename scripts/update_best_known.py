"""Merge benchmark run folders into the best-known table and compute its lower bounds.

    python scripts/update_best_known.py runs/paper runs/mazes --bounds
    python scripts/update_best_known.py runs/paper --table my_table.csv

Each run folder (``semexplore benchmark --out DIR``) whose missions used the default env config
is merged into the table (``--table``; default: the shipped
``configs/best_known/best_known.csv``): per (world, seed, start) the lowest T99 and the lowest
distance to 99 % any policy reached, with the policy spec that reached it. ``--bounds`` then
computes the certified lower bound (``semexplore_gym.core.coverage_tour.lower_bound``, privileged:
it reads the true world) for every entry that lacks one and that no merged folder's
``lower_bounds.csv`` (``scripts/check_lower_bound.py``) gives (an infinite bound is kept as ``inf``
and not computed again), writing the table after each entry, so
an interrupted run resumes where it stopped. Prints one line per run folder and a summary; with
``--json`` one JSON object instead.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

from semexplore_gym.evaluation.best_known import (
    merge_runs,
    read_table,
    run_start,
    shipped_table_path,
    write_table,
)


def entry_bound(world: str, seed: int, start: str) -> tuple[float | None, float | None]:
    """``(lower_bound_s, lower_bound_m)`` of one (world, seed, start), from the start pose that
    ``env.reset(seed=seed)`` draws with the benchmark's start setting (both ``inf`` when no
    explorer can reach the coverage goal at all: the table keeps that, so the bound is not
    computed again)."""
    from semexplore_gym.cli.oracle import certified_bound

    random_start = "true" if start == "random" else "false"
    bound = certified_bound(world, seed, env_overrides=[f"episode.random_start={random_start}"])
    if not math.isfinite(bound.distance_m):
        return math.inf, math.inf
    return round(bound.time_s, 3), round(bound.distance_m, 3)


def merge_folders(
    table: dict, folders: list[Path], log: Any, bounds_dir: Path | None = None
) -> tuple[dict, int]:
    """``table`` with every comparable run folder merged in; returns it and the new bests."""
    from semexplore_gym.evaluation.report import add_distance_to_99
    from semexplore_gym.evaluation.run_row import read_runs

    n_beats = 0
    for folder in folders:
        if not (folder / "runs.csv").is_file():
            raise ValueError(f"{folder}: no runs.csv (not a benchmark output folder)")
        start = run_start(folder)
        if start is None:
            print(f"{folder}: skipped (not the default env config)", file=log)
            continue
        rows = read_runs(folder / "runs.csv")
        add_distance_to_99(folder, rows)
        table, beats = merge_runs(table, rows, start)
        n_beats += len(beats)
        n_read = read_folder_bounds(table, folder, start, bounds_dir)
        print(
            f"{folder}: {len(rows)} missions, {len(beats)} new best known, "
            f"{n_read} bounds read from its lower_bounds.csv",
            file=log,
        )
    return table, n_beats


def read_folder_bounds(
    table: dict, folder: Path, start: str, bounds_dir: Path | None = None
) -> int:
    """Fill the missing bounds of ``table`` from ``folder/lower_bounds.csv``, or from the
    folder's CSV in ``bounds_dir`` (both written by ``scripts/check_lower_bound.py`` for the
    same starts, the latter with ``--bounds-dir``); returns how many it filled."""
    import csv

    path = folder / "lower_bounds.csv"
    if bounds_dir is not None:
        path = bounds_dir / ("_".join(folder.resolve().parts[1:]) + ".csv")
    if not path.is_file():
        return 0
    n = 0
    with path.open(newline="") as fh:
        for row in csv.DictReader(fh):
            entry = table.get((row["world"], int(row["seed"]), start))
            if entry is None or entry.get("lower_bound_s") is not None:
                continue
            bound_s, bound_m = float(row["lower_bound_s"]), float(row["lower_bound_m"])
            finite = math.isfinite(bound_s) and math.isfinite(bound_m)
            entry["lower_bound_s"] = round(bound_s, 3) if finite else math.inf
            entry["lower_bound_m"] = round(bound_m, 3) if finite else math.inf
            n += 1
    return n


def add_bounds(table: dict, path: Path, progress: bool) -> int:
    """Compute the missing lower bounds, writing the table after each one; returns how many."""
    from tqdm import tqdm

    todo = [k for k, e in sorted(table.items()) if e.get("lower_bound_s") is None]
    for key in tqdm(todo, desc="lower bounds", unit="start", disable=not progress, file=sys.stderr):
        world, seed, start = key
        table[key]["lower_bound_s"], table[key]["lower_bound_m"] = entry_bound(world, seed, start)
        write_table(path, table)
    return len(todo)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="*", type=Path, help="benchmark output folders to merge")
    ap.add_argument("--table", type=Path, default=None, help="table to update (default: shipped)")
    ap.add_argument("--bounds", action="store_true", help="compute missing lower bounds")
    ap.add_argument(
        "--bounds-dir",
        type=Path,
        default=None,
        help="read the folders' checked bounds from here (check_lower_bound.py --bounds-dir)",
    )
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    ap.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    args = ap.parse_args(argv)
    path = args.table if args.table is not None else shipped_table_path()
    log = sys.stderr if args.json else sys.stdout
    t0 = time.perf_counter()
    try:
        table = read_table(path)
        table, n_beats = merge_folders(table, args.runs, log, args.bounds_dir)
        write_table(path, table)
        n_bounds = add_bounds(table, path, not args.no_progress) if args.bounds else 0
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    out = {
        "table": str(path),
        "entries": len(table),
        "new_best_known": n_beats,
        "bounds_computed": n_bounds,
        "without_bound": sum(1 for e in table.values() if e.get("lower_bound_s") is None),
        "seconds": round(time.perf_counter() - t0, 1),
    }
    if args.json:
        print(json.dumps(out))
    else:
        print(
            f"{out['table']}: {out['entries']} entries, {n_beats} new best known, "
            f"{n_bounds} bounds computed, {out['without_bound']} without a bound"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

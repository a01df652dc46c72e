"""Run today's oracle again on every start of the shipped tables that hold its missions, and
write its numbers into them.

    SEMEXPLORE_MAPS_DIR=../shared/maps python scripts/rerun_oracle.py \\
        docs/results/oracle/missions.csv docs/results/oracle/runs.csv \\
        configs/best_known/best_known.csv --workers 2 --old-spec 'oracle[drive_planned_legs=false]'
    python scripts/rerun_oracle.py my_missions.csv --dry-run   # report, write nothing

After a change to the oracle (``policies/oracle.py``, its tour), the tables that ship its
missions go stale: the checked missions (``scripts/check_lower_bound.py --missions-out``), the
oracle-against-the-expert runs (a benchmark's ``runs.csv``, trimmed) and the best-known table.
This runs the oracle once per (world, seed, start) of their oracle rows (every start of a
best-known table), from the start ``env.reset(seed=seed)`` draws with the default env config
(``seed=*`` worlds take the row's seed; a runs table's rows take their start from another
table given), in ``--workers`` processes, each mission as it comes into ``--cache`` (rerunning
resumes; ``--fresh`` starts over, as after another change). It then checks today's missions
against the bounds the tables hold (one below: nothing is written, exit 1), and writes: the
oracle rows' T99 and drive to 99 % (checked missions), their coverage, times and path (runs),
and in the best-known table today's oracle wherever it is no slower than the entry; where the
entry was the oracle's and today's is slower, the old time stays under ``--old-spec``, the spec
that runs the old oracle today (required then). Prints per table the rows changed and today's
T99 over the old (faster, slower, median, extremes).
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.evaluation.table_refresh import (
    BEST_KNOWN,
    CHECKED_MISSIONS,
    RUNS,
    add_refresh_arguments,
    run_into_cache,
    table_kind,
)

#: One start: (world spelling, seed, random start).
Start = tuple[str, int, bool]
CACHE_COLUMNS = (
    "world",
    "seed",
    "random_start",
    "T90_s",
    "T99_s",
    "drive_to_99_m",
    "mission_time_s",
    "coverage",
    "path_length_m",
    "self_stopped",
    "collisions",
    "seconds",
)
RUNS_COLUMNS = ("world", "policy", "seed", "coverage", "mission_time_s", "T99_s")
ORACLE = "oracle"


def oracle_mission(task: tuple[Start, float]) -> dict[str, Any]:
    """One mission of today's oracle from ``start`` (a worker's task: the start and the
    mission's time limit), as a cache row."""
    import gymnasium as gym
    from semexplore_gym.policies.oracle import OraclePolicy

    import semexplore_gym  # noqa: F401  (registers the env)
    from semexplore_gym.evaluation.rollout import run_mission
    from semexplore_gym.evaluation.tasks import resolve_world

    (world, seed, random_start), limit_s = task
    t0 = time.perf_counter()
    overrides = [
        f"episode.random_start={'true' if random_start else 'false'}",
        f"episode.max_time_s={limit_s}",
    ]
    env = gym.make(
        "SemanticExplore-v0", world=resolve_world(world, seed), overrides=overrides, privileged=True
    )
    try:
        res = run_mission(env, OraclePolicy(), seed=seed)
    finally:
        env.close()
    cov = np.array([c for _, c, _ in res.coverage_trace])
    hit = np.flatnonzero(cov >= 0.99 - 1e-12)
    drive = None
    if hit.size and res.trajectory.shape[0] == cov.size:
        steps = np.diff(res.trajectory[: hit[0] + 1, :2], axis=0)
        drive = float(np.hypot(steps[:, 0], steps[:, 1]).sum())
    return {
        "world": world,
        "seed": seed,
        "random_start": random_start,
        "T90_s": res.t90_s,
        "T99_s": res.t99_s,
        "drive_to_99_m": drive,
        "mission_time_s": res.mission_time_s,
        "coverage": res.coverage,
        "path_length_m": res.path_length_m,
        "self_stopped": res.self_stopped,
        "collisions": res.collisions,
        "seconds": round(time.perf_counter() - t0, 1),
    }


def _num(text: Any) -> float | None:
    return None if text in (None, "", "None", "nan", "inf") else float(text)


def _cell(x: float | None, digits: int) -> str:
    return "" if x is None else repr(round(float(x), digits))


def read_cache(path: Path) -> dict[Start, dict[str, Any]]:
    """The missions already in the cache CSV (none when it does not exist)."""
    if not path.is_file():
        return {}
    with path.open(newline="", encoding="utf-8") as fh:
        return {
            (r["world"], int(r["seed"]), r["random_start"] == "True"): r for r in csv.DictReader(fh)
        }


class Table:
    """A table's oracle starts and how to write today's missions into it."""

    def __init__(self, path: Path) -> None:
        from semexplore_gym.evaluation.best_known import read_table
        from semexplore_gym.evaluation.bound_check import read_missions

        self.path = path
        self.kind = table_kind(path, RUNS_COLUMNS)
        self.starts: dict[tuple[str, int], bool] = {}  # (world, seed) -> random start
        if self.kind == BEST_KNOWN:
            self.entries: Any = read_table(path)
            self.starts = {(w, s): st == "random" for (w, s, st) in self.entries}
        elif self.kind == CHECKED_MISSIONS:
            self.entries = read_missions(path)
            for m in self.entries:
                if m["policy"] == ORACLE:
                    w, s, random_start = m["start"]
                    self.starts[(w, s)] = random_start
        else:
            text = path.read_bytes().decode("utf-8")
            self.newline = "\r\n" if "\r\n" in text else "\n"
            self.entries = list(csv.DictReader(io.StringIO(text, newline="")))
            self.header = list(self.entries[0]) if self.entries else list(RUNS_COLUMNS)

    def oracle_keys(self) -> list[tuple[str, int]]:
        """(world, seed) of the rows today's oracle is run for."""
        if self.kind == RUNS:
            return [(r["world"], int(r["seed"])) for r in self.entries if r["policy"] == ORACLE]
        return list(self.starts)

    def update(
        self, starts: dict[tuple[str, int], bool], runs: dict[Start, dict[str, Any]], old_spec: str
    ) -> tuple[list[str], list[tuple[float, float]], int]:
        """Today's missions written into the rows (not to disk); returns lines on the rows
        below their bound, the (today's, old) T99 pairs and how many rows changed."""
        below: list[str] = []
        pairs: list[tuple[float, float]] = []
        changed = 0

        def today(key: tuple[str, int]) -> dict[str, Any]:
            return runs[(key[0], key[1], starts[key])]

        def check(where: str, t99: float | None, drive: float | None, bound_s, bound_m) -> None:
            if (t99 is not None and bound_s is not None and t99 < bound_s) or (
                drive is not None and bound_m is not None and drive < bound_m
            ):
                below.append(f"  BELOW THE BOUND {where}: T99 {t99} s, drive {drive} m")

        if self.kind == CHECKED_MISSIONS:
            for m in self.entries:
                if m["policy"] != ORACLE:
                    continue
                r = runs[m["start"]]
                t99, drive = _num(r["T99_s"]), _num(r["drive_to_99_m"])
                t99 = None if t99 is None else round(t99, 1)
                drive = None if drive is None else round(drive, 2)
                check(
                    f"{m['start'][0]} seed {m['start'][1]}", t99, drive, m["bound_s"], m["bound_m"]
                )
                if m["T99_s"] is not None and t99 is not None:
                    pairs.append((t99, m["T99_s"]))
                changed += (t99, drive) != (m["T99_s"], m["drive_m"])
                m["T99_s"], m["drive_m"] = t99, drive
        elif self.kind == RUNS:
            for row in self.entries:
                if row["policy"] != ORACLE:
                    continue
                r = today((row["world"], int(row["seed"])))
                new = {
                    "coverage": _cell(_num(r["coverage"]), 4),
                    "mission_time_s": _cell(_num(r["mission_time_s"]), 1),
                    "T99_s": _cell(_num(r["T99_s"]), 1),
                }
                for col, digits in (("path_length_m", 2), ("T90_s", 1)):
                    if col in row:
                        new[col] = _cell(_num(r[col]), digits)
                if "self_stopped" in row:
                    new["self_stopped"] = str(r["self_stopped"])
                old_t99, new_t99 = _num(row["T99_s"]), _num(new["T99_s"])
                if old_t99 is not None and new_t99 is not None:
                    pairs.append((new_t99, old_t99))
                changed += any(row[k] != v for k, v in new.items())
                row.update(new)
        else:
            for key, e in self.entries.items():
                r = today(key[:2])
                for col, pol, run_col in (("T99_s", "T99_policy", "T99_s"), ("D99_m", "D99_policy", "drive_to_99_m")):  # fmt: skip
                    new = _num(r[run_col])
                    new = None if new is None else round(new, 3)
                    old = e[col]
                    if col == "T99_s" and new is not None and old is not None and e[pol] == ORACLE:
                        pairs.append((new, old))
                    if new is not None and (old is None or new <= old):
                        changed += (new, ORACLE) != (old, e[pol])
                        e[col], e[pol] = new, ORACLE
                    elif e[pol] == ORACLE:
                        if not old_spec:
                            raise ValueError(
                                f"{self.path}: today's oracle is slower than the entry of "
                                f"{key[0]} seed {key[1]} ({col} {new} > {old}), which was the "
                                "oracle's: name the spec that runs the old oracle with --old-spec"
                            )
                        e[pol] = old_spec
                        changed += 1
                check(f"{key[0]} seed {key[1]}", e["T99_s"], e["D99_m"],
                      e["lower_bound_s"], e["lower_bound_m"])  # fmt: skip
        return below, pairs, changed

    def write(self) -> None:
        from semexplore_gym.evaluation.best_known import write_table
        from semexplore_gym.evaluation.bound_check import write_missions

        if self.kind == BEST_KNOWN:
            write_table(self.path, self.entries)
        elif self.kind == CHECKED_MISSIONS:
            write_missions(self.path, self.entries)
        else:
            buf = io.StringIO(newline="")
            w = csv.DictWriter(buf, self.header, lineterminator=self.newline)
            w.writeheader()
            w.writerows(self.entries)
            self.path.write_bytes(buf.getvalue().encode("utf-8"))


def starts_of(tables: list[Table]) -> dict[tuple[str, int], bool]:
    """(world, seed) -> random start, over every table that records starts; every oracle row
    of a runs table must find its start there."""
    starts: dict[tuple[str, int], bool] = {}
    for t in tables:
        starts.update(t.starts)
    for t in tables:
        for key in t.oracle_keys():
            if key not in starts:
                raise ValueError(
                    f"{t.path}: the start of {key[0]} seed {key[1]} is not known: give a "
                    "checked-missions or best-known table that holds it"
                )
    return starts


def oracle_mission_row(task: tuple[Start, float]) -> list[Any]:
    """A cache row (:data:`CACHE_COLUMNS`) of one start's mission (a worker's task)."""
    row = oracle_mission(task)
    return [row[c] for c in CACHE_COLUMNS]


def run_all(todo: list[Start], cache: Path, workers: int, limit_s: float, progress: bool) -> None:
    """Each start's mission appended to ``cache`` as it comes (real maps first)."""
    todo = sorted(todo, key=lambda s: (not s[0].startswith("map:"), s))
    tasks = [(s, limit_s) for s in todo]
    run_into_cache(
        oracle_mission_row,
        tasks,
        cache,
        CACHE_COLUMNS,
        workers,
        progress=progress,
        desc="oracle",
        unit="mission",
    )


def summary(table: Table, pairs: list[tuple[float, float]], changed: int) -> str:
    ratios = np.array([a / b for a, b in pairs if b > 0])
    spread = "no old T99"
    if ratios.size:
        spread = (
            f"today's T99 / old: faster {int((ratios < 1).sum())}, slower "
            f"{int((ratios > 1).sum())}, median {np.median(ratios):.3f}, "
            f"{ratios.min():.3f}-{ratios.max():.3f}"
        )
    return f"{table.path} ({table.kind}): {changed} rows changed; {spread}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "tables", nargs="+", type=Path, help="checked-missions, runs or best-known CSVs"
    )
    add_refresh_arguments(ap, "runs/oracle_rerun.csv", "mission")
    ap.add_argument(
        "--old-spec",
        default="",
        help="the spec that runs the old oracle today, kept in the best-known table where it "
        "was faster (e.g. 'oracle[drive_planned_legs=false]')",
    )
    ap.add_argument(
        "--max-time-s",
        type=float,
        default=20000.0,
        help="stop a mission after this simulated time (default 20000; the oracle stops "
        "itself at the coverage goal)",
    )
    args = ap.parse_args(argv)
    if args.workers < 1:
        print(f"error: --workers must be at least 1, got {args.workers}", file=sys.stderr)
        return 2
    if not (math.isfinite(args.max_time_s) and args.max_time_s > 0):
        print(f"error: --max-time-s must be > 0, got {args.max_time_s}", file=sys.stderr)
        return 2
    try:
        tables = [Table(p) for p in args.tables]
        starts = starts_of(tables)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.fresh:
        args.cache.unlink(missing_ok=True)
    wanted = sorted({(w, s, starts[(w, s)]) for t in tables for (w, s) in t.oracle_keys()})
    done = read_cache(args.cache)
    todo = [s for s in wanted if s not in done]
    print(f"{len(wanted)} starts, {len(wanted) - len(todo)} in {args.cache}, {len(todo)} to do")
    try:
        run_all(todo, args.cache, args.workers, args.max_time_s, not args.no_progress)
    except (ValueError, FileNotFoundError) as e:  # a world the env refuses, a map not here
        print(f"error: {e}", file=sys.stderr)
        return 2
    runs = read_cache(args.cache)
    below_all = 0
    try:
        for t in tables:
            below, pairs, changed = t.update(starts, runs, args.old_spec)
            below_all += len(below)
            print("\n".join([summary(t, pairs, changed), *below]))
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if below_all:
        print(f"{below_all} rows below their bound: no table written", file=sys.stderr)
        return 1
    if not args.dry_run:
        for t in tables:
            t.write()
            print(f"wrote {t.path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

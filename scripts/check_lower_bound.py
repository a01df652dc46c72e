"""Check the certified lower bound against every mission of benchmark output folders.

For each (world, start seed) of each ``RUN_DIR/runs.csv`` it computes the bound from the same
start the benchmark used (``benchmark.json``: random or fixed start, env config), writes one row
per pair to a CSV in that folder as it goes (rerunning resumes), then reports how many missions
reached 99 % coverage sooner than the bound's time, or after a shorter drive than its distance
(the drive to 99 % read from the mission's trace and trajectory when the folder has them;
``seed=*`` worlds take the mission's seed), which must be none; per world family the starts,
the missions, the median best known ÷ bound (the best T99 any policy of any folder reached from
that start), the oracle's median T99 ÷ bound and the share of paired missions where the
oracle's T99 is at most each other policy's; and the median T99 / bound per policy and family.
A mission that repeats an earlier folder's (same world, start and policy: the same
deterministic mission) counts once.

    python scripts/check_lower_bound.py runs/paper
    python scripts/check_lower_bound.py runs/paper runs/mazes runs/offices --json
    python scripts/check_lower_bound.py runs/paper --fresh   # after a change to the bound
    python scripts/check_lower_bound.py ../theirs/runs/x --bounds-dir runs/bounds   # read-only
    python scripts/check_lower_bound.py runs/paper --out runs/paper/lower_bounds.csv
    python scripts/check_lower_bound.py runs/a runs/b --missions-out checked.csv
    semexplore report checked.csv   # the same tables again, from the checked missions

The per-family figures are :mod:`semexplore_gym.evaluation.bound_check`'s.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path

import numpy as np

from semexplore_gym.evaluation.bound_check import (
    family_report,
    report_lines,
    unique_missions,
    write_missions,
)

BOUND_COLUMNS = ("world", "seed", "lower_bound_m", "lower_bound_s", "groups", "bound_planning_s")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dirs", nargs="+", type=Path, help="'semexplore benchmark' output folders")
    ap.add_argument(
        "--out",
        type=Path,
        default=None,
        help="bound CSV of a single folder (default: RUN_DIR/lower_bounds.csv)",
    )
    ap.add_argument(
        "--bounds-dir",
        type=Path,
        default=None,
        help="keep each folder's bound CSV here (named after the folder's path) instead of in "
        "the folder: for folders that are not yours to write in",
    )
    ap.add_argument(
        "--missions-out",
        type=Path,
        default=None,
        help="write every checked mission (its T99, drive to 99 %% and its start's bound) to "
        "this CSV, which 'semexplore report FILE' reads",
    )
    ap.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    ap.add_argument("--json", action="store_true", help="print the per-family report as JSON")
    ap.add_argument(
        "--fresh",
        action="store_true",
        help="recompute every bound (after a change to the bound) instead of reading the CSVs",
    )
    args = ap.parse_args(argv)
    if args.out is not None and len(args.run_dirs) > 1:
        print("error: --out needs exactly one RUN_DIR", file=sys.stderr)
        return 2
    missions: list[dict] = []
    for run_dir in args.run_dirs:
        runs_csv = run_dir / "runs.csv"
        if not runs_csv.is_file():
            print(f"error: no runs.csv in {run_dir}", file=sys.stderr)
            return 2
        with runs_csv.open(newline="") as fh:
            runs = list(csv.DictReader(fh))
        settings = _benchmark_settings(run_dir)
        out = args.out or run_dir / "lower_bounds.csv"
        if args.bounds_dir is not None:
            args.bounds_dir.mkdir(parents=True, exist_ok=True)
            name = "_".join(run_dir.resolve().parts[1:]) or "root"
            out = args.bounds_dir / f"{name}.csv"
        if args.fresh:
            out.unlink(missing_ok=True)
        bounds = compute_bounds(runs, settings, out, not args.no_progress)
        missions += checked_missions(runs, bounds, run_dir, settings)
    missions, repeats = unique_missions(missions)
    if repeats:
        print(
            f"{repeats} missions repeat a (world, start, policy) of an earlier folder: counted once",
            file=sys.stderr,
        )
    if args.missions_out is not None:
        write_missions(args.missions_out, missions)
    if args.json:
        print(json.dumps(family_report(missions), indent=1))
    else:
        print("\n".join(report_lines(missions)))
    return 0


def _benchmark_settings(run_dir: Path) -> tuple[object, dict[str, bool], bool]:
    """The env config the benchmark made its starts with, the suites' random-start setting of
    each of their worlds, and whether every start was the world's own (``--fixed-start``)."""
    from semexplore_gym.evaluation.splits import PARTS, split_suite
    from semexplore_gym.evaluation.suites import load_suite

    meta_path = run_dir / "benchmark.json"
    meta = json.loads(meta_path.read_text()) if meta_path.is_file() else {}
    config = meta.get("config")
    env_config = config if isinstance(config, str) else None
    random_start: dict[str, bool] = {}
    for entry in meta.get("suites") or []:
        source = str(entry["source"])
        # A split's part (`--split caves:test`) is recorded as its YAML path and ":test".
        is_split = source.rpartition(":")[2] in PARTS and source.rpartition(":")[0]
        suite = split_suite(source) if is_split else load_suite(source)
        for w in suite.worlds:
            random_start[w.world] = suite.random_start
    return env_config, random_start, bool(meta.get("fixed_start", False))


def compute_bounds(
    runs: list[dict[str, str]],
    settings: tuple[object, dict[str, bool], bool],
    out: Path,
    progress: bool,
) -> dict[tuple[str, int], dict[str, str]]:
    """The bound of each (world, seed) of ``runs``, read from ``out`` or computed and appended."""
    from semexplore_gym.cli.oracle import certified_bound
    from semexplore_gym.evaluation.tasks import resolve_world

    done: dict[tuple[str, int], dict[str, str]] = {}
    if out.is_file():
        with out.open(newline="") as fh:
            for row in csv.DictReader(fh):
                done[(row["world"], int(row["seed"]))] = row
    todo = sorted({(r["world"], int(r["seed"])) for r in runs} - set(done))
    new_file = not out.is_file()
    with out.open("a", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=BOUND_COLUMNS)
        if new_file:
            writer.writeheader()
        for i, (world, seed) in enumerate(todo):
            if progress:
                print(f"\r[{i + 1}/{len(todo)}] {world} seed {seed}   ", end="", file=sys.stderr)
            env_config, suite_random, fixed = settings
            random_start = suite_random.get(world, True) and not fixed
            start = [f"episode.random_start={'true' if random_start else 'false'}"]
            b = certified_bound(resolve_world(world, seed), seed, env_config, start)
            row = {
                "world": world,
                "seed": str(seed),
                "lower_bound_m": repr(b.distance_m),
                "lower_bound_s": repr(b.time_s),
                "groups": str(b.n_groups),
                "bound_planning_s": f"{b.planning_s:.2f}",
            }
            writer.writerow(row)
            fh.flush()
            done[(world, seed)] = row
    if progress and todo:
        print(file=sys.stderr)
    return done


def drive_to_99_m(run_dir: Path, world: str, policy: str, seed: int) -> float | None:
    """Path length up to the first trace row at coverage >= 0.99 (None without the files)."""
    from semexplore_gym.evaluation.run_writer import task_stem

    stem = task_stem(world, policy, seed)
    trace, traj = run_dir / "traces" / f"{stem}.csv", run_dir / "trajectories" / f"{stem}.npy"
    if not (trace.is_file() and traj.is_file()):
        return None
    cov = np.loadtxt(trace, delimiter=",", skiprows=1, usecols=1, ndmin=1)
    hit = np.flatnonzero(cov >= 0.99 - 1e-12)
    poses = np.load(traj)
    if hit.size == 0 or poses.shape[0] != cov.size:
        return None
    steps = np.diff(poses[: hit[0] + 1, :2], axis=0)
    return float(np.hypot(steps[:, 0], steps[:, 1]).sum())


def checked_missions(
    runs: list[dict[str, str]],
    bounds: dict[tuple[str, int], dict[str, str]],
    run_dir: Path,
    settings: tuple[object, dict[str, bool], bool],
) -> list[dict]:
    """One record per mission: its start key, T99, drive to 99 % and the bound of its start."""
    from semexplore_gym.evaluation.suites import world_family

    _, suite_random, fixed = settings
    out = []
    for r in runs:
        seed = int(r["seed"])
        b = bounds[(r["world"], seed)]
        random_start = suite_random.get(r["world"], True) and not fixed
        t99 = float(r["T99_s"]) if r.get("T99_s") not in (None, "", "None") else None
        out.append(
            {
                "folder": str(run_dir),
                "start": (r["world"], seed, random_start),
                "family": world_family(r["world"]),
                "policy": r["policy"],
                "T99_s": t99,
                "drive_m": drive_to_99_m(run_dir, r["world"], r["policy"], seed),
                "bound_s": float(b["lower_bound_s"]),
                "bound_m": float(b["lower_bound_m"]),
            }
        )
    return out


if __name__ == "__main__":
    sys.exit(main())

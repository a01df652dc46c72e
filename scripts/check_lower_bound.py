"""Check the certified lower bound against every mission of a benchmark output folder.

For each (world, start seed) of ``RUN_DIR/runs.csv`` it computes the bound from the same start
the benchmark used (``benchmark.json``: random or fixed start, env config), writes one row per
pair to a CSV as it goes (rerunning resumes), then reports how many missions reached 99 %
coverage sooner than the bound's time, or after a shorter drive than its distance (the drive
to 99 % read from the mission's trace and trajectory when the folder has them; ``seed=*``
worlds take the mission's seed), which must be
none, and the median T99 / bound per policy and world family.

    python scripts/check_lower_bound.py runs/paper
    python scripts/check_lower_bound.py runs/paper --out runs/paper/lower_bounds.csv
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

BOUND_COLUMNS = ("world", "seed", "lower_bound_m", "lower_bound_s", "groups", "bound_planning_s")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dir", type=Path, help="a 'semexplore benchmark' output folder")
    ap.add_argument(
        "--out", type=Path, default=None, help="bound CSV (default: RUN_DIR/lower_bounds.csv)"
    )
    ap.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    args = ap.parse_args(argv)
    runs_csv = args.run_dir / "runs.csv"
    if not runs_csv.is_file():
        print(f"error: no runs.csv in {args.run_dir}", file=sys.stderr)
        return 2
    with runs_csv.open(newline="") as fh:
        runs = list(csv.DictReader(fh))
    out = args.out or args.run_dir / "lower_bounds.csv"
    bounds = compute_bounds(runs, _benchmark_settings(args.run_dir), out, not args.no_progress)
    print(report(runs, bounds, args.run_dir))
    return 0


def _benchmark_settings(run_dir: Path) -> tuple[object, dict[str, bool], bool]:
    """The env config the benchmark made its starts with, the suites' random-start setting of
    each of their worlds, and whether every start was the world's own (``--fixed-start``)."""
    from semexplore_gym.evaluation.suites import load_suite

    meta_path = run_dir / "benchmark.json"
    meta = json.loads(meta_path.read_text()) if meta_path.is_file() else {}
    config = meta.get("config")
    env_config = config if isinstance(config, str) else None
    random_start: dict[str, bool] = {}
    for entry in meta.get("suites") or []:
        suite = load_suite(entry["source"])
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


def report(
    runs: list[dict[str, str]], bounds: dict[tuple[str, int], dict[str, str]], run_dir: Path
) -> str:
    """Violations (must be none) and median T99 / bound per policy and family."""
    from semexplore_gym.evaluation.suites import world_family

    ratios: dict[tuple[str, str], list[float]] = defaultdict(list)
    n_t99 = n_drive = bad_t = bad_d = 0
    for r in runs:
        seed = int(r["seed"])
        b = bounds[(r["world"], seed)]
        bound_s, bound_m = float(b["lower_bound_s"]), float(b["lower_bound_m"])
        if r["T99_s"] not in ("", "None"):
            t99 = float(r["T99_s"])
            n_t99 += 1
            bad_t += t99 < bound_s
            if bound_s > 0:
                ratios[(r["policy"], world_family(r["world"]))].append(t99 / bound_s)
        drive = drive_to_99_m(run_dir, r["world"], r["policy"], seed)
        if drive is not None:
            n_drive += 1
            bad_d += drive < bound_m
    lines = [
        f"missions: {len(runs)}; with T99: {n_t99}, T99 below the bound: {bad_t}",
        f"with a drive to 99 % on file: {n_drive}, drive below the bound: {bad_d}",
        "| policy | family | n | median T99 / bound | min |",
        "|---|---|---|---|---|",
    ]
    for (policy, fam), xs in sorted(ratios.items()):
        lines.append(
            f"| {policy} | {fam} | {len(xs)} | {float(np.median(xs)):.2f} | {min(xs):.2f} |"
        )
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())

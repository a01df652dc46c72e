"""Is the first benchmark row timed like the next ones, straight after installing?

``semexplore benchmark`` warms the numba kernels up before any mission clock starts (the
deterministic part, no compile inside a mission, is a unit test:
``tests/evaluation/test_warmup_first_row.py``). This script measures the consequence: each
round runs the same benchmark (one world, fixed start, ``--runs`` identical missions per
policy) in a fresh process with an empty ``NUMBA_CACHE_DIR``, as after ``pip install``, and
compares each policy's per-call times of the first row with the median of the later rows.
A ratio near 1 means the first row is honest; the median over rounds is what to quote (the
machine's load moves single rows by up to 2x).

    python scripts/bench_first_row.py --rounds 3
"""

from __future__ import annotations

import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
KEYS = ("mean_map_generation_ms", "mean_global_planning_ms")


def one_round(world: str, policies: str, runs: int, max_time_s: float) -> dict[str, float]:
    """First-row time / median of the later rows, per ``policy:key`` (stages a policy has)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench"
        env = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / "cache")}
        argv = [sys.executable, "-m", "semexplore_gym.cli", "benchmark", "--worlds", world]
        argv += ["--policies", policies, "--runs", str(runs), "--fixed-start"]
        argv += ["--max-time-s", str(max_time_s), "--no-plots", "--no-progress", "--out", str(out)]
        subprocess.run(argv, check=True, env=env, cwd=REPO, capture_output=True)
        rows = list(csv.DictReader((out / "runs.csv").open()))
    ratios: dict[str, float] = {}
    for policy in policies.split(","):
        mine = sorted((r for r in rows if r["policy"] == policy), key=lambda r: int(r["seed"]))
        for key in KEYS:
            first, *later = (float(r[key]) for r in mine)
            if later and statistics.median(later) > 0:
                ratios[f"{policy}:{key}"] = first / statistics.median(later)
    return ratios


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--world", default="maze1")
    ap.add_argument("--policies", default="semantic,frontier")
    ap.add_argument("--runs", type=int, default=3, help="identical missions per policy (>= 2)")
    ap.add_argument("--max-time-s", type=float, default=40.0)
    ap.add_argument("--rounds", type=int, default=3, help="fresh-cache rounds (>= 1)")
    args = ap.parse_args(argv)
    if args.runs < 2 or args.rounds < 1:
        ap.error(f"--runs must be >= 2 and --rounds >= 1, got {args.runs} and {args.rounds}")
    per_key: dict[str, list[float]] = {}
    for k in range(args.rounds):
        for key, ratio in one_round(args.world, args.policies, args.runs, args.max_time_s).items():
            per_key.setdefault(key, []).append(ratio)
        print(f"round {k + 1}/{args.rounds} done", file=sys.stderr)
    print("first row / median of later rows (median over rounds, [min, max]):")
    for key, values in per_key.items():
        print(f"  {key:45s} {statistics.median(values):.2f} [{min(values):.2f}, {max(values):.2f}]")


if __name__ == "__main__":
    main()

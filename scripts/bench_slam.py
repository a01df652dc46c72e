"""What does the SLAM mode cost in wall time? The expert's mission on the perfect map and on the
SLAM map, alternated, per world.

For each world and round the same mission (world, start seed) runs once with
``--env-config default`` and once with ``--env-config slam``, in this process, in alternating
order (perfect first in even rounds, SLAM first in odd ones), after one warm-up mission of each
(numba kernels load from their cache, gtsam imports). Each mission's wall time covers the
env's reset and every step, as the benchmark's ``wall_time_s`` does. Printed per world: the
median wall time of each mode and the median of the paired ratios; at the end the median ratio
over all worlds' rounds, with the load average (the machine is shared: quote the ratios, which
alternation keeps fair, more than the seconds).

A benchmark check as well: the SLAM issue (#54) keeps the SLAM mission's wall time at most 3x
the perfect map's, so the script exits with status 1, and a line saying so, when the median
ratio over all pairs is above ``--max-ratio`` (3.0).

    python scripts/bench_slam.py --worlds 'maze1;maze2' --rounds 3
    python scripts/bench_slam.py --worlds 'office:seed=300,size_m=12' --rounds 3 --json
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys


def one_mission(world: str, env_config: str, seed: int) -> float:
    """Wall seconds of one expert mission (its ``wall_time_s``: reset and every step)."""
    from semexplore_gym.policies.registry import make_policy

    from semexplore_gym.evaluation.rollout import (
        make_mission_env,
        map_observation_for,
        run_mission,
    )

    policy = make_policy("semantic")
    env = make_mission_env(world, env_config, **map_observation_for(policy))
    try:
        return float(run_mission(env, policy, seed).wall_time_s)
    finally:
        env.close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--worlds",
        default="maze1;maze2",
        help="world specs separated by ';' (a spec may hold commas: 'maze:seed=1,size_m=10')",
    )
    ap.add_argument("--seed", type=int, default=0, help="the missions' start seed")
    ap.add_argument("--rounds", type=int, default=3, help="alternated pairs per world (>= 1)")
    ap.add_argument("--json", action="store_true", help="print the results as JSON")
    ap.add_argument(
        "--max-ratio",
        type=float,
        default=3.0,
        help="exit 1 when the median SLAM / perfect wall-time ratio is above this (default 3.0)",
    )
    args = ap.parse_args(argv)
    if args.rounds < 1:
        ap.error(f"--rounds must be >= 1, got {args.rounds}")
    if not args.max_ratio > 0:
        ap.error(f"--max-ratio must be > 0, got {args.max_ratio}")
    worlds = [w.strip() for w in args.worlds.split(";") if w.strip()]
    if not worlds:
        ap.error(f"--worlds names no world: {args.worlds!r}")
    try:
        from semexplore_gym.core.slam.pose_graph import require_gtsam

        require_gtsam()
        one_mission(worlds[0], "default", args.seed)  # warm-up: kernels, imports
        one_mission(worlds[0], "slam", args.seed)
    except (ImportError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out: dict[str, dict[str, float]] = {}
    ratios_all: list[float] = []
    for world in worlds:
        perfect, slam = [], []
        for r in range(args.rounds):
            for mode in ("default", "slam") if r % 2 == 0 else ("slam", "default"):
                (perfect if mode == "default" else slam).append(one_mission(world, mode, args.seed))
        ratios = [s / p for s, p in zip(slam, perfect, strict=True)]
        ratios_all += ratios
        out[world] = {
            "perfect_wall_s": statistics.median(perfect),
            "slam_wall_s": statistics.median(slam),
            "ratio": statistics.median(ratios),
        }
        if not args.json:
            print(
                f"{world}: perfect {out[world]['perfect_wall_s']:.2f} s, "
                f"SLAM {out[world]['slam_wall_s']:.2f} s, SLAM / perfect "
                f"{out[world]['ratio']:.2f} (median of {args.rounds})",
                flush=True,
            )
    median = statistics.median(ratios_all)
    summary = {
        "median_ratio": median,
        "load_avg_1min": os.getloadavg()[0],
        "max_ratio": args.max_ratio,
        "within_max_ratio": median <= args.max_ratio,
    }
    if args.json:
        print(json.dumps({"worlds": out, **summary}, indent=2))
    else:
        print(
            f"all: SLAM / perfect wall time, median {median:.2f} over "
            f"{len(ratios_all)} pairs (load average {summary['load_avg_1min']:.2f})"
        )
    if median > args.max_ratio:
        print(
            f"check failed: the median SLAM / perfect wall-time ratio {median:.2f} is above "
            f"--max-ratio {args.max_ratio:g}",
            file=sys.stderr,
        )
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""How long does ``semexplore oracle WORLD --json`` take, tour and certified bound, end to end?

Each round runs the command in a fresh process (kernels already compiled and cached, as after
the first use) and records its wall time, its CPU time (user + system of the child), and the
tour's and the bound's own planning times from its JSON. The medians over rounds are what to
quote; the load average printed beside them says whether the machine was busy (on a shared
2-core machine the wall time follows the load, the CPU time much less).

    python scripts/bench_oracle.py --world 'office:seed=1,size_m=20' --rounds 3
    python scripts/bench_oracle.py --world maze1 --rounds 5 --json
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def one_round(world: str, seed: int) -> dict[str, float]:
    """Wall and CPU seconds of one ``semexplore oracle`` process, and its planning times."""
    argv = [sys.executable, "-m", "semexplore_gym.cli", "oracle", world, "--start-seed", str(seed)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    res = subprocess.run([*argv, "--json"], cwd=REPO, capture_output=True, text=True)
    wall_s = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode != 0:
        last = (res.stderr.strip().splitlines() or ["(no output)"])[-1]
        print(f"error: semexplore oracle {world} failed: {last}", file=sys.stderr)
        raise SystemExit(2)
    out = json.loads(res.stdout)
    return {
        "wall_s": wall_s,
        "cpu_s": (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime),
        "tour_planning_s": float(out["planning_s"]),
        "bound_planning_s": float(out.get("bound_planning_s") or "nan"),
        "load_avg_1min": os.getloadavg()[0],
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--world", default="office:seed=1,size_m=20", help="a world spec")
    ap.add_argument("--start-seed", type=int, default=0, help="the start's seed")
    ap.add_argument("--rounds", type=int, default=3, help="fresh processes (>= 1)")
    ap.add_argument("--json", action="store_true", help="print the medians as JSON")
    args = ap.parse_args(argv)
    if args.rounds < 1:
        ap.error(f"--rounds must be >= 1, got {args.rounds}")
    rounds = []
    for i in range(args.rounds):
        rounds.append(one_round(args.world, args.start_seed))
        print(
            f"round {i + 1}/{args.rounds}: "
            + ", ".join(f"{k} {v:.1f}" for k, v in rounds[-1].items()),
            file=sys.stderr,
        )
    medians = {k: round(statistics.median(r[k] for r in rounds), 2) for k in rounds[0]}
    if args.json:
        print(json.dumps({"world": args.world, "rounds": args.rounds, **medians}))
    else:
        print(
            f"{args.world}, median of {args.rounds}: "
            + ", ".join(f"{k} {v}" for k, v in medians.items())
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())

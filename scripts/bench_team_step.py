"""Time SemanticExploreMulti-v0's step for teams of several sizes against one robot.

The issue's target: stepping 4 robots costs at most 4.5x one robot's step (one physics space,
one shared map). Each team drives the same scripted, wall-bouncing actions from the same start
region. Every step is timed on its own; the figure is the median wall time per env step, and
the team sizes alternate round by round, so that a loaded machine slows them alike (compare
ratios within one run, not milliseconds across runs).

    python scripts/bench_team_step.py --world office:seed=304,size_m=20 --robots 1,4 --rounds 3

``--against DIR`` times another checkout (e.g. an older commit unpacked with ``git archive``)
in the same run: each round runs both trees, one after the other, in fresh processes, and the
report gives both trees' medians and ratios.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np


def time_steps(world: str, n_robots: int, steps: int, seed: int) -> list[float]:
    """Wall seconds of each of ``steps`` steps of an ``n_robots`` team."""
    from semexplore_gym.envs.multi_robot import make_multi

    env = make_multi(world=world, n_robots=n_robots, overrides=["episode.coverage_goal=1.0"])
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    turn = {a: 0 for a in env.agents}
    times = []
    for _ in range(steps):
        actions = {}
        for a in env.agents:
            scan = obs[a]["scan"]
            ahead = np.concatenate([scan[:20], scan[-20:]])
            blocked = bool(np.any((ahead > 0) & (ahead < 0.35)))
            if blocked and turn[a] == 0:
                turn[a] = int(rng.integers(3, 10))
            if turn[a] > 0:
                turn[a] -= 1
                actions[a] = np.array([0.0, 1.0], dtype=np.float32)
            else:
                actions[a] = np.array([1.0, 0.0], dtype=np.float32)
        t0 = time.perf_counter()
        obs, *_ = env.step(actions)
        times.append(time.perf_counter() - t0)
        if not env.agents:
            break
    return times


def run_rounds(world: str, sizes: list[int], steps: int, seed: int, rounds: int) -> dict:
    """Per team size, the step times of every round (sizes alternate within each round)."""
    time_steps(world, max(sizes), 5, seed)  # JIT warm-up
    out: dict[int, list[float]] = {n: [] for n in sizes}
    for _ in range(rounds):
        for n in sizes:
            out[n] += time_steps(world, n, steps, seed)
    return out


def report(label: str, times: dict[int, list[float]]) -> dict[int, float]:
    """Print median ms/step and the ratio to one robot; return the medians."""
    med = {n: float(np.median(v)) for n, v in times.items()}
    base = med.get(1)
    for n, m in med.items():
        ratio = f"  {m / base:.2f}x one robot" if base else ""
        print(f"{label}{n} robots: {m * 1e3:.3f} ms/step (median of {len(times[n])}){ratio}")
    return med


def _worker(args: argparse.Namespace, sizes: list[int]) -> int:
    times = run_rounds(args.world, sizes, args.steps, args.seed, 1)
    print(json.dumps({str(n): v for n, v in times.items()}))
    return 0


def _against(args: argparse.Namespace, sizes: list[int]) -> int:
    here = Path(__file__).resolve().parents[1]
    trees = {"A (--against)": Path(args.against).resolve(), "B (this checkout)": here}
    times: dict[str, dict[int, list[float]]] = {k: {n: [] for n in sizes} for k in trees}
    for r in range(args.rounds):
        for label, tree in trees.items():
            cmd = [sys.executable, str(Path(__file__).resolve()), "--worker"]
            cmd += ["--world", args.world, "--robots", args.robots]
            cmd += ["--steps", str(args.steps), "--seed", str(args.seed)]
            env = {**os.environ, "PYTHONPATH": str(tree)}
            res = subprocess.run(cmd, env=env, cwd=tree, capture_output=True, text=True)
            if res.returncode:
                sys.stderr.write(res.stderr)
                return res.returncode
            got = json.loads(res.stdout.strip().splitlines()[-1])
            for n in sizes:
                times[label][n] += got[str(n)]
            print(f"round {r + 1}/{args.rounds}: {label} done", flush=True)
    meds = {label: report(f"{label}: ", t) for label, t in times.items()}
    a, b = meds.values()
    for n in sizes:
        print(f"{n} robots: B / A = {b[n] / a[n]:.2f}")
    return 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--world", default="office:seed=304,size_m=20")
    p.add_argument("--robots", default="1,2,4", help="team sizes (default: %(default)s)")
    p.add_argument("--steps", type=int, default=300, help="steps per team and round")
    p.add_argument("--rounds", type=int, default=3, help="rounds of every team size")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--against", help="another checkout to time in the same run (A/B)")
    p.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    sizes = [int(v) for v in args.robots.split(",")]
    if args.worker:
        return _worker(args, sizes)
    if args.against:
        return _against(args, sizes)
    report("", run_rounds(args.world, sizes, args.steps, args.seed, args.rounds))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Time SemanticExploreMulti-v0's step for teams of several sizes against one robot.

The issue's target: stepping 4 robots costs at most 4.5x one robot's step (one physics space,
one shared map). Each team drives the same scripted, wall-bouncing actions from the same start
region; the figure is the mean wall time per env step.

    python scripts/bench_team_step.py --world office:seed=304,size_m=20 --robots 1,2,4 --steps 300
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def time_steps(world: str, n_robots: int, steps: int, seed: int) -> float:
    """Mean wall seconds per step of an ``n_robots`` team over ``steps`` steps."""
    from semexplore_gym.envs.multi_robot import make_multi

    env = make_multi(world=world, n_robots=n_robots, overrides=["episode.coverage_goal=1.0"])
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    turn = {a: 0 for a in env.agents}
    t0 = time.perf_counter()
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
        obs, *_ = env.step(actions)
        if not env.agents:
            break
    return (time.perf_counter() - t0) / steps


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--world", default="office:seed=304,size_m=20")
    p.add_argument("--robots", default="1,2,4", help="team sizes (default: %(default)s)")
    p.add_argument("--steps", type=int, default=300)
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args(argv)
    sizes = [int(v) for v in args.robots.split(",")]
    time_steps(args.world, max(sizes), 5, args.seed)  # JIT warm-up
    base = None
    for n in sizes:
        per = time_steps(args.world, n, args.steps, args.seed)
        base = per if base is None and n == 1 else base
        ratio = f"{per / base:.2f}x one robot" if base else ""
        print(f"{n} robots: {per * 1e3:.2f} ms/step {ratio}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

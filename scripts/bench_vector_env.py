"""Benchmark vectorised envs against stepping the same envs in a plain Python loop.

    python scripts/bench_vector_env.py [--world maze1] [--envs 1 2 4] [--steps 1500] [--repeats 3]

For each number of envs N: a plain loop over N envs (``env.step`` each, no batching), gymnasium's
``SyncVectorEnv`` (default ``copy=True``, and ``copy=False``) and ``AsyncVectorEnv`` (one worker
process per env; shared-memory observations). All run seeded random actions for ``--steps``
vector steps; the methods are timed in turn within each repeat (round-robin), and the table
gives the median aggregate env steps/s and the ratio to the plain loop of the same repeat.
Not a test: the numbers depend on the machine (AsyncVectorEnv only pays off with free cores).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

REAL_MAPS = {
    "intel_lab": "ipa_room_segmentation/intel_map.yaml",
    "willow": "stage_ros/willow-full.yaml",
}


def _env_fn(world: str) -> Callable[[], Any]:
    def make() -> Any:
        import gymnasium as gym

        import semexplore_gym  # noqa: F401

        cfg = {"episode": {"max_time_s": 1e7, "coverage_goal": 1.0}}
        return gym.make("SemanticExplore-v0", world=world, config=cfg)

    return make


def _actions(n_steps: int, n_envs: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    a = rng.uniform(-1, 1, size=(n_steps, n_envs, 2)).astype(np.float32)
    a[..., 0] = np.abs(a[..., 0])
    return a


def time_loop(envs: list, actions: np.ndarray) -> float:
    for i, e in enumerate(envs):
        e.reset(seed=i)
    t0 = time.perf_counter()
    for a in actions:
        for e, ai in zip(envs, a, strict=True):
            e.step(ai)
    return time.perf_counter() - t0


def time_vector(venv: Any, actions: np.ndarray) -> float:
    venv.reset(seed=0)
    t0 = time.perf_counter()
    for a in actions:
        venv.step(a)
    return time.perf_counter() - t0


def main(argv: list[str] | None = None) -> int:
    import gymnasium as gym

    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--world", default="maze1", help="world spec; also intel_lab, willow")
    p.add_argument(
        "--maps-dir", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "maps")
    )
    p.add_argument("--envs", type=int, nargs="+", default=[1, 2, 4], help="numbers of envs")
    p.add_argument("--steps", type=int, default=1500, help="vector steps per timed run")
    p.add_argument("--repeats", type=int, default=3, help="round-robin repeats (median reported)")
    p.add_argument("--no-async", action="store_true", help="skip AsyncVectorEnv")
    args = p.parse_args(argv)
    world = (
        os.path.join(args.maps_dir, REAL_MAPS[args.world])
        if args.world in REAL_MAPS
        else args.world
    )
    fn = _env_fn(world)

    print(
        f"Aggregate env steps/s, {args.world}, {args.steps} vector steps, median of {args.repeats}\n"
    )
    print("| envs | method | steps/s | x plain loop |")
    print("|---:|---|---:|---:|")
    for n in args.envs:
        actions = _actions(args.steps, n)
        methods: dict[str, Callable[[], float]] = {}
        envs = [fn() for _ in range(n)]
        methods["plain loop"] = lambda envs=envs, a=actions: time_loop(envs, a)
        sync = gym.vector.SyncVectorEnv([fn] * n)
        methods["SyncVectorEnv"] = lambda v=sync, a=actions: time_vector(v, a)
        sync_nc = gym.vector.SyncVectorEnv([fn] * n, copy=False)
        methods["SyncVectorEnv copy=False"] = lambda v=sync_nc, a=actions: time_vector(v, a)
        if not args.no_async:
            asy = gym.vector.AsyncVectorEnv([fn] * n, shared_memory=True)
            methods["AsyncVectorEnv"] = lambda v=asy, a=actions: time_vector(v, a)
        for f in methods.values():  # warm-up: numba caches, worker start-up
            f()
        times: dict[str, list[float]] = {k: [] for k in methods}
        for _ in range(args.repeats):
            for k, f in methods.items():
                times[k].append(f())
        base = np.array(times["plain loop"])
        for k, ts in times.items():
            t = np.array(ts)
            rate = n * args.steps / float(np.median(t))
            print(f"| {n} | {k} | {rate:,.0f} | {float(np.median(base / t)):.2f} |")
        sync.close()
        sync_nc.close()
        if not args.no_async:
            asy.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())

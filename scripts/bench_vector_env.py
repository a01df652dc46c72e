"""Benchmark vectorised envs against stepping the same envs in a plain Python loop.

    python scripts/bench_vector_env.py [--world maze1] [--envs 1 2 4] [--steps 1500] [--repeats 3]

For each number of envs N: a plain loop over N envs (``env.step`` each, no batching), gymnasium's
``SyncVectorEnv`` (default ``copy=True``, and ``copy=False``) and ``AsyncVectorEnv`` (one worker
process per env; shared-memory observations). All run seeded random actions for ``--steps``
vector steps; the methods are timed in turn within each repeat (round-robin), and the table
gives the median aggregate env steps/s and the ratio to the plain loop of the same repeat
(wall clock, and CPU time of this process, which other jobs disturb less; AsyncVectorEnv's
workers are other processes, so only its wall-clock ratio means anything). ``FastSyncVectorEnv`` (``semexplore_gym.envs.vector``, same
results as ``SyncVectorEnv``) is timed where the checkout has it. ``--fast-info`` adds both
over envs built with ``static_info="reset"``; ``--map-observation window`` builds every env with that
option.
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


def _env_fn(world: str, **env_kwargs: Any) -> Callable[[], Any]:
    def make() -> Any:
        import gymnasium as gym

        import semexplore_gym  # noqa: F401

        cfg = {"episode": {"max_time_s": 1e7, "coverage_goal": 1.0}}
        return gym.make("SemanticExplore-v0", world=world, config=cfg, **env_kwargs)

    return make


def _vector_module() -> Any:
    """``semexplore_gym.envs.vector`` where the checkout has it (None before issue #17)."""
    try:
        from semexplore_gym.envs import vector
    except ImportError:
        return None
    return vector


def _actions(n_steps: int, n_envs: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    a = rng.uniform(-1, 1, size=(n_steps, n_envs, 2)).astype(np.float32)
    a[..., 0] = np.abs(a[..., 0])
    return a


def time_loop(envs: list, actions: np.ndarray) -> tuple[float, float]:
    for i, e in enumerate(envs):
        e.reset(seed=i)
    t0, c0 = time.perf_counter(), time.process_time()
    for a in actions:
        for e, ai in zip(envs, a, strict=True):
            e.step(ai)
    return time.perf_counter() - t0, time.process_time() - c0


def time_vector(venv: Any, actions: np.ndarray) -> tuple[float, float]:
    venv.reset(seed=0)
    t0, c0 = time.perf_counter(), time.process_time()
    for a in actions:
        venv.step(a)
    return time.perf_counter() - t0, time.process_time() - c0


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
    p.add_argument(
        "--map-observation",
        default=None,
        choices=["copy", "window", "shared"],
        help="env option map_observation",
    )
    p.add_argument(
        "--fast-info",
        action="store_true",
        help="also time SyncVectorEnv over envs with static_info='reset'",
    )
    args = p.parse_args(argv)
    world = (
        os.path.join(args.maps_dir, REAL_MAPS[args.world])
        if args.world in REAL_MAPS
        else args.world
    )
    kw: dict[str, Any] = {}
    if args.map_observation is not None:
        kw["map_observation"] = args.map_observation
    fn = _env_fn(world, **kw)
    fn_fast = _env_fn(world, **kw, static_info="reset")

    print(
        f"Aggregate env steps/s, {args.world}, {args.steps} vector steps, median of {args.repeats}\n"
    )
    print("| envs | method | steps/s (wall) | x plain loop (wall) | x plain loop (CPU) |")
    print("|---:|---|---:|---:|---:|")
    for n in args.envs:
        actions = _actions(args.steps, n)
        methods: dict[str, Callable[[], tuple[float, float]]] = {}
        envs = [fn() for _ in range(n)]
        methods["plain loop"] = lambda envs=envs, a=actions: time_loop(envs, a)
        sync = gym.vector.SyncVectorEnv([fn] * n)
        methods["SyncVectorEnv"] = lambda v=sync, a=actions: time_vector(v, a)
        sync_nc = gym.vector.SyncVectorEnv([fn] * n, copy=False)
        methods["SyncVectorEnv copy=False"] = lambda v=sync_nc, a=actions: time_vector(v, a)
        vecs = [sync, sync_nc]
        fast_cls = getattr(_vector_module(), "FastSyncVectorEnv", None)
        variants = [(gym.vector.SyncVectorEnv, "SyncVectorEnv", fn_fast)] if args.fast_info else []
        if fast_cls is not None:
            variants.append((fast_cls, "FastSyncVectorEnv", fn))
            if args.fast_info:
                variants.append((fast_cls, "FastSyncVectorEnv", fn_fast))
        for cls, name, f in variants:
            for copy in (True, False):
                v = cls([f] * n, copy=copy)
                label = name + (" static_info=reset" if f is fn_fast else "")
                label += "" if copy else " copy=False"
                methods[label] = lambda v=v, a=actions: time_vector(v, a)
                vecs.append(v)
        if not args.no_async:
            asy = gym.vector.AsyncVectorEnv([fn] * n, shared_memory=True)
            methods["AsyncVectorEnv"] = lambda v=asy, a=actions: time_vector(v, a)
        for f in methods.values():  # warm-up: numba caches, worker start-up
            f()
        times: dict[str, list[tuple[float, float]]] = {k: [] for k in methods}
        for _ in range(args.repeats):
            for k, f in methods.items():
                times[k].append(f())
        base = np.array(times["plain loop"])
        for k, ts in times.items():
            t = np.array(ts)
            rate = n * args.steps / float(np.median(t[:, 0]))
            wall = float(np.median(base[:, 0] / t[:, 0]))
            # Async workers run in other processes: this process's CPU time says nothing.
            cpu = "-" if k.startswith("Async") else f"{float(np.median(base[:, 1] / t[:, 1])):.2f}"
            print(f"| {n} | {k} | {rate:,.0f} | {wall:.2f} | {cpu} |")
        for v in vecs:
            v.close()
        if not args.no_async:
            asy.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())

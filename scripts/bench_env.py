"""Benchmark the env: steps/s, LiDAR scans/s vs a pymunk per-beam reference, memory per env.

    python scripts/bench_env.py [--world maze1] [--steps 20000] [--envs 16]

Prints a markdown table (the README quotes it). Not a test: numbers depend on the machine.
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import resource
import sys
import time

import numpy as np


def _rss_mb() -> float:
    with open(f"/proc/{os.getpid()}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def bench_steps(world: str, n_steps: int) -> dict[str, float]:
    import gymnasium as gym

    import semexplore_gym  # noqa: F401

    env = gym.make(
        "SemanticExplore-v0", world=world, config={"episode": {"max_time_s": 1e9}}
    ).unwrapped
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    actions = rng.uniform(-1, 1, size=(n_steps, 2)).astype(np.float32)
    actions[:, 0] = np.abs(actions[:, 0])
    for a in actions[:200]:  # warm-up (numba caches, allocator)
        env.step(a)
    t0 = time.perf_counter()
    for a in actions:
        env.step(a)
    dt = time.perf_counter() - t0
    # Split: time the stages on their own.
    x, y, yaw = env.sim.pose
    t0 = time.perf_counter()
    for _ in range(2000):
        env.lidar.scan(x, y, yaw, env.np_random)
    scan_ms = (time.perf_counter() - t0) / 2000 * 1e3
    scan = env.lidar.scan(x, y, yaw, env.np_random)
    t0 = time.perf_counter()
    for _ in range(2000):
        env.grid.integrate_scan(
            x, y, yaw, env.lidar.beam_angles_rad, scan, env.config.lidar.max_range_m
        )
    map_ms = (time.perf_counter() - t0) / 2000 * 1e3
    t0 = time.perf_counter()
    for a in actions[:2000]:
        env.sim.step(float(a[0]) * 0.22, float(a[1]) * 2.84, 0.2)
    phys_ms = (time.perf_counter() - t0) / 2000 * 1e3
    return {
        "steps_per_s": n_steps / dt,
        "ms_per_step": dt / n_steps * 1e3,
        "scan_ms": scan_ms,
        "map_ms": map_ms,
        "physics_ms": phys_ms,
    }


def bench_lidar_vs_pymunk(world: str, n_scans: int = 300) -> dict[str, float]:
    import pymunk

    from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan
    from semexplore_gym.core.worlds import make_world
    from semexplore_gym.core.worlds.start import sample_start_pose

    w = make_world(world)
    space = pymunk.Space()
    for x0, y0, x1, y1 in w.segments_m:
        space.add(pymunk.Segment(space.static_body, (x0, y0), (x1, y1), 0.0))
    index = SegmentIndex(w.segments_m)
    rng = np.random.default_rng(0)
    poses = [sample_start_pose(w, rng, 0.15) for _ in range(64)]
    angles = np.arange(360) * (2 * math.pi / 360)
    cast_scan(index, *poses[0], angles, 3.5)
    flt = pymunk.ShapeFilter()
    t0 = time.perf_counter()
    for i in range(n_scans):
        x, y, yaw = poses[i % 64]
        for a in angles:
            end = (x + 3.5 * math.cos(yaw + a), y + 3.5 * math.sin(yaw + a))
            space.segment_query_first((x, y), end, 0.0, flt)
    pm = (time.perf_counter() - t0) / n_scans
    t0 = time.perf_counter()
    reps = n_scans * 20
    for i in range(reps):
        cast_scan(index, *poses[i % 64], angles, 3.5)
    ours = (time.perf_counter() - t0) / reps
    return {
        "pymunk_ms": pm * 1e3,
        "ours_ms": ours * 1e3,
        "speedup": pm / ours,
        "n_segments": w.n_segments,
    }


def bench_memory(world: str, n_envs: int) -> dict[str, float]:
    import gymnasium as gym

    import semexplore_gym  # noqa: F401

    first = gym.make("SemanticExplore-v0", world=world)  # imports and numba caches loaded
    first.reset(seed=0)
    gc.collect()
    base = _rss_mb()
    t0 = time.perf_counter()
    envs = [gym.make("SemanticExplore-v0", world=world) for _ in range(n_envs)]
    for i, e in enumerate(envs):
        e.reset(seed=i)
    make_s = (time.perf_counter() - t0) / n_envs
    gc.collect()
    return {"mb_per_env": (_rss_mb() - base) / n_envs, "make_reset_s": make_s}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--world", default="maze1")
    p.add_argument("--steps", type=int, default=20000)
    p.add_argument("--envs", type=int, default=16)
    args = p.parse_args(argv)
    s = bench_steps(args.world, args.steps)
    lid = bench_lidar_vs_pymunk(args.world)
    mem = bench_memory(args.world, args.envs)
    print(f"| metric ({args.world}, 360 beams) | value |")
    print("|---|---:|")
    print(f"| env steps/s (one process, random actions) | {s['steps_per_s']:,.0f} |")
    print(f"| ms per env step | {s['ms_per_step']:.3f} |")
    print(f"| of which LiDAR scan ms | {s['scan_ms']:.3f} |")
    print(f"| of which map update ms | {s['map_ms']:.3f} |")
    print(f"| of which physics ms | {s['physics_ms']:.3f} |")
    print(f"| LiDAR scans/s, ours ({lid['n_segments']} segments) | {1e3 / lid['ours_ms']:,.0f} |")
    print(f"| LiDAR scans/s, pymunk segment_query_first per beam | {1e3 / lid['pymunk_ms']:,.0f} |")
    print(f"| LiDAR speed-up vs pymunk | {lid['speedup']:.1f}x |")
    print(f"| memory per env instance (MB, {args.envs} envs) | {mem['mb_per_env']:.1f} |")
    print(f"| make + reset per env (s, warm) | {mem['make_reset_s']:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())

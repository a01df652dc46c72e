"""Benchmark the env step along real trajectories, stage by stage, against a pymunk reference.

    python scripts/bench_env.py [--world maze1 ...] [--steps 5000] [--repeats 3] [--envs 16]

For each world one env is stepped with seeded random actions (forward-biased, as
``bench_expert.py`` drives) and the whole step loop is timed. The trajectory is recorded and
replayed to time each stage on the poses the robot really visited:

* physics: a second env with the same seed and actions, only ``env.sim.step`` (the same path);
* LiDAR: ``env.lidar.scan`` at each recorded true pose;
* map update: ``OccupancyGrid.integrate_scan`` of each recorded scan into a fresh grid, so the
  map grows as it did (cell visits and distinct cells per scan are counted alongside);
* fused LiDAR + map: the env's one-call sensing path, where the checkout has one;
* rest: the step minus the stages (action checks, odometry, observation, reward, info);
* pymunk reference: ``Space.segment_query_first`` per beam at the recorded poses.

``--no-stages`` only times the step loop, but round-robin: each repeat steps every world (and
every ``--map-observation`` variant, e.g. ``copy window shared``) once in turn, and the table gives the
median wall and CPU time per step and the median ratio to the first row within each repeat::

    python scripts/bench_env.py --no-stages --world maze1 intel_lab willow \
        --map-observation copy window shared --steps 2000 --repeats 7

Prints a markdown table (median over ``--repeats``) and the peak memory per env instance. Not
a test: the numbers depend on the machine. Run it against two checkouts alternately to compare
(``PYTHONPATH=<checkout> python scripts/bench_env.py``); the script only uses APIs both have.
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import sys
import time
from typing import Any

import numpy as np

REAL_MAPS = {
    "intel_lab": "ipa_room_segmentation/intel_map.yaml",
    "willow": "stage_ros/willow-full.yaml",
}


def _world_spec(name: str, maps_dir: str) -> str:
    return os.path.join(maps_dir, REAL_MAPS[name]) if name in REAL_MAPS else name


def _rss_mb() -> float:
    with open(f"/proc/{os.getpid()}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def _make(world: str, **env_kwargs: Any) -> Any:
    import gymnasium as gym

    import semexplore_gym  # noqa: F401

    cfg = {"episode": {"max_time_s": 1e7, "coverage_goal": 1.0}}
    return gym.make("SemanticExplore-v0", world=world, config=cfg, **env_kwargs).unwrapped


def _actions(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    a = rng.uniform(-1, 1, size=(n, 2)).astype(np.float32)
    a[:, 0] = np.abs(a[:, 0])  # mostly forward, so the robot travels and meets walls
    return a


def run_steps(env: Any, actions: np.ndarray) -> tuple[float, list, list, list]:
    """Step through ``actions``; return seconds and the true poses, estimated poses and scans."""
    env.reset(seed=0)
    true_p, est_p, scans = [], [], []
    t0 = time.perf_counter()
    for a in actions:
        env.step(a)
    dt = time.perf_counter() - t0
    # Second pass (untimed) to record the trajectory; stepping is deterministic.
    env.reset(seed=0)
    for a in actions:
        obs = env.step(a)[0]
        true_p.append(env.sim.pose)
        est_p.append(tuple(float(v) for v in obs["pose"]))
        scans.append(obs["scan"].copy())
    return dt, true_p, est_p, scans


def time_stages(env: Any, actions: np.ndarray, true_p: list, scans: list) -> dict[str, float]:
    """Seconds per stage over the whole trajectory (see the module docstring)."""
    from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid

    out: dict[str, float] = {}
    env.reset(seed=0)
    sim, dt_s = env.sim, env.config.episode.dt_s
    rp = env.config.robot
    cmds = [
        (float(a[0]) * rp.max_linear_speed_mps, float(a[1]) * rp.max_angular_speed_radps)
        for a in actions
    ]
    t0 = time.perf_counter()
    for v, w in cmds:
        sim.step(v, w, dt_s)
    out["physics"] = time.perf_counter() - t0

    lidar, rng = env.lidar, env.np_random
    t0 = time.perf_counter()
    for x, y, yaw in true_p:
        lidar.scan(x, y, yaw, rng)
    out["lidar"] = time.perf_counter() - t0

    beams, max_r = lidar.beam_angles_rad, env.config.lidar.max_range_m
    grid = OccupancyGrid(env.map_geometry, env.config.mapping)
    t0 = time.perf_counter()
    for (x, y, yaw), s in zip(true_p, scans, strict=True):
        grid.integrate_scan(x, y, yaw, beams, s, max_r)
    out["map"] = time.perf_counter() - t0

    fused = getattr(env, "_sense_and_map", None)
    if fused is not None and getattr(env.lidar, "sense_and_map", None) is not None:
        env.grid = OccupancyGrid(env.map_geometry, env.config.mapping)
        t0 = time.perf_counter()
        for pose in true_p:
            env._est_pose = pose
            fused(pose)
        out["fused"] = time.perf_counter() - t0
    return out


def count_visits(env: Any, true_p: list, scans: list, stride: int = 10) -> tuple[float, float]:
    """Mean cell visits and distinct cells per scan of the free-space traversal (pure numpy)."""
    g = env.map_geometry
    beams, max_r = env.lidar.beam_angles_rad, env.config.lidar.max_range_m
    visits, distinct = [], []
    for (x, y, yaw), s in list(zip(true_p, scans, strict=True))[::stride]:
        r = np.minimum(s.astype(np.float64), max_r)
        ok = r > 0
        cells = []
        for b, rr in zip(beams[ok], r[ok], strict=True):
            n = max(2, int(math.ceil(rr / g.resolution_m * 4)))
            t = np.linspace(0.0, rr, n, endpoint=False)
            col = np.floor((x + t * math.cos(yaw + b) - g.origin_x_m) / g.resolution_m).astype(
                np.int64
            )
            row = np.floor((y + t * math.sin(yaw + b) - g.origin_y_m) / g.resolution_m).astype(
                np.int64
            )
            lin = np.unique(row * g.width + col)
            cells.append(lin)
        allc = np.concatenate(cells) if cells else np.zeros(0, np.int64)
        visits.append(allc.size)
        distinct.append(np.unique(allc).size)
    return float(np.mean(visits)), float(np.mean(distinct))


def pymunk_reference(env: Any, true_p: list, n_scans: int) -> float:
    """Seconds per scan of pymunk ``segment_query_first`` per beam on the world's walls."""
    import pymunk

    space = pymunk.Space()
    for x0, y0, x1, y1 in env.world.segments_m:
        space.add(pymunk.Segment(space.static_body, (x0, y0), (x1, y1), 0.0))
    beams, max_r = env.lidar.beam_angles_rad, env.config.lidar.max_range_m
    flt = pymunk.ShapeFilter()
    poses = true_p[:: max(1, len(true_p) // n_scans)][:n_scans]
    t0 = time.perf_counter()
    for x, y, yaw in poses:
        for a in beams:
            end = (x + max_r * math.cos(yaw + a), y + max_r * math.sin(yaw + a))
            space.segment_query_first((x, y), end, 0.0, flt)
    return (time.perf_counter() - t0) / len(poses)


def bench_world(
    world: str,
    n_steps: int,
    repeats: int,
    pymunk_scans: int,
    stages: bool = True,
    env_kwargs: dict[str, Any] | None = None,
) -> dict[str, float]:
    env = _make(world, **(env_kwargs or {}))
    actions = _actions(n_steps, 0)
    warm = actions[: min(300, n_steps)]
    _dt, warm_p, _est, warm_s = run_steps(env, warm)  # warm-up: numba caches, allocator
    if stages:  # the stage kernels too (their first call loads or compiles them)
        time_stages(env, warm, warm_p, warm_s)
    rows: dict[str, list[float]] = {}
    for _ in range(repeats):
        dt, true_p, _est_p, scans = run_steps(env, actions)
        rows.setdefault("step", []).append(dt)
        if stages:
            for k, v in time_stages(env, actions, true_p, scans).items():
                rows.setdefault(k, []).append(v)
    med = {k: float(np.median(v)) / n_steps * 1e6 for k, v in rows.items()}  # us per step
    if not stages:
        return {"step": med["step"], "steps_per_s": 1e6 / med["step"]}
    med["rest"] = med["step"] - med.get("fused", med["lidar"] + med["map"]) - med["physics"]
    med["steps_per_s"] = 1e6 / med["step"]
    med["pymunk_scan"] = pymunk_reference(env, true_p, pymunk_scans) * 1e6
    med["visits"], med["distinct"] = count_visits(env, true_p, scans)
    med["n_segments"] = float(env.world.n_segments)
    med["map_cells"] = float(env.map_geometry.height * env.map_geometry.width)
    return med


def round_robin(
    variants: list[tuple[str, str, dict[str, Any], str | None]], n_steps: int, repeats: int
) -> str:
    """Time the step loop of each variant in turn, ``repeats`` times; a markdown table.

    Each repeat times every variant once (round-robin), so load drifts hit all alike. The
    ratios are taken within each repeat against the first variant, then the median is quoted.
    CPU time (``time.process_time``) is less disturbed by other jobs than wall time.
    """
    actions = _actions(n_steps, 0)
    envs = []
    for _label, world, kw, mo in variants:
        env = _make(world, **kw, **({"map_observation": mo} if mo else {}))
        run_steps(env, actions[: min(300, n_steps)])  # warm-up: numba caches, allocator
        envs.append(env)
    wall: list[list[float]] = [[] for _ in envs]
    cpu: list[list[float]] = [[] for _ in envs]
    for _ in range(repeats):
        for k, env in enumerate(envs):
            env.reset(seed=0)
            t0, c0 = time.perf_counter(), time.process_time()
            for a in actions:
                env.step(a)
            wall[k].append(time.perf_counter() - t0)
            cpu[k].append(time.process_time() - c0)
    lines = [
        f"Step loop, {n_steps} steps, {repeats} round-robin repeats (medians; ratio to the first row)\n",
        "| world | steps/s (wall) | us/step (wall) | us/step (CPU) | x first (wall) | x first (CPU) |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    w0, c0_ = np.array(wall[0]), np.array(cpu[0])
    for (label, *_), w, c in zip(variants, wall, cpu, strict=True):
        wa, ca = np.array(w), np.array(c)
        lines.append(
            f"| {label} | {n_steps / float(np.median(wa)):,.0f} "
            f"| {float(np.median(wa)) / n_steps * 1e6:.1f} | {float(np.median(ca)) / n_steps * 1e6:.1f} "
            f"| {float(np.median(w0 / wa)):.2f} | {float(np.median(c0_ / ca)):.2f} |"
        )
    return "\n".join(lines)


def bench_memory(world: str, n_envs: int) -> float:
    first = _make(world)
    first.reset(seed=0)
    gc.collect()
    base = _rss_mb()
    envs = [_make(world) for _ in range(n_envs)]
    for i, e in enumerate(envs):
        e.reset(seed=i)
    gc.collect()
    return (_rss_mb() - base) / n_envs


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--world", nargs="+", default=["maze1"], help="worlds; also intel_lab, willow")
    p.add_argument(
        "--maps-dir", default=os.path.join(os.path.dirname(__file__), "..", "..", "shared", "maps")
    )
    p.add_argument("--steps", type=int, default=5000, help="steps per timed run")
    p.add_argument("--repeats", type=int, default=3, help="timed runs (median reported)")
    p.add_argument("--pymunk-scans", type=int, default=100, help="scans for the pymunk reference")
    p.add_argument("--envs", type=int, default=0, help="also measure memory per env with N envs")
    p.add_argument(
        "--no-stages", action="store_true", help="only the step loop (one line per world)"
    )
    p.add_argument(
        "--map-observation",
        nargs="+",
        default=None,
        choices=["copy", "window", "shared"],
        help="env option map_observation; several values are timed side by side",
    )
    p.add_argument(
        "--static-info",
        default=None,
        choices=["every_step", "reset"],
        help="env option static_info",
    )
    args = p.parse_args(argv)
    kw: dict[str, Any] = {}
    if args.static_info is not None:
        kw["static_info"] = args.static_info
    if args.no_stages:
        variants = [
            (f"{w}" + (f" [{mo}]" if mo else ""), _world_spec(w, args.maps_dir), kw, mo)
            for w in args.world
            for mo in (args.map_observation or [None])
        ]
        print(round_robin(variants, args.steps, args.repeats))
        return 0
    if args.map_observation:
        kw["map_observation"] = args.map_observation[0]
    res = {
        w: bench_world(
            _world_spec(w, args.maps_dir), args.steps, args.repeats, args.pymunk_scans, True, kw
        )
        for w in args.world
    }
    print(
        f"Env step along a {args.steps}-step random trajectory, median of {args.repeats} (us per step)\n"
    )
    print(
        "| world | segments | map cells | steps/s | step | physics | LiDAR | map | LiDAR+map fused | rest | cell visits/scan | distinct cells/scan | pymunk scan | LiDAR x vs pymunk |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for w, m in res.items():
        fused = f"{m['fused']:.1f}" if "fused" in m else "-"
        print(
            f"| {w} | {m['n_segments']:.0f} | {m['map_cells']:,.0f} | {m['steps_per_s']:,.0f} | {m['step']:.1f} "
            f"| {m['physics']:.1f} | {m['lidar']:.1f} | {m['map']:.1f} | {fused} | {m['rest']:.1f} "
            f"| {m['visits']:,.0f} | {m['distinct']:,.0f} | {m['pymunk_scan']:.0f} | {m['pymunk_scan'] / m['lidar']:.0f}x |"
        )
    if args.envs:
        for w in args.world:
            mb = bench_memory(_world_spec(w, args.maps_dir), args.envs)
            print(f"\nmemory per env instance ({w}, {args.envs} envs): {mb:.1f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())

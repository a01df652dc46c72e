"""Benchmark the numba log-odds occupancy update (one 360-beam scan per update).

Scans are cast with :func:`semexplore_gym.core.raycast.cast_scan` in the maze worlds of
``bench_lidar.py`` from random corridor poses; the grid then fuses them one by one. The grid
is reset whenever all poses have been used, so the timing covers the whole exploration, from
an empty map to a well-known one. Prints a markdown table of median ms per update.

Usage::

    python scripts/bench_mapping.py [--repeats 7] [--poses 64] [--seed 0]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from bench_lidar import corridor_poses, maze_segments

from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN
from semexplore_gym.core.mapping.occupancy_grid import MappingParams, OccupancyGrid
from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7, help="timing repeats (median is reported)")
    ap.add_argument("--poses", type=int, default=64, help="scans per map (one per random pose)")
    ap.add_argument("--beams", type=int, default=360, help="beams per scan")
    ap.add_argument("--max-range-m", type=float, default=3.5, help="LiDAR max range in metres")
    ap.add_argument("--resolution-m", type=float, default=0.05, help="grid cell size in metres")
    ap.add_argument("--seed", type=int, default=0, help="seed for worlds and poses")
    ap.add_argument(
        "--stat",
        choices=["median", "min"],
        default="median",
        help="statistic over repeats (min estimates the uncontended time on a busy machine)",
    )
    args = ap.parse_args(argv)

    rng = np.random.default_rng(args.seed)
    beams = np.arange(args.beams) * (2 * np.pi / args.beams)
    worlds = {
        "maze 11 m": (maze_segments(5, 2.2, 4, rng), 5, 2.2),
        "maze 50 m": (maze_segments(20, 2.5, 59, rng), 20, 2.5),
    }
    params = MappingParams(resolution_m=args.resolution_m, margin_m=0.1)
    rows = []
    for name, (segs, n_cells, cell_m) in worlds.items():
        index = SegmentIndex(segs)
        poses = corridor_poses(n_cells, cell_m, args.poses, rng)
        scans = np.stack(
            [cast_scan(index, x, y, yaw, beams, args.max_range_m) for x, y, yaw in poses]
        )
        scans = np.minimum(scans, args.max_range_m)  # no return -> max range, as the env reports
        size = n_cells * cell_m
        grid = OccupancyGrid(params.grid_geometry((0.0, 0.0, size, size)), params)
        grid.integrate_scan(*poses[0], beams, scans[0], args.max_range_m)

        times = []
        for _ in range(args.repeats):
            grid.reset()
            t = time.perf_counter()
            for (x, y, yaw), ranges in zip(poses, scans, strict=True):
                grid.integrate_scan(x, y, yaw, beams, ranges, args.max_range_m)
            times.append((time.perf_counter() - t) * 1e3 / len(poses))

        enc = grid.encoded
        lo = grid.log_odds
        expect = np.where(
            lo < np.float32(params.free_threshold),
            FREE,
            np.where(lo > np.float32(params.occupied_threshold), OCCUPIED, UNKNOWN),
        )
        if not np.array_equal(enc, expect) or grid.n_free_cells != int((enc == FREE).sum()):
            raise AssertionError(
                f"{name}: incremental encoding or counter disagrees with a full recount"
            )
        ms = float(np.median(times) if args.stat == "median" else np.min(times))
        known = float((enc != UNKNOWN).mean())
        rows.append((name, grid.geometry.shape, ms, known))

    print(
        f"Log-odds update: {args.beams} beams, max range {args.max_range_m} m, {args.poses} scans per map, "
        f"{args.stat} of {args.repeats}\n"
    )
    print("| world | grid | ms/update | updates/s | known after all scans |")
    print("|---|---|---:|---:|---:|")
    for name, shape, ms, known in rows:
        print(f"| {name} | {shape[0]}x{shape[1]} | {ms:.4f} | {1e3 / ms:,.0f} | {known:.0%} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

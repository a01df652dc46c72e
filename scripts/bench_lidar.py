"""Benchmark the numba LiDAR ray caster against pymunk ``segment_query_first``.

Worlds (all built here from a seeded maze generator):

* ``maze-40``: 11 m x 11 m perfect maze of 5 x 5 cells, 40 segments.
* ``maze-500``: 50 m x 50 m maze of 20 x 20 cells plus furniture, 500 segments.
* ``maze-10k``: 142.5 m x 142.5 m maze of 95 x 95 cells plus furniture, 10,000 segments.
* ``split-12k``: ``maze-500`` with every wall cut into 0.1 m pieces, like walls traced from a
  raster map (HouseExpo / ROS maps): many tiny segments near every pose.

Each scan is 360 beams at 1 degree, max range 3.5 m, from random poses in corridors. Timings
are medians over repeats, methods interleaved within a repeat. Prints a markdown table.

Usage::

    python scripts/bench_lidar.py [--repeats 7] [--poses 64] [--seed 0]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan


def maze_segments(
    n_cells: int, cell_m: float, n_furniture: int, rng: np.random.Generator
) -> np.ndarray:
    """Walls of a perfect maze (randomised depth-first search) as unit edges, plus diagonals."""
    # walls[kind, r, c]: kind 0 = east wall of cell (r, c), kind 1 = north wall of cell (r, c)
    east = np.ones((n_cells, n_cells), dtype=bool)
    north = np.ones((n_cells, n_cells), dtype=bool)
    seen = np.zeros((n_cells, n_cells), dtype=bool)
    stack = [(0, 0)]
    seen[0, 0] = True
    while stack:
        r, c = stack[-1]
        options = [
            (r + dr, c + dc)
            for dr, dc in ((0, 1), (0, -1), (1, 0), (-1, 0))
            if 0 <= r + dr < n_cells and 0 <= c + dc < n_cells and not seen[r + dr, c + dc]
        ]
        if not options:
            stack.pop()
            continue
        nr, nc = options[int(rng.integers(len(options)))]
        if nr == r:
            east[r, min(c, nc)] = False
        else:
            north[min(r, nr), c] = False
        seen[nr, nc] = True
        stack.append((nr, nc))
    segs = []
    for r in range(n_cells):
        for c in range(n_cells):
            x0, y0 = c * cell_m, r * cell_m
            if c == 0:
                segs.append((x0, y0, x0, y0 + cell_m))
            if r == 0:
                segs.append((x0, y0, x0 + cell_m, y0))
            if east[r, c]:
                segs.append((x0 + cell_m, y0, x0 + cell_m, y0 + cell_m))
            if north[r, c]:
                segs.append((x0, y0 + cell_m, x0 + cell_m, y0 + cell_m))
    cells = rng.choice(n_cells * n_cells, size=n_furniture, replace=n_furniture > n_cells * n_cells)
    for k in cells:
        cx = (k % n_cells + 0.5) * cell_m
        cy = (k // n_cells + 0.5) * cell_m
        segs.append(
            (cx + 0.25 * cell_m, cy + 0.38 * cell_m, cx + 0.38 * cell_m, cy + 0.22 * cell_m)
        )
    return np.asarray(segs, dtype=np.float64)


def split_segments(segments_m: np.ndarray, piece_m: float) -> np.ndarray:
    """Cut every segment into pieces of at most ``piece_m``."""
    out = []
    for x0, y0, x1, y1 in segments_m:
        n = max(1, int(np.ceil(np.hypot(x1 - x0, y1 - y0) / piece_m)))
        t = np.linspace(0.0, 1.0, n + 1)
        xs = x0 + t * (x1 - x0)
        ys = y0 + t * (y1 - y0)
        out.append(np.c_[xs[:-1], ys[:-1], xs[1:], ys[1:]])
    return np.concatenate(out)


def corridor_poses(n_cells: int, cell_m: float, n: int, rng: np.random.Generator) -> np.ndarray:
    """Random poses near cell centres (clear of walls and furniture)."""
    cells = rng.integers(0, n_cells, size=(n, 2))
    xy = (cells + 0.5) * cell_m + rng.uniform(-0.15, 0.15, size=(n, 2)) * cell_m
    yaw = rng.uniform(-np.pi, np.pi, size=n)
    return np.c_[xy, yaw]


def make_worlds(rng: np.random.Generator) -> dict[str, tuple[np.ndarray, int, float]]:
    worlds = {
        "maze-40 (11 m)": (maze_segments(5, 2.2, 4, rng), 5, 2.2),
        "maze-500 (50 m)": (maze_segments(20, 2.5, 59, rng), 20, 2.5),
        "maze-10k (142 m)": (maze_segments(95, 1.5, 784, rng), 95, 1.5),
    }
    big = worlds["maze-500 (50 m)"]
    worlds["split-12k (50 m)"] = (split_segments(big[0], 0.1), big[1], big[2])
    return worlds


def pymunk_scan(space, x, y, angles, max_range_m, out):  # noqa: ANN001 - pymunk only here
    """Reference scan: one ``segment_query_first`` per beam (end points precomputed)."""
    import pymunk

    flt = pymunk.ShapeFilter()
    query = space.segment_query_first
    start = (float(x), float(y))
    ends = np.c_[x + max_range_m * np.cos(angles), y + max_range_m * np.sin(angles)].tolist()
    for j, end in enumerate(ends):
        q = query(start, end, 0.0, flt)
        out[j] = np.inf if q is None else q.alpha * max_range_m
    return out


def pymunk_space(segments_m: np.ndarray):  # noqa: ANN201
    import pymunk

    space = pymunk.Space()
    space.add(
        *[pymunk.Segment(space.static_body, (a, b), (c, d), 0.0) for a, b, c, d in segments_m]
    )
    return space


def first_call_s(cold: bool) -> float:
    """Seconds to import the module and cast one scan in a fresh interpreter."""
    code = (
        "import time; t = time.perf_counter();"
        "import numpy as np;"
        "from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan;"
        "i = SegmentIndex(np.array([[0.,0.,1.,0.]]*30) + np.arange(30)[:, None]);"
        "cast_scan(i, 0.5, 0.5, 0.0, np.linspace(0, 6.28, 360), 3.5);"
        "print(time.perf_counter() - t)"
    )
    env = dict(os.environ)
    with tempfile.TemporaryDirectory() as tmp:
        if cold:
            env["NUMBA_CACHE_DIR"] = tmp
        out = subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
        )
    return float(out.stdout.strip())


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7, help="timing repeats (median is reported)")
    ap.add_argument("--poses", type=int, default=64, help="random poses per world")
    ap.add_argument("--beams", type=int, default=360, help="beams per scan")
    ap.add_argument("--max-range-m", type=float, default=3.5, help="LiDAR max range in metres")
    ap.add_argument("--seed", type=int, default=0, help="seed for worlds and poses")
    ap.add_argument(
        "--stat",
        choices=["median", "min"],
        default="median",
        help="statistic over repeats (min estimates the uncontended time on a busy machine)",
    )
    ap.add_argument(
        "--skip-pymunk-above",
        type=int,
        default=100_000,
        help="skip pymunk above this many segments",
    )
    args = ap.parse_args(argv)

    rng = np.random.default_rng(args.seed)
    beams = np.arange(args.beams) * (2 * np.pi / args.beams)
    rows = []
    SegmentIndex(np.array([[0.0, 0.0, 1.0, 1.0]]))  # load the compiled builder before timing it
    for name, (segs, n_cells, cell_m) in make_worlds(rng).items():
        poses = corridor_poses(n_cells, cell_m, args.poses, rng)
        t = time.perf_counter()
        index = SegmentIndex(segs)
        build_ms = (time.perf_counter() - t) * 1e3
        out = np.empty(args.beams)
        ref = np.empty(args.beams)
        use_pm = len(segs) <= args.skip_pymunk_above
        space = pymunk_space(segs) if use_pm else None
        cast_scan(index, *poses[0], beams, args.max_range_m, out)

        max_err = 0.0
        if use_pm:
            for x, y, yaw in poses:
                cast_scan(index, x, y, yaw, beams, args.max_range_m, out)
                pymunk_scan(space, x, y, yaw + beams, args.max_range_m, ref)
                fin = np.isfinite(ref)
                if not np.array_equal(fin, np.isfinite(out)):
                    raise AssertionError(f"{name}: hit/miss pattern differs from pymunk")
                max_err = max(max_err, float(np.abs(out[fin] - ref[fin]).max(initial=0.0)))

        ours_ms, pm_ms = [], []
        inner = max(1, 2000 // args.poses)
        for _ in range(args.repeats):
            t = time.perf_counter()
            for _ in range(inner):
                for x, y, yaw in poses:
                    cast_scan(index, x, y, yaw, beams, args.max_range_m, out)
            ours_ms.append((time.perf_counter() - t) * 1e3 / (inner * len(poses)))
            if use_pm:
                t = time.perf_counter()
                for x, y, yaw in poses:
                    pymunk_scan(space, x, y, yaw + beams, args.max_range_m, ref)
                pm_ms.append((time.perf_counter() - t) * 1e3 / len(poses))
        stat = np.median if args.stat == "median" else np.min
        ours = float(stat(ours_ms))
        pm = float(stat(pm_ms)) if use_pm else float("nan")
        rows.append((name, len(segs), index, build_ms, pm, ours, max_err))

    print(
        f"LiDAR scan: {args.beams} beams, max range {args.max_range_m} m, {args.poses} poses, {args.stat} of {args.repeats}\n"
    )
    print(
        "| world | segments | bucket m | index build ms | pymunk ms/scan | ours ms/scan | ours scans/s | x vs pymunk | max abs err vs pymunk (m) |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, n, index, build_ms, pm, ours, err in rows:
        print(
            f"| {name} | {n} | {index.cell_size_m:.2f} | {build_ms:.2f} | {pm:.3f} | {ours:.4f} | {1e3 / ours:,.0f} | {pm / ours:.1f} | {err:.1e} |"
        )
    print()
    print(
        f"first call (import + one scan, fresh process): warm cache {first_call_s(False):.2f} s, "
        f"cold cache (compile) {first_call_s(True):.2f} s"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

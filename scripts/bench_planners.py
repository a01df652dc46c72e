"""Benchmark the frontier baselines' planners: WFD frontier search, costmap inflation, Navfn.

Maps come from a simulated partial exploration: LiDAR scans (``cast_scan``) from random poses
within a geodesic radius of the start are fused into an occupancy grid (``OccupancyGrid``),
which is then padded with unknown cells to a square of the requested size, as a fixed-size
gmapping map would be. ``maze1`` gives the paper's 224 x 224 map (0.05 m); a procedural
office gives the 1000 x 1000 one. Prints a markdown table of ms per call.

Rows:

* ``WFD`` - :func:`detect_frontiers` on the occupancy grid;
* ``FE frontier search`` - explore-costmap inflation plus WFD on it, what
  ``FrontierExplorationPolicy`` reports as ``map_generation_ms``;
* ``costmap inflation`` - :func:`inflate_costmap` (EDT) of the global costmap;
* ``Navfn A*`` / ``Navfn Dijkstra`` - :func:`plan_path` from the start to the frontier that is
  farthest by path (worst case), with and without the A* early exit;
* ``Dijkstra field`` - Navfn costs to every cell (``check_reachability``'s cost);
* ``geodesic field`` - :func:`geodesic_distance_m` (``NearestFrontierPolicy``'s cost).

Usage::

    python scripts/bench_planners.py [--sizes 224 1000] [--repeats 7] [--stat min]
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
from scipy import ndimage

from semexplore_gym.core.frontiers.detection import detect_frontiers
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN, GridGeometry
from semexplore_gym.core.mapping.occupancy_grid import MappingParams, OccupancyGrid
from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan
from semexplore_gym.core.planning.grid_search import (
    CostmapParams,
    NavfnParams,
    distance_field,
    geodesic_distance_m,
    inflate_costmap,
    navfn_cell_costs,
    plan_path,
)
from semexplore_gym.maps import make_world

#: World used for each map size (the map is padded to exactly that size).
WORLDS = {224: "maze1", 1000: "office:seed=0,size_m=46"}


def explored_map(
    world_spec: str, size_cells: int, fraction: float, n_poses: int, rng: np.random.Generator
) -> tuple[np.ndarray, GridGeometry, tuple[float, float]]:
    """A partly explored encoded grid of ``size_cells`` squared, and the start position."""
    world = make_world(world_spec)
    free = world.free_mask
    fgeo = world.free_geometry
    # Poses where a 0.105 m robot fits, within the first `fraction` of the geodesic extent.
    clear = ndimage.distance_transform_edt(free) * fgeo.resolution_m
    ok = clear > 0.15
    if world.start_pose is not None:
        sx, sy = world.start_pose[:2]
    else:
        r, c = np.argwhere(ok)[len(np.argwhere(ok)) // 2]
        sx, sy = (float(v) for v in fgeo.grid_to_world(r, c))
    dist = geodesic_distance_m(ok, fgeo, (sx, sy))
    reach = np.isfinite(dist)
    limit = np.quantile(dist[reach], fraction)
    cand = np.argwhere(reach & (dist <= limit))
    pick = cand[rng.choice(len(cand), size=min(n_poses, len(cand)), replace=False)]
    xs, ys = fgeo.grid_to_world(pick[:, 0], pick[:, 1])

    res = 0.05
    xmin, ymin, xmax, ymax = world.bounds_m
    side_m = size_cells * res
    if max(xmax - xmin, ymax - ymin) > side_m:
        raise ValueError(
            f"world {world_spec!r} ({xmax - xmin:.1f} m) does not fit {size_cells} cells"
        )
    cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
    geo = GridGeometry(res, cx - side_m / 2, cy - side_m / 2, size_cells, size_cells)
    grid = OccupancyGrid(geo, MappingParams(resolution_m=res))
    index = SegmentIndex(world.segments_m)
    beams = np.arange(360) * (2 * np.pi / 360)
    for x, y in zip(np.r_[sx, xs], np.r_[sy, ys], strict=True):
        yaw = float(rng.uniform(-np.pi, np.pi))
        ranges = np.minimum(cast_scan(index, x, y, yaw, beams, 3.5), 3.5)
        grid.integrate_scan(x, y, yaw, beams, ranges, 3.5)
    return grid.encoded_copy(), geo, (float(sx), float(sy))


def _time(fn: Callable[[], object], repeats: int, stat: str) -> float:
    fn()  # warm-up (numba caches are loaded on the first call)
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        ts.append((time.perf_counter() - t0) * 1e3)
    return float(np.min(ts) if stat == "min" else np.median(ts))


def bench_size(size: int, args: argparse.Namespace, rng: np.random.Generator) -> dict[str, object]:
    grid, geo, start = explored_map(WORLDS[size], size, args.fraction, args.poses, rng)
    res = geo.resolution_m
    explore = CostmapParams(inscribed_radius_m=0.105, inflation_radius_m=0.15)
    nav = CostmapParams(inscribed_radius_m=0.105, inflation_radius_m=0.2)

    def fe_search() -> list:
        cost = inflate_costmap(grid, res, explore)
        g = np.full(grid.shape, OCCUPIED, dtype=np.uint8)
        g[cost == 0] = FREE
        g[cost == 255] = UNKNOWN
        return detect_frontiers(g, geo, start, 2)

    fronts = detect_frontiers(grid, geo, start, 2)
    costmap = inflate_costmap(grid, res, nav)
    cost = navfn_cell_costs(costmap)
    sr, sc = (int(v) for v in geo.world_to_grid(*start))
    field, _ = distance_field(cost, (sr, sc))
    # Worst-case goal: the frontier cell farthest from the start by Navfn cost.
    best = None
    for f in fronts:
        d = field[f.cells[:, 0], f.cells[:, 1]]
        d = np.where(np.isfinite(d), d, -1.0)
        i = int(np.argmax(d))
        if d[i] > 0 and (best is None or d[i] > best[0]):
            best = (d[i], f.cells[i])
    if best is None:
        raise RuntimeError("no reachable frontier in the benchmark map")
    gx, gy = (float(v) for v in geo.grid_to_world(*best[1]))
    path = plan_path(costmap, geo, start, (gx, gy))
    assert path is not None
    free_mask = (grid == FREE) & (costmap < 253)

    rep, stat = args.repeats, args.stat
    return {
        "size": size,
        "world": WORLDS[size],
        "known %": 100.0 * float((grid != UNKNOWN).mean()),
        "frontiers": len(fronts),
        "path m": path.length_m,
        "WFD": _time(lambda: detect_frontiers(grid, geo, start, 2), rep, stat),
        "FE frontier search": _time(fe_search, rep, stat),
        "costmap inflation": _time(lambda: inflate_costmap(grid, res, nav), rep, stat),
        "Navfn A*": _time(lambda: plan_path(costmap, geo, start, (gx, gy)), rep, stat),
        "Navfn Dijkstra": _time(
            lambda: plan_path(costmap, geo, start, (gx, gy), NavfnParams(use_astar=False)),
            rep,
            stat,
        ),
        "Dijkstra field": _time(lambda: distance_field(cost, (sr, sc)), rep, stat),
        "geodesic field": _time(lambda: geodesic_distance_m(free_mask, geo, start), rep, stat),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=sorted(WORLDS), choices=sorted(WORLDS))
    ap.add_argument("--repeats", type=int, default=7, help="timing repeats per row")
    ap.add_argument("--poses", type=int, default=60, help="scan poses of the simulated exploration")
    ap.add_argument(
        "--fraction", type=float, default=0.5, help="explored share of the geodesic extent"
    )
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument(
        "--stat",
        choices=["median", "min"],
        default="median",
        help="statistic over repeats (min estimates the uncontended time on a busy machine)",
    )
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    rows = [bench_size(s, args, rng) for s in args.sizes]
    timed = [
        "WFD",
        "FE frontier search",
        "costmap inflation",
        "Navfn A*",
        "Navfn Dijkstra",
        "Dijkstra field",
        "geodesic field",
    ]
    print(
        f"ms per call ({args.stat} of {args.repeats}); maps: simulated partial exploration, padded with unknown\n"
    )
    print("| map | world | known % | frontiers | goal path m | " + " | ".join(timed) + " |")
    print("|---|---|---:|---:|---:|" + "---:|" * len(timed))
    for r in rows:
        cells = " | ".join(f"{r[k]:.2f}" for k in timed)
        print(
            f"| {r['size']}² | {r['world']} | {r['known %']:.1f} | {r['frontiers']} | {r['path m']:.1f} | {cells} |"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""How the planners' compute scales with the map: PM (semantic expert) against FE and nearest.

For each world (procedural mazes and offices of growing size, and the real maps of
``../shared/maps`` when present) a partly explored map is built the way a mission sees one:
LiDAR scans from random poses within the first ``--fraction`` of the world's geodesic extent
from the start, fused into a 0.05 m occupancy grid that covers the world. On that map each
method's two stages run through the policies' own code, alternately in ``--repeats`` rounds
(the first round is a warm-up and is dropped), and the median (or, with ``--stat min``, the
minimum, the uncontended time on a busy machine) is reported:

* **PM** (``semantic``): map generation = the semantic topometric segmentation
  (``TopometricSegmenter``, no previous map); global planning = Algorithm 1
  (``search_frontier_paths``) from the robot to every frontier, scored with the paper's weights.
* **FE** (``frontier``): map generation = explore-costmap inflation and the wavefront frontier
  search on it, plus goal selection (``FrontierExplorationPolicy._next_goal``); global planning =
  the navigator's plan to that goal (global-costmap inflation and Navfn A*).
* **nearest**: map generation = the wavefront frontier search; global planning = the geodesic
  Dijkstra that picks the frontier nearest by path, plus the navigator's Navfn plan to it.

Writes a CSV row per world and ``--figure`` (ms per call against map cells for every stage, and
PM's planning against the number of intersections); prints a markdown table.

Usage::

    PYTHONPATH=$PWD python scripts/bench_compute_scaling.py [--repeats 15] [--stat min] [--quick]
"""

from __future__ import annotations

import argparse
import csv
import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage
from semexplore_gym.policies.base import StepStats
from semexplore_gym.policies.frontier_baselines import (
    FrontierExplorationPolicy,
    NearestFrontierPolicy,
)

from semexplore_gym.core.grid import UNKNOWN, GridGeometry
from semexplore_gym.core.mapping.occupancy_grid import MappingParams, OccupancyGrid
from semexplore_gym.core.mapping.raycast import SegmentIndex, cast_scan
from semexplore_gym.core.planning.graph_search import FrontierCostWeights, search_frontier_paths
from semexplore_gym.core.planning.grid_search import geodesic_distance_m
from semexplore_gym.core.topometric import TopometricSegmenter
from semexplore_gym.core.topometric.types import AreaType
from semexplore_gym.maps import make_world

PROCEDURAL = [f"maze:seed=0,size_m={s}" for s in (7, 10, 15, 20, 30, 40)] + [
    f"office:seed=0,size_m={s}" for s in (10, 15, 20, 30, 40)
]
#: Real maps (relative to ``--maps``), used when the file exists.
REAL = [
    "turtlebot3/office/map_office_raw.yaml",
    "mas_domestic_robotics/brsu-c069/map.yaml",
    "ipa_room_segmentation/freiburg_building79.yaml",
    "ipa_room_segmentation/intel_map.yaml",
    "stage_ros/willow-full.yaml",
    "navigation2/warehouse.yaml",
]
RES_M = 0.05
RADIUS_M = 0.105
CLEARANCE_M = 0.155
RANGE_M = 3.5
STAGES = ("pm_map", "pm_plan", "fe_map", "fe_plan", "nearest_map", "nearest_plan")


def explored_map(
    world_spec: str, fraction: float, poses_per_m2: float, rng: np.random.Generator
) -> tuple[np.ndarray, GridGeometry, tuple[float, float, float], float]:
    """A partly explored encoded grid over the world, the robot pose, and the free area (m^2)."""
    world = make_world(world_spec)
    fgeo = world.free_geometry
    clear = ndimage.distance_transform_edt(world.free_mask) * fgeo.resolution_m
    ok = clear > CLEARANCE_M
    if world.start_pose is not None:
        sx, sy = world.start_pose[:2]
    else:  # the most open cell of the largest free component
        labels, _ = ndimage.label(ok)
        sizes = np.bincount(labels.ravel())
        sizes[0] = 0
        comp = labels == int(np.argmax(sizes))
        r, c = np.unravel_index(int(np.argmax(np.where(comp, clear, 0.0))), clear.shape)
        sx, sy = (float(v) for v in fgeo.grid_to_world(r, c))
    dist = geodesic_distance_m(ok, fgeo, (sx, sy))
    reach = np.isfinite(dist)
    limit = np.quantile(dist[reach], fraction)
    cand = np.argwhere(reach & (dist <= limit))
    area_m2 = float(reach.sum()) * fgeo.resolution_m**2
    n_poses = max(40, int(poses_per_m2 * area_m2 * fraction))
    pick = cand[rng.choice(len(cand), size=min(n_poses, len(cand)), replace=False)]
    xs, ys = fgeo.grid_to_world(pick[:, 0], pick[:, 1])
    xmin, ymin, xmax, ymax = world.bounds_m
    w = int(math.ceil((xmax - xmin) / RES_M)) + 20
    h = int(math.ceil((ymax - ymin) / RES_M)) + 20
    geo = GridGeometry(RES_M, xmin - 10 * RES_M, ymin - 10 * RES_M, h, w)
    grid = OccupancyGrid(geo, MappingParams(resolution_m=RES_M))
    index = SegmentIndex(world.segments_m)
    beams = np.arange(360) * (2 * np.pi / 360)
    for x, y in zip(np.r_[sx, xs], np.r_[sy, ys], strict=True):
        yaw = float(rng.uniform(-np.pi, np.pi))
        ranges = np.minimum(cast_scan(index, x, y, yaw, beams, RANGE_M), RANGE_M)
        grid.integrate_scan(x, y, yaw, beams, ranges, RANGE_M)
    return grid.encoded_copy(), geo, (float(sx), float(sy), 0.0), area_m2


def _obs_info(
    grid: np.ndarray, geo: GridGeometry, pose: tuple[float, float, float]
) -> tuple[dict, dict]:
    obs = {
        "map": grid,
        "pose": np.asarray(pose, dtype=np.float32),
        "scan": np.full(360, RANGE_M, dtype=np.float32),
    }
    info = {
        "map_geometry": geo.to_dict(),
        "robot": {
            "radius_m": RADIUS_M,
            "max_linear_speed_mps": 0.22,
            "max_angular_speed_radps": 2.84,
        },
        "lidar": {"n_beams": 360, "min_range_m": 0.12, "max_range_m": RANGE_M},
        "dt_s": 0.2,
    }
    return obs, info


def bench_world(spec: str, args: argparse.Namespace, rng: np.random.Generator) -> dict[str, Any]:
    grid, geo, pose, area_m2 = explored_map(spec, args.fraction, args.poses_per_m2, rng)
    obs, info = _obs_info(grid, geo, pose)
    pose_arr = np.asarray(pose, dtype=np.float64)
    segmenter = TopometricSegmenter()
    weights = FrontierCostWeights()
    fe = FrontierExplorationPolicy()
    fe.reset(obs, info)
    near = NearestFrontierPolicy()
    near.reset(obs, info)
    facts: dict[str, Any] = {}

    def pm() -> tuple[float, float]:
        t0 = time.perf_counter()
        tmap = segmenter(grid, geo, CLEARANCE_M)
        t1 = time.perf_counter()
        cands, _ = search_frontier_paths(tmap, pose[:2], pose[2], weights)
        t2 = time.perf_counter()
        facts["intersections"] = len(tmap.areas_of_type(AreaType.INTERSECTION))
        facts["areas"] = len(tmap.areas)
        facts["openings"] = len(tmap.openings)
        facts["pm_frontiers"] = len(tmap.frontiers)
        facts["pm_candidates"] = len(cands)
        return (t1 - t0) * 1e3, (t2 - t1) * 1e3

    def baseline(policy: Any, select: Callable[[StepStats], Any]) -> tuple[float, float]:
        stats = StepStats()
        goal = select(stats)
        plan_ms = 0.0
        if goal is not None:
            policy.nav.set_goal(goal, 0.0)
            t0 = time.perf_counter()
            path = policy.nav._plan(pose_arr, grid, geo)
            plan_ms = (time.perf_counter() - t0) * 1e3
            facts[f"{policy.name}_path_m"] = None if path is None else round(path.length_m, 1)
        facts[f"{policy.name}_frontiers"] = len(policy.frontiers)
        return stats.map_generation_ms, stats.global_planning_ms + plan_ms

    runs: dict[str, Callable[[], tuple[float, float]]] = {
        "pm": pm,
        "fe": lambda: baseline(fe, lambda st: fe._next_goal(grid, pose_arr, st)),
        "nearest": lambda: baseline(near, lambda st: near.select_target(grid, pose_arr, st)),
    }
    times: dict[str, list[float]] = {s: [] for s in STAGES}
    for rnd in range(args.repeats + 1):
        for name, fn in runs.items():
            a, b = fn()
            if rnd > 0:  # round 0 warms up caches and compiled kernels
                times[f"{name}_map"].append(a)
                times[f"{name}_plan"].append(b)
    row: dict[str, Any] = {
        "world": spec,
        "cells": grid.size,
        "known_cells": int(np.count_nonzero(grid != UNKNOWN)),
        "free_area_m2": round(area_m2, 1),
        **facts,
    }
    for s in STAGES:
        stat = np.min if args.stat == "min" else np.median
        row[f"{s}_ms"] = round(float(stat(times[s])), 3)
        row[f"{s}_median_ms"] = round(float(np.median(times[s])), 3)
    return row


def _family(world: str) -> str:
    return world.split(":")[0] if ":" in world else "real"


def _figure(rows: list[dict[str, Any]], path: Path, stat: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    methods = {"pm": ("PM", "C0"), "fe": ("FE", "C1"), "nearest": ("nearest", "C2")}
    markers = {"maze": "o", "office": "s", "real": "^"}
    panels = (
        ("map", "map generation / frontier search", "cells"),
        ("plan", "global planning", "cells"),
        ("plan", "global planning", "intersections"),
    )
    for ax, (stage, title, xkey) in zip(axes, panels, strict=True):
        for m, (label, color) in methods.items():
            for fam, marker in markers.items():
                sel = sorted((r for r in rows if _family(r["world"]) == fam), key=lambda r: r[xkey])
                if not sel:
                    continue
                ax.plot(
                    [r[xkey] for r in sel],
                    [r[f"{m}_{stage}_ms"] for r in sel],
                    marker=marker,
                    color=color,
                    ls="-" if fam != "real" else "none",
                    alpha=0.85,
                    label=f"{label} ({fam})",
                )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("map cells (0.05 m)" if xkey == "cells" else "intersections in PM's map")
        ax.set_ylabel(f"ms per call ({stat})")
        ax.set_title(f"{title} vs {'map size' if xkey == 'cells' else 'intersections'}")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7, ncol=1)
    fig.suptitle(
        "PM: segmentation + Algorithm 1; FE: explore costmap + wavefront + selection, Navfn; "
        "nearest: wavefront, Dijkstra + Navfn",
        fontsize=9,
    )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--worlds", nargs="*", default=None, help="world spellings (default: the built-in list)"
    )
    ap.add_argument(
        "--maps", default="../shared/maps", help="folder of the real maps (skipped if absent)"
    )
    ap.add_argument(
        "--repeats", type=int, default=15, help="timed rounds per world (plus one warm-up)"
    )
    ap.add_argument(
        "--fraction", type=float, default=0.5, help="explored share of the geodesic extent"
    )
    ap.add_argument("--poses-per-m2", type=float, default=0.3, help="scan poses per m^2 explored")
    ap.add_argument(
        "--stat",
        choices=["median", "min"],
        default="median",
        help="statistic over the rounds for the table and figure (min estimates the uncontended "
        "time on a busy machine; the CSV always has the median too)",
    )
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--quick", action="store_true", help="only the 7 m maze and the 10 m office")
    # The committed copies in docs/figures/ are drawn by scripts/make_figures.py.
    ap.add_argument("--out", default="runs/compute_scaling.csv")
    ap.add_argument("--figure", default="runs/compute_scaling.png")
    args = ap.parse_args(argv)
    if args.worlds:
        worlds = list(args.worlds)
    elif args.quick:
        worlds = [PROCEDURAL[0], PROCEDURAL[6]]
    else:
        maps = Path(args.maps)
        worlds = PROCEDURAL + [str(maps / m) for m in REAL if (maps / m).exists()]
    rng = np.random.default_rng(args.seed)
    rows = []
    for spec in worlds:
        t0 = time.perf_counter()
        rows.append(bench_world(spec, args, rng))
        r = rows[-1]
        print(
            f"{spec}: {r['cells']} cells, {r['intersections']} intersections, "
            f"{time.perf_counter() - t0:.0f} s",
            flush=True,
        )
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    keys = sorted({k for r in rows for k in r}, key=lambda k: (k != "world", k))
    with out.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    if args.figure:
        _figure(rows, Path(args.figure), args.stat)
    print(
        f"\nms per call ({args.stat} of {args.repeats}); partly explored maps "
        f"({args.fraction:.0%} of the extent)\n"
    )
    cols = [
        "cells",
        "known_cells",
        "intersections",
        "openings",
        "pm_frontiers",
        "frontier_frontiers",
    ]
    print("| world | " + " | ".join(cols) + " | " + " | ".join(STAGES) + " |")
    print("|---|" + "---:|" * (len(cols) + len(STAGES)))
    for r in rows:
        name = r["world"] if ":" in r["world"] else Path(r["world"]).stem
        vals = [str(r.get(c, "")) for c in cols] + [f"{r[f'{s}_ms']:.2f}" for s in STAGES]
        print(f"| {name} | " + " | ".join(vals) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

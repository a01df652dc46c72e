"""``semexplore segment MAP_OR_WORLD --out seg.png [--json]``: segment a map and draw it.

The map is split into intersections, pathways, dead ends and pathways leading to frontiers (the
semantic topometric map of the paper); the time of the segmentation itself is printed.

``MAP_OR_WORLD`` is a ROS map (``.yaml``, unknown cells kept) or any world spec accepted by
:func:`semexplore_gym.maps.world_specs.make_world` (``maze1``, ``office:seed=3``, a HouseExpo
``.json``); a world is rasterised from its ground-truth free space (free inside, occupied
elsewhere) at ``--resolution``. The picture shows the areas tinted by type, the openings
(frontiers in magenta), the areas' paths and the frontier targets. ``--json`` prints the
counts, the areas with their openings and ``time_ms``; ``--export FILE`` writes the full JSON
export (:func:`semexplore_gym.core.topometric.export.to_json_dict`).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import cast

import numpy as np

from semexplore_gym.cli import describe
from semexplore_gym.cli._flags import check_output_flag
from semexplore_gym.cli._output import print_json
from semexplore_gym.core.grid import FREE, OCCUPIED, GridGeometry
from semexplore_gym.core.validation import short_repr


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "segment",
        help="segment a map into intersections, pathways, dead ends and frontier pathways; draw it to a PNG",
        description=describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "map",
        metavar="MAP_OR_WORLD",
        help="a ROS map .yaml, or a world spec (maze1, 'office:seed=3', a HouseExpo .json)",
    )
    p.add_argument("--out", help="output PNG path (omit to skip drawing)")
    p.add_argument(
        "--json",
        action="store_true",
        help="print counts, areas with their openings and time_ms as JSON",
    )
    p.add_argument(
        "--export",
        metavar="FILE",
        help="write the full JSON export of the map (graphs in node-link form)",
    )
    p.add_argument(
        "--clearance",
        type=float,
        default=0.155,
        help="robot radius + margin in metres (default 0.155: TurtleBot3 0.105 + 0.05)",
    )
    p.add_argument(
        "--resolution",
        type=float,
        default=0.05,
        help="cell size in metres when rasterising a world (default 0.05)",
    )
    p.add_argument(
        "--seed", type=int, default=0, help="seed for procedural worlds given without one"
    )
    p.add_argument("--edges", action="store_true", help="also draw the graph edges")
    p.add_argument("--ids", action="store_true", help="write area ids on the picture")
    return p


def _pool_min(mask: np.ndarray, k: int) -> np.ndarray:
    """Downsample a free mask by ``k``: a coarse cell is free only if all its fine cells are."""
    h, w = mask.shape
    H, W = -(-h // k), -(-w // k)
    pad = np.zeros((H * k, W * k), dtype=bool)
    pad[:h, :w] = mask
    return cast(np.ndarray, pad.reshape(H, k, W, k).all(axis=(1, 3)))


def load_grid(
    spec: str, resolution_m: float, seed: int = 0
) -> tuple[np.ndarray, GridGeometry, str]:
    """An encoded grid for a ROS map file or a world spec: ``(grid, geometry, name)``."""
    if not (np.isfinite(resolution_m) and resolution_m > 0):
        raise ValueError(f"--resolution must be a positive number of metres, got {resolution_m!r}")
    if str(spec).lower().endswith((".yaml", ".yml")):
        path = Path(spec)
        if not path.is_file():
            raise FileNotFoundError(f"map file not found: {path}")
        from semexplore_gym.maps.ros_map import load_ros_map

        grid, geometry = load_ros_map(path)
        return grid, geometry, str(spec)
    from semexplore_gym.maps import make_world

    world = make_world(spec, rng=np.random.default_rng(seed))
    g0 = world.free_geometry
    k = max(1, int(round(resolution_m / g0.resolution_m)))
    if abs(k * g0.resolution_m - resolution_m) > 1e-6 * resolution_m:
        raise ValueError(
            f"--resolution {resolution_m:g} m: world {short_repr(world.name)} is stored at "
            f"{g0.resolution_m:g} m cells; give a whole multiple of it (e.g. "
            f"{g0.resolution_m:g}, {2 * g0.resolution_m:g}, {4 * g0.resolution_m:g})"
        )
    free = _pool_min(world.free_mask, k) if k > 1 else world.free_mask
    geometry = GridGeometry(
        g0.resolution_m * k, g0.origin_x_m, g0.origin_y_m, free.shape[0], free.shape[1]
    )
    grid = np.where(free, FREE, OCCUPIED).astype(np.uint8)
    return grid, geometry, world.name


def summary(tmap, name: str) -> dict:
    """The ``--json`` record: counts, areas with their openings, frontiers and time_ms."""
    from semexplore_gym.core.topometric.export import type_name

    c = tmap.counts()
    areas = []
    for a in tmap.areas.values():
        areas.append(
            {
                "id": a.id,
                "type": type_name(a.type),
                "centre_m": [round(a.centre_m[0], 3), round(a.centre_m[1], 3)],
                "n_cells": a.n_cells,
                "openings": [
                    {
                        "id": o.id,
                        "midpoint_m": [round(o.midpoint_m[0], 3), round(o.midpoint_m[1], 3)],
                        "width_m": round(o.width_m, 3),
                        "area_ids": list(o.area_ids),
                        "is_frontier": o.is_frontier,
                    }
                    for o in (tmap.openings[k] for k in a.opening_ids)
                ],
            }
        )
    l_path = tmap.mean_intersection_path_m
    return {
        "map": name,
        **c,
        "frontiers": [
            {
                "area_id": f.area_id,
                "target_m": [round(f.midpoint_m[0], 3), round(f.midpoint_m[1], 3)],
                "width_m": round(f.width_m, 3),
                "intersection_id": f.intersection_id,
                "path_length_m": round(f.path_length_m, 3),
            }
            for f in tmap.frontiers
        ],
        "mean_intersection_path_m": round(l_path, 3) if np.isfinite(l_path) else None,
        "areas": areas,
        "time_ms": round(tmap.time_ms, 2),
    }


#: Accepted ``--resolution`` and ``--clearance`` (metres): beyond them the result is empty or
#: meaningless for a robot of ~0.1 m.
RESOLUTION_RANGE_M = (1e-3, 1.0)
CLEARANCE_RANGE_M = (0.0, 5.0)


def validate_args(args: argparse.Namespace) -> None:
    """Check the numbers and output paths before loading anything.

    Raises:
        ValueError: naming the argument and its value.
    """
    lo, hi = RESOLUTION_RANGE_M
    if not (lo <= args.resolution <= hi):
        raise ValueError(f"--resolution must be in [{lo:g}, {hi:g}] m, got {args.resolution!r}")
    lo, hi = CLEARANCE_RANGE_M
    if not (lo < args.clearance <= hi):
        raise ValueError(f"--clearance must be in ({lo:g}, {hi:g}] m, got {args.clearance!r}")
    if args.seed < 0 or args.seed > 2**32 - 1:
        raise ValueError(f"--seed must be in 0..2**32-1, got {args.seed}")
    if args.out is not None:
        check_output_flag("--out", args.out, (".png",))
    if args.export is not None:
        check_output_flag("--export", args.export, (".json",))


def run(args: argparse.Namespace) -> int:
    from semexplore_gym.core.topometric import segment_map

    validate_args(args)
    grid, geometry, name = load_grid(args.map, args.resolution, args.seed)
    # The first call of a process loads the compiled kernels (~0.3 s): do that on a tiny grid so
    # the reported time_ms is the segmentation's own.
    segment_map(np.full((8, 8), FREE, np.uint8), geometry.resolution_m, args.clearance)
    tmap = segment_map(grid, geometry, args.clearance)
    if not tmap.areas:
        raise ValueError(
            f"{short_repr(name)}: no area is left at --clearance {args.clearance:g} m and "
            f"{geometry.resolution_m:g} m cells (the free space is narrower than the clearance, "
            "or the map has none); lower --clearance or use a finer --resolution"
        )
    if args.out:
        from semexplore_gym.rendering.topometric_plot import save_topometric_png

        c = tmap.counts()
        # No time in the picture: it is the machine's, printed below; a figure keeps its title.
        title = (
            f"{name}: {c['intersections']} intersections, {c['pathways']} pathways, "
            f"{c['dead_ends']} dead ends, {c['frontier_pathways']} frontier pathways"
        )
        save_topometric_png(
            tmap, grid, args.out, show_edges=args.edges, show_ids=args.ids, title=title
        )
    if args.export:
        from semexplore_gym.core.topometric.export import to_json_dict

        Path(args.export).write_text(json.dumps(to_json_dict(tmap)))
        print(f"wrote {args.export}", file=sys.stderr)
    if args.json:
        print_json(args, summary(tmap, name))
    else:
        c = tmap.counts()
        print(
            f"{name}: {c['intersections']} intersections, {c['pathways']} pathways, {c['dead_ends']} dead ends, "
            f"{c['frontier_pathways']} frontier pathways, {len(tmap.frontiers)} frontiers in {tmap.time_ms:.1f} ms"
            + (f" -> {args.out}" if args.out else ""),
            file=sys.stdout,
        )
    return 0

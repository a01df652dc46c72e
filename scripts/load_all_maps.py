"""Load every world of the shared map collection (and the built-in worlds) and time it.

Prints one line per map: name, native free-mask size (cells and metres), number of wall
segments, free area, load time, and the time of the first start-pose sample (which computes
and caches the clearance mask) and of rasterising the free space on a 0.05 m grid.

    python scripts/load_all_maps.py                 # ../shared/maps next to the repository
    python scripts/load_all_maps.py --maps-dir DIR --builtin --repeat 3
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.worlds import (
    rasterize_free,
    sample_start_pose,
    world_from_free_mask,
)
from semexplore_gym.maps import make_world

DEFAULT_MAPS = Path(__file__).resolve().parents[1] / ".." / "shared" / "maps"
BUILTIN = [
    "maze1",
    "maze2",
    "maze:seed=0,size_m=10,braid=0.3",
    "office:seed=0,size_m=20",
    "cave:seed=0,size_m=15",
]


def _time_ms(fn, repeat: int) -> tuple[float, object]:
    best = np.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return 1e3 * best, out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--maps-dir", type=Path, default=DEFAULT_MAPS, help="root of the map collection"
    )
    parser.add_argument(
        "--builtin", action="store_true", help="also time the built-in and procedural worlds"
    )
    parser.add_argument(
        "--repeat", type=int, default=1, help="load each map this many times, report the best"
    )
    parser.add_argument("--clearance-m", type=float, default=0.155, help="start-pose clearance")
    parser.add_argument(
        "--grid-resolution-m", type=float, default=0.05, help="resolution for rasterize_free"
    )
    parser.add_argument(
        "--max-grid-cells",
        type=int,
        default=20_000_000,
        help="skip rasterize_free on grids larger than this",
    )
    args = parser.parse_args(argv)

    specs: list[str] = list(BUILTIN) if args.builtin else []
    maps_dir = args.maps_dir.resolve()
    if maps_dir.is_dir():
        files = sorted(maps_dir.rglob("*.yaml")) + sorted(
            (maps_dir / "houseexpo" / "json").glob("*.json")
        )
        specs += [str(p) for p in files]
    elif not specs:
        print(f"map directory not found: {maps_dir}", file=sys.stderr)
        return 1

    # Compile / load the numba kernels once so the first map's time is comparable.
    warm = make_world("maze1")
    world_from_free_mask("warm-up", np.ones((3, 3), dtype=bool), GridGeometry(1.0, 0.0, 0.0, 3, 3))
    sample_start_pose(warm, np.random.default_rng(0), 0.155)
    header = f"{'name':58s} {'cells (W x H)':>14s} {'metres':>14s} {'segments':>8s} {'free m2':>8s} {'load ms':>8s} {'start ms':>8s} {'raster ms':>9s}"
    print(header)
    print("-" * len(header))
    total_ms = 0.0
    for spec in specs:
        load_ms, world = _time_ms(lambda spec=spec: make_world(spec), args.repeat)
        total_ms += load_ms
        t0 = time.perf_counter()
        sample_start_pose(world, np.random.default_rng(0), args.clearance_m)
        start_ms = 1e3 * (time.perf_counter() - t0)
        geometry = GridGeometry.covering(
            *world.bounds_m, resolution_m=args.grid_resolution_m, margin_m=0.2
        )
        if geometry.height * geometry.width <= args.max_grid_cells:
            raster_ms, _ = _time_ms(
                lambda world=world, geometry=geometry: rasterize_free(world, geometry), 1
            )
        else:
            raster_ms = float("nan")  # e.g. the 1.2 km SFU campus at 0.05 m
        g = world.free_geometry
        w_m, h_m = world.size_m
        free_m2 = world.free_mask.sum() * g.resolution_m**2
        name = (
            str(Path(spec).resolve().relative_to(maps_dir))
            if spec.startswith(str(maps_dir))
            else spec
        )
        print(
            f"{name[:58]:58s} {f'{g.width} x {g.height}':>14s} {f'{w_m:.1f} x {h_m:.1f}':>14s} "
            f"{world.n_segments:8d} {free_m2:8.1f} {load_ms:8.1f} {start_ms:8.1f} {raster_ms:9.1f}"
        )
    print(f"total load time {total_ms:.0f} ms for {len(specs)} worlds")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

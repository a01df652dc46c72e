"""Segment every ROS map (``*.yaml``) under ``../shared/maps`` and print counts and times.

The shared map collection lives beside the repository (``<repo>/../shared/maps``); the script
exits cleanly with a message when it is absent. Usage::

    python scripts/segment_all_maps.py [--maps DIR] [--clearance 0.155] [--repeats 3] [--json]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from semexplore_gym.core.topometric import segment_map
from semexplore_gym.maps.ros_map import load_ros_map

DEFAULT_MAPS = Path(__file__).resolve().parents[1] / ".." / "shared" / "maps"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--maps", type=Path, default=DEFAULT_MAPS, help="directory searched recursively for *.yaml"
    )
    ap.add_argument(
        "--clearance", type=float, default=0.155, help="robot radius + margin in metres"
    )
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per map (median reported)")
    ap.add_argument(
        "--json", action="store_true", help="print one JSON object per map instead of a table"
    )
    args = ap.parse_args(argv)
    if not args.maps.is_dir():
        print(f"no map directory at {args.maps.resolve()}; nothing to do")
        return 0
    files = sorted(args.maps.rglob("*.yaml"))
    if not files:
        print(f"no *.yaml maps under {args.maps.resolve()}")
        return 0
    if not args.json:
        print(
            "| map | cells | res (m) | intersections | pathways | dead ends | frontier pathways | frontiers | median ms |"
        )
        print("|---|---|---|---|---|---|---|---|---|")
    failures = 0
    for path in files:
        name = str(path.relative_to(args.maps))
        try:
            grid, geometry = load_ros_map(path)
            times = []
            tmap = None
            for _ in range(max(1, args.repeats)):
                t0 = time.perf_counter()
                tmap = segment_map(grid, geometry, args.clearance)
                times.append((time.perf_counter() - t0) * 1000.0)
        except Exception as e:  # report and continue: the script's purpose is a survey
            failures += 1
            print(
                f"| {name} | error: {type(e).__name__}: {e} |"
                if not args.json
                else json.dumps({"map": name, "error": str(e)})
            )
            continue
        assert tmap is not None
        c = tmap.counts()
        ms = float(np.median(times))
        if args.json:
            print(
                json.dumps(
                    {
                        "map": name,
                        "shape": list(grid.shape),
                        "resolution_m": geometry.resolution_m,
                        **c,
                        "frontiers": len(tmap.frontiers),
                        "time_ms": round(ms, 2),
                    }
                )
            )
        else:
            print(
                f"| {name} | {grid.shape[1]}x{grid.shape[0]} | {geometry.resolution_m:g} | {c['intersections']} | "
                f"{c['pathways']} | {c['dead_ends']} | {c['frontier_pathways']} | {len(tmap.frontiers)} | {ms:.1f} |"
            )
        sys.stdout.flush()
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

"""Explore the real maps in ``../shared/maps`` with a policy (default: the semantic expert).

The maps a TurtleBot can explore within the time limit: the TurtleBot3 world and office, the
@Home lab (brsu-c069), the Nav2 depot, the Intel lab and the HouseExpo plans. One row per map
is printed as soon as its mission ends (coverage, mission time, collisions, stop reason, wall
time); ``--jsonl FILE`` appends the full summaries as JSON lines. A map that raises is reported
as an error row and the script goes on; the exit code is 1 if any map failed.

Usage::

    python scripts/explore_real_maps.py [--maps-dir ../shared/maps] [--max-time-s 1200]
        [--only intel_map] [--policy semantic] [--policy-config FILE] [--policy-set KEY=VALUE] [--jsonl out.jsonl]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import traceback
from pathlib import Path

#: Map files relative to the maps directory, with a short name each.
REAL_MAPS: tuple[tuple[str, str], ...] = (
    ("tb3_world", "turtlebot3/world/map.yaml"),
    ("tb3_office", "turtlebot3/office/map_office_raw.yaml"),
    ("brsu_lab", "mas_domestic_robotics/brsu-c069/map.yaml"),
    ("depot", "navigation2/depot.yaml"),
    ("intel_lab", "ipa_room_segmentation/intel_map.yaml"),
    ("houseexpo_1451", "houseexpo/json/house_expo_room_1451.json"),
    ("houseexpo_08d4", "houseexpo/png/08d4ecc49835d0bd677138765d90a035.yaml"),
    ("houseexpo_15de", "houseexpo/png/15ded3a168cd9513b876ab36600b5650.yaml"),
    ("houseexpo_1dfb", "houseexpo/png/1dfb7bd5d9a447175a9719096fbacea7.yaml"),
    ("houseexpo_1eb9", "houseexpo/png/1eb932a28c3b80449c06b59a35fbf549.yaml"),
    ("houseexpo_20ec", "houseexpo/png/20ec9ec7f8783ee18b3c9da7bff12b0e.yaml"),
    ("houseexpo_237f", "houseexpo/png/237f80139e1659ec0232b6c7e6bd3e21.yaml"),
    ("houseexpo_9cea", "houseexpo/png/9cea230f67d0a5a2fb1dd857e1f4393d.yaml"),
    ("houseexpo_c451", "houseexpo/png/c4513f5dfd084681ed2d0c24e85b9cf7.yaml"),
)


def default_maps_dir() -> Path:
    return Path(__file__).resolve().parents[1] / ".." / "shared" / "maps"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument(
        "--maps-dir",
        type=Path,
        default=default_maps_dir(),
        help="the shared maps directory (default: <repo>/../shared/maps)",
    )
    ap.add_argument(
        "--only",
        nargs="*",
        default=None,
        help="map names to run (default: all): " + ", ".join(n for n, _ in REAL_MAPS),
    )
    ap.add_argument("--policy", default="semantic", help="policy spec (default: semantic)")
    ap.add_argument(
        "--policy-config", default=None, help="policy config YAML (sections env / policy / params)"
    )
    ap.add_argument(
        "--policy-set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="policy parameter override",
    )
    ap.add_argument("--seed", type=int, default=0, help="seed of each mission (default: 0)")
    ap.add_argument(
        "--max-time-s",
        type=float,
        default=1200.0,
        help="simulated time limit per map (default: 1200)",
    )
    ap.add_argument(
        "--jsonl",
        type=Path,
        default=None,
        help="append each map's full summary to this JSON-lines file",
    )
    ap.add_argument(
        "--progress", action="store_true", help="show a progress bar per mission on stderr"
    )
    args = ap.parse_args(argv)

    import gymnasium as gym
    from semexplore_gym.policies.registry import make_policy
    from semexplore_gym.policies.specs import load_policy_config

    import semexplore_gym  # noqa: F401
    from semexplore_gym.evaluation.rollout import run_mission

    if not args.maps_dir.is_dir():
        print(f"maps directory not found: {args.maps_dir}", file=sys.stderr)
        return 2
    names = {n for n, _ in REAL_MAPS}
    for n in args.only or []:
        if n not in names:
            print(f"unknown map {n!r}; known: {', '.join(sorted(names))}", file=sys.stderr)
            return 2
    cfg = load_policy_config(args.policy_config)
    kwargs = cfg.policy_kwargs(args.overrides)

    header = f"{'map':16s} {'coverage':>8s} {'time_s':>8s} {'stopped':>7s} {'coll':>4s} {'path_m':>7s} {'wall_s':>7s}  stop reason"
    print(header, flush=True)
    failures = 0
    for name, rel in REAL_MAPS:
        if args.only and name not in args.only:
            continue
        path = args.maps_dir / rel
        t0 = time.perf_counter()
        try:
            env = gym.make(
                "SemanticExplore-v0",
                world=str(path),
                config=cfg.env,
                overrides=[f"episode.max_time_s={args.max_time_s!r}"],
            )
            try:
                policy = make_policy(args.policy or cfg.policy or "semantic", **dict(kwargs))
                # The mission lasts until the policy stops (or the time limit), not until the
                # env's coverage goal.
                res = run_mission(
                    env,
                    policy,
                    seed=args.seed,
                    max_time_s=args.max_time_s,
                    progress=args.progress,
                    ignore_terminated=True,
                )
            finally:
                env.close()
        except Exception as e:  # noqa: BLE001 - report and go on with the next map
            failures += 1
            print(
                f"{name:16s} {'error':>8s} {'':8s} {'':7s} {'':4s} {'':7s} {time.perf_counter() - t0:7.1f}  {type(e).__name__}: {e}",
                flush=True,
            )
            traceback.print_exc(file=sys.stderr)
            continue
        s = res.summary()
        print(
            f"{name:16s} {s['coverage']:8.3f} {s['mission_time_s']:8.1f} {str(s['self_stopped']):>7s} {s['collisions']:4d} "
            f"{s['path_length_m']:7.1f} {s['wall_time_s']:7.1f}  {s['stop_reason']}",
            flush=True,
        )
        if args.jsonl is not None:
            with args.jsonl.open("a") as f:
                f.write(json.dumps({"map": name, "file": rel, **s}) + "\n")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

"""``semexplore show-world WORLD --out FILE.png``: draw a world's walls, free space and start.

The world is drawn as if fully mapped: walls, free space and the start pose (sampled with
``--seed`` when the world has none). ``--json`` prints its size, free area and load time.

Example::

    semexplore show-world maze1 --out maze1.png
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import TYPE_CHECKING, cast

import numpy as np

from semexplore_gym.cli import describe
from semexplore_gym.cli._output import print_json

if TYPE_CHECKING:
    from semexplore_gym.envs.semantic_explore import SemanticExploreEnv


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "show-world",
        help="draw a world (walls, free space, start pose) to a PNG",
        description=describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "world",
        help="maze1, maze2, 'maze:seed=3', 'office:...', 'cave:...', 'noisecave:...', a ROS map "
        ".yaml or a HouseExpo .json",
    )
    p.add_argument("--out", required=True, help="output PNG path")
    p.add_argument(
        "--seed", type=int, default=0, help="seed for procedural worlds and start sampling"
    )
    p.add_argument("--json", action="store_true", help="print facts about the world as JSON")
    return p


def run(args: argparse.Namespace) -> int:
    import gymnasium as gym

    import semexplore_gym  # noqa: F401  (registers the env)
    from semexplore_gym.cli._flags import check_output_flag
    from semexplore_gym.rendering.renderer import Renderer, RenderSnapshot

    check_output_flag("--out", args.out, (".png",))
    if not (0 <= args.seed <= 2**32 - 1):
        raise ValueError(f"--seed must be in 0..2**32-1, got {args.seed}")
    t0 = time.perf_counter()
    env = gym.make("SemanticExplore-v0", world=args.world)
    base = cast("SemanticExploreEnv", env.unwrapped)
    base.reset(seed=args.seed)
    load_s = time.perf_counter() - t0
    world = base.world
    # Draw the ground truth as if fully mapped, so the picture shows the whole building.
    from semexplore_gym.core.grid import FREE, OCCUPIED
    from semexplore_gym.envs.coverage_mask import coverage_mask

    g = base.map_geometry
    pose = base.sim.pose
    reach = coverage_mask(world, g, pose[:2], base.config)
    grid = np.where(reach, FREE, OCCUPIED).astype(np.uint8)
    grid[~reach] = 128
    snap = RenderSnapshot(
        map=grid,
        geometry=g,
        segments_m=world.segments_m,
        pose=pose,
        radius_m=base.config.robot.radius_m,
        text=f"{world.name}",
    )
    frame = Renderer(g, max_size_px=900).draw(snap)
    from PIL import Image

    Image.fromarray(frame).save(args.out)
    facts = {
        "world": world.name,
        "size_m": [round(v, 3) for v in world.size_m],
        "n_segments": world.n_segments,
        "map_shape": list(g.shape),
        "resolution_m": g.resolution_m,
        "start_pose": [round(v, 4) for v in pose],
        "reachable_area_m2": float(reach.sum() * g.resolution_m**2),
        "load_s": round(load_s, 3),
        "out": args.out,
    }
    if args.json:
        print_json(args, facts)
    else:
        print(
            f"{world.name}: {facts['size_m'][0]} x {facts['size_m'][1]} m, {world.n_segments} wall segments, "
            f"map {g.height}x{g.width} at {g.resolution_m} m, reachable {facts['reachable_area_m2']:.1f} m^2 -> {args.out}",
            file=sys.stdout,
        )
    env.close()
    return 0

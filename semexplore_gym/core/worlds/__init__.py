"""Worlds: wall geometry, bounds, start pose and ground-truth free space.

Build one with :func:`make_world` (``"maze1"``, ``"office:seed=3,size_m=20"``, a ROS map
``.yaml``, a HouseExpo ``.json``). A :class:`World` holds wall segments in metres and a native
ground-truth free mask; :func:`rasterize_free` puts that free space on any other grid,
:func:`sample_start_pose` / :func:`validate_start_pose` handle start poses and
:func:`reachable_free_mask` gives the area a robot can cover (for coverage accounting).
"""

from semexplore_gym.core.worlds.build import world_from_free_mask, world_from_segments
from semexplore_gym.core.worlds.cave import CaveParams, generate_cave
from semexplore_gym.core.worlds.fixed_mazes import make_maze1, make_maze2
from semexplore_gym.core.worlds.geometry import distance_to_segments_m, segment_distance_field
from semexplore_gym.core.worlds.grid_maze import MazeParams, generate_maze
from semexplore_gym.core.worlds.houseexpo import load_houseexpo_world
from semexplore_gym.core.worlds.office import OfficeParams, generate_office
from semexplore_gym.core.worlds.raster import raster_to_segments, rasterize_free
from semexplore_gym.core.worlds.registry import (
    list_world_names,
    make_world,
    parse_world_spec,
    world_family_parameters,
)
from semexplore_gym.core.worlds.ros_map import load_ros_map, load_ros_map_world
from semexplore_gym.core.worlds.start import (
    reachable_free_mask,
    sample_start_pose,
    validate_start_pose,
)
from semexplore_gym.core.worlds.world import World

__all__ = [
    "CaveParams",
    "MazeParams",
    "OfficeParams",
    "World",
    "distance_to_segments_m",
    "generate_cave",
    "generate_maze",
    "generate_office",
    "list_world_names",
    "load_houseexpo_world",
    "load_ros_map",
    "load_ros_map_world",
    "make_maze1",
    "make_maze2",
    "make_world",
    "parse_world_spec",
    "raster_to_segments",
    "rasterize_free",
    "reachable_free_mask",
    "sample_start_pose",
    "segment_distance_field",
    "validate_start_pose",
    "world_family_parameters",
    "world_from_free_mask",
    "world_from_segments",
]

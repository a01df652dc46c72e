"""Worlds: wall geometry, bounds, start pose and ground-truth free space.

Build a fixed or procedural one with :func:`make_procedural_world` (``"maze1"``,
``"office:seed=3,size_m=20"``, ``"noisecave:seed=1,threshold=0.44"``); worlds from map files (a ROS map ``.yaml``, a HouseExpo
``.json``, ``"map:NAME"``) and ``make_world``, which takes any spec, are in
:mod:`semexplore_gym.maps`. A :class:`World` holds wall segments in metres and a native
ground-truth free mask; :func:`rasterize_free` puts that free space on any other grid,
:func:`sample_start_pose` / :func:`validate_start_pose` handle start poses and
:func:`reachable_free_mask` gives the area a robot can cover (for coverage accounting).
"""

from semexplore_gym.core.worlds.build import world_from_free_mask, world_from_segments
from semexplore_gym.core.worlds.cave import CaveParams, generate_cave
from semexplore_gym.core.worlds.fixed_mazes import make_maze1, make_maze2
from semexplore_gym.core.worlds.geometry import distance_to_segments_m, segment_distance_field
from semexplore_gym.core.worlds.grid_maze import MazeParams, generate_maze
from semexplore_gym.core.worlds.noise_cave import NoiseCaveParams, generate_noise_cave
from semexplore_gym.core.worlds.office import OfficeParams, generate_office
from semexplore_gym.core.worlds.procedural import (
    list_world_names,
    make_procedural_world,
    parse_world_spec,
    world_family_parameters,
)
from semexplore_gym.core.worlds.raster import raster_to_segments, rasterize_free
from semexplore_gym.core.worlds.start import (
    reachable_free_mask,
    sample_start_pose,
    validate_start_pose,
)
from semexplore_gym.core.worlds.world import World

__all__ = [
    "CaveParams",
    "MazeParams",
    "NoiseCaveParams",
    "OfficeParams",
    "World",
    "distance_to_segments_m",
    "generate_cave",
    "generate_maze",
    "generate_noise_cave",
    "generate_office",
    "list_world_names",
    "make_maze1",
    "make_maze2",
    "make_procedural_world",
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

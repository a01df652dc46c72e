"""The fused scan + map call gives the bits of the separate scan and ``integrate_scan`` calls."""

from __future__ import annotations

import math

import numpy as np
import pytest

from semexplore_gym.core.grid import GridGeometry
from semexplore_gym.core.mapping.occupancy_grid import MappingParams, OccupancyGrid
from semexplore_gym.core.mapping.raycast import SegmentIndex
from semexplore_gym.maps import make_world
from semexplore_gym.sim.lidar import Lidar, LidarParams


@pytest.mark.parametrize(
    "params,odometry_offset",
    [
        (LidarParams(), 0.0),
        (LidarParams(range_noise_std_m=0.02, dropout_prob=0.1), 0.0),
        (LidarParams(mount_x_m=0.05, mount_y_m=-0.02, min_range_m=0.0, max_range_m=2.0), 0.03),
        (LidarParams(n_beams=90, range_noise_std_m=0.01), 0.01),
    ],
)
def test_fused_scan_and_map_match_the_separate_calls(
    params: LidarParams, odometry_offset: float
) -> None:
    world = make_world("maze1")
    geometry = GridGeometry.covering(*world.bounds_m, 0.05, 0.5)
    lidar = Lidar(params, SegmentIndex(world.segments_m))
    mp = MappingParams()
    separate, fused = OccupancyGrid(geometry, mp), OccupancyGrid(geometry, mp)
    rng_a, rng_b, poses_rng = (
        np.random.default_rng(5),
        np.random.default_rng(5),
        np.random.default_rng(1),
    )
    xmin, ymin, xmax, ymax = world.bounds_m
    for _ in range(300):  # more than 255 scans: the stamp reset happens on both
        pose = (
            float(poses_rng.uniform(xmin, xmax)),
            float(poses_rng.uniform(ymin, ymax)),
            float(poses_rng.uniform(-math.pi, math.pi)),
        )
        est = (pose[0] + odometry_offset, pose[1], pose[2] + 0.5 * odometry_offset)
        scan_a = lidar.scan(*pose, rng_a)
        separate.integrate_scan(
            *lidar.sensor_pose(*est), lidar.beam_angles_rad, scan_a, params.max_range_m
        )
        scan_b = lidar.sense_and_map(pose, est, fused, rng_b)
        assert scan_b.dtype == np.float32
        np.testing.assert_array_equal(scan_a, scan_b)
    np.testing.assert_array_equal(separate.log_odds, fused.log_odds)
    np.testing.assert_array_equal(separate.encoded, fused.encoded)
    assert (separate.n_free_cells, separate.n_free_in_mask) == (
        fused.n_free_cells,
        fused.n_free_in_mask,
    )


def test_fused_call_rejects_a_non_finite_pose() -> None:
    world = make_world("maze1")
    lidar = Lidar(LidarParams(), SegmentIndex(world.segments_m))
    grid = OccupancyGrid(GridGeometry.covering(*world.bounds_m, 0.05, 0.5))
    with pytest.raises(ValueError, match="finite"):
        lidar.sense_and_map(
            (1.0, float("nan"), 0.0), (1.0, 1.0, 0.0), grid, np.random.default_rng(0)
        )
